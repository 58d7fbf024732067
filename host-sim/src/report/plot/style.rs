//! The house style: series colours, wide strokes without spikes, chart margins and
//! label areas, axis fonts and grid.

use super::{DrawResult, FONT};
use plotters::coord::{CoordTranslate, Shift};
use plotters::element::DashedPathElement;
use plotters::prelude::*;

/// Tableau 10 plus two darker colours: distinguishable series colours.
pub(super) const PALETTE: [RGBColor; 12] = [
    RGBColor(31, 119, 180),
    RGBColor(255, 127, 14),
    RGBColor(44, 160, 44),
    RGBColor(214, 39, 40),
    RGBColor(148, 103, 189),
    RGBColor(140, 86, 75),
    RGBColor(227, 119, 194),
    RGBColor(127, 127, 127),
    RGBColor(188, 189, 34),
    RGBColor(23, 190, 207),
    RGBColor(0, 70, 40),
    RGBColor(100, 0, 110),
];
pub(super) const LEADER: RGBColor = RGBColor(200, 0, 0);
pub(super) const DARK: RGBColor = RGBColor(20, 20, 20);

pub(super) fn colour(i: usize) -> RGBColor {
    PALETTE[i % PALETTE.len()]
}

/// A continuous colour scale for `f` in [0, 1] (five anchors of matplotlib's viridis,
/// linearly interpolated: dark blue → green → yellow), for colouring many agents by index.
pub(super) fn ramp(f: f64) -> RGBColor {
    const ANCHORS: [(f64, f64, f64); 5] = [
        (68.0, 1.0, 84.0),
        (59.0, 82.0, 139.0),
        (33.0, 145.0, 140.0),
        (94.0, 201.0, 98.0),
        (253.0, 231.0, 37.0),
    ];
    let x = if f.is_finite() {
        f.clamp(0.0, 1.0)
    } else {
        0.0
    } * 4.0;
    let k = (x.floor() as usize).min(3);
    let u = x - k as f64;
    let (a, b) = (ANCHORS[k], ANCHORS[k + 1]);
    let mix = |p: f64, q: f64| (p + (q - p) * u).round() as u8;
    RGBColor(mix(a.0, b.0), mix(a.1, b.1), mix(a.2, b.2))
}

/// Draws the polyline `pts` (in `area`'s coordinates), `width` pixels wide,
/// solid or dashed.
///
/// On bitmaps a wide line is drawn as `width × width` one-pixel lines offset
/// by a pixel each: plotters fills wide polylines as one polygon whose inner
/// corners grow long spikes wherever the line turns sharply (a jump, a dip
/// on a log axis). SVG strokes are drawn by the viewer and are fine.
pub(super) fn stroke<DB, CT>(
    area: &DrawingArea<DB, CT>,
    pts: &[CT::From],
    colour: RGBColor,
    width: u32,
    dashed: bool,
    bitmap: bool,
) -> DrawResult
where
    DB: DrawingBackend,
    DB::ErrorType: 'static,
    CT: CoordTranslate,
    CT::From: Clone,
{
    if pts.len() < 2 {
        return Ok(());
    }
    if !bitmap || width <= 1 {
        let style = colour.stroke_width(width);
        if dashed {
            area.draw(&DashedPathElement::new(pts.to_vec(), DASH.0, DASH.1, style))?;
        } else {
            area.draw(&PathElement::new(pts.to_vec(), style))?;
        }
        return Ok(());
    }
    let (pixels, base) = pixel_path(area, pts);
    draw_wide(&pixels, &base, colour, width, dashed)
}

/// Dash and gap lengths (pixels) of a dashed stroke.
const DASH: (i32, i32) = (9, 6);

/// `pts` in the pixels of `area`'s backend (relative to its base pixel, repeats in a row
/// dropped), and that backend's area.
fn pixel_path<DB, CT>(
    area: &DrawingArea<DB, CT>,
    pts: &[CT::From],
) -> (DrawingArea<DB, Shift>, Vec<(i32, i32)>)
where
    DB: DrawingBackend,
    CT: CoordTranslate,
{
    let pixels = area.strip_coord_spec();
    let (bx, by) = pixels.get_base_pixel();
    let mut path: Vec<(i32, i32)> = pts
        .iter()
        .map(|p| {
            let (x, y) = area.map_coordinate(p);
            (x - bx, y - by)
        })
        .collect();
    path.dedup();
    (pixels, path)
}

/// The pixel polyline `path` drawn as `width × width` one-pixel lines offset by a pixel
/// each (see [`stroke`]), solid or dashed.
fn draw_wide<DB>(
    pixels: &DrawingArea<DB, Shift>,
    path: &[(i32, i32)],
    colour: RGBColor,
    width: u32,
    dashed: bool,
) -> DrawResult
where
    DB: DrawingBackend,
    DB::ErrorType: 'static,
{
    let w = i32::try_from(width).unwrap_or(1);
    let lo = -(w - 1) / 2;
    let style = colour.stroke_width(1);
    for dx in lo..lo + w {
        for dy in lo..lo + w {
            let shifted: Vec<(i32, i32)> = path.iter().map(|&(x, y)| (x + dx, y + dy)).collect();
            if dashed {
                pixels.draw(&DashedPathElement::new(shifted, DASH.0, DASH.1, style))?;
            } else {
                pixels.draw(&PathElement::new(shifted, style))?;
            }
        }
    }
    Ok(())
}

/// The pixel offset of line `i` of `n` that [`stroke_offset`] draws side by side:
/// `2 i − (n − 1)` pixels (−9 … 9 for ten lines), so that ten 2-pixel lines over the same
/// data lie next to each other instead of on top of each other.
pub(super) fn fan_offset(i: usize, n: usize) -> i32 {
    let i = i32::try_from(i).unwrap_or(0);
    let n = i32::try_from(n).unwrap_or(1);
    2 * i - (n - 1)
}

/// [`stroke`] shifted by `offset` pixels along the line's normal (in pixels, at every
/// point the normal of the chord between its neighbours): lines over the same data stay
/// visible side by side (see [`fan_offset`]).
pub(super) fn stroke_offset<DB, CT>(
    area: &DrawingArea<DB, CT>,
    pts: &[CT::From],
    colour: RGBColor,
    width: u32,
    offset: i32,
    bitmap: bool,
) -> DrawResult
where
    DB: DrawingBackend,
    DB::ErrorType: 'static,
    CT: CoordTranslate,
    CT::From: Clone,
{
    if pts.len() < 2 {
        return Ok(());
    }
    let (pixels, base) = pixel_path(area, pts);
    let last = base.len().saturating_sub(1);
    let mut normal = (0.0, -1.0);
    let shifted: Vec<(i32, i32)> = (0..base.len())
        .map(|k| {
            let (a, b) = (base[k.saturating_sub(1)], base[(k + 1).min(last)]);
            let (dx, dy) = (f64::from(b.0 - a.0), f64::from(b.1 - a.1));
            let len = dx.hypot(dy);
            if len > 0.0 {
                normal = (-dy / len, dx / len);
            }
            let o = f64::from(offset);
            (
                base[k].0 + (normal.0 * o).round() as i32,
                base[k].1 + (normal.1 * o).round() as i32,
            )
        })
        .collect();
    if !bitmap || width <= 1 {
        return Ok(pixels.draw(&PathElement::new(shifted, colour.stroke_width(width)))?);
    }
    draw_wide(&pixels, &shifted, colour, width, false)
}

pub(super) const CHART_MARGIN: u32 = 14;
pub(super) const X_LABEL_AREA: u32 = 56;
pub(super) const Y_LABEL_AREA: u32 = 96;

/// A chart builder on `area` with the house margins and label areas.
pub(super) fn chart_on<'a, 'b, DB: DrawingBackend>(
    area: &'a DrawingArea<DB, Shift>,
) -> ChartBuilder<'a, 'b, DB> {
    let mut builder = ChartBuilder::on(area);
    builder
        .margin(CHART_MARGIN)
        .x_label_area_size(X_LABEL_AREA)
        .y_label_area_size(Y_LABEL_AREA);
    builder
}

/// A chart in metres on both axes.
pub(super) type PlanView<'a, DB> = ChartContext<
    'a,
    DB,
    Cartesian2d<plotters::coord::types::RangedCoordf64, plotters::coord::types::RangedCoordf64>,
>;

/// A plan view on `area`: a chart whose axes cover `x` and `y` (value ranges) with one
/// metre the same length on both, centred on them, and the house mesh with the axis
/// descriptions `x_desc` and `y_desc`.
pub(super) fn plan_view<'a, DB: DrawingBackend>(
    area: &'a DrawingArea<DB, Shift>,
    (x0, x1): (f64, f64),
    (y0, y1): (f64, f64),
    (x_desc, y_desc): (&str, &str),
) -> Result<PlanView<'a, DB>, Box<dyn std::error::Error>>
where
    DB::ErrorType: 'static,
{
    let (w, h) = area.dim_in_pixel();
    let pw = f64::from(w.saturating_sub(2 * CHART_MARGIN + Y_LABEL_AREA).max(1));
    let ph = f64::from(h.saturating_sub(2 * CHART_MARGIN + X_LABEL_AREA).max(1));
    let scale = ((x1 - x0) / pw).max((y1 - y0) / ph);
    let (cx, cy) = ((x0 + x1) / 2.0, (y0 + y1) / 2.0);
    let (hx, hy) = (scale * pw / 2.0, scale * ph / 2.0);
    let mut chart = chart_on(area).build_cartesian_2d(cx - hx..cx + hx, cy - hy..cy + hy)?;
    chart
        .configure_mesh()
        .x_desc(x_desc)
        .y_desc(y_desc)
        .label_style(label_style())
        .axis_desc_style(desc_style())
        .bold_line_style(BLACK.mix(0.12))
        .light_line_style(BLACK.mix(0.04))
        .draw()?;
    Ok(chart)
}

/// The house style of every time-series panel's mesh: axis descriptions, fonts, grid.
pub(super) fn styled_mesh<'m, 'a, 'b, X, Y, XT, YT, DB>(
    mesh: &'m mut plotters::chart::MeshStyle<'a, 'b, X, Y, DB>,
    y_desc: &str,
) -> &'m mut plotters::chart::MeshStyle<'a, 'b, X, Y, DB>
where
    X: plotters::coord::ranged1d::Ranged<ValueType = XT>
        + plotters::coord::ranged1d::ValueFormatter<XT>,
    Y: plotters::coord::ranged1d::Ranged<ValueType = YT>
        + plotters::coord::ranged1d::ValueFormatter<YT>,
    DB: DrawingBackend,
{
    mesh.x_desc("time t (s)")
        .y_desc(y_desc)
        .label_style(label_style())
        .axis_desc_style(desc_style())
        .bold_line_style(BLACK.mix(0.12))
        .light_line_style(BLACK.mix(0.04))
}

pub(super) fn label_style() -> TextStyle<'static> {
    (FONT, 15).into_font().color(&BLACK)
}

pub(super) fn desc_style() -> TextStyle<'static> {
    (FONT, 18).into_font().color(&BLACK)
}

/// Writes each agent's id up and right of its point, when there are at most
/// [`super::MAX_LABELLED_AGENTS`] agents (points that are not finite are skipped).
pub(super) fn agent_ids<DB: DrawingBackend>(
    chart: &mut PlanView<'_, DB>,
    pts: &[(f64, f64)],
    ids: &[String],
    bitmap: bool,
) -> DrawResult
where
    DB::ErrorType: 'static,
{
    if ids.len() > super::MAX_LABELLED_AGENTS {
        return Ok(());
    }
    let font = TextStyle::from((FONT, 17).into_font()).color(&BLACK);
    chart.draw_series(
        pts.iter()
            .zip(ids)
            .filter(|(p, _)| p.0.is_finite() && p.1.is_finite())
            .map(|(p, id)| {
                EmptyElement::at(*p)
                    + Text::new(super::text::drawable(id, bitmap), (7, -20), font.clone())
            }),
    )?;
    Ok(())
}
