//! The library's front door, re-exported at the crate root: load a scenario, run it, read
//! what it found. The command line is one client of it; sweeps and other tools are
//! meant to be others.
//!
//! ```no_run
//! # fn main() -> Result<(), ph_formation_sim::Error> {
//! let model = ph_formation_sim::load("paper", &["radio.loss=0.1".to_owned()])?;
//! let run = ph_formation_sim::Simulation::new(&model).run()?;
//! println!("{}: {}", run.result.outcome, run.result.reason);
//! let series = run.series.as_ref().expect("kept by default");
//! let v = series.column("V").expect("column V");
//! println!("V from {} to {}", v[0], v[v.len() - 1]);
//! # Ok(())
//! # }
//! ```

use crate::analysis::Outcome;
use crate::engine::hil::{self, HilOptions};
use crate::engine::{self, RunError, RunResult};
use crate::exit_code;
use crate::model::{estimate_layout, EstimateInfo, Model};
use crate::report::{
    self, expected_rows, CsvRecorder, McapRecorder, PlotError, SeriesBudget, Thinned, TimeSeries,
};
use crate::scenario::{self, ScenarioErrors, Source};
use std::fmt;
use std::path::{Path, PathBuf};

/// Loads a scenario: an existing file, else a built-in name (`host-sim list`), with
/// `key=value` overrides applied before validation (`radio.loss=0.2`, `agents.0.mass=2`,
/// as `--set`).
///
/// `controller.comm_rate_hz = "auto"` is resolved here, by measuring the channel's load
/// (`docs/radio.md`).
pub fn load(scenario: &str, overrides: &[String]) -> Result<Model, ScenarioErrors> {
    scenario::load(scenario, overrides).map(crate::engine::load::resolve_auto)
}

/// Loads a scenario from TOML text (the schema of `docs/scenarios.md`); `name` labels
/// errors and names the scenario when the text has no `name`.
pub fn load_toml(text: &str, name: &str, overrides: &[String]) -> Result<Model, ScenarioErrors> {
    let source = Source::from_text(name, text);
    let file = source.parse(overrides)?;
    scenario::validate_text(&file, &source.label, &source.default_name, &source.text)
        .map(crate::engine::load::resolve_auto)
}

/// What stopped a library call: an invalid scenario, a run that could not finish, or an
/// output that could not be written. Each has the exit code of `docs/outputs.md`.
#[derive(Clone, Debug, PartialEq)]
pub enum Error {
    /// The scenario is invalid (every problem found).
    Scenario(ScenarioErrors),
    /// The run stopped without a result.
    Run(RunError),
    /// An output file or directory could not be written.
    Output(String),
}

impl Error {
    /// The process exit code.
    pub fn exit_code(&self) -> u8 {
        match self {
            Self::Scenario(e) => e.exit_code(),
            Self::Run(e) => e.exit_code(),
            Self::Output(_) => exit_code::IO,
        }
    }
}

impl fmt::Display for Error {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::Scenario(e) => e.fmt(f),
            Self::Run(e) => e.fmt(f),
            Self::Output(s) => f.write_str(s),
        }
    }
}

impl std::error::Error for Error {}

impl From<ScenarioErrors> for Error {
    fn from(e: ScenarioErrors) -> Self {
        Self::Scenario(e)
    }
}

impl From<RunError> for Error {
    fn from(e: RunError) -> Self {
        Self::Run(e)
    }
}

/// Told how far a run has got, in simulated seconds; told once more when it is over
/// (before any output is written). Any `FnMut(f64) + Send` is one (a run with
/// [`Simulation::threads`] reports from a worker thread of its pool).
pub trait Progress: Send {
    /// The run has simulated up to `t` (s).
    fn update(&mut self, t: f64);
    /// The simulation is over.
    fn finish(&mut self) {}
}

impl<F: FnMut(f64) + Send> Progress for F {
    fn update(&mut self, t: f64) {
        self(t);
    }
}

/// A run to be made: by default in memory only, keeping the time series and writing no
/// file.
pub struct Simulation<'a> {
    model: &'a Model,
    keep_series: bool,
    out: Option<(PathBuf, bool)>,
    hil: Option<&'a HilOptions>,
    progress: Option<&'a mut dyn Progress>,
    threads: Option<usize>,
    csv: bool,
    mcap: bool,
    budget: SeriesBudget,
    stride: Option<u64>,
}

impl<'a> Simulation<'a> {
    /// A run of `model`.
    pub fn new(model: &'a Model) -> Self {
        Self {
            model,
            keep_series: true,
            out: None,
            hil: None,
            progress: None,
            threads: None,
            csv: true,
            mcap: false,
            budget: SeriesBudget::DEFAULT,
            stride: None,
        }
    }

    /// Whether [`Self::write_to`] also writes `timeseries.csv` (default yes). Without it
    /// only `summary.json` is written and no figure is drawn (they are drawn from the
    /// CSV): for huge runs, whose rows (every agent's state every `log_interval`) would
    /// cost more than the simulation.
    pub fn csv(mut self, csv: bool) -> Self {
        self.csv = csv;
        self
    }

    /// Whether [`Self::write_to`] also writes `run.mcap` (default no): the same rows as
    /// MCAP for Foxglove and PlotJuggler, and the run's events (`docs/outputs.md`).
    pub fn mcap(mut self, mcap: bool) -> Self {
        self.mcap = mcap;
        self
    }

    /// The size budget of `timeseries.csv` and `run.mcap` (default
    /// [`SeriesBudget::DEFAULT`]): a series larger than it keeps every `stride`-th logged
    /// row (the first and the last always), named in `summary.json`'s `series` and in a
    /// warning; [`SeriesBudget::FULL_RATE`] writes every row (`host-sim run --full-rate`).
    /// The run, its verdict and the in-memory [`Run::series`] are the same either way.
    pub fn series_budget(mut self, budget: SeriesBudget) -> Self {
        self.budget = budget;
        self
    }

    /// Keep every `stride`-th row in the row files whatever the budget (for measuring a
    /// short run at the stride of a long one: `cargo xtask bench-counts`).
    pub fn row_stride(mut self, stride: u64) -> Self {
        self.stride = Some(stride.max(1));
        self
    }

    /// Worker threads of a large run (default: rayon's global pool, one per core). Runs of
    /// at least [`crate::engine::PARALLEL_MIN_AGENTS`] agents compute the agents' ticks and
    /// the plant on them; the result is the same for any number of threads.
    ///
    /// The run then happens on a worker of a private rayon pool. For one huge run per
    /// process, sizing rayon's global pool instead (`rayon::ThreadPoolBuilder::build_global`,
    /// as `host-sim run -j N` does) keeps it on the calling thread, whose allocator can
    /// reuse what loading the scenario freed (0.6 GB less at 100,000 agents).
    pub fn threads(mut self, threads: usize) -> Self {
        self.threads = Some(threads);
        self
    }

    /// Whether to keep the time series in memory ([`Run::series`]; default yes).
    pub fn keep_series(mut self, keep: bool) -> Self {
        self.keep_series = keep;
        self
    }

    /// Also write `timeseries.csv` and `summary.json` into `dir` (created if needed), and
    /// what `options` asks for (the figures and `replay.html` with `plots`), as `host-sim run --out DIR` does.
    pub fn write_to(mut self, dir: impl Into<PathBuf>, options: WriteOptions) -> Self {
        self.out = Some((dir.into(), options.plots));
        self
    }

    /// Run some agents' controllers as firmware on emulated targets (`docs/hil.md`).
    pub fn hil(mut self, options: &'a HilOptions) -> Self {
        self.hil = Some(options);
        self
    }

    /// Report progress to `progress`.
    pub fn progress(mut self, progress: &'a mut dyn Progress) -> Self {
        self.progress = Some(progress);
        self
    }

    /// Runs to the end (or to a terminal failure: the outcome says which).
    pub fn run(self) -> Result<Run, Error> {
        let model = self.model;
        if let Some((dir, _)) = &self.out {
            std::fs::create_dir_all(dir).map_err(|e| {
                Error::Output(format!(
                    "cannot create output directory {}: {e}",
                    dir.display()
                ))
            })?;
        }
        // The estimate layout (for the columns) comes from the agents' own configurations.
        let estimates = estimate_layout(model).map_err(RunError::from)?;
        let csv_path = self
            .out
            .as_ref()
            .filter(|_| self.csv)
            .map(|(d, _)| d.join("timeseries.csv"));
        // One stride for both row files, so that they hold the same rows.
        let columns = report::header(model, &estimates).len() as u64;
        let rows = expected_rows(model);
        let stride = self
            .stride
            .unwrap_or_else(|| self.budget.stride(rows, columns));
        let csv = match &csv_path {
            Some(p) => Some(Thinned::new(
                CsvRecorder::create(p, model, &estimates)
                    .map_err(|e| Error::Output(format!("cannot create {}: {e}", p.display())))?,
                stride,
            )),
            None => None,
        };
        let mcap_path = self
            .out
            .as_ref()
            .filter(|_| self.mcap)
            .map(|(d, _)| d.join("run.mcap"));
        let mcap = match &mcap_path {
            Some(p) => Some(Thinned::new(
                McapRecorder::create(p, model, &estimates)
                    .map_err(|e| Error::Output(format!("cannot create {}: {e}", p.display())))?,
                stride,
            )),
            None => None,
        };
        let thinned = stride > 1 && (csv.is_some() || mcap.is_some());
        let series = self.keep_series.then(|| TimeSeries::new(model, &estimates));
        // The rows written to timeseries.csv, kept for the figures and the replay page
        // (drawn from memory instead of reading the file back).
        let drawn = match &self.out {
            Some((_, true)) if csv.is_some() => {
                Some(Thinned::new(TimeSeries::new(model, &estimates), stride))
            }
            _ => None,
        };
        let mut recorder = (csv, (series, (mcap, drawn)));
        let mut silent = |_: f64| {};
        let progress: &mut dyn Progress = match self.progress {
            Some(p) => p,
            None => &mut silent,
        };
        let result = match (self.hil, self.threads) {
            (Some(h), _) => hil::run(model, h, &mut recorder, &mut |t| progress.update(t)),
            (None, None) => engine::run(model, &mut recorder, &mut |t| progress.update(t)),
            (None, Some(n)) => {
                let pool = rayon::ThreadPoolBuilder::new()
                    .num_threads(n)
                    .build()
                    .map_err(|e| Error::Output(format!("cannot start {n} threads: {e}")))?;
                pool.install(|| engine::run(model, &mut recorder, &mut |t| progress.update(t)))
            }
        };
        progress.finish();
        let mut result = result?;
        let (series, (mcap, drawn)) = recorder.1;
        let drawn = drawn.map(Thinned::into_inner);
        let thinning = thinned.then(|| {
            let t = Thinning {
                stride,
                columns,
                rows_expected: rows,
                log_interval: model.log_every as f64 * model.dt,
                row_interval: (stride * model.log_every as u64) as f64 * model.dt,
                max_full_cells: self.budget.max_full_cells,
            };
            result.warnings.push(t.warning());
            t
        });
        if let (Some(m), Some(p)) = (mcap, &mcap_path) {
            m.into_inner()
                .close(&result.events)
                .map_err(|e| Error::Output(format!("cannot write {}: {e}", p.display())))?;
        }
        let mut run = Run {
            series,
            thinning,
            result,
            estimates,
            files: Vec::new(),
            plot_error: None,
            replay_error: None,
        };
        if let Some((dir, plots)) = &self.out {
            run.write_outputs(model, dir, csv_path, *plots, drawn.as_ref())?;
            run.files.extend(mcap_path);
        }
        Ok(run)
    }
}

/// What [`Simulation::write_to`] writes besides `summary.json` and `timeseries.csv`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct WriteOptions {
    /// The figures, one PNG each (`docs/outputs.md`), drawn from `timeseries.csv`.
    pub plots: bool,
}

impl Default for WriteOptions {
    /// Everything `host-sim run --out DIR` writes: the figures too.
    fn default() -> Self {
        Self { plots: true }
    }
}

impl WriteOptions {
    /// `summary.json` and `timeseries.csv` only (`host-sim run --no-plots`).
    pub fn without_plots() -> Self {
        Self { plots: false }
    }
}

/// What a run found.
#[derive(Debug)]
pub struct Run {
    /// The outcome, its reason and every figure of `summary.json`.
    pub result: RunResult,
    /// The owned estimates, in the order of their columns.
    pub estimates: Vec<EstimateInfo>,
    /// Every logged row (when kept, see [`Simulation::keep_series`]; never thinned).
    pub series: Option<TimeSeries>,
    /// How `timeseries.csv` and `run.mcap` were thinned (`None`: every logged row
    /// written; see [`Simulation::series_budget`]).
    pub thinning: Option<Thinning>,
    /// The files written (see [`Simulation::write_to`]): `timeseries.csv`,
    /// `summary.json`, then the figures and `replay.html`, then `run.mcap`.
    pub files: Vec<PathBuf>,
    /// Why the figures were not drawn (a failed plot does not fail the run).
    pub plot_error: Option<PlotError>,
    /// Why `replay.html` was not written (written with the figures; its failure does not
    /// fail the run).
    pub replay_error: Option<PlotError>,
}

impl Run {
    /// How the run ended.
    pub fn outcome(&self) -> Outcome {
        self.result.outcome
    }

    /// The exit code of `host-sim run` for this outcome.
    pub fn exit_code(&self) -> u8 {
        self.result.outcome.exit_code()
    }

    /// `summary.json` of this run of `model` (with `series` when its row files were
    /// thinned).
    pub fn summary_json(&self, model: &Model) -> serde_json::Value {
        let mut v = report::summary_json(model, &self.result, &self.estimates);
        if let (Some(t), Some(obj)) = (&self.thinning, v.as_object_mut()) {
            obj.insert("series".to_owned(), t.json());
        }
        v
    }

    /// Writes `summary.json` next to the finished `timeseries.csv`, then the figures.
    fn write_outputs(
        &mut self,
        model: &Model,
        dir: &Path,
        csv_path: Option<PathBuf>,
        plots: bool,
        rows: Option<&TimeSeries>,
    ) -> Result<(), Error> {
        let summary_path = dir.join("summary.json");
        report::write_summary(&summary_path, &self.summary_json(model))
            .map_err(|e| Error::Output(format!("cannot write {}: {e}", summary_path.display())))?;
        let has_csv = csv_path.is_some();
        self.files = csv_path.into_iter().chain([summary_path]).collect();
        if plots && has_csv {
            match report::plot_run_from(dir, rows) {
                Ok(p) => self.files.extend(p),
                Err(e) => self.plot_error = Some(e),
            }
            match report::write_replay_from(dir, rows) {
                Ok(p) => self.files.push(p),
                Err(e) => self.replay_error = Some(e),
            }
        }
        Ok(())
    }
}

/// How a run's row files were thinned ([`Simulation::series_budget`]; `summary.json`'s
/// `series`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Thinning {
    /// Every `stride`-th logged row was written (and the last).
    pub stride: u64,
    /// Columns of a row.
    pub columns: u64,
    /// Rows a whole run logs.
    pub rows_expected: u64,
    /// The scenario's `integration.log_interval` (s).
    pub log_interval: f64,
    /// Simulated time between two written rows (s): `stride` log intervals.
    pub row_interval: f64,
    /// The budget's [`SeriesBudget::max_full_cells`].
    pub max_full_cells: u64,
}

impl Thinning {
    /// The warning of a thinned run.
    pub fn warning(&self) -> String {
        let cells = self.rows_expected.saturating_mul(self.columns);
        format!(
            "timeseries.csv (and run.mcap) keep every {}th logged row (every {:?} s, and the last): \
             the full-rate series would be {:.1} M cells ({} rows × {} columns), over the \
             budget of {:.1} M; `--full-rate` writes every row (docs/outputs.md)",
            self.stride,
            self.row_interval,
            cells as f64 / 1e6,
            self.rows_expected,
            self.columns,
            self.max_full_cells as f64 / 1e6,
        )
    }

    /// `summary.json`'s `series`.
    pub fn json(&self) -> serde_json::Value {
        serde_json::json!({
            "stride": self.stride,
            "row_interval_s": self.row_interval,
            "log_interval_s": self.log_interval,
            "full_rate_rows": self.rows_expected,
            "columns": self.columns,
            "max_full_cells": self.max_full_cells,
        })
    }
}
