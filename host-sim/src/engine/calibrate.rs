//! The calibration run behind the verdict's bands (`analysis::bands`,
//! `docs/outputs.md` "Outcome"): the same scenario under the same sensing, radio, world
//! and controllers, started **at its target shape** where the run ended (fitted to its
//! final positions, or placed on `z*` with a leader edge), moving at the final `v*`, with
//! constant references and another seed; what its errors reach over a steady window as
//! long as the run's is what the controller achieves under that sensing.

use super::continuous::ContinuousSim;
use super::record::NullRecorder;
use super::sampled::SampledSim;
use super::simulator::Engine;
use super::time_loop::simulate;
use crate::analysis::bands::{caps, Bands, Calibration};
use crate::analysis::steady::{Quantity, Window};
use crate::model::shape::fit_similarity;
use crate::model::{Mode, Model};
use ph_formation_core::{Schedule, Vec2};

/// Mixed into the run's seed: the calibration draws other noise than the run.
const SEED_MIX: u64 = 0x9E37_79B9_7F4A_7C15;

/// The bands of `model`, whose run ended at positions `q` with estimates `est`: from a
/// calibration run, or the caps of `[criteria]` when none can be made.
pub fn bands(model: &Model, q: &[Vec2<f64>], est: &[f64]) -> Bands {
    let norm = |v: [f64; 2]| v[0].hypot(v[1]);
    let end = model.duration;
    let caps = caps(
        &model.criteria,
        model.z_star(end).map_or(0.0, norm),
        norm(model.v_star(end)),
    );
    match calibration(model, q, est) {
        Some(c) => Bands::calibrated(&model.criteria, c, caps),
        None => Bands::capped(caps),
    }
}

/// The calibration's figures (`None` when its scenario cannot be built or run).
pub fn calibration(model: &Model, q: &[Vec2<f64>], est: &[f64]) -> Option<Calibration> {
    let m = calibration_model(model, q, est)?;
    let mut engine: Box<dyn Engine + '_> = match m.mode {
        Mode::Sampled => Box::new(SampledSim::new(&m).ok()?),
        Mode::Continuous => Box::new(ContinuousSim::new(&m).ok()?),
    };
    let sim = simulate(&m, engine.as_mut(), &mut NullRecorder, &mut |_| {}).ok()?;
    let w = Window::of(&m);
    let s = sim.monitor.series();
    let stat = |q| s.worst_sub_window(q, &w).unwrap_or(f64::NAN);
    Some(Calibration {
        seed: m.seed,
        duration: m.duration,
        window: w,
        angle: stat(Quantity::Angle),
        scale: stat(Quantity::Scale),
        velocity: stat(Quantity::Velocity),
    })
}

/// The calibration's warm-up before its steady window (s): the fresh trackers and
/// estimators settle first. `min(W, max(W/4, 10 s))`: with a warm-up of `W/4` only, a
/// 30 s formation-only run at 2° calibrated 4× its own steady error (0.81° against 0.18°,
/// the trackers' start still ringing); 10 s or more matched it within 20 %.
pub fn warm_up(w: f64) -> f64 {
    (0.25 * w).max(WARM_UP_S).min(w)
}

/// The shortest warm-up (s) of a calibration whose window allows it.
const WARM_UP_S: f64 = 10.0;

/// The calibration's scenario: `model` started at its target, a warm-up ([`warm_up`])
/// then a steady window of the run's length `W`.
pub fn calibration_model(model: &Model, q: &[Vec2<f64>], est: &[f64]) -> Option<Model> {
    let w = Window::of(model).length();
    let period = model.control_period();
    let mut m = model.clone();
    m.duration = (((w + warm_up(w)) / period).ceil() * period).max(period);
    m.criteria.steady_window = w.min(m.duration);
    m.seed = model.seed ^ SEED_MIX;
    let end = model.duration;
    let v_star = model.v_star(end);
    m.velocity_reference = Schedule::constant(v_star);
    if let Some(l) = m.leader.as_mut() {
        l.displacement = Schedule::constant(model.z_star(end)?);
    }
    let placed = placed_target(model, q)?;
    for (a, p) in m.agents.iter_mut().zip(placed) {
        a.position = p;
        a.velocity = v_star;
    }
    // The estimates start where the run's ended (their median: one value for all).
    let mut e: Vec<f64> = est.iter().copied().filter(|x| x.is_finite()).collect();
    if let Some(med) = crate::analysis::steady::quantile(&mut e, 0.5) {
        if med > model.min_estimate {
            m.initial_estimate = med;
        }
    }
    // Attacks are not sensing.
    m.attacks.clear();
    Some(m)
}

/// The target shape placed where the run ended: with a leader edge, turned and scaled so
/// that the edge is `z*(T)`, centred on the final centroid; else the best similarity fit
/// onto the final positions.
fn placed_target(model: &Model, q: &[Vec2<f64>]) -> Option<Vec<[f64; 2]>> {
    let target = &model.target.positions;
    if target.len() != q.len() || q.is_empty() {
        return None;
    }
    let n = q.len() as f64;
    let centroid = |p: &mut dyn Iterator<Item = [f64; 2]>| {
        let s = p.fold([0.0, 0.0], |a, x| [a[0] + x[0], a[1] + x[1]]);
        [s[0] / n, s[1] / n]
    };
    let cq = centroid(&mut q.iter().map(|p| [p.x, p.y]));
    let ct = centroid(&mut target.iter().copied());
    let placed: Vec<[f64; 2]> = match (&model.leader, model.z_star(model.duration)) {
        (Some(l), Some(z)) => {
            let e = [
                target[l.a][0] - target[l.b][0],
                target[l.a][1] - target[l.b][1],
            ];
            let e2 = e[0] * e[0] + e[1] * e[1];
            if e2.is_nan() || e2 <= 0.0 {
                return None;
            }
            // a = z / e as complex numbers: the turn and scale taking e onto z.
            let a = [
                (z[0] * e[0] + z[1] * e[1]) / e2,
                (z[1] * e[0] - z[0] * e[1]) / e2,
            ];
            target
                .iter()
                .map(|p| {
                    let d = [p[0] - ct[0], p[1] - ct[1]];
                    [
                        cq[0] + a[0] * d[0] - a[1] * d[1],
                        cq[1] + a[1] * d[0] + a[0] * d[1],
                    ]
                })
                .collect()
        }
        _ => {
            let qs: Vec<[f64; 2]> = q.iter().map(|p| [p.x, p.y]).collect();
            let fit = fit_similarity(target, &qs).ok()?;
            target.iter().map(|&p| fit.apply(p)).collect()
        }
    };
    placed
        .iter()
        .all(|p| p[0].is_finite() && p[1].is_finite())
        .then_some(placed)
}
