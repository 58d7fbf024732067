//! Sensing: the agent's own measurements of one tick (bearings, rates, ranges, velocity,
//! partner offset), the finite-difference bearing rates of SPEC §2, and the kernels of
//! the angles this agent is the apex of (S4–S8), which depend on nothing else.

use super::state::{AngleState, ApexPart, Neighbour, Side};
use super::{Agent, BearingMeasurement, Fault, MeasurementError, Measurements};
use crate::config::{AgentId, BearingFilter, EstimatorMode, TrackerConfig};
use crate::tracker::{RelativeVelocity, TrackLimits};
use crate::{law, Real, Vec2};

/// Neither NaN nor infinite, in two float operations: `x − x` is 0 exactly for finite `x`
/// and NaN otherwise.
#[inline(always)]
#[allow(clippy::eq_op)] // `x − x` on purpose: NaN for NaN and ±∞.
fn finite<T: Real>(x: T) -> bool {
    x - x == T::zero()
}

impl<T: Real, const MT: usize, const NB: usize> Agent<T, MT, NB> {
    /// Ages the neighbour table by `dt` (when `dt` is finite and ≥ 0, even if the rest is
    /// refused), checks and stores the own measurements (bearings, rates, velocity, time),
    /// and computes the angles this agent is the apex of from them (S4–S8, with the
    /// current estimates). Nothing else changes if they are refused, except that no
    /// angle is sent until the next accepted measurements.
    ///
    /// [`Agent::step`] does the same; simulators that drive [`Agent::evaluate`] themselves
    /// call it first (after [`Agent::set_estimate`], before exchanging frames). Feature
    /// `sim` only (not built for the firmware).
    #[cfg(any(feature = "sim", test))]
    pub fn sense(&mut self, m: &Measurements<'_, T>) -> Result<(), Fault> {
        self.sense_own(m)?;
        let (mode, v) = (self.config.estimator, self.velocity);
        let nbs = self.neighbours.as_slice();
        for a in self.angles.as_mut_slice().as_flattened_mut() {
            sense_angle(nbs, mode, &v, a, m.dt);
        }
        Ok(())
    }

    /// [`Agent::sense`] up to the angles: checks and stores the own measurements, ages and
    /// updates the neighbour table. On refused measurements it also marks every angle
    /// of which this agent is the apex with the fault and ages the others (what
    /// [`sense_angle`] would have done), and nothing else changes.
    #[inline(always)]
    pub(super) fn sense_own(&mut self, m: &Measurements<'_, T>) -> Result<(), Fault> {
        let dt = m.dt;
        if !(finite(dt) && dt >= T::zero()) {
            return Err(Fault::Measurement(bad_dt(dt)));
        }
        // The checks read nothing that aging changes: age after them.
        let in_order = match self.check_measurements(m) {
            Ok(in_order) => in_order,
            Err(e) => {
                for n in self.neighbours.iter_mut() {
                    n.age += dt;
                    n.bearing_age += dt;
                }
                let fault = Fault::Measurement(e);
                for a in self.angles.as_mut_slice().as_flattened_mut() {
                    match &mut a.side {
                        Side::Apex { fault: f, .. } => *f = Some(fault),
                        Side::Far { age, .. } => *age += dt,
                    }
                }
                return Err(fault);
            }
        };
        self.time = m.time;
        let v_before = core::mem::replace(&mut self.velocity, m.velocity);
        self.partner_offset = m.partner_offset;
        // The tracker's inputs, only when it runs (no divisions on the finite-difference
        // path).
        let tracking = match &self.config.bearing_filter {
            BearingFilter::Tracker(c) => Some(Tracking {
                c,
                v: m.velocity,
                v_before,
                limits: TrackLimits {
                    inv_range_initial: T::one() / self.config.initial_estimate,
                    inv_range_max: T::one() / self.config.min_estimate,
                    // S15c: the neighbour timeout, or the hold if longer (a held bearing
                    // is predicted across the hold by design, S18).
                    max_interval: larger(
                        self.config.limits.neighbour_timeout,
                        self.config.limits.bearing_hold,
                    ),
                },
            }),
            BearingFilter::FiniteDifference => None,
        };
        let how = tracking.as_ref();
        // The oldest neighbour (ages are never NaN: ∞ + a finite dt ≥ 0, or 0 when heard).
        let mut oldest = T::zero();
        if in_order {
            // Bearing i is to slot i: one pass.
            let mut bearings = m.bearings.iter();
            for n in self.neighbours.iter_mut() {
                n.age += dt;
                if n.age > oldest {
                    oldest = n.age;
                }
                match bearings.next() {
                    Some(b) => take_bearing(n, b, dt, how),
                    None => no_bearing(n, dt),
                }
            }
        } else {
            for n in self.neighbours.iter_mut() {
                n.age += dt;
                if n.age > oldest {
                    oldest = n.age;
                }
                match bearing_to(m.bearings, n.id) {
                    Some(b) => take_bearing(n, b, dt, how),
                    None => no_bearing(n, dt),
                }
            }
        }
        self.oldest = Some(oldest);
        // The bearings are to distinct neighbours (checked): fewer than the neighbours
        // means some are missing, and only then does the hold run (SPEC §12, S18).
        if m.bearings.len() < self.neighbours.len() {
            hold_missing(
                self.neighbours.as_mut_slice(),
                dt,
                self.config.limits.bearing_hold,
                how,
            );
        }
        Ok(())
    }

    /// Checks the own measurements. Returns whether bearing `i` is to neighbour slot `i`
    /// for every `i` (the usual case, what the firmware sends).
    fn check_measurements(&self, m: &Measurements<'_, T>) -> Result<bool, MeasurementError> {
        let v = &m.velocity;
        // `x − x` is 0 for finite `x`, NaN otherwise: one comparison for the sum.
        let p = m.partner_offset.unwrap_or_default();
        #[allow(clippy::eq_op)]
        let all = (m.time - m.time) + (v.x - v.x) + (v.y - v.y) + (p.x - p.x) + (p.y - p.y);
        if all != T::zero() {
            return Err(MeasurementError::NonFinite);
        }
        let tol = self.config.limits.bearing_tolerance;
        // Bearing i to slot i: known and distinct without searching (neighbour ids are
        // unique), and all valid.
        if m.bearings.len() <= self.neighbours.len()
            && m.bearings
                .iter()
                .zip(&self.neighbours)
                .all(|(b, n)| b.neighbour == n.id && bearing_error(b, tol).is_none())
        {
            return Ok(true);
        }
        self.check_bearings_in_order(m.bearings, tol)
    }

    /// The bearing checks in general (any order): the first error in order, or whether
    /// bearing `i` is to slot `i` for every `i`.
    #[cold]
    #[inline(never)]
    fn check_bearings_in_order(
        &self,
        bearings: &[BearingMeasurement<T>],
        tol: T,
    ) -> Result<bool, MeasurementError> {
        let mut in_order = true;
        let mut slots = self.neighbours.iter();
        for (i, b) in bearings.iter().enumerate() {
            let id = b.neighbour;
            in_order = in_order && slots.next().is_some_and(|n| n.id == id);
            if !in_order {
                if self.slot(id).is_none() {
                    return Err(MeasurementError::UnknownNeighbour(id));
                }
                if bearings.iter().take(i).any(|o| o.neighbour == id) {
                    return Err(MeasurementError::DuplicateBearing(id));
                }
            }
            if let Some(e) = bearing_error(b, tol) {
                return Err(e);
            }
        }
        Ok(in_order)
    }
}

/// The larger of `a` and `b` (`a` when they are not ordered).
#[inline(always)]
fn larger<T: Real>(a: T, b: T) -> T {
    if b > a {
        b
    } else {
        a
    }
}

/// Why a `dt` that is not finite and non-negative was refused.
#[cold]
#[inline(never)]
fn bad_dt<T: Real>(dt: T) -> MeasurementError {
    if finite(dt) {
        MeasurementError::NegativeDt
    } else {
        MeasurementError::NonFinite
    }
}

/// One angle's part of [`Agent::sense`] after the own measurements were taken: the apex
/// computes its kernel ([`apex_part`]) and keeps it, or the fault, for the law; a far
/// vertex ages what it last received by `dt`.
#[inline(always)]
pub(super) fn sense_angle<T: Real, const MT: usize>(
    nbs: &[Neighbour<T, MT>],
    mode: EstimatorMode,
    v: &Vec2<T>,
    a: &mut AngleState<T>,
    dt: T,
) {
    let computed = match a.side {
        Side::Apex { .. } => Some(apex_part(nbs, mode, a, v)),
        Side::Far { .. } => None,
    };
    match (&mut a.side, computed) {
        (Side::Apex { part, fault }, Some(result)) => match result {
            Ok(p) => {
                *part = p;
                *fault = None;
            }
            Err(f) => *fault = Some(f),
        },
        (Side::Far { age, .. }, _) => *age += dt,
        (Side::Apex { .. }, None) => {}
    }
}

/// The kernel of an angle this agent is the apex of (S4–S8, [`law::apex_angle`]) from its
/// fresh bearings and rates to both far vertices and its distances to them (own estimates,
/// or measured ranges), with the motion shares its estimators need (S9) and what the far
/// vertices need (`γ`, `σ`, the distances).
#[inline]
fn apex_part<T: Real, const MT: usize>(
    nbs: &[Neighbour<T, MT>],
    mode: EstimatorMode,
    a: &AngleState<T>,
    v: &Vec2<T>,
) -> Result<ApexPart<T>, Fault> {
    let (Some(nv), Some(nw)) = (nbs.get(a.slots[1]), nbs.get(a.slots[2])) else {
        return Err(Fault::Internal);
    };
    // S19: both bearings measured or held (S18), else the angle cannot be formed.
    if !(nv.fresh && nw.fresh) {
        let missing = if nv.fresh { nw.id } else { nv.id };
        return Err(Fault::MissingBearing(missing));
    }
    let r = match (mode, nv.range, nw.range) {
        (EstimatorMode::Measured, Some(rv), Some(rw)) => [rv, rw],
        (EstimatorMode::Measured, None, _) => return Err(Fault::MissingRange(nv.id)),
        (EstimatorMode::Measured, _, None) => return Err(Fault::MissingRange(nw.id)),
        (EstimatorMode::Shared | EstimatorMode::PerAgent, ..) => a.estimate,
    };
    let (s_v, d_v, s_w, d_w) = (nv.s, nv.rate, nw.s, nw.rate);
    let k = law::apex_angle(
        &[s_v, s_w],
        &[d_v, d_w],
        a.cos_desired,
        a.stiffness,
        a.damping,
        r,
    );
    // γ is finite whenever the measurements are (they were checked) unless a rate
    // overflowed; σ and the distances are finite. Only finite values are sent.
    if !finite(k.gamma) {
        return Err(Fault::NonFinite);
    }
    let share = match mode {
        // S9 with the angle's own shares t_{α,e} (S5).
        EstimatorMode::Shared => k.t,
        // SPEC §6: the apex's own shares f^u_{α,e} = −g_{α,e}ᵀ v_u / r̂^u_{α,e} (unused in
        // measured mode, which has no estimator).
        EstimatorMode::PerAgent | EstimatorMode::Measured => [
            law::own_share(&k.g[0], v, r[0], false),
            law::own_share(&k.g[1], v, r[1], false),
        ],
    };
    Ok(ApexPart {
        y: k.y,
        gamma: k.gamma,
        share,
        force: k.force,
        sigma: k.sigma,
        range: r,
    })
}

/// What is wrong with one bearing measurement itself, if anything (neighbour aside).
#[inline(always)]
fn bearing_error<T: Real>(b: &BearingMeasurement<T>, tol: T) -> Option<MeasurementError> {
    // A unit vector within a finite tolerance is finite (NaN and ∞ fail the comparison):
    // no separate finiteness check.
    let s = &b.bearing;
    let unit = (s.dot(s) - T::one()).abs() <= tol;
    #[allow(clippy::eq_op)]
    let rate_ok = b
        .rate
        .as_ref()
        .is_none_or(|r| (r.x - r.x) + (r.y - r.y) == T::zero());
    if !unit || !rate_ok {
        return Some(MeasurementError::BadBearing(b.neighbour));
    }
    match b.range {
        Some(r) if !(finite(r) && r > T::zero()) => Some(MeasurementError::BadRange(b.neighbour)),
        _ => None,
    }
}

/// The bearing to neighbour `id`, if any.
#[inline(never)]
fn bearing_to<T: Real>(
    bearings: &[BearingMeasurement<T>],
    id: AgentId,
) -> Option<&BearingMeasurement<T>> {
    bearings.iter().find(|b| b.neighbour == id)
}

/// What [`take_bearing`] needs of the agent to run the bearing tracker: its settings, its
/// own velocity of this tick and of the last, and the tracker's limits.
struct Tracking<'a, T: Real> {
    c: &'a TrackerConfig<T>,
    v: Vec2<T>,
    v_before: Vec2<T>,
    limits: TrackLimits<T>,
}

/// Stores a checked bearing of this tick and its rate (`dt`: time since the last tick);
/// `tracking` when the agent runs the bearing tracker.
#[inline(always)]
fn take_bearing<T: Real, const MT: usize>(
    n: &mut Neighbour<T, MT>,
    b: &BearingMeasurement<T>,
    dt: T,
    tracking: Option<&Tracking<'_, T>>,
) {
    let interval = n.bearing_age + dt;
    let (s, rate) = match (b.rate, tracking) {
        (Some(rate), _) => (b.bearing, rate),
        // Finite difference of successive bearings (SPEC §2), over the time since the
        // previous bearing (a missed tick widens the interval). Without a previous
        // bearing the interval is −∞: zero rate.
        (None, None) if interval > T::zero() => (b.bearing, (b.bearing - n.s) / interval),
        (None, None) => (b.bearing, Vec2::zeros()),
        // SPEC §11: the tracker, driven by the relative velocity Δv = v_w − v_u (the
        // neighbour's from its last frame, sent at about the last tick): the motion since
        // the last tick with the own velocity then, the rate with the own velocity now.
        (None, Some(t)) => {
            let dv = RelativeVelocity {
                over_interval: n.velocity - t.v_before,
                now: n.velocity - t.v,
            };
            let mut s = n.s;
            let rate = n
                .track
                .update(&mut s, &b.bearing, &dv, interval, t.c, &t.limits);
            (s, rate)
        }
    };
    n.rate = rate;
    n.s = s;
    n.bearing_age = T::zero();
    n.range = b.range;
    n.fresh = true;
}

/// No bearing to this neighbour this tick: it ages ([`hold_missing`] decides then
/// whether it is held).
#[inline(always)]
fn no_bearing<T: Real, const MT: usize>(n: &mut Neighbour<T, MT>, dt: T) {
    n.bearing_age += dt;
    n.fresh = false;
}

/// The neighbours without a bearing this tick (SPEC §12). S18: the last one is still
/// used while it is younger than the hold `T_h` ([`crate::Limits::bearing_hold`]; never
/// for a neighbour not yet measured, whose age is −∞): with the finite difference the
/// bearing, its rate and its range are held as they were; with the tracker `ŝ` and `ρ̂`
/// are predicted (S15 without S16) and the rate is S17 on the prediction; the range is
/// held. Past the hold it is missing (S19: the angles that need it cannot be formed).
/// Out of the neighbour loop's way: a bearing is rarely missing.
#[cold]
#[inline(never)]
fn hold_missing<T: Real, const MT: usize>(
    neighbours: &mut [Neighbour<T, MT>],
    dt: T,
    hold: T,
    tracking: Option<&Tracking<'_, T>>,
) {
    for n in neighbours.iter_mut().filter(|n| !n.fresh) {
        let since = n.bearing_age;
        // S18: 0 ≤ τ < T_h (false for −∞, "never").
        n.fresh = since >= T::zero() && since < hold;
        if !n.fresh {
            n.range = None;
            continue;
        }
        if let Some(t) = tracking {
            if since - dt <= T::zero() {
                // The first tick of the gap (the bearing was measured at the last one):
                // nothing of an earlier gap is left to subtract (a bearing with a
                // measured rate bypasses the tracker's update, which clears it).
                n.track.predicted_span = T::zero();
            }
            // The same relative velocities as `take_bearing` gives the tracker (SPEC §11).
            let dv = RelativeVelocity {
                over_interval: n.velocity - t.v_before,
                now: n.velocity - t.v,
            };
            n.rate = n.track.predict(&mut n.s, &dv, since, t.c, &t.limits);
        }
    }
}
