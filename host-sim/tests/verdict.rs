//! The honest verdict (docs/outputs.md, "Outcome"): negative controls that must never be
//! `converged` — a frozen controller, a controller too weak to move, a camera that sees
//! nothing, a wrong target, noise too large for the shape to hold — and the genuine
//! successes, each asserting the exact outcome over several seeds.

use ph_formation_sim::engine::{self as sim, drive, NullRecorder, RunResult, SampledSim};
use ph_formation_sim::model::Model;
use ph_formation_sim::{load, Outcome};

const STRIP: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/scenarios/strip20.toml");

fn model(name: &str, overrides: &[&str]) -> Model {
    let o: Vec<String> = overrides.iter().map(|s| (*s).to_owned()).collect();
    load(name, &o).unwrap_or_else(|e| panic!("{name}: {e}"))
}

fn run(m: &Model) -> RunResult {
    sim::run(m, &mut NullRecorder, &mut |_| {}).expect("run")
}

/// `name` with `overrides` under seeds 1–3: each run's outcome.
fn seeds(name: &str, overrides: &[&str]) -> Vec<RunResult> {
    (1..=3)
        .map(|s| {
            let seed = format!("seed={s}");
            let mut o = overrides.to_vec();
            o.push(&seed);
            run(&model(name, &o))
        })
        .collect()
}

fn assert_all(rs: &[RunResult], want: Outcome, what: &str) {
    for (k, r) in rs.iter().enumerate() {
        assert_eq!(r.outcome, want, "{what}, seed {}: {}", k + 1, r.reason);
    }
}

/// The trial: a 90° camera never sees the strip's neighbours; the band of the old
/// verdict (√2 σ = 9.9°) was wider than the initial error, so it said `converged`.
#[test]
fn a_blind_camera_is_not_in_control_and_says_why() {
    let rs = seeds(
        STRIP,
        &[
            "sensors.bearing_noise_deg=7",
            "sensors.camera.fov_deg=90",
            "duration=20",
        ],
    );
    assert_all(&rs, Outcome::NotInControl, "90° camera");
    let r = &rs[0];
    assert!(r.reason.contains("safe output"), "{}", r.reason);
    assert!(r.reason.contains("bearings missing"), "{}", r.reason);
    assert!(r.reason.contains("no bearing to agent"), "{}", r.reason);
    assert_eq!(r.outcome.exit_code(), 15);
    assert!(r.safe_share.unwrap() > 0.99);
}

/// A camera that detects nothing, and one whose range reaches no neighbour.
#[test]
fn a_camera_that_sees_nothing_is_not_in_control() {
    for o in [
        "sensors.camera.detection_probability=0",
        "sensors.camera.range_m=0.01",
    ] {
        let rs = seeds(
            "formation-only",
            &[o, "sensors.bearing_noise_deg=2", "duration=20"],
        );
        assert_all(&rs, Outcome::NotInControl, o);
    }
}

/// A frozen controller: nothing is ever heard (every frame lost), every agent stays in
/// its safe output.
#[test]
fn a_frozen_controller_is_not_in_control() {
    let rs = seeds(
        "paper",
        &["radio.loss=1", "sensors.bearing_noise_deg=2", "duration=30"],
    );
    assert_all(&rs, Outcome::NotInControl, "every frame lost");
    assert!(
        rs[0].reason.contains("a neighbour silent"),
        "{}",
        rs[0].reason
    );
    // Noise-free too: the control check is for every run.
    let r = run(&model("paper", &["radio.loss=1", "duration=30"]));
    assert_eq!(r.outcome, Outcome::NotInControl, "{}", r.reason);
}

/// A controller too weak to move: in control, but the errors never fall into the band.
#[test]
fn a_controller_too_weak_to_move_does_not_converge() {
    let rs = seeds(
        STRIP,
        &[
            "gains.stiffness=1e-6",
            "sensors.bearing_noise_deg=2",
            "duration=20",
        ],
    );
    assert_all(&rs, Outcome::NotConverged, "stiffness 1e-6");
    assert!(rs[0].reason.contains("not held"), "{}", rs[0].reason);
}

/// Noise too large for the shape to hold: the calibration's band would exceed the 1° cap,
/// and the run's errors do.
#[test]
fn noise_beyond_the_cap_does_not_converge() {
    let rs = seeds(STRIP, &["sensors.bearing_noise_deg=25", "duration=30"]);
    assert_all(&rs, Outcome::NotConverged, "25° noise");
    let s = rs[0].steady.expect("judged with bands");
    assert!(s.bands.capped[0], "{s:?}");
    // The same scenario with the cap widened explicitly in [criteria] holds (the cap,
    // not the run, decided).
    let wide = run(&model(
        STRIP,
        &[
            "sensors.bearing_noise_deg=25",
            "duration=30",
            "seed=1",
            "criteria.angle_band_cap=0.2",
        ],
    ));
    assert_eq!(wide.outcome, Outcome::Converged, "{}", wide.reason);
}

/// A wrong target: the controllers hold angles 2° off the ones the verdict judges.
#[test]
fn a_wrong_target_does_not_converge() {
    for noise in ["0", "1"] {
        let judge = model(
            "formation-only",
            &[&format!("sensors.bearing_noise_deg={noise}"), "duration=40"],
        );
        let mut ctrl = judge.clone();
        for t in &mut ctrl.triangles {
            t.angles[0].desired += 2f64.to_radians();
        }
        let mut engine = SampledSim::new(&ctrl).expect("engine");
        let r = drive(&judge, &mut engine, &mut NullRecorder, &mut |_| {}, vec![]).expect("run");
        // One angle per triangle 2° (0.035 rad) off the judged one, beyond the noise-free
        // tolerance and the calibrated band alike: not converged (not a wrong shape,
        // which needs every angle within its tolerance).
        assert_eq!(
            r.outcome,
            Outcome::NotConverged,
            "noise {noise}: {}",
            r.reason
        );
        // The positive control: the same judge on the right controllers converges.
        let mut engine = SampledSim::new(&judge).expect("engine");
        let ok = drive(&judge, &mut engine, &mut NullRecorder, &mut |_| {}, vec![]).expect("run");
        assert_eq!(
            ok.outcome,
            Outcome::Converged,
            "noise {noise}: {}",
            ok.reason
        );
    }
}

/// The genuine successes stay `converged`: the paper's run (noise-free criteria, today's
/// settle time), formation-only, and the strip at 2° and 10 % loss over three seeds.
#[test]
fn genuine_successes_converge() {
    let p = run(&model("paper", &[]));
    assert_eq!(p.outcome, Outcome::Converged, "{}", p.reason);
    assert!(p.steady.is_none(), "a noise-free run keeps its criteria");
    assert_eq!(p.settle_time, Some(40.85));
    let rs = seeds(
        STRIP,
        &[
            "sensors.bearing_noise_deg=2",
            "radio.loss=0.1",
            "duration=40",
        ],
    );
    assert_all(&rs, Outcome::Converged, "strip20 at 2°, 10 % loss");
    for r in &rs {
        let s = r.steady.expect("judged with bands");
        // The bands come from the calibration, under the cap.
        assert!(s.bands.calibration.is_some() && !s.bands.capped[0], "{s:?}");
        assert!(s.bands.angle < 1f64.to_radians());
        assert!(r.settle_time.unwrap() <= s.window.from);
    }
    let rs = seeds(
        "formation-only",
        &[
            "sensors.bearing_noise_deg=2",
            "radio.loss=0.1",
            "duration=30",
        ],
    );
    assert_all(&rs, Outcome::Converged, "formation-only at 2°, 10 % loss");
}

/// The camera with 1 % outliers and no bearing noise: `auto` runs the tracker
/// (the chain is lossy), and the run converges.
#[test]
fn camera_outliers_without_noise_converge_on_the_tracker() {
    let m = model(
        "formation-only",
        &[
            "sensors.camera.fov_deg=360",
            "sensors.camera.outlier_probability=0.01",
            "sensors.bearing_noise_deg=0",
            "duration=40",
        ],
    );
    assert!(
        matches!(
            m.sensors.bearing_filter,
            ph_formation_core::BearingFilter::Tracker(_)
        ),
        "auto must pick the tracker for a lossy camera"
    );
    let r = run(&m);
    assert_eq!(r.outcome, Outcome::Converged, "{}", r.reason);
}

/// A leader edge turned by a heading error is a pose error, reported apart, not a
/// shape failure.
#[test]
fn pose_is_reported_apart_from_shape() {
    let r = run(&model("paper", &["sensors.bearing_noise_deg=1"]));
    assert_eq!(r.outcome, Outcome::Converged, "{}", r.reason);
    let (fin, p95) = r.pose.orientation.expect("leader edge");
    assert!(fin.is_finite() && p95 >= 0.0);
    assert!(r.pose.scale_rel.is_some() && r.pose.translation.is_some());
    let none = run(&model("formation-only", &["duration=20"]));
    assert!(none.pose.orientation.is_none() && none.pose.scale_rel.is_none());
}

/// A channel far too slow for the swarm's frames: the neighbours fall silent, and the
/// reason says the channel was overloaded.
#[test]
fn an_overloaded_channel_is_named() {
    let r = run(&model(
        STRIP,
        &[
            "radio.channel.preset=crazyflie",
            "radio.channel.bit_rate_bps=2000",
            "duration=10",
        ],
    ));
    assert_eq!(r.outcome, Outcome::NotInControl, "{}", r.reason);
    assert!(r.reason.contains("a neighbour silent"), "{}", r.reason);
    assert!(r.reason.contains("channel was overloaded"), "{}", r.reason);
}
