//! The plot module on a real (short) run and on broken inputs.

use host_sim::report::{plot_run, PlotError};
use std::path::Path;

fn run_formation_only(dir: &Path) {
    let o = std::process::Command::new(env!("CARGO_BIN_EXE_host-sim"))
        .args([
            "run",
            "formation-only",
            "--quiet",
            "--no-plots",
            "--duration",
            "5",
            "--out",
        ])
        .arg(dir)
        .output()
        .expect("host-sim runs");
    assert!(
        dir.join("timeseries.csv").exists(),
        "{}",
        String::from_utf8_lossy(&o.stderr)
    );
}

#[test]
fn every_figure_is_written_as_png_and_svg_with_its_title() {
    let dir = tempfile::tempdir().expect("tempdir");
    run_formation_only(dir.path());
    let files = plot_run(dir.path()).expect("plots");
    for name in [
        "trajectories",
        "angle_errors",
        "energy",
        "estimates",
        "maneuvers",
    ] {
        let png = std::fs::read(dir.path().join(format!("{name}.png"))).expect("png");
        assert!(
            png.starts_with(b"\x89PNG\r\n\x1a\n") && png.len() > 10_000,
            "{name}.png"
        );
        let svg = std::fs::read_to_string(dir.path().join(format!("{name}.svg"))).expect("svg");
        assert!(
            svg.contains("<svg") && svg.contains("formation-only"),
            "{name}.svg lacks its title"
        );
    }
    assert_eq!(files.len(), 10);
}

#[test]
fn a_missing_column_or_an_empty_csv_is_a_named_error() {
    let dir = tempfile::tempdir().expect("tempdir");
    run_formation_only(dir.path());
    let csv = dir.path().join("timeseries.csv");
    let text = std::fs::read_to_string(&csv).expect("csv");
    let (header, rest) = text.split_once('\n').expect("header");
    let without_v: Vec<&str> = header
        .split(',')
        .map(|c| if c == "V" { "W" } else { c })
        .collect();
    std::fs::write(&csv, format!("{}\n{rest}", without_v.join(","))).expect("write");
    match plot_run(dir.path()) {
        Err(e @ PlotError::MissingColumn { .. }) => assert!(e.to_string().contains("`V`"), "{e}"),
        other => panic!("expected a missing-column error, got {other:?}"),
    }
    std::fs::write(&csv, "").expect("write");
    let e = plot_run(dir.path()).expect_err("empty CSV");
    assert!(e.to_string().contains("timeseries.csv"), "{e}");
}
