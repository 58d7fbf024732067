//! `angle_errors`: |angle error| of every controlled angle (at most `MAX_ANGLES`) and
//! their maximum vs time, log scale, with the threshold line.

use super::input::Run;
use super::legend::{entry, with_legend, Key};
use super::ranges::*;
use super::style::*;
use super::text::frame;
use super::{DrawResult, ANGLE_FLOOR, ANGLE_THRESHOLD};
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
    let note = if run.angles.len() < run.n_angles {
        format!("{} of {} angles shown", run.angles.len(), run.n_angles)
    } else {
        String::new()
    };
    let area = frame(root, run, "angle errors", &note, bitmap)?;

    let series: Vec<Vec<(f64, f64)>> = run
        .angles
        .iter()
        .map(|a| log_points(&run.t, &a.values, ANGLE_FLOOR))
        .collect();
    let max_series = log_points(&run.t, &run.max_angle_err, ANGLE_FLOOR);

    let mut entries = vec![entry("max over all angles", Key::Line(DARK, 3))];
    if run.angles.len() <= 10 {
        for (i, a) in run.angles.iter().enumerate() {
            entries.push(entry(a.label.clone(), Key::Line(colour(i), 2)));
        }
    } else {
        entries.push(entry(
            format!("{} individual angles", run.angles.len()),
            Key::Line(colour(0), 1),
        ));
    }
    if run.n_angles == 0 {
        entries.push(entry("(no angle columns)", Key::None));
    }
    entries.push(entry(
        format!("threshold {ANGLE_THRESHOLD:.0e} rad"),
        Key::Dashed(LEADER, 2),
    ));
    entries.push(entry(
        format!("values < {ANGLE_FLOOR:.0e} drawn at it"),
        Key::None,
    ));
    let plot = with_legend(&area, &entries, bitmap)?;

    let (t0, t1) = time_range(&run.t);
    let (y0, y1) = log_range(
        series
            .iter()
            .flatten()
            .chain(&max_series)
            .map(|p| p.1)
            .chain([ANGLE_THRESHOLD, ANGLE_THRESHOLD * 10.0]),
    );
    let mut chart = chart_on(&plot).build_cartesian_2d(t0..t1, (y0..y1).log_scale())?;
    styled_mesh(&mut chart.configure_mesh(), "|angle error| (rad)")
        .y_label_formatter(&log_label)
        .draw()?;

    let width = if run.angles.len() > 10 { 1 } else { 2 };
    for (i, pts) in series.into_iter().enumerate() {
        stroke(chart.plotting_area(), &pts, colour(i), width, false, bitmap)?;
    }
    let area = chart.plotting_area();
    stroke(area, &max_series, DARK, 3, false, bitmap)?;
    let threshold = [(t0, ANGLE_THRESHOLD), (t1, ANGLE_THRESHOLD)];
    stroke(area, &threshold, LEADER, 2, true, bitmap)?;
    Ok(())
}
