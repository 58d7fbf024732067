//! `[[faults]]`: faults of a real flight (`docs/faults.md`).

use super::agents::lookup;
use super::checker::Checker;
use crate::model::{FaultKind, FaultModel, Mode, FAULT_KINDS};
use crate::scenario::error::ErrorKind::InvalidValue;
use crate::scenario::ScenarioFile;
use std::collections::HashMap;

/// Checks every fault; returns those that resolved.
pub(super) fn check(
    c: &mut Checker<'_>,
    s: &ScenarioFile,
    index: &HashMap<String, usize>,
) -> Vec<FaultModel> {
    if !s.faults.is_empty() && s.mode != Mode::Sampled {
        c.err(
            InvalidValue,
            "faults",
            "faults are simulated in sampled mode only (mode = \"sampled\")",
        );
        return Vec::new();
    }
    let mut out = Vec::new();
    for (k, f) in s.faults.iter().enumerate() {
        let field = |name: &str| format!("faults[{k}].{name}");
        let kind = match f.kind.as_str() {
            "agent_loss" => Some(FaultKind::AgentLoss),
            "reboot" => Some(FaultKind::Reboot),
            "radio_blackout" => Some(FaultKind::RadioBlackout),
            "clock_jump" => Some(FaultKind::ClockJump),
            "outlier_burst" => Some(FaultKind::OutlierBurst),
            "sensor_freeze" => Some(FaultKind::SensorFreeze),
            other => {
                c.err(
                    InvalidValue,
                    &field("kind"),
                    format!(
                        "unknown kind `{other}`; the kinds are {}",
                        FAULT_KINDS.join(", ")
                    ),
                );
                None
            }
        };
        if !(f.t.is_finite() && f.t >= 0.0) {
            c.err(
                InvalidValue,
                &field("t"),
                format!("must be a time ≥ 0 s, got {}", f.t),
            );
        }
        let agent = match &f.agent {
            Some(id) => lookup(c, index, &field("agent"), id),
            None if kind == Some(FaultKind::RadioBlackout) => None,
            None => {
                c.err(
                    InvalidValue,
                    &field("agent"),
                    "needs the id of the agent it strikes (only a radio_blackout may leave it out: every agent)",
                );
                continue;
            }
        };
        let jump = match (kind, f.jump_s) {
            (Some(FaultKind::ClockJump), Some(j)) if j.is_finite() && j != 0.0 => j,
            (Some(FaultKind::ClockJump), j) => {
                c.err(
                    InvalidValue,
                    &field("jump_s"),
                    format!(
                        "a clock_jump needs a finite jump ≠ 0 s, got {}",
                        j.map_or("none".to_owned(), |j| j.to_string())
                    ),
                );
                continue;
            }
            (_, Some(_)) => {
                c.err(
                    InvalidValue,
                    &field("jump_s"),
                    format!("only a clock_jump has it (this one is `{}`)", f.kind),
                );
                continue;
            }
            (_, None) => 0.0,
        };
        let end = match (kind, f.duration) {
            (Some(k @ (FaultKind::AgentLoss | FaultKind::ClockJump)), Some(_)) => {
                c.err(
                    InvalidValue,
                    &field("duration"),
                    if k == FaultKind::AgentLoss {
                        "an agent_loss lasts to the end of the run (use reboot for an agent that comes back)"
                    } else {
                        "a clock_jump is an instant (its size is jump_s)"
                    },
                );
                continue;
            }
            (Some(FaultKind::AgentLoss), None) => f64::INFINITY,
            // An instant: recovery counts from it on.
            (Some(FaultKind::ClockJump), None) => f.t,
            (Some(_), Some(d)) if d.is_finite() && d > 0.0 => f.t + d,
            (Some(k), d) => {
                c.err(
                    InvalidValue,
                    &field("duration"),
                    format!(
                        "a {} needs a finite duration > 0 s, got {}",
                        k.as_str(),
                        d.map_or("none".to_owned(), |d| d.to_string())
                    ),
                );
                continue;
            }
            (None, _) => continue,
        };
        if let Some(kind) = kind {
            if f.agent.is_some() && agent.is_none() {
                continue; // reported by lookup
            }
            out.push(FaultModel {
                kind,
                agent,
                t: f.t,
                end,
                jump,
            });
        }
    }
    out
}
