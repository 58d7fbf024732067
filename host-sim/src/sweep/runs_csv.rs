//! `runs.csv`: one row per finished run, in job order; written and read back (for
//! `sweep merge`) without loss (floats in their shortest round-trip form).

use super::error::SweepError;
use super::output::Manifest;
use super::run::RunRow;
use std::path::Path;

/// The columns after the point's axis values.
const TAIL: [&str; 14] = [
    "seed",
    "outcome",
    "settle_time",
    "final_time",
    "final_max_angle_error",
    "final_displacement_error",
    "final_velocity_error",
    "min_distance",
    "min_estimate",
    "V0",
    "V_final",
    "rotation_deg",
    "shortened",
    "reason",
];

/// The header: `point, run`, the axis keys, then `seed, outcome, …, reason`.
pub fn header(m: &Manifest) -> Vec<String> {
    let mut h = vec!["point".to_owned(), "run".to_owned()];
    h.extend(m.axes.iter().cloned());
    h.extend(TAIL.iter().map(|s| (*s).to_owned()));
    h
}

/// A float in its shortest round-trip form, with an exponent when small or large
/// (`5.329070518200751e-15`), as Rust's `Debug` writes it.
pub fn float(x: f64) -> String {
    format!("{x:?}")
}

fn opt(x: Option<f64>) -> String {
    x.map_or(String::new(), float)
}

/// The cells of one row (its point's axis values from `m`).
pub fn record(m: &Manifest, r: &RunRow) -> Vec<String> {
    let mut rec = vec![r.point.to_string(), r.run.to_string()];
    rec.extend(m.points.get(r.point).cloned().unwrap_or_default());
    rec.extend([
        r.seed.to_string(),
        r.outcome.clone(),
        opt(r.settle_time),
        float(r.final_time),
        float(r.final_max_angle_error),
        float(r.final_displacement_error),
        float(r.final_velocity_error),
        float(r.min_distance),
        opt(r.min_estimate),
        float(r.v0),
        float(r.v_final),
        opt(r.rotation_deg),
        r.shortened.map_or(String::new(), |k| k.to_string()),
        r.reason.clone(),
    ]);
    rec
}

/// Writes `rows` (their points' axis values from `m`).
pub fn write(path: &Path, m: &Manifest, rows: &[RunRow]) -> Result<(), SweepError> {
    let err = |e: &dyn std::fmt::Display| SweepError::output(path, format!("cannot write: {e}"));
    let mut w = csv::Writer::from_path(path).map_err(|e| err(&e))?;
    w.write_record(header(m)).map_err(|e| err(&e))?;
    for r in rows {
        w.write_record(record(m, r)).map_err(|e| err(&e))?;
    }
    w.flush().map_err(|e| err(&e))
}

/// Opens a `runs.csv` written for `m` and checks its header.
pub fn open(path: &Path, m: &Manifest) -> Result<csv::Reader<std::fs::File>, SweepError> {
    let mut r = csv::Reader::from_path(path)
        .map_err(|e| SweepError::output(path, format!("cannot read: {e}")))?;
    let want = header(m);
    let got: Vec<String> = r
        .headers()
        .map_err(|e| SweepError::output(path, format!("cannot read: {e}")))?
        .iter()
        .map(str::to_owned)
        .collect();
    if got != want {
        return Err(SweepError::output(
            path,
            format!("header is not {}", want.join(",")),
        ));
    }
    Ok(r)
}

/// The point and run of a record (its first two cells), read without the rest.
pub fn key(rec: &csv::StringRecord) -> Option<(usize, u64)> {
    Some((rec.get(0)?.parse().ok()?, rec.get(1)?.parse().ok()?))
}

/// Parses one record of a `runs.csv` written for `m` (`line`: its line, for errors).
pub fn parse(
    path: &Path,
    m: &Manifest,
    rec: &csv::StringRecord,
    line: u64,
) -> Result<RunRow, SweepError> {
    let a = m.axes.len();
    let cell = |k: usize| rec.get(k).unwrap_or("");
    let bad = |col: &str| SweepError::output(path, format!("line {line}: bad `{col}`"));
    let num = |k: usize, col: &str| cell(k).parse::<f64>().map_err(|_| bad(col));
    let opt_num = |k: usize, col: &str| match cell(k) {
        "" => Ok(None),
        s => s.parse::<f64>().map(Some).map_err(|_| bad(col)),
    };
    let t = 2 + a;
    let row = RunRow {
        point: cell(0).parse().map_err(|_| bad("point"))?,
        run: cell(1).parse().map_err(|_| bad("run"))?,
        seed: cell(t).parse().map_err(|_| bad("seed"))?,
        outcome: cell(t + 1).to_owned(),
        settle_time: opt_num(t + 2, "settle_time")?,
        final_time: num(t + 3, "final_time")?,
        final_max_angle_error: num(t + 4, "final_max_angle_error")?,
        final_displacement_error: num(t + 5, "final_displacement_error")?,
        final_velocity_error: num(t + 6, "final_velocity_error")?,
        min_distance: num(t + 7, "min_distance")?,
        min_estimate: opt_num(t + 8, "min_estimate")?,
        v0: num(t + 9, "V0")?,
        v_final: num(t + 10, "V_final")?,
        rotation_deg: opt_num(t + 11, "rotation_deg")?,
        shortened: match cell(t + 12) {
            "" => None,
            s => Some(s.parse().map_err(|_| bad("shortened"))?),
        },
        reason: cell(t + 13).to_owned(),
    };
    if row.point >= m.points.len() || row.run >= m.runs {
        return Err(bad(if row.point >= m.points.len() {
            "point"
        } else {
            "run"
        }));
    }
    Ok(row)
}

/// Reads the rows of a `runs.csv` written for `m` (in memory: for small sweeps and tests;
/// the command streams, `journal.rs`).
pub fn read(path: &Path, m: &Manifest) -> Result<Vec<RunRow>, SweepError> {
    let mut r = open(path, m)?;
    let mut rows = Vec::new();
    for (i, rec) in r.records().enumerate() {
        let line = i as u64 + 2;
        let rec = rec.map_err(|e| SweepError::output(path, format!("line {line}: {e}")))?;
        rows.push(parse(path, m, &rec, line)?);
    }
    Ok(rows)
}
