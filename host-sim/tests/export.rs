//! `host-sim export`: one agent's configuration as the C API's checked blob.
//!
//! * the blob of every agent of the paper scenario decodes (controller-ffi's decoder) to
//!   exactly the scenario's configuration of that agent rounded to `f32`;
//! * a blob with one byte changed is refused (CRC-32);
//! * the C host demo of controller-ffi, configured only by the four exported blobs,
//!   converges on the paper's square (the "designed on the laptop, flashed without
//!   retyping numbers" path);
//! * an unknown agent id is a usage error naming the agent and the scenario's ids.

// The C tests' helpers (building the C programs, reading their DEMO lines): one
// implementation, shared with controller-ffi's own tests.
#[path = "../../controller-ffi/tests/common/mod.rs"]
mod common;

use common::{build, max_difference, parse_demo_final, scratch, SQUARE, TOLERANCE};
use ph_formation_ffi::blob::{decode_blob, BlobError};
use std::path::PathBuf;
use std::process::Command;

fn ph_formation_sim(args: &[&str]) -> std::process::Output {
    Command::new(env!("CARGO_BIN_EXE_host-sim"))
        .args(args)
        .output()
        .expect("run host-sim")
}

/// Exports agent `id` of the paper scenario into `dir`; returns the file.
fn export(dir: &std::path::Path, id: &str) -> PathBuf {
    let path = dir.join(format!("agent{id}.blob"));
    let out = ph_formation_sim(&[
        "export",
        "--agent",
        id,
        "paper",
        "-o",
        path.to_str().expect("UTF-8 path"),
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    path
}

#[test]
fn blobs_decode_to_the_scenarios_configuration() {
    let dir = scratch("export-decode");
    let model = ph_formation_sim::load("paper", &[]).expect("paper");
    for (i, a) in model.agents.iter().enumerate() {
        let blob = std::fs::read(export(&dir, &a.id.to_string())).expect("blob");
        let decoded = decode_blob(&blob).expect("decodes");
        let expected = model.agent_config_f32::<8>(i).expect("config");
        assert_eq!(decoded, expected, "agent {}", a.id);
        // One changed byte anywhere: refused.
        for k in [0, 4, 9, blob.len() / 2, blob.len() - 1] {
            let mut bad = blob.clone();
            bad[k] ^= 0x10;
            assert!(decode_blob(&bad).is_err(), "byte {k} of agent {}", a.id);
        }
        let mut bad = blob.clone();
        bad[blob.len() / 2] ^= 1;
        assert_eq!(decode_blob(&bad), Err(BlobError::Checksum));
    }
}

#[test]
fn the_c_demo_configured_by_exported_blobs_converges() {
    let dir = scratch("export-c-demo");
    let files: Vec<String> = ["1", "2", "3", "4"]
        .iter()
        .map(|id| export(&dir, id).to_str().expect("UTF-8").to_string())
        .collect();
    let program = build("host", &dir);
    let out = Command::new(program)
        .arg("--blob")
        .args(&files)
        .output()
        .expect("run the C demo");
    let log = format!(
        "{}{}",
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(out.status.success(), "exit {}:\n{log}", out.status);
    assert!(log.contains("DEMO result converged=true"), "{log}");
    let (t, rel) = parse_demo_final(&log).unwrap_or_else(|e| panic!("{e}\n{log}"));
    let d = max_difference(&rel, &SQUARE).unwrap_or_else(|e| panic!("{e}"));
    println!("C demo from exported blobs: t = {t} s, {d:.2e} m from the square");
    assert!(d <= TOLERANCE, "{rel:?}\n{log}");
}

#[test]
fn an_unknown_agent_is_a_usage_error() {
    let out = ph_formation_sim(&["export", "--agent", "9", "paper"]);
    assert_eq!(out.status.code(), Some(2));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("--agent 9") && err.contains("1, 2, 3, 4"),
        "{err}"
    );
    assert!(out.stdout.is_empty());
}

#[test]
fn c_source_output_holds_the_same_bytes() {
    let dir = scratch("export-c-source");
    let raw = std::fs::read(export(&dir, "3")).expect("blob");
    let out = ph_formation_sim(&["-q", "export", "--agent", "3", "--c-array", "paper"]);
    assert!(out.status.success());
    let c = String::from_utf8_lossy(&out.stdout);
    assert!(
        c.contains(&format!("const uint8_t ph_blob[{}]", raw.len())),
        "{c}"
    );
    let bytes: Vec<u8> = c
        .split(|ch: char| ch == ',' || ch.is_whitespace() || ch == '{' || ch == '}')
        .filter_map(|w| w.strip_prefix("0x"))
        .map(|h| u8::from_str_radix(h, 16).expect("hex"))
        .collect();
    assert_eq!(bytes, raw);
}
