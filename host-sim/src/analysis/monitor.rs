//! The failure monitor: watches the snapshots of a run for collision, estimate collapse
//! and divergence (the run stops at a terminal failure), keeps the run's extremes, and
//! gives the verdict at the end (`docs/outputs.md`, "Outcome").

use super::outcome::{Event, Outcome};
use super::snapshot::{Diagnostics, Snapshot};
use super::steady::{schedule_integral, Instant, Series};
use crate::model::Model;
use ph_formation_core::Vec2;
use rayon::prelude::*;

/// Watches the snapshots of a run for failures and keeps the run's extremes.
#[derive(Clone, Debug)]
pub struct Monitor {
    /// `V(0)`.
    pub v0: Option<f64>,
    run_min: f64,
    epoch: usize,
    /// Largest rise of `V` above its running minimum (reset when a reference switches).
    pub max_rise: f64,
    /// When the largest rise peaked.
    pub max_rise_t: f64,
    pub(super) settle_candidate: Option<f64>,
    /// Every observed instant's errors and pose (the steady window's verdict).
    pub(super) series: Series,
    /// The centroid at the first instant.
    c0: Option<[f64; 2]>,
    /// Smallest estimate seen (`None` without estimates).
    pub min_estimate: Option<f64>,
    /// Smallest inter-agent distance seen, with time and pair.
    pub min_distance: (f64, f64, usize, usize),
    /// How many estimates are watched for a collapse.
    n_estimates: usize,
    /// The estimates held at `r_min` at the last instant, with the instant each reached
    /// it, by index (usually none: a list rather than a slot per estimate, which every
    /// instant of a 100,000-agent run would walk).
    held: Vec<(usize, f64)>,
    /// Scratch for the next `held`.
    held_next: Vec<(usize, f64)>,
    collapsed: bool,
    /// Failures detected, in order.
    pub events: Vec<Event>,
    /// A terminal failure (collision, divergence) has ended the run.
    pub terminal: bool,
}

impl Monitor {
    /// For a run of `model` with `n_estimates` estimates: the series of observed instants
    /// is sized for every control and log instant of the run, so that observing never
    /// allocates.
    pub fn new(model: &Model, n_estimates: usize) -> Self {
        let total = model.total_steps();
        let instants = total / model.steps_per_tick.max(1) + total / model.log_every.max(1) + 2;
        Self {
            v0: None,
            run_min: f64::INFINITY,
            epoch: 0,
            max_rise: 0.0,
            max_rise_t: 0.0,
            settle_candidate: None,
            series: Series {
                instants: Vec::with_capacity(instants),
            },
            c0: None,
            min_estimate: None,
            min_distance: (f64::INFINITY, 0.0, 0, 0),
            n_estimates,
            held: Vec::new(),
            held_next: Vec::new(),
            collapsed: false,
            events: Vec::new(),
            terminal: false,
        }
    }

    /// The noise-free settle time: the first observed instant after which every angle
    /// error stayed below the tolerance (`None` if the last one was above).
    pub fn settle_time(&self) -> Option<f64> {
        self.settle_candidate
    }

    /// The observed instants.
    pub fn series(&self) -> &Series {
        &self.series
    }

    /// Records the instant's errors and pose (`analysis::steady`).
    fn record_instant(&mut self, model: &Model, s: &Snapshot, q: &[Vec2<f64>]) {
        let n = q.len().max(1) as f64;
        let sum = q.iter().fold([0.0, 0.0], |a, p| [a[0] + p.x, a[1] + p.y]);
        let c = [sum[0] / n, sum[1] / n];
        let c0 = *self.c0.get_or_insert(c);
        let moved = schedule_integral(&model.velocity_reference, s.t);
        let translation = (c[0] - c0[0] - moved[0]).hypot(c[1] - c0[1] - moved[1]);
        let (mut scale, mut orientation) = (0.0, 0.0);
        if let (Some(l), Some(zs)) = (model.leader.as_ref(), model.z_star(s.t)) {
            if let (Some(a), Some(b)) = (q.get(l.a), q.get(l.b)) {
                let z = [a.x - b.x, a.y - b.y];
                scale = (z[0].hypot(z[1]) - zs[0].hypot(zs[1])).abs();
                // The signed angle from z* to z.
                orientation = (zs[0] * z[1] - zs[1] * z[0]).atan2(zs[0] * z[0] + zs[1] * z[1]);
            }
        }
        self.series.push(Instant {
            t: s.t,
            angle: s.max_angle_err,
            scale,
            velocity: s.vel_err,
            displacement: s.disp_err,
            orientation,
            translation,
        });
    }

    /// Observes one snapshot of positions `q` and the estimates; returns `true` when the
    /// run must stop.
    pub fn observe(
        &mut self,
        model: &Model,
        d: &Diagnostics,
        q: &[Vec2<f64>],
        est: &[f64],
    ) -> bool {
        let s = &d.snap;
        let cr = &model.criteria;
        let name = |i: usize| model.agents.get(i).map_or("?", |a| a.name.as_str());
        // V: its start, and its largest rise above the running minimum.
        let epoch = model.schedule_epoch(s.t);
        if self.v0.is_none() {
            self.v0 = Some(s.v);
        }
        self.record_instant(model, s, q);
        if epoch != self.epoch {
            self.epoch = epoch;
            self.run_min = f64::INFINITY;
        }
        if s.v.is_finite() {
            self.run_min = self.run_min.min(s.v);
            let rise = s.v - self.run_min;
            if rise > self.max_rise {
                self.max_rise = rise;
                self.max_rise_t = s.t;
            }
        }
        // Settling against the noise-free tolerance (a noisy run's settle time is the
        // steady window's, `analysis::steady`).
        if s.max_angle_err < cr.angle_tolerance {
            if self.settle_candidate.is_none() {
                self.settle_candidate = Some(s.t);
            }
        } else {
            self.settle_candidate = None;
        }
        // Extremes.
        if s.min_dist < self.min_distance.0 {
            self.min_distance = (s.min_dist, s.t, s.min_pair.0, s.min_pair.1);
        }
        // The smallest estimate (`f64::min` ignores NaN: the order does not matter), and
        // the estimates held at `r_min` (each keeps the instant it reached it while held).
        let floor = model.min_estimate * (1.0 + 1e-12);
        let watched = &est[..self.n_estimates.min(est.len())];
        let (least, any_held) = scan_estimates(est, watched.len(), floor, d.parallel());
        if let Some(m) = least {
            self.min_estimate = Some(self.min_estimate.map_or(m, |prev| prev.min(m)));
        }
        // Nothing held now nor before: the list stays empty without a walk.
        let due = if any_held || !self.held.is_empty() {
            self.update_held(watched, floor, s.t, cr.collapse_time)
        } else {
            None
        };
        if let (Some((k, t0)), false) = (due, self.collapsed) {
            self.collapse(model, d, k, t0);
        }
        // Terminal failures.
        if !s.finite {
            return self.stop(
                model,
                d,
                Outcome::Diverged,
                "the state became non-finite (NaN or infinite)".to_owned(),
            );
        }
        if s.max_speed > cr.divergence_speed {
            return self.stop(
                model,
                d,
                Outcome::Diverged,
                format!(
                    "an agent's speed reached {:.3e} m/s (> divergence_speed {} m/s)",
                    s.max_speed, cr.divergence_speed
                ),
            );
        }
        let v_cap = cr.divergence_energy_factor * self.v0.unwrap_or(0.0).max(1.0);
        if s.v.is_nan() || s.v > v_cap {
            return self.stop(
                model,
                d,
                Outcome::Diverged,
                format!(
                    "V reached {:.3e} (> {} × max(V(0), 1) = {:.3e})",
                    s.v, cr.divergence_energy_factor, v_cap
                ),
            );
        }
        if s.min_dist < cr.collision_distance {
            return self.stop(
                model,
                d,
                Outcome::Collision,
                format!(
                    "agents {} and {} collided: distance {:.4} m < collision_distance {} m",
                    name(s.min_pair.0),
                    name(s.min_pair.1),
                    s.min_dist,
                    cr.collision_distance
                ),
            );
        }
        false
    }

    /// The estimates of `watched` held at `r_min` (at most `floor`) at instant `t`, each
    /// with the instant it reached it (kept from the last instant while still held), and
    /// the first one held for `collapse_time` or longer, as `(index, since)`.
    fn update_held(
        &mut self,
        watched: &[f64],
        floor: f64,
        t: f64,
        collapse_time: f64,
    ) -> Option<(usize, f64)> {
        let mut before = self.held.iter().peekable();
        let mut due = None;
        self.held_next.clear();
        for (k, &r) in watched.iter().enumerate() {
            let held = r <= floor;
            if !held {
                continue;
            }
            while before.next_if(|&&(j, _)| j < k).is_some() {}
            match before.next_if(|&&(j, _)| j == k) {
                Some(&(_, t0)) => {
                    // Held since t0: collapsed once held for `collapse_time`.
                    if due.is_none() && t - t0 >= collapse_time {
                        due = Some((k, t0));
                    }
                    self.held_next.push((k, t0));
                }
                None => self.held_next.push((k, t)),
            }
        }
        std::mem::swap(&mut self.held, &mut self.held_next);
        due
    }

    /// Records the collapse of estimate `k`, held at `r_min` since `t0`.
    fn collapse(&mut self, model: &Model, d: &Diagnostics, k: usize, t0: f64) {
        let name = |i: usize| model.agents.get(i).map_or("?", |a| a.name.as_str());
        let s = &d.snap;
        let Some(e) = d.estimates.get(k) else {
            return;
        };
        self.collapsed = true;
        let r_true = s.est_true.get(k).copied().unwrap_or(f64::NAN);
        self.events.push(Event {
            t: t0,
            kind: Outcome::EstimateCollapse,
            message: format!(
                "estimate r̂ of edge {}–{} (owned by agent {}, angle at {} with other vertex {}) collapsed to r_min = {} m at t = {:.3} s and was still held there at t = {:.3} s (true distance then {:.3} m)",
                name(e.apex),
                name(e.far),
                name(e.owner),
                name(e.apex),
                name(e.other),
                model.min_estimate,
                t0,
                s.t,
                r_true,
            ),
        });
    }

    /// Ends the run with a terminal failure. An estimate held at `r_min` at that moment
    /// (for any time) is recorded first, as the likely cause.
    fn stop(&mut self, model: &Model, d: &Diagnostics, kind: Outcome, message: String) -> bool {
        if !self.collapsed {
            let held = self.held.iter().copied().min_by(|a, b| a.1.total_cmp(&b.1));
            if let Some((k, t0)) = held {
                self.collapse(model, d, k, t0);
            }
        }
        let t = d.snap.t;
        self.events.push(Event { t, kind, message });
        self.terminal = true;
        true
    }

    /// `max rise / V(0)` (0 when `V(0) = 0`).
    pub fn v_max_increase_rel(&self) -> f64 {
        match self.v0 {
            Some(v0) if v0 > 0.0 => self.max_rise / v0,
            _ => 0.0,
        }
    }
}

/// Estimates per parallel work item of [`scan_estimates`].
const CHUNK: usize = 2048;

/// The smallest of `est` (`None` when empty) and whether any of the first `watched` is at
/// most `floor`: one pass, on every thread of the current rayon pool when `parallel` (as
/// the diagnostics of the instant were). `f64::min` ignores NaN
/// and keeps its first operand on a tie (`+0` against `−0`), and rayon's reduction keeps
/// the order of the elements, so the answer is the sequential fold's on any number of
/// threads.
fn scan_estimates(est: &[f64], watched: usize, floor: f64, parallel: bool) -> (Option<f64>, bool) {
    let each = |(k, &r): (usize, &f64)| (r, k < watched && r <= floor);
    let merge = |a: (f64, bool), b: (f64, bool)| (a.0.min(b.0), a.1 || b.1);
    let scan = if parallel {
        est.par_iter()
            .enumerate()
            .with_min_len(CHUNK)
            .map(each)
            .reduce_with(merge)
    } else {
        est.iter().enumerate().map(each).reduce(merge)
    };
    scan.map_or((None, false), |(m, held)| (Some(m), held))
}
