//! `energy`: V and its terms V_kin, V_ang, V_lead, V_est vs time, log scale.

use super::input::Run;
use super::legend::{entry, with_legend, Key};
use super::ranges::*;
use super::style::*;
use super::text::frame;
use super::{DrawResult, ENERGY_FLOOR};
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
    let area = frame(root, run, "energy V(t)", "", bitmap)?;

    let min_pos = run
        .energy
        .iter()
        .flat_map(|s| s.values.iter().copied())
        .filter(|v| sane(*v) && *v > 0.0)
        .fold(f64::INFINITY, f64::min);
    let floor = if min_pos.is_finite() {
        min_pos.max(ENERGY_FLOOR)
    } else {
        ENERGY_FLOOR
    };
    let colours = [DARK, colour(0), colour(1), colour(2), colour(3)];
    let mut drawn = Vec::new();
    let mut entries = Vec::new();
    for (i, s) in run.energy.iter().enumerate() {
        let positive = s.values.iter().any(|v| sane(*v) && *v > 0.0);
        let width = if i == 0 { 3 } else { 2 };
        if positive {
            drawn.push((log_points(&run.t, &s.values, floor), colours[i], width));
            entries.push(entry(s.label.clone(), Key::Line(colours[i], width)));
        } else {
            entries.push(entry(format!("{} ≡ 0 (not drawn)", s.label), Key::None));
        }
    }
    let clamped = run.energy.iter().any(|s| {
        s.values.iter().any(|v| sane(*v) && *v > 0.0)
            && s.values.iter().any(|v| sane(*v) && *v < floor)
    });
    if clamped {
        entries.push(entry(
            format!("values < {floor:.0e} drawn at it"),
            Key::None,
        ));
    }
    let plot = with_legend(&area, &entries, bitmap)?;

    let (t0, t1) = time_range(&run.t);
    let (y0, y1) = log_range(drawn.iter().flat_map(|d| d.0.iter().map(|p| p.1)));
    let mut chart = chart_on(&plot).build_cartesian_2d(t0..t1, (y0..y1).log_scale())?;
    styled_mesh(&mut chart.configure_mesh(), "energy")
        .y_label_formatter(&log_label)
        .draw()?;
    // V first (thick), the terms over it, so that a term equal to V shows.
    for (pts, c, width) in drawn {
        stroke(chart.plotting_area(), &pts, c, width, false, bitmap)?;
    }
    Ok(())
}
