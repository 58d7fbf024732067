//! An agent's configuration for the firmware: the host's configuration rounded to `f32`
//! and checked against the firmware's capacity.

use super::error::HilError;
use super::link::TARGET_MT;
use super::options::TARGET_NB;
use crate::model::Model;
use controller_core::{
    Agent, AgentConfig, AngleConfig, LeaderConfig, Limits, Schedule, ScheduleStep, TriangleConfig,
};

fn schedule(s: &Schedule<f64>) -> Schedule<f32> {
    let mut out = Schedule::default();
    for st in &s.steps {
        // Same capacity on both sides: never full.
        let _ = out.steps.push(ScheduleStep {
            from: st.from as f32,
            value: st.value.map(|x| x as f32),
        });
    }
    out
}

/// Agent `i`'s configuration for the firmware: the host's `AgentConfig<f64, 8>` (built as
/// for every simulated agent) rounded to `f32`, checked against the firmware's capacity
/// (`Agent<f32, 4, 8>`).
pub fn target_config(model: &Model, i: usize) -> Result<AgentConfig<f32, TARGET_MT>, HilError> {
    let id = model.agents.get(i).map_or(0, |a| a.id);
    let refused = |reason: String| HilError::Refused { agent: id, reason };
    let c = model.agent_config(i).map_err(refused)?;
    let f = |x: f64| x as f32;
    let mut t = AgentConfig::<f32, TARGET_MT>::new(c.id);
    for tri in &c.triangles {
        let ang = |a: &AngleConfig<f64>| AngleConfig {
            apex: a.apex,
            cos_desired: f(a.cos_desired),
            stiffness: f(a.stiffness),
            damping: f(a.damping),
            estimator_gain: f(a.estimator_gain),
        };
        t.triangles
            .push(TriangleConfig {
                vertices: tri.vertices,
                angles: [ang(&tri.angles[0]), ang(&tri.angles[1])],
            })
            .map_err(|_| {
                refused(format!(
                    "agent {id} belongs to {} triangles; the firmware holds at most {TARGET_MT}",
                    c.triangles.len()
                ))
            })?;
    }
    t.estimator = c.estimator;
    t.integrity = c.integrity;
    t.comm_every = c.comm_every;
    t.comm_phase = c.comm_phase;
    t.initial_estimate = f(c.initial_estimate);
    t.min_estimate = f(c.min_estimate);
    t.friction = c.friction.map(f);
    t.velocity_damping = c.velocity_damping.map(f);
    t.velocity_reference = schedule(&c.velocity_reference);
    t.leader = c.leader.as_ref().map(|l| LeaderConfig {
        role: l.role,
        partner: l.partner,
        stiffness: f(l.stiffness),
        damping: l.damping.map(f),
        displacement: schedule(&l.displacement),
    });
    t.limits = Limits {
        max_force: f(c.limits.max_force),
        neighbour_timeout: f(c.limits.neighbour_timeout),
        safe_damping: f(c.limits.safe_damping),
        bearing_tolerance: f(c.limits.bearing_tolerance),
        margin_cos: f(c.limits.margin_cos),
    };
    Agent::<f32, TARGET_MT, TARGET_NB>::new(t.clone()).map_err(|e| {
        refused(format!(
            "{e} (the firmware's agent holds {TARGET_MT} triangles and {TARGET_NB} neighbours)"
        ))
    })?;
    Ok(t)
}
