//! The target shape: the positions the formation should take up to translation,
//! rotation, scale and mirror (`[target]` of the scenario, or built from the desired
//! angles).

use super::formation::TriangleModel;
use super::geometry::{cross, sub};

/// The target shape of a formation.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Target {
    /// One position per agent, in agent order (m; only the shape matters).
    pub positions: Vec<[f64; 2]>,
    /// Given by the scenario's `[target]` (`false`: built by [`target_from_angles`]).
    pub from_file: bool,
}

/// The shape the desired angles encode (SPEC §3: a triangulated Laman graph fixes the
/// shape up to similarity once each triangle's orientation is fixed). `order` is a
/// construction order of the triangles (`graph::laman_order`). The first triangle's base
/// edge keeps its initial positions; each new vertex `v` of a triangle on the placed edge
/// `u–w` is placed by the triangle's angles (the two desired ones, the third is
/// `π − α − β`) and the sine rule, `|uv| = |uw| sin∠w / sin∠v`, on the side of `u–w`
/// where it lies in `initial` (the orientation the angles cannot see).
pub fn target_from_angles(
    initial: &[[f64; 2]],
    triangles: &[TriangleModel],
    order: &[usize],
) -> Vec<[f64; 2]> {
    let n = initial.len();
    let mut out = initial.to_vec();
    let mut placed = vec![false; n];
    for (k, &ti) in order.iter().enumerate() {
        let Some(t) = triangles.get(ti) else { continue };
        if t.vertices.iter().any(|&v| v >= n) {
            continue;
        }
        if k == 0 {
            placed[t.vertices[0]] = true;
            placed[t.vertices[1]] = true;
        }
        let Some(&v) = t.vertices.iter().find(|&&v| !placed[v]) else {
            continue;
        };
        let base: Vec<usize> = t.vertices.iter().copied().filter(|&x| x != v).collect();
        let (u, w) = (base[0], base[1]);
        let angle = |apex: usize| t.angles.iter().find(|a| a.apex == apex).map(|a| a.desired);
        let third = std::f64::consts::PI - t.angles[0].desired - t.angles[1].desired;
        let au = angle(u).unwrap_or(third);
        let aw = angle(w).unwrap_or(third);
        let av = angle(v).unwrap_or(third);
        let side = if cross(initial[u], initial[w], initial[v]) >= 0.0 {
            1.0
        } else {
            -1.0
        };
        let d = sub(out[w], out[u]);
        let len = d[0].hypot(d[1]) * aw.sin() / av.sin();
        let (s, c) = (side * au).sin_cos();
        let scale = len / d[0].hypot(d[1]);
        out[v] = [
            out[u][0] + scale * (c * d[0] - s * d[1]),
            out[u][1] + scale * (s * d[0] + c * d[1]),
        ];
        placed[v] = true;
    }
    out
}
