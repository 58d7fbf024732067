//! `Diagnostics` evaluated again with fewer velocities or estimates than the last call
//! (the terms it keeps between calls must not leak into the sums): the same snapshot as a
//! fresh `Diagnostics`, on the paper formation and, on two threads, on a formation large
//! enough for the parallel terms.

use ph_formation_sim::analysis::Diagnostics;
use ph_formation_sim::engine::{Engine, SampledSim};
use ph_formation_sim::scenario::strip_model;
use ph_formation_sim::{load, Model};

fn reused_equals_fresh(model: &Model) {
    let mut sim = SampledSim::new(model).expect("sim");
    let info = sim.estimate_info().to_vec();
    let (q, v, est) = sim.view();
    let (q, v, est) = (q.to_vec(), v.to_vec(), est.to_vec());
    // Velocities away from v* and estimates away from the true distances: every term is
    // non-zero, so a stale one would change a sum.
    let v: Vec<_> = v.iter().map(|x| x.add_scalar(0.3)).collect();
    let est: Vec<f64> = est.iter().map(|r| r * 1.5).collect();
    let mut reused = Diagnostics::new(model, info.clone());
    reused.evaluate(model, 0.0, &q, &v, &est);
    for (v_len, est_len) in [(v.len(), 2), (1, est.len()), (1, 2)] {
        reused.evaluate(model, 0.0, &q, &v[..v_len], &est[..est_len]);
        let mut fresh = Diagnostics::new(model, info.clone());
        fresh.evaluate(model, 0.0, &q, &v[..v_len], &est[..est_len]);
        let bits = |d: &Diagnostics| [d.snap.v_kin, d.snap.v_est, d.snap.v].map(f64::to_bits);
        assert_eq!(
            bits(&reused),
            bits(&fresh),
            "{v_len} velocities, {est_len} estimates"
        );
    }
}

#[test]
fn a_reused_diagnostics_sums_only_what_it_was_given() {
    reused_equals_fresh(&load("paper", &[]).expect("paper"));
}

/// The same for a 3,000-agent strip on two threads (its terms are computed on both).
#[test]
#[ignore = "slow lane: `cargo xtask test` runs it (phase \"slow tests\")"]
fn a_reused_diagnostics_sums_only_what_it_was_given_on_two_threads() {
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(2)
        .build()
        .expect("pool");
    pool.install(|| reused_equals_fresh(&strip_model(3000, 10.0).unwrap()));
}
