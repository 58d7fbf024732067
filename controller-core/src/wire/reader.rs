//! Checking and reading frames in place (layout in [`super`]).

use super::{
    mode_byte, offset, quant, FrameError, FrameHeader, Integrity, ANGLE_ITEM_LEN, FIXED_LEN,
    MAX_ANGLES_PER_FRAME, MAX_FRAME_LEN, WIRE_VERSION,
};
use crate::config::EstimatorMode;
use crate::{crc16, AgentId};

/// `N` bytes at `at` (zeros if out of bounds; every caller reads within a checked length).
#[inline(always)]
fn get<const N: usize>(b: &[u8], at: usize) -> [u8; N] {
    b.get(at..at + N)
        .and_then(|s| s.first_chunk::<N>())
        .copied()
        .unwrap_or([0; N])
}

/// One angle item, decoded (fields: see [`super`]).
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct AngleItem {
    /// The far vertices `v`, `w` of the angle `(sender; v, w)`.
    pub far: [AgentId; 2],
    /// `γ_α` (S7).
    pub gamma: f32,
    /// `σ_α = s_nv × s_nw`.
    pub sigma: f32,
    /// `[ρ_v, ρ_w]`: the distances the apex used.
    pub rho: [f32; 2],
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
    /// The angle items' bytes (a whole number of items).
    items: &'a [u8],
}

impl<'a> FrameView<'a> {
    /// Number of angle items.
    pub fn len(&self) -> usize {
        self.items.len() / ANGLE_ITEM_LEN
    }

    /// No angle items.
    pub fn is_empty(&self) -> bool {
        self.items.is_empty()
    }

    /// The raw items: far vertices and the binary16 codes of `[γ, σ, ρ_v, ρ_w]`.
    #[inline]
    pub(crate) fn raw_items(&self) -> impl Iterator<Item = ([AgentId; 2], [u16; 4])> + 'a {
        self.items.chunks_exact(ANGLE_ITEM_LEN).map(|b| {
            let code = |at| u16::from_le_bytes(get(b, at));
            (
                get::<2>(b, offset::ITEM_FAR0),
                [
                    code(offset::ITEM_GAMMA),
                    code(offset::ITEM_SIGMA),
                    code(offset::ITEM_RHO0),
                    code(offset::ITEM_RHO1),
                ],
            )
        })
    }

    /// Checks every value: a finite velocity, and per item two distinct far vertices, a
    /// finite `γ`, `|σ| ≤ 1`, finite positive distances. Reads nothing but bits (no float
    /// conversion).
    #[inline]
    pub fn validate(&self) -> Result<(), FrameError> {
        let [vx, vy] = self.velocity;
        // `x·0` is ±0 for finite `x` and NaN otherwise: one comparison for both.
        if vx * 0.0 + vy * 0.0 != 0.0 {
            return Err(FrameError::InvalidValue);
        }
        let mut ok = true;
        for (far, [gamma, sigma, rho0, rho1]) in self.raw_items() {
            if far[0] == far[1] {
                return Err(FrameError::Malformed);
            }
            // binary16: exponent all ones is ∞ or NaN; magnitude bits order the values.
            // A positive finite value is 0x0001..=0x7BFF.
            let positive = |c: u16| c.wrapping_sub(1) < 0x7BFF;
            ok &= (gamma & 0x7C00 != 0x7C00)
                & (sigma & 0x7FFF <= F16_ONE)
                & positive(rho0)
                & positive(rho1);
        }
        if ok {
            Ok(())
        } else {
            Err(FrameError::InvalidValue)
        }
    }

    /// The decoded angle items (invalid codes read as NaN; call [`FrameView::validate`]
    /// first).
    pub fn angles(&self) -> impl Iterator<Item = AngleItem> + 'a {
        self.raw_items().map(|(far, [g, s, r0, r1])| {
            let v = |c| quant::decode(c).unwrap_or(f32::NAN);
            AngleItem {
                far,
                gamma: v(g),
                sigma: v(s),
                rho: [v(r0), v(r1)],
            }
        })
    }
}

/// Checks length, trailer, version and modes of one frame for a receiver with
/// `integrity` and `estimator` mode, and returns a view of it. Never panics.
pub fn check_frame(
    bytes: &[u8],
    integrity: Integrity,
    estimator: EstimatorMode,
) -> Result<FrameView<'_>, FrameError> {
    if bytes.len() > MAX_FRAME_LEN {
        return Err(FrameError::TooLong);
    }
    let body_len = bytes
        .len()
        .checked_sub(integrity.trailer_len())
        .filter(|&n| n >= FIXED_LEN)
        .ok_or(FrameError::TooShort)?;
    let (body, trailer) = bytes.split_at(body_len);
    if integrity == Integrity::Crc16 && crc16::checksum(body) != u16::from_le_bytes(get(trailer, 0))
    {
        return Err(FrameError::BadCrc);
    }
    let [mode, sender] = get::<2>(body, offset::MODE);
    if mode >> 4 != WIRE_VERSION {
        return Err(FrameError::UnknownVersion(mode >> 4));
    }
    if mode != mode_byte(integrity, estimator) {
        return Err(FrameError::ModeMismatch(mode));
    }
    let items = body.get(FIXED_LEN..).unwrap_or(&[]);
    if items.len() % ANGLE_ITEM_LEN != 0 {
        return Err(FrameError::Malformed);
    }
    let f32_at = |at| f32::from_le_bytes(get(body, at));
    Ok(FrameView {
        header: FrameHeader {
            mode,
            sender,
            seq: u16::from_le_bytes(get(body, offset::SEQ)),
        },
        velocity: [f32_at(offset::VELOCITY), f32_at(offset::VELOCITY + 4)],
        items,
    })
}

/// A frame decoded completely (for tools and tests; agents read frames in place).
#[derive(Clone, Debug, PartialEq)]
pub struct Frame {
    /// The header.
    pub header: FrameHeader,
    /// The sender's velocity.
    pub velocity: [f32; 2],
    /// The angle items.
    pub angles: heapless::Vec<AngleItem, MAX_ANGLES_PER_FRAME>,
}

/// Checks a frame ([`check_frame`] and [`FrameView::validate`]) and decodes it. Never
/// panics.
pub fn decode_frame(
    bytes: &[u8],
    integrity: Integrity,
    estimator: EstimatorMode,
) -> Result<Frame, FrameError> {
    let view = check_frame(bytes, integrity, estimator)?;
    view.validate()?;
    Ok(Frame {
        header: view.header,
        velocity: view.velocity,
        // At most MAX_ANGLES_PER_FRAME items fit in MAX_FRAME_LEN bytes.
        angles: view.angles().take(MAX_ANGLES_PER_FRAME).collect(),
    })
}
