//! The final formation against the model's target shape, up to translation, rotation,
//! scale and a mirror image of the whole formation (which no angle can see), and the
//! triangles folded across an edge (`model::shape`).

use crate::model::shape::{compare, folded_triangles, ShapeComparison};
use crate::model::Model;

/// Compares positions `q` (agent order) with `model.target`; `None` when the model has no
/// usable target (none built, or all its points coincide). The folded triangles are the
/// fewer of the two sets "folded relative to the target" and "folded relative to its
/// mirror image" (a fold of a few triangles can make the mirror the closer fit, but the
/// triangles that moved are the few).
pub fn shape_check(model: &Model, q: &[[f64; 2]]) -> Option<ShapeComparison> {
    if model.target.positions.len() != q.len() {
        return None;
    }
    let tris: Vec<[usize; 3]> = model.triangles.iter().map(|t| t.vertices).collect();
    let mut c = compare(q, &model.target.positions, &tris).ok()?;
    if !c.folded.is_empty() {
        let other = folded_triangles(q, &model.target.positions, &tris, !c.fit.reflected).ok()?;
        if other.len() < c.folded.len() {
            c.folded = other;
        }
    }
    Some(c)
}

/// The folded triangles as `[a, b, c]` of the user's ids, for messages.
pub fn folded_names(model: &Model, folded: &[usize]) -> Vec<String> {
    let name = |i: usize| model.agents.get(i).map_or("?", |a| a.name.as_str());
    folded
        .iter()
        .filter_map(|&k| model.triangles.get(k))
        .map(|t| {
            let [a, b, c] = t.vertices.map(name);
            format!("[{a}, {b}, {c}]")
        })
        .collect()
}
