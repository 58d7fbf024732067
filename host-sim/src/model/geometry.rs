//! Plane geometry that every layer shares: the one triangle orientation ([`cross`]) and
//! the one interior angle ([`interior_angle`]). Validation, the designer, sweeps, the
//! driver's flip check and the diagnostics call these; nothing else computes either.

/// A point of the plane (m).
pub type Point = [f64; 2];

/// `b − a`.
#[inline]
pub fn sub(b: Point, a: Point) -> Point {
    [b[0] - a[0], b[1] - a[1]]
}

/// Twice the signed area of the triangle `o, a, b`: `(a − o) × (b − o)`, positive when
/// `o, a, b` turn counter-clockwise (the orientation the desired angles cannot see,
/// docs/spec.md §3).
#[inline]
pub fn cross(o: Point, a: Point, b: Point) -> f64 {
    let u = sub(a, o);
    let w = sub(b, o);
    u[0] * w[1] - u[1] * w[0]
}

/// The interior angle at `p` between the rays to `a` and `b` (rad, in `[0, π]`): the
/// angle `α` whose cosine S4 (docs/spec.md) controls, as `atan2(|u × w|, u · w)`, which
/// keeps its precision near 0 and π (`acos` of the cosine does not). 0 when `a` or `b`
/// coincides with `p`.
#[inline]
pub fn interior_angle(p: Point, a: Point, b: Point) -> f64 {
    let u = sub(a, p);
    let w = sub(b, p);
    (u[0] * w[1] - u[1] * w[0])
        .abs()
        .atan2(u[0] * w[0] + u[1] * w[1])
}

#[cfg(test)]
mod tests {
    use super::{cross, interior_angle};
    use std::f64::consts::{FRAC_PI_2, FRAC_PI_3, PI};

    #[test]
    fn angles_and_orientation_of_known_triangles() {
        let (o, x, y) = ([0.0, 0.0], [1.0, 0.0], [0.0, 1.0]);
        assert_eq!(cross(o, x, y), 1.0);
        assert_eq!(cross(o, y, x), -1.0);
        assert_eq!(interior_angle(o, x, y), FRAC_PI_2);
        let apex = [0.5, 3f64.sqrt() / 2.0];
        assert!((interior_angle(apex, o, x) - FRAC_PI_3).abs() < 1e-15);
        assert_eq!(interior_angle(o, x, [-1.0, 0.0]), PI);
        // Near 0, where acos of the cosine rounds to 0: the angle keeps its digits.
        let tiny = interior_angle(o, [1.0, 0.0], [1.0, 1e-9]);
        assert!((tiny - 1e-9).abs() < 1e-20, "{tiny}");
        assert_eq!(interior_angle(o, o, x), 0.0);
    }
}
