//! Wire frames: versioned, sequence-numbered, CRC-checked postcard messages of at most
//! [`MAX_FRAME_LEN`] bytes (the Crazyflie peer-to-peer payload), and COBS framing for
//! byte streams (UART).
//!
//! Layout of one frame: `postcard(FrameHeader) ‖ postcard(WireItem)* ‖ CRC-16 (LE)`.
//! The CRC is CRC-16/IBM-SDLC (X-25, see [`crate::crc16`]) over everything before it. Items are packed
//! greedily; an agent whose data does not fit sends several frames, each with its own
//! sequence number.
//!
//! Values travel as `f32`. For `f64` agents this rounds every value to the nearest `f32`:
//! relative error at most 2⁻²⁴ ≈ 6·10⁻⁸ per component (tested in `tests/wire.rs`).

use crate::{crc16, AgentId};
use serde::{Deserialize, Serialize};

/// Largest encoded frame, in bytes (Crazyflie P2P payload limit).
pub const MAX_FRAME_LEN: usize = 60;
/// The wire-format version this crate writes and accepts.
pub const WIRE_VERSION: u8 = 2;
/// More items than one frame can hold (the smallest item is 9 bytes).
pub const MAX_ITEMS_PER_FRAME: usize = 8;
/// Largest COBS-encoded frame including the trailing zero delimiter.
pub const MAX_COBS_LEN: usize = MAX_FRAME_LEN + MAX_FRAME_LEN / 254 + 2;

const CRC_LEN: usize = 2;
/// Header bytes before the sequence number (version, sender).
const HEADER_FIXED: usize = 2;

/// Postcard variant indices of [`WireItem`] (one varint byte each).
const TAG_VELOCITY: u8 = 0;
const TAG_ANGLE: u8 = 1;
const TAG_ANGLE_BEARINGS: u8 = 2;
/// Encoded lengths (variant index included).
const LEN_VELOCITY: usize = 9;
const LEN_ANGLE: usize = 43;
const LEN_ANGLE_BEARINGS: usize = 35;

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

/// One piece of what an agent broadcasts (SPEC §6): its velocity, and for every
/// controlled angle of which it is the apex, what the angle's two far vertices need.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum WireItem {
    /// The sender's velocity `v_n` (world frame): for the range rates S3 of its
    /// neighbours' estimators and the leader's `ż` (S11).
    Velocity([f32; 2]),
    /// A controlled angle `α = (n; far[0], far[1])` whose apex `n` is the sender, with the
    /// estimates it owns (shared estimators, SPEC §6): far vertex `far[k]` takes the
    /// other far vertex's bearing and rate (S4, S5, S6) and `r[k]` (S8).
    Angle {
        /// The far vertices `v`, `w`.
        far: [AgentId; 2],
        /// Unit bearings `[s_nv, s_nw]`.
        s: [[f32; 2]; 2],
        /// Bearing rates `[ṡ_nv, ṡ_nw]`.
        rate: [[f32; 2]; 2],
        /// Estimates `[r̂_{α,nv}, r̂_{α,nw}] > 0`.
        r: [f32; 2],
    },
    /// The same angle without estimates (`PerAgent` and `Measured` modes).
    AngleBearings {
        /// The far vertices `v`, `w`.
        far: [AgentId; 2],
        /// Unit bearings `[s_nv, s_nw]`.
        s: [[f32; 2]; 2],
        /// Bearing rates `[ṡ_nv, ṡ_nw]`.
        rate: [[f32; 2]; 2],
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
        self.len = header.encode(&mut self.buf);
    }

    /// Appends `item` if it fits (leaving room for the CRC); returns whether it did.
    pub fn push(&mut self, item: &WireItem) -> bool {
        if self.items >= MAX_ITEMS_PER_FRAME {
            return false;
        }
        let Some(rest) = self.buf.get_mut(self.len..MAX_FRAME_LEN - CRC_LEN) else {
            return false;
        };
        match item.encode(rest) {
            Some(used) => {
                self.len += used;
                self.items += 1;
                true
            }
            None => false,
        }
    }

    /// Number of items pushed so far.
    pub fn items(&self) -> usize {
        self.items
    }

    /// Appends the CRC and returns the finished frame bytes.
    pub fn finish(&mut self) -> &[u8] {
        let crc = crc16::checksum(self.buf.get(..self.len).unwrap_or(&[]));
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
    /// The encoded items (everything between the header and the CRC).
    pub(crate) fn item_bytes(&self) -> &'a [u8] {
        self.items
    }

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
        Some(match WireItem::decode(&mut self.rest) {
            Some(item) => Ok(item),
            None => {
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
    if crc16::checksum(body) != expected {
        return Err(FrameError::BadCrc);
    }
    let mut items = body;
    let header = FrameHeader::decode(&mut items).ok_or(FrameError::TooShort)?;
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

/// Every value is finite: `x·0` is `±0` for finite `x` and NaN for `±∞` and NaN, so one
/// comparison checks them all (no branch per value).
#[inline(always)]
fn all_finite<const N: usize>(xs: [f32; N]) -> bool {
    let mut acc = 0.0f32;
    for x in xs {
        acc += x * 0.0;
    }
    acc == 0.0
}

#[inline(always)]
fn finite2(v: &[f32; 2]) -> bool {
    all_finite(*v)
}

/// `| |s|² − 1 | ≤ tol` (for finite `s`).
#[inline(always)]
fn unit(s: &[f32; 2], tol: f32) -> bool {
    ((s[0] * s[0] + s[1] * s[1]) - 1.0).abs() <= tol
}

#[inline(always)]
fn bearings_valid(s: &[[f32; 2]; 2], rate: &[[f32; 2]; 2], tol: f32) -> bool {
    let [[a, b], [c, d]] = *s;
    let [[e, f], [g, h]] = *rate;
    all_finite([a, b, c, d, e, f, g, h]) & unit(&s[0], tol) & unit(&s[1], tol)
}

/// Estimates are finite and positive.
#[inline(always)]
fn estimates_valid(r: &[f32; 2]) -> bool {
    all_finite(*r) & (r[0] > 0.0) & (r[1] > 0.0)
}

/// Values of an item are acceptable: finite, unit bearings within `tol` on `|s|²`, and
/// positive estimates.
pub(crate) fn item_valid(item: &WireItem, tol: f32) -> bool {
    match item {
        WireItem::Velocity(v) => finite2(v),
        WireItem::Angle { s, rate, r, .. } => bearings_valid(s, rate, tol) & estimates_valid(r),
        WireItem::AngleBearings { s, rate, .. } => bearings_valid(s, rate, tol),
    }
}

// ---------------------------------------------------------------- postcard codec
//
// Frames are encoded and decoded by hand, in exactly postcard's format: the serde derives
// on `FrameHeader` and `WireItem` describe the same bytes, and `tests/wire.rs` checks both
// directions against `postcard` itself on random input. The generic serde path costs
// several times more instructions per item on the Cortex-M4. The postcard rules used:
// `u8` is one raw byte; `u16` and `u32` are LEB128 varints (at most 3 and 5 bytes, the
// last byte at most 0x03 and 0x0F, longer-than-needed forms accepted); `f32` is 4
// little-endian bytes; an enum is its variant index (a `u32` varint) followed by its
// fields; structs and arrays are their fields in order.

/// Takes the next `N` bytes.
#[inline(always)]
fn take<const N: usize>(rest: &mut &[u8]) -> Option<[u8; N]> {
    split(rest).copied()
}

/// Postcard `u16`/`u32` varint of at most `MAX` bytes whose last byte is at most `LAST`.
#[inline(always)]
fn take_varint<const MAX: u32, const LAST: u8>(rest: &mut &[u8]) -> Option<u32> {
    let mut out = 0u32;
    for i in 0..MAX {
        let [b] = take::<1>(rest)?;
        out |= u32::from(b & 0x7F) << (7 * i);
        if b & 0x80 == 0 {
            return (i + 1 < MAX || b <= LAST).then_some(out);
        }
    }
    None
}

/// The `f32` at byte `at` of `b` (constant offsets: the check compiles away).
#[inline(always)]
fn get_f32(b: &[u8], at: usize) -> f32 {
    match b.get(at..at + 4) {
        Some(&[b0, b1, b2, b3]) => f32::from_le_bytes([b0, b1, b2, b3]),
        _ => 0.0,
    }
}

#[inline(always)]
fn get_pair(b: &[u8], at: usize) -> [f32; 2] {
    [get_f32(b, at), get_f32(b, at + 4)]
}

#[inline(always)]
fn set_f32(b: &mut [u8], at: usize, x: f32) {
    if let Some(d) = b.get_mut(at..at + 4) {
        d.copy_from_slice(&x.to_le_bytes());
    }
}

#[inline(always)]
fn set_pair(b: &mut [u8], at: usize, x: &[f32; 2]) {
    set_f32(b, at, x[0]);
    set_f32(b, at + 4, x[1]);
}

impl FrameHeader {
    /// Writes the postcard encoding into `out`; returns its length.
    fn encode(&self, out: &mut [u8; MAX_FRAME_LEN]) -> usize {
        let s = self.seq;
        let (lo, mid, hi) = ((s & 0x7F) as u8, ((s >> 7) & 0x7F) as u8, (s >> 14) as u8);
        out[0] = self.version;
        out[1] = self.sender;
        if s < 0x80 {
            out[2] = lo;
            3
        } else if s < 0x4000 {
            out[2] = lo | 0x80;
            out[3] = mid;
            4
        } else {
            out[2] = lo | 0x80;
            out[3] = mid | 0x80;
            out[4] = hi;
            5
        }
    }

    /// Decodes a header from the front of `rest`.
    fn decode(rest: &mut &[u8]) -> Option<Self> {
        let [version, sender] = take::<HEADER_FIXED>(rest)?;
        let seq = take_varint::<3, 0x03>(rest)?;
        Some(Self {
            version,
            sender,
            seq: seq as u16,
        })
    }
}

impl WireItem {
    /// Length of the encoding in bytes (variant index + fields).
    pub const fn encoded_len(&self) -> usize {
        match self {
            WireItem::Velocity(_) => LEN_VELOCITY,
            WireItem::Angle { .. } => LEN_ANGLE,
            WireItem::AngleBearings { .. } => LEN_ANGLE_BEARINGS,
        }
    }

    /// Writes the postcard encoding at the start of `out`; `None` if it does not fit.
    fn encode(&self, out: &mut [u8]) -> Option<usize> {
        let len = self.encoded_len();
        let b = out.get_mut(..len)?;
        match self {
            WireItem::Velocity(v) => {
                if let Some(t) = b.first_mut() {
                    *t = TAG_VELOCITY;
                }
                set_pair(b, 1, v);
            }
            WireItem::Angle { far, s, rate, r } => {
                encode_angle(b, TAG_ANGLE, far, s, rate);
                set_pair(b, 35, r);
            }
            WireItem::AngleBearings { far, s, rate } => {
                encode_angle(b, TAG_ANGLE_BEARINGS, far, s, rate);
            }
        }
        Some(len)
    }

    /// Decodes one item from the front of `rest` (`None`: malformed or truncated).
    pub(crate) fn decode(rest: &mut &[u8]) -> Option<Self> {
        RawItem::next(rest).map(|raw| raw.item())
    }
}

/// One item of a frame, split off but not decoded: its field bytes, by variant.
/// Receiving agents check and read items through it without copying them.
#[derive(Clone, Copy, Debug)]
pub(crate) enum RawItem<'a> {
    Velocity(&'a [u8; LEN_VELOCITY - 1]),
    Angle(&'a [u8; LEN_ANGLE - 1]),
    AngleBearings(&'a [u8; LEN_ANGLE_BEARINGS - 1]),
}

/// Splits `N` bytes off the front of `rest`.
#[inline(always)]
fn split<'a, const N: usize>(rest: &mut &'a [u8]) -> Option<&'a [u8; N]> {
    let (head, tail) = rest.split_first_chunk::<N>()?;
    *rest = tail;
    Some(head)
}

impl<'a> RawItem<'a> {
    /// Splits the next item off the front of `rest` (`None`: malformed or truncated).
    #[inline(always)]
    pub(crate) fn next(rest: &mut &'a [u8]) -> Option<Self> {
        match take_varint::<5, 0x0F>(rest)? {
            0 => split(rest).map(RawItem::Velocity),
            1 => split(rest).map(RawItem::Angle),
            2 => split(rest).map(RawItem::AngleBearings),
            _ => None,
        }
    }

    /// The bytes an angle item shares with its estimate-less form: far vertices, bearings
    /// and rates.
    #[inline(always)]
    fn angle_part(&self) -> Option<&'a [u8; LEN_ANGLE_BEARINGS - 1]> {
        match *self {
            RawItem::Velocity(_) => None,
            RawItem::Angle(b) => b.first_chunk(),
            RawItem::AngleBearings(b) => Some(b),
        }
    }

    /// The decoded item.
    pub(crate) fn item(&self) -> WireItem {
        match *self {
            RawItem::Velocity(b) => WireItem::Velocity(get_pair(b, 0)),
            RawItem::Angle(b) => WireItem::Angle {
                far: angle_far(b),
                s: [get_pair(b, 2), get_pair(b, 10)],
                rate: [get_pair(b, 18), get_pair(b, 26)],
                r: get_pair(b, 34),
            },
            RawItem::AngleBearings(b) => WireItem::AngleBearings {
                far: angle_far(b),
                s: [get_pair(b, 2), get_pair(b, 10)],
                rate: [get_pair(b, 18), get_pair(b, 26)],
            },
        }
    }

    /// [`item_valid`] on the undecoded item.
    #[inline(always)]
    pub(crate) fn valid(&self, tol: f32) -> bool {
        let bearings = |b: &[u8; LEN_ANGLE_BEARINGS - 1]| {
            bearings_valid(
                &[get_pair(b, 2), get_pair(b, 10)],
                &[get_pair(b, 18), get_pair(b, 26)],
                tol,
            )
        };
        match *self {
            RawItem::Velocity(b) => finite2(&get_pair(b, 0)),
            RawItem::AngleBearings(b) => bearings(b),
            RawItem::Angle(b) => {
                b.first_chunk().is_some_and(bearings) & estimates_valid(&get_pair(b, 34))
            }
        }
    }

    /// A velocity item's value.
    #[inline(always)]
    pub(crate) fn velocity(&self) -> Option<[f32; 2]> {
        match *self {
            RawItem::Velocity(b) => Some(get_pair(b, 0)),
            _ => None,
        }
    }

    /// An angle item's far vertices.
    #[inline(always)]
    pub(crate) fn far(&self) -> Option<[AgentId; 2]> {
        self.angle_part().map(|b| angle_far(b))
    }

    /// An angle item's bearing and rate to far vertex `k` (0, else 1).
    #[inline(always)]
    pub(crate) fn bearing(&self, k: usize) -> ([f32; 2], [f32; 2]) {
        match (self.angle_part(), k) {
            (Some(b), 0) => (get_pair(b, 2), get_pair(b, 18)),
            (Some(b), _) => (get_pair(b, 10), get_pair(b, 26)),
            (None, _) => ([0.0; 2], [0.0; 2]),
        }
    }

    /// An angle item's estimate of the edge to far vertex `k` (0, else 1), if it carries
    /// estimates.
    #[inline(always)]
    pub(crate) fn estimate(&self, k: usize) -> Option<f32> {
        match *self {
            RawItem::Angle(b) => Some(get_f32(b, if k == 0 { 34 } else { 38 })),
            _ => None,
        }
    }
}

/// Variant index, far vertices, bearings and rates of an angle item (fields in order).
#[inline(always)]
fn encode_angle(
    b: &mut [u8],
    tag: u8,
    far: &[AgentId; 2],
    s: &[[f32; 2]; 2],
    rate: &[[f32; 2]; 2],
) {
    if let Some(h) = b.get_mut(..3) {
        h.copy_from_slice(&[tag, far[0], far[1]]);
    }
    set_pair(b, 3, &s[0]);
    set_pair(b, 11, &s[1]);
    set_pair(b, 19, &rate[0]);
    set_pair(b, 27, &rate[1]);
}

#[inline(always)]
fn angle_far(b: &[u8]) -> [AgentId; 2] {
    match b.get(..2) {
        Some(&[v, w]) => [v, w],
        _ => [0, 0],
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
