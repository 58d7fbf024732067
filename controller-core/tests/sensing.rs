//! Finite-difference bearing rates (SPEC §2), as the agent computes them.

mod testkit;

use ph_formation_core::{BearingMeasurement, Measurements, Vec2};
use testkit::{rng, strip, strip_positions, Formation};

#[test]
fn finite_difference_rate_tracks_a_rotating_bearing_across_missed_ticks() {
    let mut r = rng(0);
    let mut f = Formation::random(4, strip(4), &strip_positions(4, 0.1, &mut r), &mut r);
    f.leader = None;
    let mut c = f.config(0);
    c.bearing_filter = ph_formation_core::BearingFilter::FiniteDifference;
    let mut a = testkit::HostAgent::<f64>::new(c).expect("valid");
    let (omega, dt) = (0.8, 0.01);
    let bearing = |k: usize, to: u8| {
        let th = omega * dt * k as f64 + f64::from(to);
        BearingMeasurement {
            neighbour: to,
            bearing: Vec2::new(th.cos(), th.sin()),
            rate: None,
            range: None,
        }
    };
    for k in 0..6usize {
        // Tick 3: the sensor misses agent 2.
        let b: Vec<_> = if k == 3 {
            vec![bearing(k, 3)]
        } else {
            vec![bearing(k, 2), bearing(k, 3)]
        };
        let m = Measurements {
            time: k as f64 * dt,
            dt,
            velocity: Vec2::zeros(),
            bearings: &b,
            partner_offset: None,
        };
        let _ = a.step(&m);
        let rate = a.bearing(2).map(|(_, rate)| rate);
        if k == 0 || k == 3 {
            // First tick: zero rate; missed tick: no bearing this tick.
            assert!(
                rate.is_none_or(|r| r == Vec2::zeros()),
                "tick {k}: {rate:?}"
            );
            continue;
        }
        // Midpoint of the difference: the previous bearing is from tick k − 1, or k − 2 after the miss.
        let prev = if k == 4 { 2.0 } else { k as f64 - 1.0 };
        let th = omega * dt * (k as f64 + prev) / 2.0 + 2.0;
        let exact = Vec2::new(-th.sin(), th.cos()) * omega;
        let got = rate.expect("rate broadcast");
        assert!(
            (got - exact).norm() <= 1e-3 * omega,
            "tick {k}: {got:?} vs {exact:?}"
        );
    }
}
