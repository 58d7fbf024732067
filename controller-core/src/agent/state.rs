//! The agent's internal state: one entry per controlled angle it takes part in, and one per
//! neighbour (what it measured of it and last heard from it).

use super::Fault;
use crate::config::AgentId;
use crate::{Real, Vec2};

/// No neighbour slot (the vertex is this agent itself).
pub(super) const SELF_SLOT: usize = usize::MAX;

/// This agent's place in a controlled angle, with what it keeps for that place.
#[derive(Clone, Copy, Debug)]
pub(super) enum Side<T: Real> {
    /// The apex `u`: measures both bearings, computes the angle (S4–S8), owns the
    /// estimates.
    Apex {
        /// The result of the last sense (valid when `fault` is `None`).
        part: ApexPart<T>,
        /// Why the last sense could not compute the angle.
        fault: Option<Fault>,
    },
    /// Far vertex `far[k]`: receives what the apex sends of the angle.
    Far {
        /// Which far vertex (0 or 1).
        k: usize,
        /// What the apex last sent.
        remote: Remote<T>,
        /// Seconds since it arrived (`∞` before the first).
        age: T,
    },
}

/// What the apex of an angle computed from its own measurements at the last sense
/// (S4–S8, see [`crate::law::apex_angle`]), and what its estimators and far vertices need.
#[derive(Clone, Copy, Debug, Default)]
pub(super) struct ApexPart<T: Real> {
    /// `y_α` (S4), for the degeneracy check.
    pub y: T,
    /// `γ_α` (S7).
    pub gamma: T,
    /// The motion share of each edge in S9: `t_{α,e}` (S5) in shared mode, the apex's own
    /// share `f^u_{α,e}` in per-agent mode.
    pub share: [T; 2],
    /// S8 on the apex.
    pub force: Vec2<T>,
    /// `σ_α = s_uv × s_uw` (for the far vertices).
    pub sigma: T,
    /// The distances used in S8 (estimates or ranges), sent to the far vertices.
    pub range: [T; 2],
}

/// What a far vertex last received of an angle from its apex.
#[derive(Clone, Copy, Debug, Default)]
pub(super) struct Remote<T: Real> {
    /// `γ_α` (S7) as the apex computed it.
    pub gamma: T,
    /// `σ_k = ±σ_α` for this far vertex ([`crate::law::far_sigma`], applied on receipt).
    pub sigma: T,
    /// The apex's distance to this agent (`r_k`).
    pub range: T,
    /// Own velocity when it arrived (the last one sensed before: about when the apex
    /// measured).
    pub v_ref: Vec2<T>,
}

/// One controlled angle `α = (apex; far[0], far[1])` this agent belongs to.
#[derive(Clone, Copy, Debug)]
pub(super) struct AngleState<T: Real> {
    pub apex: AgentId,
    pub far: [AgentId; 2],
    pub side: Side<T>,
    /// Neighbour slots of `[apex, far0, far1]` (`SELF_SLOT` for this agent).
    pub slots: [usize; 3],
    pub cos_desired: T,
    pub stiffness: T,
    pub damping: T,
    pub estimator_gain: T,
    /// Own estimates for edges `[apex–far0, apex–far1]` (only the owned ones are used).
    pub estimate: [T; 2],
    /// Scratch of the law: the S9 flows of `estimate` ([`crate::Agent::evaluate`]), or the
    /// estimates before the step's integration ([`crate::Agent::step`], to roll back).
    pub flow: [T; 2],
}

/// An angle of which a neighbour is the apex and this agent a far vertex.
#[derive(Clone, Copy, Debug)]
pub(super) struct ApexOf {
    /// The angle's other far vertex (how the neighbour's items name it, with this agent).
    pub other: AgentId,
    /// Flat index `2·triangle + angle` of the angle.
    pub flat: u16,
}

/// One neighbour: a triangle neighbour or the leader partner.
#[derive(Clone, Debug)]
pub(super) struct Neighbour<T: Real, const MT: usize> {
    pub id: AgentId,
    /// The angles whose apex is this neighbour and of which this agent is a far vertex:
    /// where its angle items go.
    pub apex_of: heapless::Vec<ApexOf, MT>,
    /// Seconds since a frame was last accepted from it (`∞` before the first).
    pub age: T,
    pub last_seq: Option<u16>,
    /// `auth`: the counter of the last frame accepted from it (see [`crate::wire::auth`]).
    pub last_counter: Option<crate::wire::auth::StoredCounter>,
    /// The velocity it last broadcast (zero before its first frame). Every accepted frame
    /// carries one, and the law reads it only after `check_fresh` passed (every neighbour
    /// heard within the timeout): no `Option` to test at each use.
    pub velocity: Vec2<T>,
    /// The last bearing `s` to it (zero before the first).
    pub s: Vec2<T>,
    /// The bearing rate `ṡ` that goes with `s`.
    pub rate: Vec2<T>,
    /// Seconds since a bearing to it was last measured (the finite-difference interval,
    /// and `τ` of the hold, SPEC §12); −∞ while there is none.
    pub bearing_age: T,
    /// The range measured with the bearing (held with it, S18).
    pub range: Option<T>,
    /// `s` and `rate` can be used this tick: measured, or held or predicted within the
    /// bearing hold (S18).
    pub fresh: bool,
    /// The bearing tracker of this neighbour (SPEC §11; unused with the finite difference).
    pub track: crate::tracker::Track<T>,
}

impl<T: Real, const MT: usize> Neighbour<T, MT> {
    pub(super) fn new(id: AgentId) -> Self {
        Self {
            id,
            apex_of: heapless::Vec::new(),
            // Never heard: infinitely old (so `age <= timeout` alone means heard recently).
            age: T::lit(f64::INFINITY),
            last_seq: None,
            last_counter: None,
            velocity: Vec2::zeros(),
            s: Vec2::zeros(),
            rate: Vec2::zeros(),
            bearing_age: T::lit(f64::NEG_INFINITY),
            range: None,
            fresh: false,
            track: crate::tracker::Track::default(),
        }
    }

    /// The bearing and rate of this tick (measured, held or predicted: S18), or
    /// [`Fault::MissingBearing`].
    #[inline]
    pub(super) fn bearing(&self) -> Result<(Vec2<T>, Vec2<T>), Fault> {
        if self.fresh {
            Ok((self.s, self.rate))
        } else {
            Err(Fault::MissingBearing(self.id))
        }
    }

    /// This tick's range measurement, or [`Fault::MissingRange`].
    #[inline]
    pub(super) fn range(&self) -> Result<T, Fault> {
        self.range.ok_or(Fault::MissingRange(self.id))
    }
}
