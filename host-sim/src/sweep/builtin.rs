//! The sweeps shipped with the binary (`host-sim sweep --list`), from `host-sim/sweeps/`.

/// A built-in sweep: its name, one line, and its TOML text.
#[derive(Clone, Copy, Debug)]
pub struct BuiltinSweep {
    /// Name on the command line (`host-sim sweep basin`).
    pub name: &'static str,
    /// One line for `--list`.
    pub description: &'static str,
    /// The TOML text.
    pub text: &'static str,
}

/// The built-in sweeps (`docs/sweeps.md` has their results).
pub const BUILTIN_SWEEPS: &[BuiltinSweep] = &[
    BuiltinSweep {
        name: "basin",
        description: "formation-only from random shapes 10/30/60 % off a 1.5 m square, continuous and sampled, 100 runs each",
        text: include_str!("../../sweeps/basin.toml"),
    },
    BuiltinSweep {
        name: "noise-loss",
        description: "paper against bearing noise 0–5° and packet loss 0–50 %",
        text: include_str!("../../sweeps/noise-loss.toml"),
    },
    BuiltinSweep {
        name: "comm-rate",
        description: "paper against the communication rate (needs the scenario key controller.comm_rate_hz)",
        text: include_str!("../../sweeps/comm-rate.toml"),
    },
];

/// Looks up a built-in sweep by name.
pub fn builtin_sweep(name: &str) -> Option<&'static BuiltinSweep> {
    BUILTIN_SWEEPS.iter().find(|b| b.name == name)
}
