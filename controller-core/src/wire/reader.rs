//! Checking and reading frames in place (layout in [`super`]).

use super::auth::{self, Counter, SwarmKey, TAG_LEN};
use super::frame::{AngleItem, CounterExt, Frame, F16};
use super::{
    items_of_mode, mode_byte, mode_with_items, offset, FrameError, FrameHeader, Integrity,
    ANGLE_ITEM_LEN, FIXED_LEN, MAX_ANGLES_PER_FRAME, MAX_FRAME_LEN,
};
use crate::config::EstimatorMode;
use crate::{crc16, AgentId};

/// One angle item's bytes: far vertices and the binary16 codes of `[γ, σ, r_v, r_w]`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) struct RawAngle {
    /// The far vertices.
    pub far: [AgentId; 2],
    /// The codes of `[γ, σ, r_v, r_w]`.
    pub codes: [u16; 4],
}

// The destructuring patterns below read the fields in the documented order.
const _: () = assert!(
    offset::MODE == 0
        && offset::SENDER == 1
        && offset::SEQ == 2
        && offset::VELOCITY == 4
        && offset::ANGLES == FIXED_LEN
        && FIXED_LEN == 12
        && offset::ITEM_FAR0 == 0
        && offset::ITEM_FAR1 == 1
        && offset::ITEM_GAMMA == 2
        && offset::ITEM_SIGMA == 4
        && offset::ITEM_RHO0 == 6
        && offset::ITEM_RHO1 == 8
        && ANGLE_ITEM_LEN == 10
);

impl RawAngle {
    #[inline(always)]
    fn of(b: &[u8; ANGLE_ITEM_LEN]) -> Self {
        // Five little-endian 16-bit words (half-word loads on target): the far vertices,
        // then the codes.
        let [far, g, s, r0, r1] = b.as_chunks::<2>().0 else {
            // Unreachable: ten bytes are five pairs (the check folds away).
            return Self {
                far: [0; 2],
                codes: [0; 4],
            };
        };
        let code = |c: &[u8; 2]| u16::from_le_bytes(*c);
        Self {
            far: *far,
            codes: [code(g), code(s), code(r0), code(r1)],
        }
    }
}

/// binary16 `1.0` (`|σ| ≤ 1`).
const F16_ONE: u16 = 0x3C00;

/// A frame whose length, trailer, version and modes are checked; its items are read in
/// place (no copy of the frame).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FrameView<'a> {
    /// The header.
    pub header: FrameHeader,
    /// The sender's velocity (not yet checked for finiteness: see [`FrameView::validate`]).
    pub velocity: [f32; 2],
    /// The angle items.
    items: &'a [[u8; ANGLE_ITEM_LEN]],
    /// `auth`: the bytes before the tag, the tag, and the counter the frame carries.
    signed: Option<Signed<'a>>,
}

/// The authenticated part of an `auth` frame.
#[derive(Clone, Copy, Debug, PartialEq)]
struct Signed<'a> {
    /// Every byte before the tag.
    bytes: &'a [u8],
    /// The tag.
    tag: &'a [u8; TAG_LEN],
    /// The full counter, if the frame carries the extension.
    counter: Option<Counter>,
}

impl<'a> FrameView<'a> {
    /// Number of angle items.
    pub fn len(&self) -> usize {
        self.items.len()
    }

    /// No angle items.
    pub fn is_empty(&self) -> bool {
        self.items.is_empty()
    }

    /// `auth`: the sender's full counter, if the frame carries the counter extension
    /// (see [`super::auth`]); `None` otherwise and in the other integrity modes.
    pub fn carried_counter(&self) -> Option<Counter> {
        self.signed.and_then(|s| s.counter)
    }

    /// `auth`: checks the tag of the frame as sent with `counter` (in constant time);
    /// [`FrameError::BadTag`] if it does not verify or the frame has no tag.
    #[inline]
    pub fn verify_tag(&self, key: &SwarmKey, counter: Counter) -> Result<(), FrameError> {
        match self.signed {
            Some(s) if auth::verify(key, counter, s.bytes, s.tag) => Ok(()),
            _ => Err(FrameError::BadTag),
        }
    }

    /// The raw items.
    #[inline(always)]
    pub(crate) fn raw_items(&self) -> impl Iterator<Item = RawAngle> + 'a {
        self.items.iter().map(RawAngle::of)
    }

    /// Checks every value: a finite velocity, and per item two distinct far vertices, a
    /// finite `γ`, `|σ| ≤ 1`, and distances at least `range_min` (a binary16 code of a
    /// positive value: the receiver's `r_min` as rounded, or 1 for any positive value).
    /// Reads nothing but bits (no float conversion: binary16 codes of positive values are
    /// ordered like the values). Always inlined: the receiver's view stays in registers.
    #[inline(always)]
    pub fn validate(&self, range_min: u16) -> Result<(), FrameError> {
        let [vx, vy] = self.velocity;
        // `x·0` is ±0 for finite `x` and NaN otherwise: one comparison for both.
        if vx * 0.0 + vy * 0.0 != 0.0 {
            return Err(FrameError::InvalidValue);
        }
        let mut ok = true;
        for it in self.raw_items() {
            if it.far[0] == it.far[1] {
                return Err(FrameError::Malformed);
            }
            let [gamma, sigma, range0, range1] = it.codes;
            // Exponent all ones: ∞ or NaN. Positive finite values are 0x0001..=0x7BFF.
            let distance = |c: u16| (c >= range_min) & (c < 0x7C00);
            ok &= (gamma & 0x7C00 != 0x7C00)
                & (sigma & 0x7FFF <= F16_ONE)
                & distance(range0)
                & distance(range1);
        }
        if ok {
            Ok(())
        } else {
            Err(FrameError::InvalidValue)
        }
    }

    /// The angle items (their values unchecked until [`FrameView::validate`]).
    pub fn angles(&self) -> impl Iterator<Item = AngleItem> + 'a {
        self.raw_items().map(|it| {
            let [g, s, r0, r1] = it.codes;
            AngleItem {
                far: it.far,
                gamma: F16(g),
                sigma: F16(s),
                range: [F16(r0), F16(r1)],
            }
        })
    }
}

/// Checks length, trailer, version and modes of one frame for a receiver with
/// `integrity` and `estimator` mode, and returns a view of it. Never panics.
///
/// In `auth` mode the tag is *not* checked here: it depends on the sender's counter,
/// which only a receiver that tracks the sender can know (see
/// [`FrameView::verify_tag`], [`crate::Agent::receive`] and [`decode_frame`]).
#[inline]
pub fn check_frame(
    bytes: &[u8],
    integrity: Integrity,
    estimator: EstimatorMode,
) -> Result<FrameView<'_>, FrameError> {
    check_mode(bytes, integrity, mode_byte(integrity, estimator), None)
}

/// [`check_frame`] against the receiver's mode byte (see [`super::mode_byte`]), with the
/// result of the CRC check if it is already known for these bytes (`crc_ok`, see
/// [`super::CrcCheck`]). Always inlined: where `integrity` is a constant, the other
/// modes' checks fold away.
#[inline(always)]
pub(crate) fn check_mode(
    bytes: &[u8],
    integrity: Integrity,
    expected_mode: u8,
    crc_ok: Option<bool>,
) -> Result<FrameView<'_>, FrameError> {
    if bytes.len() > MAX_FRAME_LEN {
        return Err(FrameError::TooLong);
    }
    let (body, trailer) = bytes
        .split_at_checked(bytes.len().wrapping_sub(integrity.trailer_len()))
        .ok_or(FrameError::TooShort)?;
    let (head, items) = body
        .split_first_chunk::<FIXED_LEN>()
        .ok_or(FrameError::TooShort)?;
    if let (Integrity::Crc16, [c0, c1]) = (integrity, trailer) {
        let ok = match crc_ok {
            Some(ok) => ok,
            None => crc16::checksum(body) == u16::from_le_bytes([*c0, *c1]),
        };
        if !ok {
            return Err(FrameError::BadCrc);
        }
    }
    // The velocity as two 4-byte arrays: one (unaligned) word load each on target.
    let [mode, sender, q0, q1, ref velocity @ ..] = *head;
    let [ref vx @ .., _, _, _, _] = *velocity;
    let [_, _, _, _, ref vy @ ..] = *velocity;
    // Bits 7–4: 8 + the item count (version 4); bits 3–0: the modes. With the expected
    // mode byte's nibble 8, `mode − expected` is `0x10 · count` exactly when the modes
    // agree and the nibble is 8..=12: one subtraction, one rotation, one comparison.
    let count = mode.wrapping_sub(expected_mode).rotate_right(4);
    if usize::from(count) > MAX_ANGLES_PER_FRAME {
        return Err(mode_error(mode));
    }
    let seq = u16::from_le_bytes([q0, q1]);
    let (items, rest) = items.as_chunks::<ANGLE_ITEM_LEN>();
    if items.len() != usize::from(count) {
        return Err(FrameError::Malformed);
    }
    // `auth`: the counter extension exactly when there is room for it (at most 3 items).
    let signed = match (integrity, rest, trailer.first_chunk::<TAG_LEN>()) {
        (Integrity::Auth(_), [], Some(tag)) if usize::from(count) == MAX_ANGLES_PER_FRAME => {
            Some(Signed {
                bytes: body,
                tag,
                counter: None,
            })
        }
        (Integrity::Auth(_), [e0, e1, e2, e3, h0, h1], Some(tag))
            if usize::from(count) < MAX_ANGLES_PER_FRAME =>
        {
            let epoch = u32::from_le_bytes([*e0, *e1, *e2, *e3]);
            let high = u32::from(u16::from_le_bytes([*h0, *h1]));
            Some(Signed {
                bytes: body,
                tag,
                counter: Some(auth::counter(epoch, (high << 16) | u32::from(seq))),
            })
        }
        (Integrity::Crc16 | Integrity::Link, [], _) => None,
        _ => return Err(FrameError::Malformed),
    };
    Ok(FrameView {
        header: FrameHeader {
            mode: mode_with_items(mode, 0),
            sender,
            seq,
        },
        velocity: [f32::from_le_bytes(*vx), f32::from_le_bytes(*vy)],
        items,
        signed,
    })
}

/// Why a mode byte is not the receiver's (cold): another version, or other modes.
#[cold]
fn mode_error(mode: u8) -> FrameError {
    match items_of_mode(mode) {
        None => FrameError::UnknownVersion(mode >> 4),
        Some(_) => FrameError::ModeMismatch(mode),
    }
}

/// Checks a frame ([`check_frame`] and [`FrameView::validate`] with any positive
/// distance) and decodes it: the fast path's decoder, equal to the postcard decoder
/// [`Frame::decode`] on every input (`tests/wire_postcard.rs`). Never panics.
///
/// In `auth` mode it also verifies the tag with the counter the frame carries
/// ([`FrameError::Unsynced`] for a frame without the counter extension); it keeps no
/// state, so it cannot detect replays: agents use [`crate::Agent::receive`].
pub fn decode_frame(
    bytes: &[u8],
    integrity: Integrity,
    estimator: EstimatorMode,
) -> Result<Frame, FrameError> {
    let view = check_frame(bytes, integrity, estimator)?;
    if let Integrity::Auth(key) = &integrity {
        let counter = view
            .carried_counter()
            .ok_or(FrameError::Unsynced(view.header.sender))?;
        view.verify_tag(key, counter)?;
    }
    view.validate(1)?;
    Ok(Frame {
        header: view.header,
        velocity: view.velocity,
        // At most MAX_ANGLES_PER_FRAME items fit in MAX_FRAME_LEN bytes.
        angles: view.angles().take(MAX_ANGLES_PER_FRAME).collect(),
        counter_ext: view.carried_counter().map(CounterExt::of_counter),
    })
}
