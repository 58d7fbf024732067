//! Wire frames, version 4: what one agent broadcasts per communication tick, in one
//! frame of at most [`MAX_FRAME_LEN`] bytes (the Crazyflie peer-to-peer payload), and
//! COBS framing for byte streams (UART).
//!
//! # Definition
//!
//! A frame is **postcard of [`Frame`]**, followed by its integrity trailer:
//! `postcard::to_slice(&frame)` and then the CRC-16/IBM-SDLC of those bytes
//! ([`Integrity::Crc16`]: exactly postcard's own CRC flavour,
//! `postcard::ser_flavors::crc::to_slice_u16` with that CRC), nothing
//! ([`Integrity::Link`]), or the SipHash-2-4 tag ([`Integrity::Auth`], see [`auth`]).
//! [`Frame::encode`] and [`Frame::decode`] are that definition in code (postcard's own
//! serializer and deserializer); [`FrameWriter`] and [`check_frame`] are the hand-written
//! fast path the agents use, proven byte for byte equal to them
//! (`tests/wire_postcard.rs`, a property test over every integrity and estimator mode and
//! item count, valid, random and corrupted bytes).
//!
//! # Layout (the consequence; all multi-byte fields little-endian)
//!
//! | offset | bytes | field |
//! |---|---|---|
//! | 0 | 1 | mode byte: bits 7–4 `8 +` the number `k` of angle items (0–4; wire version 4), bits 3–2 [`Integrity`], bits 1–0 [`EstimatorMode`] |
//! | 1 | 1 | sender id ([`AgentId`]) |
//! | 2 | 2 | sequence number (`u16`, +1 per frame, wrapping; postcard `fixint`) |
//! | 4 | 8 | sender velocity `v_n` (S1): `f32` x, `f32` y (m/s) |
//! | 12 | 10·k | k angle items ([`AngleItem`], below) |
//! | 12 + 10k | 0 or 2 | integrity trailer: CRC-16/IBM-SDLC of bytes `0..12+10k` ([`Integrity::Crc16`]), nothing ([`Integrity::Link`]) |
//!
//! With [`Integrity::Auth`] a frame of at most 3 items carries a 6-byte counter
//! extension ([`CounterExt`]) after its items (a frame of 4 has no room for it), and
//! every frame ends with an 8-byte tag ([`auth`]):
//!
//! | offset | bytes | field |
//! |---|---|---|
//! | 12 + 10k | 6 (k ≤ 3) or 0 (k = 4) | counter extension: boot epoch (`u32`), high 16 bits of the frame number (`u16`) |
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
//! # Where postcard's item count lives
//!
//! postcard writes the length of a variable sequence (or an enum's tag) as one byte of
//! its own. Here it would cost a byte that the budget does not have: `auth` at 4 items
//! is 12 + 40 + 8 = 60 bytes, the Crazyflie limit. The count therefore lives in the
//! mode byte's top nibble, which held the version (3) and now holds `8 + k`: the bits
//! that integrity and estimator mode use (3–0) keep their meaning, a version-3 receiver
//! reads nibbles 8–12 as unknown versions, and this one reads 0–7 (earlier versions) and
//! 13–15 the same way ([`FrameError::UnknownVersion`]). A derived struct cannot share a
//! byte between two fields, so [`Frame`]'s `Serialize` and `Deserialize` are written by
//! hand: a tuple whose first element, the mode byte, says how many items (and whether a
//! counter extension) follow; every element is a derived type with postcard's `fixint`
//! for the fixed-width integers. The other homes cost more: a sequence number of 8 bits
//! would shrink the replay window of `auth` to 128 frames and the stale-sequence window
//! to 127; an item-count enum's tag is the same extra byte.
//!
//! An agent that is the apex of more angles than a frame holds
//! ([`Integrity::max_angles`], 4) sends several frames, each with its own sequence
//! number and the velocity.
//!
//! Receivers reject, with a typed [`FrameError`] counted in [`crate::FrameStats`], every
//! frame whose length, CRC, version, integrity or estimator mode, item count, sender,
//! sequence number or values (non-finite, `|σ| > 1`, `ρ ≤ 0`, an estimate below the
//! receiver's `r_min`) are wrong, and in `auth` mode every frame whose tag does not
//! verify or whose counter is not newer than the sender's last accepted one; a rejected
//! frame changes nothing but the counters.

pub mod auth;
mod checked;
mod cobs;
mod frame;
pub mod position;
pub mod quant;
mod reader;
mod writer;

pub use auth::SwarmKey;
pub use checked::CrcCheck;
pub use cobs::{cobs_decode, cobs_encode, CobsAccumulator, MAX_COBS_LEN};
pub use frame::{AngleItem, CounterExt, Frame, F16};
pub use reader::{check_frame, decode_frame, FrameView};
pub(crate) use reader::{check_mode, RawAngle};
pub use writer::FrameWriter;

use crate::config::EstimatorMode;
use crate::AgentId;
use serde::{Deserialize, Serialize};

/// Largest frame, in bytes (Crazyflie P2P payload limit).
pub const MAX_FRAME_LEN: usize = 60;
/// The wire-format version this crate writes and accepts. Versions up to 3 carried their
/// number in bits 7–4 of the mode byte; version 4 carries `8 +` the item count there
/// ([`COUNT_NIBBLE_BASE`]).
pub const WIRE_VERSION: u8 = 4;
/// Bits 7–4 of a version-4 mode byte are this plus the number of angle items (0–4):
/// nibbles 8–12. Any other nibble is refused as [`FrameError::UnknownVersion`].
pub const COUNT_NIBBLE_BASE: u8 = 8;

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

/// The mode byte of a frame without angle items written with `integrity` by an agent in
/// `estimator` mode; a frame with `k` items carries [`mode_with_items`]`(mode, k)`.
/// [`FrameHeader::mode`] and [`crate::Agent`] use this form (the count is the items').
pub const fn mode_byte(integrity: Integrity, estimator: EstimatorMode) -> u8 {
    (COUNT_NIBBLE_BASE << 4) | (integrity.code() << 2) | estimator_code(estimator)
}

/// The mode byte on the air of a frame with `items` angle items whose modes are those of
/// `mode` (bits 3–0; bits 7–4 become `8 + items`).
pub const fn mode_with_items(mode: u8, items: usize) -> u8 {
    ((COUNT_NIBBLE_BASE + items as u8) << 4) | (mode & 0x0F)
}

/// The number of angle items a mode byte announces, or `None` if its bits 7–4 are not a
/// version-4 nibble (8–12).
pub const fn items_of_mode(mode: u8) -> Option<usize> {
    let k = (mode >> 4).wrapping_sub(COUNT_NIBBLE_BASE) as usize;
    if k <= MAX_ANGLES_PER_FRAME {
        Some(k)
    } else {
        None
    }
}

/// The fixed header of every frame.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct FrameHeader {
    /// The sender's mode byte without the item count, as [`mode_byte`] gives it (bits 7–4
    /// are 8; on the air they are `8 +` the number of items, see [`mode_with_items`]).
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
    /// The mode byte's bits 7–4 (carried) are not those of a version-4 frame (8 + an item
    /// count of 0–4): another wire version.
    UnknownVersion(u8),
    /// The frame's integrity or estimator mode differs from the receiver's: the swarm is
    /// misconfigured. Carries the received mode byte.
    ModeMismatch(u8),
    /// The length is not that of the item count the mode byte announces (with `auth`:
    /// and the counter extension when there is room for it), or an item names the same
    /// far vertex twice.
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
            Self::UnknownVersion(v) => write!(
                f,
                "unknown wire version (mode byte bits 7-4 = {v}, version 4 uses 8-12)"
            ),
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
