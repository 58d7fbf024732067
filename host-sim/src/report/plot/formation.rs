//! The formation before it runs (`host-sim validate … --plot FILE`,
//! `host-sim design … --plot FILE`): the graph on the target shape with its triangles,
//! every agent labelled, each controlled angle marked at its apex with its desired value,
//! the leader edge, and the initial positions joined to their target points. Equal
//! aspect ratio; PNG or SVG by the file's extension.

use super::legend::{entry, with_legend, Key};
use super::ranges::{lin_range, sane};
use super::style::{agent_ids, colour, plan_view, LEADER};
use super::text::{drawable, fit_text};
use super::{ensure_font, DrawResult, PlotError, FONT, IMAGE_SIZE};
use crate::model::Model;
use plotters::coord::Shift;
use plotters::element::DashedPathElement;
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};
use std::path::Path;

/// Plan views (trajectories, shape, formation) label agents with their ids up to this many;
/// beyond, the formation picture also leaves out the triangles and angle marks (they
/// would cover each other).
pub const MAX_LABELLED_AGENTS: usize = 50;
/// Grey of the initial positions.
const INITIAL: RGBColor = RGBColor(130, 130, 130);
/// The target shape's edges and agents.
const TARGET: RGBColor = RGBColor(31, 119, 180);

/// Draws `model`'s formation into `path` (`.svg`: SVG, anything else: PNG, 1200×900).
///
/// # Errors
///
/// [`PlotError::Draw`] naming the file when it cannot be drawn or written.
pub fn plot_formation(model: &Model, path: &Path) -> Result<(), PlotError> {
    ensure_font()?;
    let err = |e: &dyn std::fmt::Display| PlotError::Draw {
        path: path.to_path_buf(),
        reason: e.to_string(),
    };
    if path
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("svg"))
    {
        let root = SVGBackend::new(path, IMAGE_SIZE).into_drawing_area();
        draw(&root, model, false).map_err(|e| err(&e))?;
        root.present().map_err(|e| err(&e))
    } else {
        super::write_png(path, IMAGE_SIZE, |root| draw(root, model, true)).map_err(|e| err(&e))
    }
}

/// The angle's three points' directions at the apex: the arc from `from` to `from + span`.
fn arc(apex: (f64, f64), a: (f64, f64), b: (f64, f64)) -> (f64, f64) {
    let ta = (a.1 - apex.1).atan2(a.0 - apex.0);
    let tb = (b.1 - apex.1).atan2(b.0 - apex.0);
    let mut span = tb - ta;
    while span > std::f64::consts::PI {
        span -= 2.0 * std::f64::consts::PI;
    }
    while span < -std::f64::consts::PI {
        span += 2.0 * std::f64::consts::PI;
    }
    (ta, span)
}

fn draw<DB: DrawingBackend>(root: &DrawingArea<DB, Shift>, m: &Model, bitmap: bool) -> DrawResult
where
    DB::ErrorType: 'static,
{
    root.fill(&WHITE)?;
    let (w, _) = root.dim_in_pixel();
    let n = m.n();
    let title = format!(
        "{} — formation: {n} agents, {} triangles, {} edges",
        m.name,
        m.triangles.len(),
        m.graph.edges.len()
    );
    let centre = Pos::new(HPos::Center, VPos::Center);
    let tf = TextStyle::from((FONT, 24).into_font());
    let title = fit_text(root, &drawable(&title, bitmap), &tf, w - 24)?;
    root.draw(&Text::new(
        title,
        (w as i32 / 2, 24),
        tf.color(&BLACK).pos(centre),
    ))?;
    let sub = format!(
        "target shape from {}; controlled angles marked at their apex with the desired value{}",
        if m.target.from_file {
            "[target]"
        } else {
            "the desired angles"
        },
        if n > MAX_LABELLED_AGENTS {
            format!(" (not drawn beyond {MAX_LABELLED_AGENTS} agents)")
        } else {
            String::new()
        }
    );
    let sf = TextStyle::from((FONT, 16).into_font());
    let sub = fit_text(root, &drawable(&sub, bitmap), &sf, w - 24)?;
    root.draw(&Text::new(
        sub,
        (w as i32 / 2, 54),
        sf.color(&RGBColor(80, 80, 80)).pos(centre),
    ))?;
    let area = root.split_vertically(74).1;

    let mut entries = vec![
        entry("target shape: edges, agents", Key::Net(TARGET)),
        entry("triangles (SPEC §3)", Key::Triangle(colour(2))),
        entry("initial position → target", Key::Dashed(INITIAL, 1)),
    ];
    if m.leader.is_some() {
        entries.push(entry("leader edge", Key::Line(LEADER, 4)));
    }
    entries.push(entry("α* desired angle (degrees)", Key::None));
    let plot = with_legend(&area, &entries, bitmap)?;

    let tgt: Vec<(f64, f64)> = (0..n)
        .map(|i| {
            m.target
                .positions
                .get(i)
                .map_or((f64::NAN, f64::NAN), |p| (p[0], p[1]))
        })
        .collect();
    let init: Vec<(f64, f64)> = m
        .agents
        .iter()
        .map(|a| (a.position[0], a.position[1]))
        .collect();
    let ok = |p: &&(f64, f64)| sane(p.0) && sane(p.1);
    let (x0, x1) = lin_range(tgt.iter().chain(&init).filter(ok).map(|p| p.0));
    let (y0, y1) = lin_range(tgt.iter().chain(&init).filter(ok).map(|p| p.1));
    let mut chart = plan_view(&plot, (x0, x1), (y0, y1), ("x (m)", "y (m)"))?;
    let at = |i: usize| tgt.get(i).filter(|p| sane(p.0) && sane(p.1)).copied();
    let few = n <= MAX_LABELLED_AGENTS;

    if few {
        for (k, t) in m.triangles.iter().enumerate() {
            let v = t.vertices;
            if let (Some(a), Some(b), Some(c)) = (at(v[0]), at(v[1]), at(v[2])) {
                chart.draw_series(std::iter::once(Polygon::new(
                    vec![a, b, c],
                    colour(2 + k % 3).mix(0.12).filled(),
                )))?;
            }
        }
    }
    // Initial positions joined to their targets.
    chart.draw_series(
        init.iter()
            .zip(&tgt)
            .filter(|(p, q)| sane(p.0) && sane(p.1) && sane(q.0) && sane(q.1))
            .map(|(p, q)| DashedPathElement::new(vec![*p, *q], 4, 4, INITIAL.stroke_width(1))),
    )?;
    chart.draw_series(
        init.iter()
            .filter(|p| sane(p.0) && sane(p.1))
            .map(|p| Circle::new(*p, 4, INITIAL.stroke_width(1))),
    )?;
    chart.draw_series(m.graph.edges.iter().filter_map(|&[a, b]| {
        Some(PathElement::new(
            vec![at(a)?, at(b)?],
            TARGET.stroke_width(2),
        ))
    }))?;
    if let Some(l) = &m.leader {
        if let (Some(a), Some(b)) = (at(l.a), at(l.b)) {
            chart.draw_series(std::iter::once(PathElement::new(
                vec![a, b],
                LEADER.stroke_width(4),
            )))?;
        }
    }
    let radius = if few { 5 } else { 2 };
    chart.draw_series(
        (0..n)
            .filter_map(at)
            .map(|p| Circle::new(p, radius, TARGET.filled())),
    )?;

    if few {
        // The angle marks: an arc of a fifth of the shorter arm, the value beside it.
        let label = TextStyle::from((FONT, 13).into_font()).color(&RGBColor(0, 100, 0));
        for a in m.triangles.iter().flat_map(|t| &t.angles) {
            let (Some(p), Some(q), Some(r)) = (at(a.apex), at(a.far[0]), at(a.far[1])) else {
                continue;
            };
            let arm = ((q.0 - p.0).hypot(q.1 - p.1)).min((r.0 - p.0).hypot(r.1 - p.1));
            let rad = 0.22 * arm;
            let (from, span) = arc(p, q, r);
            let pts: Vec<(f64, f64)> = (0..=16)
                .map(|k| {
                    let th = from + span * f64::from(k) / 16.0;
                    (p.0 + rad * th.cos(), p.1 + rad * th.sin())
                })
                .collect();
            chart.draw_series(std::iter::once(PathElement::new(
                pts,
                RGBColor(0, 130, 0).stroke_width(1),
            )))?;
            let mid = from + span / 2.0;
            let at_text = (p.0 + 1.7 * rad * mid.cos(), p.1 + 1.7 * rad * mid.sin());
            chart.draw_series(std::iter::once(Text::new(
                drawable(&format!("{:.1}°", a.desired.to_degrees()), bitmap),
                at_text,
                label.clone().pos(centre),
            )))?;
        }
    }
    let ids: Vec<String> = m.agents.iter().map(|a| a.name.clone()).collect();
    agent_ids(&mut chart, &tgt, &ids, bitmap)
}
