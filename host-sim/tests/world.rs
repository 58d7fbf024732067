//! The robot's world (docs/world.md): clocks that drift by exactly their ppm, body frames
//! that change nothing when every heading estimate is right, the wind's gust process, the
//! `crazyflie` preset on room-sized formations, the speed-limit warning, and every new
//! field refused with file, field and reason.

#[path = "support/docs.rs"]
mod docs;

use ph_formation_sim::engine::world::{Clocks, Headings, Wind};
use ph_formation_sim::engine::{self as sim, NullRecorder, RunResult};
use ph_formation_sim::model::{ClockModel, HeadingModel, Model, WindModel};
use ph_formation_sim::{load, Outcome};

fn model(name: &str, overrides: &[&str]) -> Model {
    let o: Vec<String> = overrides.iter().map(|s| (*s).to_owned()).collect();
    load(name, &o).unwrap_or_else(|e| panic!("{name}: {e}"))
}

fn run(m: &Model) -> RunResult {
    sim::run(m, &mut NullRecorder, &mut |_| {}).expect("run")
}

fn refused(overrides: &[&str]) -> String {
    let o: Vec<String> = overrides.iter().map(|s| (*s).to_owned()).collect();
    match load("formation-only", &o) {
        Ok(_) => panic!("{overrides:?} was accepted"),
        Err(e) => e.to_string(),
    }
}

/// Each agent's clock reads `(1 + ε) t + φ` and ticks `k T` apart on it: over 1,000 s an
/// agent of rate error ε ticks `⌊1000 (1 + ε) / T⌋ + 1` times, and its readings advance
/// by exactly its rate.
#[test]
fn a_clock_drifts_by_exactly_its_ppm() {
    let m = model("formation-only", &["duration=1000"]);
    let c = ClockModel {
        offset: 0.0,
        ppm: 50.0,
        jitter: 0.0,
    };
    let mut clocks = Clocks::new(&m, &c);
    let period = m.control_period();
    let steps = m.total_steps();
    let mut counts = vec![0u64; m.n()];
    let mut last = vec![(0.0, 0.0); m.n()];
    for step in 0..=steps {
        if !clocks.any_due(step) {
            continue;
        }
        let t = m.time(step);
        for (i, count) in counts.iter_mut().enumerate() {
            if clocks.due(i, step) {
                let (local, _, k) = clocks.tick(i, t, step);
                assert_eq!(k, *count, "agent {i}: ticks in order");
                *count += 1;
                last[i] = (t, local);
            }
        }
    }
    let mut rates = Vec::new();
    for (i, &count) in counts.iter().enumerate() {
        let rate = clocks.rate(i);
        let ppm = (rate - 1.0) * 1e6;
        assert!(ppm.abs() <= 50.0, "agent {i}: {ppm} ppm");
        let want = (1000.0 * rate / period + 1e-9).floor() as u64 + 1;
        assert_eq!(count, want, "agent {i} at {ppm:.2} ppm");
        let (t, local) = last[i];
        assert!(
            (local - rate * t).abs() < 1e-9,
            "agent {i}: reading {local} at {t}"
        );
        rates.push(ppm);
    }
    // Different agents, different crystals.
    assert!(
        rates.iter().any(|&p| (p - rates[0]).abs() > 1.0),
        "{rates:?}"
    );
}

/// A run with own clocks ticks every agent at its own rate and still converges; the same
/// seed gives the same bits on one thread and on four.
#[test]
fn own_clocks_converge_and_are_reproducible_on_any_pool() {
    let m = model(
        "formation-only",
        &[
            "duration=30",
            "clock.ppm=50",
            "clock.offset_s=0.01",
            "clock.jitter_s=0.0002",
        ],
    );
    let on = |threads| {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap();
        pool.install(|| run(&m))
    };
    let (one, four) = (on(1), on(4));
    assert_eq!(one.outcome, Outcome::Converged, "{}", one.reason);
    let bits = |r: &RunResult| -> Vec<u64> {
        r.final_positions
            .iter()
            .flatten()
            .map(|x| x.to_bits())
            .collect()
    };
    assert_eq!(bits(&one), bits(&four));
    // Every agent ticked at about 100 Hz for 30 s (a random phase may skip t = 0).
    let ticks = one.control.ticks;
    assert!((4 * 2999..=4 * 3001).contains(&ticks), "{ticks}");
}

/// Bearings and velocities are measured in each agent's body frame and turned back by
/// its heading estimate, its force the other way: with every estimate exact, headings
/// spread all round give the world-frame run (to rounding).
#[test]
fn a_body_frame_run_is_the_world_frame_run_when_every_heading_is_known() {
    let world = run(&model("paper", &["duration=20"]));
    let body = run(&model(
        "paper",
        &[
            "duration=20",
            "heading.spread_deg=180",
            "heading.initial_deg=37",
        ],
    ));
    assert_eq!(body.outcome, world.outcome);
    for (a, b) in world.final_positions.iter().zip(&body.final_positions) {
        let d = (a[0] - b[0]).hypot(a[1] - b[1]);
        assert!(d < 1e-8, "{a:?} vs {b:?}");
    }
    // The true headings really differ: the frames are not all the world's.
    let m = model("paper", &["heading.spread_deg=180"]);
    let h = Headings::new(
        &m,
        &HeadingModel {
            initial: 0.0,
            spread: std::f64::consts::PI,
            error: 0.0,
            drift: 0.0,
            noise: 0.0,
        },
    );
    assert!(h.truth.iter().any(|&x| x.abs() > 0.5), "{:?}", h.truth);
}

/// A heading error turns what the agent senses and commands: a leader pair whose
/// estimates are off turns the leader edge with them when both hold `z*` in their own
/// frames (`leader.orientation = "held"`, S11; the default there is S11b, tests/heading.rs).
#[test]
fn heading_errors_turn_the_leader_edge() {
    let r = run(&model(
        "paper",
        &[
            "duration=60",
            "heading.error_deg=5",
            "seed=3",
            "leader.orientation=held",
        ],
    ));
    let exact = run(&model("paper", &["duration=60", "seed=3"]));
    assert!(
        r.final_displacement_error > 100.0 * exact.final_displacement_error.max(1e-6),
        "{} vs {}",
        r.final_displacement_error,
        exact.final_displacement_error
    );
}

/// The gusts are an Ornstein–Uhlenbeck process: stationary variance σ² per axis and
/// correlation `e^{−h/τ}` one step apart, over many agents.
#[test]
fn gusts_have_their_variance_and_correlation() {
    let m = ph_formation_sim::scenario::strip_model(400, 1.0).unwrap();
    let w = WindModel {
        mean: [0.0; 2],
        gust: 0.3,
        gust_time_constant: 2.0,
    };
    let mut wind = Wind::new(&m, &w);
    let h = 0.5;
    let (mut var, mut cov, mut count) = (0.0, 0.0, 0.0);
    for _ in 0..50 {
        let before: Vec<_> = wind.now.clone();
        wind.advance(h);
        for (a, b) in before.iter().zip(&wind.now) {
            var += b.x * b.x + b.y * b.y;
            cov += a.x * b.x + a.y * b.y;
            count += 2.0;
        }
    }
    let (var, rho) = (var / count, cov / count / (var / count));
    assert!((var / 0.09 - 1.0).abs() < 0.05, "variance {var}");
    let want = (-h / 2.0f64).exp();
    assert!((rho - want).abs() < 0.03, "correlation {rho} vs {want}");
}

/// `world = "crazyflie"` (the cascade, shared positions, absolute yaw) flies the app's
/// square. Its sensing is random (position noise, clock jitter), so one seed proves
/// little: of 5 seeds at least 4 must converge under the honest verdict and every one
/// must end with its angles within 0.01 rad. Why 4: all 5 converged when measured
/// (final errors 0.9–1.2 mrad); one seed may still meet a burst the calibration run did
/// not (docs/sensors.md, `paper`), and a broken cascade, lead or sensor fails them all.
/// `crazyflie-camera` loads with its camera and drifting yaw. Summary figures name the
/// preset and its assumptions.
#[test]
fn the_crazyflie_world_flies_the_apps_square() {
    use rayon::prelude::*;
    let square = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../crazyflie-app/formation.toml"
    );
    let m = model(square, &["world=crazyflie", "duration=100"]);
    assert_eq!(m.world.preset, "crazyflie");
    assert!(m.world.clock.is_some() && m.world.heading.is_none());
    assert!(!m.world.assumptions.is_empty());
    let runs: Vec<RunResult> = (1..=5u64)
        .into_par_iter()
        .map(|seed| {
            run(&model(
                square,
                &["world=crazyflie", "duration=100", &format!("seed={seed}")],
            ))
        })
        .collect();
    let converged = runs
        .iter()
        .filter(|r| r.outcome == Outcome::Converged)
        .count();
    let reasons: Vec<&str> = runs.iter().map(|r| r.reason.as_str()).collect();
    assert!(converged >= 4, "{converged} of 5 converged: {reasons:#?}");
    for r in &runs {
        assert!(
            r.final_max_angle_error < 0.01,
            "{}: {}",
            r.final_max_angle_error,
            r.reason
        );
    }
    // Noise-free, the cascade alone: the square converges with the second-order lead
    // (S21b; docs/crazyflie.md: "to settle in 14 s") and settles only after 60 s without
    // it. Nothing here is random: another seed gives the same bits, so one seed is
    // every seed.
    // S21b as it was (no S21d filter), then S21d's default.
    let alone = |extra: &[&str]| {
        let mut o = vec![
            "plant.model=crazyflie_pid",
            "duration=60",
            "plant.jerk_filter_s=0",
        ];
        o.extend_from_slice(extra);
        run(&model(square, &o))
    };
    let led = alone(&["plant.lead_s=0.2337"]);
    assert_eq!(led.outcome, Outcome::Converged, "{}", led.reason);
    let other_seed = alone(&["plant.lead_s=0.2337", "seed=2"]);
    assert_eq!(led.final_positions, other_seed.final_positions);
    let doc = docs::read("docs/crazyflie.md");
    let settle = docs::between(&doc, "`ph_actuator_set_second_lead`) to settle in", " s (");
    let got = led.settle_time.expect("settled");
    assert!(
        docs::shows(got, &settle),
        "docs/crazyflie.md: {settle} s, run {got} s"
    );
    // docs/world.md: "With S21 alone the app's square (plant only, noise-free) settles in
    // 97 s; with S21b in 13.8 s (…); the 20-agent strip settles in 10.75 s with S21b and
    // collapses without."
    let world = docs::read("docs/world.md");
    let unled = alone(&["plant.second_lead_s2=0", "duration=150"]);
    assert_eq!(unled.outcome, Outcome::Converged, "{}", unled.reason);
    let slow = unled.settle_time.expect("settled");
    assert!(
        slow > 60.0,
        "without S21b the square settles after 60 s: {slow}"
    );
    let said = docs::between(
        &world,
        "With S21 alone the app's square (plant only, noise-free) settles in",
        " s;",
    );
    assert!(
        docs::shows(slow, &said),
        "docs/world.md: {said} s, run {slow} s"
    );
    let said = docs::between(&doc, "to settle in 14 s (", " s with S21 alone)");
    assert!(
        docs::shows(slow, &said),
        "docs/crazyflie.md: {said} s, run {slow} s"
    );
    let said = docs::between(&world, "settles in 97 s; with S21b in", " s (");
    assert!(
        docs::shows(got, &said),
        "docs/world.md: {said} s, run {got} s"
    );
    let filtered = run(&model(
        square,
        &["plant.model=crazyflie_pid", "duration=60"],
    ));
    let t = filtered.settle_time.expect("settled");
    let said = docs::between(
        &world,
        "jerk filter (the default 0.03 s, below) the square settles in",
        " s and",
    );
    assert!(docs::shows(t, &said), "docs/world.md: {said} s, run {t} s");
    let strip = concat!(env!("CARGO_MANIFEST_DIR"), "/scenarios/strip20.toml");
    let strip_filtered = run(&model(strip, &["plant.model=crazyflie_pid", "duration=60"]));
    let t = strip_filtered.settle_time.expect("settled");
    let said = docs::between(&world, " s and the strip in", " s (");
    assert!(docs::shows(t, &said), "docs/world.md: {said} s, run {t} s");
    let strip_led = run(&model(
        strip,
        &[
            "plant.model=crazyflie_pid",
            "duration=60",
            "plant.jerk_filter_s=0",
        ],
    ));
    assert_eq!(
        strip_led.outcome,
        Outcome::Converged,
        "{}",
        strip_led.reason
    );
    let said = docs::between(&world, "the 20-agent strip settles in", " s with S21b");
    let t = strip_led.settle_time.expect("settled");
    assert!(docs::shows(t, &said), "docs/world.md: {said} s, run {t} s");
    let strip_unled = run(&model(
        strip,
        &[
            "plant.model=crazyflie_pid",
            "plant.second_lead_s2=0",
            "duration=60",
        ],
    ));
    assert_eq!(
        strip_unled.outcome,
        Outcome::EstimateCollapse,
        "{}",
        strip_unled.reason
    );
    let m = model("formation-only", &["world=crazyflie-camera", "duration=1"]);
    assert!(m.world.heading.is_some() && m.world.preset == "crazyflie-camera");
}

/// The paper's v* = (3, 3) m/s is beyond a Crazyflie: the run says so in a warning and in
/// its outcome's reason, naming v* and the limit.
#[test]
fn a_reference_above_the_speed_limit_is_named() {
    let r = run(&model("paper", &["world=crazyflie", "duration=20"]));
    // Limited to 1 m/s the square falls behind v*: its errors stay, nothing fails.
    assert_eq!(r.outcome, Outcome::NotConverged, "{}", r.reason);
    let says = |s: &str| s.contains("v* = (3, 3)") && s.contains("plant.max_speed = 1");
    assert!(r.warnings.iter().any(|w| says(w)), "{:?}", r.warnings);
    assert!(says(&r.reason), "{}", r.reason);
    // `host-sim validate` says it before any run.
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_host-sim"))
        .args(["validate", "paper", "--set", "world=crazyflie"])
        .output()
        .expect("host-sim validate");
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success() && says(&err), "{err}");
}

/// Every new field is checked with its name and the reason.
#[test]
fn bad_world_values_are_refused_with_their_field() {
    let cases: &[(&[&str], &str)] = &[
        (
            &[
                "plant.model=velocity_tracking",
                "plant.time_constant_s=-0.1",
            ],
            "plant.time_constant_s",
        ),
        (
            &["plant.model=velocity_tracking", "plant.max_tilt_deg=90"],
            "plant.max_tilt_deg",
        ),
        (
            &["plant.model=velocity_tracking", "plant.max_speed=0"],
            "plant.max_speed",
        ),
        (
            &["plant.model=velocity_tracking", "plant.lead_s=nan"],
            "plant.lead_s",
        ),
        (&["wind.gust=-1"], "wind.gust"),
        (
            &["wind.gust_time_constant_s=0"],
            "wind.gust_time_constant_s",
        ),
        (&["wind.mean=[inf, 0.0]"], "wind.mean"),
        (&["heading.spread_deg=200"], "heading.spread_deg"),
        (&["heading.drift_deg_per_s=-1"], "heading.drift_deg_per_s"),
        (&["clock.ppm=nan"], "clock.ppm"),
        (&["clock.jitter_s=0.01"], "clock.jitter_s"),
        (&["clock.offset_s=-1"], "clock.offset_s"),
        (&["world=mars"], "world"),
        (&["mode=continuous", "clock.ppm=10"], "mode"),
        (
            &[
                "heading.error_deg=1",
                "sensors.bearing_source=shared_positions",
            ],
            "heading",
        ),
    ];
    for (overrides, field) in cases {
        let e = refused(overrides);
        assert!(
            e.contains("formation-only") && e.contains(field),
            "{overrides:?}: {e}"
        );
    }
}

/// `world = "crazyflie-camera"`: the AI-deck's 87° camera leaves formation-only's agents
/// without some neighbours, and the outcome's reason names the agent, the neighbour and
/// the field of view; with a camera seeing all round no such note (negative control).
#[test]
fn the_camera_world_names_a_neighbour_out_of_view() {
    let r = run(&model(
        "formation-only",
        &["world=crazyflie-camera", "duration=30"],
    ));
    // Agents without a bearing sit in their safe output: not in control.
    assert_eq!(r.outcome, Outcome::NotInControl, "{}", r.reason);
    assert!(
        r.reason
            .contains("out of view of its camera (field of view 87°"),
        "{}",
        r.reason
    );
    let r = run(&model(
        "formation-only",
        &[
            "world=crazyflie-camera",
            "duration=30",
            "sensors.camera.fov_deg=360",
        ],
    ));
    assert!(!r.reason.contains("out of view"), "{}", r.reason);
}
