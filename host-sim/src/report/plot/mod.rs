//! Plots of one simulator run.
//!
//! [`plot_run`] reads `timeseries.csv` and `summary.json` from a run directory
//! and writes five figures next to them, each as PNG (1200×900) and SVG:
//!
//! | file | content |
//! | --- | --- |
//! | `trajectories` | x–y path of every agent (at most [`MAX_AGENT_PATHS`]), formation snapshots (graph edges between agent positions) at five times from start to end, leaders marked; equal aspect ratio |
//! | `angle_errors` | \|angle error\| of every controlled angle (at most [`MAX_ANGLES`]) and their maximum vs time, log scale, with the [`ANGLE_THRESHOLD`] line |
//! | `energy` | V and its terms V_kin, V_ang, V_lead, V_est vs time, log scale |
//! | `estimates` | each distance estimate r̂ (solid) against its true distance r (dashed), at most [`MAX_ESTIMATES`] |
//! | `maneuvers` | leader displacement and velocity errors, and the minimum inter-agent distance vs time |
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

use std::collections::HashMap;
use std::error::Error as StdError;
use std::fs::File;
use std::io::BufReader;
use std::path::{Path, PathBuf};
use std::sync::OnceLock;

/// One plotted line: `(t, value)` points.
type Series = Vec<(f64, f64)>;

use plotters::coord::{CoordTranslate, Shift};
use plotters::element::DashedPathElement;
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};
use plotters::style::FontStyle;
use serde::Deserialize;

/// At most this many rows (points per series) are kept from `timeseries.csv`.
pub const MAX_POINTS: usize = 2000;
/// Runs with more agents than this draw the paths of an evenly spaced subset
/// of this many agents (plus the leaders); formation snapshots still show all.
pub const MAX_AGENT_PATHS: usize = 50;
/// Runs with more controlled angles than this draw an evenly spaced subset of
/// this many angle errors (the maximum over all angles is always drawn).
pub const MAX_ANGLES: usize = 50;
/// At most this many estimates (the first ones in column order) are drawn.
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

/// Why plotting a run failed. Every variant names the file concerned.
#[derive(Debug, thiserror::Error)]
pub enum PlotError {
    /// An input file could not be opened or read.
    #[error("{}: cannot read: {source}", path.display())]
    Io {
        /// The file.
        path: PathBuf,
        /// The underlying error.
        #[source]
        source: std::io::Error,
    },
    /// `timeseries.csv` is not well-formed CSV (e.g. a row has the wrong
    /// number of fields).
    #[error("{}: malformed CSV: {source}", path.display())]
    Csv {
        /// The file.
        path: PathBuf,
        /// The underlying error, with its position.
        #[source]
        source: csv::Error,
    },
    /// `summary.json` is not valid JSON or lacks a required field.
    #[error("{}: malformed summary: {source}", path.display())]
    Json {
        /// The file.
        path: PathBuf,
        /// The underlying error, with its position or the field name.
        #[source]
        source: serde_json::Error,
    },
    /// A column that the plots need is not in the CSV header.
    #[error("{}: missing column `{column}`", path.display())]
    MissingColumn {
        /// The file.
        path: PathBuf,
        /// Name of the missing column.
        column: String,
    },
    /// The CSV has no header or no data row with a finite `t`.
    #[error("{}: no data: {reason}", path.display())]
    Empty {
        /// The file.
        path: PathBuf,
        /// What exactly is missing.
        reason: &'static str,
    },
    /// A field is neither a number nor empty.
    #[error("{}: line {line}, column `{column}`: `{value}` is not a number", path.display())]
    BadValue {
        /// The file.
        path: PathBuf,
        /// 1-based line number in the file.
        line: u64,
        /// Column name.
        column: String,
        /// The offending text (at most 40 characters of it).
        value: String,
    },
    /// Drawing or writing an output image failed.
    #[error("{}: cannot draw: {reason}", path.display())]
    Draw {
        /// The output file.
        path: PathBuf,
        /// What the plotting library reported.
        reason: String,
    },
    /// The embedded font could not be loaded (a build problem).
    #[error("{FONT_ASSET}: embedded font is not a valid TrueType font")]
    Font,
}

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
    ensure_font()?;
    let run = load_run(dir)?;
    let mut written = Vec::with_capacity(2 * Figure::ALL.len());
    for figure in Figure::ALL {
        render(dir, figure, &run, &mut written)?;
    }
    Ok(written)
}

// ---------------------------------------------------------------------------
// Font

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

// ---------------------------------------------------------------------------
// Input

/// The fields of `summary.json` the plots use.
#[derive(Debug, Deserialize)]
struct Summary {
    scenario: String,
    outcome: String,
    #[serde(default)]
    outcome_reason: Option<String>,
    agents: Vec<i64>,
    edges: Vec<[i64; 2]>,
    #[serde(default)]
    leaders: Option<[i64; 2]>,
    #[serde(default)]
    mode: Option<serde_json::Value>,
    #[serde(default)]
    estimator: Option<serde_json::Value>,
}

/// A labelled series aligned with [`Run::t`].
struct Named {
    label: String,
    values: Vec<f64>,
}

/// The kept path of one agent, aligned with [`Run::t`].
struct AgentPath {
    agent: usize,
    x: Vec<f64>,
    y: Vec<f64>,
}

/// All agent positions at one time.
struct Snapshot {
    t: f64,
    pos: Vec<(f64, f64)>,
}

/// One estimate and its true value, aligned with [`Run::t`].
struct Estimate {
    label: String,
    rhat: Vec<f64>,
    r: Vec<f64>,
}

/// Everything the figures draw, downsampled.
struct Run {
    summary: Summary,
    /// Time of each kept row.
    t: Vec<f64>,
    /// `V`, `V_kin`, `V_ang`, `V_lead`, `V_est`.
    energy: Vec<Named>,
    max_angle_err: Vec<f64>,
    disp_err: Vec<f64>,
    vel_err: Vec<f64>,
    min_dist: Vec<f64>,
    /// Agent ids (as in the column names) in agent order.
    agent_ids: Vec<String>,
    /// Indices into `agent_ids`.
    leaders: Vec<usize>,
    /// Graph edges as index pairs into `agent_ids` (unknown ids dropped).
    edges: Vec<(usize, usize)>,
    paths: Vec<AgentPath>,
    snapshots: Vec<Snapshot>,
    angles: Vec<Named>,
    n_angles: usize,
    estimates: Vec<Estimate>,
    n_estimates: usize,
}

/// Column indices of the CSV header, by name.
struct Header<'a> {
    path: &'a Path,
    names: Vec<String>,
    index: HashMap<String, usize>,
}

impl Header<'_> {
    fn require(&self, column: &str) -> Result<usize, PlotError> {
        self.index
            .get(column)
            .copied()
            .ok_or_else(|| PlotError::MissingColumn {
                path: self.path.to_path_buf(),
                column: column.to_string(),
            })
    }

    /// `(column index, suffix)` of every column whose name starts with
    /// `prefix`, in column order.
    fn with_prefix(&self, prefix: &str) -> Vec<(usize, String)> {
        self.names
            .iter()
            .enumerate()
            .filter_map(|(i, n)| n.strip_prefix(prefix).map(|s| (i, s.to_string())))
            .collect()
    }
}

/// Downsampled columns being collected: `data[k]` holds the kept values of
/// CSV column `src[k]`.
#[derive(Default)]
struct Columns {
    src: Vec<usize>,
    data: Vec<Vec<f64>>,
}

impl Columns {
    fn add(&mut self, column: usize) -> usize {
        self.src.push(column);
        self.data.push(Vec::new());
        self.src.len() - 1
    }

    fn take(&mut self, slot: usize) -> Vec<f64> {
        std::mem::take(&mut self.data[slot])
    }
}

/// Which valid rows (rows with a finite `t`) are kept.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Thinning {
    valid: usize,
    stride: usize,
}

impl Thinning {
    fn new(valid: usize) -> Self {
        Self {
            valid,
            stride: valid.div_ceil(MAX_POINTS).max(1),
        }
    }

    /// Whether valid row `v` (0-based) is kept: every `stride`-th and the last.
    fn keeps(&self, v: usize) -> bool {
        v.is_multiple_of(self.stride) || v + 1 == self.valid
    }

    /// Number of kept rows.
    fn kept(&self) -> usize {
        if self.valid == 0 {
            return 0;
        }
        let last = self.valid - 1;
        last / self.stride + 1 + usize::from(!last.is_multiple_of(self.stride))
    }

    /// Kept-row ordinals of the formation snapshots: evenly spread, first
    /// and last included, no duplicates.
    fn snapshots(&self) -> Vec<usize> {
        let m = self.kept();
        let mut out: Vec<usize> = (0..SNAPSHOTS)
            .map(|k| ((k * m.saturating_sub(1)) as f64 / (SNAPSHOTS - 1) as f64).round() as usize)
            .collect();
        out.dedup();
        out
    }
}

fn open_csv(path: &Path) -> Result<csv::Reader<File>, PlotError> {
    let file = File::open(path).map_err(|source| PlotError::Io {
        path: path.to_path_buf(),
        source,
    })?;
    Ok(csv::ReaderBuilder::new()
        .has_headers(true)
        .from_reader(file))
}

/// Parses one field: empty → NaN; a number (including `NaN`/`inf`) → it;
/// anything else → [`PlotError::BadValue`].
fn field(rec: &csv::ByteRecord, col: usize, header: &Header<'_>) -> Result<f64, PlotError> {
    let raw = rec.get(col).unwrap_or(b"");
    let text = String::from_utf8_lossy(raw);
    let text = text.trim();
    if text.is_empty() {
        return Ok(f64::NAN);
    }
    text.parse::<f64>().map_err(|_| PlotError::BadValue {
        path: header.path.to_path_buf(),
        line: rec.position().map_or(0, |p| p.line()),
        column: header.names.get(col).cloned().unwrap_or_default(),
        value: text.chars().take(40).collect(),
    })
}

fn load_summary(path: &Path) -> Result<Summary, PlotError> {
    let file = File::open(path).map_err(|source| PlotError::Io {
        path: path.to_path_buf(),
        source,
    })?;
    serde_json::from_reader(BufReader::new(file)).map_err(|source| PlotError::Json {
        path: path.to_path_buf(),
        source,
    })
}

/// Indices `0..n` thinned to at most `max`, evenly spaced, first and last
/// included.
fn spread(n: usize, max: usize) -> Vec<usize> {
    if n <= max {
        return (0..n).collect();
    }
    if max < 2 {
        return (0..max).collect();
    }
    let mut out: Vec<usize> = (0..max)
        .map(|k| ((k * (n - 1)) as f64 / (max - 1) as f64).round() as usize)
        .collect();
    out.dedup();
    out
}

fn load_run(dir: &Path) -> Result<Run, PlotError> {
    let summary = load_summary(&dir.join("summary.json"))?;
    let csv_path = dir.join("timeseries.csv");
    let csv_err = |source| PlotError::Csv {
        path: csv_path.clone(),
        source,
    };

    // Header.
    let mut reader = open_csv(&csv_path)?;
    let names: Vec<String> = reader
        .headers()
        .map_err(csv_err)?
        .iter()
        .map(|s| s.trim().to_string())
        .collect();
    if names.iter().all(String::is_empty) {
        return Err(PlotError::Empty {
            path: csv_path,
            reason: "no header row",
        });
    }
    let mut index = HashMap::new();
    for (i, n) in names.iter().enumerate() {
        index.entry(n.clone()).or_insert(i);
    }
    let header = Header {
        path: &csv_path,
        names,
        index,
    };

    // Columns.
    let mut cols = Columns::default();
    let fixed: Vec<usize> = REQUIRED
        .iter()
        .map(|name| header.require(name).map(|c| cols.add(c)))
        .collect::<Result<_, _>>()?;
    let t_col = header.require("t")?;

    let agent_ids: Vec<String> = if summary.agents.is_empty() {
        header
            .with_prefix("x_")
            .into_iter()
            .map(|(_, s)| s)
            .collect()
    } else {
        summary.agents.iter().map(i64::to_string).collect()
    };
    let mut agent_xy = Vec::with_capacity(agent_ids.len());
    for id in &agent_ids {
        agent_xy.push((
            header.require(&format!("x_{id}"))?,
            header.require(&format!("y_{id}"))?,
        ));
    }
    let agent_index: HashMap<&str, usize> = agent_ids
        .iter()
        .enumerate()
        .rev()
        .map(|(i, id)| (id.as_str(), i))
        .collect();
    let lookup = |id: i64| agent_index.get(id.to_string().as_str()).copied();
    let leaders: Vec<usize> = summary
        .leaders
        .map(|[a, b]| [lookup(a), lookup(b)].into_iter().flatten().collect())
        .unwrap_or_default();
    let edges: Vec<(usize, usize)> = summary
        .edges
        .iter()
        .filter_map(|&[a, b]| Some((lookup(a)?, lookup(b)?)))
        .collect();

    let mut path_agents = spread(agent_ids.len(), MAX_AGENT_PATHS);
    path_agents.extend(&leaders);
    path_agents.sort_unstable();
    path_agents.dedup();
    let path_slots: Vec<(usize, usize, usize)> = path_agents
        .iter()
        .map(|&a| (a, cols.add(agent_xy[a].0), cols.add(agent_xy[a].1)))
        .collect();

    let angle_cols = header.with_prefix("angle_err_");
    let n_angles = angle_cols.len();
    let angle_slots: Vec<(String, usize)> = spread(n_angles, MAX_ANGLES)
        .into_iter()
        .map(|k| {
            let (c, suffix) = &angle_cols[k];
            (angle_label(suffix), cols.add(*c))
        })
        .collect();

    let est_cols = header.with_prefix("rhat_");
    let n_estimates = est_cols.len();
    let mut est_slots = Vec::new();
    for (c, suffix) in est_cols.iter().take(MAX_ESTIMATES) {
        let r = header.require(&format!("r_{suffix}"))?;
        est_slots.push((estimate_label(suffix), cols.add(*c), cols.add(r)));
    }

    // Pass 1: count the rows with a finite t.
    let mut rec = csv::ByteRecord::new();
    let mut valid = 0usize;
    while reader.read_byte_record(&mut rec).map_err(csv_err)? {
        if field(&rec, t_col, &header)?.is_finite() {
            valid += 1;
        }
    }
    if valid == 0 {
        return Err(PlotError::Empty {
            path: csv_path.clone(),
            reason: "no data row with a finite `t`",
        });
    }
    let thin = Thinning::new(valid);
    let snapshot_at = thin.snapshots();

    // Pass 2: keep the thinned rows.
    let mut reader = open_csv(&csv_path)?;
    let mut snapshots = Vec::with_capacity(snapshot_at.len());
    let (mut v, mut kept) = (0usize, 0usize);
    while reader.read_byte_record(&mut rec).map_err(csv_err)? {
        let t = field(&rec, t_col, &header)?;
        if !t.is_finite() {
            continue;
        }
        if thin.keeps(v) {
            for (slot, &c) in cols.src.iter().enumerate() {
                let x = field(&rec, c, &header)?;
                cols.data[slot].push(x);
            }
            if snapshot_at.contains(&kept) {
                let pos = agent_xy
                    .iter()
                    .map(|&(cx, cy)| Ok((field(&rec, cx, &header)?, field(&rec, cy, &header)?)))
                    .collect::<Result<_, PlotError>>()?;
                snapshots.push(Snapshot { t, pos });
            }
            kept += 1;
        }
        v += 1;
        if v == valid {
            break; // the file changed between the passes; ignore the rest
        }
    }

    let t = cols.take(fixed[0]);
    let energy = ["V", "V_kin", "V_ang", "V_lead", "V_est"]
        .iter()
        .zip(&fixed[1..6])
        .map(|(name, &slot)| Named {
            label: (*name).to_string(),
            values: cols.take(slot),
        })
        .collect();
    let max_angle_err = cols.take(fixed[6]);
    let disp_err = cols.take(fixed[7]);
    let vel_err = cols.take(fixed[8]);
    let min_dist = cols.take(fixed[9]);
    let paths = path_slots
        .into_iter()
        .map(|(agent, sx, sy)| AgentPath {
            agent,
            x: cols.take(sx),
            y: cols.take(sy),
        })
        .collect();
    let angles = angle_slots
        .into_iter()
        .map(|(label, slot)| Named {
            label,
            values: cols.take(slot),
        })
        .collect();
    let estimates = est_slots
        .into_iter()
        .map(|(label, sh, sr)| Estimate {
            label,
            rhat: cols.take(sh),
            r: cols.take(sr),
        })
        .collect();

    Ok(Run {
        summary,
        t,
        energy,
        max_angle_err,
        disp_err,
        vel_err,
        min_dist,
        agent_ids,
        leaders,
        edges,
        paths,
        snapshots,
        angles,
        n_angles,
        estimates,
        n_estimates,
    })
}

/// `u_v_w` (apex u) → `∠v-u-w`.
fn angle_label(suffix: &str) -> String {
    match suffix.split('_').collect::<Vec<_>>()[..] {
        [u, v, w] => format!("∠{v}-{u}-{w}"),
        _ => suffix.to_string(),
    }
}

/// `o_u_f_w` → `o: u→f (w)`.
fn estimate_label(suffix: &str) -> String {
    match suffix.split('_').collect::<Vec<_>>()[..] {
        [o, u, f, w] => format!("{o}: {u}→{f} ({w})"),
        _ => suffix.to_string(),
    }
}

// ---------------------------------------------------------------------------
// Output

/// The five figures.
#[derive(Debug, Clone, Copy)]
enum Figure {
    Trajectories,
    AngleErrors,
    Energy,
    Estimates,
    Maneuvers,
}

impl Figure {
    const ALL: [Figure; 5] = [
        Figure::Trajectories,
        Figure::AngleErrors,
        Figure::Energy,
        Figure::Estimates,
        Figure::Maneuvers,
    ];

    fn stem(self) -> &'static str {
        match self {
            Figure::Trajectories => "trajectories",
            Figure::AngleErrors => "angle_errors",
            Figure::Energy => "energy",
            Figure::Estimates => "estimates",
            Figure::Maneuvers => "maneuvers",
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
    {
        let root = BitMapBackend::new(&png, IMAGE_SIZE).into_drawing_area();
        draw_figure(figure, &root, run, true).map_err(|e| draw_err(&png, &e))?;
        root.present().map_err(|e| draw_err(&png, &e))?;
    }
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
        Figure::Trajectories => draw_trajectories(root, run, bitmap),
        Figure::AngleErrors => draw_angle_errors(root, run, bitmap),
        Figure::Energy => draw_energy(root, run, bitmap),
        Figure::Estimates => draw_estimates(root, run, bitmap),
        Figure::Maneuvers => draw_maneuvers(root, run, bitmap),
    }
}

// --- Colours, styles, legend -------------------------------------------------

/// Tableau 10 plus two darker colours: distinguishable series colours.
const PALETTE: [RGBColor; 12] = [
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
const LEADER: RGBColor = RGBColor(200, 0, 0);
const DARK: RGBColor = RGBColor(20, 20, 20);

fn colour(i: usize) -> RGBColor {
    PALETTE[i % PALETTE.len()]
}

/// Draws the polyline `pts` (in `area`'s coordinates), `width` pixels wide,
/// solid or dashed.
///
/// On bitmaps a wide line is drawn as `width × width` one-pixel lines offset
/// by a pixel each: plotters fills wide polylines as one polygon whose inner
/// corners grow long spikes wherever the line turns sharply (a jump, a dip
/// on a log axis). SVG strokes are drawn by the viewer and are fine.
fn stroke<DB, CT>(
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
    const DASH: (i32, i32) = (9, 6);
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
    let pixels = area.strip_coord_spec();
    let (bx, by) = pixels.get_base_pixel();
    let mut base: Vec<(i32, i32)> = pts
        .iter()
        .map(|p| {
            let (x, y) = area.map_coordinate(p);
            (x - bx, y - by)
        })
        .collect();
    base.dedup();
    let w = i32::try_from(width).unwrap_or(1);
    let lo = -(w - 1) / 2;
    let style = colour.stroke_width(1);
    for dx in lo..lo + w {
        for dy in lo..lo + w {
            let shifted: Vec<(i32, i32)> = base.iter().map(|&(x, y)| (x + dx, y + dy)).collect();
            if dashed {
                pixels.draw(&DashedPathElement::new(shifted, DASH.0, DASH.1, style))?;
            } else {
                pixels.draw(&PathElement::new(shifted, style))?;
            }
        }
    }
    Ok(())
}

/// How a legend entry's key is drawn.
enum Key {
    Line(RGBColor, u32),
    Dashed(RGBColor, u32),
    /// An edge with a node at each end.
    Net(RGBColor),
    Triangle(RGBColor),
    /// No key (a note line).
    None,
}

struct Entry {
    label: String,
    key: Key,
}

fn entry(label: impl Into<String>, key: Key) -> Entry {
    Entry {
        label: label.into(),
        key,
    }
}

const LEGEND_FONT: u32 = 15;
const LEGEND_ROW: i32 = 24;
const LEGEND_KEY_W: i32 = 34;

/// Splits `area` into the plot (left) and a legend panel (right) wide enough
/// for the entries' labels (within limits), and draws the legend.
fn with_legend<DB: DrawingBackend>(
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

fn draw_legend<DB: DrawingBackend>(
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

/// `text` as it can be drawn: plotters' bitmap text renderer has no
/// shaping, so a combining mark lands after its letter instead of on it.
/// For bitmaps a combining circumflex is spelled out ("r̂" → "rhat") and other
/// combining marks are dropped; SVG text is drawn by the viewer and kept.
fn drawable(text: &str, bitmap: bool) -> String {
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
fn fit_text<DB: DrawingBackend>(
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
fn wrap<DB: DrawingBackend>(
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

fn json_text(v: &serde_json::Value) -> String {
    match v {
        serde_json::Value::String(s) => s.clone(),
        other => other.to_string(),
    }
}

/// Fills the figure white, draws the title (scenario, figure name, outcome,
/// optional note) and the subtitle, and returns the area below them.
fn frame<DB: DrawingBackend>(
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

// --- Ranges and points -------------------------------------------------------------

fn sane(v: f64) -> bool {
    v.is_finite() && v.abs() < ABSURD
}

/// Finite `(t, v)` pairs.
fn points(t: &[f64], v: &[f64]) -> Vec<(f64, f64)> {
    t.iter()
        .zip(v)
        .filter(|(t, v)| sane(**t) && sane(**v))
        .map(|(&t, &v)| (t, v))
        .collect()
}

/// Finite `(t, max(|v|, floor))` pairs, for a log axis.
fn log_points(t: &[f64], v: &[f64], floor: f64) -> Vec<(f64, f64)> {
    t.iter()
        .zip(v)
        .filter(|(t, v)| sane(**t) && sane(**v))
        .map(|(&t, &v)| (t, v.abs().max(floor)))
        .collect()
}

/// Padded, non-degenerate linear range covering the finite values.
fn lin_range(values: impl IntoIterator<Item = f64>) -> (f64, f64) {
    let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
    for v in values.into_iter().filter(|v| sane(*v)) {
        lo = lo.min(v);
        hi = hi.max(v);
    }
    if lo > hi {
        return (0.0, 1.0);
    }
    if hi - lo <= f64::EPSILON * hi.abs().max(lo.abs()) {
        let d = if lo == 0.0 { 1.0 } else { 0.1 * lo.abs() };
        return (lo - d, hi + d);
    }
    let pad = 0.04 * (hi - lo);
    (lo - pad, hi + pad)
}

/// Time range of the run.
fn time_range(t: &[f64]) -> (f64, f64) {
    let (lo, hi) = lin_range(t.iter().copied());
    // No padding on the time axis when there is a real span.
    let (tlo, thi) = t
        .iter()
        .filter(|v| sane(**v))
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &v| {
            (a.min(v), b.max(v))
        });
    if thi > tlo {
        (tlo, thi)
    } else {
        (lo, hi)
    }
}

/// Log range (positive, non-degenerate) covering positive `values`.
fn log_range(values: impl IntoIterator<Item = f64>) -> (f64, f64) {
    let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
    for v in values.into_iter().filter(|v| sane(*v) && *v > 0.0) {
        lo = lo.min(v);
        hi = hi.max(v);
    }
    if lo > hi {
        return (0.1, 10.0);
    }
    if hi <= lo * 1.01 {
        return (lo / 10.0, hi * 10.0);
    }
    let pad = (hi / lo).powf(0.04).max(1.2);
    (lo / pad, hi * pad)
}

fn log_label(v: &f64) -> String {
    let exp = v.log10();
    if (exp - exp.round()).abs() < 1e-9 {
        format!("1e{}", exp.round() as i64)
    } else {
        format!("{v:.1e}")
    }
}

const CHART_MARGIN: u32 = 14;
const X_LABEL_AREA: u32 = 56;
const Y_LABEL_AREA: u32 = 96;

/// A chart builder on `area` with the house margins and label areas.
fn chart_on<'a, 'b, DB: DrawingBackend>(
    area: &'a DrawingArea<DB, Shift>,
) -> ChartBuilder<'a, 'b, DB> {
    let mut builder = ChartBuilder::on(area);
    builder
        .margin(CHART_MARGIN)
        .x_label_area_size(X_LABEL_AREA)
        .y_label_area_size(Y_LABEL_AREA);
    builder
}

/// The house style of every time-series panel's mesh: axis descriptions, fonts, grid.
fn styled_mesh<'m, 'a, 'b, X, Y, XT, YT, DB>(
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

fn label_style() -> TextStyle<'static> {
    (FONT, 15).into_font().color(&BLACK)
}

fn desc_style() -> TextStyle<'static> {
    (FONT, 18).into_font().color(&BLACK)
}

// --- The figures ------------------------------------------------------------

fn draw_trajectories<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    run: &Run,
    bitmap: bool,
) -> DrawResult
where
    DB::ErrorType: 'static,
{
    let n = run.agent_ids.len();
    let note = if run.paths.len() < n {
        format!("paths of {} of {} agents shown", run.paths.len(), n)
    } else {
        String::new()
    };
    let area = frame(root, run, "trajectories and formation", &note, bitmap)?;

    // Legend.
    let mut entries = Vec::new();
    let label_each = run.paths.len() <= 10;
    if label_each {
        for (i, p) in run.paths.iter().enumerate() {
            entries.push(entry(
                format!("agent {}", run.agent_ids[p.agent]),
                Key::Line(colour(i), 2),
            ));
        }
    } else {
        entries.push(entry(
            format!("agent paths ({})", run.paths.len()),
            Key::Line(colour(0), 2),
        ));
    }
    let shades = snapshot_shades(run.snapshots.len());
    for (s, shade) in run.snapshots.iter().zip(&shades) {
        entries.push(entry(
            format!("formation at t = {}", fmt_time(s.t)),
            Key::Net(*shade),
        ));
    }
    if !run.leaders.is_empty() {
        let ids: Vec<&str> = run
            .leaders
            .iter()
            .map(|&l| run.agent_ids[l].as_str())
            .collect();
        entries.push(entry(
            format!("leader ({})", ids.join(", ")),
            Key::Triangle(LEADER),
        ));
    }
    if run.edges.len() < run.summary.edges.len() {
        entries.push(entry(
            format!(
                "edges with unknown ids (not drawn): {}",
                run.summary.edges.len() - run.edges.len()
            ),
            Key::None,
        ));
    }
    let plot = with_legend(&area, &entries, bitmap)?;

    // Equal-aspect ranges covering paths and snapshots.
    let xs = run
        .paths
        .iter()
        .flat_map(|p| p.x.iter().copied())
        .chain(run.snapshots.iter().flat_map(|s| s.pos.iter().map(|p| p.0)));
    let ys = run
        .paths
        .iter()
        .flat_map(|p| p.y.iter().copied())
        .chain(run.snapshots.iter().flat_map(|s| s.pos.iter().map(|p| p.1)));
    let (x0, x1) = lin_range(xs);
    let (y0, y1) = lin_range(ys);
    let (w, h) = plot.dim_in_pixel();
    let pw = f64::from(w.saturating_sub(2 * CHART_MARGIN + Y_LABEL_AREA).max(1));
    let ph = f64::from(h.saturating_sub(2 * CHART_MARGIN + X_LABEL_AREA).max(1));
    let scale = ((x1 - x0) / pw).max((y1 - y0) / ph);
    let (cx, cy) = ((x0 + x1) / 2.0, (y0 + y1) / 2.0);
    let (hx, hy) = (scale * pw / 2.0, scale * ph / 2.0);

    let mut chart = chart_on(&plot).build_cartesian_2d(cx - hx..cx + hx, cy - hy..cy + hy)?;
    chart
        .configure_mesh()
        .x_desc("x (m)")
        .y_desc("y (m)")
        .label_style(label_style())
        .axis_desc_style(desc_style())
        .bold_line_style(BLACK.mix(0.12))
        .light_line_style(BLACK.mix(0.04))
        .draw()?;

    // Snapshot edges, then the paths over them, then the snapshot nodes, then
    // the leaders on top.
    let valid = |s: &Snapshot, a: usize| s.pos.get(a).filter(|p| sane(p.0) && sane(p.1)).copied();
    for (s, shade) in run.snapshots.iter().zip(&shades) {
        chart.draw_series(run.edges.iter().filter_map(|&(a, b)| {
            Some(PathElement::new(
                vec![valid(s, a)?, valid(s, b)?],
                shade.stroke_width(1),
            ))
        }))?;
    }
    for (i, p) in run.paths.iter().enumerate() {
        let pts = points(&p.x, &p.y);
        stroke(chart.plotting_area(), &pts, colour(i), 2, false, bitmap)?;
    }
    let radius = if n > 100 { 2 } else { 4 };
    for (s, shade) in run.snapshots.iter().zip(&shades) {
        chart.draw_series(
            (0..s.pos.len())
                .filter_map(|a| valid(s, a))
                .map(|p| Circle::new(p, radius, shade.filled())),
        )?;
    }
    for s in &run.snapshots {
        chart.draw_series(
            run.leaders
                .iter()
                .filter_map(|&l| valid(s, l))
                .map(|p| TriangleMarker::new(p, radius + 5, LEADER.filled())),
        )?;
    }
    Ok(())
}

/// Greys from light (first snapshot) to black (last).
fn snapshot_shades(n: usize) -> Vec<RGBColor> {
    (0..n)
        .map(|k| {
            let f = if n > 1 {
                k as f64 / (n - 1) as f64
            } else {
                1.0
            };
            let g = (175.0 * (1.0 - f)).round() as u8;
            RGBColor(g, g, g)
        })
        .collect()
}

fn fmt_time(t: f64) -> String {
    if t == 0.0 || (t.abs() >= 0.01 && t.abs() < 1e5) {
        format!("{t:.2} s")
    } else {
        format!("{t:.2e} s")
    }
}

fn draw_angle_errors<DB: DrawingBackend>(
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

fn draw_energy<DB: DrawingBackend>(
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

fn draw_estimates<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    run: &Run,
    bitmap: bool,
) -> DrawResult
where
    DB::ErrorType: 'static,
{
    let note = if run.n_estimates > run.estimates.len() {
        format!(
            "first {} of {} estimates shown",
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

fn draw_maneuvers<DB: DrawingBackend>(
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

#[cfg(test)]
mod tests {
    use super::*;
    use std::fmt::Write as _;

    /// Shape of a synthetic run.
    struct Synth {
        agents: usize,
        rows: usize,
        angles: usize,
        estimates: usize,
    }

    /// Writes a synthetic `timeseries.csv` and `summary.json` into `dir`:
    /// agents (ids 1..=n) spiral onto a ring, errors decay, a few values are
    /// NaN, inf, empty or exactly zero.
    fn write_run(dir: &Path, s: &Synth) {
        let ids: Vec<usize> = (1..=s.agents).collect();
        let mut header: Vec<String> = REQUIRED.iter().map(|c| (*c).to_string()).collect();
        header.extend(["frames_sent", "frames_dropped", "frames_rejected"].map(String::from));
        for i in &ids {
            header.extend([
                format!("x_{i}"),
                format!("y_{i}"),
                format!("vx_{i}"),
                format!("vy_{i}"),
            ]);
        }
        let triple = |k: usize| {
            (
                1 + k % s.agents,
                1 + (k + 1) % s.agents,
                1 + (k + 2) % s.agents,
            )
        };
        for k in 0..s.angles {
            let (u, v, w) = triple(k);
            header.push(format!("angle_err_{u}_{v}_{w}"));
        }
        for k in 0..s.estimates {
            let (u, f, w) = triple(k);
            header.push(format!("rhat_{u}_{u}_{f}_{w}"));
            header.push(format!("r_{u}_{u}_{f}_{w}"));
        }
        let mut csv = header.join(",");
        csv.push('\n');
        for row in 0..s.rows {
            let t = 0.01 * row as f64;
            let e = (-0.5 * t).exp();
            let mut v = vec![
                3.0 * e,
                e,
                e,
                if t > 1.0 { 0.0 } else { e },
                if row == 3 { f64::NAN } else { 0.5 * e },
                0.3 * e,
                2.0 * e,
                e,
                1.0 - 0.5 * e,
                row as f64,
                0.0,
                0.0,
            ];
            let mut line = format!("{t}");
            for x in v.drain(..) {
                let _ = write!(line, ",{x}");
            }
            for (a, _) in ids.iter().enumerate() {
                let phase = a as f64 * std::f64::consts::TAU / s.agents as f64;
                let r = 5.0 + 2.0 * e;
                let _ = write!(
                    line,
                    ",{},{},0,0",
                    r * (phase + 0.1 * t).cos(),
                    r * (phase + 0.1 * t).sin()
                );
            }
            for k in 0..s.angles {
                let x = 0.2 * e * (t + k as f64).cos();
                if row == 5 && k == 0 {
                    line.push_str(",inf");
                } else if row == 6 && k == 0 {
                    line.push(',');
                } else if t > 2.0 && k == 0 {
                    line.push_str(",0");
                } else {
                    let _ = write!(line, ",{x}");
                }
            }
            for k in 0..s.estimates {
                let r = 2.0 + 0.1 * k as f64;
                let _ = write!(line, ",{},{r}", r + e * (t + k as f64).sin());
            }
            csv.push_str(&line);
            csv.push('\n');
        }
        std::fs::write(dir.join("timeseries.csv"), csv).unwrap();
        let edges: Vec<[usize; 2]> = (0..s.agents)
            .map(|a| [1 + a, 1 + (a + 1) % s.agents])
            .collect();
        let summary = serde_json::json!({
            "scenario": "unit-ring",
            "outcome": "converged",
            "outcome_reason": "every angle error below 0.001 rad; estimate r\u{302} ok",
            "agents": ids,
            "edges": edges,
            "leaders": [1, 2],
            "mode": "sampled",
            "estimator": "shared",
            "extra_field": {"ignored": true},
        });
        std::fs::write(dir.join("summary.json"), summary.to_string()).unwrap();
    }

    fn small() -> Synth {
        Synth {
            agents: 4,
            rows: 300,
            angles: 3,
            estimates: 4,
        }
    }

    /// Rewrites the CSV header through `f`.
    fn edit_header(dir: &Path, f: impl Fn(&str) -> String) {
        let path = dir.join("timeseries.csv");
        let text = std::fs::read_to_string(&path).unwrap();
        let (header, rest) = text.split_once('\n').unwrap();
        std::fs::write(&path, format!("{}\n{rest}", f(header))).unwrap();
    }

    #[test]
    fn writes_every_figure_as_png_and_svg_with_titles() {
        let dir = tempfile::tempdir().unwrap();
        write_run(dir.path(), &small());
        let files = plot_run(dir.path()).unwrap();
        let titles = [
            ("trajectories", "trajectories and formation"),
            ("angle_errors", "angle errors"),
            ("energy", "energy V(t)"),
            ("estimates", "distance estimates"),
            ("maneuvers", "maneuvers"),
        ];
        let expected: Vec<PathBuf> = titles
            .iter()
            .flat_map(|(stem, _)| {
                ["png", "svg"].map(|ext| dir.path().join(format!("{stem}.{ext}")))
            })
            .collect();
        assert_eq!(files, expected);
        for (stem, what) in titles {
            let png = std::fs::read(dir.path().join(format!("{stem}.png"))).unwrap();
            assert!(
                png.starts_with(b"\x89PNG\r\n\x1a\n"),
                "{stem}.png signature"
            );
            assert!(png.len() > 10_000, "{stem}.png is {} bytes", png.len());
            let svg = std::fs::read_to_string(dir.path().join(format!("{stem}.svg"))).unwrap();
            assert!(svg.contains("<svg"), "{stem}.svg");
            let title = format!("unit-ring — {what} — outcome: converged");
            assert!(svg.contains(&title), "{stem}.svg lacks `{title}`");
            // The SVG keeps the combining circumflex; only bitmaps spell it out.
            assert!(svg.contains("r\u{302} ok"), "{stem}.svg subtitle");
        }
        let legend = std::fs::read_to_string(dir.path().join("angle_errors.svg")).unwrap();
        assert!(legend.contains("∠2-1-3") && legend.contains("threshold 1e-3 rad"));
        let legend = std::fs::read_to_string(dir.path().join("estimates.svg")).unwrap();
        assert!(legend.contains("1: 1→2 (3)") && legend.contains("4: 4→1 (2)"));
    }

    #[test]
    fn a_large_run_is_thinned_and_says_so() {
        let dir = tempfile::tempdir().unwrap();
        let s = Synth {
            agents: 120,
            rows: 4321,
            angles: 130,
            estimates: 20,
        };
        write_run(dir.path(), &s);
        let run = load_run(dir.path()).unwrap();
        assert!(run.t.len() <= MAX_POINTS + 1, "{} rows kept", run.t.len());
        assert_eq!(run.t.first(), Some(&0.0));
        assert_eq!(run.t.last(), Some(&(0.01 * 4320.0)));
        assert_eq!(run.snapshots.len(), 5);
        assert_eq!(run.snapshots[0].t, 0.0);
        assert_eq!(run.snapshots[4].t, 0.01 * 4320.0);
        assert!(run.snapshots.iter().all(|s| s.pos.len() == 120));
        assert_eq!(run.edges.len(), 120);
        assert_eq!(run.leaders, [0, 1]);
        assert!(run.paths.len() <= MAX_AGENT_PATHS + 2);
        assert!(run.paths.iter().all(|p| p.x.len() == run.t.len()));
        assert_eq!((run.angles.len(), run.n_angles), (MAX_ANGLES, 130));
        assert_eq!((run.estimates.len(), run.n_estimates), (MAX_ESTIMATES, 20));

        plot_run(dir.path()).unwrap();
        let read = |f: &str| std::fs::read_to_string(dir.path().join(f)).unwrap();
        let n = run.paths.len();
        assert!(read("trajectories.svg").contains(&format!("paths of {n} of 120 agents shown")));
        assert!(read("angle_errors.svg").contains("50 of 130 angles shown"));
        assert!(read("estimates.svg").contains("first 12 of 20 estimates shown"));
    }

    #[test]
    fn a_missing_column_is_named() {
        let cases: [(&str, &str); 4] = [
            ("V_est", "W_est"),
            ("t", "time"),
            ("y_3", "z_3"),
            ("r_2_2_3_4", "s_2_2_3_4"),
        ];
        for (column, renamed) in cases {
            let dir = tempfile::tempdir().unwrap();
            write_run(dir.path(), &small());
            edit_header(dir.path(), |h| {
                h.split(',')
                    .map(|c| if c == column { renamed } else { c })
                    .collect::<Vec<_>>()
                    .join(",")
            });
            match plot_run(dir.path()) {
                Err(e @ PlotError::MissingColumn { .. }) => {
                    let msg = e.to_string();
                    assert!(msg.contains(&format!("`{column}`")), "{msg}");
                    assert!(msg.contains("timeseries.csv"), "{msg}");
                }
                other => panic!("{column}: expected MissingColumn, got {other:?}"),
            }
        }
    }

    #[test]
    fn an_agent_in_the_summary_without_columns_is_named() {
        let dir = tempfile::tempdir().unwrap();
        write_run(dir.path(), &small());
        let path = dir.path().join("summary.json");
        let mut summary: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(&path).unwrap()).unwrap();
        summary["agents"] = serde_json::json!([1, 2, 3, 4, 9]);
        std::fs::write(&path, summary.to_string()).unwrap();
        let e = plot_run(dir.path()).unwrap_err();
        assert!(e.to_string().ends_with("missing column `x_9`"), "{e}");
    }

    #[test]
    fn an_empty_csv_is_an_error() {
        let dir = tempfile::tempdir().unwrap();
        write_run(dir.path(), &small());
        let csv = dir.path().join("timeseries.csv");
        let header = std::fs::read_to_string(&csv)
            .unwrap()
            .lines()
            .next()
            .unwrap()
            .to_string();
        for (content, reason) in [
            (String::new(), "no header row"),
            (format!("{header}\n"), "no data row"),
            (
                format!(
                    "{header}\n{}\n",
                    vec!["NaN"; header.split(',').count()].join(",")
                ),
                "no data row",
            ),
        ] {
            std::fs::write(&csv, content).unwrap();
            match plot_run(dir.path()) {
                Err(e @ PlotError::Empty { .. }) => {
                    let msg = e.to_string();
                    assert!(
                        msg.contains("timeseries.csv") && msg.contains(reason),
                        "{msg}"
                    );
                }
                other => panic!("expected Empty, got {other:?}"),
            }
        }
    }

    #[test]
    fn bad_inputs_are_named_errors() {
        // A field that is not a number.
        let dir = tempfile::tempdir().unwrap();
        write_run(dir.path(), &small());
        let csv = dir.path().join("timeseries.csv");
        let text = std::fs::read_to_string(&csv).unwrap();
        let mut lines: Vec<String> = text.lines().map(String::from).collect();
        let mut fields: Vec<&str> = lines[3].split(',').collect();
        fields[1] = "oops";
        lines[3] = fields.join(",");
        std::fs::write(&csv, lines.join("\n")).unwrap();
        let e = plot_run(dir.path()).unwrap_err();
        assert!(matches!(e, PlotError::BadValue { line: 4, .. }), "{e:?}");
        assert!(
            e.to_string().contains("column `V`: `oops` is not a number"),
            "{e}"
        );

        // A row with too few fields.
        lines[3] = "0.5,1,2".to_string();
        std::fs::write(&csv, lines.join("\n")).unwrap();
        let e = plot_run(dir.path()).unwrap_err();
        assert!(
            matches!(e, PlotError::Csv { .. }) && e.to_string().contains("timeseries.csv"),
            "{e}"
        );

        // No summary, then a summary without `agents`.
        let dir = tempfile::tempdir().unwrap();
        write_run(dir.path(), &small());
        let summary = dir.path().join("summary.json");
        std::fs::remove_file(&summary).unwrap();
        let e = plot_run(dir.path()).unwrap_err();
        assert!(
            matches!(e, PlotError::Io { .. }) && e.to_string().contains("summary.json"),
            "{e}"
        );
        std::fs::write(
            &summary,
            r#"{"scenario": "s", "outcome": "o", "edges": []}"#,
        )
        .unwrap();
        let e = plot_run(dir.path()).unwrap_err();
        assert!(
            e.to_string().contains("summary.json") && e.to_string().contains("agents"),
            "{e}"
        );

        // An output that cannot be written.
        let dir = tempfile::tempdir().unwrap();
        write_run(dir.path(), &small());
        std::fs::create_dir(dir.path().join("energy.png")).unwrap();
        let e = plot_run(dir.path()).unwrap_err();
        assert!(
            matches!(e, PlotError::Draw { .. }) && e.to_string().contains("energy.png"),
            "{e}"
        );
    }

    #[test]
    fn odd_but_valid_inputs_still_plot() {
        // Null leaders, no angles, no estimates, an edge to an unknown agent,
        // one data row, constant and all-NaN series.
        let dir = tempfile::tempdir().unwrap();
        write_run(
            dir.path(),
            &Synth {
                agents: 2,
                rows: 1,
                angles: 0,
                estimates: 0,
            },
        );
        let summary = serde_json::json!({
            "scenario": "odd", "outcome": "timeout", "agents": [1, 2],
            "edges": [[1, 2], [2, 7]], "leaders": null,
        });
        std::fs::write(dir.path().join("summary.json"), summary.to_string()).unwrap();
        assert_eq!(plot_run(dir.path()).unwrap().len(), 10);
        let svg = std::fs::read_to_string(dir.path().join("estimates.svg")).unwrap();
        assert!(svg.contains("no estimates in this run"));
        let svg = std::fs::read_to_string(dir.path().join("trajectories.svg")).unwrap();
        assert!(svg.contains("edges with unknown ids (not drawn): 1"));
    }

    #[test]
    fn thinning_keeps_first_last_and_at_most_max_points() {
        for valid in [1, 2, 5, 1999, 2000, 2001, 4001, 12_345, 100_000] {
            let thin = Thinning::new(valid);
            let kept = (0..valid).filter(|&v| thin.keeps(v)).count();
            assert_eq!(kept, thin.kept(), "{valid}");
            assert!(kept <= MAX_POINTS + 1, "{valid}: {kept}");
            assert!(thin.keeps(0) && thin.keeps(valid - 1));
            let snaps = thin.snapshots();
            assert_eq!(snaps.first(), Some(&0));
            assert_eq!(snaps.last(), Some(&(kept - 1)));
            assert_eq!(snaps.len(), kept.min(SNAPSHOTS), "{valid}");
        }
        assert_eq!(spread(1000, 50).len(), 50);
        assert_eq!(spread(1000, 50).last(), Some(&999));
        assert_eq!(spread(7, 50), (0..7).collect::<Vec<_>>());
    }

    #[test]
    fn labels_and_ranges() {
        assert_eq!(angle_label("3_1_2"), "∠1-3-2");
        assert_eq!(angle_label("odd"), "odd");
        assert_eq!(estimate_label("1_1_2_3"), "1: 1→2 (3)");
        assert_eq!(
            drawable("estimate r\u{302} of e\u{301}dge", true),
            "estimate rhat of edge"
        );
        assert_eq!(drawable("r\u{302}", false), "r\u{302}");
        assert_eq!(log_label(&1e-3), "1e-3");
        assert_eq!(log_label(&2e-3), "2.0e-3");
        assert_eq!(lin_range([f64::NAN, f64::INFINITY]), (0.0, 1.0));
        assert_eq!(lin_range([0.0, 0.0]), (-1.0, 1.0));
        let (lo, hi) = lin_range([2.0, 2.0, 1e200]);
        assert!(lo < 2.0 && hi > 2.0 && hi < 3.0);
        let (lo, hi) = log_range([0.0, -1.0, 1e-9, 1e-3]);
        assert!(lo > 0.0 && lo < 1e-9 && hi > 1e-3);
        assert_eq!(log_range([0.0]), (0.1, 10.0));
    }
}
