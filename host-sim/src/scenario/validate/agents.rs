//! `[agent_defaults]` and `[[agents]]`: ids, initial states, masses, damping.

use super::checker::Checker;
use crate::model::AgentModel;
use crate::scenario::error::ErrorKind::{self, InvalidValue, NonPositiveGain};
use crate::scenario::{AgentId, ScenarioFile};
use std::collections::HashMap;

/// Longest name id.
const MAX_NAME: usize = 32;

/// Why `id` is not a valid agent id, if it is not.
fn bad_id(id: &AgentId) -> Option<String> {
    match id {
        AgentId::Number(i) if *i < 0 => Some(format!(
            "id {i} is negative: ids are non-negative integers or short names"
        )),
        AgentId::Name(s)
            if s.is_empty()
                || s.len() > MAX_NAME
                || !s
                    .chars()
                    .all(|ch| ch.is_ascii_alphanumeric() || ch == '-' || ch == '.') =>
        {
            Some(format!(
                "id {s:?} is not a short name: use 1–{MAX_NAME} ASCII letters, digits, `-` or `.`"
            ))
        }
        _ => None,
    }
}

/// Checks the agents; returns them and the index of each id.
pub(super) fn check(
    c: &mut Checker<'_>,
    s: &ScenarioFile,
) -> (Vec<AgentModel>, HashMap<String, usize>) {
    // ---- agents
    let d = &s.agent_defaults;
    c.positive(InvalidValue, "agent_defaults.mass", d.mass);
    let mut index: HashMap<String, usize> = HashMap::with_capacity(s.agents.len());
    let mut agents = Vec::with_capacity(s.agents.len());
    for (i, a) in s.agents.iter().enumerate() {
        let f = |x: &str| format!("agents[{i}].{x}");
        let key = a.id.to_string();
        if let Some(reason) = bad_id(&a.id) {
            c.err(InvalidValue, &f("id"), reason);
        } else if let Some(&j) = index.get(&key) {
            c.err(
                ErrorKind::DuplicateId,
                &f("id"),
                format!("id {} is already used by agents[{j}]", a.id),
            );
        } else {
            index.insert(key.clone(), i);
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
        if let Some(h) = a.heading_deg {
            if !(h.is_finite() && h.abs() <= 360.0) {
                c.err(
                    InvalidValue,
                    &f("heading_deg"),
                    format!("must be a finite angle in [-360, 360] degrees, got {h}"),
                );
            }
        }
        agents.push(AgentModel {
            id: match a.id {
                AgentId::Number(k) => u8::try_from(k).unwrap_or(0),
                AgentId::Name(_) => 0,
            },
            name: key,
            position: a.position,
            velocity,
            mass,
            friction,
            velocity_damping,
            heading: a.heading_deg.map(f64::to_radians),
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
    index: &HashMap<String, usize>,
    field: &str,
    id: &AgentId,
) -> Option<usize> {
    let found = index.get(&id.to_string()).copied();
    if found.is_none() {
        c.err(ErrorKind::UnknownId, field, format!("no agent has id {id}"));
    }
    found
}

/// Ids as a list for messages: `[1, 2, 3]`.
pub(super) fn list<T: std::fmt::Display>(ids: &[T]) -> String {
    let parts: Vec<String> = ids.iter().map(ToString::to_string).collect();
    format!("[{}]", parts.join(", "))
}

/// The user's id of agent index `i` (`?` if there is none), for messages.
pub(super) fn agent_id(agents: &[AgentModel], i: usize) -> String {
    agents
        .get(i)
        .map_or_else(|| "?".to_owned(), |a| a.name.clone())
}

/// Assigns the one-byte wire ids: the user's ids when every one is an integer 0–255
/// (unique, so unique within two hops), else a distance-2 colouring of the radio graph
/// (`model::wire_ids`); an error names the agent that finds no free id.
pub(super) fn wire_ids(
    c: &mut Checker<'_>,
    s: &ScenarioFile,
    agents: &mut [AgentModel],
    radio: &crate::model::graph::Adjacency,
) {
    let small = s
        .agents
        .iter()
        .all(|a| matches!(a.id, AgentId::Number(k) if (0..=255).contains(&k)));
    if small || radio.len() != agents.len() {
        return;
    }
    let adj: Vec<Vec<usize>> = (0..radio.len()).map(|i| radio.of(i).to_vec()).collect();
    match crate::model::wire_ids::distance2_colouring(&adj, &[]) {
        Ok(ids) => {
            for (a, id) in agents.iter_mut().zip(ids) {
                a.id = id;
            }
        }
        Err(crate::model::wire_ids::ColouringError::TooManyColours { agent, conflicts }) => {
            c.err(
                InvalidValue,
                &format!("agents[{agent}]"),
                format!(
                    "no one-byte wire id is left for agent {}: it has {conflicts} agents within two hops whose ids use all 256; give it (and its neighbours) fewer neighbours",
                    agent_id(agents, agent)
                ),
            );
        }
        Err(e) => c.err(InvalidValue, "agents", e.to_string()),
    }
}
