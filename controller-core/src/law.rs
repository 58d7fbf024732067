//! The control law: SPEC S7–S12 as pure functions, and the per-angle kernels the agent
//! runs (one implementation of each: [`apex_angle`] on the apex, [`far_angle`] on a far
//! vertex).

use crate::geometry::{self, AngleGeometry};
use crate::{Real, Vec2};

/// What one controlled angle gives its apex (see [`apex_angle`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ApexAngle<T: Real> {
    /// S4: `y_α = cos α`.
    pub y: T,
    /// S7: `γ_α`.
    pub gamma: T,
    /// S5: the shares `t_{α,uv}`, `t_{α,uw}` of `ẏ_α`.
    pub t: [T; 2],
    /// S6: `g_{α,v}`, `g_{α,w}`.
    pub g: [Vec2<T>; 2],
    /// `σ = s_uv × s_uw = sin α` (signed): `g_{α,v} = σ J s_uv`, `g_{α,w} = −σ J s_uw`.
    pub sigma: T,
    /// S8: the force of the angle on its apex, with the distances `r` it was given.
    pub force: Vec2<T>,
}

/// The kernel of one controlled angle `α = (u; v, w)` at its apex: S4–S6 from the apex's
/// bearings `s = [s_uv, s_uw]` and rates `s_dot`, S7 with the angle's gains, and S8 on the
/// apex with the distances `r = [r_uv, r_uw]` (estimates or ranges).
#[inline]
pub fn apex_angle<T: Real>(
    s: &[Vec2<T>; 2],
    s_dot: &[Vec2<T>; 2],
    cos_desired: T,
    stiffness: T,
    damping: T,
    r: [T; 2],
) -> ApexAngle<T> {
    // S4–S6.
    let geo = AngleGeometry::new(s, s_dot);
    // S7.
    let gamma = port_effort(stiffness, damping, geo.y - cos_desired, geo.y_dot);
    ApexAngle {
        y: geo.y,
        gamma,
        t: geo.t,
        g: geo.g,
        sigma: geo.sigma,
        // S8.
        force: apex_force(gamma, &geo.g, r),
    }
}

/// The far vertex `k` of an angle `α = (u; v, w)` (`k = 0` for `v`, 1 for `w`): its S8 force
/// and its port effort, from what the apex sent — `γ_α` (S7), `σ = s_uv × s_uw` as
/// `σ_k = ±σ` ([`far_sigma`], applied when the item arrives) — and its own fresh bearing
/// to the apex `s_ku` (`s_uk = −s_ku`, SPEC §2), its distance `r_k` to the apex (the
/// apex's shared estimate, its own copy, or its range: SPEC §6), and its own motion
/// relative to the apex since the apex measured: displacement `δ` and change of own
/// velocity `Δv`. With `n_k = J s_uk`, `g_{α,k} = σ_k n_k` (S6), so to first order
/// `Δy = g_kᵀ δ / r_k` and `Δẏ = g_kᵀ Δv / r_k` (S4, S5), and
/// `γ_k = γ_α + c_α Δy + d_α Δẏ` (S7): the far vertex's own stiffness and damping act on
/// fresh measurements. Returns `(γ_k, g_k, U_k)` with `U_k = −(γ_k / r_k) g_k` (S8).
#[inline]
pub fn far_angle<T: Real>(input: &FarAngle<T>) -> (T, Vec2<T>, Vec2<T>) {
    let FarAngle {
        gamma,
        sigma_k,
        r_k,
        s_to_apex,
        stiffness,
        damping,
        delta,
        dv,
    } = *input;
    // n_k = J s_uk = −J s_ku, so g_k = −σ_k J s_ku and g_kᵀ x = −σ_k (s_ku × x).
    let x = delta * stiffness + dv * damping;
    let gamma_k = gamma - sigma_k * geometry::cross(&s_to_apex, &x) / r_k;
    // U_k = −(γ_k / r_k) g_k = (σ_k γ_k / r_k) J s_ku.
    let j_s = geometry::perp(&s_to_apex);
    (gamma_k, j_s * -sigma_k, j_s * (sigma_k * gamma_k / r_k))
}

/// What [`far_angle`] reads: what the apex sent and the far vertex's own measurements.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FarAngle<T: Real> {
    /// S7: the apex's `γ_α`.
    pub gamma: T,
    /// `σ_k = ±σ` ([`far_sigma`]).
    pub sigma_k: T,
    /// The distance `r_k` to the apex (estimate or range).
    pub r_k: T,
    /// The far vertex's fresh bearing to the apex `s_ku`.
    pub s_to_apex: Vec2<T>,
    /// The far vertex's own stiffness `c_α`.
    pub stiffness: T,
    /// The far vertex's own damping `d_α`.
    pub damping: T,
    /// Its displacement relative to the apex since the apex measured, `δ`.
    pub delta: Vec2<T>,
    /// The change of its own velocity since then, `Δv`.
    pub dv: Vec2<T>,
}

/// S6: the sign of far vertex `k`'s direction, `g_{α,v} = σ J s_uv` and
/// `g_{α,w} = −σ J s_uw`: `σ_k = σ` for `k = 0`, `−σ` for `k = 1`.
#[inline]
pub fn far_sigma<T: Real>(sigma: T, k: usize) -> T {
    if k == 0 {
        sigma
    } else {
        -sigma
    }
}

/// S7: port effort `γ_α = c_α ỹ_α + d_α ẏ_α`.
#[inline]
pub fn port_effort<T: Real>(stiffness: T, damping: T, y_tilde: T, y_dot: T) -> T {
    stiffness * y_tilde + damping * y_dot
}

/// S8: force of one angle on its apex.
#[inline]
pub fn apex_force<T: Real>(gamma: T, g: &[Vec2<T>; 2], r: [T; 2]) -> Vec2<T> {
    g[0] * (gamma / r[0]) + g[1] * (gamma / r[1])
}

/// S9: estimator flow `dr̂/dt = ṙ_e − γ_α t_{α,e} / (c_e r̂_{α,e})`.
///
/// For the `PerAgent` variant (SPEC §6) pass the agent's own share `f^n_{α,e}` as `t`.
#[inline]
pub fn estimator_rate<T: Real>(range_rate: T, gamma: T, t: T, gain: T, r_hat: T) -> T {
    range_rate - gamma * t / (gain * r_hat)
}

/// S10: whether an estimate is on the floor `r_min` (at or below it, or NaN): the one
/// test behind [`estimate_floor`] and [`projected_rate`].
#[inline]
#[allow(clippy::neg_cmp_op_on_partial_ord)] // `!(r̂ > r_min)`: a NaN estimate is on the floor.
pub fn at_floor<T: Real>(r_hat: T, r_min: T) -> bool {
    !(r_hat > r_min)
}

/// S10's floor `max(r_min, r̂)`, a NaN estimate read as `r_min`: the one implementation
/// of the floor (the sampled step [`estimator_step`], `Agent::set_estimate` (feature `sim`) and
/// host-sim's continuous integration use it).
#[inline]
pub fn estimate_floor<T: Real>(r_hat: T, r_min: T) -> T {
    if at_floor(r_hat, r_min) {
        r_min
    } else {
        r_hat
    }
}

/// S10, continuous form: the projected flow (0 instead of a negative flow at `r_min`,
/// [`at_floor`]).
#[inline]
pub fn projected_rate<T: Real>(r_hat: T, rate: T, r_min: T) -> T {
    if at_floor(r_hat, r_min) && rate < T::zero() {
        T::zero()
    } else {
        rate
    }
}

/// S10, sampled form: `r̂ ← max(r_min, r̂ + Δt·S9)` ([`estimate_floor`]).
#[inline]
pub fn estimator_step<T: Real>(r_hat: T, rate: T, dt: T, r_min: T) -> T {
    estimate_floor(r_hat + dt * rate, r_min)
}

/// `PerAgent` share (SPEC §6): `f^n_{α,e} = ±g_{α,e}ᵀ v_n / r̂^n_{α,e}`, `+` for the far
/// vertex of `e`, `−` for the apex.
#[inline]
pub fn own_share<T: Real>(g_e: &Vec2<T>, v_n: &Vec2<T>, r_hat: T, is_far_vertex: bool) -> T {
    let f = g_e.dot(v_n) / r_hat;
    if is_far_vertex {
        f
    } else {
        -f
    }
}

/// Component-wise product with a diagonal matrix `diag(d)`.
#[inline]
pub fn diag_mul<T: Real>(d: &[T; 2], x: &Vec2<T>) -> Vec2<T> {
    Vec2::new(d[0] * x.x, d[1] * x.y)
}

/// S11: leader force on agent `a` with `z = q_a − q_b`: `U^z_a = −k_z z̃ − D_z ż`.
/// Agent `b` receives the negation.
#[inline]
pub fn leader_force<T: Real>(k_z: T, d_z: &[T; 2], z_tilde: &Vec2<T>, z_dot: &Vec2<T>) -> Vec2<T> {
    -(z_tilde * k_z) - diag_mul(d_z, z_dot)
}

/// S11b: the leader force of an edge whose orientation no one controls, on the end whose
/// partner offset is `p` (partner minus self) and relative velocity `ṗ`:
/// `U = (k_z (|p| − |z*|) + d_u u·ṗ) u` with `u = p/|p|` and `d_u = uᵀD_z u` (the
/// gradient and the radial damping of `½ k_z (|z| − |z*|)²`). It is odd in `(p, ṗ)`, so
/// both ends use it as is and their forces are opposite; it reads `p` only through its
/// length and the agent's own bearing `u`, so it needs no common frame (SPEC §7, "Heading
/// disagreement"). Zero at `p = 0`, where `u` is undefined.
#[inline]
pub fn leader_distance_force<T: Real>(
    k_z: T,
    d_z: &[T; 2],
    p: &Vec2<T>,
    z_star_norm: T,
    p_dot: &Vec2<T>,
) -> Vec2<T> {
    let len = geometry::norm(p);
    if len <= T::zero() {
        return Vec2::new(T::zero(), T::zero());
    }
    let u = p / len;
    let d_u = d_z[0] * u.x * u.x + d_z[1] * u.y * u.y;
    u * (k_z * (len - z_star_norm) + d_u * u.dot(p_dot))
}

/// S12: velocity tracking `U^v_n = D^r_n v* − D^v_n (v_n − v*)`.
#[inline]
pub fn velocity_force<T: Real>(
    friction: &[T; 2],
    damping: &[T; 2],
    v: &Vec2<T>,
    v_star: &Vec2<T>,
) -> Vec2<T> {
    diag_mul(friction, v_star) - diag_mul(damping, &(v - v_star))
}

/// Scales `f` down to Euclidean norm `limit` if it is longer (direction kept).
#[inline]
pub fn saturate<T: Real>(f: &Vec2<T>, limit: T) -> (Vec2<T>, bool) {
    let n2 = f.dot(f);
    if n2 > limit * limit {
        (f * (limit / n2.sqrt_fast()), true)
    } else {
        (*f, false)
    }
}
