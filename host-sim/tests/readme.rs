//! The README's figures of the paper run stay true: the number of plots a run writes and
//! "every angle error below 1e-3 rad from t ≈ X s, … |z − z*| ≈ A m and |v − v*| ≈ B m/s"
//! (read from README.md, checked against `host-sim run paper`).

use std::path::Path;

fn readme() -> String {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../README.md");
    std::fs::read_to_string(path).expect("README.md")
}

/// The number written after `before` (up to `after`), e.g. `t ≈ ` … ` s`.
fn figure(text: &str, before: &str, after: &str) -> f64 {
    let flat = text.split_whitespace().collect::<Vec<_>>().join(" ");
    let start = flat
        .find(before)
        .unwrap_or_else(|| panic!("README: no `{before}`"))
        + before.len();
    let rest = &flat[start..];
    rest[..rest.find(after).expect("end")]
        .trim()
        .parse()
        .expect("a number")
}

/// `x` rounds to `shown` at `shown`'s precision (one significant digit for `2e-5`).
fn rounds_to(x: f64, shown: f64, digits: i32) -> bool {
    let scale = 10f64.powi(shown.abs().log10().floor() as i32 - digits + 1);
    ((x / scale).round() * scale - shown).abs() < 1e-9 * shown.abs()
}

#[test]
fn the_readme_figures_of_the_paper_run_are_true() {
    let text = readme();
    let words = [
        "one", "two", "three", "four", "five", "six", "seven", "eight", "nine",
    ];
    let flat = text.split_whitespace().collect::<Vec<_>>().join(" ");
    let plots = words
        .iter()
        .position(|w| flat.contains(&format!("`summary.json`, {w} plots (PNG and SVG)")))
        .map(|k| k + 1)
        .expect("README: `summary.json`, N plots (PNG and SVG)");
    let settle = figure(&text, "every angle error below 1e-3 rad from t ≈", " s");
    let z = figure(&text, "|z − z*| ≈", " m");
    let v = figure(&text, "|v − v*| ≈", " m/s");

    let model = ph_formation_sim::load("paper", &[]).expect("paper");
    let dir = tempfile::tempdir().expect("tempdir");
    let run = ph_formation_sim::Simulation::new(&model)
        .keep_series(false)
        .write_to(dir.path(), ph_formation_sim::WriteOptions::default())
        .run()
        .expect("run");
    let r = &run.result;
    let pngs = run
        .files
        .iter()
        .filter(|f| f.extension().is_some_and(|e| e == "png"))
        .count();
    assert_eq!(pngs, plots, "README says {plots} plots");
    assert!(dir.path().join("replay.html").is_file());
    let got = r.settle_time.expect("settles");
    assert!(
        rounds_to(got, settle, 4),
        "settle time {got} s, README {settle} s"
    );
    let summary = run.summary_json(&model);
    let dz = summary["final_displacement_error"].as_f64().expect("dz");
    let dv = summary["final_velocity_error"].as_f64().expect("dv");
    assert!(rounds_to(dz, z, 1), "|z − z*| {dz}, README {z}");
    assert!(rounds_to(dv, v, 1), "|v − v*| {dv}, README {v}");
}
