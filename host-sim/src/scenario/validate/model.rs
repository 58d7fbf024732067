//! The checks every [`Model`] passes before it runs, whether a scenario file made it
//! (after the file's own checks) or it was generated (`scenario::strip`): a triangulated
//! Laman graph (SPEC §3), no (nearly) collinear initial triangle, the controller's
//! capacity, one-byte wire ids that every receiver can tell apart, and the core's own
//! checks of each agent's configuration.
//!
//! # Repeated wire ids
//!
//! A frame names its sender by a one-byte id, and its angle items name the triangle's
//! other vertices by their ids. A receiver looks its neighbours up by id in its own table
//! (`ph_formation_core`), so it must tell apart itself and every agent it hears, and the
//! agents that a neighbour's frames name: ids must differ between any two agents within
//! two hops of the radio graph (neighbours, or neighbours of one agent). Farther apart an
//! id may repeat, which is how formations of more than 256 agents get their ids
//! (`model::wire_ids`). A repeat within two hops is refused here, naming both agents.

use super::agents::agent_id;
use super::checker::{interior_angle, Checker};
use crate::model::graph::{laman_order, LamanError};
use crate::model::wire_ids::check_distance2;
use crate::model::Model;
use crate::scenario::error::ErrorKind::{self, InvalidValue};
use crate::scenario::error::ScenarioErrors;
use std::f64::consts::PI;

/// Checks `model` (errors are labelled with `model.source`); every problem found.
pub fn check_model(model: &Model) -> Result<(), ScenarioErrors> {
    let mut c = Checker {
        file: &model.source,
        text: None,
        errors: Vec::new(),
    };
    structure(&mut c, model);
    if c.errors.is_empty() {
        super::graph::capacity(&mut c, &model.agents, &model.graph);
    }
    if c.errors.is_empty() {
        built(&mut c, model);
    }
    if c.errors.is_empty() {
        Ok(())
    } else {
        Err(ScenarioErrors(c.errors))
    }
}

/// The checks of a model whose structure and capacity were checked already (a file's, by
/// the file's own checks, with its lines and fields): wire ids, then the core's checks.
pub(super) fn built(c: &mut Checker<'_>, model: &Model) {
    wire_ids(c, model);
    if c.errors.is_empty() {
        core(c, model);
    }
}

/// Indices in range, a Laman graph, no collinear initial triangle, a graph of the model's
/// own triangles and leader.
fn structure(c: &mut Checker<'_>, m: &Model) {
    let n = m.agents.len();
    let id_of = |i: usize| agent_id(&m.agents, i);
    for (k, t) in m.triangles.iter().enumerate() {
        let named = t.angles.iter().flat_map(|a| [a.apex, a.far[0], a.far[1]]);
        if t.vertices.into_iter().chain(named).any(|v| v >= n) {
            c.err(
                ErrorKind::UnknownId,
                &format!("triangles[{k}]"),
                format!("an agent index of {:?} is not below {n}", t.vertices),
            );
            return;
        }
    }
    let tri_idx: Vec<[usize; 3]> = m.triangles.iter().map(|t| t.vertices).collect();
    if let Err(e) = laman_order(n, &tri_idx) {
        let (field, reason) = match e {
            LamanError::Empty => ("triangles".to_owned(), "no triangles".to_owned()),
            LamanError::Isolated(i) => (
                format!("agents[{i}]"),
                format!("agent {} belongs to no triangle", id_of(i)),
            ),
            LamanError::Count { agents, triangles } => (
                "triangles".to_owned(),
                format!(
                    "{agents} agents need exactly {} triangles (N = M + 2), got {triangles}",
                    agents.saturating_sub(2)
                ),
            ),
            LamanError::Unattached(rest) => (
                format!("triangles[{}]", rest.first().copied().unwrap_or(0)),
                format!(
                    "{} triangles join no new agent to an edge of the ones before",
                    rest.len()
                ),
            ),
        };
        c.err(ErrorKind::NotLaman, &field, reason);
        return;
    }
    if m.graph.radio.len() != n || m.graph.membership.len() != n {
        c.err(
            InvalidValue,
            "agents",
            "the interaction graph is not the graph of these agents",
        );
        return;
    }
    let margin = m.limits.margin_cos.clamp(-1.0, 1.0).acos();
    for (k, t) in m.triangles.iter().enumerate() {
        let p = t.vertices.map(|v| m.agents[v].position);
        if let Some(j) = (0..3).find(|&j| {
            let ang = interior_angle(p[j], p[(j + 1) % 3], p[(j + 2) % 3]);
            !(ang > margin && ang < PI - margin)
        }) {
            c.err(
                ErrorKind::CollinearTriangle,
                &format!("triangles[{k}]"),
                format!(
                    "the initial angle at agent {} is within {:.1}° of 0 or 180°",
                    id_of(t.vertices[j]),
                    margin.to_degrees()
                ),
            );
        }
    }
}

/// Wire ids distinct within two hops of the radio graph (module docs).
fn wire_ids(c: &mut Checker<'_>, m: &Model) {
    let adj: Vec<Vec<usize>> = (0..m.graph.radio.len())
        .map(|i| m.graph.radio.of(i).to_vec())
        .collect();
    let ids: Vec<u8> = m.agents.iter().map(|a| a.id).collect();
    if let Err([u, w]) = check_distance2(&adj, &[], &ids) {
        let (u, w) = (u.min(w), u.max(w));
        let how = if adj[u].contains(&w) {
            "neighbours".to_owned()
        } else {
            let common = adj[u].iter().find(|v| adj[w].contains(v));
            format!(
                "neighbours of agent {}",
                common.map_or_else(|| "?".to_owned(), |&v| id_of(m, v))
            )
        };
        c.err(
            ErrorKind::DuplicateId,
            &format!("agents[{w}]"),
            format!(
                "agents {} (agents[{u}]) and {} (agents[{w}]) share wire id {} and are {how}: \
                 a receiver could not tell their frames apart; wire ids may repeat only \
                 beyond two hops",
                id_of(m, u),
                id_of(m, w),
                ids[u]
            ),
        );
    }
}

fn id_of(m: &Model, i: usize) -> String {
    agent_id(&m.agents, i)
}

/// The core's own checks of every agent's configuration.
fn core(c: &mut Checker<'_>, m: &Model) {
    for i in 0..m.n() {
        if let Err(e) = m.core_agent(i) {
            c.err(InvalidValue, &format!("agents[{i}]"), e.to_string());
        }
    }
}
