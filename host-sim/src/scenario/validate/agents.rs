//! `[agent_defaults]` and `[[agents]]`: ids, initial states, masses, damping.

use super::checker::Checker;
use crate::model::AgentModel;
use crate::scenario::error::ErrorKind::{self, InvalidValue, NonPositiveGain};
use crate::scenario::ScenarioFile;
use std::collections::HashMap;

/// Checks the agents; returns them and the index of each id.
pub(super) fn check(
    c: &mut Checker<'_>,
    s: &ScenarioFile,
) -> (Vec<AgentModel>, HashMap<i64, usize>) {
    // ---- agents
    let d = &s.agent_defaults;
    c.positive(InvalidValue, "agent_defaults.mass", d.mass);
    let mut index: HashMap<i64, usize> = HashMap::new();
    let mut agents = Vec::with_capacity(s.agents.len());
    for (i, a) in s.agents.iter().enumerate() {
        let f = |x: &str| format!("agents[{i}].{x}");
        if !(0..=255).contains(&a.id) {
            c.err(
                InvalidValue,
                &f("id"),
                format!(
                    "id {} is out of range: ids are 0–255 (one byte on the wire)",
                    a.id
                ),
            );
        } else if let Some(&j) = index.get(&a.id) {
            c.err(
                ErrorKind::DuplicateId,
                &f("id"),
                format!("id {} is already used by agents[{j}]", a.id),
            );
        } else {
            index.insert(a.id, i);
        }
        c.finite2(&f("position"), a.position);
        let velocity = a.velocity.unwrap_or([0.0; 2]);
        c.finite2(&f("velocity"), velocity);
        let mass = a.mass.unwrap_or(d.mass);
        c.positive(InvalidValue, &f("mass"), mass);
        let friction = a.friction.unwrap_or(d.friction).pair();
        let velocity_damping = a.velocity_damping.unwrap_or(d.velocity_damping).pair();
        for k in 0..2 {
            c.non_negative(InvalidValue, &f("friction"), friction[k]);
            c.non_negative(NonPositiveGain, &f("velocity_damping"), velocity_damping[k]);
        }
        agents.push(AgentModel {
            id: u8::try_from(a.id).unwrap_or(0),
            position: a.position,
            velocity,
            mass,
            friction,
            velocity_damping,
        });
    }
    if s.agents.len() < 3 {
        c.err(
            ErrorKind::NotLaman,
            "agents",
            format!(
                "a formation needs at least 3 agents, got {}",
                s.agents.len()
            ),
        );
    }
    (agents, index)
}

/// The index of agent `id`, or an [`ErrorKind::UnknownId`] error on `field`.
pub(super) fn lookup(
    c: &mut Checker<'_>,
    index: &HashMap<i64, usize>,
    field: &str,
    id: i64,
) -> Option<usize> {
    let found = index.get(&id).copied();
    if found.is_none() {
        c.err(ErrorKind::UnknownId, field, format!("no agent has id {id}"));
    }
    found
}

/// The id of agent index `i` (-1 if there is none), for messages.
pub(super) fn agent_id(agents: &[AgentModel], i: usize) -> i64 {
    agents.get(i).map_or(-1, |a| i64::from(a.id))
}
