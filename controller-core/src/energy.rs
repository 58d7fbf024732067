//! The closed-loop Hamiltonian S13 and its dissipation S14, term by term.
//!
//! The controller itself never needs these; simulators and tests use them as the main
//! correctness diagnostic.

use crate::law::diag_mul;
use crate::{Real, Vec2};

/// S13 kinetic term `½ m |v − v*|²`.
#[inline]
pub fn kinetic<T: Real>(mass: T, v: &Vec2<T>, v_star: &Vec2<T>) -> T {
    let e = v - v_star;
    T::lit(0.5) * mass * e.dot(&e)
}

/// S13 angle term `½ c_α ỹ_α²`.
#[inline]
pub fn angle<T: Real>(stiffness: T, y_tilde: T) -> T {
    T::lit(0.5) * stiffness * y_tilde * y_tilde
}

/// S13 leader term `½ k_z |z̃|²`.
#[inline]
pub fn leader<T: Real>(k_z: T, z_tilde: &Vec2<T>) -> T {
    T::lit(0.5) * k_z * z_tilde.dot(z_tilde)
}

/// S13 estimator term `½ c_e (r̂ − r)²`.
#[inline]
pub fn estimate<T: Real>(gain: T, r_hat: T, r: T) -> T {
    let e = r_hat - r;
    T::lit(0.5) * gain * e * e
}

/// S14 agent term `(v − v*)ᵀ (D^r + D^v)(v − v*)` (enters V̇ with a minus sign).
#[inline]
pub fn agent_dissipation<T: Real>(
    friction: &[T; 2],
    damping: &[T; 2],
    v: &Vec2<T>,
    v_star: &Vec2<T>,
) -> T {
    let e = v - v_star;
    let d = [friction[0] + damping[0], friction[1] + damping[1]];
    e.dot(&diag_mul(&d, &e))
}

/// S14 angle term `d_α ẏ_α²`.
#[inline]
pub fn angle_dissipation<T: Real>(damping: T, y_dot: T) -> T {
    damping * y_dot * y_dot
}

/// S14 leader term `żᵀ D_z ż`.
#[inline]
pub fn leader_dissipation<T: Real>(d_z: &[T; 2], z_dot: &Vec2<T>) -> T {
    z_dot.dot(&diag_mul(d_z, z_dot))
}
