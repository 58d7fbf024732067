//! A generic x–y figure for tools above the reports (sweeps): lines of points with
//! vertical error bars in one or more panels sharing the x axis, numeric or categorical x, written as PNG and SVG in the house
//! style (title block, legend panel, fonts, strokes).

use super::legend::{entry, with_legend, Key};
use super::ranges::{lin_range, sane};
use super::style::{chart_on, colour, desc_style, label_style, stroke};
use super::text::{drawable, fit_text};
use super::{ensure_font, DrawResult, PlotError, FONT, IMAGE_SIZE};
use plotters::coord::Shift;
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};
use std::path::{Path, PathBuf};

/// One point: `x`, `y` and its error bar `[lo, hi]` (equal to `y` for none).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct XyPoint {
    /// Abscissa (the category's index for a categorical axis).
    pub x: f64,
    /// Value.
    pub y: f64,
    /// Lower end of the error bar.
    pub lo: f64,
    /// Upper end of the error bar.
    pub hi: f64,
}

/// One series (the same series, in the same order, in every panel: colour `i` is
/// series `i`, and the legend names the first panel's).
#[derive(Clone, Debug, PartialEq)]
pub struct XyLine {
    /// Legend label.
    pub label: String,
    /// Points, in x order.
    pub points: Vec<XyPoint>,
    /// Join the points by a line (else markers only).
    pub join: bool,
}

/// One panel: its y axis and its series.
#[derive(Clone, Debug, PartialEq)]
pub struct XyPanel {
    /// Y axis description (names the panel).
    pub y_label: String,
    /// Fixed y range (else fitted to the data and error bars).
    pub y_range: Option<(f64, f64)>,
    /// The series.
    pub lines: Vec<XyLine>,
}

/// A whole figure: panels sharing the x axis (one column up to two panels, else two),
/// and one legend.
#[derive(Clone, Debug, PartialEq)]
pub struct XyChart {
    /// First title line.
    pub title: String,
    /// Second line (grey).
    pub subtitle: String,
    /// X axis description.
    pub x_label: String,
    /// Names of the x categories (x = 0, 1, …), for a categorical axis.
    pub categories: Option<Vec<String>>,
    /// The panels (at least one).
    pub panels: Vec<XyPanel>,
}

/// Draws `chart` into `dir/<stem>.png` and `.svg`; returns both paths.
pub fn plot_xy(dir: &Path, stem: &str, chart: &XyChart) -> Result<Vec<PathBuf>, PlotError> {
    ensure_font()?;
    let draw_err = |path: &Path, e: &dyn std::fmt::Display| PlotError::Draw {
        path: path.to_path_buf(),
        reason: e.to_string(),
    };
    let png = dir.join(format!("{stem}.png"));
    super::write_png(&png, IMAGE_SIZE, |root| draw(root, chart, true))
        .map_err(|e| draw_err(&png, &e))?;
    let svg = dir.join(format!("{stem}.svg"));
    {
        let root = SVGBackend::new(&svg, IMAGE_SIZE).into_drawing_area();
        draw(&root, chart, false).map_err(|e| draw_err(&svg, &e))?;
        root.present().map_err(|e| draw_err(&svg, &e))?;
    }
    Ok(vec![png, svg])
}

/// A tick label: three decimals at most, trailing zeros dropped (`0.15`, not
/// `0.15000000000000002`).
fn tick(x: f64) -> String {
    let s = format!("{x:.3}");
    let s = s.trim_end_matches('0').trim_end_matches('.');
    if s == "-0" {
        "0".to_owned()
    } else {
        s.to_owned()
    }
}

fn draw<DB: DrawingBackend>(root: &DrawingArea<DB, Shift>, c: &XyChart, bitmap: bool) -> DrawResult
where
    DB::ErrorType: 'static,
{
    root.fill(&WHITE)?;
    let (w, _) = root.dim_in_pixel();
    let centre = Pos::new(HPos::Center, VPos::Center);
    let title_font = TextStyle::from((FONT, 24).into_font());
    let title = fit_text(root, &drawable(&c.title, bitmap), &title_font, w - 24)?;
    root.draw(&Text::new(
        title,
        (w as i32 / 2, 24),
        title_font.color(&BLACK).pos(centre),
    ))?;
    let sub_font = TextStyle::from((FONT, 16).into_font());
    let sub = fit_text(root, &drawable(&c.subtitle, bitmap), &sub_font, w - 24)?;
    root.draw(&Text::new(
        sub,
        (w as i32 / 2, 56),
        sub_font.color(&RGBColor(80, 80, 80)).pos(centre),
    ))?;
    let area = root.split_vertically(80).1;

    let first = c.panels.first().map_or(&[][..], |p| &p.lines[..]);
    let entries: Vec<_> = first
        .iter()
        .enumerate()
        .map(|(i, l)| entry(l.label.clone(), Key::Line(colour(i), 2)))
        .collect();
    let plot = with_legend(&area, &entries, bitmap)?;
    let n = c.panels.len().max(1);
    let cols = if n <= 2 { 1 } else { 2 };
    let cells = plot.split_evenly((n.div_ceil(cols), cols));
    let xs = || {
        c.panels
            .iter()
            .flat_map(|p| p.lines.iter().flat_map(|l| l.points.iter().map(|q| q.x)))
    };
    let (x0, x1) = match &c.categories {
        Some(k) => (-0.5, k.len().max(1) as f64 - 0.5),
        None => lin_range(xs()),
    };
    for (panel, cell) in c.panels.iter().zip(&cells) {
        draw_panel(cell, c, panel, (x0, x1), bitmap)?;
    }
    Ok(())
}

fn draw_panel<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    c: &XyChart,
    panel: &XyPanel,
    (x0, x1): (f64, f64),
    bitmap: bool,
) -> DrawResult
where
    DB::ErrorType: 'static,
{
    let all = || panel.lines.iter().flat_map(|l| l.points.iter());
    let (y0, y1) = panel
        .y_range
        .unwrap_or_else(|| lin_range(all().flat_map(|p| [p.y, p.lo, p.hi])));
    let mut chart = chart_on(area).build_cartesian_2d(x0..x1, y0..y1)?;
    let cats = c.categories.clone().unwrap_or_default();
    let x_fmt = |x: &f64| {
        if c.categories.is_none() {
            return tick(*x);
        }
        let k = x.round();
        if (x - k).abs() < 1e-6 && k >= 0.0 {
            cats.get(k as usize).cloned().unwrap_or_default()
        } else {
            String::new()
        }
    };
    let mut mesh = chart.configure_mesh();
    mesh.x_desc(drawable(&c.x_label, bitmap))
        .y_desc(drawable(&panel.y_label, bitmap))
        .label_style(label_style())
        .axis_desc_style(desc_style())
        .bold_line_style(BLACK.mix(0.12))
        .light_line_style(BLACK.mix(0.04))
        .x_label_formatter(&x_fmt)
        .y_label_formatter(&|y: &f64| tick(*y));
    if let Some(k) = &c.categories {
        mesh.x_labels(k.len() * 4 + 1);
    }
    mesh.draw()?;
    // A small horizontal offset per series keeps overlapping error bars apart (all
    // offsets within 6 % of the x span); none in a panel without error bars, whose x
    // is exact (time series held side by side, `host-sim compare`).
    let nl = panel.lines.len().max(1) as f64;
    let bars = all().any(|p| sane(p.lo) && sane(p.hi) && p.hi > p.lo);
    let step = if bars {
        (x1 - x0) * (0.06 / nl).min(0.006)
    } else {
        0.0
    };
    for (i, l) in panel.lines.iter().enumerate() {
        let col = colour(i);
        let dx = step * (i as f64 - (nl - 1.0) / 2.0);
        let shown: Vec<&XyPoint> = l.points.iter().filter(|p| sane(p.x) && sane(p.y)).collect();
        if l.join {
            let pts: Vec<(f64, f64)> = shown.iter().map(|p| (p.x + dx, p.y)).collect();
            stroke(chart.plotting_area(), &pts, col, 2, false, bitmap)?;
        }
        for p in shown {
            let x = p.x + dx;
            if sane(p.lo) && sane(p.hi) && p.hi > p.lo {
                chart.draw_series(std::iter::once(PathElement::new(
                    vec![(x, p.lo), (x, p.hi)],
                    col.stroke_width(1),
                )))?;
            }
            chart.draw_series(std::iter::once(Circle::new((x, p.y), 3, col.filled())))?;
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn line(label: &str, pts: &[(f64, f64)]) -> XyLine {
        XyLine {
            label: label.to_owned(),
            points: pts
                .iter()
                .map(|&(x, y)| XyPoint {
                    x,
                    y,
                    lo: y - 0.1,
                    hi: y + 0.1,
                })
                .collect(),
            join: true,
        }
    }

    #[test]
    fn ticks_are_short() {
        assert_eq!(tick(0.15000000000000002), "0.15");
        assert_eq!(tick(2.0), "2");
        assert_eq!(tick(-0.0001), "0");
        assert_eq!(tick(12.3456), "12.346");
    }

    #[test]
    fn numeric_and_categorical_figures_are_written() {
        let dir = tempfile::tempdir().unwrap();
        // A NaN point (no run at that point) is skipped, not drawn.
        let panel = |y: &str| XyPanel {
            y_label: y.to_owned(),
            y_range: Some((0.0, 1.0)),
            lines: vec![line("loss", &[(0.0, 1.0), (0.1, f64::NAN), (0.2, 0.5)])],
        };
        let numeric = XyChart {
            title: "t".to_owned(),
            subtitle: "s".to_owned(),
            x_label: "radio.loss".to_owned(),
            categories: None,
            panels: vec![panel("converged"), panel("collision"), panel("diverged")],
        };
        let files = plot_xy(dir.path(), "numeric", &numeric).unwrap();
        let categorical = XyChart {
            categories: Some(vec!["continuous".to_owned(), "sampled".to_owned()]),
            panels: vec![XyPanel {
                y_label: "settle time (s)".to_owned(),
                y_range: None,
                lines: vec![line("a", &[(0.0, 3.0), (1.0, 4.0)]), line("b", &[])],
            }],
            ..numeric
        };
        let more = plot_xy(dir.path(), "categorical", &categorical).unwrap();
        for f in files.iter().chain(&more) {
            assert!(
                std::fs::metadata(f).unwrap().len() > 1000,
                "{}",
                f.display()
            );
        }
        let svg = std::fs::read_to_string(dir.path().join("categorical.svg")).unwrap();
        assert!(svg.contains("continuous") && svg.contains("sampled"));
        let svg = std::fs::read_to_string(dir.path().join("numeric.svg")).unwrap();
        assert!(
            svg.contains("converged") && svg.contains("diverged"),
            "a panel per outcome"
        );
    }
}
