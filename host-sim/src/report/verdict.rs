//! `summary.json`'s `verdict` and `pose` keys (`docs/outputs.md`, "Outcome"): how the run
//! was judged (noise-free criteria at the last instant, or calibrated bands over the steady
//! window), the safe outputs in the steady window by cause, and the formation's pose
//! reported apart from its shape.

use crate::analysis::control::FAULT_KINDS;
use crate::engine::RunResult;
use crate::model::Model;
use serde_json::{json, Map, Value};

fn opt(x: Option<f64>) -> Value {
    match x {
        Some(v) if v.is_finite() => json!(v),
        _ => Value::Null,
    }
}

/// `{ "final": …, "p95": … }`, or `null`.
fn pair(x: Option<(f64, f64)>) -> Value {
    x.map_or(
        Value::Null,
        |(f, p)| json!({ "final": opt(Some(f)), "p95": opt(Some(p)) }),
    )
}

/// The key of a fault kind in `safe_by_cause`.
fn kind_key(k: usize) -> &'static str {
    const KEYS: [&str; FAULT_KINDS] = [
        "measurement_refused",
        "missing_bearing",
        "stale_neighbour",
        "missing_data",
        "missing_partner_offset",
        "missing_range",
        "non_finite",
        "internal",
    ];
    // Keys in `fault_kind`'s order (checked by the test below).
    KEYS.get(k).copied().unwrap_or("unknown")
}

/// Adds `verdict` and `pose` to a summary object.
pub fn add_json(obj: &mut Map<String, Value>, model: &Model, r: &RunResult) {
    let w = &r.control.window;
    let by_cause: Map<String, Value> = (0..FAULT_KINDS)
        .filter(|&k| w.safe.counts[k] > 0)
        .map(|k| (kind_key(k).to_owned(), json!(w.safe.counts[k])))
        .collect();
    let name = |i: usize| {
        model
            .agents
            .get(i)
            .map_or(Value::Null, |a| super::summary::user_id(&a.name))
    };
    let examples: Vec<Value> = w
        .safe
        .examples
        .iter()
        .flatten()
        .map(|&(i, f)| json!({ "agent": name(i), "fault": format!("{f:?}") }))
        .collect();
    let pose = &r.pose;
    let mut verdict = json!({
        "judged": if r.steady.is_some() { "calibrated_bands" } else { "noise_free" },
        "steady_window_s": [pose.window.from, pose.window.to],
        "sub_window_s": pose.window.sub,
        "safe_share": opt(r.safe_share),
        "safe_by_cause": by_cause,
        "safe_agents": examples,
    });
    if let (Some(s), Some(v)) = (&r.steady, verdict.as_object_mut()) {
        let b = &s.bands;
        v.insert(
            "bands".to_owned(),
            json!({
                "angle_rad": b.angle, "scale_m": b.scale, "velocity_m_s": b.velocity,
                "capped": { "angle": b.capped[0], "scale": b.capped[1], "velocity": b.capped[2] },
            }),
        );
        v.insert(
            "p95".to_owned(),
            json!({ "angle_rad": opt(s.p95[0]), "scale_m": opt(s.p95[1]), "velocity_m_s": opt(s.p95[2]) }),
        );
        v.insert(
            "settle_s".to_owned(),
            json!({ "angle": opt(s.settle[0]), "scale": opt(s.settle[1]), "velocity": opt(s.settle[2]) }),
        );
        v.insert(
            "calibration".to_owned(),
            b.calibration.map_or(Value::Null, |c| {
                json!({
                    "seed": c.seed, "duration_s": c.duration,
                    "steady_window_s": [c.window.from, c.window.to],
                    "angle_rad": opt(Some(c.angle)), "scale_m": opt(Some(c.scale)),
                    "velocity_m_s": opt(Some(c.velocity)),
                    "margin": crate::analysis::bands::MARGIN,
                })
            }),
        );
    }
    obj.insert("verdict".to_owned(), verdict);
    // The core's safety policies (`[policy]`, docs/scenarios.md): what each agent's did.
    if !r.policy.is_empty() {
        let agents: Vec<Value> = r
            .policy
            .iter()
            .enumerate()
            .map(|(i, p)| {
                json!({
                    "agent": name(i),
                    "hold_ticks": p.hold_ticks,
                    "landings": p.landings,
                    "last_landing": format!("{:?}", p.last_landing),
                    "guarded": p.guarded,
                })
            })
            .collect();
        obj.insert("policy".to_owned(), Value::Array(agents));
    }
    obj.insert(
        "pose".to_owned(),
        json!({
            "window_s": [pose.window.from, pose.window.to],
            "orientation_error_rad": pair(pose.orientation),
            "scale_error_rel": pair(pose.scale_rel),
            "translation_error_m": pair(pose.translation),
        }),
    );
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::analysis::control::{fault_kind, FAULT_SAMPLES};

    /// The keys follow `fault_kind`'s numbering.
    #[test]
    fn keys_follow_the_fault_kinds() {
        for (k, f) in FAULT_SAMPLES.iter().enumerate() {
            assert_eq!(fault_kind(f).0, k);
            assert_ne!(kind_key(k), "unknown");
        }
    }
}
