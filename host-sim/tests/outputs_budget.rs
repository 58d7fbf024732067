//! The outputs' size budget (docs/outputs.md, "Size budget"): by default a 100-agent,
//! 100 s run writes under 50 MB (its rows thinned, the stride named in summary.json and a
//! warning, the verdict that of the whole run), `--full-rate` writes every row, and a
//! thinned series keeps its first and last rows and every `stride`-th between.

use ph_formation_sim::{SeriesBudget, Simulation, WriteOptions};
use std::path::Path;
use std::process::{Command, Output};

fn host_sim(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_host-sim"))
        .args(args)
        .output()
        .expect("host-sim runs")
}

fn json(p: &Path) -> serde_json::Value {
    serde_json::from_slice(&std::fs::read(p).expect("read")).expect("json")
}

fn lines(p: &Path) -> Vec<String> {
    std::fs::read_to_string(p)
        .expect("read csv")
        .lines()
        .map(str::to_owned)
        .collect()
}

/// `host-sim design --shape tri-lattice -n 100` into `dir/lat100.toml`.
fn lattice(dir: &Path) -> String {
    let file = dir.join("lat100.toml");
    let file = file.to_str().expect("utf-8 path").to_owned();
    let o = host_sim(&[
        "design",
        "--shape",
        "tri-lattice",
        "-n",
        "100",
        "--duration",
        "100",
        "-q",
        "-o",
        &file,
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    file
}

fn dir_bytes(dir: &Path) -> u64 {
    std::fs::read_dir(dir)
        .expect("dir")
        .map(|e| e.expect("entry").metadata().expect("meta").len())
        .sum()
}

#[test]
fn a_100_agent_100_s_run_writes_under_50_mb_with_the_verdict_of_the_whole_run() {
    let tmp = tempfile::tempdir().expect("temp dir");
    let scenario = lattice(tmp.path());
    let out = tmp.path().join("run");
    let o = host_sim(&[
        "run",
        &scenario,
        "-q",
        "--out",
        out.to_str().expect("utf-8"),
    ]);
    assert_eq!(o.status.code(), Some(0), "converges");
    let stderr = String::from_utf8_lossy(&o.stderr);
    assert!(stderr.contains("keep every 20th logged row"), "{stderr}");
    let total = dir_bytes(&out);
    assert!(total < 50_000_000, "{total} bytes written");
    // The full-rate series would be 10,001 rows × 1,393 columns (274 MB of CSV).
    let summary = json(&out.join("summary.json"));
    assert_eq!(summary["series"]["stride"], 20);
    assert_eq!(summary["series"]["full_rate_rows"], 10_001);
    let csv = lines(&out.join("timeseries.csv"));
    assert_eq!(csv.len(), 1 + 501, "header and rows 0, 20, …, 10,000");
    assert!(csv[2].starts_with("0.2,") && csv[501].starts_with("100.0,"));
    // Every figure and the replay page from the thinned rows, and `host-sim plot` again.
    for f in ["trajectories.png", "angle_errors.svg", "replay.html"] {
        assert!(out.join(f).is_file(), "{f}");
    }
    let o = host_sim(&["plot", out.to_str().expect("utf-8"), "-q"]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    // The verdict is the engine's, not the CSV's: a run that writes no rows at all
    // judges the same (outcome, reason, settle time, every final figure).
    let bare = tmp.path().join("bare");
    let o = host_sim(&[
        "run",
        &scenario,
        "-q",
        "--summary-only",
        "--out",
        bare.to_str().expect("utf-8"),
    ]);
    assert_eq!(o.status.code(), Some(0));
    let mut whole = json(&bare.join("summary.json"));
    let mut thinned = summary.clone();
    for s in [&mut whole, &mut thinned] {
        let o = s.as_object_mut().expect("object");
        o.remove("series");
        o.remove("warnings");
    }
    assert_eq!(thinned, whole);
    assert!(whole.get("series").is_none());
}

#[test]
fn full_rate_writes_every_row_of_a_run_over_the_budget() {
    let tmp = tempfile::tempdir().expect("temp dir");
    let scenario = lattice(tmp.path());
    // 58 s: 5,801 rows × 1,393 columns = 8.08 M cells, just over the budget.
    let (thin, full) = (tmp.path().join("thin"), tmp.path().join("full"));
    for (dir, flag) in [(&thin, None), (&full, Some("--full-rate"))] {
        let mut args = vec![
            "run",
            &scenario,
            "-q",
            "--no-plots",
            "--duration",
            "58",
            "--out",
            dir.to_str().expect("utf-8"),
        ];
        args.extend(flag);
        let o = host_sim(&args);
        assert_eq!(
            o.status.code(),
            Some(0),
            "{}",
            String::from_utf8_lossy(&o.stderr)
        );
    }
    let (thin_rows, full_rows) = (
        lines(&thin.join("timeseries.csv")),
        lines(&full.join("timeseries.csv")),
    );
    assert_eq!(full_rows.len(), 1 + 5_801, "every logged row");
    assert!(json(&full.join("summary.json")).get("series").is_none());
    assert_eq!(json(&thin.join("summary.json"))["series"]["stride"], 10);
    // The thinned file is the full one's header, rows 0, 10, 20, … 5,800: byte for byte.
    let every_tenth: Vec<&String> = std::iter::once(&full_rows[0])
        .chain(full_rows[1..].iter().step_by(10))
        .collect();
    assert_eq!(thin_rows.iter().collect::<Vec<_>>(), every_tenth);
}

/// With a small budget, through the library: the first row, every `stride`-th and the
/// last (also of a run that a failure ends between two kept rows); `FULL_RATE` keeps
/// every row; the summary names the stride only when the files were thinned.
#[test]
fn a_thinned_series_keeps_the_first_every_stride_th_and_the_last_row() {
    let tmp = tempfile::tempdir().expect("temp dir");
    let small = SeriesBudget {
        max_full_cells: 10_000,
        thinned_cells: 3_000,
    };
    // paper for 3 s: 301 rows × 49 columns; paper-printed ends at 0.96 s (97 rows).
    for (scenario, rows, last) in [("paper", 301, 300), ("paper-printed", 97, 96)] {
        let model = ph_formation_sim::load(scenario, &["duration=3".to_owned()]).expect("load");
        let write = |dir: &Path, budget: SeriesBudget| {
            let run = Simulation::new(&model)
                .keep_series(false)
                .write_to(dir, WriteOptions::without_plots())
                .series_budget(budget)
                .run()
                .expect("run");
            (run.thinning, lines(&dir.join("timeseries.csv")))
        };
        let (full_t, full) = write(&tmp.path().join("full"), SeriesBudget::FULL_RATE);
        assert_eq!((full_t, full.len()), (None, 1 + rows), "{scenario}");
        let (thin_t, thin) = write(&tmp.path().join("thin"), small);
        let stride = thin_t.expect("thinned").stride;
        assert_eq!(stride, 10, "{scenario}");
        let mut want: Vec<usize> = (0..rows).step_by(10).collect();
        if want.last() != Some(&last) {
            want.push(last);
        }
        let want: Vec<&String> = std::iter::once(&full[0])
            .chain(want.iter().map(|&i| &full[1 + i]))
            .collect();
        assert_eq!(thin.iter().collect::<Vec<_>>(), want, "{scenario}");
        let summary = json(&tmp.path().join("thin/summary.json"));
        assert_eq!(summary["series"]["stride"], 10);
        // Negative control: the default budget does not thin these runs.
        let (none, _) = write(&tmp.path().join("default"), SeriesBudget::DEFAULT);
        assert_eq!(none, None);
        let summary = json(&tmp.path().join("default/summary.json"));
        assert!(summary.get("series").is_none());
    }
}

/// The figures and the replay page a run draws from the rows it kept in memory are the
/// files `host-sim plot` and `host-sim view` draw from `timeseries.csv` afterwards, byte
/// for byte (a run that ends early included); a run without figures draws none.
#[test]
fn figures_drawn_from_memory_are_those_drawn_from_the_csv() {
    let tmp = tempfile::tempdir().expect("temp dir");
    for scenario in ["paper", "paper-printed"] {
        let (run, redrawn) = (
            tmp.path().join(format!("{scenario}-run")),
            tmp.path().join(format!("{scenario}-redrawn")),
        );
        let o = host_sim(&[
            "run",
            scenario,
            "-q",
            "--duration",
            "20",
            "--out",
            run.to_str().expect("utf-8"),
        ]);
        assert!(o.status.code().is_some());
        let o = host_sim(&[
            "run",
            scenario,
            "-q",
            "--duration",
            "20",
            "--no-plots",
            "--out",
            redrawn.to_str().expect("utf-8"),
        ]);
        assert!(o.status.code().is_some());
        assert!(!redrawn.join("energy.png").exists() && !redrawn.join("replay.html").exists());
        let r = redrawn.to_str().expect("utf-8");
        assert!(host_sim(&["plot", r, "-q"]).status.success());
        assert!(host_sim(&["view", r, "--no-open"]).status.success());
        let mut names: Vec<String> = std::fs::read_dir(&run)
            .expect("dir")
            .map(|e| e.expect("entry").file_name().to_string_lossy().into_owned())
            .collect();
        names.sort();
        assert!(names.len() >= 14, "{names:?}");
        for f in &names {
            let (a, b) = (std::fs::read(run.join(f)), std::fs::read(redrawn.join(f)));
            assert!(a.expect("read") == b.expect(f), "{scenario}: {f} differs");
        }
    }
}

/// `TimeSeries::read_csv` reads a run's `timeseries.csv` back as the rows the run kept
/// (the figures' rows in `cargo xtask bench-counts`); a changed value differs.
#[test]
fn a_series_read_back_from_the_csv_is_the_series_of_the_run() {
    let tmp = tempfile::tempdir().expect("temp dir");
    let model = ph_formation_sim::load("paper", &["duration=3".to_owned()]).expect("load");
    let run = Simulation::new(&model)
        .write_to(tmp.path(), WriteOptions::without_plots())
        .run()
        .expect("run");
    let csv = tmp.path().join("timeseries.csv");
    let back = ph_formation_sim::TimeSeries::read_csv(&csv).expect("read");
    assert_eq!(Some(&back), run.series.as_ref());
    assert_eq!(back.len(), 301);
    let text = std::fs::read_to_string(&csv).expect("csv");
    std::fs::write(&csv, text.replacen("\n0.01,", "\n0.02,", 1)).expect("write");
    let changed = ph_formation_sim::TimeSeries::read_csv(&csv).expect("read");
    assert_ne!(Some(&changed), run.series.as_ref());
}
