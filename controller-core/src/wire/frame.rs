//! The frame as a serde type: the bytes on the air are postcard of [`Frame`] and the
//! integrity trailer (layout and the reasons in [`super`]).

use super::auth::{self, Counter, TAG_LEN};
use super::{
    items_of_mode, mode_byte, mode_with_items, quant, FrameError, FrameHeader, Integrity,
    MAX_ANGLES_PER_FRAME, MAX_FRAME_LEN,
};
use crate::config::EstimatorMode;
use crate::{crc16, AgentId};
use core::fmt;
use serde::de::{self, Deserializer, SeqAccess, Visitor};
use serde::ser::{self, SerializeTuple, Serializer};
use serde::{Deserialize, Serialize};

/// An IEEE 754 binary16 code as it travels: 2 bytes little-endian (postcard `fixint`).
/// See [`quant`] for the rounding.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct F16(#[serde(with = "postcard::fixint::le")] pub u16);

impl F16 {
    /// The value; `None` for the codes of infinity and NaN.
    pub fn value(self) -> Option<f32> {
        quant::decode(self.0)
    }
}

impl From<F16> for f32 {
    /// The value (NaN for the codes of infinity and NaN, which no valid frame carries).
    fn from(x: F16) -> f32 {
        x.value().unwrap_or(f32::NAN)
    }
}

impl From<F16> for f64 {
    /// The value (NaN for the codes of infinity and NaN, which no valid frame carries).
    fn from(x: F16) -> f64 {
        f64::from(f32::from(x))
    }
}

/// One angle item (fields and ranges: see [`super`]): 10 bytes.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct AngleItem {
    /// The far vertices `v`, `w` of the angle `(sender; v, w)`.
    pub far: [AgentId; 2],
    /// `γ_α` (S7).
    pub gamma: F16,
    /// `σ_α = s_nv × s_nw`.
    pub sigma: F16,
    /// `[r_v, r_w]`: the distances the apex used.
    pub range: [F16; 2],
}

/// `auth`: the high 48 bits of the sender's counter (see [`auth`]), carried by every
/// frame with room for it (at most 3 items): 6 bytes.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct CounterExt {
    /// The sender's boot epoch.
    #[serde(with = "postcard::fixint::le")]
    pub epoch: u32,
    /// Bits 16–31 of the sender's frame number (bits 0–15 are the sequence number).
    #[serde(with = "postcard::fixint::le")]
    pub high: u16,
}

impl CounterExt {
    /// The extension of a full counter.
    pub const fn of_counter(c: Counter) -> Self {
        Self {
            epoch: (c >> 32) as u32,
            high: (c >> 16) as u16,
        }
    }

    /// The full counter of a frame with this extension and sequence number `seq`.
    pub const fn counter(self, seq: u16) -> Counter {
        auth::counter(self.epoch, ((self.high as u32) << 16) | seq as u32)
    }
}

/// The sequence number as it travels: `u16` little-endian (postcard `fixint`).
#[derive(Serialize, Deserialize)]
struct Seq(#[serde(with = "postcard::fixint::le")] u16);

/// One frame, as defined: its bytes on the air are `postcard::to_slice` of it followed by
/// the integrity trailer ([`Frame::encode`], [`Frame::decode`]; layout in [`super`]).
///
/// In serde's data model a frame is a tuple: the mode byte (`u8`; bits 7–4 `8 +` the
/// number of items, bits 3–0 the modes of [`FrameHeader::mode`]), the sender (`u8`), the
/// sequence number (`u16`, `fixint`), the velocity (`[f32; 2]`), the items
/// ([`AngleItem`], as many as the mode byte says) and, with `auth` and at most 3 items,
/// the [`CounterExt`]. The mode byte is the home of postcard's item count (see
/// [`super`], "Where postcard's item count lives"), so these two impls are written by
/// hand; every element is a derived type.
#[derive(Clone, Debug, PartialEq)]
pub struct Frame {
    /// The header; its mode byte without the item count ([`super::mode_byte`]).
    pub header: FrameHeader,
    /// The sender's velocity.
    pub velocity: [f32; 2],
    /// The angle items.
    pub angles: heapless::Vec<AngleItem, MAX_ANGLES_PER_FRAME>,
    /// `auth`: the counter extension, exactly when the frame has at most 3 items; `None`
    /// in the other integrity modes.
    pub counter_ext: Option<CounterExt>,
}

/// Whether a frame with `items` items and these modes (bits 3–2 of `mode`: integrity)
/// carries the counter extension: `auth` with room for it.
const fn carries_extension(mode: u8, items: usize) -> bool {
    (mode >> 2) & 0b11 == AUTH_CODE && items < MAX_ANGLES_PER_FRAME
}

/// The integrity code of `auth` (the key does not matter).
const AUTH_CODE: u8 = Integrity::Auth(super::SwarmKey::new([0; 16])).code();

/// Elements of the longest frame tuple: mode, sender, sequence number, velocity, items.
const MAX_ELEMENTS: usize = 4 + MAX_ANGLES_PER_FRAME;

impl Serialize for Frame {
    fn serialize<S: Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
        let k = self.angles.len();
        let mode = self.header.mode;
        if items_of_mode(mode) != Some(0) {
            return Err(ser::Error::custom(
                "header.mode is not a version-4 mode byte without items (mode_byte)",
            ));
        }
        if self.counter_ext.is_some() != carries_extension(mode, k) {
            return Err(ser::Error::custom(
                "counter extension present other than with auth and at most 3 items",
            ));
        }
        let ext = usize::from(self.counter_ext.is_some());
        let mut t = serializer.serialize_tuple(4 + k + ext)?;
        t.serialize_element(&mode_with_items(mode, k))?;
        t.serialize_element(&self.header.sender)?;
        t.serialize_element(&Seq(self.header.seq))?;
        t.serialize_element(&self.velocity)?;
        for a in &self.angles {
            t.serialize_element(a)?;
        }
        if let Some(e) = &self.counter_ext {
            t.serialize_element(e)?;
        }
        t.end()
    }
}

impl<'de> Deserialize<'de> for Frame {
    fn deserialize<D: Deserializer<'de>>(deserializer: D) -> Result<Self, D::Error> {
        deserializer.deserialize_tuple(MAX_ELEMENTS, FrameVisitor)
    }
}

/// Reads the tuple of [`Frame`]: the mode byte first, which says what follows.
struct FrameVisitor;

/// The next element of the frame tuple, which must be there.
fn element<'de, A: SeqAccess<'de>, T: Deserialize<'de>>(seq: &mut A) -> Result<T, A::Error> {
    seq.next_element()?
        .ok_or_else(|| de::Error::custom("frame ends early"))
}

impl<'de> Visitor<'de> for FrameVisitor {
    type Value = Frame;

    fn expecting(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str("a wire-version-4 frame")
    }

    fn visit_seq<A: SeqAccess<'de>>(self, mut seq: A) -> Result<Frame, A::Error> {
        let on_air: u8 = element(&mut seq)?;
        let k = items_of_mode(on_air).ok_or_else(|| {
            de::Error::invalid_value(
                de::Unexpected::Unsigned(u64::from(on_air)),
                &"a mode byte with bits 7-4 in 8..=12 (wire version 4)",
            )
        })?;
        let sender: AgentId = element(&mut seq)?;
        let Seq(seq_no) = element(&mut seq)?;
        let velocity: [f32; 2] = element(&mut seq)?;
        let mut angles = heapless::Vec::new();
        for _ in 0..k {
            angles
                .push(element::<A, AngleItem>(&mut seq)?)
                .map_err(|_| de::Error::custom("more items than a frame holds"))?;
        }
        let counter_ext = if carries_extension(on_air, k) {
            Some(element(&mut seq)?)
        } else {
            None
        };
        Ok(Frame {
            header: FrameHeader {
                mode: mode_with_items(on_air, 0),
                sender,
                seq: seq_no,
            },
            velocity,
            angles,
            counter_ext,
        })
    }
}

impl Frame {
    /// The frame's bytes for `integrity`: `postcard::to_slice` of it, then the trailer
    /// (CRC-16/IBM-SDLC, nothing, or the SipHash-2-4 tag with `counter`, the frame's full
    /// counter; `counter` is unused in the other modes). [`FrameError::ModeMismatch`] if
    /// the header's integrity bits are not `integrity`'s, [`FrameError::Malformed`] if
    /// postcard refuses the frame (a mode byte with items, or a counter extension other
    /// than with `auth` and at most 3 items), [`FrameError::TooLong`] beyond
    /// [`MAX_FRAME_LEN`]. The definition the fast writer ([`super::FrameWriter`]) is
    /// proven equal to.
    pub fn encode<'b>(
        &self,
        integrity: &Integrity,
        counter: Counter,
        buf: &'b mut [u8; MAX_FRAME_LEN],
    ) -> Result<&'b [u8], FrameError> {
        if (self.header.mode >> 2) & 0b11 != integrity.code() {
            return Err(FrameError::ModeMismatch(self.header.mode));
        }
        let body = match postcard::to_slice(self, buf) {
            Ok(b) => b.len(),
            Err(postcard::Error::SerializeBufferFull) => return Err(FrameError::TooLong),
            Err(_) => return Err(FrameError::Malformed),
        };
        let end = body + integrity.trailer_len();
        let (signed, rest) = buf.split_at_mut_checked(body).ok_or(FrameError::TooLong)?;
        let trailer = rest
            .get_mut(..integrity.trailer_len())
            .ok_or(FrameError::TooLong)?;
        match integrity {
            Integrity::Crc16 => trailer.copy_from_slice(&crc16::checksum(signed).to_le_bytes()),
            Integrity::Link => {}
            Integrity::Auth(key) => trailer.copy_from_slice(&auth::tag(key, counter, signed)),
        }
        buf.get(..end).ok_or(FrameError::TooLong)
    }

    /// Decodes and checks a frame for a receiver with `integrity` and `estimator` mode
    /// with postcard's deserializer: length and trailer (CRC, or in `auth` mode the tag
    /// with the counter the frame carries, [`FrameError::Unsynced`] without), then
    /// `postcard::take_from_bytes` of the bytes before the trailer, which must consume
    /// them all, the receiver's modes, then the values ([`Frame::check_values`]). The
    /// definition the fast decoder ([`super::decode_frame`]) is proven equal to; it keeps
    /// no state (no replay check: agents use [`crate::Agent::receive`]). Never panics.
    pub fn decode(
        bytes: &[u8],
        integrity: Integrity,
        estimator: EstimatorMode,
    ) -> Result<Frame, FrameError> {
        if bytes.len() > MAX_FRAME_LEN {
            return Err(FrameError::TooLong);
        }
        let (body, trailer) = bytes
            .split_at_checked(bytes.len().wrapping_sub(integrity.trailer_len()))
            .ok_or(FrameError::TooShort)?;
        if let (Integrity::Crc16, Some(crc)) = (integrity, trailer.first_chunk::<2>()) {
            if crc16::checksum(body) != u16::from_le_bytes(*crc) {
                return Err(FrameError::BadCrc);
            }
        }
        let frame = match postcard::take_from_bytes::<Frame>(body) {
            Ok((frame, [])) => frame,
            Ok(_) => return Err(FrameError::Malformed),
            Err(postcard::Error::DeserializeUnexpectedEnd) => return Err(FrameError::TooShort),
            Err(_) => {
                return Err(match body.first() {
                    Some(&m) if items_of_mode(m).is_none() => FrameError::UnknownVersion(m >> 4),
                    _ => FrameError::Malformed,
                })
            }
        };
        if frame.header.mode != mode_byte(integrity, estimator) {
            return Err(FrameError::ModeMismatch(mode_with_items(
                frame.header.mode,
                frame.angles.len(),
            )));
        }
        if let (Integrity::Auth(key), Some(tag)) = (&integrity, trailer.first_chunk::<TAG_LEN>()) {
            let ext = frame
                .counter_ext
                .ok_or(FrameError::Unsynced(frame.header.sender))?;
            if !auth::verify(key, ext.counter(frame.header.seq), body, tag) {
                return Err(FrameError::BadTag);
            }
        }
        frame.check_values()?;
        Ok(frame)
    }

    /// Checks the values as a receiver does that accepts any positive distance: a finite
    /// velocity ([`FrameError::InvalidValue`]), two distinct far vertices per item
    /// ([`FrameError::Malformed`]), a finite `γ`, `|σ| ≤ 1`, finite distances `r > 0`
    /// ([`FrameError::InvalidValue`]). Written with floats, apart from the fast path's
    /// checks on the codes ([`super::FrameView::validate`]).
    pub fn check_values(&self) -> Result<(), FrameError> {
        if !self.velocity.iter().all(|v| v.is_finite()) {
            return Err(FrameError::InvalidValue);
        }
        let mut valid = true;
        for a in &self.angles {
            if a.far[0] == a.far[1] {
                return Err(FrameError::Malformed);
            }
            let finite = |x: F16| x.value().filter(|v| v.is_finite());
            valid &= finite(a.gamma).is_some()
                && finite(a.sigma).is_some_and(|s| s.abs() <= 1.0)
                && a.range.iter().all(|&r| finite(r).is_some_and(|r| r > 0.0));
        }
        if valid {
            Ok(())
        } else {
            Err(FrameError::InvalidValue)
        }
    }
}
