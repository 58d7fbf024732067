//! `estimates`: each distance estimate r̂ (solid) against its true distance r
//! (dashed), at most `MAX_ESTIMATES` (beyond, the ones farthest from their true
//! distance at the end, worst first).

use super::input::Run;
use super::legend::{entry, with_legend, Key};
use super::ranges::*;
use super::style::*;
use super::text::frame;
use super::{DrawResult, Series};
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
    let note = if run.n_estimates > run.estimates.len() {
        format!(
            "the {} of {} estimates farthest from their true distance at the end",
            run.estimates.len(),
            run.n_estimates
        )
    } else if run.n_estimates == 0 {
        "no estimates in this run".to_string()
    } else {
        String::new()
    };
    let area = frame(root, run, "distance estimates", &note, bitmap)?;

    let mut entries = vec![
        entry("estimated distance (solid)", Key::Line(DARK, 2)),
        entry("true distance r (dashed)", Key::Dashed(DARK, 2)),
        entry("owner: apex→far (other far)", Key::None),
    ];
    for (i, e) in run.estimates.iter().enumerate() {
        entries.push(entry(e.label.clone(), Key::Line(colour(i), 3)));
    }
    let plot = with_legend(&area, &entries, bitmap)?;

    let series: Vec<(Series, Series)> = run
        .estimates
        .iter()
        .map(|e| (points(&run.t, &e.rhat), points(&run.t, &e.r)))
        .collect();
    let (t0, t1) = time_range(&run.t);
    let (y0, y1) = lin_range(
        series
            .iter()
            .flat_map(|(a, b)| a.iter().chain(b).map(|p| p.1)),
    );
    let mut chart = chart_on(&plot).build_cartesian_2d(t0..t1, y0..y1)?;
    styled_mesh(&mut chart.configure_mesh(), "distance (m)").draw()?;
    for (i, (rhat, r)) in series.into_iter().enumerate() {
        stroke(chart.plotting_area(), &r, colour(i), 2, true, bitmap)?;
        stroke(chart.plotting_area(), &rhat, colour(i), 2, false, bitmap)?;
    }
    Ok(())
}
