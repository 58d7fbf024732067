//! Issue 9 §5: the paper scenario with wire v3 converges into the same square as with
//! wire v2 — final relative positions within 1e-3 m of the v2 run, settle time within 2 %.
//!
//! The v2 figures are the ones recorded by `cargo run --release -p host-sim` at commit
//! 265c94e (wire v2, the last landed version; docs/firmware.md "History"): settle time
//! 40.57 s and these final positions (seed 1, sampled 100 Hz, finite-difference rates).

use host_sim::{load, Outcome, Simulation};

/// Final positions of agents 1–4 in the wire-v2 run (summary.json `final_positions`).
const V2_FINAL: [[f64; 2]; 4] = [
    [301.40354088823193, 289.89334888920604],
    [291.40355758917826, 299.89334608278284],
    [311.40352758080815, 299.8933186551299],
    [301.4035575857263, 309.89331554366987],
];
/// Settle time of the wire-v2 run (s).
const V2_SETTLE: f64 = 40.57;

#[test]
fn paper_converges_into_the_v2_square_within_2_percent_of_its_settle_time() {
    let m = load("paper", &[]).expect("paper");
    let run = Simulation::new(&m).run().expect("run");
    let r = &run.result;
    assert_eq!(r.outcome, Outcome::Converged, "{}", r.reason);
    let settle = r.settle_time.expect("settled");
    let rel = (settle - V2_SETTLE).abs() / V2_SETTLE;
    println!(
        "settle time {settle} s (v2 {V2_SETTLE} s, {:+.2} %)",
        100.0 * (settle / V2_SETTLE - 1.0)
    );
    assert!(rel <= 0.02, "settle time {settle} s vs v2 {V2_SETTLE} s");
    // Relative positions (the formation's translation along v* is not controlled).
    let q = &r.final_positions;
    let mut worst = 0.0f64;
    for i in 1..4 {
        for k in 0..2 {
            let now = q[i][k] - q[0][k];
            let v2 = V2_FINAL[i][k] - V2_FINAL[0][k];
            worst = worst.max((now - v2).abs());
        }
    }
    println!("final relative positions differ from v2 by at most {worst:.2e} m");
    assert!(worst <= 1e-3, "relative positions differ by {worst} m");
}
