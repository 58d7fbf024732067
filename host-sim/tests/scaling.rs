//! Cost grows linearly in N: the time per agent-step of a 1,000-agent strip is within a
//! small factor of a 100-agent strip's (quadratic cost would make it ~10× larger).

use host_sim::engine::SampledSim;
use host_sim::scenario::strip_model;
use std::time::Instant;

/// Best-of-3 seconds per agent-step over `ticks` control periods.
fn per_agent_step(n: usize, ticks: usize) -> f64 {
    let m = strip_model(n, 10.0);
    let mut sim = SampledSim::new(&m).expect("sim");
    sim.advance_ticks(0.0, 5);
    let mut best = f64::INFINITY;
    for k in 0..3 {
        let t0 = Instant::now();
        sim.advance_ticks(0.05 + (k * ticks) as f64 * 0.01, ticks);
        best = best.min(t0.elapsed().as_secs_f64());
    }
    best / (n * ticks) as f64
}

#[test]
fn cost_per_agent_step_does_not_grow_with_n() {
    let small = per_agent_step(100, 50);
    let large = per_agent_step(1000, 5);
    let ratio = large / small;
    eprintln!("per agent-step: N=100 {small:.3e} s, N=1000 {large:.3e} s, ratio {ratio:.2}");
    assert!(ratio < 3.0, "ratio {ratio}");
}
