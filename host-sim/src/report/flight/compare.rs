//! `host-sim compare RUN FLIGHT`: a run and a flight of the same scenario on one time
//! axis, and their differences (docs/crazyflie.md "Flights beside simulations").
//!
//! Time: the run starts its formation at `t = 0`; the flight's formation starts when
//! the swarm tool enables it, after take-off, at the first row of any drone in state 1
//! (or `--start`). That instant is the common `t = 0`; the flight is resampled on its
//! own log period from there ([`FlightSeries`]) and the run interpolated linearly at the
//! same instants. The window ends with the shorter of the two: the run's last row, or
//! the last row in which every drone is still in formation, hold or landing (after it,
//! the tool lands them by the high-level commander).

use super::log::{column, for_each_row, open_csv, FlightError, FlightLog};
use super::series::FlightSeries;
use super::write::{changes, state_name, user_id};
use crate::model::Model;
use crate::report::{header as run_header, BASE_COLUMNS};
use ph_formation_core::Vec2;
use serde_json::{json, Value};
use std::path::{Path, PathBuf};

/// What a run directory must hold.
const RUN_DIR: &str = "the timeseries.csv of host-sim run's output directory";

/// A run's logged positions, velocities, angle errors and V (`timeseries.csv`) and its
/// `summary.json`.
#[derive(Clone, Debug)]
pub struct RunSeries {
    /// The run's directory.
    pub dir: PathBuf,
    /// Times (s).
    pub t: Vec<f64>,
    /// Positions, `rows × agents` (model order).
    pub q: Vec<Vec2<f64>>,
    /// Velocities, as [`Self::q`].
    pub v: Vec<Vec2<f64>>,
    /// `max_angle_err` (rad).
    pub max_angle_err: Vec<f64>,
    /// Every angle's error, `rows × angles` (model order, columns `angle_err_*`).
    pub angles: Vec<f64>,
    /// `V`.
    pub big_v: Vec<f64>,
    /// `summary.json` (`null` when absent).
    pub summary: Value,
    n: usize,
    n_angles: usize,
}

/// A run interpolated at one instant.
struct RunAt {
    q: Vec<Vec2<f64>>,
    v: Vec<Vec2<f64>>,
    angles: Vec<f64>,
    err: f64,
    big_v: f64,
}

impl RunSeries {
    /// Reads `dir/timeseries.csv` (columns `t`, `V`, `max_angle_err`, `x_<id>`, `y_<id>`,
    /// `vx_<id>`, `vy_<id>` of every agent of `model` and its `angle_err_*`) and
    /// `dir/summary.json` if there.
    ///
    /// # Errors
    ///
    /// A [`FlightError`] naming the file, column or line.
    pub fn read(dir: &Path, model: &Model) -> Result<Self, FlightError> {
        let path = dir.join("timeseries.csv");
        let (mut reader, header) = open_csv(&path)?;
        let need = |c: &str| column(&path, &header, c, RUN_DIR);
        let (ct, ce, cv) = (need("t")?, need("max_angle_err")?, need("V")?);
        let mut cq = Vec::with_capacity(model.n());
        for a in &model.agents {
            let [x, y, vx, vy] = ["x", "y", "vx", "vy"].map(|c| need(&format!("{c}_{}", a.name)));
            cq.push([x?, y?, vx?, vy?]);
        }
        let n_agent_cols = BASE_COLUMNS.len() + 4 * model.n();
        let ca = run_header(model, &[])[n_agent_cols..]
            .iter()
            .map(|c| need(c))
            .collect::<Result<Vec<usize>, _>>()?;
        let mut s = Self {
            dir: dir.to_path_buf(),
            t: Vec::new(),
            q: Vec::new(),
            v: Vec::new(),
            max_angle_err: Vec::new(),
            angles: Vec::new(),
            big_v: Vec::new(),
            summary: Value::Null,
            n: model.n(),
            n_angles: ca.len(),
        };
        for_each_row(&path, &mut reader, &header, |c| {
            s.t.push(c.number(ct)?);
            s.max_angle_err.push(c.optional(Some(ce))?);
            s.big_v.push(c.optional(Some(cv))?);
            for &[x, y, vx, vy] in &cq {
                s.q.push(Vec2::new(c.optional(Some(x))?, c.optional(Some(y))?));
                s.v.push(Vec2::new(c.optional(Some(vx))?, c.optional(Some(vy))?));
            }
            for &a in &ca {
                s.angles.push(c.optional(Some(a))?);
            }
            Ok(())
        })?;
        if s.t.len() < 2 {
            return Err(FlightError::Content {
                path,
                reason: "fewer than 2 rows".to_owned(),
            });
        }
        let sp = dir.join("summary.json");
        if let Ok(text) = std::fs::read_to_string(&sp) {
            s.summary = serde_json::from_str(&text).map_err(|e| FlightError::Content {
                path: sp,
                reason: format!("malformed JSON: {e}"),
            })?;
        }
        Ok(s)
    }

    /// The run at `t` (linear between rows), `None` outside it.
    fn at(&self, t: f64) -> Option<RunAt> {
        let last = *self.t.last()?;
        if t < self.t[0] || t > last + 1e-9 {
            return None;
        }
        let j = self
            .t
            .partition_point(|&x| x <= t)
            .clamp(1, self.t.len() - 1);
        let (a, b) = (j - 1, j);
        let w = if self.t[b] > self.t[a] {
            ((t - self.t[a]) / (self.t[b] - self.t[a])).clamp(0.0, 1.0)
        } else {
            0.0
        };
        let lerp = |x: &[f64], m: usize| -> Vec<f64> {
            (0..m)
                .map(|i| x[a * m + i] + (x[b * m + i] - x[a * m + i]) * w)
                .collect()
        };
        let lerp2 = |x: &[Vec2<f64>], m: usize| -> Vec<Vec2<f64>> {
            (0..m)
                .map(|i| x[a * m + i] + (x[b * m + i] - x[a * m + i]) * w)
                .collect()
        };
        Some(RunAt {
            q: lerp2(&self.q, self.n),
            v: lerp2(&self.v, self.n),
            angles: lerp(&self.angles, self.n_angles),
            err: lerp(&self.max_angle_err, 1)[0],
            big_v: lerp(&self.big_v, 1)[0],
        })
    }
}

/// The choices of a comparison.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Options {
    /// Converged: the largest angle error at most this (degrees) from then to the end of
    /// the window.
    pub settle_deg: f64,
    /// Within: every agent's RMS position difference (common start) at most this (m).
    pub tolerance_m: Option<f64>,
}

/// Both series on the common instants of the window.
#[derive(Clone, Debug, Default)]
pub struct Overlay {
    /// Time from the formation's start (s).
    pub t: Vec<f64>,
    /// The run's positions, `instants × agents`.
    pub run_q: Vec<Vec2<f64>>,
    /// The flight's positions, as [`Self::run_q`].
    pub flight_q: Vec<Vec2<f64>>,
    /// The run's velocities, as [`Self::run_q`].
    pub run_v: Vec<Vec2<f64>>,
    /// The flight's velocities, as [`Self::run_q`].
    pub flight_v: Vec<Vec2<f64>>,
    /// The run's angle errors (rad), `instants × angles` (model order).
    pub run_angles: Vec<f64>,
    /// The flight's, as [`Self::run_angles`].
    pub flight_angles: Vec<f64>,
    /// The run's V.
    pub run_big_v: Vec<f64>,
    /// Largest angle errors (rad).
    pub run_err: Vec<f64>,
    /// See [`Self::run_err`].
    pub flight_err: Vec<f64>,
    /// Drones in hold or landing, or with a fault, at each instant.
    pub flight_faulty: Vec<f64>,
    /// The run's events (time, kind) from `summary.json`.
    pub run_events: Vec<(f64, String)>,
}

/// A comparison: the JSON written to `compare.json` and the overlay drawn.
#[derive(Clone, Debug)]
pub struct Comparison {
    /// `compare.json`.
    pub json: Value,
    /// The series drawn.
    pub overlay: Overlay,
    /// Every agent's RMS difference (common start) within the tolerance (`None`
    /// without one).
    pub within: Option<bool>,
}

/// The first instant from which `err` stays at most `threshold` to the end.
fn settle(t: &[f64], err: &[f64], threshold: f64) -> Option<f64> {
    let mut first = None;
    for (&ti, &e) in t.iter().zip(err) {
        if e <= threshold {
            first = first.or(Some(ti));
        } else {
            first = None;
        }
    }
    first
}

fn rms(x: impl Iterator<Item = f64>) -> f64 {
    let (mut s, mut n) = (0.0, 0usize);
    for v in x {
        s += v * v;
        n += 1;
    }
    (s / n.max(1) as f64).sqrt()
}

fn centroid(q: &[Vec2<f64>]) -> Vec2<f64> {
    q.iter().fold(Vec2::zeros(), |a, b| a + b) / q.len().max(1) as f64
}

/// The last flight-clock time at which every drone was still in state 1–3.
fn formation_end(log: &FlightLog) -> Option<f64> {
    log.tracks
        .iter()
        .map(|k| {
            k.samples
                .iter()
                .rev()
                .find(|s| matches!(s.state, Some(1..=3)))
                .map(|s| s.t)
        })
        .collect::<Option<Vec<f64>>>()?
        .into_iter()
        .reduce(f64::min)
}

/// Holds `series` (the flight `log` resampled) against `run` for `model`.
///
/// # Errors
///
/// [`FlightError::Content`] when the window holds fewer than 2 common instants.
pub fn compare(
    run: &RunSeries,
    log: &FlightLog,
    series: &FlightSeries,
    model: &Model,
    options: Options,
) -> Result<Comparison, FlightError> {
    let n = model.n();
    let (err, angles) = series.angle_errors(model);
    let n_angles = 2 * model.triangles.len();
    let end = formation_end(log).map_or(f64::INFINITY, |e| e - series.start);
    let mut o = Overlay::default();
    for (f, &flight_err) in err.iter().enumerate() {
        let tau = series.t[f] - series.start;
        if tau < -1e-9 || tau > end + 1e-9 {
            continue;
        }
        let Some(r) = run.at(tau.max(0.0)) else {
            continue;
        };
        o.t.push(tau.max(0.0));
        o.run_q.extend(r.q);
        o.run_v.extend(r.v);
        o.run_angles.extend(r.angles);
        o.run_err.push(r.err);
        o.run_big_v.push(r.big_v);
        o.flight_q.extend_from_slice(series.q_at(f));
        o.flight_v.extend_from_slice(series.v_at(f));
        o.flight_angles
            .extend_from_slice(&angles[f * n_angles..(f + 1) * n_angles]);
        o.flight_err.push(flight_err);
        let faulty = (0..n)
            .filter(|&i| {
                matches!(series.state[f * n + i], Some(2 | 3))
                    || series.fault[f * n + i].is_some_and(|x| x != 0)
            })
            .count();
        o.flight_faulty.push(faulty as f64);
    }
    let frames = o.t.len();
    if frames < 2 {
        return Err(log.content(format!(
            "fewer than 2 instants in common with the run {} (the flight's formation from \
             {:.3} s to {:.3} s on its clock, the run to {:.3} s)",
            run.dir.display(),
            series.start,
            series.start + end,
            run.t.last().copied().unwrap_or(0.0)
        )));
    }
    // The common start: the flight moved by the difference of the formations'
    // centroids at t = 0 (one translation for every agent).
    let offset = centroid(&o.flight_q[..n]) - centroid(&o.run_q[..n]);
    let mut agents = Vec::with_capacity(n);
    let mut within = options.tolerance_m.map(|_| true);
    for (i, a) in model.agents.iter().enumerate() {
        let (fq, rq) = (&o.flight_q, &o.run_q);
        let d = |shift: Vec2<f64>| {
            (0..frames).map(move |f| (fq[f * n + i] - shift - rq[f * n + i]).norm())
        };
        let common = rms(d(offset));
        if let (Some(tol), Some(w)) = (options.tolerance_m, within.as_mut()) {
            *w &= common <= tol;
        }
        agents.push(json!({
            "agent": user_id(&a.name),
            "rms_m": rms(d(Vec2::zeros())),
            "rms_common_start_m": common,
            "max_m": d(Vec2::zeros()).fold(0.0, f64::max),
            "start_offset_m": (o.flight_q[i] - o.run_q[i]).norm(),
            "final_difference_m": d(Vec2::zeros()).next_back().unwrap_or(f64::NAN),
        }));
    }
    let worst = |e: &[f64]| e.iter().copied().fold(0.0, f64::max).to_degrees();
    let thr = options.settle_deg.to_radians();
    let summary = &run.summary;
    o.run_events = summary["events"]
        .as_array()
        .into_iter()
        .flatten()
        .filter_map(|e| Some((e["t"].as_f64()?, e["kind"].as_str()?.to_owned())))
        .collect();
    let flight_changes: Vec<Value> = changes(log)
        .into_iter()
        .map(|(t, agent, state, fault)| {
            json!({"t": t - series.start, "agent": user_id(&agent),
                   "state": state_name(state), "fault": fault})
        })
        .collect();
    let last = |agent: &str, f: fn(&super::log::Sample) -> Option<u64>| {
        log.track(agent)
            .and_then(|k| k.samples.iter().rev().find_map(f))
    };
    let json = json!({
        "run": run.dir.display().to_string(),
        "flight": log.path.display().to_string(),
        "scenario": model.name,
        "alignment": {
            "t0": "the formation's start: the run's t = 0; the flight's first row in state 1 \
                   (formation) of any drone, or --start",
            "flight_start_s": series.start,
            "window_s": [0.0, o.t[frames - 1]],
            "step_s": series.step,
            "instants": frames,
            "common_start_offset_m": [offset.x, offset.y],
        },
        "agents": agents,
        "angle_error_deg": {
            "run_worst": worst(&o.run_err),
            "flight_worst": worst(&o.flight_err),
            "run_final": o.run_err[frames - 1].to_degrees(),
            "flight_final": o.flight_err[frames - 1].to_degrees(),
        },
        "convergence_s": {
            "threshold_deg": options.settle_deg,
            "run": settle(&o.t, &o.run_err, thr),
            "flight": settle(&o.t, &o.flight_err, thr),
        },
        "faults": {
            "run": {
                "events": summary["events"],
                "policy": summary["policy"],
                "last_fault": summary["control"]["last_fault"],
            },
            "flight": {
                "changes": flight_changes,
                "policy": model.agents.iter().map(|a| json!({
                    "agent": user_id(&a.name),
                    "hold_ticks": last(&a.name, |s| s.hold_ticks),
                    "landings": last(&a.name, |s| s.landings),
                })).collect::<Vec<_>>(),
            },
        },
        "tolerance_m": options.tolerance_m,
        "within_tolerance": within,
    });
    Ok(Comparison {
        json,
        overlay: o,
        within,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn settle_is_the_first_instant_from_which_the_error_stays_below() {
        let t = [0.0, 1.0, 2.0, 3.0, 4.0];
        assert_eq!(settle(&t, &[5.0, 1.0, 5.0, 1.0, 1.0], 2.0), Some(3.0));
        assert_eq!(settle(&t, &[1.0; 5], 2.0), Some(0.0));
        assert_eq!(settle(&t, &[1.0, 1.0, 1.0, 1.0, 3.0], 2.0), None);
    }
}
