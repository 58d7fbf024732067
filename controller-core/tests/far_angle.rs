//! The far-vertex kernel `law::far_angle` against the exact geometry: its S8 force equals
//! the apex kernel's force on that vertex (S8) when nothing moved; its update of γ for a
//! change of the far vertex's own velocity is exact (ẏ is linear in the velocities, S5);
//! its update for a displacement is first order: the error is within the second-order
//! bound and falls with the square of the displacement (with the relative velocities zero: the neglected term `d_α (∂ẏ/∂q_k)·δ` is
//! proportional to them, and vanishes at the formation's equilibrium).

use ph_formation_core::{geometry, law, Vec2};
use proptest::prelude::*;

fn point() -> impl Strategy<Value = Vec2<f64>> {
    (-5.0..5.0f64, -5.0..5.0f64).prop_map(|(x, y)| Vec2::new(x, y))
}

/// Sides ≥ 0.5 and every interior angle in [15°, 165°].
fn non_degenerate(p: &[Vec2<f64>; 3]) -> bool {
    let cos_at = |u: Vec2<f64>, v: Vec2<f64>, w: Vec2<f64>| {
        ((v - u) / (v - u).norm()).dot(&((w - u) / (w - u).norm()))
    };
    let c = 15f64.to_radians().cos();
    (0..3).all(|i| (p[i] - p[(i + 1) % 3]).norm() >= 0.5)
        && (0..3).all(|i| cos_at(p[i], p[(i + 1) % 3], p[(i + 2) % 3]).abs() <= c)
}

/// The apex kernel of angle (u; v, w) at positions `q` and velocities `vel`, with exact
/// bearing rates (S2) and the true distances.
fn apex(
    q: &[Vec2<f64>; 3],
    vel: &[Vec2<f64>; 3],
    cos_d: f64,
    c: f64,
    d: f64,
) -> law::ApexAngle<f64> {
    let r = [(q[1] - q[0]).norm(), (q[2] - q[0]).norm()];
    let s = [(q[1] - q[0]) / r[0], (q[2] - q[0]) / r[1]];
    let s_dot = [
        geometry::bearing_rate(&s[0], &(vel[1] - vel[0]), r[0]),
        geometry::bearing_rate(&s[1], &(vel[2] - vel[0]), r[1]),
    ];
    law::apex_angle(&s, &s_dot, cos_d, c, d, r)
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(1000))]
    #[test]
    fn far_kernel_matches_the_geometry(
        u in point(), v in point(), w in point(),
        vu in point(), vv in point(), vw in point(),
        dir in point(), dv in point(), k in 0usize..2,
        cos_d in -0.8..0.8f64, c in 0.5..50.0f64, d in 0.0..5.0f64,
    ) {
        let q = [u, v, w];
        prop_assume!(non_degenerate(&q));
        prop_assume!(dir.norm() > 0.5 && dv.norm() > 0.5);
        let vel = [vu, vv, vw];
        let a = apex(&q, &vel, cos_d, c, d);
        let far = k + 1;
        let r = (q[far] - q[0]).norm();
        let s_to_apex = (q[0] - q[far]) / r;
        // Nothing moved: exactly S8 on the far vertex, and the apex's γ.
        let (gamma_k, g, f) =
            law::far_angle(&far_input(a.gamma, law::far_sigma(a.sigma, k), r, s_to_apex, c, d, Vec2::zeros(), Vec2::zeros()));
        let s8 = a.g[k] * (-a.gamma / r);
        prop_assert!((f - s8).norm() <= 1e-9 * (1.0 + s8.norm()), "{:?} vs {:?}", f, s8);
        prop_assert!((g - a.g[k]).norm() <= 1e-12);
        prop_assert_eq!(gamma_k, a.gamma);
        // The far vertex changed its velocity by dv: exact.
        let mut vel1 = vel;
        vel1[far] += dv;
        let exact = apex(&q, &vel1, cos_d, c, d).gamma;
        let (approx, ..) =
            law::far_angle(&far_input(a.gamma, law::far_sigma(a.sigma, k), r, s_to_apex, c, d, Vec2::zeros(), dv));
        prop_assert!((approx - exact).abs() <= 1e-9 * (1.0 + exact.abs()), "{} vs {}", approx, exact);
        // The far vertex moved by ε·dir (everybody moving together): second order.
        let same = [vu; 3];
        let a = apex(&q, &same, cos_d, c, d);
        let err = |eps: f64| {
            let mut q1 = q;
            q1[far] += dir * (0.01 * eps);
            let exact = apex(&q1, &same, cos_d, c, d).gamma;
            let (approx, ..) = law::far_angle(&far_input(
                a.gamma, law::far_sigma(a.sigma, k), r, s_to_apex, c, d,
                dir * (0.01 * eps), Vec2::zeros(),
            ));
            ((approx - exact).abs(), (a.gamma - exact).abs())
        };
        // Second order: within the Taylor remainder ½·max|∂²y/∂q²|·c|δ|², with
        // |∂²y/∂q²| ≤ 3/r'² (r' ≥ 0.85 r on the segment: |δ| ≤ 0.07, r ≥ 0.5), at every
        // scale; a first-order error would break the bound as the displacement shrinks.
        for eps in [1.0, 0.1, 0.01] {
            let (e, u) = err(eps);
            let delta = (dir * (0.01 * eps)).norm();
            let bound = 2.1 * c * (delta / r).powi(2) + 1e-13;
            prop_assert!(e <= bound, "ε = {}: error {} > {} (uncorrected {})", eps, e, bound, u);
        }
    }
}

/// `law::FarAngle` from its fields in their order (gamma, σ_k, r_k, s_ku, c, d, δ, Δv).
#[allow(clippy::too_many_arguments)]
fn far_input(
    gamma: f64,
    sigma_k: f64,
    r_k: f64,
    s_to_apex: Vec2<f64>,
    stiffness: f64,
    damping: f64,
    delta: Vec2<f64>,
    dv: Vec2<f64>,
) -> law::FarAngle<f64> {
    law::FarAngle {
        gamma,
        sigma_k,
        r_k,
        s_to_apex,
        stiffness,
        damping,
        delta,
        dv,
    }
}
