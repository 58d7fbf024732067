//! The failure monitor's estimate-collapse rule (`docs/outputs.md`, "Outcome") on a made-up
//! sequence of estimates: an estimate held at `r_min` for `collapse_time` collapses, from
//! the instant it first reached it; release restarts its clock; NaN is never "held"; only
//! the first collapse is recorded. On the paper formation, and on a formation large enough
//! for the monitor to scan its estimates on every thread.

use ph_formation_sim::analysis::{Diagnostics, Monitor, Outcome};
use ph_formation_sim::engine::{Engine, SampledSim};
use ph_formation_sim::scenario::strip_model;
use ph_formation_sim::{load, Model};

/// Plays the sequence on `model` with the estimates `roles = [a, b, c, nan]` in the roles
/// of the paper formation's estimates 0, 1, 3 and 2, on `threads` threads.
fn held_sequence(model: &Model, roles: [usize; 4], threads: usize) {
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .expect("pool");
    pool.install(|| play(model, roles));
}

fn play(model: &Model, [e0, e1, e3, nan]: [usize; 4]) {
    let mut sim = SampledSim::new(model).expect("sim");
    let info = sim.estimate_info().to_vec();
    let (q, v, est) = sim.view();
    let (q, v, normal) = (q.to_vec(), v.to_vec(), est.to_vec());
    assert!(
        normal.len() > e0.max(e1).max(e3).max(nan),
        "{} estimates",
        normal.len()
    );
    let r_min = model.min_estimate;
    let wait = model.criteria.collapse_time;
    let mut diag = Diagnostics::new(model, info);
    let mut monitor = Monitor::new(model, normal.len());
    // At each instant: the estimates at r_min, and one that is NaN.
    let mut observe = |t: f64, held: &[usize]| {
        let mut est = normal.clone();
        for &k in held {
            est[k] = r_min;
        }
        diag.evaluate(model, t, &q, &v, &est);
        // The monitor's copy only (a NaN in V would end the run as diverged).
        est[nan] = f64::NAN;
        assert!(
            !monitor.observe(model, &diag, &q, &est),
            "no terminal failure"
        );
        monitor
            .events
            .iter()
            .filter(|e| e.kind == Outcome::EstimateCollapse)
            .map(|e| e.t)
            .collect::<Vec<_>>()
    };
    // In steps of a quarter of the wait: e1 held from 0, e3 from h; e1 released at 2h and
    // held again from 3h; e0 from 2h; a release of all at 4h.
    let h = wait / 4.0;
    assert!(observe(0.0, &[e1]).is_empty());
    assert!(observe(h, &[e1, e3]).is_empty());
    assert!(observe(2.0 * h, &[e0, e3]).is_empty());
    assert!(observe(3.0 * h, &[e0, e1, e3]).is_empty());
    assert!(observe(4.5 * h, &[e0, e1, e3]).is_empty());
    // e3 has been held for more than the wait since h (e0 since 2h, e1 only since 3h): it
    // collapses, dated h.
    assert_eq!(observe(5.5 * h, &[e0, e1, e3]), [h]);
    // e0 and e1 come due later, but only the first collapse is recorded.
    assert_eq!(observe(9.0 * h, &[e0, e1, e3]), [h]);
    assert_eq!(monitor.min_estimate, Some(r_min));
}

#[test]
fn an_estimate_held_at_r_min_for_the_collapse_time_collapses_from_when_it_reached_it() {
    let model = load("paper", &[]).expect("paper");
    held_sequence(&model, [0, 1, 3, 2], 1);
}

/// The same sequence among the estimates of a 3,000-agent strip, on one and on two
/// threads (the smallest estimate and whether any is held are then found on both).
#[test]
#[ignore = "slow lane: `cargo xtask test` runs it (phase \"slow tests\")"]
fn the_collapse_rule_holds_for_a_large_formation_on_any_number_of_threads() {
    let model = strip_model(3000, 10.0).unwrap();
    let n = SampledSim::new(&model).expect("sim").estimate_info().len();
    assert!(n > 10_000, "{n} estimates");
    let roles = [n / 3, n - 1, 7, n / 2];
    for threads in [1, 2] {
        held_sequence(&model, roles, threads);
    }
}
