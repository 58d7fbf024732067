//! The `qemu-demo` firmware (the paper scenario simulated inside the firmware
//! in `f32`, four agents exchanging real frames) against the host simulator's
//! `f64` run of the same scenario.
//!
//! * `demo_converges_to_the_square`: the firmware exits 0 (converged, see
//!   `firmware-example/src/bin/qemu-demo.rs` for its thresholds) and its final
//!   relative positions `q_i − q_1` are the paper's square, `(0, 0)`,
//!   `(−10, 10)`, `(10, 10)`, `(0, 20)`, within [`TOLERANCE`].
//! * `demo_matches_host_sim`: the same relative positions agree with those of
//!   `cargo run --release -p ph-formation-sim -- run paper --out <tmp> --quiet
//!   --no-plots` (its `summary.json`, `final_positions`) within [`TOLERANCE`].
//!
//! Tolerance: 1e-2 m on a square of side 14 m. The demo stops as soon as all
//! its angle errors are below 1e-4 rad and its leader error below 1e-3 m
//! (about t = 68 s), so its shape is within about 2e-3 m of the target; the
//! host simulator runs 100 s and is closer still.
//!
//! Both are ignored by default: they need `qemu-system-arm`, `defmt-print` and
//! the release firmware (`cargo build -p firmware-example --target
//! thumbv7em-none-eabihf --release --bin qemu-demo`); `cargo xtask
//! firmware-check` runs them with `--include-ignored` (the one `qemu-demo` run
//! of a test run, shared by both tests). The parsers and the comparison are
//! checked by the plain tests at the end.
//!
//! Environment: `PH_QEMU_DEMO_ELF` (the firmware ELF), `QEMU_TIMEOUT` (time
//! limit of the QEMU run in seconds, default here 120), `PH_QEMU_DEMO_LOG`
//! (write the demo's decoded defmt log there; `cargo xtask firmware-check`
//! reads its `DEMO` and stack lines), `PH_HOST_SIM_SUMMARY` (use this
//! `summary.json` instead of running the host simulator), `QEMU_SYSTEM_ARM`,
//! `DEFMT_PRINT`.

use std::path::PathBuf;
use std::process::Command;
use std::sync::OnceLock;
use std::time::Duration;

use qemu_harness::{defmt, firmware, Exit, Qemu};

// The `DEMO` line's parser, the paper's square and the tolerance: one implementation,
// shared with the C demos' tests of controller-ffi.
#[path = "../../controller-ffi/tests/common/mod.rs"]
mod common;

use common::{max_difference, parse_demo_final, SQUARE, TOLERANCE};

/// Extracts `final_positions: [[x, y], …]` from a `summary.json`.
fn parse_final_positions(json: &str) -> Result<Vec<[f64; 2]>, String> {
    #[derive(serde::Deserialize)]
    struct Summary {
        final_positions: Vec<[f64; 2]>,
    }
    serde_json::from_str::<Summary>(json)
        .map(|s| s.final_positions)
        .map_err(|e| format!("summary.json: {e}"))
}

/// `q_i − q_1` of absolute positions.
fn relative(positions: &[[f64; 2]]) -> Vec<[f64; 2]> {
    let p0 = positions.first().copied().unwrap_or([0.0; 2]);
    positions
        .iter()
        .map(|p| [p[0] - p0[0], p[1] - p0[1]])
        .collect()
}

struct DemoRun {
    exit: Exit,
    log: String,
}

/// Runs the demo under QEMU once per test binary (shared by the tests).
fn demo() -> &'static DemoRun {
    static RUN: OnceLock<DemoRun> = OnceLock::new();
    RUN.get_or_init(|| {
        let elf = firmware::elf_or_env("qemu-demo", "PH_QEMU_DEMO_ELF");
        let elf = firmware::require_elf(&elf, "qemu-demo").unwrap_or_else(|e| panic!("{e}"));
        let limit = match std::env::var("QEMU_TIMEOUT") {
            Ok(v) => v.trim().parse().expect("QEMU_TIMEOUT: whole seconds"),
            Err(_) => 120,
        };
        let qemu = Qemu::new(&elf, firmware::target_dir().join("qemu-tests/qemu-demo"));
        let exit = qemu
            .run(Duration::from_secs(limit))
            .unwrap_or_else(|e| panic!("{e}: {}", qemu.display()));
        let mut log = defmt::decode_or_note(&elf, qemu.stdout_path());
        if let Some(path) = std::env::var_os("PH_QEMU_DEMO_LOG") {
            std::fs::write(&path, &log).expect("write PH_QEMU_DEMO_LOG");
        }
        if exit != Exit::Code(0) {
            log.push_str(&format!("qemu-demo: {exit} (limit {limit} s)\n"));
            log.push_str(&std::fs::read_to_string(qemu.stderr_path()).unwrap_or_default());
        }
        DemoRun { exit, log }
    })
}

/// The host simulator's final positions of the `paper` scenario.
fn host_sim_final_positions() -> Vec<[f64; 2]> {
    let summary = match std::env::var_os("PH_HOST_SIM_SUMMARY") {
        Some(p) => PathBuf::from(p),
        None => {
            let dir =
                std::env::temp_dir().join(format!("ph-qemu-demo-host-sim-{}", std::process::id()));
            let _ = std::fs::remove_dir_all(&dir);
            std::fs::create_dir_all(&dir).expect("temporary directory");
            let cargo = std::env::var("CARGO").unwrap_or_else(|_| "cargo".into());
            let out = Command::new(cargo)
                .current_dir(firmware::workspace_root())
                .args([
                    "run",
                    "--release",
                    "-p",
                    "ph-formation-sim",
                    "--",
                    "run",
                    "paper",
                    "--out",
                ])
                .arg(&dir)
                // The plots take most of the run time (about 50 s of 50 s).
                .args(["--quiet", "--no-plots"])
                .output()
                .expect("run cargo");
            assert!(
                out.status.success(),
                "host-sim run paper failed ({}):\n{}{}",
                out.status,
                String::from_utf8_lossy(&out.stdout),
                String::from_utf8_lossy(&out.stderr)
            );
            dir.join("summary.json")
        }
    };
    let json = std::fs::read_to_string(&summary)
        .unwrap_or_else(|e| panic!("cannot read {}: {e}", summary.display()));
    parse_final_positions(&json).unwrap_or_else(|e| panic!("{}: {e}", summary.display()))
}

#[test]
#[ignore = "needs qemu-system-arm and the firmware ELF; run by cargo xtask firmware-check"]
fn demo_converges_to_the_square() {
    let run = demo();
    assert_eq!(
        run.exit,
        Exit::Code(0),
        "qemu-demo did not exit 0 (not converged?):\n{}",
        run.log
    );
    let (t, rel) = parse_demo_final(&run.log).unwrap_or_else(|e| panic!("{e}\n{}", run.log));
    let d = max_difference(&rel, &SQUARE).expect("four agents");
    println!("qemu-demo: converged at t = {t} s, q_i - q_1 = {rel:?}, max |difference to the square| = {d:.2e} m");
    assert!(
        d <= TOLERANCE,
        "final shape {rel:?} is {d} m from the square {SQUARE:?}"
    );
}

#[test]
#[ignore = "needs qemu-system-arm and the firmware ELF; run by cargo xtask firmware-check"]
fn demo_matches_host_sim() {
    let run = demo();
    assert_eq!(
        run.exit,
        Exit::Code(0),
        "qemu-demo did not exit 0:\n{}",
        run.log
    );
    let (_, firmware) = parse_demo_final(&run.log).unwrap_or_else(|e| panic!("{e}\n{}", run.log));
    let host = relative(&host_sim_final_positions());
    let d = max_difference(&firmware, &host).unwrap_or_else(|e| panic!("{e}"));
    println!("qemu-demo (f32) vs host-sim (f64): q_i - q_1 firmware {firmware:?}, host {host:?}, max difference {d:.2e} m");
    assert!(
        d <= TOLERANCE,
        "firmware {firmware:?} and host-sim {host:?} differ by {d} m > {TOLERANCE} m"
    );
}

// ------------------------------------------------------------------ plain tests

const DEMO_OUTPUT: &str = "INFO  t=5.0 s: angle error 0.07 rad\n\
DEMO final t=67.87 rel=0.0,0.0;-9.999017,9.999824;9.999203,9.998219;0.00097146025,19.998024\n\
DEMO result converged=true t=67.87\n";

const SUMMARY: &str = r#"{
  "scenario": "paper",
  "converged": true,
  "final_positions": [ [300.9, 302.2], [290.90000001, 312.2],
    [310.9, 312.2] ,[300.9,322.2] ],
  "final_velocities": [[3.0, 3.0], [3.0, 3.0], [3.0, 3.0], [3.0, 3.0]]
}"#;

#[test]
fn parses_the_demo_line() {
    let (t, rel) = parse_demo_final(DEMO_OUTPUT).expect("parse");
    assert_eq!(t, 67.87);
    assert_eq!(rel.len(), 4);
    assert_eq!(rel[1], [-9.999017, 9.999824]);
    assert!(parse_demo_final("no such line").is_err());
    assert!(parse_demo_final("DEMO final t=1 rel=1,2;3").is_err());
}

#[test]
fn parses_final_positions_of_a_summary() {
    let p = parse_final_positions(SUMMARY).expect("parse");
    assert_eq!(p.len(), 4);
    assert_eq!(p[1], [290.90000001, 312.2]);
    assert!(parse_final_positions("{\"final_positions\": [[1, 2, 3]]}").is_err());
    assert!(parse_final_positions("{}").is_err());
    assert!(parse_final_positions("{\"final_positions\":[]}")
        .expect("empty")
        .is_empty());
}

#[test]
fn compares_relative_positions() {
    let (_, firmware) = parse_demo_final(DEMO_OUTPUT).expect("parse");
    let host = relative(&parse_final_positions(SUMMARY).expect("parse"));
    assert!((host[3][1] - 20.0).abs() < 1e-9);
    let d = max_difference(&firmware, &host).expect("same length");
    assert!(d > 1e-3 && d < TOLERANCE, "{d}");
    assert!(max_difference(&firmware, &SQUARE).expect("same length") < TOLERANCE);
    // A mirrored square is far off.
    let mirrored: Vec<[f64; 2]> = SQUARE.iter().map(|p| [-p[0], p[1]]).collect();
    assert!(max_difference(&firmware, &mirrored).expect("same length") > 10.0);
    assert!(max_difference(&firmware, &host[..3]).is_err());
}
