//! Diagnostics of one instant (V and its terms S13, angle errors, estimates against true
//! distances, maneuver errors, minimum distance) and the failure monitor (collision,
//! estimate collapse, divergence, convergence).
//!
//! Everything is evaluated from the TRUE state, not from what the agents measured.

use crate::model::Model;
use controller_core::{energy, OwnedEstimate, Vec2};
use std::fmt;

/// Where one owned estimate belongs (by agent index).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct EstimateInfo {
    /// The agent that owns (integrates) it.
    pub owner: usize,
    /// The angle's apex `u`.
    pub apex: usize,
    /// The far vertex `f` of its edge.
    pub far: usize,
    /// The angle's other far vertex `w`.
    pub other: usize,
    /// `c_e` of the angle.
    pub gain: f64,
    /// Triangle index in the owner's controller configuration.
    pub local_triangle: usize,
    /// Angle index (0, 1) in the triangle.
    pub angle: usize,
    /// Edge index (0, 1) in the angle.
    pub edge: usize,
}

/// Resolves the estimates reported by agent `owner`'s controller to agent indices.
pub fn resolve_estimates(
    model: &Model,
    owner: usize,
    owned: &[OwnedEstimate<f64>],
) -> Result<Vec<EstimateInfo>, String> {
    let tris: Vec<usize> = model.triangles_of(owner).collect();
    owned
        .iter()
        .map(|e| {
            let k = *tris
                .get(e.triangle)
                .ok_or_else(|| format!("estimate of unknown triangle {}", e.triangle))?;
            let a = model.triangles[k]
                .angles
                .get(e.angle)
                .ok_or_else(|| format!("estimate of unknown angle {}", e.angle))?;
            let (far, other) = match e.edge {
                0 => (a.far[0], a.far[1]),
                _ => (a.far[1], a.far[0]),
            };
            if model.agents[far].id != e.far || model.agents[a.apex].id != e.apex {
                return Err(format!(
                    "estimate layout mismatch for agent index {owner}: core says apex {} far {}",
                    e.apex, e.far
                ));
            }
            Ok(EstimateInfo {
                owner,
                apex: a.apex,
                far,
                other,
                gain: a.estimator_gain,
                local_triangle: e.triangle,
                angle: e.angle,
                edge: e.edge,
            })
        })
        .collect()
}

/// Exact minimum pairwise distance by sort-and-sweep on `x`: the order is kept between
/// calls (insertion sort on an almost sorted list), and the sweep stops as soon as the
/// `x` gap exceeds the best distance. Expected cost O(N) for spread-out formations;
/// worst case O(N²) when all agents share one `x`.
#[derive(Clone, Debug, Default)]
pub struct MinDistance {
    order: Vec<usize>,
}

impl MinDistance {
    /// For `n` agents.
    pub fn new(n: usize) -> Self {
        Self {
            order: (0..n).collect(),
        }
    }

    /// `(distance, i, j)` of the closest pair (`inf` with fewer than two agents).
    pub fn compute(&mut self, q: &[Vec2<f64>]) -> (f64, usize, usize) {
        let x = |i: usize| q.get(i).map_or(f64::NAN, |p| p.x);
        // Insertion sort by x (NaN sorts last through total_cmp).
        for k in 1..self.order.len() {
            let mut j = k;
            while j > 0 && x(self.order[j - 1]).total_cmp(&x(self.order[j])).is_gt() {
                self.order.swap(j - 1, j);
                j -= 1;
            }
        }
        let mut best = (f64::INFINITY, 0, 0);
        for (a, &i) in self.order.iter().enumerate() {
            for &j in self.order.iter().skip(a + 1) {
                if x(j) - x(i) >= best.0 {
                    break;
                }
                let d = (q[j] - q[i]).norm();
                if d < best.0 {
                    best = (d, i.min(j), i.max(j));
                }
            }
        }
        best
    }
}

/// Everything the diagnostics know about one instant.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Snapshot {
    /// Time (s).
    pub t: f64,
    /// `V` (S13).
    pub v: f64,
    /// Kinetic term `Σ ½ m |v − v*|²`.
    pub v_kin: f64,
    /// Angle term `Σ ½ c ỹ²`.
    pub v_ang: f64,
    /// Leader term `½ k_z |z̃|²`.
    pub v_lead: f64,
    /// Estimator term `Σ ½ c_e (r̂ − r)²`.
    pub v_est: f64,
    /// Signed angle errors `α − α*` (rad), model order (triangles, then angles).
    pub angle_err: Vec<f64>,
    /// `max |α − α*|`.
    pub max_angle_err: f64,
    /// True distances of the estimates, layout order.
    pub est_true: Vec<f64>,
    /// `|z − z*|` (0 without a leader edge).
    pub disp_err: f64,
    /// `max_n |v_n − v*|`.
    pub vel_err: f64,
    /// Smallest inter-agent distance.
    pub min_dist: f64,
    /// The closest pair (agent indices).
    pub min_pair: (usize, usize),
    /// Largest speed.
    pub max_speed: f64,
    /// Every position and velocity is finite.
    pub finite: bool,
}

/// Evaluates [`Snapshot`]s without allocating.
#[derive(Clone, Debug)]
pub struct Diagnostics {
    /// The estimates, in layout order.
    pub estimates: Vec<EstimateInfo>,
    /// The latest snapshot.
    pub snap: Snapshot,
    min_distance: MinDistance,
}

fn unit(d: Vec2<f64>) -> Vec2<f64> {
    let n = d.norm();
    if n > 0.0 {
        d / n
    } else {
        Vec2::zeros()
    }
}

impl Diagnostics {
    /// For `model` with these estimates.
    pub fn new(model: &Model, estimates: Vec<EstimateInfo>) -> Self {
        let snap = Snapshot {
            angle_err: vec![0.0; 2 * model.triangles.len()],
            est_true: vec![0.0; estimates.len()],
            ..Snapshot::default()
        };
        Self {
            estimates,
            snap,
            min_distance: MinDistance::new(model.n()),
        }
    }

    /// Evaluates the instant `t` with true positions `q`, velocities `v` and the current
    /// estimate values `est` (layout order).
    pub fn evaluate(
        &mut self,
        model: &Model,
        t: f64,
        q: &[Vec2<f64>],
        v: &[Vec2<f64>],
        est: &[f64],
    ) {
        let s = &mut self.snap;
        s.t = t;
        let vs = model.v_star(t);
        let v_star = Vec2::new(vs[0], vs[1]);
        s.v_kin = 0.0;
        s.vel_err = 0.0;
        s.max_speed = 0.0;
        s.finite = true;
        for ((a, qi), vi) in model.agents.iter().zip(q).zip(v) {
            s.v_kin += energy::kinetic(a.mass, vi, &v_star);
            s.vel_err = s.vel_err.max((vi - v_star).norm());
            s.max_speed = s.max_speed.max(vi.norm());
            s.finite &=
                qi.x.is_finite() && qi.y.is_finite() && vi.x.is_finite() && vi.y.is_finite();
        }
        s.v_ang = 0.0;
        s.max_angle_err = 0.0;
        for (t_i, tri) in model.triangles.iter().enumerate() {
            for (a_i, a) in tri.angles.iter().enumerate() {
                let su = unit(q[a.far[0]] - q[a.apex]);
                let sw = unit(q[a.far[1]] - q[a.apex]);
                let y = su.dot(&sw);
                s.v_ang += energy::angle(a.stiffness, y - a.desired.cos());
                let err = y.clamp(-1.0, 1.0).acos() - a.desired;
                if let Some(slot) = s.angle_err.get_mut(2 * t_i + a_i) {
                    *slot = err;
                }
                // NaN propagates as "not settled".
                s.max_angle_err = if err.is_nan() {
                    f64::NAN
                } else {
                    s.max_angle_err.max(err.abs())
                };
            }
        }
        s.v_lead = 0.0;
        s.disp_err = 0.0;
        if let (Some(l), Some(zs)) = (&model.leader, model.z_star(t)) {
            let zt = q[l.a] - q[l.b] - Vec2::new(zs[0], zs[1]);
            s.v_lead = energy::leader(l.stiffness, &zt);
            s.disp_err = zt.norm();
        }
        s.v_est = 0.0;
        for ((e, r_hat), r_true) in self.estimates.iter().zip(est).zip(s.est_true.iter_mut()) {
            *r_true = (q[e.apex] - q[e.far]).norm();
            s.v_est += energy::estimate(e.gain, *r_hat, *r_true);
        }
        s.v = s.v_kin + s.v_ang + s.v_lead + s.v_est;
        let (d, i, j) = self.min_distance.compute(q);
        s.min_dist = d;
        s.min_pair = (i, j);
    }
}

/// How a run ended (`summary.json` field `outcome`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Outcome {
    /// Angles, displacement and velocity errors within tolerance at the end.
    Converged,
    /// Two agents closer than the collision distance.
    Collision,
    /// An estimate held at `r_min`.
    EstimateCollapse,
    /// Non-finite state, excessive speed, or unbounded `V`.
    Diverged,
    /// None of the above, but not within tolerance at the end.
    NotConverged,
}

impl Outcome {
    /// The name in `summary.json`.
    pub fn as_str(self) -> &'static str {
        match self {
            Outcome::Converged => "converged",
            Outcome::Collision => "collision",
            Outcome::EstimateCollapse => "estimate_collapse",
            Outcome::Diverged => "diverged",
            Outcome::NotConverged => "not_converged",
        }
    }

    /// The process exit code.
    pub fn exit_code(self) -> u8 {
        use crate::scenario::error::exit_code as x;
        match self {
            Outcome::Converged => x::CONVERGED,
            Outcome::Collision => x::COLLISION,
            Outcome::EstimateCollapse => x::ESTIMATE_COLLAPSE,
            Outcome::Diverged => x::DIVERGED,
            Outcome::NotConverged => x::NOT_CONVERGED,
        }
    }
}

impl fmt::Display for Outcome {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.as_str())
    }
}

/// A detected failure.
#[derive(Clone, Debug, PartialEq)]
pub struct Event {
    /// When (s).
    pub t: f64,
    /// Which failure.
    pub kind: Outcome,
    /// A human sentence.
    pub message: String,
}

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
    settle_candidate: Option<f64>,
    /// Smallest estimate seen (`None` without estimates).
    pub min_estimate: Option<f64>,
    /// Smallest inter-agent distance seen, with time and pair.
    pub min_distance: (f64, f64, usize, usize),
    at_min_since: Vec<Option<f64>>,
    collapsed: bool,
    /// Failures detected, in order.
    pub events: Vec<Event>,
    /// A terminal failure (collision, divergence) has ended the run.
    pub terminal: bool,
}

impl Monitor {
    /// For `n_estimates` estimates.
    pub fn new(n_estimates: usize) -> Self {
        Self {
            v0: None,
            run_min: f64::INFINITY,
            epoch: 0,
            max_rise: 0.0,
            max_rise_t: 0.0,
            settle_candidate: None,
            min_estimate: None,
            min_distance: (f64::INFINITY, 0.0, 0, 0),
            at_min_since: vec![None; n_estimates],
            collapsed: false,
            events: Vec::new(),
            terminal: false,
        }
    }

    /// The settle time: the first observed instant after which every angle error stayed
    /// below the tolerance (`None` if the last one was above).
    pub fn settle_time(&self) -> Option<f64> {
        self.settle_candidate
    }

    /// Observes one snapshot and the estimates; returns `true` when the run must stop.
    pub fn observe(&mut self, model: &Model, d: &Diagnostics, est: &[f64]) -> bool {
        let s = &d.snap;
        let cr = &model.criteria;
        let name = |i: usize| model.agents.get(i).map_or(0, |a| a.id);
        // V: its start, and its largest rise above the running minimum.
        let epoch = model.schedule_epoch(s.t);
        if self.v0.is_none() {
            self.v0 = Some(s.v);
        }
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
        // Settling.
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
        for (k, &r) in est.iter().enumerate() {
            self.min_estimate = Some(self.min_estimate.map_or(r, |m: f64| m.min(r)));
            let held = r <= model.min_estimate * (1.0 + 1e-12);
            let Some(since) = self.at_min_since.get_mut(k) else {
                continue;
            };
            match (held, *since) {
                (true, None) => *since = Some(s.t),
                (false, _) => *since = None,
                (true, Some(t0)) => {
                    if !self.collapsed && s.t - t0 >= cr.collapse_time {
                        self.collapse(model, d, k, t0);
                    }
                }
            }
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

    /// Records the collapse of estimate `k`, held at `r_min` since `t0`.
    fn collapse(&mut self, model: &Model, d: &Diagnostics, k: usize, t0: f64) {
        let name = |i: usize| model.agents.get(i).map_or(0, |a| a.id);
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
            let held = self
                .at_min_since
                .iter()
                .enumerate()
                .filter_map(|(k, s)| s.map(|t0| (k, t0)))
                .min_by(|a, b| a.1.total_cmp(&b.1));
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

    /// The outcome and its reason, given the last snapshot.
    ///
    /// A terminal failure preceded by an estimate collapse is reported as the collapse (the
    /// cause); a collapse in a run that still converged is only an event.
    pub fn verdict(&self, model: &Model, last: &Snapshot) -> (Outcome, String) {
        let cr = &model.criteria;
        let chain = || {
            self.events
                .iter()
                .map(|e| format!("t = {:.3} s: {}", e.t, e.message))
                .collect::<Vec<_>>()
                .join("; then ")
        };
        let collapse = self
            .events
            .iter()
            .find(|e| e.kind == Outcome::EstimateCollapse);
        if self.terminal {
            let kind = match (collapse, self.events.last()) {
                (Some(c), Some(last)) if c.t <= last.t => Outcome::EstimateCollapse,
                (_, Some(last)) => last.kind,
                _ => Outcome::Diverged,
            };
            return (kind, chain());
        }
        let settled = self.settle_candidate.is_some();
        let disp_ok = last.disp_err <= cr.displacement_tolerance;
        let vel_ok = last.vel_err <= cr.velocity_tolerance;
        if settled && disp_ok && vel_ok {
            let mut why = format!(
                "every angle error below {} rad from t = {:.3} s; final |z − z*| = {:.2e} m, max |v − v*| = {:.2e} m/s",
                cr.angle_tolerance,
                self.settle_candidate.unwrap_or(0.0),
                last.disp_err,
                last.vel_err
            );
            if !self.events.is_empty() {
                why.push_str(&format!(" (despite: {})", chain()));
            }
            return (Outcome::Converged, why);
        }
        let mut missing = Vec::new();
        if !settled {
            missing.push(format!(
                "max angle error {:.3e} rad ≥ {} rad",
                last.max_angle_err, cr.angle_tolerance
            ));
        }
        if !disp_ok {
            missing.push(format!(
                "|z − z*| = {:.3e} m > {} m",
                last.disp_err, cr.displacement_tolerance
            ));
        }
        if !vel_ok {
            missing.push(format!(
                "max |v − v*| = {:.3e} m/s > {} m/s",
                last.vel_err, cr.velocity_tolerance
            ));
        }
        let end = format!(
            "not converged at t = {:.3} s: {}",
            last.t,
            missing.join(", ")
        );
        match collapse {
            Some(_) => (Outcome::EstimateCollapse, format!("{}; {end}", chain())),
            None => (Outcome::NotConverged, end),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn min_distance_matches_brute_force() {
        let mut q: Vec<Vec2<f64>> = (0..50)
            .map(|i| {
                let f = f64::from(i);
                Vec2::new((f * 7.3) % 11.0, (f * 3.1) % 5.0)
            })
            .collect();
        let mut md = MinDistance::new(q.len());
        for round in 0..3 {
            let mut best = f64::INFINITY;
            for i in 0..q.len() {
                for j in i + 1..q.len() {
                    best = best.min((q[i] - q[j]).norm());
                }
            }
            assert_eq!(md.compute(&q).0, best, "round {round}");
            for p in &mut q {
                p.x += 0.3 * p.y.sin();
            }
        }
    }
}
