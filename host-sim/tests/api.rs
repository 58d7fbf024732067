//! The library API: runs in memory match runs written to a directory, scenarios load from
//! files, TOML text and built-in names, errors keep their exit codes, and the example in
//! `examples/paper.rs` runs.

use ph_formation_sim::{exit_code, load, load_toml, Error, Outcome, Simulation};

#[path = "../examples/paper.rs"]
mod paper_example;

#[test]
fn the_example_runs_and_converges() {
    paper_example::main().expect("examples/paper.rs");
}

#[test]
fn the_series_in_memory_is_the_csv_that_is_written() {
    let m = load("paper", &["duration=2".to_owned()]).expect("paper");
    let dir = tempfile::tempdir().expect("tempdir");
    let run = Simulation::new(&m)
        .write_to(dir.path(), ph_formation_sim::WriteOptions::without_plots())
        .run()
        .expect("run");
    let series = run.series.as_ref().expect("kept by default");
    let csv = std::fs::read_to_string(dir.path().join("timeseries.csv")).expect("csv");
    let mut lines = csv.lines();
    assert_eq!(lines.next(), Some(series.columns().join(",").as_str()));
    let mut rows = 0;
    for (k, line) in lines.enumerate() {
        let row = series.row(k).expect("row");
        let parsed: Vec<f64> = line
            .split(',')
            .map(|x| x.parse().expect("number"))
            .collect();
        assert_eq!(parsed, row, "row {k}");
        rows += 1;
    }
    assert_eq!(rows, series.len());
    assert_eq!(rows, 201, "2 s logged every 10 ms");
    // The files written, and the summary from memory is the one on disk.
    let names: Vec<_> = run.files.iter().map(|p| p.file_name().unwrap()).collect();
    assert_eq!(names, ["timeseries.csv", "summary.json"]);
    let disk = std::fs::read_to_string(&run.files[1]).expect("summary");
    let memory = serde_json::to_string_pretty(&run.summary_json(&m)).expect("json");
    assert_eq!(disk, memory + "\n");
    // In memory only: nothing written, same result.
    let again = Simulation::new(&m).run().expect("run");
    assert!(again.files.is_empty());
    assert_eq!(again.result.v_final, run.result.v_final);
    assert_eq!(again.series, run.series);
    let t = series.column("t").expect("t");
    assert_eq!((t[0], t[t.len() - 1]), (0.0, 2.0));
    assert!(series.column("no such column").is_none());
}

#[test]
fn scenarios_load_from_text_files_and_names() {
    let text = ph_formation_sim::BUILTINS[2].text;
    let from_text = load_toml(text, "inline", &[]).expect("toml");
    let from_name = load("formation-only", &[]).expect("builtin");
    assert_eq!(from_text.agents, from_name.agents);
    assert_eq!(from_text.source, "inline");
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/scenarios/maneuvers.toml");
    assert_eq!(load(path, &[]).expect("file").name, "maneuvers");

    let e = load_toml("agents = 3", "bad", &[]).expect_err("invalid");
    assert_eq!(Error::from(e.clone()).exit_code(), e.exit_code());
    assert!(e.to_string().contains("bad"), "{e}");
    let e = load("no-such-scenario", &[]).expect_err("unknown");
    assert_eq!(e.exit_code(), 20);
}

#[test]
fn a_failed_run_is_an_outcome_and_an_unwritable_directory_an_error() {
    let m = load("paper-printed", &[]).expect("paper-printed");
    let run = Simulation::new(&m).keep_series(false).run().expect("run");
    assert_eq!(run.outcome(), Outcome::EstimateCollapse);
    assert_eq!(run.exit_code(), exit_code::ESTIMATE_COLLAPSE);
    assert!(run.series.is_none());

    let dir = tempfile::tempdir().expect("tempdir");
    let file = dir.path().join("a-file");
    std::fs::write(&file, "").expect("write");
    let e = Simulation::new(&m)
        .write_to(
            file.join("sub"),
            ph_formation_sim::WriteOptions::without_plots(),
        )
        .run()
        .expect_err("not a directory");
    assert!(matches!(e, Error::Output(_)), "{e:?}");
    assert_eq!(e.exit_code(), exit_code::IO);
    assert!(
        e.to_string().starts_with("cannot create output directory"),
        "{e}"
    );
}
