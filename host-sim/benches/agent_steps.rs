//! Agent-steps per second of the sampled simulator.
//!
//! One agent-step is one agent's control tick at 100 Hz (its sensors, its
//! `controller-core` receive/step/frames, its frames through the radio) plus its share of
//! the 10 RK4 plant steps (dt = 1 ms) until the next tick. Criterion reports it as
//! elements/s ("Kelem/s" = thousand agent-steps per second).
//!
//! * `paper_n4`: the `paper` scenario (4 agents).
//! * `strip_n1000`: a generated triangulated strip of 1,000 agents.
//!
//! `cargo bench -p host-sim -- --quick` runs both in well under a minute.

// `criterion_group!` generates an undocumented public function.
#![allow(missing_docs)]

use criterion::{criterion_group, criterion_main, Criterion, Throughput};
use host_sim::engine::SampledSim;
use host_sim::load;
use host_sim::scenario::strip_model;
use std::hint::black_box;
use std::time::Duration;

fn bench(c: &mut Criterion, name: &str, model: &host_sim::model::Model, ticks: usize) {
    let mut sim = SampledSim::new(model).expect("simulator");
    let period = model.control_period();
    let mut t = 0.0;
    let mut group = c.benchmark_group("agent_steps");
    group.throughput(Throughput::Elements((ticks * model.n()) as u64));
    group.bench_function(name, |b| {
        b.iter(|| {
            sim.advance_ticks(t, ticks);
            t += ticks as f64 * period;
            black_box(&sim.plant.q);
        });
    });
    group.finish();
}

fn agent_steps(c: &mut Criterion) {
    // 1,000 s of the paper run would drift far from the start but stays well-defined:
    // the formation converges and translates at v*.
    let paper = load("paper", &["duration=1000.0".to_owned()]).expect("paper");
    bench(c, "paper_n4", &paper, 100);
    let strip = strip_model(1000, 1000.0);
    bench(c, "strip_n1000", &strip, 1);
}

criterion_group! {
    name = benches;
    config = Criterion::default()
        .sample_size(20)
        .warm_up_time(Duration::from_secs(1))
        .measurement_time(Duration::from_secs(3));
    targets = agent_steps
}
criterion_main!(benches);
