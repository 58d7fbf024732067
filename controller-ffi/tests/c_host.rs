//! The C API from C on the host: `c/host/*.c` (built by `c/build.sh host` with the
//! system C compiler against the release staticlib) drives the paper's four agents
//! through `ph_*` with a plant in C, and checks the API's argument and error handling.
//!
//! The formation must converge (the demo's own criteria: angles within 1e-4 rad, leader
//! edge within 1e-3 m, velocities within 1e-3 m/s, no safe output after the first
//! tick, no frame lost or rejected except from non-neighbours) and end on the paper's
//! square 1-2-4-3 with `q1 − q2 = z* = (10, −10)` within [`common::TOLERANCE`]. The
//! square is the reference rather than a host-sim run: host-sim's `paper` run ends
//! within ~1e-5 m of it (README), and `tests/tests/qemu_demo.rs` already compares
//! host-sim with the Rust firmware demo, which this C demo reproduces.
//!
//! Needs a C compiler (`cc`); builds the host staticlib with `cargo build --release`.

mod common;

use std::path::Path;
use std::process::{Command, Output};
use std::sync::OnceLock;

use common::{build, max_difference, parse_demo_final, scratch, SQUARE, TOLERANCE};
use ph_formation_ffi::{config::to_core, encode_blob, ph_config};

fn program() -> &'static Path {
    static BUILT: OnceLock<std::path::PathBuf> = OnceLock::new();
    BUILT.get_or_init(|| build("host", &scratch("c-host")))
}

fn run(args: &[&str]) -> (Output, String) {
    let out = Command::new(program())
        .args(args)
        .output()
        .expect("run the C host program");
    let mut log = String::from_utf8_lossy(&out.stdout).into_owned();
    log.push_str(&String::from_utf8_lossy(&out.stderr));
    (out, log)
}

fn converged_on_the_square(log: &str) -> Vec<[f64; 2]> {
    assert!(
        log.contains("DEMO result converged=true"),
        "not converged:\n{log}"
    );
    let (t, rel) = parse_demo_final(log).unwrap_or_else(|e| panic!("{e}\n{log}"));
    let d = max_difference(&rel, &SQUARE).unwrap_or_else(|e| panic!("{e}\n{log}"));
    println!("C demo: converged at t = {t} s, q_i - q_1 = {rel:?}, {d:.2e} m from the square");
    assert!(
        d <= TOLERANCE,
        "final shape {rel:?} is {d} m from {SQUARE:?}\n{log}"
    );
    rel
}

#[test]
fn c_demo_converges_to_the_square() {
    let (out, log) = run(&[]);
    assert!(out.status.success(), "exit {}:\n{log}", out.status);
    converged_on_the_square(&log);
}

#[test]
fn c_api_checks_pass() {
    let (out, log) = run(&["--checks"]);
    assert!(
        out.status.success() && log.contains("checks: 0 failed"),
        "exit {}:\n{log}",
        out.status
    );
    assert!(!log.contains("FAIL"), "{log}");
}

/// The C configurations → `to_core` → `encode_blob` → files → `ph_agent_init_blob` in
/// C: the same run, bit for bit, as with the C structs.
#[test]
fn blobs_give_the_same_run_as_c_structs() {
    let dir = scratch("c-host-blobs");
    let (out, log) = run(&["--dump-configs", dir.to_str().expect("UTF-8 path")]);
    assert!(out.status.success(), "{log}");
    let mut files = Vec::new();
    for i in 1..=4 {
        let raw = std::fs::read(dir.join(format!("config{i}.bin"))).expect("config dump");
        assert_eq!(
            raw.len(),
            size_of::<ph_config>(),
            "ph_config size in C and Rust"
        );
        // SAFETY: `raw` holds the bytes of a `ph_config` written by C on this machine
        // (same layout: repr(C)); every field is an integer or a float.
        let c: ph_config = unsafe { std::ptr::read_unaligned(raw.as_ptr().cast()) };
        let config = to_core(&c).unwrap_or_else(|e| panic!("agent {i}: {e:?}"));
        let mut blob = [0u8; ph_formation_ffi::blob::PH_MAX_BLOB_LEN];
        let n = encode_blob(&config, &mut blob).expect("encode");
        let path = dir.join(format!("agent{i}.blob"));
        std::fs::write(&path, &blob[..n]).expect("write blob");
        files.push(path.to_str().expect("UTF-8 path").to_string());
    }
    let mut args = vec!["--blob"];
    args.extend(files.iter().map(String::as_str));
    let (out, blob_log) = run(&args);
    assert!(out.status.success(), "exit {}:\n{blob_log}", out.status);
    converged_on_the_square(&blob_log);
    let (_, struct_log) = run(&[]);
    let demo_lines = |l: &str| {
        l.lines()
            .filter(|x| x.starts_with("DEMO"))
            .map(str::to_string)
            .collect::<Vec<_>>()
    };
    assert_eq!(demo_lines(&blob_log), demo_lines(&struct_log));
}

#[test]
fn parses_the_demo_line() {
    let log = "x\nDEMO final t=6.787000e1 rel=0.0,0.0;-9.999016e0,9.999824e0;9.999204e0,9.998220e0;9.714602e-4,1.999802e1\nDEMO result converged=true\n";
    let (t, rel) = parse_demo_final(log).expect("parse");
    assert_eq!(t, 67.87);
    assert_eq!(rel[3], [9.714602e-4, 19.99802]);
    assert!(max_difference(&rel, &SQUARE).expect("four agents") < 3e-3);
    assert!(parse_demo_final("DEMO final t=1 rel=1,2;3").is_err());
    assert!(parse_demo_final("nothing").is_err());
}
