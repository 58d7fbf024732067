//! The public types of one control tick: what the agent measures, what it outputs, and
//! why an output is the safe one.

use crate::config::AgentId;
use crate::{Real, Vec2};
use serde::{Deserialize, Serialize};

/// One bearing measured by this agent.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BearingMeasurement<T: Real> {
    /// The neighbour it points to.
    pub neighbour: AgentId,
    /// Unit bearing `s_{n,neighbour}` in the shared world frame (S2).
    pub bearing: Vec2<T>,
    /// Measured bearing rate `ṡ`, if the sensor gives one. Without it the agent uses the
    /// finite difference of successive bearings (zero on the first step).
    pub rate: Option<Vec2<T>>,
    /// Measured distance, for [`EstimatorMode::Measured`](crate::EstimatorMode::Measured).
    pub range: Option<T>,
}

/// What one agent's own sensors give it at one control tick.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Measurements<'a, T: Real> {
    /// Time in seconds (for the `v*`, `z*` schedules).
    pub time: T,
    /// Seconds since the previous step (the estimator's `Δt`, finite differences and
    /// neighbour ages). Zero is allowed (no time passes); a negative one is refused
    /// ([`MeasurementError::NegativeDt`]).
    pub dt: T,
    /// Own velocity `v_n` (world frame).
    pub velocity: Vec2<T>,
    /// Bearings to the neighbours (every triangle neighbour, every tick; one missing is
    /// held or predicted for up to [`Limits::bearing_hold`](crate::Limits::bearing_hold),
    /// SPEC §12).
    pub bearings: &'a [BearingMeasurement<T>],
    /// Leaders only: the partner's position minus this agent's (relative-position sensor).
    pub partner_offset: Option<Vec2<T>>,
}

/// A measurement the agent refused.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum MeasurementError {
    /// Time, `Δt`, velocity or partner offset is NaN or infinite.
    NonFinite,
    /// `Δt` is finite but negative (time ran backwards).
    NegativeDt,
    /// The bearing to this neighbour is not a finite unit vector (or its rate is not finite).
    BadBearing(AgentId),
    /// The bearing's neighbour is not a neighbour of this agent.
    UnknownNeighbour(AgentId),
    /// Two bearings to the same neighbour.
    DuplicateBearing(AgentId),
    /// A range that is not finite and positive.
    BadRange(AgentId),
}

/// Why a step produced the safe output instead of the control law.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Fault {
    /// The measurements were refused.
    Measurement(MeasurementError),
    /// No bearing to this triangle neighbour this tick, nor one measured less than
    /// [`Limits::bearing_hold`](crate::Limits::bearing_hold) ago (SPEC §12, S19).
    MissingBearing(AgentId),
    /// Nothing heard from this neighbour for longer than the timeout (or ever).
    Stale(AgentId),
    /// This neighbour's frames lacked something the step needs: as the apex of an angle
    /// this agent is a far vertex of, the angle's effort, or that effort is older than the
    /// neighbour timeout. (A neighbour never heard is [`Fault::Stale`] first, and every
    /// frame carries the sender's velocity.)
    MissingData(AgentId),
    /// A leader without the partner's relative position.
    MissingPartnerOffset,
    /// [`EstimatorMode::Measured`](crate::EstimatorMode::Measured) without a range to this neighbour.
    MissingRange(AgentId),
    /// The computed force was not finite.
    NonFinite,
    /// An internal inconsistency that the construction of [`crate::Agent`] rules out (a
    /// neighbour slot that does not exist). Reported instead of panicking; never seen.
    Internal,
}

impl core::fmt::Display for MeasurementError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        match self {
            Self::NonFinite => write!(f, "time, dt, velocity or partner offset is not finite"),
            Self::NegativeDt => write!(f, "dt is negative"),
            Self::BadBearing(id) => write!(
                f,
                "bearing to agent {id} is not a finite unit vector (or its rate is not finite)"
            ),
            Self::UnknownNeighbour(id) => {
                write!(f, "bearing to agent {id}, which is not a neighbour")
            }
            Self::DuplicateBearing(id) => write!(f, "two bearings to agent {id}"),
            Self::BadRange(id) => write!(f, "range to agent {id} is not finite and positive"),
        }
    }
}

impl core::fmt::Display for Fault {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        match self {
            Self::Measurement(e) => write!(f, "measurement refused: {e}"),
            Self::MissingBearing(id) => {
                write!(
                    f,
                    "no bearing to agent {id} this tick, nor one within the hold"
                )
            }
            Self::Stale(id) => write!(f, "agent {id} not heard within the timeout"),
            Self::MissingData(id) => write!(f, "agent {id}'s frames lack data this step needs"),
            Self::MissingPartnerOffset => {
                write!(f, "leader without the partner's relative position")
            }
            Self::MissingRange(id) => write!(f, "no range to agent {id} (measured-distance mode)"),
            Self::NonFinite => write!(f, "the computed force is not finite"),
            Self::Internal => write!(f, "internal inconsistency (a bug: please report)"),
        }
    }
}

/// The kind of output of a step.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Status {
    /// The control law S7–S12 (saturated to `max_force`).
    Nominal,
    /// The safe output `U = −safe_damping · v` (no formation force), and why.
    Safe(Fault),
}

/// The result of [`crate::Agent::step`]. `force` is always finite and at most `max_force` long.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct StepOutput<T: Real> {
    /// The force command `U_n`.
    pub force: Vec2<T>,
    /// Control law or safe output.
    pub status: Status,
    /// The force was scaled down to `max_force`.
    pub saturated: bool,
    /// A current angle of which this agent is the apex is within the configured margin
    /// of 0 or π (SPEC §3). (Far vertices do not see the angle; its apex reports it.)
    pub degenerate: bool,
}

#[cfg(feature = "defmt")]
impl<T: Real> defmt::Format for StepOutput<T> {
    fn format(&self, f: defmt::Formatter) {
        defmt::write!(
            f,
            "StepOutput {{ force: ({}, {}), status: {}, saturated: {}, degenerate: {} }}",
            self.force.x,
            self.force.y,
            self.status,
            self.saturated,
            self.degenerate
        )
    }
}

/// What the control law gives before saturation (the input of `Agent::output`, feature
/// `sim`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LawOutput<T: Real> {
    /// `U_n` before saturation.
    pub force: Vec2<T>,
    /// A current angle is within the configured margin of 0 or π.
    pub degenerate: bool,
}

/// The control law evaluated without changing any state (see [`crate::Agent::evaluate`]).
/// Feature `sim` only (not built for the firmware).
#[cfg(any(feature = "sim", test))]
#[derive(Clone, Debug, PartialEq)]
pub struct Evaluation<T: Real, const MT: usize> {
    /// `U_n` before saturation.
    pub force: Vec2<T>,
    /// S9 with the S10 projection for every estimate this agent owns, indexed
    /// `[triangle][angle][edge]` (zero where it owns none).
    pub estimate_rates: heapless::Vec<[[T; 2]; 2], MT>,
    /// A current angle is within the configured margin of 0 or π.
    pub degenerate: bool,
}

/// One estimate owned by this agent (see [`crate::Agent::owned_estimates`]).
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct OwnedEstimate<T> {
    /// Triangle index in the configuration.
    pub triangle: usize,
    /// Controlled angle index (0 or 1) in the triangle.
    pub angle: usize,
    /// Edge index: 0 is apex → first far vertex, 1 is apex → second far vertex.
    pub edge: usize,
    /// The angle's apex.
    pub apex: AgentId,
    /// The far vertex of the edge.
    pub far: AgentId,
    /// `r̂`.
    pub value: T,
}
