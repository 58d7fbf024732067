//! A flight log on one time grid, in the scenario's agent order: what the run's writers
//! take. Every agent's position and velocity is interpolated linearly between its own
//! packets at the grid's instants; its state and fault are the latest logged at or
//! before each instant. The diagnostics (angle errors, V's terms, distances) of each
//! instant come from [`Diagnostics`], the simulator's one implementation, on the logged
//! positions: a flight's angle errors are computed exactly as a run's.

use super::log::{FlightError, FlightLog, Track};
use crate::analysis::Diagnostics;
use crate::engine::{FrameCounts, Row};
use crate::model::Model;
use ph_formation_core::Vec2;

/// A flight resampled for `model`.
#[derive(Clone, Debug)]
pub struct FlightSeries {
    /// The flight-clock time that is the run's `t = 0` (the formation's start).
    pub start: f64,
    /// The grid's step (s): the median interval between one drone's packets.
    pub step: f64,
    /// The instants, on the flight's clock (s).
    pub t: Vec<f64>,
    /// Positions, `frames × agents` (model order).
    pub q: Vec<Vec2<f64>>,
    /// Velocities, as [`Self::q`].
    pub v: Vec<Vec2<f64>>,
    /// `formation.state` of each agent at each instant, as [`Self::q`].
    pub state: Vec<Option<u8>>,
    /// `formation.fault`, as [`Self::q`].
    pub fault: Vec<Option<u8>>,
    n: usize,
}

/// The median of the positive intervals between consecutive samples of every track.
fn median_interval(tracks: &[&Track]) -> Option<f64> {
    let mut d: Vec<f64> = tracks
        .iter()
        .flat_map(|k| k.samples.windows(2).map(|w| w[1].t - w[0].t))
        .filter(|d| *d > 0.0)
        .collect();
    if d.is_empty() {
        return None;
    }
    d.sort_by(f64::total_cmp);
    Some(d[d.len() / 2])
}

impl FlightSeries {
    /// `log` for `model`: every agent of the scenario must have rows and every logged
    /// agent must be in the scenario. `start`: the flight-clock time of the run's
    /// `t = 0`; by default the first row in state 1 (formation) of any drone.
    ///
    /// # Errors
    ///
    /// [`FlightError::Content`] naming the flight log and what does not fit.
    pub fn new(log: &FlightLog, model: &Model, start: Option<f64>) -> Result<Self, FlightError> {
        for k in &log.tracks {
            if !model.agents.iter().any(|a| a.name == k.agent) {
                return Err(log.content(format!(
                    "agent {} is not in the scenario {} ({})",
                    k.agent, model.name, model.source
                )));
            }
        }
        let mut tracks = Vec::with_capacity(model.n());
        for a in &model.agents {
            match log.track(&a.name) {
                Some(k) if k.samples.len() >= 2 => tracks.push(k),
                _ => {
                    return Err(log.content(format!(
                        "agent {} of the scenario {} has fewer than 2 rows",
                        a.name, model.name
                    )))
                }
            }
        }
        let start = match start.or_else(|| log.formation_start()) {
            Some(s) => s,
            None => {
                return Err(log.content(
                    "no row in state 1 (formation): give --start S, the flight-clock time \
                     of the formation's start"
                        .to_owned(),
                ))
            }
        };
        let step = median_interval(&tracks)
            .ok_or_else(|| log.content("no two rows of a drone at different times".to_owned()))?
            .max(1e-3);
        let first = tracks
            .iter()
            .map(|k| k.samples[0].t)
            .fold(f64::MIN, f64::max);
        let last = tracks
            .iter()
            .map(|k| k.samples[k.samples.len() - 1].t)
            .fold(f64::MAX, f64::min);
        // The grid holds `start` exactly: instants `start + k·step` within every track.
        let k0 = ((first - start) / step).ceil() as i64;
        let k1 = ((last - start) / step).floor() as i64;
        if k1 < k0 {
            return Err(log.content(
                "the drones' logs do not overlap in time (no instant logged by every drone)"
                    .to_owned(),
            ));
        }
        let n = tracks.len();
        let frames = (k1 - k0 + 1) as usize;
        let mut s = Self {
            start,
            step,
            t: (k0..=k1).map(|k| start + k as f64 * step).collect(),
            q: vec![Vec2::zeros(); frames * n],
            v: vec![Vec2::zeros(); frames * n],
            state: vec![None; frames * n],
            fault: vec![None; frames * n],
            n,
        };
        for (i, k) in tracks.iter().enumerate() {
            let mut j = 0usize;
            for (f, &t) in s.t.iter().enumerate() {
                while j + 2 < k.samples.len() && k.samples[j + 1].t <= t {
                    j += 1;
                }
                let (a, b) = (&k.samples[j], &k.samples[j + 1]);
                let w = if b.t > a.t {
                    ((t - a.t) / (b.t - a.t)).clamp(0.0, 1.0)
                } else {
                    1.0
                };
                let lerp = |p: f64, r: f64| p + (r - p) * w;
                s.q[f * n + i] = Vec2::new(lerp(a.x, b.x), lerp(a.y, b.y));
                s.v[f * n + i] = Vec2::new(lerp(a.vx, b.vx), lerp(a.vy, b.vy));
                let held = if b.t <= t { b } else { a };
                s.state[f * n + i] = held.state;
                s.fault[f * n + i] = held.fault;
            }
        }
        Ok(s)
    }

    /// Number of agents.
    pub fn n(&self) -> usize {
        self.n
    }

    /// Number of instants.
    pub fn frames(&self) -> usize {
        self.t.len()
    }

    /// Positions at instant `f`.
    pub fn q_at(&self, f: usize) -> &[Vec2<f64>] {
        &self.q[f * self.n..(f + 1) * self.n]
    }

    /// Calls `f` with each instant as a run's logged row: time on the flight's clock, the
    /// diagnostics evaluated by [`Diagnostics`] at the time since the formation's start
    /// (0 before it: what the references `v*(t)`, `z*(t)` are read at), no estimates,
    /// no frame counts.
    ///
    /// # Errors
    ///
    /// The first error `f` returns.
    pub fn for_each_row<E>(
        &self,
        model: &Model,
        mut f: impl FnMut(&Row<'_>) -> Result<(), E>,
    ) -> Result<(), E> {
        let mut d = Diagnostics::new(model, Vec::new());
        let n = self.n;
        for (k, &t) in self.t.iter().enumerate() {
            let (q, v) = (&self.q[k * n..(k + 1) * n], &self.v[k * n..(k + 1) * n]);
            d.evaluate(model, (t - self.start).max(0.0), q, v, &[]);
            d.snap.t = t;
            f(&Row {
                snap: &d.snap,
                q,
                v,
                estimates: &[],
                frames: FrameCounts::default(),
            })?;
        }
        Ok(())
    }

    /// The largest angle error (rad) at each instant, and every angle's signed error
    /// (`instants × angles`, model order), from [`Diagnostics`].
    pub fn angle_errors(&self, model: &Model) -> (Vec<f64>, Vec<f64>) {
        let mut max = Vec::with_capacity(self.frames());
        let mut all = Vec::with_capacity(self.frames() * 2 * model.triangles.len());
        let _ = self.for_each_row(model, |r| {
            max.push(r.snap.max_angle_err);
            all.extend_from_slice(&r.snap.angle_err);
            Ok::<(), ()>(())
        });
        (max, all)
    }

    /// Velocities at instant `f`.
    pub fn v_at(&self, f: usize) -> &[Vec2<f64>] {
        &self.v[f * self.n..(f + 1) * self.n]
    }
}
