//! The legend panel to the right of every plot.

use super::text::{drawable, fit_text};
use super::{DrawResult, FONT};
use plotters::coord::Shift;
use plotters::element::DashedPathElement;
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};
use std::error::Error as StdError;

/// How a legend entry's key is drawn.
pub(super) enum Key {
    Line(RGBColor, u32),
    Dashed(RGBColor, u32),
    /// An edge with a node at each end.
    Net(RGBColor),
    Triangle(RGBColor),
    /// The colour scale [`super::style::ramp`] from 0 (left) to 1 (right): a colour bar.
    Ramp,
    /// No key (a note line).
    None,
}

pub(super) struct Entry {
    pub(super) label: String,
    pub(super) key: Key,
}

pub(super) fn entry(label: impl Into<String>, key: Key) -> Entry {
    Entry {
        label: label.into(),
        key,
    }
}

pub(super) const LEGEND_FONT: u32 = 15;
pub(super) const LEGEND_ROW: i32 = 24;
pub(super) const LEGEND_KEY_W: i32 = 34;

/// Splits `area` into the plot (left) and a legend panel (right) wide enough
/// for the entries' labels (within limits), and draws the legend.
pub(super) fn with_legend<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    entries: &[Entry],
    bitmap: bool,
) -> Result<DrawingArea<DB, Shift>, Box<dyn StdError>>
where
    DB::ErrorType: 'static,
{
    let (w, _) = area.dim_in_pixel();
    let font = TextStyle::from((FONT, LEGEND_FONT).into_font());
    let mut text_w = 0u32;
    for e in entries {
        text_w = text_w.max(area.estimate_text_size(&e.label, &font)?.0);
    }
    let max_w = w / 3;
    let legend_w = (text_w + LEGEND_KEY_W as u32 + 40).clamp(170, max_w);
    let (plot, legend) = area.split_horizontally(w - legend_w);
    let labels: Vec<String> = entries.iter().map(|e| drawable(&e.label, bitmap)).collect();
    draw_legend(
        &legend,
        entries,
        &labels,
        legend_w - LEGEND_KEY_W as u32 - 40,
    )?;
    Ok(plot)
}

pub(super) fn draw_legend<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    entries: &[Entry],
    labels: &[String],
    max_text_w: u32,
) -> DrawResult
where
    DB::ErrorType: 'static,
{
    let (w, h) = area.dim_in_pixel();
    let font = TextStyle::from((FONT, LEGEND_FONT).into_font());
    let text_style = font.color(&BLACK).pos(Pos::new(HPos::Left, VPos::Center));
    let top = 20;
    let rows = ((h as i32 - top - 20) / LEGEND_ROW).max(1) as usize;
    let shown = entries.len().min(rows);
    let box_h = shown as i32 * LEGEND_ROW + 12;
    area.draw(&Rectangle::new(
        [(4, top - 8), (w as i32 - 12, top - 8 + box_h)],
        ShapeStyle::from(&BLACK.mix(0.35)).stroke_width(1),
    ))?;
    for (i, e) in entries.iter().take(shown).enumerate() {
        let y = top + i as i32 * LEGEND_ROW + LEGEND_ROW / 2 - 2;
        let (x0, x1) = (12, 12 + LEGEND_KEY_W - 6);
        match e.key {
            Key::Line(c, width) => {
                area.draw(&PathElement::new(
                    vec![(x0, y), (x1, y)],
                    c.stroke_width(width),
                ))?;
            }
            Key::Dashed(c, width) => {
                area.draw(&DashedPathElement::new(
                    vec![(x0, y), (x1, y)],
                    7,
                    4,
                    c.stroke_width(width),
                ))?;
            }
            Key::Net(c) => {
                area.draw(&PathElement::new(
                    vec![(x0 + 3, y), (x1 - 3, y)],
                    c.stroke_width(1),
                ))?;
                area.draw(&Circle::new((x0 + 3, y), 3, c.filled()))?;
                area.draw(&Circle::new((x1 - 3, y), 3, c.filled()))?;
            }
            Key::Triangle(c) => {
                area.draw(&TriangleMarker::new(((x0 + x1) / 2, y), 7, c.filled()))?;
            }
            Key::Ramp => {
                let steps = 16;
                for k in 0..steps {
                    let xa = x0 + (x1 - x0) * k / steps;
                    let xb = x0 + (x1 - x0) * (k + 1) / steps;
                    let c = super::style::ramp(f64::from(k) / f64::from(steps - 1));
                    area.draw(&Rectangle::new([(xa, y - 6), (xb, y + 6)], c.filled()))?;
                }
            }
            Key::None => {}
        }
        let label = if i + 1 == shown && shown < entries.len() {
            format!("… and {} more", entries.len() - shown + 1)
        } else {
            fit_text(area, &labels[i], &font, max_text_w)?
        };
        let x = if matches!(e.key, Key::None) {
            x0
        } else {
            x1 + 8
        };
        area.draw(&Text::new(label, (x, y), text_style.clone()))?;
    }
    Ok(())
}
