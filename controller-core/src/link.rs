//! Messages for running an [`crate::Agent`] behind a byte link (host-in-the-loop over a
//! UART): postcard-encoded, COBS-framed (see [`crate::wire::cobs_encode`]), one message
//! per COBS frame.
//!
//! Lock-step protocol, host → target then target → host:
//! 1. once: [`HostMsg::Configure`] → [`TargetMsg::Ready`] (or [`TargetMsg::Error`]);
//! 2. per control tick: any number of [`HostMsg::Radio`] (frames the agent's radio
//!    received), then one [`HostMsg::Step`] with the agent's own measurements →
//!    any number of [`TargetMsg::Radio`] (frames to broadcast), optionally one
//!    [`TargetMsg::Estimates`], then one [`TargetMsg::Output`]. The host advances simulated time only after `Output`.
//!
//! All values are `f32`, as on the target.

use crate::agent::{Agent, BearingMeasurement, Fault, OwnedEstimate, Status, StepOutput};
use crate::config::{AgentConfig, AgentId, ConfigError};
use crate::wire::{FrameError, MAX_FRAME_LEN};
use serde::{Deserialize, Serialize};

/// Largest number of bearings in one [`HostMsg::Step`].
pub const MAX_LINK_BEARINGS: usize = 12;
/// Largest encoded link message (before COBS), in bytes.
pub const MAX_LINK_MSG: usize = 512;
/// Link protocol version, sent in [`TargetMsg::Ready`] (3: the configuration carries
/// the bearing filter of SPEC §11; 4: its limits the bearing hold of SPEC §12).
pub const LINK_VERSION: u8 = 4;

/// One bearing measurement on the link (see [`crate::BearingMeasurement`]).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct LinkBearing {
    /// The neighbour.
    pub neighbour: AgentId,
    /// Unit bearing.
    pub s: [f32; 2],
    /// Measured bearing rate, if any.
    pub rate: Option<[f32; 2]>,
    /// Measured range, if any.
    pub range: Option<f32>,
}

impl LinkBearing {
    /// The core's form of this bearing.
    pub fn measurement(&self) -> BearingMeasurement<f32> {
        BearingMeasurement {
            neighbour: self.neighbour,
            bearing: crate::Vec2::new(self.s[0], self.s[1]),
            rate: self.rate.map(|r| crate::Vec2::new(r[0], r[1])),
            range: self.range,
        }
    }
}

/// One control tick's own measurements (see [`crate::Measurements`]).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct LinkStep {
    /// Time (s).
    pub time: f32,
    /// Seconds since the previous step.
    pub dt: f32,
    /// Own velocity.
    pub velocity: [f32; 2],
    /// Bearings.
    pub bearings: heapless::Vec<LinkBearing, MAX_LINK_BEARINGS>,
    /// Leaders: partner position minus own.
    pub partner_offset: Option<[f32; 2]>,
}

/// Host → target.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum HostMsg<const MT: usize> {
    /// (Re)build the agent from this configuration.
    Configure(AgentConfig<f32, MT>),
    /// A frame the agent's radio received.
    Radio(heapless::Vec<u8, MAX_FRAME_LEN>),
    /// Run one control step on these measurements.
    Step(LinkStep),
    /// End of run: the target reports its counters and may exit.
    Finish,
}

/// What a step produced, as it crosses the link.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct LinkOutput {
    /// The force command.
    pub force: [f32; 2],
    /// Control law or safe output, with the fault itself.
    pub status: Status,
    /// Force saturated.
    pub saturated: bool,
    /// A current angle is degenerate.
    pub degenerate: bool,
    /// Frames sent this tick (the preceding [`TargetMsg::Radio`] messages).
    pub frames: u32,
    /// Frames the target's agent rejected so far.
    pub rejected: u32,
}

impl LinkOutput {
    /// The link form of a step's output, with the tick's frame count and the rejection
    /// counter.
    pub fn new(out: &StepOutput<f32>, frames: usize, rejected: u32) -> Self {
        Self {
            force: [out.force.x, out.force.y],
            status: out.status,
            saturated: out.saturated,
            degenerate: out.degenerate,
            frames: u32::try_from(frames).unwrap_or(u32::MAX),
            rejected,
        }
    }

    /// The neighbour the fault names, if any.
    pub fn fault_neighbour(&self) -> Option<AgentId> {
        match self.status {
            Status::Safe(
                Fault::Stale(id)
                | Fault::MissingBearing(id)
                | Fault::MissingData(id)
                | Fault::MissingRange(id),
            ) => Some(id),
            _ => None,
        }
    }
}

/// Why the target refused a host message.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum LinkError {
    /// A message that does not decode (COBS or postcard).
    Malformed,
    /// A configuration the core refused, with the core's reason.
    Config(ConfigError),
    /// `Step` or `Radio` before a successful `Configure`.
    NotConfigured,
    /// A radio frame the agent rejected (informational; the tick goes on).
    Frame(FrameError),
    /// The agent owns more estimates than one [`TargetMsg::Estimates`] holds.
    TooManyEstimates,
}

/// Largest number of estimates in one [`TargetMsg::Estimates`]: an agent owns at most 3
/// per triangle (2 as an apex, 1 more as a far vertex in per-agent mode), for up to
/// [`crate::MAX_TRIANGLES`] triangles.
pub const MAX_LINK_ESTIMATES: usize = 3 * crate::MAX_TRIANGLES;

/// One owned estimate, reported to the host for diagnostics (see [`crate::OwnedEstimate`]).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct LinkEstimate {
    /// The angle's apex.
    pub apex: AgentId,
    /// The far vertex of the edge.
    pub far: AgentId,
    /// Triangle index in the agent's configuration.
    pub triangle: u8,
    /// Angle index (0 or 1).
    pub angle: u8,
    /// Edge index (0 or 1).
    pub edge: u8,
    /// `r̂`.
    pub value: f32,
}

impl TryFrom<OwnedEstimate<f32>> for LinkEstimate {
    type Error = LinkError;

    fn try_from(e: OwnedEstimate<f32>) -> Result<Self, LinkError> {
        let small = |x: usize| u8::try_from(x).map_err(|_| LinkError::TooManyEstimates);
        Ok(Self {
            apex: e.apex,
            far: e.far,
            triangle: small(e.triangle)?,
            angle: small(e.angle)?,
            edge: small(e.edge)?,
            value: e.value,
        })
    }
}

/// The estimates `agent` owns, in link form, or [`LinkError::TooManyEstimates`] when
/// they do not fit one message (more than [`MAX_LINK_ESTIMATES`]): never truncated.
pub fn link_estimates<const MT: usize, const NB: usize>(
    agent: &Agent<f32, MT, NB>,
) -> Result<heapless::Vec<LinkEstimate, MAX_LINK_ESTIMATES>, LinkError> {
    let mut out = heapless::Vec::new();
    for e in agent.owned_estimates() {
        out.push(LinkEstimate::try_from(e)?)
            .map_err(|_| LinkError::TooManyEstimates)?;
    }
    Ok(out)
}

/// Target → host.
// `Estimates` is the large variant (~300 bytes): messages live on the stack of a no-heap
// target, one at a time.
#[allow(clippy::large_enum_variant)]
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum TargetMsg {
    /// Configured: agent id, [`LINK_VERSION`] and the target agent's capacity.
    Ready {
        /// The agent's id.
        id: AgentId,
        /// [`LINK_VERSION`].
        version: u8,
        /// Triangles the target's agent type holds (`MT`).
        max_triangles: u16,
        /// Neighbours the target's agent type holds (`NB`).
        max_neighbours: u16,
    },
    /// A frame to broadcast.
    Radio(heapless::Vec<u8, MAX_FRAME_LEN>),
    /// The estimates the agent owns after the step (sent before `Output`, optional).
    Estimates(heapless::Vec<LinkEstimate, MAX_LINK_ESTIMATES>),
    /// End of a step.
    Output(LinkOutput),
    /// A refused message.
    Error(LinkError),
    /// Reply to `Finish`: frames accepted and rejected over the run.
    Finished {
        /// Accepted radio frames.
        accepted: u32,
        /// Rejected radio frames.
        rejected: u32,
    },
}
