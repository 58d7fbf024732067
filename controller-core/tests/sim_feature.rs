//! The simulator's entry points (feature `sim`: `Agent::sense`, `evaluate`, `output`,
//! `set_estimate`, …) are not built into the flight code: cargo's own resolution of the
//! firmware's and the C API's builds leaves the feature off (docs/core.md, "Feature
//! `sim`"). `cargo tree` resolves features exactly as `cargo build` does, without
//! building; the flight builds are resolved for their target (`thumbv7em-none-eabihf`),
//! so a dependency that only the microcontroller build has is seen too.

use std::path::Path;
use std::process::Command;

/// The microcontroller target of the firmware and the C API's staticlib.
const FLIGHT: &str = "thumbv7em-none-eabihf";

/// The features of `ph-formation-core` in the normal (not dev) dependency graph of
/// `cargo tree` run with `args`, or the error.
fn core_features(args: &[&str]) -> Vec<String> {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
    let cargo = std::env::var("CARGO").unwrap_or_else(|_| "cargo".to_owned());
    let out = Command::new(cargo)
        .current_dir(&root)
        .args(["tree", "-e", "normal,build"])
        .args(["--prefix", "none", "-f", "{p}|{f}"])
        .args(args)
        .output()
        .expect("cargo runs");
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(
        out.status.success(),
        "cargo tree {args:?} failed: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    features_of(&text, "ph-formation-core")
}

/// The features `cargo tree -f "{p}|{f}"` lists for `package` (empty if it is absent).
fn features_of(tree: &str, package: &str) -> Vec<String> {
    let mut found: Vec<String> = tree
        .lines()
        .filter(|l| l.split_whitespace().next() == Some(package))
        .filter_map(|l| l.split_once('|'))
        .flat_map(|(_, f)| f.trim_end_matches(" (*)").split(','))
        .filter(|f| !f.is_empty())
        .map(str::to_owned)
        .collect();
    found.sort();
    found.dedup();
    found
}

/// Every flight build: the firmware as `cargo xtask firmware-check` and the QEMU demo
/// build it (default features), as a real board builds it (`rtt`), and the C API's
/// staticlib (`controller-ffi/c/build.sh`, `crazyflie-app/Kbuild`).
#[test]
fn no_flight_build_enables_the_simulator_entry_points() {
    let builds: [&[&str]; 3] = [
        &["--target", FLIGHT, "-p", "firmware-example"],
        &[
            "--target",
            FLIGHT,
            "-p",
            "firmware-example",
            "--no-default-features",
            "--features",
            "rtt",
        ],
        &["--target", FLIGHT, "-p", "ph-formation-ffi"],
    ];
    for args in builds {
        let features = core_features(args);
        assert!(
            !features.iter().any(|f| f == "sim"),
            "{args:?} builds ph-formation-core with `sim`: {features:?}"
        );
    }
}

/// Negative control: the same check sees the feature where it is on (the simulator), so
/// the test above cannot pass by reading nothing.
#[test]
fn the_check_sees_the_feature_where_it_is_enabled() {
    let features = core_features(&["-p", "ph-formation-sim"]);
    assert!(features.iter().any(|f| f == "sim"), "{features:?}");
    assert_eq!(
        features_of(
            "ph-formation-core v0.1.0 (/x)|defmt,sim (*)\nother v1|sim\n",
            "ph-formation-core"
        ),
        ["defmt", "sim"]
    );
}
