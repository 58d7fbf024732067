//! Agent-steps per second of the sampled simulator.
//!
//! One agent-step is one agent's control tick at 100 Hz (its sensors, its
//! `controller-core` receive/step/frames, its frames through the radio) plus its share of
//! the 10 RK4 plant steps (dt = 1 ms) until the next tick. Criterion reports it as
//! elements/s ("Melem/s" = million agent-steps per second).
//!
//! * `agent_steps/paper_n4`: the `paper` scenario (4 agents), one thread.
//! * `agent_steps/strip_nN`: a generated triangulated strip of N = 100 … 100,000 agents,
//!   one thread (a one-thread rayon pool): the cost per agent-step should not grow with N.
//! * `agent_steps_parallel/strip_nN`: the same on every core (rayon's global pool); the
//!   result is bit-identical to one thread (`tests/scaling.rs`).
//! * `…/strip_noisy_nN` (N = 10,000 and 100,000): the strip with sensor noise (bearings
//!   0.5°, velocities 0.01 m/s): every agent draws from its own stream of the tick
//!   (`Sensors::stream`), on whichever thread ticks it.
//!
//! `cargo bench -p ph-formation-sim --bench agent_steps -- --quick` runs all in a few minutes;
//! docs/performance.md has the figures and the log-log slope.

// `criterion_group!` generates an undocumented public function.
#![allow(missing_docs)]

use criterion::{criterion_group, criterion_main, BenchmarkGroup, Criterion, Throughput};
use ph_formation_sim::engine::SampledSim;
use ph_formation_sim::load;
use ph_formation_sim::model::Model;
use ph_formation_sim::scenario::strip_model;
use std::cell::OnceCell;
use std::hint::black_box;
use std::time::Duration;

/// Strip sizes and the ticks per iteration (about 10⁵ agent-steps per iteration).
const STRIPS: [(usize, usize); 4] = [(100, 1000), (1000, 100), (10_000, 10), (100_000, 1)];

/// The strip of `n` agents with noisy sensors (every measurement draws random numbers).
fn noisy_strip(n: usize) -> Model {
    let mut m = strip_model(n, 1000.0).expect("the strip is a valid model");
    m.sensors.bearing_noise = 0.5f64.to_radians();
    m.sensors.velocity_noise = 0.01;
    m
}

/// Benchmarks `ticks` control periods per iteration of the model `make` builds. The model
/// and its simulator are built only when criterion runs this benchmark (a filtered run,
/// or a `perf` profile of one benchmark, builds nothing else), and once.
fn bench(
    group: &mut BenchmarkGroup<'_, criterion::measurement::WallTime>,
    name: &str,
    make: impl Fn() -> Model,
    n: usize,
    ticks: usize,
    pool: Option<&rayon::ThreadPool>,
) {
    let model = OnceCell::new();
    let mut sim: Option<SampledSim<'_>> = None;
    let mut t = 0.0;
    group.throughput(Throughput::Elements((ticks * n) as u64));
    group.bench_function(name, |b| {
        let model = model.get_or_init(&make);
        assert_eq!(model.n(), n, "{name}: agents");
        let period = model.control_period();
        let sim = sim.get_or_insert_with(|| SampledSim::new(model).expect("simulator"));
        b.iter(|| {
            let mut step = || {
                sim.advance_ticks(t, ticks);
                t += ticks as f64 * period;
            };
            match pool {
                Some(p) => p.install(step),
                None => step(),
            }
            black_box(sim.plant.q());
        });
    });
}

fn agent_steps(c: &mut Criterion) {
    let one = rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build()
        .expect("pool");
    // 1,000 s of the paper run would drift far from the start but stays well-defined:
    // the formation converges and translates at v*.
    let paper = || load("paper", &["duration=1000.0".to_owned()]).expect("paper");
    let mut group = c.benchmark_group("agent_steps");
    bench(&mut group, "paper_n4", paper, 4, 1000, Some(&one));
    for (n, ticks) in STRIPS {
        let strip = || strip_model(n, 1000.0).expect("the strip is a valid model");
        bench(
            &mut group,
            &format!("strip_n{n}"),
            strip,
            n,
            ticks,
            Some(&one),
        );
    }
    for (n, ticks) in STRIPS.into_iter().skip(2) {
        let name = format!("strip_noisy_n{n}");
        bench(&mut group, &name, || noisy_strip(n), n, ticks, Some(&one));
    }
    group.finish();
    let mut group = c.benchmark_group("agent_steps_parallel");
    for (n, ticks) in STRIPS.into_iter().skip(2) {
        let strip = || strip_model(n, 1000.0).expect("the strip is a valid model");
        bench(&mut group, &format!("strip_n{n}"), strip, n, ticks, None);
    }
    for (n, ticks) in STRIPS.into_iter().skip(2) {
        let name = format!("strip_noisy_n{n}");
        bench(&mut group, &name, || noisy_strip(n), n, ticks, None);
    }
    group.finish();
}

criterion_group! {
    name = benches;
    config = Criterion::default()
        .sample_size(10)
        .warm_up_time(Duration::from_secs(1))
        .measurement_time(Duration::from_secs(3));
    targets = agent_steps
}
criterion_main!(benches);
