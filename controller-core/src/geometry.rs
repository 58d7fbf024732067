//! Bearing geometry: SPEC S2–S6 as pure functions.
//!
//! Notation: an angle `α = (u; v, w)` has apex `u` and far vertices `v`, `w`. Index 0 of
//! the arrays below is the edge `uv`, index 1 the edge `uw`.

use crate::{Real, Vec2};

/// `P(s) x = x − s (sᵀx)`: projection orthogonal to the unit vector `s` (SPEC §2).
#[inline]
pub fn project<T: Real>(s: &Vec2<T>, x: &Vec2<T>) -> Vec2<T> {
    x - s * s.dot(x)
}

/// `J x`: `x` rotated by +90° (`J = [[0, −1], [1, 0]]`). For a unit `s`, `P(s) = (Js)(Js)ᵀ`
/// in the plane, so `P(s) x = ((Js)·x) Js` (SPEC §2).
#[inline]
pub fn perp<T: Real>(x: &Vec2<T>) -> Vec2<T> {
    Vec2::new(-x.y, x.x)
}

/// `a × b = (Ja)·b = a_x b_y − a_y b_x`: for the apex bearings of an angle,
/// `σ = s_uv × s_uw = sin α` (signed), and `g_{α,v} = σ J s_uv`, `g_{α,w} = −σ J s_uw` (S6).
#[inline]
pub fn cross<T: Real>(a: &Vec2<T>, b: &Vec2<T>) -> T {
    a.x * b.y - a.y * b.x
}

/// Euclidean norm through [`Real::sqrt_fast`] (hardware square root on target).
#[inline]
pub fn norm<T: Real>(x: &Vec2<T>) -> T {
    x.dot(x).sqrt_fast()
}

/// S2: bearing rate `ṡ_uw = P(s_uw)(v_w − v_u) / r_uw` (needs the true distance: used by
/// simulators to produce exact rates, never by the controller).
#[inline]
pub fn bearing_rate<T: Real>(s: &Vec2<T>, relative_velocity: &Vec2<T>, r: T) -> Vec2<T> {
    project(s, relative_velocity) / r
}

/// S3: range rate `ṙ_uw = s_uwᵀ (v_w − v_u)`.
#[inline]
pub fn range_rate<T: Real>(s: &Vec2<T>, relative_velocity: &Vec2<T>) -> T {
    s.dot(relative_velocity)
}

/// S4: `y_α = cos α = s_uvᵀ s_uw`.
#[inline]
pub fn cosine<T: Real>(s: &[Vec2<T>; 2]) -> T {
    s[0].dot(&s[1])
}

/// S5: the two shares `t_{α,uv} = s_uwᵀ ṡ_uv` and `t_{α,uw} = s_uvᵀ ṡ_uw` of `ẏ_α`.
#[inline]
pub fn cosine_rate_shares<T: Real>(s: &[Vec2<T>; 2], s_dot: &[Vec2<T>; 2]) -> [T; 2] {
    [s[1].dot(&s_dot[0]), s[0].dot(&s_dot[1])]
}

/// S6: `g_{α,v} = P(s_uv) s_uw` and `g_{α,w} = P(s_uw) s_uv`, as `σ J s_uv` and
/// `−σ J s_uw` with `σ = s_uv × s_uw` (for unit `s`, `P(s) x = (J s)(J s)ᵀ x` and
/// `(J s_uv)ᵀ s_uw = σ = −(J s_uw)ᵀ s_uv`: the same vectors in four multiplications).
#[inline]
pub fn jacobian_directions<T: Real>(s: &[Vec2<T>; 2]) -> [Vec2<T>; 2] {
    directions_of(s, cross(&s[0], &s[1]))
}

/// [`jacobian_directions`] with `σ = s_uv × s_uw` already known.
#[inline]
fn directions_of<T: Real>(s: &[Vec2<T>; 2], sigma: T) -> [Vec2<T>; 2] {
    [perp(&s[0]) * sigma, perp(&s[1]) * -sigma]
}

/// Everything S4–S6 give for one angle, from its apex's two bearings and their rates.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct AngleGeometry<T: Real> {
    /// S4: `y_α = cos α`.
    pub y: T,
    /// S5: `ẏ_α = t[0] + t[1]`.
    pub y_dot: T,
    /// S5: the shares `t_{α,uv}`, `t_{α,uw}`.
    pub t: [T; 2],
    /// S6: `g_{α,v}`, `g_{α,w}`.
    pub g: [Vec2<T>; 2],
    /// `σ = s_uv × s_uw = sin α` (signed): `g_{α,v} = σ J s_uv`, `g_{α,w} = −σ J s_uw`.
    pub sigma: T,
}

impl<T: Real> AngleGeometry<T> {
    /// Evaluates S4–S6 from the apex bearings `s = [s_uv, s_uw]` and rates `s_dot`.
    #[inline]
    pub fn new(s: &[Vec2<T>; 2], s_dot: &[Vec2<T>; 2]) -> Self {
        let t = cosine_rate_shares(s, s_dot);
        let sigma = cross(&s[0], &s[1]);
        Self {
            y: cosine(s),
            y_dot: t[0] + t[1],
            t,
            g: directions_of(s, sigma),
            sigma,
        }
    }
}

/// S6, exact: `[∂y/∂q_u, ∂y/∂q_v, ∂y/∂q_w]` (as column vectors) for distances `r = [r_uv, r_uw]`.
#[inline]
pub fn angle_jacobian<T: Real>(s: &[Vec2<T>; 2], r: [T; 2]) -> [Vec2<T>; 3] {
    let g = jacobian_directions(s);
    let dv = g[0] / r[0];
    let dw = g[1] / r[1];
    [-(dv + dw), dv, dw]
}
