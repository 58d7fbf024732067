//! `maneuvers`: leader displacement and velocity errors, and the minimum inter-agent
//! distance vs time.

use super::input::Run;
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
    let area = frame(root, run, "maneuvers", "", bitmap)?;
    let disp = points(&run.t, &run.disp_err);
    let vel = points(&run.t, &run.vel_err);
    let dist = points(&run.t, &run.min_dist);
    let no_data = |label: &str, pts: &[(f64, f64)]| {
        if pts.is_empty() {
            format!("{label} (no data)")
        } else {
            label.to_string()
        }
    };
    let entries = vec![
        entry(
            no_data("leader displacement error |z − z*| (m)", &disp),
            Key::Line(colour(0), 2),
        ),
        entry(
            no_data("leader velocity error (m/s)", &vel),
            Key::Line(colour(1), 2),
        ),
        entry(
            no_data("min inter-agent distance (m)", &dist),
            Key::Line(colour(2), 2),
        ),
    ];
    let plot = with_legend(&area, &entries, bitmap)?;
    let (_, h) = plot.dim_in_pixel();
    let (upper, lower) = plot.split_vertically(h * 55 / 100);
    let (t0, t1) = time_range(&run.t);

    let (y0, y1) = lin_range(disp.iter().chain(&vel).map(|p| p.1).chain([0.0]));
    let mut chart = chart_on(&upper).build_cartesian_2d(t0..t1, y0..y1)?;
    styled_mesh(&mut chart.configure_mesh(), "leader error (m, m/s)").draw()?;
    stroke(chart.plotting_area(), &disp, colour(0), 2, false, bitmap)?;
    stroke(chart.plotting_area(), &vel, colour(1), 2, false, bitmap)?;

    let (y0, y1) = lin_range(dist.iter().map(|p| p.1).chain([0.0]));
    let mut chart = chart_on(&lower).build_cartesian_2d(t0..t1, y0..y1)?;
    styled_mesh(&mut chart.configure_mesh(), "min distance (m)").draw()?;
    stroke(chart.plotting_area(), &dist, colour(2), 2, false, bitmap)?;
    Ok(())
}
