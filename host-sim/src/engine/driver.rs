//! The run driver shared by both simulators: picks the simulator of the model's mode, runs
//! its time loop (`time_loop.rs`) and gathers the run's result (the verdict, the bands,
//! the counters).

use super::continuous::ContinuousSim;
use super::error::RunError;
use super::record::Recorder;
use super::result::RunResult;
use super::sampled::SampledSim;
use super::simulator::Engine;
use super::time_loop::{signed_area, simulate};
use crate::model::{Mode, Model};
use std::time::Instant;

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

/// Why the setpoints run ahead of the vehicle, if the force limit lets an agent's
/// virtual mass (SPEC S20) accelerate faster than the vehicle's tilt limit lets it
/// (`controller.max_force / mass` above
/// [`crate::model::world::WorldModel::max_acceleration`]): the
/// ideal world's `max_force = 1000` N under `world = "crazyflie"` (docs/design.md): a
/// warning, and part of the outcome's reason.
pub fn force_limit_note(model: &Model) -> Option<String> {
    let a_max = model.world.max_acceleration()?;
    let f = model.limits.max_force;
    let (i, x) = model
        .agents
        .iter()
        .enumerate()
        .find(|(_, x)| f / x.mass > a_max)?;
    Some(format!(
        "controller.max_force = {f} N lets agent {}'s virtual mass ({} kg) accelerate at up \
         to {:.2} m/s², above the {a_max:.2} m/s² the vehicle gives itself (its tilt \
         limit): its setpoints run ahead of what it flies; `host-sim design --vehicle \
         crazyflie` chooses 2 N per kg (docs/design.md)",
        model.agents.get(i).map_or("?", |a| a.name.as_str()),
        x.mass,
        f / x.mass
    ))
}

/// What `[leader] orientation` does that the scenario may not expect (SPEC §7, "Heading
/// disagreement"): `held` in a world whose heading estimates disagree (the leaders pull
/// toward two targets), or a free orientation under a `displacement` that turns `z*`
/// (only `|z*|` is held). A warning, and part of the outcome's reason.
pub fn leader_orientation_note(model: &Model) -> Option<String> {
    use crate::model::LeaderOrientation;
    let l = model.leader.as_ref()?;
    if model.orientation_free(l.orientation) {
        let first = l.displacement.steps.first()?.value;
        let turn = l.displacement.steps.iter().find(|s| {
            let [x, y] = s.value;
            (first[0] * y - first[1] * x).abs() > 1e-9 * (x.hypot(y) * first[0].hypot(first[1]))
                || first[0] * x + first[1] * y < 0.0
        })?;
        let why = if l.orientation == LeaderOrientation::Auto {
            "auto: the world's heading estimates disagree"
        } else {
            "free"
        };
        Some(format!(
            "leader.displacement turns z* at {} s, but leader.orientation is {why}: the \
             leaders hold only |z*| (SPEC S11b) and the formation keeps the orientation it \
             formed in",
            turn.from
        ))
    } else if l.orientation == LeaderOrientation::Held && model.world.headings_disagree() {
        Some(
            "leader.orientation = \"held\" in a world whose heading estimates disagree \
             ([heading]): each leader turns z* by its own heading error, so the two pull \
             toward two targets and the formation drifts (SPEC §7, \"Heading \
             disagreement\"); \"free\" (the default there) holds only |z*|"
                .to_owned(),
        )
    } else {
        None
    }
}

/// Every note on what the scenario asks that the world will not give (the speed limit,
/// the force limit, the leader edge's orientation), in that order: `run`'s and
/// `validate`'s warnings, and part of a failed run's reason.
pub fn model_notes(model: &Model) -> Vec<String> {
    [
        speed_limit_note(model),
        force_limit_note(model),
        leader_orientation_note(model),
    ]
    .into_iter()
    .flatten()
    .collect()
}

/// Why some bearings are missing at the end, if a camera with a limited field of view
/// or range, or another agent's body in the way, leaves an agent without one of its
/// triangles' neighbours at positions `q` (each agent's heading its `[[agents]]
/// heading_deg` if given, else the preset's `heading.initial`, spread ignored): part of
/// the outcome's reason when the run does not converge.
pub fn view_note(model: &Model, q: &[[f64; 2]]) -> Option<String> {
    let cam = model.sensors.camera.as_ref()?;
    let nominal = model.world.heading.map_or(0.0, |h| h.initial);
    let (cos_half, limited) = ((0.5 * cam.fov).cos(), cam.fov < std::f64::consts::TAU);
    // The camera's own occlusion test (engine/sensors/occlusion.rs) on these positions.
    let at: Vec<ph_formation_core::Vec2<f64>> = q
        .iter()
        .map(|p| ph_formation_core::Vec2::new(p[0], p[1]))
        .collect();
    let bodies = (cam.occlusion_radius > 0.0).then(|| {
        let mut o = super::sensors::occlusion::Occluders::new(cam.occlusion_radius);
        o.rebuild(&at);
        o
    });
    for t in &model.triangles {
        for &i in &t.vertices {
            let heading = model
                .agents
                .get(i)
                .and_then(|a| a.heading)
                .unwrap_or(nominal);
            let d = [heading.cos(), heading.sin()];
            for &j in t.vertices.iter().filter(|&&j| j != i) {
                let (Some(a), Some(b)) = (q.get(i), q.get(j)) else {
                    continue;
                };
                let e = [b[0] - a[0], b[1] - a[1]];
                let r = e[0].hypot(e[1]);
                let outside = limited && d[0] * e[0] + d[1] * e[1] < r * cos_half;
                let name = |k: usize| model.agents.get(k).map_or("?", |x| x.name.as_str());
                let hidden = !outside
                    && r <= cam.range
                    && bodies.as_ref().is_some_and(|o| o.hides(&at, i, j, r));
                if hidden {
                    return Some(format!(
                        "agent {}'s neighbour {} is hidden from its camera by another \
                         agent's body (occlusion radius {} m: sensors.camera), so it has no \
                         bearing to it",
                        name(i),
                        name(j),
                        cam.occlusion_radius
                    ));
                }
                if outside || r > cam.range {
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
    if let Some(auto) = &model.comm_auto {
        warnings.push(super::load::auto_note(auto));
    }
    warnings.extend(model_notes(model));
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
    mut warnings: Vec<String>,
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
    let frames = engine.frame_counts();
    let loss = engine.loss_by_sender();
    let faults = engine.fault_reports();
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
        for note in model_notes(model) {
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
    let period = model.dt * model.steps_per_tick as f64;
    let collisions = channel
        .as_ref()
        .and_then(|c| c.collision_note(sim.diag.snap.t, frames.sent, period, model.comm_every));
    if let Some(note) = collisions {
        if verdict.outcome != crate::analysis::Outcome::Converged {
            reason = format!("{reason}; {note}");
        }
        warnings.push(note);
    }
    let names: Vec<&str> = model.agents.iter().map(|a| a.name.as_str()).collect();
    for f in &faults {
        reason = format!("{reason}; fault: {}", f.note(&names));
    }
    if let Some(note) = super::channel::lossy_note(&loss, &names) {
        if verdict.outcome != crate::analysis::Outcome::Converged {
            reason = format!("{reason}; {note}");
        }
        warnings.push(note);
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
        frames,
        control: engine.control_stats(),
        channel,
        attacks: engine.attack_counts(),
        policy,
        faults,
        warnings,
        steps: sim.steps,
        wall_seconds: started.elapsed().as_secs_f64(),
        hil: Vec::new(),
    })
}
