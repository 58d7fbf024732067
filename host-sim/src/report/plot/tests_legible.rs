//! Legibility for ten agents (issue 47 item 3): in `trajectories.png` and
//! `angle_errors.png` every agent's path and every angle's line stays visible when their
//! data coincide (lines drawn side by side, `style::fan_offset`). The check counts the
//! pixels of each line's colour in the PNG; its negative control draws the same ten lines
//! without offsets and finds all but the top one hidden.

use super::style::{colour, fan_offset, stroke, stroke_offset};
use super::*;
use plotters::prelude::*;
use std::fmt::Write as _;

/// The RGB pixels of a PNG file.
fn pixels(path: &Path) -> Vec<[u8; 3]> {
    let mut decoder = png::Decoder::new(std::fs::File::open(path).expect("png"));
    decoder.set_transformations(png::Transformations::EXPAND | png::Transformations::STRIP_16);
    let mut reader = decoder.read_info().expect("png header");
    let mut buf = vec![0; reader.output_buffer_size()];
    let info = reader.next_frame(&mut buf).expect("png frame");
    let bpp = info.color_type.samples();
    buf[..info.buffer_size()]
        .chunks_exact(bpp)
        .map(|p| [p[0], p[1], p[2]])
        .collect()
}

/// The pixels of each of the first `n` palette colours.
fn colour_counts(px: &[[u8; 3]], n: usize) -> Vec<usize> {
    (0..n)
        .map(|i| {
            let c = colour(i);
            px.iter().filter(|p| **p == [c.0, c.1, c.2]).count()
        })
        .collect()
}

/// Every one of the `n` colours has at least `min` pixels.
fn all_visible(counts: &[usize], min: usize) -> bool {
    counts.iter().all(|&c| c >= min)
}

/// A run of ten agents that all move along the same line, and ten angle errors that are
/// all the same: without care, one line hides all others.
fn write_coincident(dir: &Path, angles: usize) {
    let n = 10;
    // The required columns (t, V and its parts, max_angle_err, …), then the agents.
    let mut header = REQUIRED.join(",");
    for i in 1..=n {
        let _ = write!(header, ",x_{i},y_{i},vx_{i},vy_{i}");
    }
    for k in 0..angles {
        let _ = write!(
            header,
            ",angle_err_{}_{}_{}",
            1 + k,
            1 + (k + 1) % n,
            1 + (k + 2) % n
        );
    }
    let mut csv = header + "\n";
    for row in 0..400 {
        let t = 0.05 * f64::from(row);
        let e = 0.3 * (-0.2 * t).exp();
        let _ = write!(csv, "{t}");
        for c in &REQUIRED[1..] {
            let _ = write!(csv, ",{}", if *c == "min_dist" { 1.0 } else { e });
        }
        for _ in 0..n {
            let _ = write!(csv, ",{},{},1,0.5", t, 0.5 * t + (0.3 * t).sin());
        }
        for _ in 0..angles {
            let _ = write!(csv, ",{e}");
        }
        csv.push('\n');
    }
    std::fs::write(dir.join("timeseries.csv"), csv).unwrap();
    let ids: Vec<usize> = (1..=n).collect();
    let edges: Vec<[usize; 2]> = (1..n).map(|a| [a, a + 1]).collect();
    let summary = serde_json::json!({
        "scenario": "unit-coincident", "outcome": "converged", "agents": ids,
        "edges": edges, "leaders": [1, 2], "mode": "sampled", "estimator": "shared",
    });
    std::fs::write(dir.join("summary.json"), summary.to_string()).unwrap();
}

#[test]
fn ten_coincident_paths_and_angles_each_stay_visible() {
    let dir = tempfile::tempdir().unwrap();
    write_coincident(dir.path(), 10);
    plot_run(dir.path()).unwrap();
    for fig in ["trajectories", "angle_errors"] {
        let counts = colour_counts(&pixels(&dir.path().join(format!("{fig}.png"))), 10);
        // 200 pixels: a visible stretch of line, far more than its legend key's (2 × 40).
        assert!(
            all_visible(&counts, 200),
            "{fig}.png: pixels per colour {counts:?}"
        );
    }
}

#[test]
fn the_check_fails_for_ten_lines_drawn_on_top_of_each_other() {
    let dir = tempfile::tempdir().unwrap();
    let draw = |offsets: bool| {
        let path = dir.path().join(format!("lines-{offsets}.png"));
        {
            let root = BitMapBackend::new(&path, (400, 300)).into_drawing_area();
            root.fill(&WHITE).unwrap();
            let chart = ChartBuilder::on(&root)
                .build_cartesian_2d(0.0..10.0, 0.0..10.0)
                .unwrap();
            let pts: Vec<(f64, f64)> = (0..=100)
                .map(|k| (0.1 * f64::from(k), 0.07 * f64::from(k) + 1.0))
                .collect();
            for i in 0..10 {
                if offsets {
                    stroke_offset(
                        chart.plotting_area(),
                        &pts,
                        colour(i),
                        2,
                        fan_offset(i, 10),
                        true,
                    )
                    .unwrap();
                } else {
                    stroke(chart.plotting_area(), &pts, colour(i), 2, false, true).unwrap();
                }
            }
            chart.plotting_area().present().unwrap();
        }
        colour_counts(&pixels(&path), 10)
    };
    let side_by_side = draw(true);
    assert!(all_visible(&side_by_side, 200), "{side_by_side:?}");
    let on_top = draw(false);
    assert!(!all_visible(&on_top, 200), "{on_top:?}");
    assert_eq!(on_top[..9], [0; 9], "only the last line shows: {on_top:?}");
}

#[test]
fn beyond_ten_angles_the_named_worst_stay_visible_beside_the_maximum() {
    // Sixteen equal angle errors: five named in colour, all equal to the maximum.
    let dir = tempfile::tempdir().unwrap();
    write_coincident(dir.path(), 16);
    plot_run(dir.path()).unwrap();
    let counts = colour_counts(&pixels(&dir.path().join("angle_errors.png")), WORST_NAMED);
    assert!(all_visible(&counts, 200), "angle_errors.png: {counts:?}");
}
