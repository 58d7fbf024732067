//! The scenarios embedded in the binary (`host-sim list`).

/// A built-in scenario: its name, one-line description and TOML text.
#[derive(Clone, Copy, Debug)]
pub struct Builtin {
    /// Name used on the command line (`host-sim run paper`).
    pub name: &'static str,
    /// One line for `host-sim list`.
    pub description: &'static str,
    /// The TOML text.
    pub text: &'static str,
}

/// The scenarios embedded in the binary (SPEC §9). The first is the default run.
pub const BUILTINS: &[Builtin] = &[
    Builtin {
        name: "paper",
        description: "SPEC §9 reference: c = 1000, d = 10, c_e = 1000, leader edge and v*, 100 s (converges)",
        text: include_str!("../../scenarios/paper.toml"),
    },
    Builtin {
        name: "paper-printed",
        description: "SPEC §9 with the printed gains c = 10, d = 1, c_e = 10 (fails: estimates collapse, agents collide)",
        text: include_str!("../../scenarios/paper-printed.toml"),
    },
    Builtin {
        name: "formation-only",
        description: "SPEC §9 printed gains without maneuvers (no leader edge, v* = 0, D^v = 0; converges)",
        text: include_str!("../../scenarios/formation-only.toml"),
    },
];

/// Looks up a built-in scenario by name.
pub fn builtin(name: &str) -> Option<&'static Builtin> {
    BUILTINS.iter().find(|b| b.name == name)
}
