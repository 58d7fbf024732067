//! The figures of `host-sim compare`, drawn by the run's plot helper ([`plot_xy`]):
//! `compare_positions.png` (x and y of every agent, run and flight, one colour pair per
//! agent), `compare_angles.png` (the largest angle error of each; the flight's drones in
//! hold, landing or with a fault, and the run's events so far) and, for a step,
//! `compare_step.png`.

use super::compare::Overlay;
use super::step::StepComparison;
use crate::model::Model;
use crate::report::plot::{plot_xy, XyChart, XyLine, XyPanel, XyPoint};
use crate::report::PlotError;
use std::path::{Path, PathBuf};

/// At most this many points per line (evenly spaced, the last kept).
const MAX_POINTS: usize = 300;

fn line(label: String, t: &[f64], y: impl Fn(usize) -> f64) -> XyLine {
    let stride = t.len().div_ceil(MAX_POINTS).max(1);
    let keep = (0..t.len()).filter(|k| k % stride == 0 || k + 1 == t.len());
    XyLine {
        label,
        points: keep
            .map(|k| {
                let v = y(k);
                XyPoint {
                    x: t[k],
                    y: v,
                    lo: v,
                    hi: v,
                }
            })
            .collect(),
        join: true,
    }
}

/// Draws the overlay of a run and a flight into `dir`; returns the files.
///
/// # Errors
///
/// A [`PlotError`] naming the file.
pub fn plot_overlay(
    dir: &Path,
    o: &Overlay,
    model: &Model,
    subtitle: &str,
) -> Result<Vec<PathBuf>, PlotError> {
    let n = model.n();
    let axis = |coord: usize| XyPanel {
        y_label: format!("{} (m)", ["x", "y"][coord]),
        y_range: None,
        lines: model
            .agents
            .iter()
            .enumerate()
            .flat_map(|(i, a)| {
                let pick = |q: &[ph_formation_core::Vec2<f64>], k: usize| {
                    let p = q[k * n + i];
                    if coord == 0 {
                        p.x
                    } else {
                        p.y
                    }
                };
                [
                    line(format!("run {}", a.name), &o.t, |k| pick(&o.run_q, k)),
                    line(format!("flight {}", a.name), &o.t, |k| pick(&o.flight_q, k)),
                ]
            })
            .collect(),
    };
    let x_label = "t from the formation's start (s)".to_owned();
    let mut files = plot_xy(
        dir,
        "compare_positions",
        &XyChart {
            title: "positions: run and flight".to_owned(),
            subtitle: subtitle.to_owned(),
            x_label: x_label.clone(),
            categories: None,
            panels: vec![axis(0), axis(1)],
        },
    )?;
    let events_so_far = |k: usize| o.run_events.iter().filter(|e| e.0 <= o.t[k]).count() as f64;
    files.extend(plot_xy(
        dir,
        "compare_angles",
        &XyChart {
            title: "largest angle error, faults: run and flight".to_owned(),
            subtitle: subtitle.to_owned(),
            x_label,
            categories: None,
            panels: vec![
                XyPanel {
                    y_label: "largest angle error (°)".to_owned(),
                    y_range: None,
                    lines: vec![
                        line("run".to_owned(), &o.t, |k| o.run_err[k].to_degrees()),
                        line("flight".to_owned(), &o.t, |k| o.flight_err[k].to_degrees()),
                    ],
                },
                XyPanel {
                    y_label: "run: events; flight: drones held/landing/faulted".to_owned(),
                    y_range: Some((-0.2, (n as f64).max(1.0) + 0.2)),
                    lines: vec![
                        line("run".to_owned(), &o.t, events_so_far),
                        line("flight".to_owned(), &o.t, |k| o.flight_faulty[k]),
                    ],
                },
            ],
        },
    )?);
    Ok(files)
}

/// Draws a step comparison into `dir/compare_step.png`.
///
/// # Errors
///
/// A [`PlotError`] naming the file.
pub fn plot_step(
    dir: &Path,
    c: &StepComparison,
    subtitle: &str,
) -> Result<Vec<PathBuf>, PlotError> {
    let t: Vec<f64> = c.logged.iter().map(|p| p.0).collect();
    plot_xy(
        dir,
        "compare_step",
        &XyChart {
            title: format!(
                "velocity step: log against host-sim vehicle step (shift {} ms)",
                c.shift_ms
            ),
            subtitle: subtitle.to_owned(),
            x_label: "t from the step's setpoint, drone clock (s)".to_owned(),
            categories: None,
            panels: vec![XyPanel {
                y_label: "velocity along x (m/s)".to_owned(),
                y_range: None,
                lines: vec![
                    line("vehicle step".to_owned(), &t, |k| c.model_at[k]),
                    line("flight log".to_owned(), &t, |k| c.logged[k].1),
                ],
            }],
        },
    )
}
