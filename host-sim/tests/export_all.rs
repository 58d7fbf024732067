//! `host-sim export --all` and `--vehicle`: every agent's blob and the C table the
//! Crazyflie app loads its own from (docs/crazyflie.md).
//!
//! * `--all paper -o DIR` writes 4 blobs, each decoding to the scenario's agent, and
//!   `ph_blobs.c` + `ph_blobs.h`, which compile and index the blobs by wire id;
//! * `crazyflie-app/src/blobs` is the export of `crazyflie-app/formation.toml`
//!   (re-export when this fails: the command is in the message);
//! * `--vehicle crazyflie` refuses the simulator's force limits and a `v*` faster than
//!   a Crazyflie flies, naming the figure and its source.

use ph_formation_ffi::blob::decode_blob;
use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("..")
}

fn ph_formation_sim(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_host-sim"))
        .current_dir(root())
        .args(args)
        .output()
        .expect("run host-sim")
}

fn scratch(name: &str) -> PathBuf {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join(name);
    let _ = std::fs::remove_dir_all(&dir);
    dir
}

#[test]
fn all_writes_every_blob_and_one_c_table() {
    let dir = scratch("export-all-paper");
    let out = ph_formation_sim(&[
        "export",
        "--all",
        "paper",
        "-o",
        dir.to_str().expect("UTF-8"),
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let mut names: Vec<String> = std::fs::read_dir(&dir)
        .expect("output directory")
        .map(|e| e.expect("entry").file_name().to_string_lossy().into_owned())
        .collect();
    names.sort();
    assert_eq!(
        names,
        [
            "agent1.blob",
            "agent2.blob",
            "agent3.blob",
            "agent4.blob",
            "ph_blobs.c",
            "ph_blobs.h"
        ]
    );
    let model = ph_formation_sim::load("paper", &[]).expect("paper");
    let table = std::fs::read_to_string(dir.join("ph_blobs.c")).expect("ph_blobs.c");
    for (i, agent) in model.agents.iter().enumerate() {
        let blob = std::fs::read(dir.join(format!("agent{}.blob", agent.name))).expect("blob");
        let config = decode_blob(&blob).expect("decodes");
        assert_eq!(config, model.agent_config_f32(i).expect("f32 config"));
        // The C table holds the same bytes under the wire id.
        let first = format!(
            "static const uint8_t blob_{}[{}] = {{\n    0x{:02x},",
            agent.id,
            blob.len(),
            blob[0]
        );
        assert!(table.contains(&first), "{first:?} not in\n{table}");
        assert!(table.contains(&format!("    {},\n", blob.len())), "{table}");
    }
    assert!(
        table.contains("const uint8_t *const ph_blobs[5] = {\n    NULL,\n    blob_1,"),
        "{table}"
    );
    assert!(table.contains("const size_t ph_blob_count = 5;"), "{table}");
    // The C compiles (warnings as errors) against its header.
    let cc = std::env::var("CC").unwrap_or_else(|_| "cc".into());
    let run = Command::new(&cc)
        .args([
            "-std=c11",
            "-Wall",
            "-Wextra",
            "-Werror",
            "-Wmissing-prototypes",
            "-fsyntax-only",
        ])
        .arg(format!("-I{}", dir.display()))
        .arg(dir.join("ph_blobs.c"))
        .output()
        .expect("run cc");
    assert!(
        run.status.success(),
        "{}",
        String::from_utf8_lossy(&run.stderr)
    );
}

#[test]
fn the_apps_blobs_are_the_export_of_its_formation() {
    let dir = scratch("export-all-crazyflie");
    let scenario = "crazyflie-app/formation.toml";
    let d = dir.to_str().expect("UTF-8");
    let out = ph_formation_sim(&[
        "export",
        "--all",
        scenario,
        "--vehicle",
        "crazyflie",
        "-o",
        d,
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let checked_in = root().join("crazyflie-app/src/blobs");
    for name in [
        "agent1.blob",
        "agent2.blob",
        "agent3.blob",
        "agent4.blob",
        "ph_blobs.c",
        "ph_blobs.h",
    ] {
        assert_eq!(
            std::fs::read(dir.join(name)).expect("exported"),
            std::fs::read(checked_in.join(name)).expect("checked in"),
            "crazyflie-app/src/blobs/{name} is stale: run `host-sim export --all {scenario} \
             --vehicle crazyflie -o crazyflie-app/src/blobs` from the repository root"
        );
    }
}

fn refused(args: &[&str]) -> String {
    let out = ph_formation_sim(args);
    assert_eq!(
        out.status.code(),
        Some(2),
        "{args:?} should be a usage error"
    );
    String::from_utf8_lossy(&out.stderr).into_owned()
}

#[test]
fn the_crazyflie_refuses_what_it_cannot_fly() {
    let dir = scratch("export-vehicle");
    let d = dir.to_str().expect("UTF-8");
    // The simulator's force limit on a 1 kg virtual mass.
    let e = refused(&[
        "export",
        "--all",
        "paper",
        "--vehicle",
        "crazyflie",
        "--set",
        "controller.max_force=1000",
        "-o",
        d,
    ]);
    assert!(e.contains("controller.max_force = 1000 N"), "{e}");
    assert!(
        e.contains("3.57 m/s²") && e.contains("platform_defaults_cf2.h"),
        "{e}"
    );
    assert!(!dir.exists(), "nothing is written when refused");
    // The force fits, the paper's v* = (3, 3) does not.
    let e = refused(&[
        "export",
        "--agent",
        "1",
        "paper",
        "--vehicle",
        "crazyflie",
        "--set",
        "controller.max_force=3",
    ]);
    assert!(
        e.contains("4.243 m/s") && e.contains("FORMATION_MAX_SPEED"),
        "{e}"
    );
    // Within the limits: exported.
    std::fs::create_dir_all(&dir).expect("scratch directory");
    let blob = dir.join("a.blob");
    let out = ph_formation_sim(&[
        "export",
        "--agent",
        "1",
        "paper",
        "--vehicle",
        "crazyflie",
        "--set",
        "controller.max_force=3",
        "--set",
        "velocity_reference=[0.5,0.5]",
        "-o",
        blob.to_str().expect("UTF-8"),
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(decode_blob(&std::fs::read(&blob).expect("blob")).is_ok());
}
