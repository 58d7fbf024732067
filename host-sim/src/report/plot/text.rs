//! Text on the figures: what the bitmap renderer can draw, fitting and wrapping, and
//! the title block (scenario, figure, outcome, reason, settings) of every figure.

use super::input::Run;
use super::FONT;
use plotters::coord::Shift;
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};
use std::error::Error as StdError;

/// `text` as it can be drawn: plotters' bitmap text renderer has no
/// shaping, so a combining mark lands after its letter instead of on it.
/// For bitmaps a combining circumflex is spelled out ("r̂" → "rhat") and other
/// combining marks are dropped; SVG text is drawn by the viewer and kept.
pub(super) fn drawable(text: &str, bitmap: bool) -> String {
    if !bitmap {
        return text.to_string();
    }
    let mut out = String::with_capacity(text.len());
    for c in text.chars() {
        match c {
            '\u{302}' => out.push_str("hat"),
            '\u{300}'..='\u{36f}' => {}
            _ => out.push(c),
        }
    }
    out
}

/// `text`, shortened with "…" until it fits in `max_w` pixels.
pub(super) fn fit_text<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    text: &str,
    font: &TextStyle<'_>,
    max_w: u32,
) -> Result<String, Box<dyn StdError>>
where
    DB::ErrorType: 'static,
{
    if area.estimate_text_size(text, font)?.0 <= max_w {
        return Ok(text.to_string());
    }
    let chars: Vec<char> = text.chars().collect();
    for n in (0..chars.len()).rev() {
        let s: String = chars[..n].iter().chain(std::iter::once(&'…')).collect();
        if area.estimate_text_size(&s, font)?.0 <= max_w {
            return Ok(s);
        }
    }
    Ok("…".to_string())
}

/// `text` broken at spaces into at most `max_lines` lines of at most `max_w`
/// pixels; the last line ends in "…" if text is left over.
pub(super) fn wrap<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    text: &str,
    font: &TextStyle<'_>,
    max_w: u32,
    max_lines: usize,
) -> Result<Vec<String>, Box<dyn StdError>>
where
    DB::ErrorType: 'static,
{
    let mut lines: Vec<String> = Vec::new();
    let mut current = String::new();
    let mut words = text.split(' ').peekable();
    while let Some(word) = words.next() {
        let candidate = if current.is_empty() {
            word.to_string()
        } else {
            format!("{current} {word}")
        };
        if current.is_empty() || area.estimate_text_size(&candidate, font)?.0 <= max_w {
            current = candidate;
            continue;
        }
        if lines.len() + 1 == max_lines {
            // Last line: take the rest and cut it to fit.
            let rest: Vec<&str> = std::iter::once(word).chain(words).collect();
            current = format!("{current} {}", rest.join(" "));
            break;
        }
        lines.push(std::mem::replace(&mut current, word.to_string()));
    }
    lines.push(current);
    lines
        .into_iter()
        .map(|l| fit_text(area, &l, font, max_w))
        .collect()
}

pub(super) fn json_text(v: &serde_json::Value) -> String {
    match v {
        serde_json::Value::String(s) => s.clone(),
        other => other.to_string(),
    }
}

/// Fills the figure white, draws the title (scenario, figure name, outcome,
/// optional note) and the subtitle, and returns the area below them.
pub(super) fn frame<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    run: &Run,
    what: &str,
    note: &str,
    bitmap: bool,
) -> Result<DrawingArea<DB, Shift>, Box<dyn StdError>>
where
    DB::ErrorType: 'static,
{
    root.fill(&WHITE)?;
    let (w, _) = root.dim_in_pixel();
    let s = &run.summary;
    let mut title = format!("{} — {} — outcome: {}", s.scenario, what, s.outcome);
    if !note.is_empty() {
        title.push_str(&format!(" ({note})"));
    }
    // Shrink the title font until it fits (down to 14 px).
    let mut size = 26u32;
    while size > 14 && root.estimate_text_size(&title, &(FONT, size).into())?.0 > w - 24 {
        size -= 1;
    }
    let title_font = TextStyle::from((FONT, size).into_font());
    let title = fit_text(root, &drawable(&title, bitmap), &title_font, w - 24)?;
    let centre = Pos::new(HPos::Center, VPos::Center);
    root.draw(&Text::new(
        title,
        (w as i32 / 2, 24),
        title_font.color(&BLACK).pos(centre),
    ))?;

    // Subtitle: the outcome reason, then the run's settings.
    let sub_font = TextStyle::from((FONT, 16).into_font());
    let mut lines = Vec::new();
    match s.outcome_reason.as_deref() {
        Some(r) if !r.is_empty() => {
            let reason = drawable(&format!("{}: {r}", s.outcome), bitmap);
            lines = wrap(root, &reason, &sub_font, w - 24, 2)?;
        }
        _ => {}
    }
    let mut parts = Vec::new();
    if let Some(m) = &s.mode {
        parts.push(format!("mode: {}", json_text(m)));
    }
    if let Some(e) = &s.estimator {
        parts.push(format!("estimator: {}", json_text(e)));
    }
    parts.push(format!(
        "{} agents, {} edges",
        run.agent_ids.len(),
        s.edges.len()
    ));
    lines.push(drawable(&parts.join("  ·  "), bitmap));
    for (i, line) in lines.iter().enumerate() {
        let line = fit_text(root, line, &sub_font, w - 24)?;
        root.draw(&Text::new(
            line,
            (w as i32 / 2, 56 + 22 * i as i32),
            sub_font.color(&RGBColor(80, 80, 80)).pos(centre),
        ))?;
    }
    let header_h = 46 + 22 * lines.len() as u32 + 14;
    Ok(root.split_vertically(header_h).1)
}
