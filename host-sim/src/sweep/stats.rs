//! The statistics of a sweep point: a binomial proportion with its Wilson score interval,
//! and sample quantiles.

/// The 0.975 quantile of the standard normal distribution (two-sided 95 %).
pub const Z95: f64 = 1.959_963_984_540_054;

/// A fraction `k / n` with its 95 % Wilson score interval (Wilson 1927; Brown, Cai &
/// DasGupta 2001 recommend it over the normal approximation for small `n` or fractions
/// near 0 or 1):
///
/// `centre = (p̂ + z²/2n) / (1 + z²/n)`,
/// `half = z / (1 + z²/n) · √(p̂(1 − p̂)/n + z²/4n²)`, interval `centre ± half`.
///
/// With `n = 0` the fraction is NaN and the interval `[0, 1]` (nothing known).
pub fn wilson(k: u64, n: u64) -> (f64, f64, f64) {
    if n == 0 {
        return (f64::NAN, 0.0, 1.0);
    }
    let (kf, nf) = (k as f64, n as f64);
    let p = kf / nf;
    let z2 = Z95 * Z95;
    let denom = 1.0 + z2 / nf;
    let centre = (p + z2 / (2.0 * nf)) / denom;
    let half = Z95 / denom * (p * (1.0 - p) / nf + z2 / (4.0 * nf * nf)).sqrt();
    // The exact bounds at k = 0 and k = n (rounding would leave 1e-17 off).
    let lo = if k == 0 {
        0.0
    } else {
        (centre - half).max(0.0)
    };
    let hi = if k == n {
        1.0
    } else {
        (centre + half).min(1.0)
    };
    (p, lo, hi)
}

/// The `q` quantile of `sorted` (ascending, finite): linear interpolation between order
/// statistics, `h = (n − 1) q`, `x[⌊h⌋] + (h − ⌊h⌋)(x[⌊h⌋+1] − x[⌊h⌋])` (Hyndman & Fan
/// type 7, the default of R and NumPy). `None` for an empty sample.
pub fn quantile(sorted: &[f64], q: f64) -> Option<f64> {
    let n = sorted.len();
    if n == 0 {
        return None;
    }
    let h = (n - 1) as f64 * q.clamp(0.0, 1.0);
    let lo = h.floor() as usize;
    let hi = (lo + 1).min(n - 1);
    Some(sorted[lo] + (h - lo as f64) * (sorted[hi] - sorted[lo]))
}
