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
                    LamanError::Unattached(rest) => {
                        let first = rest.first().copied().unwrap_or(0);
                        (
                        format!("triangles[{first}]"),
                        format!(
                            "triangle {} does not join exactly one new agent to an edge of the triangles before it (triangles {:?} cannot be attached)",
                            s.triangles.get(first).map_or_else(String::new, |t| list(&t.vertices)),
                            rest
                        ),
                    )
                    }
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

/// Checks every agent's triangles and radio neighbours against the controller's
/// capacity (`MT`, `NB`: `controller_core::{MAX_TRIANGLES, MAX_NEIGHBOURS}`).
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
                    "agent {} belongs to {} triangles ({}); the controller holds at most {MT} (controller_core::MAX_TRIANGLES): move {} of them to other agents, e.g. regenerate with `host-sim design`",
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
                    "agent {} has {} neighbours ({}); the controller holds at most {NB} (controller_core::MAX_NEIGHBOURS): remove triangles through it so that it has {} fewer",
                    id_of(i),
                    nb.len(),
                    shown.join(", "),
                    nb.len() - NB
                ),
            );
        }
    }
}
