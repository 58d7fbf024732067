//! `host-sim compare STEP STEP_LOG`: a logged velocity step (`swarm.py step`) against
//! `host-sim vehicle step`'s `step.csv`, with the semantics of `swarm.py compare-step`:
//! the logged `vx` from the first row whose setpoint is the step's speed (`drone_ms`,
//! the drone's clock), from −0.2 s to 2 s, against `v_along` (0 before the step, linear
//! between its millisecond samples), shifted by the multiple of 5 ms within ±200 ms that
//! gives the smallest RMS difference (the setpoint column is the second log block's
//! latest value: up to four log periods late); within when that RMS is at most the
//! tolerance.

use super::log::{column, for_each_row, open_csv, FlightError, FLIGHT_LOG};
use serde_json::{json, Value};
use std::path::{Path, PathBuf};

/// What `host-sim vehicle step`'s file must hold.
const STEP_CSV: &str = "host-sim vehicle step's step.csv";

/// The result of a step comparison.
#[derive(Clone, Debug, PartialEq)]
pub struct StepComparison {
    /// RMS difference at the best shift (m/s).
    pub rms: f64,
    /// Largest difference at that shift (m/s).
    pub max: f64,
    /// The shift (ms) added to the log's times.
    pub shift_ms: i32,
    /// Logged samples in the window.
    pub samples: usize,
    /// The logged samples `(t from the step, vx)` and the model at the best shift.
    pub logged: Vec<(f64, f64)>,
    /// `v_along` of the model at each logged sample's shifted time.
    pub model_at: Vec<f64>,
}

impl StepComparison {
    /// `compare.json`.
    pub fn json(&self, log: &Path, model: &Path, speed: f64, tolerance: f64) -> Value {
        json!({
            "kind": "step",
            "step_log": log.display().to_string(),
            "vehicle_step": model.display().to_string(),
            "speed_m_s": speed,
            "rms_m_s": self.rms,
            "max_m_s": self.max,
            "shift_ms": self.shift_ms,
            "samples": self.samples,
            "tolerance_m_s": tolerance,
            "within_tolerance": self.rms <= tolerance,
        })
    }
}

/// `step.csv` of a directory, or the file itself.
pub fn step_csv(path: &Path) -> PathBuf {
    if path.is_dir() {
        path.join("step.csv")
    } else {
        path.to_path_buf()
    }
}

/// Reads `(t, v_along)` of `host-sim vehicle step`'s file.
fn read_model(path: &Path) -> Result<Vec<(f64, f64)>, FlightError> {
    let (mut reader, header) = open_csv(path)?;
    let (ct, cv) = (
        column(path, &header, "t", STEP_CSV)?,
        column(path, &header, "v_along", STEP_CSV)?,
    );
    let mut out = Vec::new();
    for_each_row(path, &mut reader, &header, |c| {
        out.push((c.number(ct)?, c.number(cv)?));
        Ok(())
    })?;
    if out.len() < 2 {
        return Err(FlightError::Content {
            path: path.to_path_buf(),
            reason: "fewer than 2 rows".to_owned(),
        });
    }
    Ok(out)
}

/// Reads `(drone_ms, setpoint_vx, vx)` of the step log (`setpoint_vx`, `vx`: NaN when
/// empty).
fn read_log(path: &Path, agent: Option<&str>) -> Result<Vec<(f64, f64, f64)>, FlightError> {
    let (mut reader, header) = open_csv(path)?;
    let need = |c: &str| column(path, &header, c, FLIGHT_LOG);
    let (cms, csp, cvx, cag) = (
        need("drone_ms")?,
        need("setpoint_vx")?,
        need("vx")?,
        need("agent")?,
    );
    let mut out = Vec::new();
    for_each_row(path, &mut reader, &header, |c| {
        if agent.is_some_and(|a| c.record.get(cag).map(str::trim) != Some(a)) {
            return Ok(());
        }
        out.push((
            c.number(cms)?,
            c.optional(Some(csp))?,
            c.optional(Some(cvx))?,
        ));
        Ok(())
    })?;
    Ok(out)
}

/// Holds the step log `log` (rows of `agent`, every row without one) against
/// `vehicle_step` for a step of `speed` m/s.
///
/// # Errors
///
/// A [`FlightError`] naming the file and what is wrong (no setpoint of that speed, no
/// samples in the window, a bad value).
pub fn compare_step(
    log: &Path,
    vehicle_step: &Path,
    speed: f64,
    agent: Option<&str>,
) -> Result<StepComparison, FlightError> {
    let rows = read_log(log, agent)?;
    let content = |reason: String| FlightError::Content {
        path: log.to_path_buf(),
        reason,
    };
    let start = rows
        .iter()
        .find(|r| (r.1 - speed).abs() < 1e-6)
        .map(|r| r.0)
        .ok_or_else(|| content(format!("no setpoint_vx of {speed} m/s (--speed)")))?;
    let logged: Vec<(f64, f64)> = rows
        .iter()
        .map(|r| ((r.0 - start) / 1000.0, r.2))
        .filter(|(t, v)| !v.is_nan() && (-0.2..=2.0).contains(t))
        .collect();
    if logged.is_empty() {
        return Err(content(
            "no vx sample from -0.2 s to 2 s of the step".to_owned(),
        ));
    }
    let model = read_model(vehicle_step)?;
    let at = |t: f64| -> f64 {
        if t <= 0.0 {
            return 0.0;
        }
        // step.csv: every millisecond.
        let k = ((t * 1000.0) as usize).min(model.len() - 2);
        let ((t0, v0), (t1, v1)) = (model[k], model[k + 1]);
        v0 + (v1 - v0) * (t - t0) / (t1 - t0)
    };
    let mut best: Option<StepComparison> = None;
    for shift_ms in (-200..=200).step_by(5) {
        let s = f64::from(shift_ms) / 1000.0;
        let kept: Vec<(f64, f64)> = logged
            .iter()
            .copied()
            .filter(|(t, _)| t + s >= -0.2)
            .collect();
        let model_at: Vec<f64> = kept.iter().map(|(t, _)| at(t + s)).collect();
        let d: Vec<f64> = kept
            .iter()
            .zip(&model_at)
            .map(|((_, v), m)| v - m)
            .collect();
        if d.is_empty() {
            continue;
        }
        let rms = (d.iter().map(|x| x * x).sum::<f64>() / d.len() as f64).sqrt();
        if best.as_ref().is_none_or(|b| rms < b.rms) {
            best = Some(StepComparison {
                rms,
                max: d.iter().map(|x| x.abs()).fold(0.0, f64::max),
                shift_ms,
                samples: logged.len(),
                logged: kept,
                model_at,
            });
        }
    }
    best.ok_or_else(|| content("no sample at any shift".to_owned()))
}
