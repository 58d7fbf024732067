//! Issue 29's "one of each": the simulator uses the core's one implementation of what it
//! promises (continuous mode's output), and the shortcut switches follow the models'
//! one classification of their fields.

use ph_formation_core::Status;
use ph_formation_sim::engine::sensors::Sensors;
use ph_formation_sim::engine::{direct_radio, run, ContinuousSim, NullRecorder};
use ph_formation_sim::model::{BearingRate, Mode, RadioModel, SensorModel};
use ph_formation_sim::scenario::strip_model;

/// Continuous mode's output is the core's `Agent::output`: an agent whose velocity is not
/// finite gets the safe command with a zero (finite) force, never a NaN (the continuous
/// simulator once computed `−safe_damping · v` itself, without the core's guard).
#[test]
fn continuous_mode_never_outputs_a_non_finite_force() {
    let mut model = strip_model(4, 1.0).unwrap();
    model.mode = Mode::Continuous;
    for v in [[f64::NAN, 0.0], [0.0, f64::INFINITY]] {
        model.agents[1].velocity = v;
        let mut sim = ContinuousSim::new(&model).expect("builds");
        let out = sim.output_of(0.0, 1).expect("agent 1 exists");
        assert!(matches!(out.status, Status::Safe(_)), "{out:?}");
        assert_eq!([out.force.x, out.force.y], [0.0, 0.0], "{out:?}");
        // Its neighbours see a non-finite bearing rate: safe too, with finite forces.
        for i in [0, 2, 3] {
            let out = sim.output_of(0.0, i).expect("exists");
            assert!(
                out.force.x.is_finite() && out.force.y.is_finite(),
                "{i}: {out:?}"
            );
        }
    }
    assert!(ContinuousSim::new(&model)
        .unwrap()
        .output_of(0.0, 4)
        .is_none());
}

/// Every radio field, set alone away from the ideal radio, is classified once
/// (`RadioModel::departures`), and both switches follow it: `is_faulty` (continuous mode's
/// warning) and direct delivery (`engine::direct_radio`), which only a latency under half
/// a period, or a setting that acts only with another (`queue_limit`, `reorder_delay`),
/// keeps. A reordering with no delay still draws and counts in the radio: it once kept
/// direct delivery (`direct_radio` repeated the fields with its own rules) and lost the
/// count.
#[test]
fn the_radio_shortcut_follows_the_one_classification() {
    let base = strip_model(6, 0.2).unwrap();
    let half = 0.5 * base.control_period();
    type Set = fn(&mut RadioModel);
    // (field, change, direct delivery kept, is_faulty)
    let cases: [(&str, Set, bool, bool); 11] = [
        ("none", |_| {}, true, false),
        ("latency (short)", |r| r.latency = 1e-3, true, true),
        ("latency (long)", |r| r.latency = 0.02, false, true),
        ("jitter", |r| r.jitter = 1e-3, false, true),
        ("loss", |r| r.loss = 0.1, false, true),
        ("duplication", |r| r.duplication = 0.1, false, true),
        ("reordering", |r| r.reordering = 0.5, false, true),
        ("reorder_delay", |r| r.reorder_delay = 0.01, true, false),
        ("corruption", |r| r.corruption = 0.1, false, true),
        ("bandwidth", |r| r.bandwidth = 1e4, false, true),
        ("queue_limit", |r| r.queue_limit = 0.2, true, false),
    ];
    for (field, set, direct, faulty) in cases {
        let mut m = base.clone();
        set(&mut m.radio);
        assert!(m.radio.latency < half || field == "latency (long)");
        assert_eq!(direct_radio(&m), direct, "{field}");
        assert_eq!(m.radio.is_faulty(), faulty, "{field}");
        let d = m.radio.departures();
        assert_eq!(
            m.radio.is_faulty(),
            d.alters_frames || d.latency != 0.0,
            "{field}"
        );
    }
    // The reordering without delay goes through the radio, which counts it.
    let mut m = base.clone();
    m.radio.reordering = 0.5;
    let result = run(&m, &mut NullRecorder, &mut |_| {}).expect("runs");
    assert!(result.frames.reordered > 0, "{:?}", result.frames);
}

/// The sensors' shortcut (no draws from the random streams) and `is_noisy` follow the one
/// classification (`SensorModel::departures`): noise draws, a bias does not, range noise
/// draws only where ranges are measured.
#[test]
fn the_sensor_shortcut_follows_the_one_classification() {
    type Set = fn(&mut SensorModel);
    // (field, change, draws without ranges, draws with ranges)
    let cases: [(&str, Set, bool, bool); 7] = [
        ("none", |_| {}, false, false),
        ("bearing_noise", |s| s.bearing_noise = 0.01, true, true),
        ("bearing_bias", |s| s.bearing_bias = 0.01, false, false),
        ("velocity_noise", |s| s.velocity_noise = 0.01, true, true),
        (
            "velocity_bias",
            |s| s.velocity_bias = [0.0, 0.01],
            false,
            false,
        ),
        ("offset_noise", |s| s.offset_noise = 0.01, true, true),
        ("range_noise", |s| s.range_noise = 0.01, false, true),
    ];
    for (field, set, without, with) in cases {
        let mut s = SensorModel::ideal(BearingRate::Exact);
        set(&mut s);
        let sensors = Sensors::new(&s, 1);
        assert_eq!(sensors.draws(false), without, "{field}");
        assert_eq!(sensors.draws(true), with, "{field}");
        assert_eq!(s.is_noisy(), field != "none", "{field}");
    }
}
