//! S6 against central finite differences at random non-degenerate triangles (f64).

use ph_formation_core::{geometry, Vec2};
use proptest::prelude::*;

fn cos_at(u: Vec2<f64>, v: Vec2<f64>, w: Vec2<f64>) -> f64 {
    ((v - u) / (v - u).norm()).dot(&((w - u) / (w - u).norm()))
}

fn point() -> impl Strategy<Value = Vec2<f64>> {
    (-10.0..10.0f64, -10.0..10.0f64).prop_map(|(x, y)| Vec2::new(x, y))
}

/// Non-degenerate: sides ≥ 0.1 and every interior angle in [2°, 178°].
fn non_degenerate(p: &[Vec2<f64>; 3]) -> bool {
    let ok_side = (0..3).all(|i| (p[i] - p[(i + 1) % 3]).norm() >= 0.1);
    let c = 2f64.to_radians().cos();
    ok_side && (0..3).all(|i| cos_at(p[i], p[(i + 1) % 3], p[(i + 2) % 3]).abs() <= c)
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(2000))]
    #[test]
    fn jacobian_matches_central_differences(u in point(), v in point(), w in point()) {
        let p = [u, v, w];
        prop_assume!(non_degenerate(&p));
        let (rv, rw) = ((v - u).norm(), (w - u).norm());
        let s = [(v - u) / rv, (w - u) / rw];
        let jac = geometry::angle_jacobian(&s, [rv, rw]);
        for (k, analytic) in jac.iter().enumerate() {
            for axis in 0..2 {
                let h = 1e-6 * rv.min(rw);
                let mut plus = p;
                let mut minus = p;
                plus[k][axis] += h;
                minus[k][axis] -= h;
                let fd = (cos_at(plus[0], plus[1], plus[2]) - cos_at(minus[0], minus[1], minus[2])) / (2.0 * h);
                let scale = analytic.norm().max(1e-3);
                let err = (fd - analytic[axis]).abs() / scale;
                prop_assert!(err <= 1e-6, "vertex {k} axis {axis}: fd {fd} vs S6 {} (rel {err:e})", analytic[axis]);
            }
        }
        // S5 uses the same directions: ẏ = Σ ∂y/∂q · q̇ equals t_uv + t_uw with S2 rates.
        let vel = [Vec2::new(0.3, -1.1), Vec2::new(-0.7, 0.2), Vec2::new(1.3, 0.9)];
        let s_dot = [
            geometry::bearing_rate(&s[0], &(vel[1] - vel[0]), rv),
            geometry::bearing_rate(&s[1], &(vel[2] - vel[0]), rw),
        ];
        let t = geometry::cosine_rate_shares(&s, &s_dot);
        let y_dot: f64 = (0..3).map(|k| jac[k].dot(&vel[k])).sum();
        prop_assert!((t[0] + t[1] - y_dot).abs() <= 1e-9 * (1.0 + y_dot.abs()));
    }
}
