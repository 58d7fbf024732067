//! `[target]`: the target shape. Given, it must have one finite point per agent, not all
//! in one place, and realise the desired angles; absent, it is built from the desired
//! angles with each triangle's orientation taken from the initial positions.

use super::checker::{interior_angle, Checker};
use crate::model::target::{target_from_angles, Target};
use crate::model::{AgentModel, TriangleModel};
use crate::scenario::error::ErrorKind::InvalidValue;
use crate::scenario::ScenarioFile;

/// How far (rad) a given target's angle may be from the desired one: a target that does
/// not realise the angles could never be reached.
const ANGLE_TOLERANCE: f64 = 1e-3;

/// Checks or builds the target; `order` is the triangles' construction order (`None` when
/// they are not a triangulated Laman graph: then no target is built).
pub(super) fn check(
    c: &mut Checker<'_>,
    s: &ScenarioFile,
    agents: &[AgentModel],
    triangles: &[TriangleModel],
    order: Option<&[usize]>,
) -> Target {
    let initial: Vec<[f64; 2]> = agents.iter().map(|a| a.position).collect();
    let Some(spec) = &s.target else {
        return Target {
            positions: order.map_or_else(Vec::new, |o| target_from_angles(&initial, triangles, o)),
            from_file: false,
        };
    };
    let p = &spec.positions;
    let field = "target.positions";
    if p.len() != agents.len() {
        c.err(
            InvalidValue,
            field,
            format!(
                "has {} points but there are {} agents: give one [x, y] per agent, in [[agents]] order",
                p.len(),
                agents.len()
            ),
        );
        return Target::default();
    }
    if let Some(i) = p
        .iter()
        .position(|q| !(q[0].is_finite() && q[1].is_finite()))
    {
        c.err(
            InvalidValue,
            &format!("{field}[{i}]"),
            format!("must be two finite numbers, got {:?}", p[i]),
        );
        return Target::default();
    }
    if p.iter().all(|q| q == &p[0]) {
        c.err(InvalidValue, field, "all target points coincide: no shape");
        return Target::default();
    }
    for (ti, t) in triangles.iter().enumerate() {
        for a in &t.angles {
            let got = interior_angle(p[a.apex], p[a.far[0]], p[a.far[1]]);
            if (got - a.desired).abs() > ANGLE_TOLERANCE || got.is_nan() {
                c.err(
                    InvalidValue,
                    field,
                    format!(
                        "the target does not realise triangles[{ti}]: its angle at agent {} is {:.4}°, the desired angle {:.4}°; give the positions the angles describe",
                        agents[a.apex].name,
                        got.to_degrees(),
                        a.desired.to_degrees()
                    ),
                );
                return Target::default();
            }
        }
    }
    Target {
        positions: p.clone(),
        from_file: true,
    }
}
