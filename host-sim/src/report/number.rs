//! Numbers of the row files in Rust's shortest round-trip form, the text of `{x:?}`
//! (`0.35`, `1e-7`, `100.0`, `-0.0`, `NaN`, `inf`) byte for byte, at a fraction of its
//! cost: the digits come from `zmij` (Schubfach, the shortest digits that read back as
//! the same `f64`, as the standard library's), laid out as `{:?}` lays them out. Writing
//! `timeseries.csv` with `write!(s, "{x:?}")` was 1,100 instructions a cell (dev build,
//! callgrind), more than the simulation of a row (docs/outputs.md, "What the outputs
//! cost"). The tests compare it with `{:?}` over millions of values.

/// Whether the shortest digits of `a` (finite, positive) could be a tie between two
/// candidates: only when its exact decimal expansion has at most 18 significant digits
/// (a tie is a shortest candidate of n ≤ 17 digits half-way to the next, the exact value
/// n + 1 digits ending in 5). `a = m · 2^e` with `m` odd has `−e` fractional decimal
/// digits when `e < 0` and at least ⌊log10 a⌋ + 1 − e significant ones; an integer
/// (`e ≥ 0`) is never a tie (below 2^53 its own digits are the shortest; above, every
/// candidate's step is a power of ten larger than its odd part allows).
fn may_tie(a: f64) -> bool {
    let bits = a.to_bits();
    let biased = ((bits >> 52) & 0x7ff) as i32;
    let frac = bits & ((1u64 << 52) - 1);
    let (m, e2) = if biased == 0 {
        (frac, -1074)
    } else {
        (frac | (1u64 << 52), biased - 1075)
    };
    let e = e2 + m.trailing_zeros() as i32;
    if e >= 0 {
        return false;
    }
    // a ≥ 2^(e2 + 52 − leading bits) ≥ 2^p with p = e2 + 63 − leading_zeros(m).
    let p = e2 + 63 - m.leading_zeros() as i32;
    // ⌊p · log10 2⌋ ≤ ⌊log10 a⌋, in integers (exact for |p| ≤ 1650, as in Ryu).
    let lower = (p * 78_913) >> 18;
    lower + 1 - e <= 18
}

/// Appends `x` to `out` exactly as `write!(out, "{x:?}")` would.
pub fn push_f64(out: &mut String, x: f64) {
    let mut bytes = Vec::with_capacity(32);
    write_f64(&mut bytes, x);
    out.push_str(std::str::from_utf8(&bytes).unwrap_or("NaN"));
}

/// Appends the text of `{x:?}` to `out`, as bytes.
pub fn write_f64(out: &mut Vec<u8>, x: f64) {
    if !x.is_finite() {
        out.extend_from_slice(if x.is_nan() {
            b"NaN"
        } else if x > 0.0 {
            b"inf"
        } else {
            b"-inf"
        });
        return;
    }
    if x.is_sign_negative() {
        out.push(b'-');
    }
    let a = x.abs();
    if a == 0.0 {
        out.extend_from_slice(b"0.0");
        return;
    }
    if may_tie(a) {
        // Two shortest candidates equally close (1308548795726862.25: `.2` or `.3`):
        // `zmij` takes the even digit, `{:?}` the upper one. Such a value has a short
        // exact decimal expansion (see [`may_tie`]); it goes through `{:?}` itself.
        use std::io::Write as _;
        let _ = write!(out, "{a:?}");
        return;
    }
    let mut buffer = zmij::Buffer::new();
    let printed = buffer.format_finite(a).as_bytes();
    if (1e-4..1e15).contains(&a) {
        // Both write these in decimals, the same digits (most of a run's numbers).
        out.extend_from_slice(printed);
        return;
    }
    // `{:?}` writes 1e-4 ≤ |x| < 1e16 in decimals, others in exponent form; where
    // `zmij` chose the same form the text is the same but for its `e+`.
    let decimal = (1e-4..1e16).contains(&a);
    match printed.iter().position(|&c| c == b'e') {
        None if decimal => out.extend_from_slice(printed),
        Some(e) if !decimal => {
            out.extend_from_slice(&printed[..=e]);
            let rest = &printed[e + 1..];
            out.extend_from_slice(rest.strip_prefix(b"+").unwrap_or(rest));
        }
        _ => relayout(out, printed, decimal),
    }
}

/// `printed` (digits, a point, an exponent) laid out as `{:?}`: in decimals or in
/// exponent form.
fn relayout(out: &mut Vec<u8>, printed: &[u8], decimal: bool) {
    // The significant digits and the decimal point: a = 0.DIGITS × 10^point.
    let mut digits = [0u8; 32];
    let (mut n, mut point, mut dot) = (0usize, 0i32, false);
    let mut i = 0;
    while i < printed.len() && printed[i] != b'e' {
        match printed[i] {
            b'.' => dot = true,
            b'0' if n == 0 => point -= i32::from(dot),
            c => {
                if let Some(d) = digits.get_mut(n) {
                    *d = c;
                }
                n += 1;
                point += i32::from(!dot);
            }
        }
        i += 1;
    }
    if i < printed.len() {
        let (mut sign, mut e) = (1, 0i32);
        for &c in &printed[i + 1..] {
            match c {
                b'-' => sign = -1,
                b'0'..=b'9' => e = e * 10 + i32::from(c - b'0'),
                _ => {}
            }
        }
        point += sign * e;
    }
    let n = n.min(digits.len());
    let digits = match digits[..n].iter().rposition(|&d| d != b'0') {
        Some(last) => &digits[..=last],
        None => &digits[..1],
    };
    let zeros = |out: &mut Vec<u8>, k: i32| out.extend((0..k).map(|_| b'0'));
    if decimal {
        let n = digits.len() as i32;
        if point <= 0 {
            out.extend_from_slice(b"0.");
            zeros(out, -point);
            out.extend_from_slice(digits);
        } else if point < n {
            let (int, frac) = digits.split_at(point as usize);
            out.extend_from_slice(int);
            out.push(b'.');
            out.extend_from_slice(frac);
        } else {
            out.extend_from_slice(digits);
            zeros(out, point - n);
            out.extend_from_slice(b".0");
        }
    } else {
        out.push(digits[0]);
        if digits.len() > 1 {
            out.push(b'.');
            out.extend_from_slice(&digits[1..]);
        }
        out.push(b'e');
        let mut b = [0u8; 12];
        out.extend_from_slice(format_i32(&mut b, point - 1));
    }
}

/// `e` in decimal, into `b`.
fn format_i32(b: &mut [u8; 12], e: i32) -> &[u8] {
    let mut k = b.len();
    let mut m = e.unsigned_abs();
    loop {
        k -= 1;
        b[k] = b'0' + (m % 10) as u8;
        m /= 10;
        if m == 0 {
            break;
        }
    }
    if e < 0 {
        k -= 1;
        b[k] = b'-';
    }
    &b[k..]
}

#[cfg(test)]
mod tests {
    use super::push_f64;

    fn same(x: f64) {
        let mut s = String::new();
        push_f64(&mut s, x);
        assert_eq!(s, format!("{x:?}"), "bits {:#x}", x.to_bits());
    }

    #[test]
    fn special_values_and_the_layout_boundaries_are_those_of_debug() {
        for x in [
            0.0,
            -0.0,
            f64::NAN,
            f64::INFINITY,
            f64::NEG_INFINITY,
            1.0,
            -1.0,
            0.35,
            100.0,
            1e-4,
            9.999999999999999e-5,
            1e-5,
            1e15,
            1e16,
            9999999999999998.0,
            1.5e16,
            123456.789,
            0.001,
            f64::MIN_POSITIVE,
            5e-324,
            f64::MAX,
            f64::MIN,
            f64::EPSILON,
            1.0 / 3.0,
            2.0f64.sqrt(),
            -1.2345e-300,
            6.02214076e23,
        ] {
            same(x);
        }
    }

    /// Millions of values: random bit patterns (every exponent) and the magnitudes of a
    /// run (positions, velocities, errors, energies: random in [-10^k, 10^k]), and
    /// decimals of few digits.
    #[test]
    fn random_values_read_as_debug_writes_them() {
        let mut state = 0x9e37_79b9_7f4a_7c15_u64;
        let mut next = || {
            // SplitMix64.
            state = state.wrapping_add(0x9e37_79b9_7f4a_7c15);
            let mut z = state;
            z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
            z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
            z ^ (z >> 31)
        };
        for _ in 0..1_000_000 {
            same(f64::from_bits(next()));
        }
        for k in -20..20 {
            let scale = 10f64.powi(k);
            for _ in 0..25_000 {
                let u = (next() >> 11) as f64 / (1u64 << 53) as f64;
                same((2.0 * u - 1.0) * scale);
            }
        }
        // Where ties are possible: short binary fractions of large numbers (up to 2^53).
        for j in 1..=8 {
            for _ in 0..20_000 {
                let int = (next() >> 11) % (1u64 << (53 - j));
                let frac = next() % (1u64 << j);
                same((int as f64) + (frac as f64) / f64::from(1u32 << j));
            }
        }
        for i in 0..200_000 {
            same(f64::from(i) / 1024.0);
            same(f64::from(i) / 1000.0);
            same(f64::from(i) * 0.01);
        }
    }

    /// Negative control: `zmij`'s own layout (`1e+16`) is not Debug's (`1e16`), and the
    /// comparison sees it.
    #[test]
    fn the_integer_floor_of_p_log10_2_is_exact() {
        for p in -1100..1100 {
            let exact = (f64::from(p) * std::f64::consts::LOG10_2).floor() as i32;
            assert_eq!((p * 78_913) >> 18, exact, "p = {p}");
        }
    }

    /// Negative control of the ties: there `zmij`'s digits are not Debug's, and
    /// [`super::may_tie`] sends them to `{:?}`.
    #[test]
    fn ties_go_through_debug() {
        for (x, debug) in [
            // 1308548795726862.25 and -1704666185691.03125.
            (f64::from_bits(0x4312_9879_088f_f039), "1308548795726862.3"),
            (f64::from_bits(0xc278_ce60_5bfd_b080), "-1704666185691.0313"),
        ] {
            assert_eq!(format!("{x:?}"), debug);
            let z = zmij::Buffer::new().format(x).to_owned();
            assert_ne!(z, debug);
            assert!(super::may_tie(x.abs()));
            same(x);
        }
        assert!(!super::may_tie(0.35) && !super::may_tie(1e300) && !super::may_tie(12.0));
    }

    #[test]
    fn the_comparison_catches_another_layout() {
        let z = zmij::Buffer::new().format(1e16).to_owned();
        assert_ne!(z, format!("{:?}", 1e16));
    }
}
