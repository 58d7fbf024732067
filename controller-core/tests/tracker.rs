//! The bearing tracker of SPEC §11 (S15–S17) against known trajectories: exact with exact
//! data, unbiased and far less noisy than the finite difference with noisy data, and
//! immediate on a step in the neighbour's velocity. Configuration checks through
//! `Agent::new`.

mod testkit;

use ph_formation_core::geometry::{bearing_rate, perp};
use ph_formation_core::tracker::{RelativeVelocity, Track, TrackLimits};
use ph_formation_core::{BearingFilter, ConfigError, TrackerConfig, Vec2};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

const DT: f64 = 0.01;
const SIGMA_2DEG: f64 = 2.0 * std::f64::consts::PI / 180.0;

/// Own agent at the origin at rest; the neighbour starts at `p0` and moves with `v(t)`.
struct Scene {
    p0: Vec2<f64>,
    v1: Vec2<f64>,
    /// `(t_step, v2)`: the neighbour's velocity changes to `v2` at `t_step`.
    step: Option<(f64, Vec2<f64>)>,
}

impl Scene {
    fn velocity(&self, t: f64) -> Vec2<f64> {
        match self.step {
            Some((ts, v2)) if t >= ts => v2,
            _ => self.v1,
        }
    }
    fn position(&self, t: f64) -> Vec2<f64> {
        match self.step {
            Some((ts, v2)) if t >= ts => self.p0 + self.v1 * ts + v2 * (t - ts),
            _ => self.p0 + self.v1 * t,
        }
    }
    /// True bearing and S2 rate at `t`.
    fn truth(&self, t: f64) -> (Vec2<f64>, Vec2<f64>) {
        let p = self.position(t);
        let r = p.norm();
        let s = p / r;
        (s, bearing_rate(&s, &self.velocity(t), r))
    }
}

fn rotate(s: &Vec2<f64>, angle: f64) -> Vec2<f64> {
    let (sn, cs) = angle.sin_cos();
    Vec2::new(cs * s.x - sn * s.y, sn * s.x + cs * s.y)
}

/// A standard normal draw (Box–Muller).
fn normal(r: &mut ChaCha8Rng) -> f64 {
    let u1: f64 = r.random::<f64>().max(1e-300);
    let u2: f64 = r.random();
    (-2.0 * u1.ln()).sqrt() * (2.0 * std::f64::consts::PI * u2).cos()
}

fn config(sigma: f64) -> TrackerConfig<f64> {
    TrackerConfig {
        bearing_noise: sigma,
        ..TrackerConfig::default()
    }
}

const LIMITS: TrackLimits<f64> = TrackLimits {
    inv_range_initial: 1.0,
    inv_range_max: 10.0,
    max_interval: 1.0,
};

/// Runs the tracker over `[0, t_end]` with bearing noise `sigma`; calls `each(t, ŝ, ṡ̂,
/// z, z_prev)` from the second tick on.
fn run(
    scene: &Scene,
    sigma: f64,
    t_end: f64,
    seed: u64,
    mut each: impl FnMut(f64, Vec2<f64>, Vec2<f64>, Vec2<f64>, Vec2<f64>),
) {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let c = config(sigma.max(1e-3));
    let mut tr = Track::default();
    let mut sh = Vec2::zeros();
    let mut prev = None;
    let steps = (t_end / DT).round() as usize;
    for k in 0..=steps {
        let t = k as f64 * DT;
        let (s, _) = scene.truth(t);
        let z = rotate(&s, sigma * normal(&mut rng));
        let over_interval = scene.velocity((t - DT).max(0.0));
        // The first bearing has no previous one: an interval of −∞, as the agent passes.
        let dt = if k == 0 { f64::NEG_INFINITY } else { DT };
        let dv = RelativeVelocity {
            over_interval,
            now: scene.velocity(t),
        };
        let rh = tr.update(&mut sh, &z, &dv, dt, &c, &LIMITS);
        if let Some(zp) = prev {
            each(t, sh, rh, z, zp);
        }
        prev = Some(z);
    }
}

fn crossing() -> Scene {
    Scene {
        p0: Vec2::new(3.0, -4.0),
        v1: Vec2::new(0.0, 0.5),
        step: None,
    }
}

#[test]
fn exact_bearings_give_the_exact_bearing_and_rate() {
    // The track starts with ρ̂ = 1 /m against the true 1/5 /m: the relative motion makes
    // the inverse distance observable, and the rate converges to S2.
    let scene = crossing();
    let mut worst = (0.0f64, 0.0f64);
    run(&scene, 0.0, 12.0, 1, |t, sh, rh, _, _| {
        if t >= 4.0 {
            let (s, rate) = scene.truth(t);
            worst.0 = worst.0.max((sh - s).norm());
            worst.1 = worst.1.max((rh - rate).norm() / rate.norm());
        }
    });
    assert!(worst.0 < 1e-5, "bearing error {:e}", worst.0);
    assert!(worst.1 < 1e-3, "relative rate error {:e}", worst.1);
}

#[test]
fn noisy_bearings_unbiased_and_far_less_noisy_than_the_finite_difference() {
    let scene = crossing();
    let (mut n, mut fd_sq, mut tr_sq, mut s_sq, mut raw_sq) = (0.0, 0.0, 0.0, 0.0, 0.0);
    let mut bias = Vec2::zeros();
    for seed in 0..20 {
        run(&scene, SIGMA_2DEG, 12.0, seed, |t, sh, rh, z, zp| {
            if t < 4.0 {
                return;
            }
            let (s, rate) = scene.truth(t);
            let fd = (z - zp) / DT;
            n += 1.0;
            fd_sq += (fd - rate).norm_squared();
            tr_sq += (rh - rate).norm_squared();
            s_sq += (sh - s).norm_squared();
            raw_sq += (z - s).norm_squared();
            bias += rh - rate;
        });
    }
    let (fd, tr) = ((fd_sq / n).sqrt(), (tr_sq / n).sqrt());
    let (s_rms, raw) = ((s_sq / n).sqrt(), (raw_sq / n).sqrt());
    // The finite difference: about √2 σ / Δt ≈ 4.9 rad/s of noise on a 0.1 rad/s rate.
    assert!(fd > 3.0, "finite difference RMS {fd}");
    assert!(
        tr < fd / 100.0,
        "tracker RMS {tr} vs finite difference {fd}"
    );
    assert!(s_rms < raw / 3.0, "bearing RMS {s_rms} vs raw {raw}");
    // Unbiased: the mean rate error is small against the rate (≈ 0.1 rad/s).
    let mean = bias / n;
    assert!(mean.norm() < 2e-3, "mean rate error {mean:?}");
}

#[test]
fn a_step_in_the_neighbours_velocity_shows_in_the_rate_at_once() {
    // The prediction is driven by the relative velocity: a neighbour that turns is
    // followed in the same tick, not after a filter lag.
    let scene = Scene {
        p0: Vec2::new(4.0, 0.0),
        v1: Vec2::new(0.0, 0.6),
        step: Some((6.0, Vec2::new(0.0, -0.6))),
    };
    let jump = (scene.truth(6.0).1 - scene.truth(5.99).1).norm();
    let (mut before, mut after) = (0.0f64, 0.0f64);
    run(&scene, 0.0, 9.0, 2, |t, _, rh, _, _| {
        let (_, rate) = scene.truth(t);
        let e = (rh - rate).norm();
        if (5.0..6.0).contains(&t) {
            before = before.max(e);
        } else if t >= 6.0 {
            after = after.max(e);
        }
    });
    assert!(jump > 0.1, "rate jump {jump}");
    // No transient: the error after the step is the error the track had before it (of
    // its inverse distance, still converging), and a few per cent of the jump. A filter
    // of the rate alone would lag by its time constant, with an error of the whole jump
    // at first.
    assert!(
        after <= 1.1 * before + 1e-4 && after < 0.05 * jump,
        "rate error {after} after the step, {before} before it, against a jump of {jump}"
    );
}

#[test]
fn an_outlier_is_gated_out_and_a_lost_track_restarts() {
    let c = config(SIGMA_2DEG);
    let mut tr = Track::default();
    let s = Vec2::new(1.0, 0.0);
    let mut sh = Vec2::zeros();
    let dv = RelativeVelocity::default();
    tr.update(&mut sh, &s, &dv, f64::NEG_INFINITY, &c, &LIMITS);
    for _ in 0..50 {
        tr.update(&mut sh, &s, &dv, DT, &c, &LIMITS);
    }
    // 20° off: ten standard deviations.
    let wrong = rotate(&s, 20f64.to_radians());
    tr.update(&mut sh, &wrong, &dv, DT, &c, &LIMITS);
    assert!((sh - s).norm() < 1e-9, "an outlier moved the track: {sh:?}");
    assert_eq!(tr.rejected, 1);
    tr.update(&mut sh, &s, &dv, DT, &c, &LIMITS);
    assert!((sh - s).norm() < 1e-9);
    assert_eq!(tr.rejected, 0);
    // A wrong bearing behind the track (where the innovation's sine is small again) is
    // an outlier too, not a restart.
    let behind = rotate(&s, 179f64.to_radians());
    tr.update(&mut sh, &behind, &dv, DT, &c, &LIMITS);
    assert!(
        (sh - s).norm() < 1e-9,
        "a bearing behind moved the track: {sh:?}"
    );
    assert_eq!(tr.rejected, 1);
    tr.update(&mut sh, &s, &dv, DT, &c, &LIMITS);
    // Three in a row: the neighbour really is elsewhere; the track restarts there.
    for _ in 0..3 {
        tr.update(&mut sh, &wrong, &dv, DT, &c, &LIMITS);
    }
    assert!((sh - wrong).norm() < 1e-12);
    // The restarted track's rate is S17 with ρ̂(0).
    let turning = RelativeVelocity {
        over_interval: Vec2::zeros(),
        now: Vec2::new(0.0, 1.0),
    };
    let rate = tr.update(&mut sh, &wrong, &turning, DT, &c, &LIMITS);
    let t = perp(&wrong);
    assert!((rate - t * t.dot(&Vec2::new(0.0, 1.0))).norm() < 0.05);
}

#[test]
fn bad_tracker_settings_are_refused_by_the_agent() {
    let mut r = testkit::rng(3);
    let f = testkit::Formation::random(
        4,
        testkit::strip(4),
        &testkit::strip_positions(4, 0.1, &mut r),
        &mut r,
    );
    let good = f.config(0);
    assert!(testkit::HostAgent::<f64>::new(good.clone()).is_ok());
    let bad = [
        config(0.0),
        config(-0.01),
        config(f64::NAN),
        config(1.0),
        TrackerConfig {
            rate_noise: -1.0,
            ..config(0.01)
        },
        TrackerConfig {
            inverse_range_noise: f64::INFINITY,
            ..config(0.01)
        },
        TrackerConfig {
            gate: 0.5,
            ..config(0.01)
        },
    ];
    for t in bad {
        let mut c = good.clone();
        c.bearing_filter = BearingFilter::Tracker(t);
        assert_eq!(
            testkit::HostAgent::<f64>::new(c).err(),
            Some(ConfigError::BadBearingFilter),
            "{t:?}"
        );
    }
}
