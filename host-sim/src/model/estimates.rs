//! Where each estimate an agent owns sits in the formation: the controllers report their
//! owned estimates by `(triangle, angle, edge)` of their own configuration; here they
//! are resolved to agent indices (for the diagnostics, the CSV columns and the summary).

use super::{Model, ModelError};
use ph_formation_core::OwnedEstimate;

/// Where one owned estimate belongs (by agent index).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct EstimateInfo {
    /// The agent that owns (integrates) it.
    pub owner: usize,
    /// The angle's apex `u`.
    pub apex: usize,
    /// The far vertex `f` of its edge.
    pub far: usize,
    /// The angle's other far vertex `w`.
    pub other: usize,
    /// `c_e` of the angle.
    pub gain: f64,
    /// Triangle index in the owner's controller configuration.
    pub local_triangle: usize,
    /// Angle index (0, 1) in the triangle.
    pub angle: usize,
    /// Edge index (0, 1) in the angle.
    pub edge: usize,
}

/// Resolves the estimates reported by agent `owner`'s controller to agent indices.
pub fn resolve_estimates(
    model: &Model,
    owner: usize,
    owned: &[OwnedEstimate<f64>],
) -> Result<Vec<EstimateInfo>, ModelError> {
    let tris: Vec<usize> = model.triangles_of(owner).collect();
    owned
        .iter()
        .map(|e| {
            let k = *tris
                .get(e.triangle)
                .ok_or(ModelError::UnknownTriangle(e.triangle))?;
            let a = model.triangles[k]
                .angles
                .get(e.angle)
                .ok_or(ModelError::UnknownAngle(e.angle))?;
            let (far, other) = match e.edge {
                0 => (a.far[0], a.far[1]),
                _ => (a.far[1], a.far[0]),
            };
            if model.agents[far].id != e.far || model.agents[a.apex].id != e.apex {
                return Err(ModelError::LayoutMismatch {
                    owner,
                    apex: e.apex,
                    far: e.far,
                });
            }
            Ok(EstimateInfo {
                owner,
                apex: a.apex,
                far,
                other,
                gain: a.estimator_gain,
                local_triangle: e.triangle,
                angle: e.angle,
                edge: e.edge,
            })
        })
        .collect()
}

/// Every agent's owned estimates, in agent order, as the agents' own configurations lay
/// them out (the layout of the CSV columns and of `summary.json`).
pub fn estimate_layout(model: &Model) -> Result<Vec<EstimateInfo>, ModelError> {
    let mut layout = Vec::new();
    for i in 0..model.n() {
        let a = model.core_agent(i)?;
        let owned: Vec<_> = a.owned_estimates().collect();
        layout.extend(resolve_estimates(model, i, &owned)?);
    }
    Ok(layout)
}
