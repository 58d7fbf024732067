//! The control law: SPEC S7–S12 as pure functions.

use crate::{Real, Vec2};

/// S7: port effort `γ_α = c_α ỹ_α + d_α ẏ_α`.
#[inline]
pub fn port_effort<T: Real>(stiffness: T, damping: T, y_tilde: T, y_dot: T) -> T {
    stiffness * y_tilde + damping * y_dot
}

/// S8: the forces of one angle on `[u, v, w]` (apex first), given `γ_α`, the directions
/// `g = [g_{α,v}, g_{α,w}]` and the distances `r = [r̂_{α,uv}, r̂_{α,uw}]`. They sum to zero.
#[inline]
pub fn angle_forces<T: Real>(gamma: T, g: &[Vec2<T>; 2], r: [T; 2]) -> [Vec2<T>; 3] {
    let fv = g[0] * (-gamma / r[0]);
    let fw = g[1] * (-gamma / r[1]);
    [-(fv + fw), fv, fw]
}

/// S8: force of one angle on its far vertex `k` (`g_k` = `g_{α,e}` of its edge, `r` = `r̂_{α,e}`).
#[inline]
pub fn far_vertex_force<T: Real>(gamma: T, g_k: &Vec2<T>, r: T) -> Vec2<T> {
    g_k * (-gamma / r)
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

/// S10, continuous form: the projected flow (0 instead of a negative flow at `r_min`).
#[inline]
pub fn projected_rate<T: Real>(r_hat: T, rate: T, r_min: T) -> T {
    if r_hat <= r_min && rate < T::zero() {
        T::zero()
    } else {
        rate
    }
}

/// S10, sampled form: `r̂ ← max(r_min, r̂ + Δt·S9)`.
#[inline]
pub fn estimator_step<T: Real>(r_hat: T, rate: T, dt: T, r_min: T) -> T {
    let next = r_hat + dt * rate;
    if next > r_min {
        next
    } else {
        r_min
    }
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
