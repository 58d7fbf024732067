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

use crate::agent::{Agent, BearingMeasurement, Fault, OwnedEstimate, Status};
use crate::config::{AgentConfig, AgentId, ConfigError};
use crate::wire::{FrameError, MAX_FRAME_LEN};
use serde::{Deserialize, Serialize};

/// Largest number of bearings in one [`HostMsg::Step`].
pub const MAX_LINK_BEARINGS: usize = 12;
/// Largest encoded link message (before COBS), in bytes.
pub const MAX_LINK_MSG: usize = 512;
/// Link protocol version, sent in [`TargetMsg::Ready`].
pub const LINK_VERSION: u8 = 1;

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

/// What a step produced, in a link-friendly form.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct LinkOutput {
    /// The force command.
    pub force: [f32; 2],
    /// `true` for [`Status::Nominal`].
    pub nominal: bool,
    /// The fault's neighbour, if the safe output names one.
    pub fault_neighbour: Option<AgentId>,
    /// Force saturated.
    pub saturated: bool,
    /// Frames sent this tick (the preceding [`TargetMsg::Radio`] messages).
    pub frames: u8,
    /// Frames the target's agent rejected so far.
    pub rejected: u32,
}

impl LinkOutput {
    /// Builds the link form of a step's status.
    pub fn new(
        force: [f32; 2],
        status: Status,
        saturated: bool,
        frames: u8,
        rejected: u32,
    ) -> Self {
        let fault_neighbour = match status {
            Status::Safe(
                Fault::Stale(id)
                | Fault::MissingBearing(id)
                | Fault::MissingData(id)
                | Fault::MissingRange(id),
            ) => Some(id),
            _ => None,
        };
        Self {
            force,
            nominal: status == Status::Nominal,
            fault_neighbour,
            saturated,
            frames,
            rejected,
        }
    }
}

/// Why the target refused a host message.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum LinkError {
    /// A message that does not decode (COBS or postcard).
    Malformed,
    /// A configuration the core refused (its [`ConfigError`] as text-free code).
    Config(u8),
    /// `Step` or `Radio` before a successful `Configure`.
    NotConfigured,
    /// A radio frame the agent rejected (informational; the tick goes on).
    Frame(u8),
}

impl LinkError {
    /// Compact code of a configuration error.
    pub fn config(e: ConfigError) -> Self {
        Self::Config(match e {
            ConfigError::NotInTriangle { .. } => 1,
            ConfigError::RepeatedVertex { .. } => 2,
            ConfigError::BadApex { .. } => 3,
            ConfigError::InfeasibleAngles { .. } => 4,
            ConfigError::BadGain { .. } => 5,
            ConfigError::TooManyNeighbours => 6,
            ConfigError::BadParameter => 7,
            ConfigError::BadLeader => 8,
        })
    }

    /// Compact code of a frame error.
    pub fn frame(e: FrameError) -> Self {
        Self::Frame(match e {
            FrameError::TooShort => 1,
            FrameError::TooLong => 2,
            FrameError::BadCrc => 3,
            FrameError::UnknownVersion(_) => 4,
            FrameError::Malformed => 5,
            FrameError::UnknownSender(_) => 6,
            FrameError::OwnFrame => 7,
            FrameError::StaleSequence { .. } => 8,
            FrameError::InvalidValue => 9,
            FrameError::Cobs => 10,
        })
    }
}

/// Largest number of estimates in one [`TargetMsg::Estimates`].
pub const MAX_LINK_ESTIMATES: usize = 16;

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

impl From<OwnedEstimate<f32>> for LinkEstimate {
    fn from(e: OwnedEstimate<f32>) -> Self {
        let small = |x: usize| u8::try_from(x).unwrap_or(u8::MAX);
        Self {
            apex: e.apex,
            far: e.far,
            triangle: small(e.triangle),
            angle: small(e.angle),
            edge: small(e.edge),
            value: e.value,
        }
    }
}

/// The estimates `agent` owns, in link form (at most [`MAX_LINK_ESTIMATES`]; an agent in
/// at most 4 triangles owns at most 16).
pub fn link_estimates<const MT: usize, const NB: usize>(
    agent: &Agent<f32, MT, NB>,
) -> heapless::Vec<LinkEstimate, MAX_LINK_ESTIMATES> {
    agent
        .owned_estimates()
        .take(MAX_LINK_ESTIMATES)
        .map(LinkEstimate::from)
        .collect()
}

/// Target → host.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum TargetMsg {
    /// Configured: agent id and [`LINK_VERSION`].
    Ready {
        /// The agent's id.
        id: AgentId,
        /// [`LINK_VERSION`].
        version: u8,
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
