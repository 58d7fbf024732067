//! Diagnostics of one instant (V and its terms S13, angle errors, estimates against true
//! distances, maneuver errors, minimum distance), evaluated from the TRUE state, not
//! from what the agents measured.

use super::min_distance::MinDistance;
use crate::model::geometry::interior_angle;
use crate::model::{EstimateInfo, Model, TriangleModel};
use ph_formation_core::{energy, Vec2};
use rayon::prelude::*;

/// From this many triangles on, the per-agent, per-angle and per-estimate terms are
/// computed on every thread of the current rayon pool; the sums are then taken in model
/// order (maxima do not depend on it), so the result is the same bits on any number of
/// threads.
pub const PARALLEL_MIN_TRIANGLES: usize = 2048;
/// Triangles (agents, estimates) per parallel work item.
const CHUNK: usize = 512;

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
    /// Scratch: `½ c ỹ²` of every angle, model order.
    angle_energy: Vec<f64>,
    /// `cos α*` of every angle, model order (computed once, not at every instant).
    cos_desired: Vec<f64>,
    /// Every agent's mass, and every estimate's edge `(apex, far, c_e)` in layout order:
    /// what an instant reads of the model's agents and estimates, packed (at 100,000
    /// agents each instant walks them all).
    masses: Vec<f64>,
    edges: Vec<(usize, usize, f64)>,
    /// Scratch: every agent's kinetic term, agent order.
    kinetic: Vec<f64>,
    /// Scratch: every estimate's term `½ c_e (r̂ − r)²`, layout order.
    est_energy: Vec<f64>,
    /// See [`Diagnostics::parallel`].
    parallel: bool,
}

/// The speed extremes of some agents, and whether their state is finite.
#[derive(Clone, Copy, Debug)]
struct AgentExtremes {
    /// `max |v − v*|`.
    vel_err: f64,
    /// `max |v|`.
    max_speed: f64,
    finite: bool,
}

impl Default for AgentExtremes {
    /// Of no agent.
    fn default() -> Self {
        Self {
            vel_err: 0.0,
            max_speed: 0.0,
            finite: true,
        }
    }
}

impl AgentExtremes {
    /// Of both sets (`f64::max` ignores NaN either way, so the order does not matter).
    fn merge(self, other: Self) -> Self {
        Self {
            vel_err: self.vel_err.max(other.vel_err),
            max_speed: self.max_speed.max(other.max_speed),
            finite: self.finite && other.finite,
        }
    }
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
            masses: model.agents.iter().map(|a| a.mass).collect(),
            edges: estimates.iter().map(|e| (e.apex, e.far, e.gain)).collect(),
            kinetic: vec![0.0; model.n()],
            est_energy: vec![0.0; estimates.len()],
            parallel: false,
            estimates,
            snap,
            min_distance: MinDistance::new(model.n()),
            angle_energy: vec![0.0; 2 * model.triangles.len()],
            cos_desired: model
                .triangles
                .iter()
                .flat_map(|t| t.angles.iter().map(|a| a.desired.cos()))
                .collect(),
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
        let parallel =
            model.triangles.len() >= PARALLEL_MIN_TRIANGLES && rayon::current_num_threads() > 1;
        // Each set of independent terms goes into its scratch (on every thread for large
        // formations); each sum is then taken in model order on one thread while the
        // others compute the next set.
        let (extremes, agents) =
            agent_terms(&mut self.kinetic, &self.masses, q, v, v_star, parallel);
        s.vel_err = extremes.vel_err;
        s.max_speed = extremes.max_speed;
        s.finite = extremes.finite;
        let angles = AngleTerms {
            triangles: &model.triangles,
            cos_desired: &self.cos_desired,
        };
        let (v_kin, ()) = both(
            parallel,
            || in_order(&self.kinetic[..agents]),
            || angles.evaluate(q, &mut s.angle_err, &mut self.angle_energy, parallel),
        );
        s.v_kin = v_kin;
        let ((v_ang, max_angle_err), estimates) = both(
            parallel,
            || angle_sums(&s.angle_err, &self.angle_energy),
            || {
                estimate_terms(
                    &mut self.est_energy,
                    &self.edges,
                    q,
                    est,
                    &mut s.est_true,
                    parallel,
                )
            },
        );
        (s.v_ang, s.max_angle_err) = (v_ang, max_angle_err);
        let (v_est, (d, i, j)) = both(
            parallel,
            || in_order(&self.est_energy[..estimates]),
            || self.min_distance.compute(q, parallel),
        );
        s.v_est = v_est;
        (s.min_dist, s.min_pair) = (d, (i, j));
        s.v_lead = 0.0;
        s.disp_err = 0.0;
        if let (Some(l), Some(zs)) = (&model.leader, model.z_star(t)) {
            let zt = q[l.a] - q[l.b] - Vec2::new(zs[0], zs[1]);
            s.v_lead = energy::leader(l.stiffness, &zt);
            s.disp_err = zt.norm();
        }
        s.v = s.v_kin + s.v_ang + s.v_lead + s.v_est;
        self.parallel = parallel;
    }

    /// The last [`Self::evaluate`] ran on every thread of the current rayon pool (a large
    /// formation, more than one thread): whoever reads the same instant may too.
    pub fn parallel(&self) -> bool {
        self.parallel
    }
}

/// `a` and `b`: at the same time on the current rayon pool when `parallel`, else one
/// after the other.
fn both<A: Send, B: Send>(
    parallel: bool,
    a: impl FnOnce() -> A + Send,
    b: impl FnOnce() -> B + Send,
) -> (A, B) {
    if parallel {
        rayon::join(a, b)
    } else {
        (a(), b())
    }
}

/// The sum of `terms` in their order, from `+0`.
fn in_order(terms: &[f64]) -> f64 {
    let mut sum = 0.0;
    for x in terms {
        sum += x;
    }
    sum
}

/// Every agent's kinetic term `½ m |v − v*|²` (S13) into `scratch` (agent order), the
/// extremes of the speed error and speed, and how many terms were written (the agents that
/// have a mass, a position and a velocity: only those are summed). `parallel`: on every
/// thread of the current rayon pool.
fn agent_terms(
    scratch: &mut [f64],
    masses: &[f64],
    q: &[Vec2<f64>],
    v: &[Vec2<f64>],
    v_star: Vec2<f64>,
    parallel: bool,
) -> (AgentExtremes, usize) {
    let terms = |slot: &mut f64, mass: f64, qi: &Vec2<f64>, vi: &Vec2<f64>| {
        let finite = qi.x.is_finite() && qi.y.is_finite() && vi.x.is_finite() && vi.y.is_finite();
        *slot = energy::kinetic(mass, vi, &v_star);
        AgentExtremes {
            vel_err: (vi - v_star).norm(),
            max_speed: vi.norm(),
            finite,
        }
    };
    let written = scratch.len().min(masses.len()).min(q.len()).min(v.len());
    if !parallel {
        let mut extremes = AgentExtremes::default();
        for (((slot, &mass), qi), vi) in scratch.iter_mut().zip(masses).zip(q).zip(v) {
            extremes = extremes.merge(terms(slot, mass, qi, vi));
        }
        return (extremes, written);
    }
    let extremes = scratch
        .par_iter_mut()
        .zip(masses)
        .zip(q.par_iter().zip(v))
        .with_min_len(CHUNK)
        .map(|((slot, &mass), (qi, vi))| terms(slot, mass, qi, vi))
        .reduce(AgentExtremes::default, AgentExtremes::merge);
    (extremes, written)
}

/// What an instant's angle terms read of the model.
struct AngleTerms<'a> {
    triangles: &'a [TriangleModel],
    /// `cos α*` of every angle, model order.
    cos_desired: &'a [f64],
}

impl AngleTerms<'_> {
    /// Each angle's error `α − α*` (the model's one [`interior_angle`]) into `errs` and
    /// energy `½ c ỹ²` (S13) into `energies`, model order. `parallel`: on every thread of
    /// the current rayon pool (the angles are independent).
    fn evaluate(&self, q: &[Vec2<f64>], errs: &mut [f64], energies: &mut [f64], parallel: bool) {
        type Out<'a> = (&'a mut [f64], (&'a mut [f64], &'a [f64]));
        let angles = |(tri, (err, (en, cos_desired))): (&TriangleModel, Out<'_>)| {
            let each = tri.angles.iter().zip(err).zip(en).zip(cos_desired);
            for (((a, err), en), cos_desired) in each {
                let su = unit(q[a.far[0]] - q[a.apex]);
                let sw = unit(q[a.far[1]] - q[a.apex]);
                let y = su.dot(&sw);
                *en = energy::angle(a.stiffness, y - cos_desired);
                let p = |v: usize| [q[v].x, q[v].y];
                *err = interior_angle(p(a.apex), p(a.far[0]), p(a.far[1])) - a.desired;
            }
        };
        if parallel {
            let per_angle = energies
                .par_chunks_mut(2)
                .zip(self.cos_desired.par_chunks(2));
            self.triangles
                .par_iter()
                .zip(errs.par_chunks_mut(2).zip(per_angle))
                .with_min_len(CHUNK)
                .for_each(angles);
        } else {
            let per_angle = energies.chunks_mut(2).zip(self.cos_desired.chunks(2));
            self.triangles
                .iter()
                .zip(errs.chunks_mut(2).zip(per_angle))
                .for_each(angles);
        }
    }
}

/// `V_ang`, the angle energies summed in model order, and `max |α − α*|` (NaN when an
/// error is NaN: "not settled").
fn angle_sums(errs: &[f64], energies: &[f64]) -> (f64, f64) {
    let (mut v_ang, mut max_err) = (0.0, 0.0_f64);
    for (err, en) in errs.iter().zip(energies) {
        v_ang += en;
        max_err = if err.is_nan() {
            f64::NAN
        } else {
            max_err.max(err.abs())
        };
    }
    (v_ang, max_err)
}

/// Every estimate's true distance (into `est_true`) and term `½ c_e (r̂ − r)²` (S13, into
/// `scratch`), layout order, and how many terms were written (the estimates that have a
/// value: only those are summed). `parallel`: as [`agent_terms`].
fn estimate_terms(
    scratch: &mut [f64],
    edges: &[(usize, usize, f64)],
    q: &[Vec2<f64>],
    est: &[f64],
    est_true: &mut [f64],
    parallel: bool,
) -> usize {
    let term = |&(apex, far, gain): &(usize, usize, f64), r_hat: f64, r_true: &mut f64| {
        *r_true = (q[apex] - q[far]).norm();
        energy::estimate(gain, r_hat, *r_true)
    };
    let written = edges
        .len()
        .min(est.len())
        .min(est_true.len())
        .min(scratch.len());
    if !parallel {
        let each = edges.iter().zip(est).zip(est_true.iter_mut().zip(scratch));
        for ((edge, &r_hat), (r_true, slot)) in each {
            *slot = term(edge, r_hat, r_true);
        }
        return written;
    }
    edges
        .par_iter()
        .zip(est)
        .zip(est_true.par_iter_mut().zip(scratch.par_iter_mut()))
        .with_min_len(CHUNK)
        .for_each(|((edge, &r_hat), (r_true, slot))| *slot = term(edge, r_hat, r_true));
    written
}
