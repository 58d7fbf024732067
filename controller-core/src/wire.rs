//! Wire frames: versioned, sequence-numbered, CRC-checked postcard messages of at most
//! [`MAX_FRAME_LEN`] bytes (the Crazyflie peer-to-peer payload), and COBS framing for
//! byte streams (UART).
//!
//! Layout of one frame: `postcard(FrameHeader) ‖ postcard(WireItem)* ‖ CRC-16 (LE)`.
//! The CRC is CRC-16/IBM-3740 (CCITT-FALSE) over everything before it. Items are packed
//! greedily; an agent whose data does not fit sends several frames, each with its own
//! sequence number.
//!
//! Values travel as `f32`. For `f64` agents this rounds every value to the nearest `f32`:
//! relative error at most 2⁻²⁴ ≈ 6·10⁻⁸ per component (tested in `tests/wire.rs`).

use crate::AgentId;
use serde::{Deserialize, Serialize};

/// Largest encoded frame, in bytes (Crazyflie P2P payload limit).
pub const MAX_FRAME_LEN: usize = 60;
/// The wire-format version this crate writes and accepts.
pub const WIRE_VERSION: u8 = 1;
/// Largest number of items one frame can hold (the smallest item is 7 bytes).
pub const MAX_ITEMS_PER_FRAME: usize = 8;
/// Largest COBS-encoded frame including the trailing zero delimiter.
pub const MAX_COBS_LEN: usize = MAX_FRAME_LEN + MAX_FRAME_LEN / 254 + 2;

const CRC_LEN: usize = 2;
/// CRC-16/IBM-3740, byte-wise table (512 B of flash). The slice-by-16 table was measured
/// on target: 13 % fewer CRC instructions on 30–60-byte frames for 8.7 KiB more flash.
const CRC16: crc::Crc<u16> = crc::Crc::<u16>::new(&crc::CRC_16_IBM_3740);

/// The start of every frame.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct FrameHeader {
    /// [`WIRE_VERSION`].
    pub version: u8,
    /// The sending agent.
    pub sender: AgentId,
    /// Per-sender sequence number, +1 per frame, wrapping.
    pub seq: u16,
}

/// One piece of what an agent broadcasts (SPEC §6 needs all three).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum WireItem {
    /// The sender's velocity `v_n` (world frame).
    Velocity([f32; 2]),
    /// The sender's bearing `s_{n,to}` to neighbour `to`, and its rate `ṡ_{n,to}`.
    Bearing {
        /// The neighbour.
        to: AgentId,
        /// Unit bearing.
        s: [f32; 2],
        /// Bearing rate.
        rate: [f32; 2],
    },
    /// The sender's (apex) estimate `r̂_{α,e}` for the edge to `far`, in the angle whose
    /// other far vertex is `other`.
    Estimate {
        /// The far vertex of the edge (the receiver that needs it).
        far: AgentId,
        /// The angle's other far vertex.
        other: AgentId,
        /// `r̂ > 0`.
        r: f32,
    },
}

/// Why a frame was rejected. Every rejection is counted in [`crate::FrameStats`].
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum FrameError {
    /// Shorter than a header and a CRC.
    TooShort,
    /// Longer than [`MAX_FRAME_LEN`].
    TooLong,
    /// CRC mismatch.
    BadCrc,
    /// The header's version is not [`WIRE_VERSION`].
    UnknownVersion(u8),
    /// Bytes that do not decode as header and items.
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
    /// A value is NaN or infinite, a bearing is not a unit vector, or an estimate is ≤ 0.
    InvalidValue,
    /// A COBS stream chunk that does not decode.
    Cobs,
}

impl core::fmt::Display for FrameError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        match self {
            Self::TooShort => write!(f, "frame shorter than header and CRC"),
            Self::TooLong => write!(f, "frame longer than {MAX_FRAME_LEN} bytes"),
            Self::BadCrc => write!(f, "CRC mismatch"),
            Self::UnknownVersion(v) => write!(f, "unknown wire version {v}"),
            Self::Malformed => write!(f, "malformed frame body"),
            Self::UnknownSender(id) => write!(f, "sender {id} is not a neighbour"),
            Self::OwnFrame => write!(f, "own frame"),
            Self::StaleSequence { sender, seq } => write!(
                f,
                "stale or repeated sequence number {seq} from agent {sender}"
            ),
            Self::InvalidValue => write!(
                f,
                "non-finite value, non-unit bearing or non-positive estimate"
            ),
            Self::Cobs => write!(f, "COBS chunk does not decode"),
        }
    }
}

/// Builds one frame: header, then items while they fit, then the CRC.
#[derive(Clone, Debug)]
pub struct FrameWriter {
    buf: [u8; MAX_FRAME_LEN],
    len: usize,
    items: usize,
}

impl FrameWriter {
    /// Starts a frame for `sender` with sequence number `seq`.
    pub fn new(sender: AgentId, seq: u16) -> Self {
        let mut w = Self {
            buf: [0; MAX_FRAME_LEN],
            len: 0,
            items: 0,
        };
        w.reset(sender, seq);
        w
    }

    /// Starts a new frame in the same buffer.
    pub fn reset(&mut self, sender: AgentId, seq: u16) {
        let header = FrameHeader {
            version: WIRE_VERSION,
            sender,
            seq,
        };
        self.items = 0;
        // The header is at most 5 bytes: it always fits.
        self.len = postcard::to_slice(&header, &mut self.buf).map_or(0, |used| used.len());
    }

    /// Appends `item` if it fits (leaving room for the CRC); returns whether it did.
    pub fn push(&mut self, item: &WireItem) -> bool {
        if self.items >= MAX_ITEMS_PER_FRAME {
            return false;
        }
        let Some(rest) = self.buf.get_mut(self.len..MAX_FRAME_LEN - CRC_LEN) else {
            return false;
        };
        match postcard::to_slice(item, rest) {
            Ok(used) => {
                self.len += used.len();
                self.items += 1;
                true
            }
            Err(_) => false,
        }
    }

    /// Number of items pushed so far.
    pub fn items(&self) -> usize {
        self.items
    }

    /// Appends the CRC and returns the finished frame bytes.
    pub fn finish(&mut self) -> &[u8] {
        let crc = CRC16.checksum(self.buf.get(..self.len).unwrap_or(&[]));
        if let Some(dst) = self.buf.get_mut(self.len..self.len + CRC_LEN) {
            dst.copy_from_slice(&crc.to_le_bytes());
            self.len += CRC_LEN;
        }
        self.buf.get(..self.len).unwrap_or(&[])
    }
}

/// A decoded and checked frame.
#[derive(Clone, Debug, PartialEq)]
pub struct Frame {
    /// Its header.
    pub header: FrameHeader,
    /// Its items, in order.
    pub items: heapless::Vec<WireItem, MAX_ITEMS_PER_FRAME>,
}

/// A frame whose length, CRC and version are checked; its items are decoded lazily, in
/// place, by [`FrameView::items`] (no copy of the frame).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct FrameView<'a> {
    /// The header.
    pub header: FrameHeader,
    items: &'a [u8],
}

impl<'a> FrameView<'a> {
    /// Iterates the items; a malformed item ends the iteration with an error.
    pub fn items(&self) -> Items<'a> {
        Items { rest: self.items }
    }

    /// Checks every item (decodes and values) without keeping them.
    pub fn validate(&self, bearing_tolerance: f32) -> Result<(), FrameError> {
        for item in self.items() {
            if !item_valid(&item?, bearing_tolerance) {
                return Err(FrameError::InvalidValue);
            }
        }
        Ok(())
    }
}

/// Iterator over the items of a [`FrameView`].
#[derive(Clone, Debug)]
pub struct Items<'a> {
    rest: &'a [u8],
}

impl Iterator for Items<'_> {
    type Item = Result<WireItem, FrameError>;

    fn next(&mut self) -> Option<Self::Item> {
        if self.rest.is_empty() {
            return None;
        }
        Some(match postcard::take_from_bytes::<WireItem>(self.rest) {
            Ok((item, rest)) => {
                self.rest = rest;
                Ok(item)
            }
            Err(_) => {
                self.rest = &[];
                Err(FrameError::Malformed)
            }
        })
    }
}

/// Checks length, CRC and version of one frame and returns a view of it. Never panics.
pub fn check_frame(bytes: &[u8]) -> Result<FrameView<'_>, FrameError> {
    if bytes.len() > MAX_FRAME_LEN {
        return Err(FrameError::TooLong);
    }
    let body_len = bytes
        .len()
        .checked_sub(CRC_LEN)
        .ok_or(FrameError::TooShort)?;
    let (body, crc) = bytes.split_at(body_len);
    let expected = u16::from_le_bytes([
        *crc.first().ok_or(FrameError::TooShort)?,
        *crc.get(1).ok_or(FrameError::TooShort)?,
    ]);
    if CRC16.checksum(body) != expected {
        return Err(FrameError::BadCrc);
    }
    let (header, items): (FrameHeader, &[u8]) =
        postcard::take_from_bytes(body).map_err(|_| FrameError::TooShort)?;
    if header.version != WIRE_VERSION {
        return Err(FrameError::UnknownVersion(header.version));
    }
    Ok(FrameView { header, items })
}

/// Decodes one frame completely and checks length, CRC, version and item values (finite,
/// unit bearings within `bearing_tolerance` on `|s|²`, positive estimates). Never panics.
/// (Agents use the copy-free [`check_frame`] + [`FrameView::validate`] instead.)
pub fn decode_frame(bytes: &[u8], bearing_tolerance: f32) -> Result<Frame, FrameError> {
    let view = check_frame(bytes)?;
    view.validate(bearing_tolerance)?;
    let mut items = heapless::Vec::new();
    for item in view.items() {
        items.push(item?).map_err(|_| FrameError::Malformed)?;
    }
    Ok(Frame {
        header: view.header,
        items,
    })
}

fn finite2(v: &[f32; 2]) -> bool {
    v[0].is_finite() && v[1].is_finite()
}

fn item_valid(item: &WireItem, tol: f32) -> bool {
    match item {
        WireItem::Velocity(v) => finite2(v),
        WireItem::Bearing { s, rate, .. } => {
            finite2(s) && finite2(rate) && ((s[0] * s[0] + s[1] * s[1]) - 1.0).abs() <= tol
        }
        WireItem::Estimate { r, .. } => r.is_finite() && *r > 0.0,
    }
}

/// COBS-encodes `frame` into `out` and appends the `0` delimiter; returns the length.
pub fn cobs_encode(frame: &[u8], out: &mut [u8]) -> Option<usize> {
    let n = cobs::try_encode(frame, out).ok()?;
    let end = out.get_mut(n)?;
    *end = 0;
    Some(n + 1)
}

/// Decodes one COBS chunk (without its `0` delimiter) into `out`; returns the length.
pub fn cobs_decode(chunk: &[u8], out: &mut [u8]) -> Result<usize, FrameError> {
    if chunk.len() > out.len() + 1 {
        return Err(FrameError::TooLong);
    }
    cobs::decode(chunk, out).map_err(|_| FrameError::Cobs)
}

/// Splits a byte stream at `0` delimiters and COBS-decodes each chunk (for UARTs).
#[derive(Clone, Debug)]
pub struct CobsAccumulator<const N: usize> {
    buf: [u8; N],
    len: usize,
    overflow: bool,
}

impl<const N: usize> Default for CobsAccumulator<N> {
    fn default() -> Self {
        Self {
            buf: [0; N],
            len: 0,
            overflow: false,
        }
    }
}

impl<const N: usize> CobsAccumulator<N> {
    /// An empty accumulator.
    pub fn new() -> Self {
        Self::default()
    }

    /// Feeds one byte. At a delimiter, returns the decoded frame (written to `out`) or an
    /// error for a chunk that overflowed `N` bytes or does not decode.
    pub fn push(&mut self, byte: u8, out: &mut [u8]) -> Option<Result<usize, FrameError>> {
        if byte == 0 {
            let result = if self.overflow {
                Err(FrameError::TooLong)
            } else {
                cobs_decode(self.buf.get(..self.len).unwrap_or(&[]), out)
            };
            self.len = 0;
            self.overflow = false;
            return Some(result);
        }
        match self.buf.get_mut(self.len) {
            Some(slot) => {
                *slot = byte;
                self.len += 1;
            }
            None => self.overflow = true,
        }
        None
    }
}
