//! Quantization of the angle efforts to IEEE 754 binary16 ("half precision").
//!
//! Range and worst-case error (checked over every one of the 65,536 codes and on random
//! `f32` inputs in `tests/wire_quant.rs`):
//! - finite codes cover `[−65504, 65504]`; an input that does not round into that range
//!   (`|x| ≥ 65520`) saturates to `±65504` (never to infinity, never wraps), and
//!   [`encode`] says so;
//! - rounding is to nearest (ties to even): for `2⁻¹⁴ ≤ |x| < 65520` the error is at most
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

/// The binary16 code of `x` (rounded to nearest), saturated to `±MAX` when it does not
/// round to a finite binary16 value (`|x| ≥ 65520`), and whether it saturated. `x` must
/// not be NaN (the caller sends only finite values; a NaN would saturate).
#[inline]
pub fn encode(x: f32) -> (u16, bool) {
    let code = to_code(x);
    // Exponent all ones: the rounding overflowed to ±∞. Keep the sign, take ±MAX.
    if code & 0x7C00 == 0x7C00 {
        ((code & 0x8000) | MAX_CODE, true)
    } else {
        (code, false)
    }
}

/// The code of [`MAX`].
const MAX_CODE: u16 = 0x7BFF;

/// The value of a binary16 code; `None` for infinity and NaN.
#[inline]
pub fn decode(code: u16) -> Option<f32> {
    // Exponent all ones: infinity or NaN.
    if code & 0x7C00 == 0x7C00 {
        None
    } else {
        Some(from_code(code))
    }
}

/// IEEE 754 conversion `f32` → binary16, round to nearest even (the `half` crate).
#[inline]
pub fn to_code_portable(x: f32) -> u16 {
    f16::from_f32(x).to_bits()
}

/// IEEE 754 conversion binary16 → `f32`, exact (the `half` crate).
#[inline]
pub fn from_code_portable(code: u16) -> f32 {
    f16::from_bits(code).to_f32()
}

/// `f32` → binary16 with the FPU's `vcvtb.f16.f32` (ARMv7E-M's single-precision FPU
/// converts half precision in hardware: IEEE format with the reset `FPSCR.AHP = 0`,
/// round to nearest even, subnormals kept with the reset `FPSCR.FZ = 0`). The firmware
/// checks it against [`to_code_portable`] (`measure`, `FWCHECK f16`).
#[cfg(all(target_arch = "arm", target_abi = "eabihf"))]
#[inline]
pub fn to_code(x: f32) -> u16 {
    let out: u32;
    // SAFETY: reads and writes only the FPU register s15, declared clobbered; no memory.
    unsafe {
        core::arch::asm!(
            "vmov s15, {x}",
            "vcvtb.f16.f32 s15, s15",
            "vmov {y}, s15",
            x = in(reg) x.to_bits(),
            y = out(reg) out,
            out("s15") _,
            options(pure, nomem, nostack),
        );
    }
    // The conversion writes the low half of s15.
    (out & 0xFFFF) as u16
}

/// binary16 → `f32` with the FPU's `vcvtb.f32.f16` (see [`to_code`]).
#[cfg(all(target_arch = "arm", target_abi = "eabihf"))]
#[inline]
pub fn from_code(code: u16) -> f32 {
    let out: u32;
    // SAFETY: reads and writes only the FPU register s15, declared clobbered; no memory.
    unsafe {
        core::arch::asm!(
            "vmov s15, {x}",
            "vcvtb.f32.f16 s15, s15",
            "vmov {y}, s15",
            x = in(reg) u32::from(code),
            y = out(reg) out,
            out("s15") _,
            options(pure, nomem, nostack),
        );
    }
    f32::from_bits(out)
}

/// `f32` → binary16 elsewhere: [`to_code_portable`].
#[cfg(not(all(target_arch = "arm", target_abi = "eabihf")))]
#[inline]
pub fn to_code(x: f32) -> u16 {
    to_code_portable(x)
}

/// binary16 → `f32` elsewhere: [`from_code_portable`].
#[cfg(not(all(target_arch = "arm", target_abi = "eabihf")))]
#[inline]
pub fn from_code(code: u16) -> f32 {
    from_code_portable(code)
}
