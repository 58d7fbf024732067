//! The run driver shared by both simulators: the time loop (control ticks, RK4 steps),
//! the diagnostics cadence (every control instant and every log instant), logging, and
//! early stopping on a terminal failure found by [`crate::analysis::Monitor`].

use super::attack::AttackCounts;
use super::channel::ChannelStats;
use super::continuous::ContinuousSim;
use super::error::RunError;
use super::hil::HilError;
use super::record::{Recorder, Row};
use super::result::RunResult;
use super::sampled::SampledSim;
use super::stats::{ControlStats, FrameCounts};

use crate::analysis::{Diagnostics, Monitor};
use crate::model::{geometry, EstimateInfo, Mode, Model};
use ph_formation_core::Vec2;
use std::time::Instant;

/// A simulation engine the driver advances: sampled or continuous.
pub trait Engine {
    /// Runs the controllers at a control instant `t` (sampled mode; no-op in continuous):
    /// every agent, or with own clocks those due at `t`.
    fn control(&mut self, t: f64);
    /// Whether some agent ticks at RK4 step `k` (by default every `steps_per_tick`).
    fn ticks_at(&self, model: &Model, k: usize) -> bool {
        k.is_multiple_of(model.steps_per_tick.max(1))
    }
    /// The first RK4 step after `k` at which some agent ticks.
    fn next_tick_after(&self, model: &Model, k: usize) -> usize {
        let spt = model.steps_per_tick.max(1);
        (k / spt + 1) * spt
    }
    /// Advances the state by one RK4 step from `t`.
    fn integrate(&mut self, t: f64);
    /// Advances the state by the RK4 steps `k..k + steps` of `model` (step `j` starts at
    /// `model.time(j)`) with nothing observed in between: the same as
    /// [`Self::integrate`] at each (an engine may take them in another order where that
    /// gives the same bits).
    fn integrate_steps(&mut self, model: &Model, k: usize, steps: usize) {
        for j in k..k + steps {
            self.integrate(model.time(j));
        }
    }
    /// Refreshes the estimate values and returns `(q, v, estimates)`.
    fn view(&mut self) -> (&[Vec2<f64>], &[Vec2<f64>], &[f64]);
    /// The estimates' layout.
    fn estimate_info(&self) -> &[EstimateInfo];
    /// Frame counters so far.
    fn frame_counts(&self) -> FrameCounts;
    /// Controller counters so far.
    fn control_stats(&self) -> ControlStats;
    /// Frames each attacker overheard and injected (`[[attacks]]` order; none by default).
    fn attack_counts(&self) -> Vec<AttackCounts> {
        Vec::new()
    }
    /// The shared channel's counters, if there is one.
    fn channel_stats(&self) -> Option<ChannelStats> {
        None
    }
    /// What the safety policies did, per agent (empty without `[policy]`).
    fn policy_counts(&self) -> Vec<ph_formation_core::policy::PolicyCounts> {
        Vec::new()
    }
    /// A controller failure that ends the run (a host-in-the-loop target that stopped
    /// answering or sent a corrupt frame), taken once; checked after every
    /// [`Self::control`].
    fn take_error(&mut self) -> Option<HilError> {
        None
    }
}

/// The first step after `k` that is a control tick (a multiple of `spt`), a log instant (a
/// multiple of `log_every`) or the last one (`total`).
fn next_instant(k: usize, spt: usize, log_every: usize, total: usize) -> usize {
    let after = |every: usize| (k / every + 1) * every;
    after(spt).min(after(log_every)).min(total)
}

/// Twice the signed area of triangle `t` in `q` ([`geometry::cross`]).
fn signed_area(q: &[Vec2<f64>], t: [usize; 3]) -> f64 {
    let p = |v: usize| [q[v].x, q[v].y];
    geometry::cross(p(t[0]), p(t[1]), p(t[2]))
}

/// Why the formation cannot track `v*`, if the vehicle's speed limit is below some step
/// of it (`docs/world.md`): a warning, and part of the outcome's reason.
pub fn speed_limit_note(model: &Model) -> Option<String> {
    let limit = model.world.max_speed()?;
    let step = model
        .velocity_reference
        .steps
        .iter()
        .find(|s| s.value[0].hypot(s.value[1]) > limit)?;
    let [x, y] = step.value;
    Some(format!(
        "velocity_reference from {} s: v* = ({x}, {y}) m/s, |v*| = {:.2} m/s is above the \
         vehicle's speed limit plant.max_speed = {limit} m/s: the formation cannot track v*",
        step.from,
        x.hypot(y)
    ))
}

/// Why some bearings are missing at the end, if a camera with a limited field of view
/// or range leaves an agent without one of its triangles' neighbours at positions `q`
/// (headings taken as the preset's `heading.initial`, spread ignored): part of the
/// outcome's reason when the run does not converge.
pub fn view_note(model: &Model, q: &[[f64; 2]]) -> Option<String> {
    let cam = model.sensors.camera.as_ref()?;
    let heading = model.world.heading.map_or(0.0, |h| h.initial);
    let d = [heading.cos(), heading.sin()];
    let (cos_half, limited) = ((0.5 * cam.fov).cos(), cam.fov < std::f64::consts::TAU);
    for t in &model.triangles {
        for &i in &t.vertices {
            for &j in t.vertices.iter().filter(|&&j| j != i) {
                let (Some(a), Some(b)) = (q.get(i), q.get(j)) else {
                    continue;
                };
                let e = [b[0] - a[0], b[1] - a[1]];
                let r = e[0].hypot(e[1]);
                let outside = limited && d[0] * e[0] + d[1] * e[1] < r * cos_half;
                if outside || r > cam.range {
                    let name = |k: usize| model.agents.get(k).map_or("?", |x| x.name.as_str());
                    return Some(format!(
                        "agent {}'s neighbour {} is {} its camera ({}: sensors.camera), \
                         so it has no bearing to it",
                        name(i),
                        name(j),
                        if outside {
                            "out of view of"
                        } else {
                            "out of range of"
                        },
                        if outside {
                            format!("field of view {:.0}°", cam.fov.to_degrees())
                        } else {
                            format!("range {} m at {r:.2} m", cam.range)
                        }
                    ));
                }
            }
        }
    }
    None
}

/// Runs `model` in its mode, logging rows to `recorder` and reporting the simulated time
/// to `progress`.
pub fn run(
    model: &Model,
    recorder: &mut dyn Recorder,
    progress: &mut dyn FnMut(f64),
) -> Result<RunResult, RunError> {
    let mut warnings = Vec::new();
    if let Some(w) = speed_limit_note(model) {
        warnings.push(w);
    }
    match model.mode {
        Mode::Sampled => {
            let mut e = SampledSim::new(model)?;
            drive(model, &mut e, recorder, progress, warnings)
        }
        Mode::Continuous => {
            if model.sensors.is_noisy() {
                warnings.push(
                    "continuous mode: sensor noise and bias are ignored (exact measurements)"
                        .to_owned(),
                );
            }
            if model.radio.is_faulty() {
                warnings
                    .push("continuous mode: the radio settings are ignored (no radio)".to_owned());
            }
            if model.comm_every != 1 {
                warnings.push(
                    "continuous mode: controller.comm_rate_hz is ignored (no radio)".to_owned(),
                );
            }
            let mut e = ContinuousSim::new(model)?;
            drive(model, &mut e, recorder, progress, warnings)
        }
    }
}

/// A simulated run before its verdict: the monitor that watched it and the last state.
pub(super) struct Simulated {
    /// The failure monitor, with every observed instant.
    pub(super) monitor: Monitor,
    /// The diagnostics of the last instant.
    pub(super) diag: Diagnostics,
    /// RK4 steps taken.
    pub(super) steps: usize,
    /// Each triangle's signed area at the start.
    area0: Vec<f64>,
}

/// The time loop: control ticks, RK4 steps, diagnostics at every control instant and
/// every log instant, logging, failure detection; then the verdict, with the bands of a
/// calibration run when the scenario's sensing or world is random
/// ([`super::calibrate`]). A controller failure ([`Engine::take_error`]) ends it with
/// [`RunError::Hil`].
pub fn drive(
    model: &Model,
    engine: &mut dyn Engine,
    recorder: &mut dyn Recorder,
    progress: &mut dyn FnMut(f64),
    warnings: Vec<String>,
) -> Result<RunResult, RunError> {
    let started = Instant::now();
    let sim = simulate(model, engine, recorder, progress)?;
    let (q, _, est) = engine.view();
    let bands = if model.sensing_noise().needs_calibration() && !sim.monitor.terminal {
        Some(super::calibrate::bands(model, q, est))
    } else {
        None
    };
    let steady_control = engine.control_stats().window;
    let channel = engine.channel_stats();
    let policy = engine.policy_counts();
    let (q, v, est) = engine.view();
    let verdict = sim
        .monitor
        .verdict(model, &sim.diag.snap, q, &steady_control, bands.as_ref());
    let mut reason = verdict.reason;
    if verdict.outcome == crate::analysis::Outcome::NotInControl {
        if let Some(c) = &channel {
            let u = c.total_utilisation(sim.diag.snap.t);
            if u > 1.0 {
                reason = format!(
                    "{reason}; the shared channel was overloaded: {:.0} % of its air time offered",
                    100.0 * u
                );
            }
        }
    }
    if verdict.outcome != crate::analysis::Outcome::Converged {
        if let Some(note) = speed_limit_note(model) {
            reason = format!("{reason}; {note}");
        }
        let at: Vec<[f64; 2]> = q.iter().map(|p| [p.x, p.y]).collect();
        if let Some(note) = view_note(model, &at) {
            reason = format!("{reason}; {note}");
        }
    }
    if let Some(note) = super::policy::landings_note(&policy, model) {
        reason = format!("{reason}; {note}");
    }
    let tri = model.triangles.iter().map(|t| t.vertices);
    let s = &sim.diag.snap;
    let monitor = &sim.monitor;
    Ok(RunResult {
        outcome: verdict.outcome,
        reason,
        events: monitor.events.clone(),
        final_time: s.t,
        settle_time: verdict.settle_time,
        steady: verdict.steady,
        pose: verdict.pose,
        safe_share: verdict.safe_share,
        final_max_angle_error: s.max_angle_err,
        final_displacement_error: s.disp_err,
        final_velocity_error: s.vel_err,
        min_estimate: monitor.min_estimate,
        min_distance: monitor.min_distance,
        v0: monitor.v0.unwrap_or(0.0),
        v_final: s.v,
        v_max_increase_rel: monitor.v_max_increase_rel(),
        v_max_increase_t: monitor.max_rise_t,
        final_positions: q.iter().map(|p| [p.x, p.y]).collect(),
        final_velocities: v.iter().map(|p| [p.x, p.y]).collect(),
        final_estimates: est
            .iter()
            .copied()
            .zip(s.est_true.iter().copied())
            .collect(),
        orientation_kept: tri
            .zip(&sim.area0)
            .map(|(t, &a0)| signed_area(q, t).signum() == a0.signum())
            .collect(),
        frames: engine.frame_counts(),
        control: engine.control_stats(),
        channel,
        attacks: engine.attack_counts(),
        policy,
        warnings,
        steps: sim.steps,
        wall_seconds: started.elapsed().as_secs_f64(),
        hil: Vec::new(),
    })
}

/// The time loop alone: the run up to its end or its terminal failure.
pub(super) fn simulate(
    model: &Model,
    engine: &mut dyn Engine,
    recorder: &mut dyn Recorder,
    progress: &mut dyn FnMut(f64),
) -> Result<Simulated, RunError> {
    let total = model.total_steps();
    let spt = model.steps_per_tick.max(1);
    let log_every = model.log_every.max(1);
    let progress_every = (total / 200).max(1);
    let mut diag = Diagnostics::new(model, engine.estimate_info().to_vec());
    let mut monitor = Monitor::new(model, diag.estimates.len());
    let area0: Vec<f64> = {
        let (q, _, _) = engine.view();
        model
            .triangles
            .iter()
            .map(|t| signed_area(q, t.vertices))
            .collect()
    };
    let rows = recorder.wants_rows();
    let mut steps = 0;
    let mut k = 0;
    loop {
        let t = model.time(k);
        // The diagnostics look at every control period (the common clock's ticks).
        let tick = k.is_multiple_of(spt);
        if engine.ticks_at(model, k) {
            engine.control(t);
            if let Some(e) = engine.take_error() {
                let _ = recorder.finish();
                return Err(RunError::Hil(e));
            }
        }
        let log = k.is_multiple_of(log_every) || k == total;
        if tick || log {
            // Only rows show the frame counters (summing them visits every agent).
            let frames = if rows {
                engine.frame_counts()
            } else {
                FrameCounts::default()
            };
            let (q, v, est) = engine.view();
            diag.evaluate(model, t, q, v, est);
            let stop = monitor.observe(model, &diag, q, est);
            if (log || stop) && rows {
                recorder.record(&Row {
                    snap: &diag.snap,
                    q,
                    v,
                    estimates: est,
                    frames,
                })?;
            }
            if stop {
                break;
            }
        }
        if k == total {
            break;
        }
        // The steps up to the next instant that looks at the state: a control tick, a log
        // instant or the end.
        let next = next_instant(k, spt, log_every, total).min(engine.next_tick_after(model, k));
        engine.integrate_steps(model, k, next - k);
        steps += next - k;
        // As at every step that is a multiple of `progress_every`.
        if k.next_multiple_of(progress_every) < next {
            progress(t);
        }
        k = next;
    }
    recorder.finish()?;
    progress(diag.snap.t);
    Ok(Simulated {
        monitor,
        diag,
        steps,
        area0,
    })
}

#[cfg(test)]
mod tests {
    use super::next_instant;

    /// The next instant is the nearest later tick, log instant or end, never `k` itself.
    #[test]
    fn next_instant_is_the_nearest_tick_log_or_end() {
        // Ticks every 10 steps, logs every 25, 100 steps.
        assert_eq!(next_instant(0, 10, 25, 100), 10);
        assert_eq!(next_instant(10, 10, 25, 100), 20);
        assert_eq!(next_instant(20, 10, 25, 100), 25);
        assert_eq!(next_instant(25, 10, 25, 100), 30);
        assert_eq!(next_instant(97, 10, 25, 100), 100);
        // The end before the next tick, and a log every step.
        assert_eq!(next_instant(95, 10, 25, 98), 98);
        assert_eq!(next_instant(3, 10, 1, 100), 4);
        // Walking from 0 visits every tick and every log instant.
        let (mut k, mut seen) = (0, vec![0]);
        while k < 100 {
            k = next_instant(k, 10, 25, 100);
            seen.push(k);
        }
        let expect: Vec<usize> = (0..=100).filter(|j| j % 10 == 0 || j % 25 == 0).collect();
        assert_eq!(seen, expect);
    }
}
