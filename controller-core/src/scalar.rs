//! The scalar type the controller is generic over (`f32` on target, `f64` on the host).

use serde::{de::DeserializeOwned, Serialize};

/// `defmt::Format` when the `defmt` feature is on, nothing otherwise.
#[cfg(feature = "defmt")]
pub trait MaybeFormat: defmt::Format {}
#[cfg(feature = "defmt")]
impl<T: defmt::Format> MaybeFormat for T {}
/// `defmt::Format` when the `defmt` feature is on, nothing otherwise.
#[cfg(not(feature = "defmt"))]
pub trait MaybeFormat {}
#[cfg(not(feature = "defmt"))]
impl<T> MaybeFormat for T {}

/// A real scalar: `f32` (hardware FPU on Cortex-M4F) or `f64` (host).
///
/// Only what the control step needs: no trigonometry, one square root.
pub trait Real:
    nalgebra::RealField + Copy + Default + Serialize + DeserializeOwned + MaybeFormat + 'static
{
    /// Square root; on `thumbv7em-none-eabihf` the single FPU instruction `vsqrt.f32`.
    fn sqrt_fast(self) -> Self;
    /// Converts from `f32` (wire values).
    fn of_f32(x: f32) -> Self;
    /// Converts to `f32` (wire values), rounding to nearest.
    fn as_f32(self) -> f32;
    /// A literal constant.
    fn lit(x: f64) -> Self;
    /// `true` unless NaN or infinite.
    fn finite(self) -> bool;
}

impl Real for f64 {
    #[inline]
    fn sqrt_fast(self) -> Self {
        libm::sqrt(self)
    }
    #[inline]
    fn of_f32(x: f32) -> Self {
        f64::from(x)
    }
    #[inline]
    #[allow(clippy::cast_possible_truncation)]
    fn as_f32(self) -> f32 {
        self as f32
    }
    #[inline]
    fn lit(x: f64) -> Self {
        x
    }
    #[inline]
    fn finite(self) -> bool {
        self.is_finite()
    }
}

impl Real for f32 {
    #[inline]
    fn sqrt_fast(self) -> Self {
        sqrt_f32(self)
    }
    #[inline]
    fn of_f32(x: f32) -> Self {
        x
    }
    #[inline]
    fn as_f32(self) -> f32 {
        self
    }
    #[inline]
    #[allow(clippy::cast_possible_truncation)]
    fn lit(x: f64) -> Self {
        x as f32
    }
    #[inline]
    fn finite(self) -> bool {
        self.is_finite()
    }
}

/// Hardware square root on ARMv7E-M with a single-precision FPU.
#[cfg(all(target_arch = "arm", target_abi = "eabihf"))]
#[inline]
fn sqrt_f32(x: f32) -> f32 {
    let out: u32;
    // SAFETY: `vsqrt.f32` only reads and writes the named FPU register s15, which is
    // declared as clobbered; no memory or stack is touched.
    unsafe {
        core::arch::asm!(
            "vmov s15, {x}",
            "vsqrt.f32 s15, s15",
            "vmov {y}, s15",
            x = in(reg) x.to_bits(),
            y = out(reg) out,
            out("s15") _,
            options(pure, nomem, nostack),
        );
    }
    f32::from_bits(out)
}

/// Portable square root elsewhere.
#[cfg(not(all(target_arch = "arm", target_abi = "eabihf")))]
#[inline]
fn sqrt_f32(x: f32) -> f32 {
    libm::sqrtf(x)
}

#[cfg(test)]
mod tests {
    use super::Real;

    #[test]
    fn sqrt_matches_reference() {
        for &x in &[0.0f32, 1e-8, 0.25, 2.0, 1e6] {
            assert_eq!(x.sqrt_fast(), x.sqrt());
            assert_eq!(f64::from(x).sqrt_fast(), f64::from(x).sqrt());
        }
        assert!((-1.0f32).sqrt_fast().is_nan());
    }
}
