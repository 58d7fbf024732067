//! The sweep's figures, two per axis: the outcome fractions (with their 95 % intervals)
//! against the axis, one panel per outcome that happened, and the settle time (median,
//! p10–p90 bar) against it. On a grid, one line per combination of the other axes;
//! random points are drawn as markers.

use super::aggregate::PointStats;
use super::error::SweepError;
use super::output::Manifest;
use crate::report::plot::{plot_xy, XyChart, XyLine, XyPanel, XyPoint};
use std::path::{Path, PathBuf};

/// `radio.loss` → `radio_loss` (file stems).
pub fn stem_of(key: &str) -> String {
    key.chars()
        .map(|c| if c.is_ascii_alphanumeric() { c } else { '_' })
        .collect()
}

/// The x of each point on axis `a`: numbers, else category indices (first-seen order).
fn xs(m: &Manifest, a: usize) -> (Vec<f64>, Option<Vec<String>>) {
    let cells: Vec<&String> = m.points.iter().map(|p| &p[a]).collect();
    let nums: Option<Vec<f64>> = cells.iter().map(|c| c.parse::<f64>().ok()).collect();
    if let Some(v) = nums {
        return (v, None);
    }
    let mut cats: Vec<String> = Vec::new();
    let x = cells
        .iter()
        .map(|c| match cats.iter().position(|k| k == *c) {
            Some(i) => i as f64,
            None => {
                cats.push((*c).clone());
                (cats.len() - 1) as f64
            }
        })
        .collect();
    (x, Some(cats))
}

/// Groups of points sharing the other axes' values (grid), or one group (random).
fn groups(m: &Manifest, a: usize) -> Vec<(String, Vec<usize>)> {
    if m.sampling != "grid" || m.axes.len() == 1 {
        return vec![(String::new(), (0..m.points.len()).collect())];
    }
    let mut out: Vec<(String, Vec<usize>)> = Vec::new();
    for (p, cells) in m.points.iter().enumerate() {
        let label: Vec<String> = m
            .axes
            .iter()
            .zip(cells)
            .enumerate()
            .filter(|(i, _)| *i != a)
            .map(|(_, (k, v))| format!("{k}={v}"))
            .collect();
        let label = label.join(", ");
        match out.iter_mut().find(|(l, _)| *l == label) {
            Some((_, v)) => v.push(p),
            None => out.push((label, vec![p])),
        }
    }
    out
}

/// Draws every figure into `dir`; returns the files.
pub fn draw(dir: &Path, m: &Manifest, stats: &[PointStats]) -> Result<Vec<PathBuf>, SweepError> {
    let mut files = Vec::new();
    let runs: u64 = stats.iter().map(|s| s.n).sum();
    let subtitle = format!(
        "{} · base {} · {} runs, {} per point, seed {}",
        m.sweep, m.base, runs, m.runs, m.seed
    );
    // Outcomes that happened somewhere (the others would be flat zero lines).
    let seen: Vec<usize> = (0..m.outcomes.len())
        .filter(|&o| stats.iter().any(|s| s.fractions[o].count > 0))
        .collect();
    for (a, key) in m.axes.iter().enumerate() {
        let (x, categories) = xs(m, a);
        let join = m.sampling == "grid";
        let order = |ps: &[usize]| {
            let mut v = ps.to_vec();
            v.sort_by(|&i, &j| x[i].total_cmp(&x[j]));
            v
        };
        // One panel per outcome that happened, one series per group (colour = group).
        let mut panels: Vec<XyPanel> = seen
            .iter()
            .map(|&o| XyPanel {
                y_label: format!("{} (fraction)", m.outcomes[o]),
                y_range: Some((-0.02, 1.02)),
                lines: Vec::new(),
            })
            .collect();
        let mut settle_lines = Vec::new();
        for (group, ps) in groups(m, a) {
            let ps = order(&ps);
            let label = if group.is_empty() {
                "all points".to_owned()
            } else {
                group
            };
            for (panel, &o) in panels.iter_mut().zip(&seen) {
                panel.lines.push(XyLine {
                    label: label.clone(),
                    points: ps
                        .iter()
                        .map(|&p| {
                            let f = &stats[p].fractions[o];
                            XyPoint {
                                x: x[p],
                                y: f.fraction,
                                lo: f.lo,
                                hi: f.hi,
                            }
                        })
                        .collect(),
                    join,
                });
            }
            settle_lines.push(XyLine {
                label,
                points: ps
                    .iter()
                    .filter_map(|&p| {
                        let s = &stats[p].settle;
                        Some(XyPoint {
                            x: x[p],
                            y: s[1]?,
                            lo: s[0]?,
                            hi: s[2]?,
                        })
                    })
                    .collect(),
                join,
            });
        }
        let stem = stem_of(key);
        let chart = XyChart {
            title: format!("{} — outcome fractions vs {key}", m.name),
            subtitle: format!("{subtitle} · bars: 95 % Wilson intervals"),
            x_label: key.clone(),
            categories: categories.clone(),
            panels,
        };
        files.extend(
            plot_xy(dir, &format!("outcomes_vs_{stem}"), &chart)
                .map_err(|e| SweepError::output(dir, e))?,
        );
        let chart = XyChart {
            title: format!("{} — settle time vs {key}", m.name),
            subtitle: format!("{subtitle} · median, bars: p10–p90 of the runs that settled"),
            x_label: key.clone(),
            categories,
            panels: vec![XyPanel {
                y_label: "settle time (s)".to_owned(),
                y_range: None,
                lines: settle_lines,
            }],
        };
        files.extend(
            plot_xy(dir, &format!("settle_vs_{stem}"), &chart)
                .map_err(|e| SweepError::output(dir, e))?,
        );
    }
    Ok(files)
}
