//! `angle_errors`: |angle error| of every controlled angle (at most `MAX_ANGLES`) and
//! their maximum vs time, log scale, with the threshold line. Beyond ten angles the
//! `WORST_NAMED` largest at the end are drawn in colour and named, the others grey.

use super::input::Run;
use super::legend::{entry, with_legend, Key};
use super::ranges::*;
use super::style::*;
use super::text::frame;
use super::{DrawResult, ANGLE_FLOOR};
use plotters::coord::Shift;
use plotters::prelude::*;

/// The angles that are not named (beyond ten angles).
const OTHERS: RGBColor = RGBColor(185, 185, 185);

/// Draws the figure on `root`.
pub(super) fn draw<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    run: &Run,
    bitmap: bool,
) -> DrawResult
where
    DB::ErrorType: 'static,
{
    let many = run.angles.len() > 10;
    let mut notes = Vec::new();
    if run.angles.len() < run.n_angles {
        notes.push(format!(
            "{} of {} angles shown",
            run.angles.len(),
            run.n_angles
        ));
    }
    if many {
        notes.push(format!(
            "the {} largest at the end named",
            run.worst_angles.len()
        ));
    }
    let note = notes.join("; ");
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
        for (k, &i) in run.worst_angles.iter().enumerate() {
            entries.push(entry(
                format!("{} (worst #{})", run.angles[i].label, k + 1),
                Key::Line(colour(k), 2),
            ));
        }
        entries.push(entry(
            format!("{} other angles", run.angles.len() - run.worst_angles.len()),
            Key::Line(OTHERS, 1),
        ));
    }
    let coloured = if many {
        run.worst_angles.len()
    } else {
        run.angles.len()
    };
    if coloured > 1 {
        entries.push(entry(
            format!(
                "coloured lines side by side (offset up to ±{} px)",
                fan_offset(coloured - 1, coloured)
            ),
            Key::None,
        ));
    }
    if run.n_angles == 0 {
        entries.push(entry("(no angle columns)", Key::None));
    }
    let (line, window) = run.summary.angle_line();
    entries.push(entry(
        match window {
            None => format!("threshold {line:.0e} rad"),
            Some(w) => format!("band {line:.2e} rad (steady window from {w:.1} s)"),
        },
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
            .chain([line, line * 10.0]),
    );
    let mut chart = chart_on(&plot).build_cartesian_2d(t0..t1, (y0..y1).log_scale())?;
    styled_mesh(&mut chart.configure_mesh(), "|angle error| (rad)")
        .y_label_formatter(&log_label)
        .draw()?;

    if many {
        // The others thin and grey, then the worst on top in colour.
        for (i, pts) in series.iter().enumerate() {
            if !run.worst_angles.contains(&i) {
                stroke(chart.plotting_area(), pts, OTHERS, 1, false, bitmap)?;
            }
        }
        // The maximum under the worst (the worst #1 is the maximum at the end), the worst
        // side by side.
        stroke(chart.plotting_area(), &max_series, DARK, 3, false, bitmap)?;
        let named = run.worst_angles.len();
        for (k, &i) in run.worst_angles.iter().enumerate() {
            let offset = fan_offset(k, named);
            stroke_offset(
                chart.plotting_area(),
                &series[i],
                colour(k),
                2,
                offset,
                bitmap,
            )?;
        }
    } else {
        // The maximum under the angles, and the angles side by side: none hides another.
        stroke(chart.plotting_area(), &max_series, DARK, 3, false, bitmap)?;
        for (i, pts) in series.iter().enumerate() {
            let offset = fan_offset(i, series.len());
            stroke_offset(chart.plotting_area(), pts, colour(i), 2, offset, bitmap)?;
        }
    }
    let area = chart.plotting_area();
    let from = window.map_or(t0, |w| w.clamp(t0, t1));
    let threshold = [(from, line), (t1, line)];
    stroke(area, &threshold, LEADER, 2, true, bitmap)?;
    Ok(())
}
