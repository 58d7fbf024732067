//! `cargo xtask bench-counts`, the outputs' part: what writing a run's outputs costs
//! against simulating it, in instructions counted by callgrind (dev build, like the other
//! cases; docs/performance.md, "What the outputs cost").
//!
//! A whole 100 s run of 100 agents is ~10 G instructions, minutes under callgrind, so
//! each case is measured in parts and composed for the whole run:
//!
//! 1. `counts write SCENARIO FULL DIR` (not under valgrind): the whole run's
//!    `timeseries.csv` and `summary.json` into `DIR`, with the default size budget; it
//!    prints the stride the budget chose;
//! 2. `counts engine SCENARIO SHORT` under callgrind: a short run through the library
//!    writing nothing — the engine (ticks, diagnostics, monitor, verdict) per agent-step;
//! 3. `counts rows SCENARIO SHORT STRIDE`: the same run writing its rows at the whole
//!    run's stride and its summary, and keeping every row in memory (at least what a run
//!    keeps for its figures): minus (2), the row writers per agent-step;
//! 4. `counts draw DIR`: the figures (PNG and SVG) and `replay.html` of the whole run,
//!    drawn from its rows in memory as the run draws them (read back from `DIR`'s CSV
//!    first, not counted).
//!
//! engine = (2) per agent-step × the whole run's agent-steps; writers = (3) − (2) per
//! agent-step × agent-steps + (4). The check: writers ≤ `max_writer_over_engine` ×
//! engine (`host-sim/bench-counts.toml`, `[outputs.<case>]`).

use qemu_harness::firmware::{target_dir, workspace_root};
use serde::Deserialize;
use std::path::{Path, PathBuf};
use std::process::Command;

/// One outputs case.
#[derive(Clone, Copy, Debug)]
pub struct OutputsCase {
    /// Its name in `[outputs.<name>]`.
    pub name: &'static str,
    /// `host-sim` arguments that write the scenario file first (`None`: a built-in).
    pub design: Option<&'static [&'static str]>,
    /// The scenario (a built-in name, or the file `design` writes, under the output dir).
    pub scenario: &'static str,
    /// The whole run's duration (s).
    pub full: &'static str,
    /// The short run's duration (s): the per-agent-step figures.
    pub short: &'static str,
}

/// The measured cases: the 100-agent, 100 s run (a designed triangular lattice)
/// and `paper` with its default outputs.
pub const OUTPUTS: [OutputsCase; 2] = [
    OutputsCase {
        name: "lattice100",
        design: Some(&[
            "design",
            "--shape",
            "tri-lattice",
            "-n",
            "100",
            "--duration",
            "100",
            "-q",
            "-o",
        ]),
        scenario: "lattice100.toml",
        full: "100",
        short: "2",
    },
    OutputsCase {
        name: "paper",
        design: None,
        scenario: "paper",
        full: "100",
        short: "2",
    },
];

/// `[outputs.<case>]` of the budget file.
#[derive(Clone, Copy, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct OutputLimits {
    /// The writers may cost at most this many times the engine (1: less than simulating).
    pub max_writer_over_engine: f64,
}

/// Whether the writers' count passes `max` times the engine's; the line says by how much.
pub fn check_writer(name: &str, writer: f64, engine: f64, max: f64) -> (bool, String) {
    let ratio = writer / engine;
    let ok = engine > 0.0 && writer.is_finite() && ratio <= max;
    (
        ok,
        format!(
            "   outputs.{name:<24} writers {:>8.1} M / engine {:>8.1} M = {ratio:.2} (at most {max}) {}",
            writer / 1e6,
            engine / 1e6,
            if ok { "ok" } else { "REGRESSION" }
        ),
    )
}

/// Runs `counts ARGS` (under callgrind when `counted`); returns the counted instructions
/// (0 when not counted) and what it printed.
fn counts(exe: &Path, out: &Path, args: &[&str], counted: bool) -> Result<(u64, String), String> {
    let file = out.join("outputs.callgrind.out");
    let mut cmd = if counted {
        let mut c = Command::new("valgrind");
        c.args([
            "--tool=callgrind",
            "--collect-atstart=no",
            "--toggle-collect=*counted*",
        ])
        .arg(format!("--callgrind-out-file={}", file.display()))
        .arg(exe);
        c
    } else {
        Command::new(exe)
    };
    cmd.args(args).current_dir(workspace_root());
    let shown = format!(
        "{}{} {}",
        if counted {
            "valgrind --tool=callgrind --collect-atstart=no --toggle-collect=*counted* "
        } else {
            ""
        },
        exe.display(),
        args.join(" ")
    );
    println!("$ {shown}");
    let output = cmd
        .output()
        .map_err(|e| format!("cannot run `{shown}`: {e}"))?;
    if !output.status.success() {
        return Err(format!(
            "`{shown}` failed ({}):\n{}",
            output.status,
            String::from_utf8_lossy(&output.stderr)
        ));
    }
    let stdout = String::from_utf8_lossy(&output.stdout).into_owned();
    if !counted {
        return Ok((0, stdout));
    }
    let text = std::fs::read_to_string(&file).map_err(|e| format!("{}: {e}", file.display()))?;
    let _ = std::fs::remove_file(&file);
    let (ir, _) = parse_ir(&text).map_err(|e| format!("{}: {e}", file.display()))?;
    Ok((ir, stdout))
}

/// The `Ir` total of a callgrind file without cache simulation.
fn parse_ir(text: &str) -> Result<(u64, ()), String> {
    let line = |key: &str| text.lines().find_map(|l| l.strip_prefix(key));
    let events: Vec<&str> = line("events:")
        .ok_or("no `events:` line")?
        .split_whitespace()
        .collect();
    let totals: Vec<&str> = line("totals:")
        .or_else(|| line("summary:"))
        .ok_or("no `totals:` line")?
        .split_whitespace()
        .collect();
    let i = events
        .iter()
        .position(|e| *e == "Ir")
        .ok_or("no Ir event")?;
    let ir = totals
        .get(i)
        .and_then(|v| v.parse().ok())
        .ok_or("bad Ir total")?;
    Ok((ir, ()))
}

fn value(stdout: &str, key: &str) -> Result<f64, String> {
    stdout
        .lines()
        .find_map(|l| l.strip_prefix(key))
        .and_then(|v| v.trim().parse().ok())
        .ok_or(format!("no `{key}` in the output of counts"))
}

/// Measures one case: (writers, engine) instructions of the whole run.
pub fn measure(exe: &Path, case: &OutputsCase) -> Result<(f64, f64), String> {
    let out = target_dir().join("bench-counts").join(case.name);
    let _ = std::fs::remove_dir_all(&out);
    std::fs::create_dir_all(&out).map_err(|e| format!("{}: {e}", out.display()))?;
    let scenario: PathBuf = match case.design {
        Some(design) => {
            let file = out.join(case.scenario);
            let mut args: Vec<&str> = vec!["cli"];
            args.extend(design);
            let f = file.display().to_string();
            args.push(&f);
            counts(exe, &out, &args, false)?;
            file
        }
        None => PathBuf::from(case.scenario),
    };
    let scenario = scenario.display().to_string();
    let dir = out.join("run");
    let d = dir.display().to_string();
    let (_, printed) = counts(exe, &out, &["write", &scenario, case.full, &d], false)?;
    let stride = value(&printed, "stride ")?;
    let full_steps = value(&printed, "agent-steps ")?;
    let (engine, printed) = counts(exe, &out, &["engine", &scenario, case.short], true)?;
    let short_steps = value(&printed, "agent-steps ")?;
    let s = format!("{stride}");
    let (rows, _) = counts(exe, &out, &["rows", &scenario, case.short, &s], true)?;
    let (draw, _) = counts(exe, &out, &["draw", &d], true)?;
    let per_step = |x: u64| x as f64 / short_steps;
    let engine_full = per_step(engine) * full_steps;
    let writers = per_step(rows.saturating_sub(engine)) * full_steps + draw as f64;
    println!(
        "   outputs.{}: engine {:.0} / agent-step, row writers {:.0} / agent-step (stride {stride}), \
         figures and replay {:.1} M, over {full_steps} agent-steps",
        case.name,
        per_step(engine),
        per_step(rows.saturating_sub(engine)),
        draw as f64 / 1e6
    );
    let _ = std::fs::remove_dir_all(&out);
    Ok((writers, engine_full))
}

/// Every case against its limit; `Ok(true)` when all pass (or `no_check`).
pub fn run(
    exe: &Path,
    limits: &std::collections::BTreeMap<String, OutputLimits>,
    no_check: bool,
) -> Result<bool, String> {
    let mut ok = true;
    println!("outputs against the engine (whole runs, dev build):");
    for case in &OUTPUTS {
        let (writers, engine) = measure(exe, case)?;
        match (no_check, limits.get(case.name)) {
            (false, Some(l)) => {
                let (pass, line) =
                    check_writer(case.name, writers, engine, l.max_writer_over_engine);
                ok &= pass;
                println!("{line}");
            }
            (false, None) => {
                ok = false;
                println!(
                    "   outputs.{} (no budget: add [outputs.{}])",
                    case.name, case.name
                );
            }
            (true, _) => println!("{}", check_writer(case.name, writers, engine, f64::MAX).1),
        }
    }
    Ok(ok)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The check passes writers below the engine and fails them above (negative control).
    #[test]
    fn writers_above_the_engine_fail_the_check() {
        assert!(check_writer("a", 0.4e9, 1.0e9, 1.0).0);
        assert!(check_writer("a", 1.0e9, 1.0e9, 1.0).0);
        let (pass, line) = check_writer("a", 1.2e9, 1.0e9, 1.0);
        assert!(!pass && line.contains("REGRESSION"), "{line}");
        assert!(!check_writer("a", 1.0, 0.0, 1.0).0, "no engine count");
        assert!(!check_writer("a", f64::NAN, 1.0, 1.0).0);
    }

    #[test]
    fn reads_the_ir_total() {
        let text = "events: Ir\nfn=main\n1 2\ntotals: 1234\n";
        assert_eq!(parse_ir(text), Ok((1234, ())));
        assert!(parse_ir("events: Dr\ntotals: 5\n").is_err());
    }
}
