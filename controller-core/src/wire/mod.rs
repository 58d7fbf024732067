//! Wire frames, version 3: what one agent broadcasts per communication tick, in one
//! fixed-layout frame of at most [`MAX_FRAME_LEN`] bytes (the Crazyflie peer-to-peer
//! payload), and COBS framing for byte streams (UART).
//!
//! # Layout (all multi-byte fields little-endian)
//!
//! | offset | bytes | field |
//! |---|---|---|
//! | 0 | 1 | mode byte: bits 7–4 [`WIRE_VERSION`], bits 3–2 [`Integrity`], bits 1–0 [`EstimatorMode`] |
//! | 1 | 1 | sender id ([`AgentId`]) |
//! | 2 | 2 | sequence number (`u16`, +1 per frame, wrapping) |
//! | 4 | 8 | sender velocity `v_n` (S1): `f32` x, `f32` y (m/s) |
//! | 12 | 10·k | k angle items (below) |
//! | 12 + 10k | 0 or 2 | integrity trailer: CRC-16/IBM-SDLC of bytes `0..12+10k` ([`Integrity::Crc16`]), nothing ([`Integrity::Link`]) |
//!
//! With [`Integrity::Auth`] the items are followed by a 6-byte counter extension when it
//! fits (at most 3 items) and then an 8-byte tag ([`auth`]):
//!
//! | offset | bytes | field |
//! |---|---|---|
//! | 12 + 10k | 0 or 6 | counter extension: boot epoch (`u32`), high 16 bits of the frame number (`u16`) |
//! | end − 8 | 8 | SipHash-2-4 tag of the sender's full counter and every byte before the tag |
//!
//! One angle item per controlled angle `α = (n; v, w)` whose apex `n` is the sender
//! (values in IEEE 754 binary16, see [`quant`]):
//!
//! | offset | bytes | field |
//! |---|---|---|
//! | 0 | 1 | far vertex `v` |
//! | 1 | 1 | far vertex `w` |
//! | 2 | 2 | `γ_α`, the port effort (S7) |
//! | 4 | 2 | `σ_α = s_nv × s_nw = sin α` (signed, in `[−1, 1]`; S6: `g_{α,v} = σ J s_nv`, `g_{α,w} = −σ J s_nw`) |
//! | 6 | 2 | `ρ_v`: the distance `n`–`v` the apex used in its S8 (`r̂_{α,nv}` with shared or per-agent estimates, the measured range otherwise), > 0 |
//! | 8 | 2 | `ρ_w`: the same for `n`–`w` |
//!
//! This is what a far vertex needs of the angle and nothing more (see
//! [`crate::law::far_angle`]): with its own fresh bearing to the apex it forms
//! `g_{α,k}`, brings `γ_α` up to date with its own motion since, and applies S8 with
//! `ρ_k` (shared estimates: SPEC §6) or its own distance (per-agent copy, range).
//!
//! The item count follows from the length. A frame holds at most
//! [`Integrity::max_angles`] items (4); an agent that is the apex of more angles sends
//! several frames, each with its own sequence number and the velocity.
//!
//! Receivers reject, with a typed [`FrameError`] counted in [`crate::FrameStats`], every
//! frame whose length, CRC, version, integrity or estimator mode, sender, sequence number
//! or values (non-finite, `|σ| > 1`, `ρ ≤ 0`, an estimate below the receiver's `r_min`)
//! are wrong, and in `auth` mode every frame whose tag does not verify or whose counter
//! is not newer than the sender's last accepted one; a rejected frame changes nothing
//! but the counters.

pub mod auth;
mod checked;
mod cobs;
pub mod quant;
mod reader;
mod writer;

pub use auth::SwarmKey;
pub use checked::CrcCheck;
pub use cobs::{cobs_decode, cobs_encode, CobsAccumulator, MAX_COBS_LEN};
pub use reader::{check_frame, decode_frame, AngleItem, Frame, FrameView};
pub(crate) use reader::{check_mode, RawAngle};
pub use writer::FrameWriter;

use crate::config::EstimatorMode;
use crate::AgentId;
use serde::{Deserialize, Serialize};

/// Largest frame, in bytes (Crazyflie P2P payload limit).
pub const MAX_FRAME_LEN: usize = 60;
/// The wire-format version this crate writes and accepts (bits 7–4 of the mode byte).
pub const WIRE_VERSION: u8 = 3;

/// Byte offsets of the frame fields.
pub mod offset {
    /// Mode byte: version, integrity, estimator mode.
    pub const MODE: usize = 0;
    /// Sender id.
    pub const SENDER: usize = 1;
    /// Sequence number (`u16` LE).
    pub const SEQ: usize = 2;
    /// Velocity (`[f32; 2]` LE).
    pub const VELOCITY: usize = 4;
    /// First angle item.
    pub const ANGLES: usize = 12;
    /// Within an angle item: far vertex `v`.
    pub const ITEM_FAR0: usize = 0;
    /// Within an angle item: far vertex `w`.
    pub const ITEM_FAR1: usize = 1;
    /// Within an angle item: `γ_α` (binary16 LE).
    pub const ITEM_GAMMA: usize = 2;
    /// Within an angle item: `σ_α` (binary16 LE).
    pub const ITEM_SIGMA: usize = 4;
    /// Within an angle item: `ρ_v` (binary16 LE).
    pub const ITEM_RHO0: usize = 6;
    /// Within an angle item: `ρ_w` (binary16 LE).
    pub const ITEM_RHO1: usize = 8;
}

/// Bytes of one angle item.
pub const ANGLE_ITEM_LEN: usize = 10;
/// Bytes before the angle items (header and velocity).
pub const FIXED_LEN: usize = offset::ANGLES;
/// Most angle items one frame can hold (on a link without trailer).
pub const MAX_ANGLES_PER_FRAME: usize = angles_fitting(0);
/// Most angle items a frame holds with the longest trailer (`auth`'s tag): the fewest of
/// any integrity mode.
pub const MIN_ANGLES_PER_FRAME: usize = angles_fitting(auth::TAG_LEN);

/// Angle items that fit in a frame with a trailer of `trailer` bytes.
const fn angles_fitting(trailer: usize) -> usize {
    (MAX_FRAME_LEN - FIXED_LEN - trailer) / ANGLE_ITEM_LEN
}

/// How frames are protected against corruption. Chosen per deployment in
/// [`crate::AgentConfig::integrity`]; every agent of a swarm must use the same (the mode
/// byte carries it and a receiver refuses any other).
///
/// The `Debug`, `Display` and `defmt` forms of [`Integrity::Auth`] redact the key.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default, Serialize, Deserialize)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Integrity {
    /// A CRC-16/IBM-SDLC trailer ([`crate::crc16`]): raw UART or any link without a check
    /// of its own.
    #[default]
    Crc16,
    /// No trailer: the link already checks a CRC (the Crazyflie radio does), so the frame
    /// costs no bytes and no instructions for it.
    Link,
    /// A 64-bit SipHash-2-4 tag under a pre-shared swarm key, over the sender's 64-bit
    /// frame counter and the whole frame, and replay protection ([`auth`]): for any
    /// channel an adversary can transmit on.
    Auth(SwarmKey),
}

impl core::fmt::Display for Integrity {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        match self {
            Integrity::Crc16 => f.write_str("crc16"),
            Integrity::Link => f.write_str("link"),
            Integrity::Auth(key) => write!(f, "auth (key {key})"),
        }
    }
}

impl Integrity {
    /// Code in bits 3–2 of the mode byte.
    pub const fn code(self) -> u8 {
        match self {
            Integrity::Crc16 => 0,
            Integrity::Link => 1,
            Integrity::Auth(_) => 2,
        }
    }

    /// Bytes after the angle items.
    pub const fn trailer_len(self) -> usize {
        match self {
            Integrity::Crc16 => 2,
            Integrity::Link => 0,
            Integrity::Auth(_) => auth::TAG_LEN,
        }
    }

    /// Most angle items in one frame.
    pub const fn max_angles(self) -> usize {
        angles_fitting(self.trailer_len())
    }
}

/// Code of an estimator mode in bits 1–0 of the mode byte.
pub const fn estimator_code(mode: EstimatorMode) -> u8 {
    match mode {
        EstimatorMode::Shared => 0,
        EstimatorMode::PerAgent => 1,
        EstimatorMode::Measured => 2,
    }
}

/// The mode byte of a frame written with `integrity` by an agent in `estimator` mode.
pub const fn mode_byte(integrity: Integrity, estimator: EstimatorMode) -> u8 {
    (WIRE_VERSION << 4) | (integrity.code() << 2) | estimator_code(estimator)
}

/// The fixed header of every frame.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct FrameHeader {
    /// The mode byte (version, integrity, estimator mode).
    pub mode: u8,
    /// The sending agent.
    pub sender: AgentId,
    /// Per-sender sequence number, +1 per frame, wrapping.
    pub seq: u16,
}

/// Why a frame was rejected. Every rejection is counted in [`crate::FrameStats`].
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum FrameError {
    /// Shorter than a header, the velocity and the trailer.
    TooShort,
    /// Longer than [`MAX_FRAME_LEN`].
    TooLong,
    /// CRC mismatch.
    BadCrc,
    /// The mode byte's version is not [`WIRE_VERSION`].
    UnknownVersion(u8),
    /// The frame's integrity or estimator mode differs from the receiver's: the swarm is
    /// misconfigured. Carries the received mode byte.
    ModeMismatch(u8),
    /// The length does not leave a whole number of angle items, or an item names the
    /// same far vertex twice.
    Malformed,
    /// The sender is not one of this agent's neighbours.
    UnknownSender(AgentId),
    /// Sent by this agent itself.
    OwnFrame,
    /// The sequence number is not newer than the last accepted one from this sender.
    StaleSequence {
        /// The sender.
        sender: AgentId,
        /// The rejected sequence number.
        seq: u16,
    },
    /// A value is NaN or infinite, `|σ| > 1`, a distance is not positive, or an estimate
    /// is below the receiver's `r_min`.
    InvalidValue,
    /// A COBS stream chunk that does not decode.
    Cobs,
    /// `auth`: the tag does not verify (forged, corrupted, another key, or a counter the
    /// receiver reconstructed wrongly).
    BadTag,
    /// `auth`: the frame's counter is not larger than the last one accepted from this
    /// sender (a replay, or a frame that arrived late).
    Replayed {
        /// The sender.
        sender: AgentId,
        /// The frame's counter (as carried or reconstructed, see [`auth`]).
        counter: u64,
    },
    /// `auth`: nothing accepted from this sender yet (or since this agent booted) and the
    /// frame carries no counter extension: its counter is unknown.
    Unsynced(AgentId),
}

impl core::fmt::Display for FrameError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        match self {
            Self::TooShort => write!(f, "frame shorter than header, velocity and trailer"),
            Self::TooLong => write!(f, "frame longer than {MAX_FRAME_LEN} bytes"),
            Self::BadCrc => write!(f, "CRC mismatch"),
            Self::UnknownVersion(v) => write!(f, "unknown wire version {v}"),
            Self::ModeMismatch(m) => write!(
                f,
                "integrity or estimator mode differs from this agent's (mode byte {m:#04x})"
            ),
            Self::Malformed => write!(f, "malformed frame body"),
            Self::UnknownSender(id) => write!(f, "sender {id} is not a neighbour"),
            Self::OwnFrame => write!(f, "own frame"),
            Self::StaleSequence { sender, seq } => write!(
                f,
                "stale or repeated sequence number {seq} from agent {sender}"
            ),
            Self::InvalidValue => write!(
                f,
                "non-finite value, |σ| > 1, non-positive distance or estimate below r_min"
            ),
            Self::Cobs => write!(f, "COBS chunk does not decode"),
            Self::BadTag => write!(f, "authentication tag does not verify"),
            Self::Replayed { sender, counter } => write!(
                f,
                "replayed or late frame from agent {sender} (counter {counter:#018x})"
            ),
            Self::Unsynced(id) => write!(
                f,
                "no counter known for agent {id} yet and none in the frame"
            ),
        }
    }
}
