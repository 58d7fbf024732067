//! The summary table printed at the end of `host-sim run`.

use crate::engine::RunResult;
use crate::model::Model;
use std::fmt::Write as _;
use std::path::Path;

/// A number in 4 decimals, or in scientific notation when very small or large.
fn g(x: f64) -> String {
    if x == 0.0 || (1e-3..1e4).contains(&x.abs()) {
        format!("{x:.4}")
    } else {
        format!("{x:.3e}")
    }
}

/// The table `host-sim run` prints at the end of a run: `out` is the output directory,
/// `n_files` the number of files written there.
pub fn summary_table(m: &Model, r: &RunResult, out: &Path, n_files: usize) -> String {
    let id = |i: usize| m.agents.get(i).map_or("?", |a| a.name.as_str());
    let mut rows: Vec<(&str, String)> = vec![
        ("scenario", format!("{} ({})", m.name, m.source)),
        (
            "mode / estimator",
            format!("{} / {}", m.mode.as_str(), m.estimator.as_str()),
        ),
        (
            "outcome",
            format!("{} (exit code {})", r.outcome, r.outcome.exit_code()),
        ),
        ("reason", r.reason.clone()),
        (
            "simulated",
            format!(
                "{} s of {} s in {:.2} s wall",
                g(r.final_time),
                g(m.duration),
                r.wall_seconds
            ),
        ),
        (
            "settle time",
            match (r.settle_time, &r.steady) {
                (None, None) => "never (angle errors ≥ tolerance at the end)".to_owned(),
                (None, Some(_)) => {
                    "never (outside a band at the end of the steady window)".to_owned()
                }
                (Some(t), None) => format!("{} s", g(t)),
                (Some(t), Some(s)) => format!(
                    "{} s (windowed errors in their bands for good; steady window from {} s)",
                    g(t),
                    g(s.window.from)
                ),
            },
        ),
        (
            "final max angle error",
            format!("{} rad", g(r.final_max_angle_error)),
        ),
        (
            "final displacement error",
            format!("{} m", g(r.final_displacement_error)),
        ),
        (
            "final velocity error",
            format!("{} m/s", g(r.final_velocity_error)),
        ),
        (
            "min estimate",
            r.min_estimate
                .map_or("none".to_owned(), |x| format!("{} m", g(x))),
        ),
        (
            "min distance",
            format!(
                "{} m (agents {}–{} at t = {} s)",
                g(r.min_distance.0),
                id(r.min_distance.2),
                id(r.min_distance.3),
                g(r.min_distance.1)
            ),
        ),
        ("V(0) → V(end)", format!("{} → {}", g(r.v0), g(r.v_final))),
        ("V max increase / V(0)", g(r.v_max_increase_rel)),
        (
            "frames sent / dropped / rejected",
            format!(
                "{} / {} / {}",
                r.frames.sent, r.frames.dropped, r.frames.rejected
            ),
        ),
        (
            "safe outputs after t = 0",
            format!(
                "{} of {} agent ticks",
                r.control.safe_after_start, r.control.ticks
            ),
        ),
        ("saturated outputs", r.control.saturated.to_string()),
    ];
    rows.extend(super::channel::rows(m, r));
    rows.extend(super::attack::rows(m, r));
    for h in &r.hil {
        rows.push((
            "emulated agent",
            format!(
                "{}: {} ticks, {} / {} frames and {} / {} bytes to / from the target, {:.1} s in round trips",
                h.agent,
                h.ticks,
                h.frames_to_target,
                h.frames_from_target,
                h.bytes_to_target,
                h.bytes_from_target,
                h.wall_s
            ),
        ));
    }
    if !r.hil.is_empty() && r.final_time > 0.0 {
        rows.push((
            "wall-clock per simulated s",
            format!("{:.3} s", r.wall_seconds / r.final_time),
        ));
    }
    rows.extend([("output", format!("{} ({n_files} files)", out.display()))]);
    if !r.orientation_kept.iter().all(|&k| k) {
        rows.push((
            "mirror flips",
            "a triangle's orientation flipped (mirror image)".to_owned(),
        ));
    }
    let w = rows
        .iter()
        .map(|(k, _)| k.chars().count())
        .max()
        .unwrap_or(0);
    let line = "-".repeat(w + 2 + 60);
    let mut text = format!("{line}\n");
    for (k, v) in rows {
        let _ = writeln!(text, "{k:<w$}  {v}");
    }
    let _ = writeln!(text, "{line}");
    text
}
