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
    /// The command line's `--set` (absent when none: `--resume` gives them again).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub set: Vec<String>,
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
        Self::of(
            plan,
            shard,
            done.jobs,
            done.rows.len() as u64,
            done.interrupted,
        )
    }

    /// The manifest of `plan`'s runs in `shard`: `jobs`, of which `finished` ran.
    pub fn of(plan: &Plan, shard: Shard, jobs: u64, finished: u64, interrupted: bool) -> Self {
        Self {
            name: plan.name.clone(),
            description: plan.description.clone(),
            sweep: plan.label.clone(),
            base: plan.base.label.clone(),
            set: plan.set.clone(),
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
            jobs,
            finished,
            interrupted,
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
    runs_csv::write(&dir.join("runs.csv"), m, rows)?;
    let stats = aggregate(rows, m.points.len());
    let files = write_summary(dir, m, &stats, plots)?;
    Ok((files, stats))
}

/// Writes `sweep.json` alone (as a sweep starts: a killed sweep leaves it for `--resume`).
pub fn write_manifest(dir: &Path, m: &Manifest) -> Result<PathBuf, SweepError> {
    let p = dir.join("sweep.json");
    std::fs::write(&p, json_text(&json!(m)))
        .map_err(|e| SweepError::output(&p, format!("cannot write: {e}")))?;
    Ok(p)
}

fn json_text(v: &serde_json::Value) -> String {
    serde_json::to_string_pretty(v).unwrap_or_default() + "\n"
}

/// Writes every output but `runs.csv` (already in `dir`) from the points' statistics:
/// `sweep.json`, `points.csv`, `points.json` and, if `plots` (and not a shard), the
/// figures. Returns the files, `runs.csv` included.
pub fn write_summary(
    dir: &Path,
    m: &Manifest,
    stats: &[PointStats],
    plots: bool,
) -> Result<Vec<PathBuf>, SweepError> {
    let mut files = vec![write_manifest(dir, m)?, dir.join("runs.csv")];
    let points = dir.join("points.csv");
    write_points_csv(&points, m, stats)?;
    files.push(points);
    let p = dir.join("points.json");
    std::fs::write(&p, json_text(&points_json(m, stats)))
        .map_err(|e| SweepError::output(&p, format!("cannot write: {e}")))?;
    files.push(p);
    if plots && m.shard.is_none() {
        files.extend(super::figures::draw(dir, m, stats)?);
    }
    Ok(files)
}

/// Redraws the figures of the sweep output folder `dir` from its `sweep.json` and
/// `runs.csv` (for a shard: `sweep merge` first); returns the files.
pub fn redraw(dir: &Path) -> Result<Vec<PathBuf>, SweepError> {
    let m = Manifest::read(dir)?;
    let path = dir.join("runs.csv");
    let mut r = runs_csv::open(&path, &m)?;
    let mut agg = super::aggregate::Sorted::new(m.points.len());
    let mut last = None;
    let mut rec = csv::StringRecord::new();
    let mut line = 1;
    while r
        .read_record(&mut rec)
        .map_err(|e| SweepError::output(&path, format!("cannot read: {e}")))?
    {
        line += 1;
        let row = runs_csv::parse(&path, &m, &rec, line)?;
        if last >= Some((row.point, row.run)) {
            return Err(SweepError::output(
                &path,
                format!("line {line}: not in job order (an unfinished sweep: --resume it)"),
            ));
        }
        last = Some((row.point, row.run));
        agg.add(&row);
    }
    super::figures::draw(dir, &m, &agg.finish())
}
