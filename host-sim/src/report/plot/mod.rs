//! Plots of one simulator run, and a generic x–y figure ([`plot_xy`], for sweeps).
//!
//! [`plot_run`] reads `timeseries.csv` and `summary.json` from a run directory
//! and writes five figures next to them, each as PNG (1200×900) and SVG:
//!
//! | file | content |
//! | --- | --- |
//! | `trajectories` | x–y path of every agent (at most [`MAX_AGENT_PATHS`]), formation snapshots (graph edges between agent positions) at five times from start to end, leaders marked; equal aspect ratio |
//! | `angle_errors` | \|angle error\| of every controlled angle (at most [`MAX_ANGLES`], the [`WORST_NAMED`] worst at the end always, named) and their maximum vs time, log scale, with the [`ANGLE_THRESHOLD`] line |
//! | `energy` | V and its terms V_kin, V_ang, V_lead, V_est vs time, log scale |
//! | `estimates` | each distance estimate r̂ (solid) against its true distance r (dashed), at most [`MAX_ESTIMATES`] (the worst at the end) |
//! | `maneuvers` | leader displacement and velocity errors, and the minimum inter-agent distance vs time |
//! | `shape` | the final formation, fitted onto its target shape (translation, rotation, scale, mirror), over the target; folded triangles marked |
//!
//! Every figure has the scenario name and outcome in its title, a subtitle
//! with the outcome reason, mode and estimator, axis labels and a legend in a
//! panel to the right of the plot.
//!
//! Text is rendered with DejaVu Sans embedded in the binary
//! (`host-sim/assets/DejaVuSans.ttf`), so no system font library is needed.
//!
//! Large runs are thinned while reading: the CSV is read twice (once to count
//! the rows, once to keep an evenly spaced subset of at most [`MAX_POINTS`]
//! rows, always including the first and last), and only the columns that are
//! drawn are kept in memory. Non-finite values (and absurd ones, beyond
//! ±1e100) are skipped when drawing; rows whose `t` is not finite are skipped
//! altogether.

mod angle_errors;
mod energy;
mod error;
mod estimates;
mod formation;
mod input;
mod legend;
mod maneuvers;
mod ranges;
mod shape;
mod style;
#[cfg(test)]
mod tests;
#[cfg(test)]
mod tests_legible;
mod text;
mod thinning;
mod trajectories;
mod xy;

pub use error::PlotError;
pub use formation::{plot_formation, MAX_LABELLED_AGENTS};
pub(crate) use thinning::spread;
pub use xy::{plot_xy, XyChart, XyLine, XyPanel, XyPoint};

use crate::report::TimeSeries;
use input::{load_run, Run};
use plotters::coord::Shift;
use plotters::prelude::*;
use plotters::style::FontStyle;
use std::error::Error as StdError;
use std::path::{Path, PathBuf};
use std::sync::OnceLock;

/// One plotted line: `(t, value)` points.
type Series = Vec<(f64, f64)>;

/// At most this many rows (points per series) are kept from `timeseries.csv`.
pub const MAX_POINTS: usize = 2000;
/// Runs with more agents than this draw the paths of an evenly spaced subset
/// of this many agents (plus the leaders); formation snapshots still show all.
pub const MAX_AGENT_PATHS: usize = 50;
/// Runs with more controlled angles than this draw an evenly spaced subset of
/// this many angle errors (the maximum over all angles is always drawn).
pub const MAX_ANGLES: usize = 50;
/// Runs with more than this many angles (or estimates) name only the worst ones at the
/// end of the run in the legend: the largest |angle error|, the estimates farthest from
/// their true distance.
pub const WORST_NAMED: usize = 5;
/// At most this many estimates are drawn: all when there are no more, else the ones
/// farthest from their true distance at the end of the run.
pub const MAX_ESTIMATES: usize = 12;
/// |angle error| values below this (including exact zeros) are drawn at it.
pub const ANGLE_FLOOR: f64 = 1e-9;
/// Convergence threshold for angle errors (rad), drawn as a dashed line.
pub const ANGLE_THRESHOLD: f64 = 1e-3;
/// Energy values below this (including exact zeros) are drawn at it, unless
/// the smallest positive value is larger.
pub const ENERGY_FLOOR: f64 = 1e-12;
/// Size in pixels of the PNG and SVG images.
pub const IMAGE_SIZE: (u32, u32) = (1200, 900);

/// Values of larger magnitude are treated like non-finite ones (skipped), so
/// that axis ranges stay finite.
const ABSURD: f64 = 1e100;
/// Number of formation snapshots in `trajectories`.
const SNAPSHOTS: usize = 5;
/// The embedded font and its path, for the error message.
const FONT_BYTES: &[u8] = include_bytes!("../../../assets/DejaVuSans.ttf");
const FONT_ASSET: &str = "host-sim/assets/DejaVuSans.ttf";
const FONT: &str = "sans-serif";

/// Columns of `timeseries.csv` that every run must have (besides the
/// per-agent, per-angle and per-estimate ones).
const REQUIRED: [&str; 10] = {
    let b = crate::report::BASE_COLUMNS;
    [b[0], b[1], b[2], b[3], b[4], b[5], b[6], b[7], b[8], b[9]]
};

/// Reads `dir/timeseries.csv` and `dir/summary.json` and writes
/// `trajectories`, `angle_errors`, `energy`, `estimates` and `maneuvers`, each
/// as `.png` and `.svg`, into `dir`.
///
/// Returns the paths written, PNG then SVG for each figure in that order.
///
/// # Errors
///
/// A [`PlotError`] naming the file and the reason when an input is missing,
/// malformed, lacks a needed column or has no data row, or when an output
/// image cannot be drawn or written. Figures written before the error stay.
pub fn plot_run(dir: &Path) -> Result<Vec<PathBuf>, PlotError> {
    plot_run_from(dir, None)
}

/// [`plot_run`] with the rows of `dir/timeseries.csv` given in memory (`series`, the
/// rows the run wrote there): the same figures without reading the file back.
pub fn plot_run_from(dir: &Path, series: Option<&TimeSeries>) -> Result<Vec<PathBuf>, PlotError> {
    ensure_font()?;
    let run = load_run(dir, series)?;
    let mut written = Vec::with_capacity(2 * Figure::ALL.len());
    for figure in Figure::ALL {
        // Runs written before `shape` existed have no target to draw.
        if figure == Figure::Shape && run.summary.shape.is_none() {
            continue;
        }
        render(dir, figure, &run, &mut written)?;
    }
    Ok(written)
}

/// Registers the embedded font (once per process) under the family names
/// plotters uses.
fn ensure_font() -> Result<(), PlotError> {
    static REGISTERED: OnceLock<bool> = OnceLock::new();
    let ok = *REGISTERED.get_or_init(|| {
        ["sans-serif", "serif", "monospace"].iter().all(|family| {
            plotters::style::register_font(family, FontStyle::Normal, FONT_BYTES).is_ok()
        })
    });
    if ok {
        Ok(())
    } else {
        Err(PlotError::Font)
    }
}

/// The figures.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Figure {
    Trajectories,
    AngleErrors,
    Energy,
    Estimates,
    Maneuvers,
    Shape,
}

impl Figure {
    const ALL: [Figure; 6] = [
        Figure::Trajectories,
        Figure::AngleErrors,
        Figure::Energy,
        Figure::Estimates,
        Figure::Maneuvers,
        Figure::Shape,
    ];

    fn stem(self) -> &'static str {
        match self {
            Figure::Trajectories => "trajectories",
            Figure::AngleErrors => "angle_errors",
            Figure::Energy => "energy",
            Figure::Estimates => "estimates",
            Figure::Maneuvers => "maneuvers",
            Figure::Shape => "shape",
        }
    }
}

type DrawResult = Result<(), Box<dyn StdError>>;

fn render(
    dir: &Path,
    figure: Figure,
    run: &Run,
    written: &mut Vec<PathBuf>,
) -> Result<(), PlotError> {
    let draw_err = |path: &Path, e: &dyn std::fmt::Display| PlotError::Draw {
        path: path.to_path_buf(),
        reason: e.to_string(),
    };

    let png = dir.join(format!("{}.png", figure.stem()));
    write_png(&png, IMAGE_SIZE, |root| {
        draw_figure(figure, root, run, true)
    })
    .map_err(|e| draw_err(&png, &e))?;
    written.push(png);

    let svg = dir.join(format!("{}.svg", figure.stem()));
    {
        let root = SVGBackend::new(&svg, IMAGE_SIZE).into_drawing_area();
        draw_figure(figure, &root, run, false).map_err(|e| draw_err(&svg, &e))?;
        root.present().map_err(|e| draw_err(&svg, &e))?;
    }
    written.push(svg);
    Ok(())
}

/// Draws a `size` image with `draw` into memory and writes it to `path` as an 8-bit RGB
/// PNG with one fixed filter (`Up`) and fast compression. The `image` crate's encoder,
/// which plotters' `BitMapBackend::new` uses, tries all five filters on every row
/// (adaptive): that was 57 % of the instructions of `host-sim run paper` with its
/// default outputs (callgrind, dev build; docs/outputs.md, "What the outputs cost").
/// The pixels are the same.
pub(crate) fn write_png(
    path: &Path,
    (w, h): (u32, u32),
    draw: impl FnOnce(&DrawingArea<BitMapBackend<'_>, Shift>) -> DrawResult,
) -> DrawResult {
    let mut pixels = vec![0u8; w as usize * h as usize * 3];
    {
        let root = BitMapBackend::with_buffer(&mut pixels, (w, h)).into_drawing_area();
        draw(&root)?;
        root.present()?;
    }
    let file = std::io::BufWriter::new(std::fs::File::create(path)?);
    let mut encoder = png::Encoder::new(file, w, h);
    encoder.set_color(png::ColorType::Rgb);
    encoder.set_depth(png::BitDepth::Eight);
    encoder.set_compression(png::Compression::Fast);
    encoder.set_filter(png::FilterType::Up);
    encoder.set_adaptive_filter(png::AdaptiveFilterType::NonAdaptive);
    let mut writer = encoder.write_header()?;
    writer.write_image_data(&pixels)?;
    writer.finish()?;
    Ok(())
}

fn draw_figure<DB: DrawingBackend>(
    figure: Figure,
    root: &DrawingArea<DB, Shift>,
    run: &Run,
    bitmap: bool,
) -> DrawResult
where
    DB::ErrorType: 'static,
{
    match figure {
        Figure::Trajectories => trajectories::draw(root, run, bitmap),
        Figure::AngleErrors => angle_errors::draw(root, run, bitmap),
        Figure::Energy => energy::draw(root, run, bitmap),
        Figure::Estimates => estimates::draw(root, run, bitmap),
        Figure::Maneuvers => maneuvers::draw(root, run, bitmap),
        Figure::Shape => shape::draw(root, run, bitmap),
    }
}
