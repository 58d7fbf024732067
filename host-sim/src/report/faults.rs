//! `summary.json`'s `faults` (`[[faults]]`, docs/faults.md): each fault and what the
//! swarm did about it.

use crate::engine::RunResult;
use crate::model::Model;
use serde_json::{json, Map, Value};

/// `summary.json`'s object, for scenarios with faults: one entry per fault, with the
/// agents that went to their safe output after it and those that came back to their
/// control law after it ended (scenario ids and times, s).
pub(super) fn add_json(obj: &mut Map<String, Value>, m: &Model, r: &RunResult) {
    if r.faults.is_empty() {
        return;
    }
    let id = |i: usize| {
        m.agents
            .get(i)
            .map_or(Value::Null, |a| super::summary::user_id(&a.name))
    };
    let who = |v: &[(usize, f64)]| {
        Value::Array(
            v.iter()
                .map(|&(a, t)| json!({ "agent": id(a), "t_s": t }))
                .collect(),
        )
    };
    let list = r
        .faults
        .iter()
        .map(|f| {
            json!({
                "kind": f.fault.kind.as_str(),
                "agent": f.fault.agent.map_or(Value::Null, id),
                "t_s": f.fault.t,
                "end_s": if f.fault.end.is_finite() { json!(f.fault.end) } else { Value::Null },
                "jump_s": f.fault.jump,
                "went_safe": who(&f.went_safe),
                "recovered": who(&f.recovered),
            })
        })
        .collect();
    obj.insert("faults".to_owned(), Value::Array(list));
}
