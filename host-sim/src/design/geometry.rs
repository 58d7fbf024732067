//! Plane geometry of the construction: interior angles, orientation (the model's one
//! implementation of each, [`crate::model::geometry`]), and the overlap tests of
//! triangles (separating axes) and points.

use super::points::Point;
pub(crate) use crate::model::geometry::{cross, interior_angle as angle_at, sub};

/// `|b − a|`.
#[inline]
pub(crate) fn dist(a: Point, b: Point) -> f64 {
    (b[0] - a[0]).hypot(b[1] - a[1])
}

/// The three interior angles of a triangle, at `t[0]`, `t[1]`, `t[2]`.
#[inline]
pub(crate) fn angles(t: [Point; 3]) -> [f64; 3] {
    [
        angle_at(t[0], t[1], t[2]),
        angle_at(t[1], t[2], t[0]),
        angle_at(t[2], t[0], t[1]),
    ]
}

/// Distance of an angle from the nearest of 0 and π: `min(α, π − α)`.
#[inline]
pub(crate) fn margin(alpha: f64) -> f64 {
    alpha.min(std::f64::consts::PI - alpha)
}

/// Whether the interiors of two triangles intersect (touching along an edge or at a vertex
/// is not overlap). Separating-axis test: two convex polygons with disjoint interiors are
/// separated by a line parallel to one of their edges; `tol` (m) absorbs rounding.
pub(crate) fn interiors_overlap(t: &[Point; 3], u: &[Point; 3], tol: f64) -> bool {
    for tri in [t, u] {
        for k in 0..3 {
            let e = sub(tri[(k + 1) % 3], tri[k]);
            let len = e[0].hypot(e[1]);
            if len == 0.0 {
                continue;
            }
            let axis = [-e[1] / len, e[0] / len];
            let span = |q: &[Point; 3]| {
                let mut lo = f64::INFINITY;
                let mut hi = f64::NEG_INFINITY;
                for p in q {
                    let s = p[0] * axis[0] + p[1] * axis[1];
                    lo = lo.min(s);
                    hi = hi.max(s);
                }
                (lo, hi)
            };
            let (lo_t, hi_t) = span(t);
            let (lo_u, hi_u) = span(u);
            if hi_t <= lo_u + tol || hi_u <= lo_t + tol {
                return false;
            }
        }
    }
    true
}

/// Whether `p` lies inside the triangle or on one of its edges (within `tol` m). The caller
/// leaves out the triangle's own vertices.
pub(crate) fn covers(t: &[Point; 3], p: Point, tol: f64) -> bool {
    let orient = cross(t[0], t[1], t[2]).signum();
    if orient == 0.0 {
        return false;
    }
    (0..3).all(|k| {
        let a = t[k];
        let b = t[(k + 1) % 3];
        let len = dist(a, b);
        len > 0.0 && orient * cross(a, b, p) / len >= -tol
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f64::consts::PI;

    #[test]
    fn angles_of_a_right_triangle() {
        let a = angles([[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]]);
        assert!((a[0] - PI / 2.0).abs() < 1e-15);
        assert!((a[1] - PI / 4.0).abs() < 1e-15);
        assert!((a.iter().sum::<f64>() - PI).abs() < 1e-14);
        assert!((margin(2.0 * PI / 3.0) - PI / 3.0).abs() < 1e-15);
    }

    #[test]
    fn overlap_tests() {
        let t = [[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]];
        // Glued on the hypotenuse, on the other side: touching only.
        assert!(!interiors_overlap(
            &t,
            &[[1.0, 0.0], [0.0, 1.0], [1.0, 1.0]],
            1e-12
        ));
        // Folded back over it.
        assert!(interiors_overlap(
            &t,
            &[[1.0, 0.0], [0.0, 1.0], [0.2, 0.2]],
            1e-12
        ));
        // Sharing a vertex only.
        assert!(!interiors_overlap(
            &t,
            &[[0.0, 0.0], [-1.0, 0.0], [0.0, -1.0]],
            1e-12
        ));
        // Far away.
        assert!(!interiors_overlap(
            &t,
            &[[5.0, 5.0], [6.0, 5.0], [5.0, 6.0]],
            1e-12
        ));
        // Crossing without a shared vertex.
        assert!(interiors_overlap(
            &t,
            &[[0.5, -0.5], [0.6, 2.0], [0.7, -0.5]],
            1e-12
        ));
        assert!(covers(&t, [0.2, 0.2], 1e-12));
        assert!(covers(&t, [0.5, 0.0], 1e-12));
        assert!(!covers(&t, [0.6, 0.6], 1e-12));
    }
}
