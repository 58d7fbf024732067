//! `trajectories`: the x–y path of every agent (at most `MAX_AGENT_PATHS`), formation
//! snapshots at five times, leaders marked; equal aspect ratio.

use super::input::{Run, Snapshot};
use super::legend::{entry, with_legend, Key};
use super::ranges::*;
use super::style::*;
use super::text::frame;
use super::DrawResult;
use plotters::coord::Shift;
use plotters::prelude::*;

/// Draws the figure on `root`.
pub(super) fn draw<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    run: &Run,
    bitmap: bool,
) -> DrawResult
where
    DB::ErrorType: 'static,
{
    let n = run.agent_ids.len();
    let note = if run.paths.len() < n {
        format!("paths of {} of {} agents shown", run.paths.len(), n)
    } else {
        String::new()
    };
    let area = frame(root, run, "trajectories and formation", &note, bitmap)?;

    // Legend.
    let mut entries = Vec::new();
    let label_each = run.paths.len() <= 10;
    if label_each {
        for (i, p) in run.paths.iter().enumerate() {
            entries.push(entry(
                format!("agent {}", run.agent_ids[p.agent]),
                Key::Line(colour(i), 2),
            ));
        }
    } else {
        // Many agents: one colour bar instead of a row per agent.
        let first = run.agent_ids.first().map_or("", String::as_str);
        let last = run.agent_ids.last().map_or("", String::as_str);
        entries.push(entry(
            format!("agent paths ({}), by agent index", run.paths.len()),
            Key::Ramp,
        ));
        entries.push(entry(
            format!("  left: 1st agent ({first}), right: {n}th ({last})"),
            Key::None,
        ));
    }
    if label_each && run.paths.len() > 1 {
        entries.push(entry(
            format!(
                "  paths side by side (offset up to ±{} px)",
                fan_offset(run.paths.len() - 1, run.paths.len())
            ),
            Key::None,
        ));
    }
    let shades = snapshot_shades(run.snapshots.len());
    for (s, shade) in run.snapshots.iter().zip(&shades) {
        entries.push(entry(
            format!("formation at t = {}", fmt_time(s.t)),
            Key::Net(*shade),
        ));
    }
    if !run.leaders.is_empty() {
        let ids: Vec<&str> = run
            .leaders
            .iter()
            .map(|&l| run.agent_ids[l].as_str())
            .collect();
        entries.push(entry(
            format!("leader ({})", ids.join(", ")),
            Key::Triangle(LEADER),
        ));
    }
    if run.edges.len() < run.summary.edges.len() {
        entries.push(entry(
            format!(
                "edges with unknown ids (not drawn): {}",
                run.summary.edges.len() - run.edges.len()
            ),
            Key::None,
        ));
    }
    let plot = with_legend(&area, &entries, bitmap)?;

    // Equal-aspect ranges covering paths and snapshots.
    let xs = run
        .paths
        .iter()
        .flat_map(|p| p.x.iter().copied())
        .chain(run.snapshots.iter().flat_map(|s| s.pos.iter().map(|p| p.0)));
    let ys = run
        .paths
        .iter()
        .flat_map(|p| p.y.iter().copied())
        .chain(run.snapshots.iter().flat_map(|s| s.pos.iter().map(|p| p.1)));
    let (x0, x1) = lin_range(xs);
    let (y0, y1) = lin_range(ys);
    let mut chart = plan_view(&plot, (x0, x1), (y0, y1), ("x (m)", "y (m)"))?;

    // Snapshot edges, then the paths over them, then the snapshot nodes, then
    // the leaders on top.
    let valid = |s: &Snapshot, a: usize| s.pos.get(a).filter(|p| sane(p.0) && sane(p.1)).copied();
    for (s, shade) in run.snapshots.iter().zip(&shades) {
        chart.draw_series(run.edges.iter().filter_map(|&(a, b)| {
            Some(PathElement::new(
                vec![valid(s, a)?, valid(s, b)?],
                shade.stroke_width(1),
            ))
        }))?;
    }
    for (i, p) in run.paths.iter().enumerate() {
        let pts = points(&p.x, &p.y);
        let c = if label_each {
            colour(i)
        } else {
            ramp(p.agent as f64 / n.saturating_sub(1).max(1) as f64)
        };
        if label_each {
            // Side by side: no path hides another (the legend says so).
            let offset = fan_offset(i, run.paths.len());
            stroke_offset(chart.plotting_area(), &pts, c, 2, offset, bitmap)?;
        } else {
            stroke(chart.plotting_area(), &pts, c, 2, false, bitmap)?;
        }
    }
    let radius = if n > 100 { 2 } else { 4 };
    for (s, shade) in run.snapshots.iter().zip(&shades) {
        chart.draw_series(
            (0..s.pos.len())
                .filter_map(|a| valid(s, a))
                .map(|p| Circle::new(p, radius, shade.filled())),
        )?;
    }
    for s in &run.snapshots {
        chart.draw_series(
            run.leaders
                .iter()
                .filter_map(|&l| valid(s, l))
                .map(|p| TriangleMarker::new(p, radius + 5, LEADER.filled())),
        )?;
    }
    // Ids at the last snapshot.
    if let Some(s) = run.snapshots.last() {
        agent_ids(&mut chart, &s.pos, &run.agent_ids, bitmap)?;
    }
    Ok(())
}

/// Greys from light (first snapshot) to black (last).
pub(super) fn snapshot_shades(n: usize) -> Vec<RGBColor> {
    (0..n)
        .map(|k| {
            let f = if n > 1 {
                k as f64 / (n - 1) as f64
            } else {
                1.0
            };
            let g = (175.0 * (1.0 - f)).round() as u8;
            RGBColor(g, g, g)
        })
        .collect()
}

pub(super) fn fmt_time(t: f64) -> String {
    if t == 0.0 || (t.abs() >= 0.01 && t.abs() < 1e5) {
        format!("{t:.2} s")
    } else {
        format!("{t:.2e} s")
    }
}
