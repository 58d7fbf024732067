//! A sweep's output folder: `sweep.json` (what was run), `runs.csv`, `points.csv`,
//! `points.json` and the figures (`docs/sweeps.md`). The same writer serves one run and a
//! merge of shards, so both give the same bytes.

use super::aggregate::{aggregate, PointStats, SETTLE_QUANTILES};
use super::error::SweepError;
use super::plan::{cell, Plan};
use super::run::{Finished, RunRow};
use super::runs_csv::{self, float};
use super::shard::Shard;
use crate::analysis::Outcome;
use serde::{Deserialize, Serialize};
use serde_json::json;
use std::path::{Path, PathBuf};

/// `sweep.json`: the sweep as run (points and their axis values), and how far it got.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Manifest {
    /// Sweep name.
    pub name: String,
    /// Free text.
    pub description: String,
    /// The sweep file (or `builtin:<name>`).
    pub sweep: String,
    /// The base scenario (file or `builtin:<name>`).
    pub base: String,
    /// Identifies the sweep text, base text, seed and runs (shards must agree).
    pub fingerprint: String,
    /// Sweep seed.
    pub seed: u64,
    /// Runs per point.
    pub runs: u64,
    /// Run `r` has the same seed at every point (absent: false).
    #[serde(default)]
    pub common_seeds: bool,
    /// `grid` or `random`.
    pub sampling: String,
    /// Axis keys.
    pub axes: Vec<String>,
    /// Each point's axis values, as in the CSV cells.
    pub points: Vec<Vec<String>>,
    /// The outcomes counted, in column order.
    pub outcomes: Vec<String>,
    /// `K/N` for a shard's output, absent for a whole sweep.
    pub shard: Option<String>,
    /// Jobs of this output (all of the sweep, or the shard's).
    pub jobs: u64,
    /// Jobs finished.
    pub finished: u64,
    /// Whether it stopped before every job ran (Ctrl-C).
    pub interrupted: bool,
}

impl Manifest {
    /// The manifest of `plan`'s runs in `shard`, as far as `done` got.
    pub fn new(plan: &Plan, shard: Shard, done: &Finished) -> Self {
        Self {
            name: plan.name.clone(),
            description: plan.description.clone(),
            sweep: plan.label.clone(),
            base: plan.base.label.clone(),
            fingerprint: plan.fingerprint.clone(),
            seed: plan.seed,
            runs: plan.runs,
            common_seeds: plan.common_seeds,
            sampling: plan.sampling.as_str().to_owned(),
            axes: plan.axes.clone(),
            points: plan
                .points
                .iter()
                .map(|p| p.iter().map(cell).collect())
                .collect(),
            outcomes: Outcome::ALL.iter().map(|o| o.as_str().to_owned()).collect(),
            shard: (!shard.is_all()).then(|| shard.to_string()),
            jobs: done.jobs,
            finished: done.rows.len() as u64,
            interrupted: done.interrupted,
        }
    }

    /// Reads `dir/sweep.json`.
    pub fn read(dir: &Path) -> Result<Self, SweepError> {
        let path = dir.join("sweep.json");
        let text = std::fs::read_to_string(&path)
            .map_err(|e| SweepError::output(&path, format!("cannot read: {e}")))?;
        serde_json::from_str(&text)
            .map_err(|e| SweepError::output(&path, format!("not a sweep manifest: {e}")))
    }
}

/// A number for JSON: finite, or null.
fn num(x: f64) -> serde_json::Value {
    if x.is_finite() {
        json!(x)
    } else {
        serde_json::Value::Null
    }
}

fn opt_cell(x: Option<f64>) -> String {
    x.map_or(String::new(), float)
}

/// The `points.csv` header.
pub fn points_header(m: &Manifest) -> Vec<String> {
    let mut h = vec!["point".to_owned()];
    h.extend(m.axes.iter().cloned());
    h.extend(["runs".to_owned(), "errors".to_owned()]);
    for o in &m.outcomes {
        h.extend([o.clone(), format!("{o}_lo"), format!("{o}_hi")]);
    }
    h.push("settled".to_owned());
    h.extend(SETTLE_QUANTILES.iter().map(|(_, n)| format!("settle_{n}")));
    h
}

fn write_points_csv(path: &Path, m: &Manifest, stats: &[PointStats]) -> Result<(), SweepError> {
    let err = |e: &dyn std::fmt::Display| SweepError::output(path, format!("cannot write: {e}"));
    let mut w = csv::Writer::from_path(path).map_err(|e| err(&e))?;
    w.write_record(points_header(m)).map_err(|e| err(&e))?;
    for s in stats {
        let mut rec = vec![s.point.to_string()];
        rec.extend(m.points[s.point].iter().cloned());
        rec.extend([s.n.to_string(), s.errors.to_string()]);
        for f in &s.fractions {
            rec.extend([f.fraction, f.lo, f.hi].map(|x| {
                if x.is_finite() {
                    float(x)
                } else {
                    String::new()
                }
            }));
        }
        rec.push(s.settled.to_string());
        rec.extend(s.settle.iter().map(|q| opt_cell(*q)));
        w.write_record(&rec).map_err(|e| err(&e))?;
    }
    w.flush().map_err(|e| err(&e))
}

/// `points.json`: the manifest's description of the sweep and one object per point.
pub fn points_json(m: &Manifest, stats: &[PointStats]) -> serde_json::Value {
    let points: Vec<serde_json::Value> = stats
        .iter()
        .map(|s| {
            let axes: serde_json::Map<String, serde_json::Value> = m
                .axes
                .iter()
                .zip(&m.points[s.point])
                .map(|(k, v)| (k.clone(), json!(v)))
                .collect();
            let outcomes: serde_json::Map<String, serde_json::Value> = s
                .fractions
                .iter()
                .map(|f| {
                    (
                        f.outcome.to_owned(),
                        json!({ "count": f.count, "fraction": num(f.fraction), "ci95": [num(f.lo), num(f.hi)] }),
                    )
                })
                .collect();
            let mut settle = serde_json::Map::new();
            settle.insert("settled".to_owned(), json!(s.settled));
            for ((_, name), q) in SETTLE_QUANTILES.iter().zip(&s.settle) {
                settle.insert((*name).to_owned(), q.map_or(serde_json::Value::Null, num));
            }
            json!({ "point": s.point, "axes": axes, "runs": s.n, "errors": s.errors,
                    "outcomes": outcomes, "settle_time": settle })
        })
        .collect();
    json!({
        "name": m.name, "sweep": m.sweep, "base": m.base, "seed": m.seed,
        "runs_per_point": m.runs, "sampling": m.sampling, "axes": m.axes,
        "finished": m.finished, "jobs": m.jobs, "interrupted": m.interrupted,
        "confidence": "95 % Wilson score interval", "points": points,
    })
}

/// Writes every output of `rows` into `dir` (created if needed); figures if `plots`.
/// Returns the files written and the per-point statistics.
pub fn write_all(
    dir: &Path,
    m: &Manifest,
    rows: &[RunRow],
    plots: bool,
) -> Result<(Vec<PathBuf>, Vec<PointStats>), SweepError> {
    std::fs::create_dir_all(dir)
        .map_err(|e| SweepError::output(dir, format!("cannot create: {e}")))?;
    let write_text = |name: &str, text: String| -> Result<PathBuf, SweepError> {
        let p = dir.join(name);
        std::fs::write(&p, text)
            .map_err(|e| SweepError::output(&p, format!("cannot write: {e}")))?;
        Ok(p)
    };
    let json_text =
        |v: &serde_json::Value| serde_json::to_string_pretty(v).unwrap_or_default() + "\n";
    let mut files = vec![write_text("sweep.json", json_text(&json!(m)))?];
    let runs = dir.join("runs.csv");
    runs_csv::write(&runs, m, rows)?;
    files.push(runs);
    let stats = aggregate(rows, m.points.len());
    let points = dir.join("points.csv");
    write_points_csv(&points, m, &stats)?;
    files.push(points);
    files.push(write_text(
        "points.json",
        json_text(&points_json(m, &stats)),
    )?);
    if plots && m.shard.is_none() {
        files.extend(super::figures::draw(dir, m, &stats)?);
    }
    Ok((files, stats))
}

/// Redraws the figures of the sweep output folder `dir` from its `sweep.json` and
/// `runs.csv` (for a shard: `sweep merge` first); returns the files.
pub fn redraw(dir: &Path) -> Result<Vec<PathBuf>, SweepError> {
    let m = Manifest::read(dir)?;
    let rows = runs_csv::read(&dir.join("runs.csv"), &m)?;
    super::figures::draw(dir, &m, &aggregate(&rows, m.points.len()))
}
