//! The camera (`[sensors.camera]`, docs/sensors.md): what it sees and what it gets wrong,
//! on the sensor itself (`engine::sensors::Camera` through the `BearingSensor` seam) and
//! in runs: an all-seeing camera changes no bit of a run, a camera run gives the same bits
//! on 1 and 4 threads, and bad settings are refused with file, field and reason.

mod support;
use ph_formation_core::Vec2;
use ph_formation_sim::engine::sensors::{BearingKind, BearingSensor, Camera, Sensors, World};
use ph_formation_sim::engine::PARALLEL_MIN_AGENTS;
use ph_formation_sim::load;
use ph_formation_sim::model::{BearingRate, CameraModel, SensorModel};
use ph_formation_sim::scenario::strip_model;

const PERIOD: f64 = 0.01;
const KIND: BearingKind = BearingKind {
    exact_rate: false,
    with_range: false,
};

/// Ideal sensors (no noise: the camera alone decides).
fn sensors() -> Sensors {
    Sensors::new(&SensorModel::ideal(BearingRate::FiniteDifference), 7)
}

/// The agents at `q` (at rest, headings `h`) in one tick: agent `i`'s bearing of `j`
/// through `cam`, drawn from `i`'s stream of tick `tick`.
fn look(
    cam: &mut Camera,
    q: &[Vec2<f64>],
    h: &[f64],
    i: usize,
    j: usize,
    tick: u64,
) -> Option<Vec2<f64>> {
    let v = vec![Vec2::zeros(); q.len()];
    let world = World {
        q,
        v: &v,
        headings: h,
    };
    cam.prepare(&world);
    let ids: Vec<u8> = (0..q.len() as u8).collect();
    let s = sensors();
    cam.bearing(&world, &ids, i, j, KIND, &mut s.stream(i, tick))
        .map(|b| b.bearing)
}

fn camera(edit: impl FnOnce(&mut CameraModel)) -> CameraModel {
    let mut m = CameraModel::all_seeing();
    edit(&mut m);
    m
}

#[test]
fn a_camera_cannot_see_through_an_agent() {
    let model = camera(|c| c.occlusion_radius = 0.1);
    let mut cam = Camera::new(&model, 3, PERIOD);
    let mut q = vec![
        Vec2::new(0.0, 0.0),
        Vec2::new(1.0, 0.0),
        Vec2::new(2.0, 0.0),
    ];
    let h = [0.0; 3];
    // The middle agent hides the far one from either end, not the other way round.
    assert_eq!(look(&mut cam, &q, &h, 0, 2, 0), None);
    assert_eq!(look(&mut cam, &q, &h, 2, 0, 0), None);
    assert_eq!(look(&mut cam, &q, &h, 0, 1, 0), Some(Vec2::new(1.0, 0.0)));
    // Moved off the line by more than its radius: the far one is seen, exactly.
    q[1].y = 0.15;
    assert_eq!(look(&mut cam, &q, &h, 0, 2, 1), Some(Vec2::new(1.0, 0.0)));
    // Within its radius of the line: hidden again (the index follows the state).
    q[1].y = 0.05;
    assert_eq!(look(&mut cam, &q, &h, 0, 2, 2), None);
    // Without occlusion nothing hides anything.
    let mut clear = Camera::new(&CameraModel::all_seeing(), 3, PERIOD);
    assert!(look(&mut clear, &q, &h, 0, 2, 0).is_some());
}

#[test]
fn a_neighbour_outside_the_field_of_view_or_beyond_range_is_not_measured() {
    let model = camera(|c| {
        c.fov = 90f64.to_radians();
        c.range = 2.0;
    });
    let mut cam = Camera::new(&model, 2, PERIOD);
    let at = |deg: f64, r: f64| {
        let a = deg.to_radians();
        vec![Vec2::zeros(), Vec2::new(r * a.cos(), r * a.sin())]
    };
    // Heading 0: ±45° around x.
    assert!(look(&mut cam, &at(40.0, 1.0), &[0.0, 0.0], 0, 1, 0).is_some());
    assert!(look(&mut cam, &at(-40.0, 1.0), &[0.0, 0.0], 0, 1, 0).is_some());
    assert_eq!(look(&mut cam, &at(50.0, 1.0), &[0.0, 0.0], 0, 1, 0), None);
    assert_eq!(look(&mut cam, &at(180.0, 1.0), &[0.0, 0.0], 0, 1, 0), None);
    // The field of view turns with the heading (π/2: 45°–135°).
    let up = [std::f64::consts::FRAC_PI_2, 0.0];
    assert!(look(&mut cam, &at(50.0, 1.0), &up, 0, 1, 0).is_some());
    assert_eq!(look(&mut cam, &at(40.0, 1.0), &up, 0, 1, 0), None);
    // Range: 1.9 m seen, 2.1 m not.
    assert!(look(&mut cam, &at(0.0, 1.9), &[0.0, 0.0], 0, 1, 0).is_some());
    assert_eq!(look(&mut cam, &at(0.0, 2.1), &[0.0, 0.0], 0, 1, 0), None);
    // A field of view above 180° sees behind but not straight back (270°: ±135°).
    let mut wide = Camera::new(&camera(|c| c.fov = 270f64.to_radians()), 2, PERIOD);
    assert!(look(&mut wide, &at(130.0, 1.0), &[0.0, 0.0], 0, 1, 0).is_some());
    assert_eq!(look(&mut wide, &at(140.0, 1.0), &[0.0, 0.0], 0, 1, 0), None);
}

/// `trials` looks of agent 0 at agent 1 (one per tick: a fresh stream each).
fn looks(model: &CameraModel, trials: u64) -> Vec<Option<Vec2<f64>>> {
    let mut cam = Camera::new(model, 2, PERIOD);
    let q = [Vec2::zeros(), Vec2::new(3.0, 0.0)];
    (0..trials)
        .map(|t| look(&mut cam, &q, &[0.0, 0.0], 0, 1, t))
        .collect()
}

#[test]
fn a_visible_neighbour_is_detected_with_the_detection_probability() {
    let n = 20_000;
    for p in [0.3, 0.9] {
        let seen = looks(&camera(|c| c.detection_probability = p), n);
        let k = seen.iter().filter(|b| b.is_some()).count() as f64;
        // Binomial: within 5 standard deviations of n p.
        let sd = (n as f64 * p * (1.0 - p)).sqrt();
        assert!((k - n as f64 * p).abs() < 5.0 * sd, "p = {p}: {k} of {n}");
        // What is detected is the true bearing.
        assert!(seen.iter().flatten().all(|b| *b == Vec2::new(1.0, 0.0)));
    }
    assert!(looks(&camera(|c| c.detection_probability = 0.0), 100)
        .iter()
        .all(Option::is_none));
}

#[test]
fn outlier_probability_one_gives_bearings_uncorrelated_with_the_truth() {
    let n = 20_000;
    let b: Vec<Vec2<f64>> = looks(&camera(|c| c.outlier_probability = 1.0), n)
        .into_iter()
        .map(|b| b.expect("detected"))
        .collect();
    let mean = |f: &dyn Fn(&Vec2<f64>) -> f64| b.iter().map(f).sum::<f64>() / n as f64;
    // The truth is (1, 0): E[b · s] = 0 (standard deviation of the mean √(1/2n) = 0.005),
    // and the directions are spread all round (E|cos θ| = 2/π for a uniform θ).
    assert!(mean(&|v| v.x).abs() < 0.025, "{}", mean(&|v| v.x));
    assert!(mean(&|v| v.y).abs() < 0.025, "{}", mean(&|v| v.y));
    let spread = mean(&|v| v.x.abs()) - 2.0 / std::f64::consts::PI;
    assert!(spread.abs() < 0.02, "{spread}");
    assert!(b.iter().all(|v| (v.norm() - 1.0).abs() < 1e-12));
    // Half the outliers: about half the bearings are the truth.
    let half = looks(&camera(|c| c.outlier_probability = 0.5), n);
    let truth = half
        .iter()
        .filter(|b| **b == Some(Vec2::new(1.0, 0.0)))
        .count() as f64;
    assert!((truth / n as f64 - 0.5).abs() < 0.02, "{truth}");
}

/// Agent 1's position at tick `t`: moving at (0.5, −0.3) m/s from (2, 1).
fn moving(t: usize) -> Vec2<f64> {
    let s = t as f64 * PERIOD;
    Vec2::new(2.0 + 0.5 * s, 1.0 - 0.3 * s)
}

/// Agent 0's bearing of agent 1 (moving, [`moving`]) at tick `ticks - 1` through a camera
/// with latency `latency`.
fn late_bearing(latency: f64, ticks: usize) -> Vec2<f64> {
    let mut cam = Camera::new(&camera(|c| c.latency = latency), 2, PERIOD);
    let mut last = None;
    for t in 0..ticks {
        last = look(&mut cam, &[Vec2::zeros(), moving(t)], &[0.0; 2], 0, 1, 0);
    }
    last.expect("seen")
}

#[test]
fn latency_gives_the_bearing_of_the_state_latency_ago() {
    let unit = |d: Vec2<f64>| d / d.norm();
    // Three periods: the stored state of tick 47, bit for bit.
    assert_eq!(late_bearing(0.03, 51), unit(moving(47)));
    assert_ne!(late_bearing(0.03, 51), unit(moving(50)));
    // No latency: this tick's.
    assert_eq!(late_bearing(0.0, 51), unit(moving(50)));
    // 2.5 periods: between ticks 47 and 48, exact for constant velocity.
    let s = 50.0 * PERIOD - 0.025;
    let truth = unit(Vec2::new(2.0 + 0.5 * s, 1.0 - 0.3 * s));
    assert!((late_bearing(0.025, 51) - truth).norm() < 1e-12);
    // Before the history is that long: the first state.
    assert_eq!(late_bearing(0.1, 5), unit(moving(0)));
}

use support::bits;

#[test]
fn an_all_seeing_camera_changes_no_bit() {
    let plain = load("formation-only", &["duration=2".to_owned()]).expect("load");
    let mut seeing = plain.clone();
    seeing.sensors.camera = Some(CameraModel::all_seeing());
    assert_eq!(bits(&plain, 200, 1), bits(&seeing, 200, 1));
    // A narrow one does change them (the camera's path is the one taken).
    seeing.sensors.camera = Some(camera(|c| c.fov = 1.0));
    assert_ne!(bits(&plain, 200, 1), bits(&seeing, 200, 1));
}

#[test]
fn a_camera_run_with_occlusion_gives_the_same_bits_on_1_and_4_threads() {
    let n = PARALLEL_MIN_AGENTS + 300;
    let mut m = strip_model(n, 1.0).unwrap();
    // Every fifth agent moved onto the segment between its two neighbours of the other
    // row: it hides one from the other (spacing 0.5 m, bodies of 0.2 m).
    let h = 3f64.sqrt() / 2.0;
    for k in (1..n - 1).step_by(5) {
        m.agents[k].position = [0.5 * k as f64, h * ((k + 1) % 2) as f64];
    }
    m.sensors.bearing_noise = 0.01;
    // All round (the headings are 0: a narrower view would send every agent to its safe
    // output, whatever the rest of the camera does).
    m.sensors.camera = Some(camera(|c| {
        c.range = 1.5;
        c.occlusion_radius = 0.2;
        c.detection_probability = 0.95;
        c.outlier_probability = 0.02;
        c.latency = 0.025;
    }));
    let one = bits(&m, 20, 1);
    assert!(one == bits(&m, 20, 4), "the states differ");
    // Occlusion changed the run (the test is not comparing camera-less runs).
    let mut clear = m.clone();
    if let Some(c) = clear.sensors.camera.as_mut() {
        c.occlusion_radius = 0.0;
    }
    assert!(one != bits(&clear, 20, 1));
}

#[test]
fn every_camera_field_can_be_set() {
    let sets: Vec<String> = [
        "sensors.camera.fov_deg=90",
        "sensors.camera.range_m=4",
        "sensors.camera.occlusion_radius_m=0.1",
        "sensors.camera.detection_probability=0.8",
        "sensors.camera.outlier_probability=0.05",
        "sensors.camera.latency_s=0.02",
    ]
    .map(str::to_owned)
    .to_vec();
    let m = load("formation-only", &sets).expect("load");
    let c = m.sensors.camera.expect("a camera");
    assert_eq!(c.fov, 90f64.to_radians());
    assert_eq!(
        [
            c.range,
            c.occlusion_radius,
            c.detection_probability,
            c.outlier_probability,
            c.latency
        ],
        [4.0, 0.1, 0.8, 0.05, 0.02]
    );
    // One field alone: a camera with the others at the ideal camera's values.
    let m = load("formation-only", &sets[..1]).expect("load");
    let c = m.sensors.camera.expect("a camera");
    assert_eq!(c.range, f64::INFINITY);
    assert_eq!(c.detection_probability, 1.0);
    assert!(load("formation-only", &[])
        .expect("load")
        .sensors
        .camera
        .is_none());
}

#[test]
fn bad_camera_settings_are_refused_with_file_field_and_reason() {
    let file = concat!(env!("CARGO_MANIFEST_DIR"), "/scenarios/formation-only.toml");
    let cases: &[(&str, &str, &str)] = &[
        ("fov_deg=0", "sensors.camera.fov_deg", "(0, 360]"),
        ("fov_deg=-10", "sensors.camera.fov_deg", "(0, 360]"),
        ("fov_deg=361", "sensors.camera.fov_deg", "(0, 360]"),
        ("fov_deg=nan", "sensors.camera.fov_deg", "(0, 360]"),
        ("range_m=-1", "sensors.camera.range_m", "> 0"),
        ("range_m=nan", "sensors.camera.range_m", "> 0"),
        ("range_m=0", "sensors.camera.range_m", "> 0"),
        (
            "detection_probability=1.5",
            "sensors.camera.detection_probability",
            "[0, 1]",
        ),
        (
            "detection_probability=-0.1",
            "sensors.camera.detection_probability",
            "[0, 1]",
        ),
        (
            "outlier_probability=2",
            "sensors.camera.outlier_probability",
            "[0, 1]",
        ),
        (
            "outlier_probability=nan",
            "sensors.camera.outlier_probability",
            "[0, 1]",
        ),
        ("latency_s=-0.01", "sensors.camera.latency_s", "≥ 0"),
        ("latency_s=5", "sensors.camera.latency_s", "history"),
        (
            "occlusion_radius_m=-0.1",
            "sensors.camera.occlusion_radius_m",
            "≥ 0",
        ),
        // The closest agents of formation-only are 2 and 4, 1.27 m apart.
        (
            "occlusion_radius_m=1.3",
            "sensors.camera.occlusion_radius_m",
            "agents 2 and 4",
        ),
    ];
    for (set, field, reason) in cases {
        let e = load(file, &[format!("sensors.camera.{set}")]).expect_err(set);
        let first = &e.0[0];
        assert_eq!(first.field, *field, "{set}: {e}");
        assert_eq!(first.file, file, "{set}: {e}");
        assert!(first.reason.contains(reason), "{set}: {e}");
    }
    // A position that is not a number is the agent's error (no closest pair of it).
    let sets = [
        "agents.0.position=[nan, 0.0]".to_owned(),
        "sensors.camera.occlusion_radius_m=0.1".to_owned(),
    ];
    let e = load(file, &sets).expect_err("nan");
    assert_eq!(e.0[0].field, "agents[0].position", "{e}");
    assert!(e.0.iter().all(|e| !e.field.contains("camera")), "{e}");
    // Just below the spacing: accepted.
    let ok = ["sensors.camera.occlusion_radius_m=1.27".to_owned()];
    assert!(load(file, &ok).is_ok());
    // A camera measures no rates, and continuous mode has no camera.
    let with = |other: &str| {
        let sets = ["sensors.camera.fov_deg=90".to_owned(), other.to_owned()];
        load(file, &sets).expect_err(other).0[0].field.clone()
    };
    assert_eq!(with("sensors.bearing_rate=exact"), "sensors.bearing_rate");
    assert_eq!(with("mode=continuous"), "sensors.camera");
    assert!(load(file, &["sensors.bearing_rate=exact".to_owned()]).is_ok());
}
