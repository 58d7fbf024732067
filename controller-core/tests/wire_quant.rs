//! The binary16 rounding of the efforts (`wire::quant`): every code, and random values
//! over the whole range, against the documented range and error bounds.

use ph_formation_core::wire::quant::{decode, encode, ABS_ERROR, MAX, MIN_NORMAL, REL_ERROR};
use proptest::prelude::*;

/// Every one of the 65,536 codes: infinities and NaNs are refused, every finite code
/// decodes within the range and re-encodes to itself (so no value is lost in a relay).
#[test]
fn every_code_decodes_in_range_and_round_trips() {
    let mut finite = 0;
    for code in 0..=u16::MAX {
        let exponent_all_ones = code & 0x7C00 == 0x7C00;
        match decode(code) {
            None => assert!(exponent_all_ones, "{code:#06x} refused"),
            Some(x) => {
                assert!(
                    !exponent_all_ones && x.is_finite() && x.abs() <= MAX,
                    "{code:#06x}"
                );
                let (back, saturated) = encode(x);
                assert_eq!(back, code, "{code:#06x} → {x} → {back:#06x}");
                assert!(!saturated);
                finite += 1;
            }
        }
    }
    assert_eq!(finite, 65536 - 2 * 1024);
}

/// The error bound between adjacent codes: the midpoint between two neighbouring finite
/// values is within the bound of both (the worst case of rounding to nearest).
#[test]
fn the_worst_case_rounding_error_is_the_documented_bound() {
    let mut worst_rel = 0.0f64;
    let mut worst_abs = 0.0f64;
    for code in 0..0x7BFFu16 {
        let (a, b) = (decode(code).unwrap(), decode(code + 1).unwrap());
        let mid = (f64::from(a) + f64::from(b)) / 2.0;
        let err = (f64::from(b) - f64::from(a)) / 2.0;
        if mid >= f64::from(MIN_NORMAL) {
            worst_rel = worst_rel.max(err / mid);
        } else {
            worst_abs = worst_abs.max(err);
        }
    }
    assert!(worst_rel <= f64::from(REL_ERROR), "{worst_rel:e}");
    assert!(
        worst_rel > 0.99 * f64::from(REL_ERROR) / 2.0,
        "bound not tight: {worst_rel:e}"
    );
    assert!(worst_abs <= f64::from(ABS_ERROR), "{worst_abs:e}");
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(20_000))]

    /// Any finite `f32`: saturates when it does not round into ±65504 (|x| ≥ 65520;
    /// flagged, never ∞, never wrapped: the sign is kept), otherwise within the
    /// documented error.
    #[test]
    fn any_value_rounds_within_the_bound_or_saturates(x in any::<f32>().prop_filter("not NaN", |x| !x.is_nan())) {
        let (code, saturated) = encode(x);
        let y = decode(code).expect("never infinity or NaN");
        if x.abs() >= 65520.0 {
            prop_assert!(saturated);
            prop_assert_eq!(y, MAX.copysign(x));
        } else {
            prop_assert!(!saturated);
            let err = f64::from((y - x).abs());
            prop_assert!(y.abs() <= MAX);
            let bound = if x.abs() >= MIN_NORMAL {
                f64::from(REL_ERROR) * f64::from(x.abs())
            } else {
                f64::from(ABS_ERROR)
            };
            prop_assert!(err <= bound, "{} → {} (error {:e} > {:e})", x, y, err, bound);
            prop_assert!(y == 0.0 || y.signum() == x.signum());
        }
    }

    /// Values in the range that matters (forces up to 10⁴ N): the relative bound.
    #[test]
    fn forces_round_within_the_relative_bound(x in -1.0e4f32..1.0e4) {
        let y = decode(encode(x).0).expect("finite");
        prop_assert!(f64::from((y - x).abs()) <= f64::from(REL_ERROR) * f64::from(x.abs()) + f64::from(ABS_ERROR));
    }
}

/// The edges of the saturation: 65504 is exact; up to 65519.99 rounds down to it; from
/// 65520 (the midpoint to the next power of two) it saturates.
#[test]
fn saturation_edges() {
    assert_eq!(encode(65504.0), (0x7BFF, false));
    assert_eq!(encode(65519.99), (0x7BFF, false));
    assert_eq!(encode(65520.0), (0x7BFF, true));
    assert_eq!(encode(-1.0e30), (0xFBFF, true));
    assert_eq!(encode(f32::INFINITY), (0x7BFF, true));
}
