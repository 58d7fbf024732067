use super::*;
use std::vec::Vec;

/// `v(t)` every millisecond for `seconds` after a setpoint step `sp` from hover, and the
/// largest total tilt (degrees).
fn response(sp: [f64; 2], seconds: f64) -> (Crazyflie, Vec<[f64; 2]>, f64) {
    let mut p = Crazyflie::new([0.0; 2], [0.0; 2]);
    let mut out = Vec::from([p.v]);
    let mut tilt: f64 = 0.0;
    for _ in 0..(seconds * 1000.0).round() as usize {
        p.step(sp, [0.0; 2], 1e-3);
        out.push(p.v);
        tilt = tilt.max(p.tilt());
    }
    (p, out, tilt.to_degrees())
}

/// The continuous-time linearisation (no clamps, no sampling) by fine RK4:
/// `θ_d = K_p e + K_i ∫e`, `θ̇ = K_p^a (θ_d − θ) + K_i^a ∫(θ_d − θ)`, `v̇ = g θ`.
fn linear(sp: f64, seconds: f64, kp_att: f64) -> Vec<f64> {
    let f = |x: [f64; 4]| {
        let [v, iv, th, ith] = x;
        let e = sp - v;
        let d = fw::VEL_KP * e + fw::VEL_KI * iv;
        [
            G * th.to_radians(),
            e,
            kp_att * (d - th) + fw::ATT_KI * ith,
            d - th,
        ]
    };
    let h = 1e-5;
    let mut x = [0.0; 4];
    let mut out = Vec::from([0.0]);
    for k in 1..=(seconds / h).round() as usize {
        let add = |a: [f64; 4], b: [f64; 4], s: f64| [0, 1, 2, 3].map(|i| a[i] + b[i] * s);
        let k1 = f(x);
        let k2 = f(add(x, k1, h / 2.0));
        let k3 = f(add(x, k2, h / 2.0));
        let k4 = f(add(x, k3, h));
        x = [0, 1, 2, 3].map(|i| x[i] + h / 6.0 * (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i]));
        if k % 100 == 0 {
            out.push(x[0]);
        }
    }
    out
}

/// A small step (0.01 m/s: tilts under 0.3°, far from the clamps) follows the
/// cascade's transfer function; the firmware's sampling (velocity held 10 ms, rate
/// held 2 ms) delays it by a few ms, within 3 % of the step everywhere.
#[test]
fn small_step_follows_the_linear_cascade() {
    let sp = 0.01;
    let (_, v, _) = response([sp, 0.0], 3.0);
    let lin = linear(sp, 3.0, fw::ATT_KP);
    let worst = v
        .iter()
        .zip(&lin)
        .map(|(a, b)| (a[0] - b).abs())
        .fold(0.0, f64::max);
    assert!(worst < 0.03 * sp, "worst {worst}");
    // Negative control: a ten times faster attitude loop (nearly the first-order
    // model) is not within that band.
    let fast = linear(sp, 3.0, 10.0 * fw::ATT_KP);
    let off = fast
        .iter()
        .zip(&lin)
        .map(|(a, b)| (a - b).abs())
        .fold(0.0, f64::max);
    assert!(off > 0.05 * sp, "off {off}");
}

/// The integral leaves no steady error: after 20 s the velocity is the setpoint's
/// (within 0.5 %), and the drone is level again.
#[test]
fn steady_state_is_the_setpoint() {
    let (p, v, _) = response([0.3, -0.4], 20.0);
    let last = v.last().copied().unwrap_or_default();
    let err = libm::hypot(last[0] - 0.3, last[1] + 0.4);
    assert!(err < 0.0025, "{last:?}");
    assert!(p.tilt().to_degrees() < 0.2);
}

/// Along an axis the tilt stays near the 20° clamp; on the diagonal each axis is
/// clamped to 20°, so the drone tilts by `acos(cos² 20°)` = 28.0° in total.
#[test]
fn per_axis_clamp_tilts_more_on_a_diagonal() {
    // 4 m/s: the clamps hold for long enough for the attitude loop to reach them.
    let (_, _, axis) = response([4.0, 0.0], 2.0);
    let d = 4.0 / 2f64.sqrt();
    let (p, _, diagonal) = response([d, d], 2.0);
    let both = total_tilt(20.0, 20.0).to_degrees();
    assert!((both - 27.99).abs() < 0.01, "{both}");
    // The attitude PI overshoots its 20° demand by about a degree.
    assert!(axis > 20.0 && axis < 22.0, "axis {axis}");
    assert!(
        diagonal > both - 0.5 && diagonal < both + 2.0,
        "diagonal {diagonal}"
    );
    assert!(diagonal > axis + 5.0);
    let [x, y] = p.axes;
    assert!(x.desired <= fw::TILT_MAX_DEG && y.desired <= fw::TILT_MAX_DEG);
}

/// Velocity mode has no speed limit: a 3 m/s setpoint is flown (within the slowly
/// decaying overshoot the integral wound up while the tilt was clamped).
#[test]
fn no_speed_limit_in_velocity_mode() {
    let (_, v, _) = response([3.0, 0.0], 8.0);
    let last = v.last().copied().unwrap_or_default();
    assert!((last[0] - 3.0).abs() < 0.1, "{last:?}");
}

/// The firmware's ticks follow the clock, not the calls: 1 ms steps and 0.3 ms steps
/// reach the same state at the same time (to rounding).
#[test]
fn step_size_does_not_move_the_ticks() {
    let mut a = Crazyflie::new([0.0; 2], [0.0; 2]);
    let mut b = a;
    for _ in 0..300 {
        a.step([0.5, 0.2], [0.0; 2], 1e-3);
    }
    for _ in 0..1000 {
        b.step([0.5, 0.2], [0.0; 2], 3e-4);
    }
    for k in 0..2 {
        assert!((a.v[k] - b.v[k]).abs() < 1e-9, "{:?} {:?}", a.v, b.v);
        assert!((a.q[k] - b.q[k]).abs() < 1e-9);
    }
    // Negative control: 0.3 s against 0.31 s differ.
    b.step([0.5, 0.2], [0.0; 2], 1e-2);
    assert!((a.v[0] - b.v[0]).abs() > 1e-4);
}

/// The plain-number copy is exact: a drone copied mid-flight flies on identically.
#[test]
fn words_round_trip() {
    let mut a = Crazyflie::new([1.0, -2.0], [0.1, 0.0]);
    for _ in 0..37 {
        a.step([0.5, 0.2], [0.01, 0.0], 7e-4);
    }
    let mut b = Crazyflie::from_words(a.to_words());
    assert_eq!(a, b);
    for _ in 0..100 {
        a.step([0.5, 0.2], [0.0; 2], 1e-3);
        b.step([0.5, 0.2], [0.0; 2], 1e-3);
    }
    assert_eq!(a, b);
    // Garbage words still give a drone that steps (no panic, finite phase).
    for garbage in [f64::NAN, 1e300, -1e300, f64::INFINITY] {
        let mut c = Crazyflie::from_words([garbage; WORDS]);
        c.step([0.0; 2], [0.0; 2], 1e-3);
    }
}

/// Every firmware figure the model uses is in docs/world.md's table with its value
/// and its source line (the constants above cite the same lines).
#[test]
fn the_docs_cite_every_figure() {
    let doc = include_str!("../../../docs/world.md");
    let rows = [
        (fw::VEL_KP, "25 °/(m/s)", "platform_defaults_cf2.h:132"),
        (fw::VEL_KI, "1 °/m", "platform_defaults_cf2.h:133"),
        (fw::VEL_I_LIMIT, "±5000", "pid.h:33"),
        (
            fw::TILT_MAX_DEG * fw::TILT_OVERHEAD,
            "1.1 × 20° = 22°",
            "position_controller_pid.c:63",
        ),
        (fw::ATT_KP, "6 1/s", "platform_defaults_cf2.h:114"),
        (fw::ATT_KI, "3 1/s²", "platform_defaults_cf2.h:115"),
        (fw::ATT_I_LIMIT, "±20 ° s", "platform_defaults_cf2.h:118"),
        (
            f64::from(fw::POSITION_RATE),
            "100 Hz",
            "stabilizer_types.h:373",
        ),
        (
            f64::from(fw::ATTITUDE_RATE),
            "500 Hz",
            "stabilizer_types.h:372",
        ),
    ];
    for (value, text, source) in rows {
        let row = doc
            .lines()
            .find(|l| l.contains(text) && l.contains(source))
            .unwrap_or_else(|| panic!("docs/world.md: no row with {text} and {source}"));
        let number = text
            .trim_start_matches('±')
            .split([' ', '°'])
            .next()
            .and_then(|n| n.parse::<f64>().ok());
        if let Some(n) = number.filter(|_| !text.contains('×')) {
            assert_eq!(n, value, "{row}");
        }
    }
}

/// At 20° the acceleration is `g tan 20°` along an axis; the lead is `1 / (g K_p)`.
#[test]
fn closed_forms() {
    let a = tilt_acceleration(20.0, 0.0);
    assert!((a[0] - 3.569_3).abs() < 1e-3 && a[1] == 0.0, "{a:?}");
    assert!((derived_lead() - 0.2337).abs() < 1e-4, "{}", derived_lead());
    assert!((derived_second_lead() - 0.03895).abs() < 1e-5);
}
