//! `shape`: the final formation, fitted onto the target shape by the best similarity
//! (translation, rotation, scale and, if closer, a mirror; `model::shape`), drawn over the
//! target with the graph edges; folded triangles filled red. Equal aspect ratio.

use super::input::Run;
use super::legend::{entry, with_legend, Key};
use super::ranges::*;
use super::style::*;
use super::text::frame;
use super::DrawResult;
use crate::model::shape::fit_similarity;
use plotters::coord::Shift;
use plotters::prelude::*;

/// Grey of the target.
const TARGET: RGBColor = RGBColor(150, 150, 150);
/// The fitted final formation.
const FINAL: RGBColor = RGBColor(31, 119, 180);

/// Draws the figure on `root` (a note instead of a plot when the run has no target).
pub(super) fn draw<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    run: &Run,
    bitmap: bool,
) -> DrawResult
where
    DB::ErrorType: 'static,
{
    let Some(shape) = &run.summary.shape else {
        frame(
            root,
            run,
            "final formation over its target",
            "no target in summary.json",
            bitmap,
        )?;
        return Ok(());
    };
    let target: Vec<[f64; 2]> = shape
        .target_positions
        .iter()
        .map(|p| [p[0].unwrap_or(f64::NAN), p[1].unwrap_or(f64::NAN)])
        .collect();
    let last: Vec<[f64; 2]> = run
        .snapshots
        .last()
        .map(|s| s.pos.iter().map(|p| [p.0, p.1]).collect())
        .unwrap_or_default();
    let fitted: Vec<(f64, f64)> = match fit_similarity(&last, &target) {
        Ok(fit) => last
            .iter()
            .map(|q| {
                let p = fit.apply(*q);
                (p[0], p[1])
            })
            .collect(),
        Err(_) => Vec::new(),
    };
    let tgt: Vec<(f64, f64)> = target.iter().map(|p| (p[0], p[1])).collect();
    let note = format!(
        "target from {}; largest deviation {} of its size{}",
        if shape.target == "file" {
            "[target]"
        } else {
            "the desired angles"
        },
        shape
            .max_error_rel
            .map_or_else(|| "?".to_owned(), |e| format!("{e:.2e}")),
        if shape.reflected {
            "; formation mirrored"
        } else {
            ""
        }
    );
    let area = frame(root, run, "final formation over its target", &note, bitmap)?;
    let mut entries = vec![
        entry("target shape", Key::Net(TARGET)),
        entry("final formation (fitted)", Key::Net(FINAL)),
    ];
    let index: std::collections::HashMap<&str, usize> = run
        .agent_ids
        .iter()
        .enumerate()
        .map(|(i, id)| (id.as_str(), i))
        .collect();
    let folded: Vec<[usize; 3]> = shape
        .folded_triangles
        .iter()
        .filter_map(|t| {
            let ids = [t[0].to_string(), t[1].to_string(), t[2].to_string()];
            Some([
                *index.get(ids[0].as_str())?,
                *index.get(ids[1].as_str())?,
                *index.get(ids[2].as_str())?,
            ])
        })
        .collect();
    if !folded.is_empty() {
        entries.push(entry(
            format!("folded triangles ({})", folded.len()),
            Key::Triangle(LEADER),
        ));
    }
    let plot = with_legend(&area, &entries, bitmap)?;

    let ok = |p: &(f64, f64)| sane(p.0) && sane(p.1);
    let (x0, x1) = lin_range(tgt.iter().chain(&fitted).filter(|p| ok(p)).map(|p| p.0));
    let (y0, y1) = lin_range(tgt.iter().chain(&fitted).filter(|p| ok(p)).map(|p| p.1));
    let descs = ("x (target frame, m)", "y (target frame, m)");
    let mut chart = plan_view(&plot, (x0, x1), (y0, y1), descs)?;
    let at = |set: &[(f64, f64)], i: usize| set.get(i).filter(|p| ok(p)).copied();
    for t in &folded {
        if let (Some(a), Some(b), Some(c)) =
            (at(&fitted, t[0]), at(&fitted, t[1]), at(&fitted, t[2]))
        {
            chart.draw_series(std::iter::once(Polygon::new(
                vec![a, b, c],
                LEADER.mix(0.35).filled(),
            )))?;
        }
    }
    let n = run.agent_ids.len();
    let radius = if n > 100 { 2 } else { 4 };
    for (set, c, width) in [(&tgt, TARGET, 3), (&fitted, FINAL, 1)] {
        chart.draw_series(run.edges.iter().filter_map(|&(a, b)| {
            Some(PathElement::new(
                vec![at(set, a)?, at(set, b)?],
                c.stroke_width(width),
            ))
        }))?;
        chart.draw_series(
            (0..set.len())
                .filter_map(|i| at(set, i))
                .map(|p| Circle::new(p, radius, c.filled())),
        )?;
    }
    agent_ids(&mut chart, &fitted, &run.agent_ids, bitmap)
}
