//! Quantization of the angle efforts to IEEE 754 binary16 ("half precision").
//!
//! Range and worst-case error (checked over every one of the 65,536 codes and on random
//! `f32` inputs in `tests/wire_quant.rs`):
//! - finite codes cover `[−65504, 65504]`; an input beyond that range saturates to
//!   `±65504` (never to infinity, never wraps), and [`encode`] says so;
//! - rounding is to nearest (ties to even): for `2⁻¹⁴ ≤ |x| ≤ 65504` the error is at most
//!   `2⁻¹¹ |x|` (relative `4.9·10⁻⁴`); below `2⁻¹⁴` (subnormals) at most `2⁻²⁵` absolute
//!   (`3.0·10⁻⁸`);
//! - zero, the sign and every code round-trip exactly (`decode(encode(decode(c))) = c`);
//! - codes for infinity and NaN are never written and are refused on receipt
//!   ([`decode`] gives `None`; the frame is rejected as
//!   [`FrameError::InvalidValue`](super::FrameError::InvalidValue)).
//!
//! Why binary16: the effort enters the far vertex's force linearly, so a relative error
//! bound is the natural one, and the forces span many decades (from ~10³ N during a
//! transient down to 0 at the equilibrium). Any IEEE 754 implementation (C `_Float16`,
//! numpy `float16`) decodes it.

use half::f16;

/// Largest finite binary16 value.
pub const MAX: f32 = 65504.0;
/// Relative error bound of a normal value (`2⁻¹¹`).
pub const REL_ERROR: f32 = 1.0 / 2048.0;
/// Absolute error bound below the normal range (`2⁻²⁵`).
pub const ABS_ERROR: f32 = 1.0 / 33_554_432.0;
/// Smallest positive normal binary16 value (`2⁻¹⁴`).
pub const MIN_NORMAL: f32 = 1.0 / 16384.0;

/// The binary16 code of `x`, saturated to `±MAX`, and whether it saturated. `x` must not
/// be NaN (the caller sends only finite efforts; a NaN would give a NaN code, which
/// receivers refuse).
#[inline]
pub fn encode(x: f32) -> (u16, bool) {
    let saturated = x.abs() > MAX;
    (f16::from_f32(x.clamp(-MAX, MAX)).to_bits(), saturated)
}

/// The value of a binary16 code; `None` for infinity and NaN.
#[inline]
pub fn decode(code: u16) -> Option<f32> {
    // Exponent all ones: infinity or NaN.
    if code & 0x7C00 == 0x7C00 {
        None
    } else {
        Some(f16::from_bits(code).to_f32())
    }
}
