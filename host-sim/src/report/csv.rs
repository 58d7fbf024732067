//! Outputs of a run (documented in `docs/outputs.md`): `timeseries.csv` (one row per
//! log instant, written without allocating after the first row) and `summary.json`.

use crate::analysis::diagnostics::{EstimateInfo, Snapshot};
use crate::engine::hil::LinkStats;
use crate::engine::sampled::{FrameCounts, RunResult};
use crate::model::Model;
use crate::scenario::error::exit_code;
use controller_core::Vec2;
use serde_json::{json, Value};
use std::fmt::Write as _;
use std::fs::File;
use std::io::{self, BufWriter, Write};
use std::path::Path;

/// One logged instant.
#[derive(Clone, Copy, Debug)]
pub struct Row<'a> {
    /// Diagnostics of the instant.
    pub snap: &'a Snapshot,
    /// Positions.
    pub q: &'a [Vec2<f64>],
    /// Velocities.
    pub v: &'a [Vec2<f64>],
    /// Estimates (layout order).
    pub estimates: &'a [f64],
    /// Cumulative frame counters.
    pub frames: FrameCounts,
}

/// Where logged rows go.
pub trait Recorder {
    /// Records one row.
    fn record(&mut self, row: &Row<'_>) -> io::Result<()>;
    /// Flushes at the end of the run.
    fn finish(&mut self) -> io::Result<()> {
        Ok(())
    }
}

/// Discards every row (benchmarks, tests that only need the summary).
#[derive(Clone, Copy, Debug, Default)]
pub struct NullRecorder;

impl Recorder for NullRecorder {
    fn record(&mut self, _row: &Row<'_>) -> io::Result<()> {
        Ok(())
    }
}

/// The columns of `timeseries.csv` before the per-agent, per-angle and per-estimate ones
/// (docs/outputs.md).
pub const BASE_COLUMNS: [&str; 13] = [
    "t",
    "V",
    "V_kin",
    "V_ang",
    "V_lead",
    "V_est",
    "max_angle_err",
    "disp_err",
    "vel_err",
    "min_dist",
    "frames_sent",
    "frames_dropped",
    "frames_rejected",
];

/// The column names of `timeseries.csv` for `model` with these estimates.
pub fn csv_header(model: &Model, estimates: &[EstimateInfo]) -> Vec<String> {
    let id = |i: usize| model.agents[i].id;
    let mut h: Vec<String> = BASE_COLUMNS.iter().map(|s| (*s).to_owned()).collect();
    for a in &model.agents {
        for c in ["x", "y", "vx", "vy"] {
            h.push(format!("{c}_{}", a.id));
        }
    }
    for t in &model.triangles {
        for a in &t.angles {
            let (v, w) = (id(a.far[0]), id(a.far[1]));
            h.push(format!(
                "angle_err_{}_{}_{}",
                id(a.apex),
                v.min(w),
                v.max(w)
            ));
        }
    }
    for e in estimates {
        let tag = format!(
            "{}_{}_{}_{}",
            id(e.owner),
            id(e.apex),
            id(e.far),
            id(e.other)
        );
        h.push(format!("rhat_{tag}"));
        h.push(format!("r_{tag}"));
    }
    h
}

/// Writes `timeseries.csv`.
pub struct CsvRecorder {
    out: BufWriter<File>,
    line: String,
}

impl CsvRecorder {
    /// Creates the file and writes the header row.
    pub fn create(path: &Path, model: &Model, estimates: &[EstimateInfo]) -> io::Result<Self> {
        let mut out = BufWriter::new(File::create(path)?);
        writeln!(out, "{}", csv_header(model, estimates).join(","))?;
        Ok(Self {
            out,
            line: String::with_capacity(4096),
        })
    }
}

/// Shortest round-trip text of `x` (`{:?}`: exponents for very small or large values).
fn num(line: &mut String, x: f64) {
    let _ = write!(line, "{x:?},");
}

impl Recorder for CsvRecorder {
    fn record(&mut self, r: &Row<'_>) -> io::Result<()> {
        let s = r.snap;
        let l = &mut self.line;
        l.clear();
        for x in [
            s.t,
            s.v,
            s.v_kin,
            s.v_ang,
            s.v_lead,
            s.v_est,
            s.max_angle_err,
            s.disp_err,
            s.vel_err,
            s.min_dist,
        ] {
            num(l, x);
        }
        let _ = write!(
            l,
            "{},{},{},",
            r.frames.sent, r.frames.dropped, r.frames.rejected
        );
        for (q, v) in r.q.iter().zip(r.v) {
            for x in [q.x, q.y, v.x, v.y] {
                num(l, x);
            }
        }
        for &e in &s.angle_err {
            num(l, e);
        }
        for (&rh, &rt) in r.estimates.iter().zip(&s.est_true) {
            num(l, rh);
            num(l, rt);
        }
        l.pop();
        l.push('\n');
        self.out.write_all(l.as_bytes())
    }

    fn finish(&mut self) -> io::Result<()> {
        self.out.flush()
    }
}

fn opt(x: Option<f64>) -> Value {
    match x {
        Some(v) if v.is_finite() => json!(v),
        _ => Value::Null,
    }
}

fn fin(x: f64) -> Value {
    opt(Some(x))
}

/// The exit code of a finished run.
pub fn run_exit_code(r: &RunResult) -> u8 {
    r.outcome.exit_code()
}

/// `summary.json` of a run.
pub fn summary_json(model: &Model, r: &RunResult, estimates: &[EstimateInfo]) -> Value {
    let id = |i: usize| model.agents.get(i).map_or(0, |a| a.id);
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
        "exit_code": run_exit_code(r),
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
        "agents": model.agents.iter().map(|a| a.id).collect::<Vec<_>>(),
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
        },
        "warnings": r.warnings,
        "steps": r.steps,
    });
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
        "agent": h.agent,
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

/// The exit code for an output failure.
pub const OUTPUT_ERROR: u8 = exit_code::IO;
