//! The bearing tracker of SPEC §11 (S15–S17): one per sensed neighbour, it turns noisy
//! bearings into a smoothed bearing `ŝ` and a bearing rate `ṡ̂` without differentiating
//! the noise.
//!
//! The state is the bearing `ŝ` (a unit vector) and the inverse distance `ρ̂ = 1/r̂` to the
//! neighbour; its error covariance is kept in the tangent coordinates `(δθ, δρ)` as the
//! symmetric 2×2 matrix `[p00, p01; p01, p11]`. The prediction is the exact bearing
//! kinematics (S2, S3) driven by the relative velocity `Δv = v_w − v_u`, which the agent
//! knows (its own velocity, and the neighbour's from its frames); the measurement is the
//! bearing itself. The rate the law uses is S2 with `1/r` replaced by `ρ̂` (S17): it is
//! zero whenever the relative velocity is, whatever the bearing noise.
//!
//! Everything is `no_std`, allocation-free and panic-free; no trigonometry (one square
//! root per update).

use crate::config::TrackerConfig;
use crate::geometry::perp;
use crate::{Real, Vec2};

/// One neighbour's track (S15–S17), besides its bearing `ŝ`, which the agent keeps as
/// the neighbour's bearing (the caller passes it to [`Track::update`]).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Track<T: Real> {
    /// `ρ̂ ≥ 0`, the inverse distance (1/m).
    pub inv_range: T,
    /// Covariance of `(δθ, δρ)`: `[p00, p01, p11]`.
    pub p: [T; 3],
    /// Gated-out bearings in a row that agree with the first of them (S16, S15d).
    pub rejected: u8,
    /// Gated-out bearings in a row, agreeing or not (S15d: the track is lost at
    /// ten (`MAX_MISSED`)).
    pub missed: u8,
    /// The last gated-out bearing of the current run (S15d): the next outlier counts
    /// towards a restart only if it agrees with it.
    pub outlier: Vec2<T>,
    /// Restarts of this track after its first bearing (S15c, S15d): a reset counter, as
    /// a flight estimator publishes one (never decreases; saturates).
    pub resets: u32,
    /// Seconds of the interval since the last bearing that [`Track::predict`] has
    /// already propagated `ŝ`, `ρ̂` and `P` over (SPEC §12, S18): the next
    /// [`Track::update`] predicts over the rest only.
    pub predicted_span: T,
}

/// What the tracker needs besides its configuration: the agent-wide constants.
#[derive(Clone, Copy, Debug)]
pub struct TrackLimits<T: Real> {
    /// `ρ̂(0) = 1/r̂(0)` (the configured initial estimate, SPEC §6).
    pub inv_range_initial: T,
    /// `ρ_max = 1/r_min` (S10's floor).
    pub inv_range_max: T,
    /// The longest interval between two bearings (s) that the track predicts across
    /// (S15c): the agent's neighbour timeout, or its bearing hold if longer. A longer
    /// interval (a stalled task, a jumped clock) restarts the track.
    pub max_interval: T,
}

/// The relative velocity `v_w − v_u` the tracker is driven by (S15, S17).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct RelativeVelocity<T: Real> {
    /// Over the interval since the previous bearing, as known at its start (S15).
    pub over_interval: Vec2<T>,
    /// Now (S17).
    pub now: Vec2<T>,
}

/// Consecutive gated-out bearings that agree with each other after which the track
/// restarts at the last of them (S15d).
const MAX_REJECTED: u8 = 3;

/// Consecutive gated-out bearings, agreeing or not, after which the track is lost and
/// restarts at the last of them (S15d): 0.1 s at 100 Hz, a bounded recovery whatever the
/// bearings do.
const MAX_MISSED: u8 = 10;

impl<T: Real> Track<T> {
    /// Takes bearing `z` (unit) measured `dt` seconds after the previous one, which gave
    /// `s` (`ŝ`, updated in place), with the relative velocity `dv`. Returns `ṡ̂`
    /// (S15–S17). The prediction spans `dt` less what [`Track::predict`] propagated over
    /// since the previous bearing (SPEC §12). The rules of SPEC §11a:
    /// - a negative or non-finite `dt` (the first bearing: the agent passes `−∞`) starts
    ///   the track at `z`;
    /// - S15b: nothing left to predict (`dt` equal to what was predicted, e.g. 0) is a
    ///   measurement update (S16) alone: the inverse distance is kept;
    /// - S15c: a `dt` above [`TrackLimits::max_interval`] restarts the track at `z`;
    /// - S15d: gated-out bearings restart it only when three (`MAX_REJECTED`) of them in a row
    ///   agree (each within the gate of the previous one moved as the prediction moved
    ///   `ŝ`), or after ten (`MAX_MISSED`) in a row whatever they are (the track is lost);
    /// - S15e: the 90° rule of S16 is not applied while the gate admits every sine.
    ///
    /// Restarts after the first bearing count in [`Track::resets`]. Not inlined: the
    /// agent's neighbour loop stays small on the finite-difference path.
    #[inline(never)]
    pub fn update(
        &mut self,
        s: &mut Vec2<T>,
        z: &Vec2<T>,
        dv: &RelativeVelocity<T>,
        dt: T,
        c: &TrackerConfig<T>,
        lim: &TrackLimits<T>,
    ) -> Vec2<T> {
        let r = c.bearing_noise * c.bearing_noise;
        // S15c: across a longer interval the prediction is not trusted (false for NaN).
        if dt > lim.max_interval {
            self.restart(s, z, r, lim);
            return rate(s, self.inv_range, &dv.now);
        }
        // SPEC §12: what `predict` propagated over already is not predicted again.
        let dt = dt - core::mem::take(&mut self.predicted_span);
        let (over_interval, dv) = (&dv.over_interval, &dv.now);
        if !(dt >= T::zero() && dt.finite()) {
            self.start(s, z, r, lim);
            return rate(s, self.inv_range, dv);
        }
        // S15b: with nothing to predict over (dt = 0) S15 is the identity: the update
        // alone.
        let (s_pred, inv_range_pred, [p00, p01, p11]) = self.s15(s, over_interval, dt, c, lim);
        // S16: the bearing as a measurement of the tangent angle, e = (Jŝ)ᵀz ≈ δθ.
        let tp = perp(&s_pred);
        let (e, along) = (tp.dot(z), s_pred.dot(z));
        let sv = p00 + r;
        let gate = c.gate * c.gate * sv;
        // False for a NaN innovation as for an outlier; a bearing more than 90° from the
        // prediction (where `e`, a sine, is small again) is an outlier too (a camera's
        // wrong bearing points anywhere), unless the gate admits every sine (S15e:
        // `g² S ≥ 1`, the track knows its angle no better than ±90°).
        let inside = (along > T::zero() || gate >= T::one()) && e * e <= gate;
        if !inside {
            // An outlier (or a NaN): predict only, unless it agrees with the run (S15d):
            // within the gate of the previous outlier moved as the prediction moved ŝ,
            // for two bearings' noise and the inverse distance's share of the motion.
            let moved = rotate_as(&self.outlier, s, &s_pred);
            let f01 = dt * perp(s).dot(over_interval);
            // The relative velocity changed over the interval by `dv − over_interval`
            // (known now, not when the interval began): the motion it did not predict.
            let late = dt * self.inv_range * perp(s).dot(&(dv - over_interval));
            let gate2 = c.gate * c.gate * (r + r + f01 * f01 * self.p[2]) + late * late;
            if self.rejected > 0 && agree(&moved, z, gate2) {
                self.rejected = self.rejected.saturating_add(1);
            } else {
                self.rejected = 1;
            }
            self.outlier = *z;
            self.missed = self.missed.saturating_add(1);
            if self.rejected >= MAX_REJECTED || self.missed >= MAX_MISSED {
                self.restart(s, z, r, lim);
            } else {
                *s = s_pred;
                self.inv_range = inv_range_pred;
                self.p = [p00, p01, p11];
            }
            return rate(s, self.inv_range, dv);
        }
        self.rejected = 0;
        self.missed = 0;
        let (k0, k1) = (p00 / sv, p01 / sv);
        *s = unit(&(s_pred + tp * (k0 * e)));
        self.inv_range = clamp(inv_range_pred + k1 * e, lim.inv_range_max);
        let one_k0 = T::one() - k0;
        self.p = [one_k0 * p00, one_k0 * p01, p11 - k1 * p01];
        rate(s, self.inv_range, dv)
    }

    /// No bearing this tick, `since` seconds after the last one (SPEC §12, S18): S15
    /// alone (no update) over the part of `since` not yet predicted, `ŝ` (`s`, in place),
    /// `ρ̂` and `P` brought to date. Returns `ṡ̂` (S17). Nothing moves for a `since` not
    /// above what was predicted already (or not finite).
    #[inline(never)]
    pub fn predict(
        &mut self,
        s: &mut Vec2<T>,
        dv: &RelativeVelocity<T>,
        since: T,
        c: &TrackerConfig<T>,
        lim: &TrackLimits<T>,
    ) -> Vec2<T> {
        let dt = since - self.predicted_span;
        if dt > T::zero() && dt.finite() {
            let (s_pred, inv_range_pred, p) = self.s15(s, &dv.over_interval, dt, c, lim);
            *s = s_pred;
            self.inv_range = inv_range_pred;
            self.p = p;
            self.predicted_span = since;
        }
        rate(s, self.inv_range, &dv.now)
    }

    /// S15: the prediction over `dt` along the bearing kinematics (S2, S3) with `ρ̂` for
    /// `1/r`, driven by the relative velocity `over_interval`: `(ŝ⁻, ρ̂⁻, P⁻)`.
    #[inline(always)]
    fn s15(
        &self,
        s: &Vec2<T>,
        over_interval: &Vec2<T>,
        dt: T,
        c: &TrackerConfig<T>,
        lim: &TrackLimits<T>,
    ) -> (Vec2<T>, T, [T; 3]) {
        let t = perp(s);
        let (a, b) = (t.dot(over_interval), s.dot(over_interval));
        let delta = dt * self.inv_range * a;
        let s_pred = unit(&(*s + t * delta));
        let inv_range_pred = clamp(
            self.inv_range - dt * self.inv_range * self.inv_range * b,
            lim.inv_range_max,
        );
        let f01 = dt * a;
        let f11 = T::one() - T::lit(2.0) * dt * self.inv_range * b;
        let [p00, p01, p11] = self.p;
        let p11f = p11 * f01;
        let p00 = p00 + f01 * (p01 + p01 + p11f) + c.rate_noise * c.rate_noise * dt;
        let p01 = f11 * (p01 + p11f);
        let p11 = f11 * f11 * p11 + c.inverse_range_noise * c.inverse_range_noise * dt;
        (s_pred, inv_range_pred, [p00, p01, p11])
    }

    /// (Re)starts the track at bearing `z` with `ρ̂(0)`: variance `R` on the angle, `ρ̂(0)²`
    /// (100 %) on the inverse distance.
    fn start(&mut self, s: &mut Vec2<T>, z: &Vec2<T>, r: T, lim: &TrackLimits<T>) {
        let inv_range = clamp(lim.inv_range_initial, lim.inv_range_max);
        *s = *z;
        *self = Self {
            inv_range,
            p: [r, T::zero(), inv_range * inv_range],
            rejected: 0,
            missed: 0,
            outlier: Vec2::zeros(),
            resets: self.resets,
            predicted_span: T::zero(),
        };
    }

    /// [`Track::start`] after the first bearing (S15c, S15d): counted in
    /// [`Track::resets`].
    #[cold]
    fn restart(&mut self, s: &mut Vec2<T>, z: &Vec2<T>, r: T, lim: &TrackLimits<T>) {
        self.resets = self.resets.saturating_add(1);
        self.start(s, z, r, lim);
    }
}

/// S17: `ṡ̂ = ρ̂ P(ŝ) Δv = ρ̂ ((Jŝ)ᵀΔv) Jŝ` (S2 with `ρ̂` for `1/r`).
#[inline]
pub fn rate<T: Real>(s: &Vec2<T>, inv_range: T, dv: &Vec2<T>) -> Vec2<T> {
    let t = perp(s);
    t * (inv_range * t.dot(dv))
}

/// `a` rotated by the rotation that takes unit `from` to unit `to`.
#[inline]
fn rotate_as<T: Real>(a: &Vec2<T>, from: &Vec2<T>, to: &Vec2<T>) -> Vec2<T> {
    let (cos, sin) = (from.dot(to), perp(from).dot(to));
    Vec2::new(cos * a.x - sin * a.y, sin * a.x + cos * a.y)
}

/// S15d: bearings `a` and `b` (unit) agree: less than 90° apart and the squared sine
/// between them within `gate2`.
#[inline]
fn agree<T: Real>(a: &Vec2<T>, b: &Vec2<T>, gate2: T) -> bool {
    let e = perp(a).dot(b);
    a.dot(b) > T::zero() && e * e <= gate2
}

/// `x / |x|` (the tracker's vectors are never near zero: a unit vector plus a
/// perpendicular part).
#[inline]
fn unit<T: Real>(x: &Vec2<T>) -> Vec2<T> {
    x / x.dot(x).sqrt_fast()
}

/// `ρ` clamped to `[0, ρ_max]` (NaN becomes 0).
#[inline]
fn clamp<T: Real>(inv_range: T, inv_range_max: T) -> T {
    if inv_range > inv_range_max {
        inv_range_max
    } else if inv_range >= T::zero() {
        inv_range
    } else {
        T::zero()
    }
}
