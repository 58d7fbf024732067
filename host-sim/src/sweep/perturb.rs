//! Random initial shapes: the reference (the scenario's initial positions, or the sweep's
//! `perturbation.shape`) rotated and displaced by [`crate::design::initial_positions`],
//! the same generator as `host-sim design --perturbation`, so a sweep and a designed
//! scenario perturb alike.

use super::plan::Perturb;
use crate::design::{
    initial_positions, Construction, ControlledAngle, DesignError, DesignTriangle, Figures,
    Perturbation, Scale,
};
use crate::model::Model;

/// Initial positions of one run: the positions, the rotation applied (rad) and how many
/// agents had their displacement shortened to keep every triangle valid.
#[derive(Clone, Debug, PartialEq)]
pub struct Shape {
    /// `q(0)`, agent order.
    pub positions: Vec<[f64; 2]>,
    /// Rotation about the centroid (rad).
    pub rotation: f64,
    /// Agents whose displacement was halved (see `initial_positions`).
    pub shortened: usize,
}

/// The interior angle at `p` of the triangle `p, a, b` (degrees).
fn angle_deg(p: [f64; 2], a: [f64; 2], b: [f64; 2]) -> f64 {
    crate::model::geometry::interior_angle(p, a, b).to_degrees()
}

/// Perturbed initial positions for `model` (its triangles, angle margin and collision
/// distance), at `fraction` of the reference's size, from `seed`.
pub fn positions(
    model: &Model,
    p: &Perturb,
    fraction: f64,
    seed: u64,
) -> Result<Shape, DesignError> {
    let reference: Vec<[f64; 2]> = match &p.shape {
        Some(s) => s.clone(),
        None => model.agents.iter().map(|a| a.position).collect(),
    };
    let mut min_angle = 180.0f64;
    let triangles: Vec<DesignTriangle> = model
        .triangles
        .iter()
        .map(|t| {
            let [a, b, c] = t.vertices.map(|v| reference[v]);
            min_angle = min_angle
                .min(angle_deg(a, b, c))
                .min(angle_deg(b, c, a))
                .min(angle_deg(c, a, b));
            DesignTriangle {
                vertices: t.vertices,
                angles: t.angles.clone().map(|x| ControlledAngle {
                    apex: x.apex,
                    desired: x.desired,
                }),
                overlapping: false,
            }
        })
        .collect();
    // Only the triangles and the smallest angle are read by `initial_positions`.
    let construction = Construction {
        triangles,
        leader: [0, 1],
        margin_deg: 0.0,
        figures: Figures {
            agents: model.n(),
            triangles: model.triangles.len(),
            min_controlled_deg: 0.0,
            min_angle_deg: min_angle,
            max_triangles_per_agent: 0,
            max_neighbours_per_agent: 0,
            longest_edge: 0.0,
            mean_edge: 0.0,
            overlapping: 0,
        },
    };
    let margin_deg = model.limits.margin_cos.clamp(-1.0, 1.0).acos().to_degrees();
    let init = initial_positions(
        &reference,
        &construction,
        &Perturbation {
            fraction,
            scale: Scale::Size,
            rotate: p.rotate,
            seed,
        },
        margin_deg,
        model.criteria.collision_distance,
    )?;
    Ok(Shape {
        positions: init.positions,
        rotation: init.rotation,
        shortened: init.shortened,
    })
}

/// The `--set` overrides that place the agents at `positions` (`agents.<i>.position`).
pub fn overrides(positions: &[[f64; 2]]) -> Vec<String> {
    positions
        .iter()
        .enumerate()
        .map(|(i, q)| {
            let v = toml::Value::Array(vec![toml::Value::Float(q[0]), toml::Value::Float(q[1])]);
            format!("agents.{i}.position={v}")
        })
        .collect()
}
