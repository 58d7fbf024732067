//! The agent's internal state: one entry per controlled angle it takes part in, and one per
//! neighbour (what it measured of it and last heard from it).

use super::Fault;
use crate::config::AgentId;
use crate::{Real, Vec2};
use core::cell::Cell;

/// No neighbour slot (the vertex is this agent itself).
pub(super) const SELF_SLOT: usize = usize::MAX;

/// This agent's place in a controlled angle.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum Role {
    /// The apex `u`: measures both bearings, computes the angle (S4–S8), owns the estimates.
    Apex,
    /// Far vertex `far[k]`: receives the apex's effort for its edge.
    Far(usize),
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
    pub rho: [T; 2],
}

/// What a far vertex last received of an angle from its apex, and its own motion since.
#[derive(Clone, Copy, Debug, Default)]
pub(super) struct Remote<T: Real> {
    /// `γ_α` (S7) as the apex computed it.
    pub gamma: T,
    /// `σ_α`.
    pub sigma: T,
    /// The apex's distance to this agent (`ρ_k`).
    pub rho: T,
    /// Own displacement relative to the apex since the apex measured.
    pub delta: Vec2<T>,
    /// Own velocity when the apex measured (`None` until the first sense after receipt:
    /// then no correction).
    pub v_ref: Option<Vec2<T>>,
}

/// One controlled angle `α = (apex; far[0], far[1])` this agent belongs to.
#[derive(Clone, Debug)]
pub(super) struct AngleState<T: Real> {
    pub apex: AgentId,
    pub far: [AgentId; 2],
    pub role: Role,
    /// Neighbour slots of `[apex, far0, far1]` (`SELF_SLOT` for this agent).
    pub slots: [usize; 3],
    pub cos_desired: T,
    pub stiffness: T,
    pub damping: T,
    pub estimator_gain: T,
    /// Own estimates for edges `[apex–far0, apex–far1]` (only the owned ones are used).
    pub estimate: [T; 2],
    /// The S9 flows (with the S10 projection) of `estimate` found by the last evaluation
    /// of the law (zero where not owned): written by the read-only law, read by the
    /// integration that follows it.
    pub rate: Cell<[T; 2]>,
    /// Apex: the result of the last sense (valid when `fault` is `None`).
    pub part: ApexPart<T>,
    /// Apex: why the last sense could not compute the angle.
    pub fault: Option<Fault>,
    /// Far vertex: what the apex last sent of this angle.
    pub remote: Remote<T>,
    /// Far vertex: seconds since it arrived (`∞` before the first).
    pub remote_age: T,
}

/// One neighbour: a triangle neighbour or the leader partner.
#[derive(Clone, Debug)]
pub(super) struct Neighbour<T: Real, const MT: usize> {
    pub id: AgentId,
    /// Angles (flat index `2·triangle + angle`) whose apex is this neighbour and of which
    /// this agent is a far vertex: where its angle items go.
    pub apex_of: heapless::Vec<u16, MT>,
    /// Seconds since a frame was last accepted from it (`∞` before the first).
    pub age: T,
    pub last_seq: Option<u16>,
    pub velocity: Option<Vec2<T>>,
    /// The last bearing `s` to it (zero before the first).
    pub s: Vec2<T>,
    /// The bearing rate `ṡ` that goes with `s`.
    pub rate: Vec2<T>,
    /// Seconds since `s` was measured (finite-difference interval); −∞ while there is none.
    pub bearing_age: T,
    pub range: Option<T>,
    /// `s` was measured this tick.
    pub fresh: bool,
}

impl<T: Real, const MT: usize> Neighbour<T, MT> {
    pub(super) fn new(id: AgentId) -> Self {
        Self {
            id,
            apex_of: heapless::Vec::new(),
            // Never heard: infinitely old (so `age <= timeout` alone means heard recently).
            age: T::lit(f64::INFINITY),
            last_seq: None,
            velocity: None,
            s: Vec2::zeros(),
            rate: Vec2::zeros(),
            bearing_age: T::lit(f64::NEG_INFINITY),
            range: None,
            fresh: false,
        }
    }

    /// The fresh bearing and rate, or [`Fault::MissingBearing`].
    #[inline]
    pub(super) fn bearing(&self) -> Result<(Vec2<T>, Vec2<T>), Fault> {
        if self.fresh {
            Ok((self.s, self.rate))
        } else {
            Err(Fault::MissingBearing(self.id))
        }
    }

    /// The last velocity it broadcast, or [`Fault::MissingData`].
    #[inline]
    pub(super) fn velocity(&self) -> Result<Vec2<T>, Fault> {
        self.velocity.ok_or(Fault::MissingData(self.id))
    }

    /// This tick's range measurement, or [`Fault::MissingRange`].
    #[inline]
    pub(super) fn range(&self) -> Result<T, Fault> {
        self.range.ok_or(Fault::MissingRange(self.id))
    }
}
