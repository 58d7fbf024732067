//! Helpers shared by the integration tests of bearing sensors (`camera.rs`,
//! `shared_positions.rs`).

use ph_formation_sim::engine::{Engine, SampledSim};
use ph_formation_sim::model::Model;

/// The bits of positions, velocities and estimates after `ticks` ticks of `m` on
/// `threads` threads.
pub fn bits(m: &Model, ticks: usize, threads: usize) -> Vec<u64> {
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .expect("pool");
    pool.install(|| {
        let mut sim = SampledSim::new(m).expect("sim");
        sim.advance_ticks(0.0, ticks);
        let (q, v, est) = sim.view();
        q.iter()
            .chain(v)
            .flat_map(|p| [p.x.to_bits(), p.y.to_bits()])
            .chain(est.iter().map(|e| e.to_bits()))
            .collect()
    })
}
