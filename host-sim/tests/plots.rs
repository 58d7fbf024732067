//! The plot module on a real (short) run and on broken inputs.

use ph_formation_sim::report::{plot_run, PlotError};
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
        "shape",
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
    assert_eq!(files.len(), 12);
    // A run written before `shape` existed (no `shape` in summary.json): the other five.
    let summary = dir.path().join("summary.json");
    let mut v: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&summary).expect("summary")).expect("json");
    v.as_object_mut().expect("object").remove("shape");
    std::fs::write(&summary, v.to_string()).expect("write");
    std::fs::remove_file(dir.path().join("shape.png")).expect("rm");
    let files = plot_run(dir.path()).expect("plots");
    assert_eq!(files.len(), 10);
    assert!(!dir.path().join("shape.png").exists());
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

#[test]
fn two_hundred_agents_get_a_colour_bar_not_a_legend_row_each() {
    use ph_formation_sim::design::{
        construct, render_scenario, DesignOptions, Generator, ScenarioOptions,
    };
    let p = Generator::TriangularLattice {
        n: 200,
        spacing: 1.0,
    }
    .points()
    .expect("points");
    let c = construct(&p, &DesignOptions::default()).expect("construction");
    let so = ScenarioOptions {
        name: "lattice-200".to_owned(),
        duration: Some(1.0),
        ..Default::default()
    };
    let text = render_scenario(&p, &c, &DesignOptions::default(), &so).expect("render");
    let m = ph_formation_sim::load_toml(&text, "lattice", &[]).expect("load");
    let dir = tempfile::tempdir().expect("tempdir");
    let run = ph_formation_sim::Simulation::new(&m)
        .write_to(dir.path(), ph_formation_sim::WriteOptions::default())
        .run()
        .expect("run");
    assert!(run.plot_error.is_none(), "{:?}", run.plot_error);
    let svg = std::fs::read_to_string(dir.path().join("trajectories.svg")).expect("svg");
    assert!(svg.contains("by agent index"), "no colour bar");
    assert!(
        !svg.contains("agent 57<") && !svg.contains(">agent 1<"),
        "a legend row per agent"
    );
    let shape = std::fs::read_to_string(dir.path().join("shape.svg")).expect("shape svg");
    assert!(shape.contains("final formation over its target"));
}
