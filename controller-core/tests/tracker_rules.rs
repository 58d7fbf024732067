//! The bearing tracker's recovery rules (SPEC §11a, S15b–S15e), each against the case it
//! is for: a zero interval is a measurement update that keeps the inverse distance (S15b);
//! an interval beyond the limit restarts the track and counts a reset (S15c); outliers
//! restart it only when they agree with each other (S15d); the 90° rule does not apply
//! while the track's gate admits every sine (S15e).

use ph_formation_core::geometry::perp;
use ph_formation_core::tracker::{RelativeVelocity, Track, TrackLimits};
use ph_formation_core::{TrackerConfig, Vec2};

const DT: f64 = 0.01;

const LIMITS: TrackLimits<f64> = TrackLimits {
    inv_range_initial: 1.0,
    inv_range_max: 10.0,
    max_interval: 0.5,
};

fn rotate(s: &Vec2<f64>, a: f64) -> Vec2<f64> {
    let (sin, cos) = a.sin_cos();
    Vec2::new(cos * s.x - sin * s.y, sin * s.x + cos * s.y)
}

/// A track of a neighbour 2 m ahead moving at 0.5 m/s across the first bearing for 4 s on
/// exact bearings: `ρ̂` has converged to about 0.35 from `ρ̂(0) = 1`. Returns the track,
/// `ŝ`, the last true bearing and the relative velocity.
fn converged() -> (Track<f64>, Vec2<f64>, Vec2<f64>, RelativeVelocity<f64>) {
    let c = TrackerConfig::default();
    let (p0, v) = (Vec2::new(2.0, 0.0), Vec2::new(0.0, 0.5));
    let dv = RelativeVelocity {
        over_interval: v,
        now: v,
    };
    let (mut tr, mut sh) = (Track::default(), Vec2::zeros());
    let mut z = Vec2::zeros();
    for k in 0..=400 {
        let p = p0 + v * (k as f64 * DT);
        z = p / p.norm();
        let dt = if k == 0 { f64::NEG_INFINITY } else { DT };
        tr.update(&mut sh, &z, &dv, dt, &c, &LIMITS);
    }
    (tr, sh, z, dv)
}

/// S15b: a bearing with no time since the last (the app's first tick, a repeated
/// sample) updates the track; it does not throw away the converged `ρ̂`.
#[test]
fn a_zero_interval_is_an_update_that_keeps_the_inverse_distance() {
    let c = TrackerConfig::default();
    let (mut tr, mut sh, z, dv) = converged();
    let before = tr.inv_range;
    // At 4 s the neighbour is at (2, 2): ρ = 1/(2√2).
    assert!(
        (before - 0.5 / 2f64.sqrt()).abs() < 0.02,
        "not converged: {before}"
    );
    tr.update(&mut sh, &z, &dv, 0.0, &c, &LIMITS);
    assert!(
        (tr.inv_range - before).abs() < 1e-3,
        "{} vs {before}",
        tr.inv_range
    );
    assert!(
        tr.p[0] > 0.0 && tr.p[2] < 0.5 * before * before,
        "{:?}",
        tr.p
    );
    assert_eq!(tr.resets, 0);
    // A span already predicted by the hold (S18) and then the bearing at that moment.
    let before = tr.inv_range;
    tr.predict(&mut sh, &dv, DT, &c, &LIMITS);
    tr.update(&mut sh, &z, &dv, DT, &c, &LIMITS);
    assert!(
        (tr.inv_range - before).abs() < 1e-2,
        "{} vs {before}",
        tr.inv_range
    );
    assert_eq!(tr.resets, 0);
}

/// S15c: past the limit (a stalled task, a clock jump) the prediction is not stretched
/// across the interval: the track restarts at the bearing and counts it.
#[test]
fn an_interval_beyond_the_limit_restarts_the_track_and_counts_it() {
    let c = TrackerConfig::default();
    let (mut tr, mut sh, _, dv) = converged();
    let z = rotate(&sh, 0.05);
    // Within the limit: predicted and updated, not restarted.
    let mut within = tr;
    let mut s_within = sh;
    within.update(&mut s_within, &z, &dv, LIMITS.max_interval, &c, &LIMITS);
    assert_eq!(within.resets, 0);
    assert!((within.inv_range - 1.0).abs() > 0.2, "{}", within.inv_range);
    // Beyond: restarted at z with ρ̂(0).
    tr.update(&mut sh, &z, &dv, 2.0, &c, &LIMITS);
    assert_eq!(sh, z);
    assert_eq!(tr.inv_range, LIMITS.inv_range_initial);
    assert_eq!(tr.resets, 1);
    assert_eq!(tr.p[1], 0.0);
}

/// S15d: wrong bearings that do not agree with each other (a camera's false detections
/// point anywhere) do not restart the track before ten in a row; bearings that agree do,
/// at the third, and the restart is counted.
#[test]
fn only_agreeing_outliers_restart_the_track() {
    let c = TrackerConfig::default();
    let dv = RelativeVelocity::default();
    let s = Vec2::new(1.0, 0.0);
    let (mut tr, mut sh) = (Track::default(), Vec2::zeros());
    tr.update(&mut sh, &s, &dv, f64::NEG_INFINITY, &c, &LIMITS);
    for _ in 0..50 {
        tr.update(&mut sh, &s, &dv, DT, &c, &LIMITS);
    }
    // Six scattered outliers in a row (30° and more from the track and each other).
    for deg in [40.0, -50.0, 100.0, -120.0, 160.0, 70.0] {
        tr.update(
            &mut sh,
            &rotate(&s, f64::to_radians(deg)),
            &dv,
            DT,
            &c,
            &LIMITS,
        );
        assert!((sh - s).norm() < 1e-9, "{deg}°: the track moved to {sh:?}");
    }
    assert_eq!(tr.resets, 0);
    assert_eq!(tr.rejected, 1);
    // Three that agree (within the noise of each other): the neighbour is elsewhere.
    let far = rotate(&s, 0.6);
    for (k, noise) in [0.0, 0.01, -0.01].into_iter().enumerate() {
        tr.update(&mut sh, &rotate(&far, noise), &dv, DT, &c, &LIMITS);
        assert_eq!(tr.resets, u32::from(k == 2));
    }
    assert!((sh - rotate(&far, -0.01)).norm() < 1e-12);
    // Ten scattered ones in a row: the track is lost whatever they are, and restarts at
    // the tenth (a bounded recovery).
    let mut tr = Track::default();
    let mut sh = Vec2::zeros();
    tr.update(&mut sh, &s, &dv, f64::NEG_INFINITY, &c, &LIMITS);
    for k in 0..10 {
        let z = rotate(&s, f64::to_radians(if k % 2 == 0 { 40.0 } else { -60.0 }));
        tr.update(&mut sh, &z, &dv, DT, &c, &LIMITS);
        assert_eq!(tr.resets, u32::from(k == 9), "outlier {k}");
    }
    assert!((sh - rotate(&s, f64::to_radians(-60.0))).norm() < 1e-12);
}

/// S15e: a track whose gate admits every sine (`g² S ≥ 1`: after a long prediction)
/// takes a bearing more than 90° from its prediction; a narrow track gates it out.
#[test]
fn a_wide_track_takes_a_bearing_behind_its_prediction() {
    let c = TrackerConfig::default();
    let dv = RelativeVelocity::default();
    let s = Vec2::new(1.0, 0.0);
    let z = rotate(&s, f64::to_radians(120.0));
    let run = |p00: f64| {
        let (mut tr, mut sh) = (Track::default(), Vec2::zeros());
        tr.update(&mut sh, &s, &dv, f64::NEG_INFINITY, &c, &LIMITS);
        tr.p[0] = p00;
        tr.update(&mut sh, &z, &dv, DT, &c, &LIMITS);
        (sh, tr)
    };
    let wide = 1.0 / (c.gate * c.gate);
    let (sh, tr) = run(wide);
    assert_eq!(tr.rejected, 0);
    // Moved towards z by the sine's step (K₀ e Jŝ, K₀ ≈ 1): about 41°.
    let moved = perp(&s).dot(&sh).asin();
    assert!(moved > 0.6, "{moved}");
    let (sh, tr) = run(0.1 * wide);
    assert_eq!(tr.rejected, 1);
    assert!((sh - s).norm() < 1e-9);
}
