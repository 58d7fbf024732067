//! `summary.json`: everything a run found, for people and scripts (`docs/outputs.md`).

use crate::analysis::shape_check::shape_check;
use crate::engine::hil::LinkStats;
use crate::engine::RunResult;
use crate::model::{EstimateInfo, Model};
use serde_json::{json, Value};
use std::fs::File;
use std::io::{self, BufWriter, Write};
use std::path::Path;

fn opt(x: Option<f64>) -> Value {
    match x {
        Some(v) if v.is_finite() => json!(v),
        _ => Value::Null,
    }
}

fn fin(x: f64) -> Value {
    opt(Some(x))
}

/// A user's agent id in JSON: a number when it is one, else a string.
pub(super) fn user_id(name: &str) -> Value {
    name.parse::<u64>()
        .map_or_else(|_| Value::String(name.to_owned()), Value::from)
}

/// The final formation against the target shape (`null` without one).
fn shape_json(model: &Model, q: &[[f64; 2]]) -> Value {
    match shape_check(model, q) {
        None => Value::Null,
        Some(c) => json!({
            "target": if model.target.from_file { "file" } else { "angles" },
            "max_error_rel": fin(c.fit.max_rel),
            "rms_error_rel": fin(c.fit.rms_rel),
            "reflected": c.fit.reflected,
            "scale": fin(c.fit.scale),
            "target_positions": model.target.positions.iter().map(|p| [fin(p[0]), fin(p[1])]).collect::<Vec<_>>(),
            "folded_triangles": c.folded.iter().filter_map(|&k| model.triangles.get(k)).map(|t| {
                t.vertices.map(|v| model.agents.get(v).map_or(Value::Null, |a| user_id(&a.name)))
            }).collect::<Vec<_>>(),
        }),
    }
}

/// `summary.json` of a run.
pub fn summary_json(model: &Model, r: &RunResult, estimates: &[EstimateInfo]) -> Value {
    let id = |i: usize| {
        model
            .agents
            .get(i)
            .map_or(Value::Null, |a| user_id(&a.name))
    };
    let fault = r
        .control
        .last_fault
        .map(|(t, i, f)| json!({ "t": t, "agent": id(i), "fault": format!("{f:?}") }));
    let mut v = json!({
        "scenario": model.name,
        "source": model.source,
        "description": model.description,
        "outcome": r.outcome.as_str(),
        "outcome_reason": r.reason,
        "exit_code": r.outcome.exit_code(),
        "events": r.events.iter().map(|e| json!({
            "t": e.t, "kind": e.kind.as_str(), "message": e.message
        })).collect::<Vec<_>>(),
        "mode": model.mode.as_str(),
        "estimator": model.estimator.as_str(),
        "seed": model.seed,
        "duration_s": model.duration,
        "final_time_s": r.final_time,
        "dt_s": model.dt,
        "control_period_s": model.control_period(),
        "agents": model.agents.iter().map(|a| user_id(&a.name)).collect::<Vec<_>>(),
        "edges": model.graph.edges.iter().map(|e| [id(e[0]), id(e[1])]).collect::<Vec<_>>(),
        "leaders": model.leader.as_ref().map(|l| [id(l.a), id(l.b)]),
        "settle_time_s": opt(r.settle_time),
        "final_max_angle_error_rad": fin(r.final_max_angle_error),
        "final_displacement_error": fin(r.final_displacement_error),
        "final_velocity_error": fin(r.final_velocity_error),
        "min_estimate": opt(r.min_estimate),
        "min_distance": fin(r.min_distance.0),
        "min_distance_time_s": fin(r.min_distance.1),
        "min_distance_agents": [id(r.min_distance.2), id(r.min_distance.3)],
        "V0": fin(r.v0),
        "V_final": fin(r.v_final),
        "v_max_increase_rel": fin(r.v_max_increase_rel),
        "v_max_increase_time_s": fin(r.v_max_increase_t),
        "final_positions": r.final_positions.iter().map(|p| [fin(p[0]), fin(p[1])]).collect::<Vec<_>>(),
        "final_velocities": r.final_velocities.iter().map(|p| [fin(p[0]), fin(p[1])]).collect::<Vec<_>>(),
        "final_estimates": estimates.iter().zip(&r.final_estimates).map(|(e, (rh, rt))| json!({
            "owner": id(e.owner), "apex": id(e.apex), "far": id(e.far), "other": id(e.other),
            "rhat": fin(*rh), "r": fin(*rt)
        })).collect::<Vec<_>>(),
        "triangle_orientation_kept": r.orientation_kept,
        "shape": shape_json(model, &r.final_positions),
        "frames_sent": r.frames.sent,
        "frames_dropped": r.frames.dropped,
        "frames_rejected": r.frames.rejected,
        "frames": {
            "broadcasts": r.frames.broadcasts,
            "sent": r.frames.sent,
            "dropped": r.frames.dropped,
            "lost": r.frames.lost,
            "queue_dropped": r.frames.queue_dropped,
            "duplicated": r.frames.duplicated,
            "corrupted": r.frames.corrupted,
            "reordered": r.frames.reordered,
            "delivered": r.frames.delivered,
            "accepted": r.frames.accepted,
            "rejected": r.frames.rejected,
        },
        "control": {
            "ticks": r.control.ticks,
            "safe": r.control.safe,
            "safe_after_start": r.control.safe_after_start,
            "saturated": r.control.saturated,
            "degenerate": r.control.degenerate,
            "max_force": fin(r.control.max_force),
            "last_fault": fault,
        },
        "criteria": {
            "angle_tolerance_rad": model.criteria.angle_tolerance,
            "displacement_tolerance": model.criteria.displacement_tolerance,
            "velocity_tolerance": model.criteria.velocity_tolerance,
            "collision_distance": model.criteria.collision_distance,
            "collapse_time_s": model.criteria.collapse_time,
            "shape_tolerance": model.criteria.shape_tolerance,
        },
        "warnings": r.warnings,
        "steps": r.steps,
    });
    if let Some(obj) = v.as_object_mut() {
        // Only when they apply, so that a noise-free run's summary is what it always was
        // (but for `verdict` and `pose`).
        super::verdict::add_json(obj, model, r);
        if let ph_formation_core::BearingFilter::Tracker(t) = &model.sensors.bearing_filter {
            obj.insert(
                "bearing_filter".to_owned(),
                json!({
                    "kind": "tracker",
                    "bearing_noise_rad": fin(t.bearing_noise),
                    "rate_noise": fin(t.rate_noise),
                    "inverse_range_noise": fin(t.inverse_range_noise),
                    "gate": fin(t.gate),
                }),
            );
        }
        super::channel::add_json(obj, model, r);
        super::attack::add_json(obj, model, r);
        super::faults::add_json(obj, model, r);
        super::world::add_json(obj, model);
    }
    // Host-in-the-loop runs only (wall-clock figures would make summaries of the same
    // seed differ).
    if let (false, Some(obj)) = (r.hil.is_empty(), v.as_object_mut()) {
        obj.insert(
            "hil".to_owned(),
            Value::Array(r.hil.iter().map(hil_json).collect()),
        );
        obj.insert("wall_s".to_owned(), fin(r.wall_seconds));
        obj.insert(
            "wall_s_per_sim_s".to_owned(),
            if r.final_time > 0.0 {
                fin(r.wall_seconds / r.final_time)
            } else {
                Value::Null
            },
        );
    }
    v
}

fn hil_json(h: &LinkStats) -> Value {
    json!({
        "agent": user_id(&h.agent),
        "frames_to_target": h.frames_to_target,
        "frames_from_target": h.frames_from_target,
        "bytes_to_target": h.bytes_to_target,
        "bytes_from_target": h.bytes_from_target,
        "radio_frames_to_target": h.radio_to_target,
        "radio_frames_from_target": h.radio_from_target,
        "ticks": h.ticks,
        "wall_s": fin(h.wall_s),
        "startup_s": fin(h.startup_s),
        "estimates_from": h.estimates_source(),
        "target_frames_accepted": h.target_accepted,
        "target_frames_rejected": h.target_rejected,
        "exit_code": h.exit_code,
    })
}

/// Writes `summary.json`.
pub fn write_summary(path: &Path, summary: &Value) -> io::Result<()> {
    let mut out = BufWriter::new(File::create(path)?);
    serde_json::to_writer_pretty(&mut out, summary)?;
    writeln!(out)?;
    out.flush()
}
