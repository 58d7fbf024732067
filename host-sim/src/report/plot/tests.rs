//! Unit tests of the figures on synthetic runs.

use super::input::load_run;
use super::input::{angle_label, estimate_label};
use super::ranges::{lin_range, log_label, log_range};
use super::text::drawable;
use super::thinning::{spread, Thinning};

use super::*;
use std::fmt::Write as _;

/// Shape of a synthetic run.
struct Synth {
    agents: usize,
    rows: usize,
    angles: usize,
    estimates: usize,
}

/// Writes a synthetic `timeseries.csv` and `summary.json` into `dir`:
/// agents (ids 1..=n) spiral onto a ring, errors decay, a few values are
/// NaN, inf, empty or exactly zero.
fn write_run(dir: &Path, s: &Synth) {
    let ids: Vec<usize> = (1..=s.agents).collect();
    let mut header: Vec<String> = REQUIRED.iter().map(|c| (*c).to_string()).collect();
    header.extend(["frames_sent", "frames_dropped", "frames_rejected"].map(String::from));
    for i in &ids {
        header.extend([
            format!("x_{i}"),
            format!("y_{i}"),
            format!("vx_{i}"),
            format!("vy_{i}"),
        ]);
    }
    let triple = |k: usize| {
        (
            1 + k % s.agents,
            1 + (k + 1) % s.agents,
            1 + (k + 2) % s.agents,
        )
    };
    for k in 0..s.angles {
        let (u, v, w) = triple(k);
        header.push(format!("angle_err_{u}_{v}_{w}"));
    }
    for k in 0..s.estimates {
        let (u, f, w) = triple(k);
        header.push(format!("rhat_{u}_{u}_{f}_{w}"));
        header.push(format!("r_{u}_{u}_{f}_{w}"));
    }
    let mut csv = header.join(",");
    csv.push('\n');
    for row in 0..s.rows {
        let t = 0.01 * row as f64;
        let e = (-0.5 * t).exp();
        let mut v = vec![
            3.0 * e,
            e,
            e,
            if t > 1.0 { 0.0 } else { e },
            if row == 3 { f64::NAN } else { 0.5 * e },
            0.3 * e,
            2.0 * e,
            e,
            1.0 - 0.5 * e,
            row as f64,
            0.0,
            0.0,
        ];
        let mut line = format!("{t}");
        for x in v.drain(..) {
            let _ = write!(line, ",{x}");
        }
        for (a, _) in ids.iter().enumerate() {
            let phase = a as f64 * std::f64::consts::TAU / s.agents as f64;
            let r = 5.0 + 2.0 * e;
            let _ = write!(
                line,
                ",{},{},0,0",
                r * (phase + 0.1 * t).cos(),
                r * (phase + 0.1 * t).sin()
            );
        }
        for k in 0..s.angles {
            let x = 0.2 * e * (t + k as f64).cos();
            if row == 5 && k == 0 {
                line.push_str(",inf");
            } else if row == 6 && k == 0 {
                line.push(',');
            } else if t > 2.0 && k == 0 {
                line.push_str(",0");
            } else {
                let _ = write!(line, ",{x}");
            }
        }
        for k in 0..s.estimates {
            let r = 2.0 + 0.1 * k as f64;
            let _ = write!(line, ",{},{r}", r + e * (t + k as f64).sin());
        }
        csv.push_str(&line);
        csv.push('\n');
    }
    std::fs::write(dir.join("timeseries.csv"), csv).unwrap();
    let edges: Vec<[usize; 2]> = (0..s.agents)
        .map(|a| [1 + a, 1 + (a + 1) % s.agents])
        .collect();
    let summary = serde_json::json!({
        "scenario": "unit-ring",
        "outcome": "converged",
        "outcome_reason": "every angle error below 0.001 rad; estimate r\u{302} ok",
        "agents": ids,
        "edges": edges,
        "leaders": [1, 2],
        "mode": "sampled",
        "estimator": "shared",
        "extra_field": {"ignored": true},
    });
    std::fs::write(dir.join("summary.json"), summary.to_string()).unwrap();
}

fn small() -> Synth {
    Synth {
        agents: 4,
        rows: 300,
        angles: 3,
        estimates: 4,
    }
}

/// Rewrites the CSV header through `f`.
fn edit_header(dir: &Path, f: impl Fn(&str) -> String) {
    let path = dir.join("timeseries.csv");
    let text = std::fs::read_to_string(&path).unwrap();
    let (header, rest) = text.split_once('\n').unwrap();
    std::fs::write(&path, format!("{}\n{rest}", f(header))).unwrap();
}

#[test]
fn writes_every_figure_as_png_and_svg_with_titles() {
    let dir = tempfile::tempdir().unwrap();
    write_run(dir.path(), &small());
    let files = plot_run(dir.path()).unwrap();
    let titles = [
        ("trajectories", "trajectories and formation"),
        ("angle_errors", "angle errors"),
        ("energy", "energy V(t)"),
        ("estimates", "distance estimates"),
        ("maneuvers", "maneuvers"),
    ];
    let expected: Vec<PathBuf> = titles
        .iter()
        .flat_map(|(stem, _)| ["png", "svg"].map(|ext| dir.path().join(format!("{stem}.{ext}"))))
        .collect();
    assert_eq!(files, expected);
    for (stem, what) in titles {
        let png = std::fs::read(dir.path().join(format!("{stem}.png"))).unwrap();
        assert!(
            png.starts_with(b"\x89PNG\r\n\x1a\n"),
            "{stem}.png signature"
        );
        assert!(png.len() > 10_000, "{stem}.png is {} bytes", png.len());
        let svg = std::fs::read_to_string(dir.path().join(format!("{stem}.svg"))).unwrap();
        assert!(svg.contains("<svg"), "{stem}.svg");
        let title = format!("unit-ring — {what} — outcome: converged");
        assert!(svg.contains(&title), "{stem}.svg lacks `{title}`");
        // The SVG keeps the combining circumflex; only bitmaps spell it out.
        assert!(svg.contains("r\u{302} ok"), "{stem}.svg subtitle");
    }
    let legend = std::fs::read_to_string(dir.path().join("angle_errors.svg")).unwrap();
    assert!(legend.contains("∠2-1-3") && legend.contains("threshold 1e-3 rad"));
    let legend = std::fs::read_to_string(dir.path().join("estimates.svg")).unwrap();
    assert!(legend.contains("1: 1→2 (3)") && legend.contains("4: 4→1 (2)"));
}

#[test]
fn a_large_run_is_thinned_and_says_so() {
    let dir = tempfile::tempdir().unwrap();
    let s = Synth {
        agents: 120,
        rows: 4321,
        angles: 130,
        estimates: 20,
    };
    write_run(dir.path(), &s);
    let run = load_run(dir.path(), None).unwrap();
    assert!(run.t.len() <= MAX_POINTS + 1, "{} rows kept", run.t.len());
    assert_eq!(run.t.first(), Some(&0.0));
    assert_eq!(run.t.last(), Some(&(0.01 * 4320.0)));
    assert_eq!(run.snapshots.len(), 5);
    assert_eq!(run.snapshots[0].t, 0.0);
    assert_eq!(run.snapshots[4].t, 0.01 * 4320.0);
    assert!(run.snapshots.iter().all(|s| s.pos.len() == 120));
    assert_eq!(run.edges.len(), 120);
    assert_eq!(run.leaders, [0, 1]);
    assert!(run.paths.len() <= MAX_AGENT_PATHS + 2);
    assert!(run.paths.iter().all(|p| p.x.len() == run.t.len()));
    assert!(run.angles.len() >= MAX_ANGLES && run.angles.len() <= MAX_ANGLES + WORST_NAMED);
    assert_eq!(run.n_angles, 130);
    assert_eq!((run.estimates.len(), run.n_estimates), (MAX_ESTIMATES, 20));
    // The worst angles at the end (t = 43.2 s: angle k is 0.2 e^(-t/2) cos(t + k)), named
    // in order, whether or not the evenly spaced subset has them.
    let t_end = 0.01 * 4320.0;
    let mut ks: Vec<usize> = (1..130).collect(); // angle 0 is 0 from t = 2 s
    ks.sort_by(|&a, &b| {
        let f = |k: usize| (t_end + k as f64).cos().abs();
        f(b).total_cmp(&f(a))
    });
    let names: Vec<&str> = run
        .worst_angles
        .iter()
        .map(|&i| run.angles[i].label.as_str())
        .collect();
    let expected: Vec<String> = ks[..WORST_NAMED]
        .iter()
        .map(|&k| {
            let (u, v, w) = (1 + k % 120, 1 + (k + 1) % 120, 1 + (k + 2) % 120);
            format!("∠{v}-{u}-{w}")
        })
        .collect();
    assert_eq!(names, expected);

    plot_run(dir.path()).unwrap();
    let read = |f: &str| std::fs::read_to_string(dir.path().join(f)).unwrap();
    let n = run.paths.len();
    assert!(read("trajectories.svg").contains(&format!("paths of {n} of 120 agents shown")));
    let shown = format!("{} of 130 angles shown", run.angles.len());
    assert!(read("angle_errors.svg").contains(&shown));
    assert!(read("angle_errors.svg").contains(&format!("{} (worst #1)", expected[0])));
    assert!(read("estimates.svg")
        .contains("the 12 of 20 estimates farthest from their true distance at the end"));
}

#[test]
fn a_missing_column_is_named() {
    let cases: [(&str, &str); 4] = [
        ("V_est", "W_est"),
        ("t", "time"),
        ("y_3", "z_3"),
        ("r_2_2_3_4", "s_2_2_3_4"),
    ];
    for (column, renamed) in cases {
        let dir = tempfile::tempdir().unwrap();
        write_run(dir.path(), &small());
        edit_header(dir.path(), |h| {
            h.split(',')
                .map(|c| if c == column { renamed } else { c })
                .collect::<Vec<_>>()
                .join(",")
        });
        match plot_run(dir.path()) {
            Err(e @ PlotError::MissingColumn { .. }) => {
                let msg = e.to_string();
                assert!(msg.contains(&format!("`{column}`")), "{msg}");
                assert!(msg.contains("timeseries.csv"), "{msg}");
            }
            other => panic!("{column}: expected MissingColumn, got {other:?}"),
        }
    }
}

#[test]
fn an_agent_in_the_summary_without_columns_is_named() {
    let dir = tempfile::tempdir().unwrap();
    write_run(dir.path(), &small());
    let path = dir.path().join("summary.json");
    let mut summary: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&path).unwrap()).unwrap();
    summary["agents"] = serde_json::json!([1, 2, 3, 4, 9]);
    std::fs::write(&path, summary.to_string()).unwrap();
    let e = plot_run(dir.path()).unwrap_err();
    assert!(e.to_string().ends_with("missing column `x_9`"), "{e}");
}

#[test]
fn an_empty_csv_is_an_error() {
    let dir = tempfile::tempdir().unwrap();
    write_run(dir.path(), &small());
    let csv = dir.path().join("timeseries.csv");
    let header = std::fs::read_to_string(&csv)
        .unwrap()
        .lines()
        .next()
        .unwrap()
        .to_string();
    for (content, reason) in [
        (String::new(), "no header row"),
        (format!("{header}\n"), "no data row"),
        (
            format!(
                "{header}\n{}\n",
                vec!["NaN"; header.split(',').count()].join(",")
            ),
            "no data row",
        ),
    ] {
        std::fs::write(&csv, content).unwrap();
        match plot_run(dir.path()) {
            Err(e @ PlotError::Empty { .. }) => {
                let msg = e.to_string();
                assert!(
                    msg.contains("timeseries.csv") && msg.contains(reason),
                    "{msg}"
                );
            }
            other => panic!("expected Empty, got {other:?}"),
        }
    }
}

#[test]
fn bad_inputs_are_named_errors() {
    // A field that is not a number.
    let dir = tempfile::tempdir().unwrap();
    write_run(dir.path(), &small());
    let csv = dir.path().join("timeseries.csv");
    let text = std::fs::read_to_string(&csv).unwrap();
    let mut lines: Vec<String> = text.lines().map(String::from).collect();
    let mut fields: Vec<&str> = lines[3].split(',').collect();
    fields[1] = "oops";
    lines[3] = fields.join(",");
    std::fs::write(&csv, lines.join("\n")).unwrap();
    let e = plot_run(dir.path()).unwrap_err();
    assert!(matches!(e, PlotError::BadValue { line: 4, .. }), "{e:?}");
    assert!(
        e.to_string().contains("column `V`: `oops` is not a number"),
        "{e}"
    );

    // A row with too few fields.
    lines[3] = "0.5,1,2".to_string();
    std::fs::write(&csv, lines.join("\n")).unwrap();
    let e = plot_run(dir.path()).unwrap_err();
    assert!(
        matches!(e, PlotError::Csv { .. }) && e.to_string().contains("timeseries.csv"),
        "{e}"
    );

    // No summary, then a summary without `agents`.
    let dir = tempfile::tempdir().unwrap();
    write_run(dir.path(), &small());
    let summary = dir.path().join("summary.json");
    std::fs::remove_file(&summary).unwrap();
    let e = plot_run(dir.path()).unwrap_err();
    assert!(
        matches!(e, PlotError::Io { .. }) && e.to_string().contains("summary.json"),
        "{e}"
    );
    std::fs::write(
        &summary,
        r#"{"scenario": "s", "outcome": "o", "edges": []}"#,
    )
    .unwrap();
    let e = plot_run(dir.path()).unwrap_err();
    assert!(
        e.to_string().contains("summary.json") && e.to_string().contains("agents"),
        "{e}"
    );

    // An output that cannot be written.
    let dir = tempfile::tempdir().unwrap();
    write_run(dir.path(), &small());
    std::fs::create_dir(dir.path().join("energy.png")).unwrap();
    let e = plot_run(dir.path()).unwrap_err();
    assert!(
        matches!(e, PlotError::Draw { .. }) && e.to_string().contains("energy.png"),
        "{e}"
    );
}

#[test]
fn odd_but_valid_inputs_still_plot() {
    // Null leaders, no angles, no estimates, an edge to an unknown agent,
    // one data row, constant and all-NaN series.
    let dir = tempfile::tempdir().unwrap();
    write_run(
        dir.path(),
        &Synth {
            agents: 2,
            rows: 1,
            angles: 0,
            estimates: 0,
        },
    );
    let summary = serde_json::json!({
        "scenario": "odd", "outcome": "timeout", "agents": [1, 2],
        "edges": [[1, 2], [2, 7]], "leaders": null,
    });
    std::fs::write(dir.path().join("summary.json"), summary.to_string()).unwrap();
    assert_eq!(plot_run(dir.path()).unwrap().len(), 10);
    let svg = std::fs::read_to_string(dir.path().join("estimates.svg")).unwrap();
    assert!(svg.contains("no estimates in this run"));
    let svg = std::fs::read_to_string(dir.path().join("trajectories.svg")).unwrap();
    assert!(svg.contains("edges with unknown ids (not drawn): 1"));
}

#[test]
fn thinning_keeps_first_last_and_at_most_max_points() {
    for valid in [1, 2, 5, 1999, 2000, 2001, 4001, 12_345, 100_000] {
        let thin = Thinning::new(valid);
        let kept = (0..valid).filter(|&v| thin.keeps(v)).count();
        assert_eq!(kept, thin.kept(), "{valid}");
        assert!(kept <= MAX_POINTS + 1, "{valid}: {kept}");
        assert!(thin.keeps(0) && thin.keeps(valid - 1));
        let snaps = thin.snapshots();
        assert_eq!(snaps.first(), Some(&0));
        assert_eq!(snaps.last(), Some(&(kept - 1)));
        assert_eq!(snaps.len(), kept.min(SNAPSHOTS), "{valid}");
    }
    assert_eq!(spread(1000, 50).len(), 50);
    assert_eq!(spread(1000, 50).last(), Some(&999));
    assert_eq!(spread(7, 50), (0..7).collect::<Vec<_>>());
}

#[test]
fn labels_and_ranges() {
    assert_eq!(angle_label("3_1_2"), "∠1-3-2");
    assert_eq!(angle_label("odd"), "odd");
    assert_eq!(estimate_label("1_1_2_3"), "1: 1→2 (3)");
    assert_eq!(
        drawable("estimate r\u{302} of e\u{301}dge", true),
        "estimate rhat of edge"
    );
    assert_eq!(drawable("r\u{302}", false), "r\u{302}");
    assert_eq!(log_label(&1e-3), "1e-3");
    assert_eq!(log_label(&2e-3), "2.0e-3");
    assert_eq!(lin_range([f64::NAN, f64::INFINITY]), (0.0, 1.0));
    assert_eq!(lin_range([0.0, 0.0]), (-1.0, 1.0));
    let (lo, hi) = lin_range([2.0, 2.0, 1e200]);
    assert!(lo < 2.0 && hi > 2.0 && hi < 3.0);
    let (lo, hi) = log_range([0.0, -1.0, 1e-9, 1e-3]);
    assert!(lo > 0.0 && lo < 1e-9 && hi > 1e-3);
    assert_eq!(log_range([0.0]), (0.1, 10.0));
}
