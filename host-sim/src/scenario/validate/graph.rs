//! The graph: triangulated Laman (SPEC §3), no (nearly) collinear initial triangle, and
//! every agent within the controller's capacity.

use super::agents::{agent_id, list};
use super::checker::{interior_angle, Checker};
use crate::model::graph::{laman_order, Graph, LamanError};
use crate::model::{AgentModel, TriangleModel, MT, NB};
use crate::scenario::error::ErrorKind::{self, InvalidValue};
use crate::scenario::ScenarioFile;
use std::f64::consts::PI;

/// Checks that the triangles form a triangulated Laman graph and none is (nearly)
/// collinear at the start (only when every id resolved: `ids_ok`); returns a construction
/// order of the triangles when they are one.
pub(super) fn check(
    c: &mut Checker<'_>,
    s: &ScenarioFile,
    agents: &[AgentModel],
    triangles: &[TriangleModel],
    ids_ok: bool,
    margin: f64,
) -> Option<Vec<usize>> {
    let mut order = None;
    let tri_idx: Vec<[usize; 3]> = triangles.iter().map(|t| t.vertices).collect();
    let n = agents.len();
    let id_of = |i: usize| agent_id(agents, i);
    if ids_ok && n >= 3 && c.errors.iter().all(|e| e.kind != ErrorKind::DuplicateId) {
        match laman_order(n, &tri_idx) {
            Ok(o) => order = Some(o),
            Err(e) => {
                let (field, reason) = match e {
                    LamanError::Empty => (
                        "triangles".to_owned(),
                        "no triangles: the graph must be built from triangles".to_owned(),
                    ),
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
                    LamanError::Unattached(rest) => unattached(c, s, &tri_idx, &rest, &id_of),
                };
                c.err(ErrorKind::NotLaman, &field, reason);
            }
        }
        // ---- collinear initial triangles
        for (ti, t) in triangles.iter().enumerate() {
            let p = t.vertices.map(|v| agents[v].position);
            for k in 0..3 {
                let ang = interior_angle(p[k], p[(k + 1) % 3], p[(k + 2) % 3]);
                if !(ang > margin && ang < PI - margin) {
                    let what = if ang.is_nan() {
                        "two vertices coincide".to_owned()
                    } else {
                        format!(
                            "the angle at agent {} is {:.3}°, within the {:.1}° margin of 0 or 180°",
                            id_of(t.vertices[k]),
                            ang.to_degrees(),
                            margin.to_degrees()
                        )
                    };
                    c.err(
                        ErrorKind::CollinearTriangle,
                        &format!("triangles[{ti}]"),
                        format!(
                            "triangle {} is (nearly) collinear in the initial positions: {what}",
                            list(&t.vertices.map(id_of))
                        ),
                    );
                    break;
                }
            }
        }
    }
    order
}

/// The field and reason of triangles that cannot be attached (`rest`, list positions):
/// the first in the file, by its agent ids, line and why, then all of them.
fn unattached(
    c: &Checker<'_>,
    s: &ScenarioFile,
    tri_idx: &[[usize; 3]],
    rest: &[usize],
    id_of: &dyn Fn(usize) -> String,
) -> (String, String) {
    let mut rest = rest.to_vec();
    rest.sort_unstable();
    let first = rest.first().copied().unwrap_or(0);
    let ids = |k: usize| {
        s.triangles
            .get(k)
            .map_or_else(String::new, |t| list(&t.vertices))
    };
    // What the attached triangles built: their agents and edges.
    let mut placed = std::collections::HashSet::new();
    let mut edges = std::collections::HashSet::new();
    for (k, t) in tri_idx.iter().enumerate() {
        if rest.binary_search(&k).is_err() {
            placed.extend(t.iter().copied());
            for (a, b) in [(t[0], t[1]), (t[1], t[2]), (t[0], t[2])] {
                edges.insert((a.min(b), a.max(b)));
            }
        }
    }
    let t = tri_idx.get(first).copied().unwrap_or_default();
    let on_built_edge = [(t[0], t[1]), (t[1], t[2]), (t[0], t[2])]
        .iter()
        .any(|&(a, b)| edges.contains(&(a.min(b), a.max(b))));
    let why = if t.iter().all(|v| placed.contains(v)) {
        "its three agents are already joined by the triangles that attach, so it adds no new agent (too many triangles on them)".to_owned()
    } else if on_built_edge {
        "it would join more than one new agent".to_owned()
    } else {
        let known: Vec<String> = t
            .iter()
            .filter(|v| placed.contains(v))
            .map(|&v| id_of(v))
            .collect();
        format!(
            "it shares no edge with the triangles that attach (agents of it already joined: {})",
            if known.is_empty() {
                "none".to_owned()
            } else {
                known.join(", ")
            }
        )
    };
    let all: Vec<String> = rest
        .iter()
        .map(|&k| format!("{}{}", ids(k), c.line_of("triangles", k)))
        .collect();
    (
        format!("triangles[{first}]"),
        format!(
            "triangle {}{} cannot be attached: {why}; each triangle after the first must join exactly one new agent to an edge of the triangles before it (SPEC §3); {} cannot be attached: {}",
            ids(first),
            c.line_of("triangles", first),
            if all.len() == 1 { "1 triangle".to_owned() } else { format!("{} triangles", all.len()) },
            all.join(", ")
        ),
    )
}

/// Checks every agent's triangles and radio neighbours against the controller's
/// capacity (`MT`, `NB`: `ph_formation_core::{MAX_TRIANGLES, MAX_NEIGHBOURS}`).
pub(super) fn capacity(c: &mut Checker<'_>, agents: &[AgentModel], graph: &Graph) {
    let id_of = |i: usize| agent_id(agents, i);
    for i in 0..agents.len() {
        let tris = graph.membership.of(i);
        if tris.len() > MT {
            let shown: Vec<String> = tris.iter().map(|k| format!("triangles[{k}]")).collect();
            c.err(
                InvalidValue,
                &format!("agents[{i}]"),
                format!(
                    "agent {} belongs to {} triangles ({}); the controller holds at most {MT} (ph_formation_core::MAX_TRIANGLES): move {} of them to other agents, e.g. regenerate with `host-sim design`",
                    id_of(i),
                    tris.len(),
                    shown.join(", "),
                    tris.len() - MT
                ),
            );
        }
        let nb = graph.radio.of(i);
        if nb.len() > NB {
            let shown: Vec<String> = nb.iter().map(|&j| id_of(j)).collect();
            c.err(
                InvalidValue,
                &format!("agents[{i}]"),
                format!(
                    "agent {} has {} neighbours ({}); the controller holds at most {NB} (ph_formation_core::MAX_NEIGHBOURS): remove triangles through it so that it has {} fewer",
                    id_of(i),
                    nb.len(),
                    shown.join(", "),
                    nb.len() - NB
                ),
            );
        }
    }
}
