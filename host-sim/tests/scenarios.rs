//! The built-in scenarios end as SPEC §9 says, continuous mode keeps V from increasing,
//! the paper scenario survives a lossy, delayed radio, and runs are reproducible. Each
//! run's figures are read back from docs/outputs.md's "Reference figures" (and the
//! README's and docs/scenarios.md's for `paper-printed`).

#[path = "support/docs.rs"]
mod docs;

use ph_formation_sim::engine::{self as sim, NullRecorder, RunResult};
use ph_formation_sim::model::{Mode, Model};
use ph_formation_sim::scenario::strip_model;
use ph_formation_sim::{load, Outcome, Simulation};

fn model(name: &str, overrides: &[&str]) -> Model {
    let o: Vec<String> = overrides.iter().map(|s| (*s).to_owned()).collect();
    load(name, &o).unwrap_or_else(|e| panic!("{name}: {e}"))
}

fn run(m: &Model) -> RunResult {
    sim::run(m, &mut NullRecorder, &mut |_| {}).expect("run")
}

/// The target square 1-2-4-3 built on the final leader edge, on the same side as at
/// t = 0 (not its mirror): q3 = q1 + R(−90°)(q2 − q1), q4 = q2 + (q3 − q1).
fn square_error(p: &[[f64; 2]]) -> f64 {
    let (q1, q2, q3, q4) = (p[0], p[1], p[2], p[3]);
    let d = [q2[0] - q1[0], q2[1] - q1[1]];
    let e3 = [q1[0] + d[1], q1[1] - d[0]];
    let e4 = [q2[0] + (e3[0] - q1[0]), q2[1] + (e3[1] - q1[1])];
    let dist = |a: [f64; 2], b: [f64; 2]| (a[0] - b[0]).hypot(a[1] - b[1]);
    dist(q3, e3).max(dist(q4, e4))
}

fn mirror_error(p: &[[f64; 2]]) -> f64 {
    let (q1, q2, q3, q4) = (p[0], p[1], p[2], p[3]);
    let d = [q2[0] - q1[0], q2[1] - q1[1]];
    let e3 = [q1[0] - d[1], q1[1] + d[0]];
    let e4 = [q2[0] + (e3[0] - q1[0]), q2[1] + (e3[1] - q1[1])];
    let dist = |a: [f64; 2], b: [f64; 2]| (a[0] - b[0]).hypot(a[1] - b[1]);
    dist(q3, e3).max(dist(q4, e4))
}

/// The row of docs/outputs.md's "Reference figures" whose run cell starts with `label`
/// states `r`'s figures: the outcome, the settle time, the final errors and V's largest
/// rise (with its time if given), each at the precision shown; for a failure, the times
/// in its outcome cell are the events' times, in order. Deterministic runs: the doc's
/// rounding is the only tolerance (`docs::shows`).
fn assert_reference_row(label: &str, r: &RunResult) {
    let doc = docs::read("docs/outputs.md");
    let section = &doc[doc.find("## Reference figures").expect("section")..];
    let c = docs::row(section, label);
    let first = |i: usize| c[i].split_whitespace().next().map(str::to_owned);
    assert_eq!(
        first(1).as_deref(),
        Some(r.outcome.as_str()),
        "{label}: {}",
        r.reason
    );
    let figures = [
        (2, r.settle_time.unwrap_or(f64::NAN), "settle time"),
        (3, r.final_max_angle_error, "final max angle error"),
        (4, r.final_displacement_error, "final |z − z*|"),
        (5, r.final_velocity_error, "final max |v − v*|"),
        (6, r.v_max_increase_rel, "V max increase / V(0)"),
    ];
    for (i, value, what) in figures {
        if let Some(shown) = first(i) {
            assert!(
                docs::shows(value, &shown),
                "docs/outputs.md, {label}: {what} {shown}, the run gives {value:e}"
            );
        }
    }
    if let Some(at) = docs::seconds(&c[6]).first() {
        assert!(docs::shows(r.v_max_increase_t, &format!("{at:.2}")));
    }
    if r.outcome != Outcome::Converged {
        let times: Vec<f64> = r.events.iter().map(|e| e.t).collect();
        assert_events_at(&format!("docs/outputs.md, {label}"), &c[1], &times);
    }
}

/// The times (`… 0.54 s …`) of `text` are `times` at two decimals.
fn assert_events_at(source: &str, text: &str, times: &[f64]) {
    let stated = docs::seconds(text);
    assert_eq!(stated.len(), times.len(), "{source}: {text:?} vs {times:?}");
    for (s, t) in stated.iter().zip(times) {
        assert!(
            docs::shows(*t, &format!("{s:.2}")),
            "{source}: {s} s, the run gives {t} s"
        );
    }
}

fn assert_converged_square(name: &str, r: &RunResult, side: Option<f64>) {
    assert_eq!(r.outcome, Outcome::Converged, "{name}: {}", r.reason);
    let settle = r.settle_time.expect("settle time");
    assert!(settle < 100.0, "{name}: settle {settle}");
    assert!(r.final_max_angle_error < 1e-3);
    let p = &r.final_positions;
    let side_now = (p[1][0] - p[0][0]).hypot(p[1][1] - p[0][1]);
    let err = square_error(p);
    assert!(
        err < 1e-3 * side_now,
        "{name}: not the square 1-2-4-3: {p:?} (error {err})"
    );
    assert!(mirror_error(p) > side_now, "{name}: mirror");
    assert!(
        r.orientation_kept.iter().all(|&k| k),
        "{name}: a triangle flipped"
    );
    if let Some(s) = side {
        // z* = (10, −10): the leader edge, a side of the square, is 10√2 long.
        assert!((side_now - s).abs() < 1e-2, "{name}: side {side_now}");
    }
}

#[test]
fn paper_converges_into_the_square_not_its_mirror() {
    let m = model("paper", &[]);
    assert_eq!(m.duration, 100.0);
    let r = run(&m);
    assert_converged_square("paper", &r, Some(200f64.sqrt()));
    assert!(r.final_displacement_error < 1e-2);
    assert!(r.final_velocity_error < 1e-2);
    // Sampled at 100 Hz with finite-difference rates, nothing saturates or faults
    // after the first tick (nothing heard yet at t = 0).
    assert_eq!(r.control.saturated, 0);
    assert_eq!(r.control.safe_after_start, 0);
    assert_eq!(r.frames.dropped, 0);
    assert_eq!(r.frames.rejected, 0);
    assert!(r.frames.sent > 0 && r.frames.accepted == r.frames.delivered);
    assert_reference_row("`paper` (sampled", &r);
    // "r̂ ≈ A–B m against r = C m and D m" (docs/outputs.md), at the precision shown.
    let doc = docs::read("docs/outputs.md");
    let span = docs::between(&doc, "at the end of `paper`, r̂ ≈", " m against");
    let (lo, hi) = span.split_once('–').expect("A–B");
    let est = |f: fn(f64, f64) -> f64, init| r.final_estimates.iter().map(|e| e.0).fold(init, f);
    assert!(docs::shows(est(f64::min, f64::INFINITY), lo), "{span}");
    assert!(docs::shows(est(f64::max, 0.0), hi), "{span}");
    let truth = docs::between(&doc, "m against r =", " m, so");
    let mut distances: Vec<f64> = r.final_estimates.iter().map(|e| e.1).collect();
    distances.sort_by(f64::total_cmp);
    let (a, b) = truth.split_once(" m and ").expect("C m and D");
    assert!(docs::shows(distances[0], a) && docs::shows(distances[distances.len() - 1], b));
}

#[test]
fn paper_printed_fails_and_names_the_cause() {
    let r = run(&model("paper-printed", &[]));
    assert_eq!(r.outcome, Outcome::EstimateCollapse, "{}", r.reason);
    // README.md: "run paper-printed   # the printed gains: reported as a failure, exit 12".
    let readme = docs::read("README.md");
    let code = docs::number(&readme, "reported as a failure, exit", " cargo");
    assert_eq!(f64::from(r.outcome.exit_code()), code, "README.md");
    assert_eq!(r.min_estimate, Some(0.1));
    assert!(
        r.final_time < 5.0,
        "stopped at the collision: {}",
        r.final_time
    );
    assert!(r.reason.contains("r_min"), "{}", r.reason);
    assert!(r.reason.contains("collided"), "{}", r.reason);
    let kinds: Vec<Outcome> = r.events.iter().map(|e| e.kind).collect();
    assert_eq!(kinds, [Outcome::EstimateCollapse, Outcome::Collision]);
    assert!(r.min_distance.0 < 0.05);
    assert_reference_row("`paper-printed`", &r);
    let times: Vec<f64> = r.events.iter().map(|e| e.t).collect();
    let readme = docs::read("README.md");
    let said = docs::between(&readme, "make the estimates collapse", "as [SPEC §9]");
    assert_events_at("README.md", &said, &times);
    // docs/outputs.md quotes this run's `outcome_reason` word for word.
    let outputs = docs::read("docs/outputs.md");
    let quoted = docs::between(&outputs, "e.g. for `paper-printed`: \"", "\". ");
    assert_eq!(
        quoted,
        docs::flat(&r.reason),
        "docs/outputs.md's example reason"
    );
    let table = docs::read("docs/scenarios.md");
    let said = docs::row(&table, "`paper-printed`")[2].clone();
    assert_events_at("docs/scenarios.md", &said, &times);
}

#[test]
fn paper_printed_fails_in_continuous_mode_too() {
    // The failure is the gains', not the sampling's.
    let r = run(&model("paper-printed", &["mode=continuous"]));
    assert_eq!(r.outcome, Outcome::EstimateCollapse, "{}", r.reason);
    assert!(r.v_max_increase_rel < 1e-9);
}

#[test]
fn formation_only_converges() {
    let r = run(&model("formation-only", &[]));
    assert_converged_square("formation-only", &r, None);
    assert_eq!(r.final_displacement_error, 0.0);
    assert_reference_row("`formation-only` |", &r);
}

/// Continuous mode: V (S13) must not increase beyond RK4 error. Measured: ≈ 6e-12 of
/// V(0) for `paper`, ≈ 1e-12 for `formation-only` (dt = 1 ms); the tolerance is 1e-9.
const V_TOLERANCE: f64 = 1e-9;

#[test]
fn continuous_mode_v_does_not_increase() {
    for name in ["paper", "formation-only"] {
        let m = model(name, &["mode=continuous"]);
        assert_eq!(m.mode, Mode::Continuous);
        let r = run(&m);
        assert!(
            r.v_max_increase_rel < V_TOLERANCE,
            "{name}: V rose by {} of V(0) at t = {}",
            r.v_max_increase_rel,
            r.v_max_increase_t
        );
        assert!(r.v_final < r.v0);
        assert_eq!(r.control.saturated, 0);
        assert_eq!(r.control.safe, 0);
        assert_eq!(r.frames.sent, 0);
        assert_converged_square(name, &r, None);
        let label = if name == "paper" {
            "`paper`, `mode = continuous`"
        } else {
            "`formation-only`, continuous"
        };
        assert_reference_row(label, &r);
    }
    // The README's bound: "V never rises by more than ~1e-11 of V(0)".
    let readme = docs::read("README.md");
    let bound = docs::number(&readme, "V never rises by more than ~", " of V(0)");
    let r = run(&model("paper", &["mode=continuous"]));
    assert!(r.v_max_increase_rel <= bound, "{}", r.v_max_increase_rel);
}

#[test]
fn continuous_mode_per_agent_estimator_is_not_passive_but_runs() {
    // SPEC §6: PerAgent is kept for comparison; it must run without faults.
    let r = run(&model(
        "formation-only",
        &[
            "mode=continuous",
            "controller.estimator=per_agent",
            "duration=5.0",
        ],
    ));
    assert_eq!(r.control.safe, 0);
    assert!(r.final_positions.iter().flatten().all(|x| x.is_finite()));
}

#[test]
fn paper_converges_with_20_percent_loss_and_20_ms_latency() {
    let r = run(&model("paper", &["radio.loss=0.2", "radio.latency=0.02"]));
    assert_converged_square("paper lossy", &r, Some(200f64.sqrt()));
    assert_reference_row("`paper`, 20 % loss", &r);
    // Each link copy is lost independently with p = 0.2: the count of losses is
    // binomial(n, p); 4 standard deviations (a false alarm once in ~16,000 seeds) from
    // n p, which a loss rate off by 0.01 already leaves (n = 100,010 link copies: σ ≈ 126,
    // 0.01 n = 1,000; with p = 0.19 the check fails by 1,093).
    let (n, p) = (r.frames.sent as f64, 0.2);
    let sigma = (n * p * (1.0 - p)).sqrt();
    let lost = r.frames.lost as f64;
    assert!(
        (lost - n * p).abs() <= 4.0 * sigma,
        "{lost} of {n} copies lost, expected {} ± {}",
        n * p,
        4.0 * sigma
    );
}

#[test]
fn paper_with_exact_rates_and_measured_ranges_converges() {
    let r = run(&model("paper", &["sensors.bearing_rate=exact"]));
    assert_converged_square("paper exact rates", &r, Some(200f64.sqrt()));
    let r = run(&model(
        "paper",
        &["controller.estimator=measured", "duration=60.0"],
    ));
    assert_converged_square("paper measured", &r, Some(200f64.sqrt()));
    assert_eq!(r.min_estimate, None);
}

#[test]
fn same_seed_same_csv_other_seed_other_csv() {
    let faulty = [
        "duration=10.0",
        "radio.loss=0.2",
        "radio.latency=0.02",
        "radio.jitter=0.01",
        "radio.duplication=0.05",
        "radio.reordering=0.05",
        "radio.corruption=0.02",
        "sensors.bearing_noise_deg=0.05",
        "sensors.velocity_noise=0.01",
    ];
    let dir = tempfile::tempdir().expect("tempdir");
    let mut csv = Vec::new();
    let mut summaries = Vec::new();
    for (k, seed) in [7, 7, 8].iter().enumerate() {
        let mut o: Vec<&str> = faulty.to_vec();
        let s = format!("seed={seed}");
        o.push(&s);
        let m = model("paper", &o);
        let out = dir.path().join(format!("run{k}"));
        let run = Simulation::new(&m)
            .keep_series(false)
            .write_to(&out, ph_formation_sim::WriteOptions::without_plots())
            .run()
            .expect("run");
        let r = &run.result;
        assert!(r.frames.rejected > 0 && r.frames.dropped > 0);
        csv.push(std::fs::read(out.join("timeseries.csv")).expect("csv"));
        summaries.push(std::fs::read(out.join("summary.json")).expect("json"));
    }
    assert!(csv[0].len() > 100_000);
    assert!(csv[0] == csv[1], "same seed, different CSV");
    assert!(summaries[0] == summaries[1], "same seed, different summary");
    assert!(csv[0] != csv[2], "the seed changes nothing");
}

#[test]
fn generated_strip_settles() {
    let m = strip_model(30, 40.0).unwrap();
    let r = run(&m);
    assert_eq!(r.outcome, Outcome::Converged, "{}", r.reason);
}

#[test]
fn a_file_with_two_neighbours_sharing_an_id_is_refused_naming_both() {
    // A file's ids name its agents (triangles, leader, attacks refer to them), so they are
    // unique; the wire ids made from them may repeat only beyond two hops (the strip).
    let path = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/tests/invalid/duplicate_id.toml"
    );
    let e = load(path, &[]).expect_err("duplicate id accepted");
    assert!(
        e.has(ph_formation_sim::scenario::ErrorKind::DuplicateId),
        "{e}"
    );
    let e = e.to_string();
    assert!(
        e.contains("duplicate_id.toml")
            && e.contains("field `agents[3].id`")
            && e.contains("id 2 is already used by agents[1]"),
        "{e}"
    );
}

#[test]
fn example_files_converge() {
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("scenarios");
    for name in ["maneuvers", "paper-lossy"] {
        let path = dir.join(format!("{name}.toml"));
        let r = run(&model(&path.to_string_lossy(), &[]));
        assert_eq!(r.outcome, Outcome::Converged, "{name}: {}", r.reason);
        // V jumps at the schedule switches; the running minimum restarts there.
        assert!(
            r.v_max_increase_rel < 1.0,
            "{name}: {}",
            r.v_max_increase_rel
        );
    }
}
