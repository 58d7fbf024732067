//! `cargo xtask bench-counts`: the simulator's cost in deterministic counts. Runs
//! host-sim's `counts` example under valgrind's callgrind with a fixed simulated cache,
//! counting only the measured part (`--toggle-collect`), and checks the instructions and
//! last-level misses per agent-step against `host-sim/bench-counts.toml` with a 5 % guard
//! (as `firmware-check` does on target). Wall-clock figures stay in the criterion bench
//! and `docs/performance.md`.

use crate::tools::{self, cargo};
use qemu_harness::firmware::{target_dir, workspace_root};
use serde::Deserialize;
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::process::Command;

/// A measured figure may exceed its budget by this fraction before it is a regression.
pub const GUARD: f64 = 0.05;

/// And by this much per agent-step in any case (a figure near zero, such as the
/// last-level misses of a run that fits the cache, has no meaningful fraction).
pub const SLACK: f64 = 0.1;

/// One measured case.
#[derive(Clone, Copy, Debug)]
pub struct Case {
    /// Its name in the budget file.
    pub name: &'static str,
    /// The `counts` example's arguments.
    pub args: &'static [&'static str],
    /// The simulated last-level cache (bytes; 16-way, 64-byte lines).
    pub ll_bytes: u64,
    /// Measured by `cargo xtask test` (CI); the others only with `--all`.
    pub ci: bool,
}

/// The simulated last-level cache of the tables in `docs/performance.md` (32 MiB).
const LL: u64 = 32 << 20;

/// The measured cases. The 100,000-agent strip (about 160 s under callgrind in the dev
/// build) stands in CI as an eighth of it with an eighth of the cache, `strip_12500_ll4m`:
/// the same ratio of the memory a tick walks to the cache, so the same misses per
/// agent-step (41.8 both, and 6,803 and 6,802 instructions, dev build), in 15 s. The strips count ticks after warm-up ticks (the
/// first tick receives nothing); the paper run is counted whole (diagnostics included).
pub const CASES: [Case; 5] = [
    Case {
        name: "strip_1000",
        args: &["strip", "1000", "2", "4"],
        ll_bytes: LL,
        ci: true,
    },
    Case {
        name: "strip_12500_ll4m",
        args: &["strip", "12500", "1", "1"],
        ll_bytes: LL / 8,
        ci: true,
    },
    Case {
        name: "strip_100000",
        args: &["strip", "100000", "1", "1"],
        ll_bytes: LL,
        ci: false,
    },
    Case {
        name: "paper",
        args: &["paper", "2"],
        ll_bytes: LL,
        ci: true,
    },
    // The robot's world (docs/world.md): strip20 under world = "crazyflie", whole.
    Case {
        name: "crazyflie_strip20",
        args: &["crazyflie", "2"],
        ll_bytes: LL,
        ci: true,
    },
];

/// The simulated first-level caches: 32 KiB 8-way I1, 48 KiB 12-way D1, 64-byte lines
/// (the machine of `docs/performance.md`'s tables; fixed, with the last level of each
/// [`Case`], so that the counts do not depend on the machine that measures).
const CACHE: [&str; 2] = ["--I1=32768,8,64", "--D1=49152,12,64"];

/// The budget file: per build profile (`dev`, `release`), per case, the limits.
#[derive(Clone, Debug, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Budgets {
    /// `[dev.<case>]`: the `dev` profile's binary (what CI measures: `cargo test` built it).
    #[serde(default)]
    pub dev: BTreeMap<String, Limits>,
    /// `[release.<case>]`: the release build (the figures of `docs/performance.md`).
    #[serde(default)]
    pub release: BTreeMap<String, Limits>,
    /// `[outputs.<case>]`: the outputs against the engine (dev build;
    /// [`crate::bench_outputs`]).
    #[serde(default)]
    pub outputs: BTreeMap<String, crate::bench_outputs::OutputLimits>,
}

/// The limits of one case, per agent-step.
#[derive(Clone, Copy, Debug, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Limits {
    /// Instructions executed.
    pub instructions: f64,
    /// Last-level cache misses (reads and writes, instruction and data).
    pub ll_misses: f64,
}

impl Budgets {
    /// Parses a budget file's text; errors name `name`, and any unknown case.
    pub fn parse(text: &str, name: &str) -> Result<Self, String> {
        let b: Budgets = toml::from_str(text).map_err(|e| format!("{name}: {e}"))?;
        for (profile, cases) in [("dev", &b.dev), ("release", &b.release)] {
            for case in cases.keys() {
                if !CASES.iter().any(|c| c.name == case) {
                    let known: Vec<&str> = CASES.iter().map(|c| c.name).collect();
                    return Err(format!(
                        "{name}: [{profile}.{case}]: unknown case (cases: {})",
                        known.join(", ")
                    ));
                }
            }
        }
        for case in b.outputs.keys() {
            if !crate::bench_outputs::OUTPUTS.iter().any(|c| c.name == case) {
                let known: Vec<&str> = crate::bench_outputs::OUTPUTS
                    .iter()
                    .map(|c| c.name)
                    .collect();
                return Err(format!(
                    "{name}: [outputs.{case}]: unknown case (cases: {})",
                    known.join(", ")
                ));
            }
        }
        Ok(b)
    }
}

/// What callgrind counted in one run, per agent-step.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Counts {
    /// Instructions per agent-step.
    pub instructions: f64,
    /// Last-level misses per agent-step.
    pub ll_misses: f64,
}

/// The totals of callgrind's output file: the `events:` line names the columns, the
/// `totals:` (or `summary:`) line holds them. Returns (instructions, last-level misses).
pub fn parse_callgrind(text: &str) -> Result<(u64, u64), String> {
    let line = |key: &str| text.lines().find_map(|l| l.strip_prefix(key));
    let events: Vec<&str> = line("events:")
        .ok_or("no `events:` line")?
        .split_whitespace()
        .collect();
    let totals: Vec<u64> = line("totals:")
        .or_else(|| line("summary:"))
        .ok_or("no `totals:` line")?
        .split_whitespace()
        .map(|v| v.parse().map_err(|_| format!("bad total '{v}'")))
        .collect::<Result<_, _>>()?;
    let get = |name: &str| {
        events
            .iter()
            .position(|e| *e == name)
            .map(|i| totals.get(i).copied().unwrap_or(0))
    };
    let ir = get("Ir").ok_or("no Ir event (callgrind without --cache-sim?)")?;
    let ll = ["ILmr", "DLmr", "DLmw"]
        .iter()
        .map(|e| get(e).ok_or(format!("no {e} event (callgrind without --cache-sim?)")))
        .sum::<Result<u64, String>>()?;
    Ok((ir, ll))
}

/// Whether `measured` passes `limit` with the guard; the message says by how much.
pub fn check(name: &str, measured: f64, limit: f64) -> (bool, String) {
    let margin = (limit * GUARD).max(SLACK);
    let ok = measured <= limit + margin;
    let ratio = measured / limit;
    let verdict = if !ok {
        "REGRESSION"
    } else if measured < limit - margin {
        "ok (more than 5 % under: lower the budget)"
    } else {
        "ok"
    };
    (
        ok,
        format!(
            "   {name:<32} {measured:>10.1} / budget {limit:>10.1} ({:+.1} %) {verdict}",
            (ratio - 1.0) * 100.0
        ),
    )
}

/// `host-sim/bench-counts.toml`.
pub fn default_budgets() -> PathBuf {
    workspace_root().join("host-sim/bench-counts.toml")
}

/// Options of a measurement.
#[derive(Clone, Debug)]
pub struct Options {
    /// Build profile of the measured binary: `dev` or `release`.
    pub profile: String,
    /// The budget file.
    pub budgets: PathBuf,
    /// Only measure and print (no check).
    pub no_check: bool,
    /// Every case, not only CI's.
    pub all: bool,
}

/// Builds the example, measures every case, checks against the budgets; `Ok(true)` if
/// every figure is within its guard.
pub fn run(o: &Options) -> Result<bool, String> {
    let text = std::fs::read_to_string(&o.budgets)
        .map_err(|e| format!("cannot read {}: {e}", o.budgets.display()))?;
    let budgets = Budgets::parse(&text, &o.budgets.display().to_string())?;
    let limits = match o.profile.as_str() {
        "dev" => &budgets.dev,
        "release" => &budgets.release,
        p => return Err(format!("--profile {p}: expected dev or release")),
    };
    let mut build = cargo();
    build.args(["build", "-p", "ph-formation-sim", "--example", "counts"]);
    if o.profile == "release" {
        build.arg("--release");
    }
    tools::run(&mut build)?;
    let dir = if o.profile == "release" {
        "release"
    } else {
        "debug"
    };
    let exe = target_dir().join(dir).join("examples/counts");
    let out = target_dir().join("bench-counts");
    std::fs::create_dir_all(&out).map_err(|e| format!("{}: {e}", out.display()))?;
    let mut ok = true;
    println!("per agent-step ({} build):", o.profile);
    for case in CASES.iter().filter(|c| c.ci || o.all) {
        let file = out.join(format!("{}.{}.out", case.name, o.profile));
        let c = measure(&exe, &file, case)?;
        let case = case.name;
        for (what, measured, limit) in [
            (
                "instructions",
                c.instructions,
                limits.get(case).map(|l| l.instructions),
            ),
            (
                "ll_misses",
                c.ll_misses,
                limits.get(case).map(|l| l.ll_misses),
            ),
        ] {
            let key = format!("{}.{case}.{what}", o.profile);
            match (o.no_check, limit) {
                (false, Some(limit)) => {
                    let (pass, line) = check(&key, measured, limit);
                    ok &= pass;
                    println!("{line}");
                }
                (false, None) => {
                    ok = false;
                    println!("   {key:<32} {measured:>10.1} (no budget: add it)");
                }
                (true, _) => println!("   {key:<32} {measured:>10.1}"),
            }
        }
    }
    // The outputs against the engine: measured on the dev build (what CI checks).
    if o.profile == "dev" {
        ok &= crate::bench_outputs::run(&exe, &budgets.outputs, o.no_check)?;
    }
    Ok(ok)
}

/// One case under callgrind: the counted part's totals over the agent-steps it printed.
fn measure(exe: &Path, file: &Path, case: &Case) -> Result<Counts, String> {
    let ll = format!("--LL={},16,64", case.ll_bytes);
    let mut cmd = Command::new("valgrind");
    cmd.args([
        "--tool=callgrind",
        "--cache-sim=yes",
        "--collect-atstart=no",
    ])
    .arg("--toggle-collect=*counted*")
    .args(CACHE)
    .arg(&ll)
    .arg(format!("--callgrind-out-file={}", file.display()))
    .arg(exe)
    .args(case.args)
    .current_dir(workspace_root());
    let shown = format!(
        "valgrind --tool=callgrind --cache-sim=yes --collect-atstart=no \
         --toggle-collect=*counted* {} {ll} {} {}",
        CACHE.join(" "),
        exe.display(),
        case.args.join(" ")
    );
    println!("$ {shown}");
    let output = cmd
        .output()
        .map_err(|e| format!("cannot run valgrind ({e}): install it (Debian: valgrind)"))?;
    if !output.status.success() {
        return Err(format!(
            "`{shown}` failed ({}):\n{}",
            output.status,
            String::from_utf8_lossy(&output.stderr)
        ));
    }
    let stdout = String::from_utf8_lossy(&output.stdout);
    let steps: u64 = stdout
        .lines()
        .find_map(|l| l.strip_prefix("agent-steps "))
        .and_then(|v| v.trim().parse().ok())
        .ok_or(format!("`{shown}` printed no agent-steps"))?;
    let text = std::fs::read_to_string(file).map_err(|e| format!("{}: {e}", file.display()))?;
    let (ir, ll) = parse_callgrind(&text).map_err(|e| format!("{}: {e}", file.display()))?;
    if ir == 0 {
        return Err(format!(
            "{}: nothing counted (was `counted` inlined?)",
            file.display()
        ));
    }
    Ok(Counts {
        instructions: ir as f64 / steps as f64,
        ll_misses: ll as f64 / steps as f64,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn reads_callgrind_totals_by_event_name() {
        let text = "version: 1\nevents: Ir Dr Dw I1mr D1mr D1mw ILmr DLmr DLmw\n\
                    fn=main\n1 2 3\ntotals: 1000 10 20 1 2 3 4 5 6\n";
        assert_eq!(parse_callgrind(text), Ok((1000, 15)));
        assert!(parse_callgrind("events: Ir\ntotals: 5\n")
            .unwrap_err()
            .contains("ILmr"));
        assert!(parse_callgrind("totals: 5\n").is_err());
    }

    #[test]
    fn the_guard_is_five_per_cent_over() {
        assert!(check("a", 105.0, 100.0).0);
        assert!(!check("a", 105.2, 100.0).0);
        assert!(check("a", 90.0, 100.0).1.contains("lower the budget"));
        // Near zero the absolute slack applies.
        assert!(check("a", 0.15, 0.1).0 && !check("a", 0.25, 0.1).0);
        assert!(!check("a", 0.0, 0.1).1.contains("lower"));
    }

    #[test]
    fn the_repository_budget_file_parses_and_unknown_cases_are_refused() {
        let path = workspace_root().join("host-sim/bench-counts.toml");
        let b = Budgets::parse(&std::fs::read_to_string(&path).unwrap(), "f").unwrap();
        for case in CASES.iter().filter(|c| c.ci) {
            assert!(b.dev.contains_key(case.name), "{}", case.name);
        }
        let e = Budgets::parse("[dev.strip_10]\ninstructions = 1\nll_misses = 1\n", "f");
        assert!(e.unwrap_err().contains("[dev.strip_10]"));
        for case in &crate::bench_outputs::OUTPUTS {
            assert!(b.outputs.contains_key(case.name), "outputs.{}", case.name);
        }
        let e = Budgets::parse("[outputs.x]\nmax_writer_over_engine = 1\n", "f");
        assert!(e.unwrap_err().contains("[outputs.x]"));
        let e = Budgets::parse("[dev.paper]\ninstructions = 1\n", "f").unwrap_err();
        assert!(e.contains("ll_misses"), "{e}");
    }
}
