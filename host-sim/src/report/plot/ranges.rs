//! Points and axis ranges: non-finite and absurd values skipped, log floors, padding.

use super::ABSURD;

pub(super) fn sane(v: f64) -> bool {
    v.is_finite() && v.abs() < ABSURD
}

/// Finite `(t, v)` pairs.
pub(super) fn points(t: &[f64], v: &[f64]) -> Vec<(f64, f64)> {
    t.iter()
        .zip(v)
        .filter(|(t, v)| sane(**t) && sane(**v))
        .map(|(&t, &v)| (t, v))
        .collect()
}

/// Finite `(t, max(|v|, floor))` pairs, for a log axis.
pub(super) fn log_points(t: &[f64], v: &[f64], floor: f64) -> Vec<(f64, f64)> {
    t.iter()
        .zip(v)
        .filter(|(t, v)| sane(**t) && sane(**v))
        .map(|(&t, &v)| (t, v.abs().max(floor)))
        .collect()
}

/// Padded, non-degenerate linear range covering the finite values.
pub(super) fn lin_range(values: impl IntoIterator<Item = f64>) -> (f64, f64) {
    let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
    for v in values.into_iter().filter(|v| sane(*v)) {
        lo = lo.min(v);
        hi = hi.max(v);
    }
    if lo > hi {
        return (0.0, 1.0);
    }
    if hi - lo <= f64::EPSILON * hi.abs().max(lo.abs()) {
        let d = if lo == 0.0 { 1.0 } else { 0.1 * lo.abs() };
        return (lo - d, hi + d);
    }
    let pad = 0.04 * (hi - lo);
    (lo - pad, hi + pad)
}

/// Time range of the run.
pub(super) fn time_range(t: &[f64]) -> (f64, f64) {
    let (lo, hi) = lin_range(t.iter().copied());
    // No padding on the time axis when there is a real span.
    let (tlo, thi) = t
        .iter()
        .filter(|v| sane(**v))
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &v| {
            (a.min(v), b.max(v))
        });
    if thi > tlo {
        (tlo, thi)
    } else {
        (lo, hi)
    }
}

/// Log range (positive, non-degenerate) covering positive `values`.
pub(super) fn log_range(values: impl IntoIterator<Item = f64>) -> (f64, f64) {
    let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
    for v in values.into_iter().filter(|v| sane(*v) && *v > 0.0) {
        lo = lo.min(v);
        hi = hi.max(v);
    }
    if lo > hi {
        return (0.1, 10.0);
    }
    if hi <= lo * 1.01 {
        return (lo / 10.0, hi * 10.0);
    }
    let pad = (hi / lo).powf(0.04).max(1.2);
    (lo / pad, hi * pad)
}

pub(super) fn log_label(v: &f64) -> String {
    let exp = v.log10();
    if (exp - exp.round()).abs() < 1e-9 {
        format!("1e{}", exp.round() as i64)
    } else {
        format!("{v:.1e}")
    }
}
