//! `[gains]` and `[[triangles]]`: vertices, the two controlled angles of each, their
//! desired values (feasible, within the margin) and gains.

use super::agents::{list, lookup};
use super::checker::Checker;
use crate::model::{AngleModel, TriangleModel};
use crate::scenario::error::ErrorKind::{self, InvalidValue, NonPositiveGain};
use crate::scenario::{GainsSpec, ScenarioFile};
use std::collections::HashMap;
use std::f64::consts::PI;

/// Checks the triangles; returns those whose ids resolved, and whether all did.
pub(super) fn check(
    c: &mut Checker<'_>,
    s: &ScenarioFile,
    index: &HashMap<String, usize>,
    margin: f64,
) -> (Vec<TriangleModel>, bool) {
    let g = &s.gains;
    let mut triangles = Vec::with_capacity(s.triangles.len());
    let mut ids_ok = true;
    for (ti, t) in s.triangles.iter().enumerate() {
        let tf = format!("triangles[{ti}]");
        let mut verts = [0usize; 3];
        let mut ok = true;
        for (k, id) in t.vertices.iter().enumerate() {
            match lookup(c, index, &format!("{tf}.vertices"), id) {
                Some(i) => verts[k] = i,
                None => ok = false,
            }
        }
        if ok && (verts[0] == verts[1] || verts[1] == verts[2] || verts[0] == verts[2]) {
            c.err(
                ErrorKind::NotLaman,
                &format!("{tf}.vertices"),
                format!("triangle {} repeats an agent", list(&t.vertices)),
            );
            ok = false;
        }
        if t.angles.len() != 2 {
            c.err(
                InvalidValue,
                &format!("{tf}.angles"),
                format!(
                    "a triangle controls exactly two of its angles, got {}",
                    t.angles.len()
                ),
            );
            ok = false;
        }
        let mut angle_models = Vec::new();
        let mut desired = Vec::new();
        for (ai, a) in t.angles.iter().enumerate() {
            let af = format!("{tf}.angles[{ai}]");
            let apex = if t.vertices.contains(&a.apex) {
                index.get(&a.apex.to_string()).copied()
            } else {
                c.err(
                    ErrorKind::UnknownId,
                    &format!("{af}.apex"),
                    format!(
                        "apex {} is not a vertex of triangle {}",
                        a.apex,
                        list(&t.vertices)
                    ),
                );
                None
            };
            let want = match (a.desired_deg, a.desired_rad) {
                (Some(deg), None) => Some(deg.to_radians()),
                (None, Some(rad)) => Some(rad),
                (Some(_), Some(_)) => {
                    c.err(
                        InvalidValue,
                        &af,
                        "give the desired angle once: desired_deg or desired_rad, not both",
                    );
                    None
                }
                (None, None) => {
                    c.err(
                        InvalidValue,
                        &af,
                        "missing desired angle: give desired_deg or desired_rad",
                    );
                    None
                }
            };
            if let Some(x) = want {
                let field = if a.desired_deg.is_some() {
                    format!("{af}.desired_deg")
                } else {
                    format!("{af}.desired_rad")
                };
                if !(x.is_finite() && x > margin && x < PI - margin) {
                    c.err(
                        ErrorKind::InfeasibleAngles,
                        &field,
                        format!(
                            "desired angle {:.4}° must lie strictly between {:.1}° and {:.1}° (the angle margin keeps it away from 0 and 180°)",
                            x.to_degrees(),
                            margin.to_degrees(),
                            180.0 - margin.to_degrees()
                        ),
                    );
                } else {
                    desired.push(x);
                }
            }
            // A gain of the angle, else of [gains], else formation-only's (schema.rs).
            let mut gain = |name: &str, own: Option<f64>, dflt: Option<f64>, builtin: f64| -> f64 {
                let x = own.or(dflt).unwrap_or(builtin);
                let zero_ok = name == "damping";
                let good = x.is_finite() && (x > 0.0 || (zero_ok && x == 0.0));
                if !good {
                    let need = if zero_ok { "≥ 0" } else { "> 0" };
                    let field = if own.is_some() {
                        format!("{af}.{name}")
                    } else {
                        format!("gains.{name}")
                    };
                    c.err(
                        NonPositiveGain,
                        &field,
                        format!("gain must be finite and {need}, got {x}"),
                    );
                }
                x
            };
            let stiffness = gain(
                "stiffness",
                a.stiffness,
                g.stiffness,
                GainsSpec::DEFAULT_STIFFNESS,
            );
            let damping = gain("damping", a.damping, g.damping, GainsSpec::DEFAULT_DAMPING);
            let estimator_gain = gain(
                "estimator_gain",
                a.estimator_gain,
                g.estimator_gain,
                GainsSpec::DEFAULT_ESTIMATOR_GAIN,
            );
            if let Some(u) = apex {
                let mut far = [0usize; 2];
                let mut k = 0;
                for &v in &verts {
                    if v != u && k < 2 {
                        far[k] = v;
                        k += 1;
                    }
                }
                angle_models.push(AngleModel {
                    apex: u,
                    far,
                    desired: want.unwrap_or(f64::NAN),
                    stiffness,
                    damping,
                    estimator_gain,
                });
            }
        }
        if t.angles.len() == 2 && t.angles[0].apex == t.angles[1].apex {
            c.err(
                InvalidValue,
                &format!("{tf}.angles[1].apex"),
                format!(
                    "both controlled angles have apex {}; a triangle controls two different angles",
                    t.angles[0].apex
                ),
            );
            ok = false;
        }
        if let [a0, a1] = desired[..] {
            let third = PI - a0 - a1;
            if third <= 0.0 {
                c.err(
                    ErrorKind::InfeasibleAngles,
                    &format!("{tf}.angles"),
                    format!(
                        "the controlled angles {:.4}° + {:.4}° sum to 180° or more: no triangle has them",
                        a0.to_degrees(),
                        a1.to_degrees()
                    ),
                );
            } else if third <= margin {
                c.err(
                    ErrorKind::InfeasibleAngles,
                    &format!("{tf}.angles"),
                    format!(
                        "the controlled angles {:.4}° + {:.4}° leave {:.4}° for the third angle, within the {:.1}° margin of 0",
                        a0.to_degrees(),
                        a1.to_degrees(),
                        third.to_degrees(),
                        margin.to_degrees()
                    ),
                );
            }
        }
        match (ok, <[AngleModel; 2]>::try_from(angle_models)) {
            (true, Ok(angles)) => triangles.push(TriangleModel {
                vertices: verts,
                angles,
            }),
            _ => ids_ok = false,
        }
    }
    (triangles, ids_ok)
}
