//! Cost linear in N, checked deterministically (speed itself is measured by the criterion
//! benchmark `benches/agent_steps.rs`, figures in docs/performance.md):
//!
//! * the work per agent-step does not grow with N: frames broadcast, copies sent and copies
//!   delivered per agent-tick are the same for a strip of 100, 1,000 and 10,000 agents
//!   (a quadratic radio, e.g. every frame to every agent, would multiply them by N);
//! * a large run computed on two threads is bit-identical to one thread (the parallel
//!   path of `SampledSim` draws its random numbers in agent order).
//!
//! * each in-process agent's capacity class (`LOCAL_CAPACITIES`) never changes a result;
//! * every agent's bearings reach its core in the core's slot order (its one-pass path).
//!
//! That the inner loop allocates nothing per tick is `tests/no_alloc.rs`.

use ph_formation_sim::design::{
    construct, render_scenario, DesignOptions, Generator, ScenarioOptions,
};
use ph_formation_sim::engine::PARALLEL_MIN_AGENTS;
use ph_formation_sim::engine::{
    AgentController, ControlStats, Engine, LocalCore, SampledSim, LOCAL_CAPACITIES,
};
use ph_formation_sim::scenario::strip_model;

/// Frames broadcast, copies sent and copies delivered per agent-tick over `ticks` ticks.
fn work_per_agent_tick(n: usize, ticks: usize) -> [f64; 3] {
    let m = strip_model(n, 10.0).unwrap();
    let mut sim = SampledSim::new(&m).expect("sim");
    sim.advance_ticks(0.0, ticks);
    let c = sim.frame_counts();
    let per = (n * ticks) as f64;
    [c.broadcasts, c.sent, c.delivered].map(|x| x as f64 / per)
}

#[test]
fn work_per_agent_step_does_not_grow_with_n() {
    let small = work_per_agent_tick(100, 20);
    assert!(small.iter().all(|&x| x > 0.5), "{small:?}");
    for n in [1000, 10_000] {
        let large = work_per_agent_tick(n, 20);
        for k in 0..3 {
            // A strip's two ends have fewer neighbours: 100 agents differ by a few percent.
            let ratio = large[k] / small[k];
            assert!(
                (0.97..1.06).contains(&ratio),
                "N = {n}: {large:?} vs {small:?}"
            );
        }
    }
}

/// What a run leaves: the bits of the plant state and estimates, the frame counters
/// (broadcast, sent, delivered, accepted) and the controllers' statistics.
type Snapshot = (Vec<u64>, [u64; 4], ControlStats);

/// A snapshot after `ticks` ticks of a strip of `n` agents on `threads` threads.
fn state(n: usize, ticks: usize, threads: usize) -> Snapshot {
    on_threads(&strip_model(n, 10.0).unwrap(), ticks, threads)
}

/// A snapshot after `ticks` ticks of `m` on `threads` threads.
fn on_threads(m: &ph_formation_sim::Model, ticks: usize, threads: usize) -> Snapshot {
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .expect("pool");
    pool.install(|| snapshot(m, ticks))
}

/// The [`Snapshot`] after `ticks` ticks.
fn snapshot(m: &ph_formation_sim::Model, ticks: usize) -> Snapshot {
    snapshot_of(SampledSim::new(m).expect("sim"), ticks)
}

/// [`snapshot`] of a given simulation.
fn snapshot_of(mut sim: SampledSim<'_>, ticks: usize) -> Snapshot {
    sim.advance_ticks(0.0, ticks);
    let (q, v, est) = sim.view();
    let bits = q
        .iter()
        .chain(v)
        .flat_map(|p| [p.x.to_bits(), p.y.to_bits()])
        .chain(est.iter().map(|e| e.to_bits()))
        .collect();
    let c = sim.frame_counts();
    let counts = [c.broadcasts, c.sent, c.delivered, c.accepted];
    (bits, counts, sim.control_stats())
}

#[test]
fn a_large_run_on_two_threads_is_bit_identical_to_one() {
    let n = PARALLEL_MIN_AGENTS + 500;
    let one = state(n, 30, 1);
    let two = state(n, 30, 2);
    assert_eq!(one.1, two.1);
    assert_eq!(one.2, two.2);
    assert!(one.0 == two.0, "the states differ");
    // The state moved (the check is not comparing two initial states).
    let start = state(n, 0, 1);
    assert!(start.0 != one.0);
}

/// The estimates [`Engine::view`] shows after ticks are every controller's current
/// values (once viewed, each tick copies them while the agent's state is in cache,
/// instead of a second walk over every controller), on one thread and on two, and they
/// moved.
#[test]
fn the_estimates_a_run_shows_are_the_controllers_values() {
    let m = strip_model(PARALLEL_MIN_AGENTS + 100, 1.0).unwrap();
    for threads in [1, 2] {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .expect("pool");
        pool.install(|| {
            let mut sim = SampledSim::new(&m).expect("sim");
            // Viewed once (as a run's diagnostics do at every instant): from then on the
            // ticks copy the estimates.
            let _ = sim.view();
            sim.advance_ticks(0.0, 5);
            let mut read = Vec::new();
            for i in 0..m.n() {
                let c = sim.controller(i).expect("one per agent");
                let mut own = vec![f64::NAN; c.estimate_layout().len()];
                assert_eq!(c.read_estimates(&mut own), own.len());
                read.extend(own);
            }
            let shown = sim.view().2;
            assert_eq!(shown.len(), read.len());
            for (k, (s, r)) in shown.iter().zip(&read).enumerate() {
                assert_eq!(s.to_bits(), r.to_bits(), "{threads} threads, estimate {k}");
            }
            let moved = read.iter().filter(|&&r| r != m.initial_estimate).count();
            assert!(moved > read.len() / 2, "{threads} threads: {moved} moved");
        });
    }
}

/// A large run on two threads is bit-identical to one thread (state, counters and
/// statistics) with sensors that draw random numbers (bearings, ranges, velocities and
/// the leader's partner offset: drawn in agent order) and with sensors that draw none
/// (measured on every thread), both with ranges, a leader, a lossy radio (frames through
/// the radio's queue, broadcast in agent order) and two agents that start at one point
/// (no bearing between them, so no draw).
#[test]
fn noisy_and_quiet_large_runs_on_two_threads_are_bit_identical_to_one() {
    for noisy in [true, false] {
        let mut m = designed(Generator::Strip {
            n: PARALLEL_MIN_AGENTS + 300,
            spacing: 1.0,
        });
        assert!(m.leader.is_some());
        let sigma = if noisy { 0.01 } else { 0.0 };
        m.sensors.bearing_noise = sigma;
        m.sensors.velocity_noise = sigma;
        m.sensors.range_noise = sigma;
        m.sensors.offset_noise = sigma;
        m.sensors.velocity_bias = [0.01, -0.02];
        m.estimator = ph_formation_sim::model::Estimator::Measured;
        m.radio.loss = 0.1;
        // Agents 10 and 11 start at one point: neither measures a bearing to the other.
        m.agents[11].position = m.agents[10].position;
        assert!(!ph_formation_sim::engine::direct_radio(&m));
        let one = on_threads(&m, 30, 1);
        let two = on_threads(&m, 30, 2);
        assert_eq!(one.1, two.1, "noisy: {noisy}");
        assert_eq!(one.2, two.2, "noisy: {noisy}");
        assert!(one.0 == two.0, "noisy: {noisy}: the states differ");
        // Faults happened (the coincident pair), so the statistics compare something.
        assert!(one.2.safe_after_start > 0, "{:?}", one.2);
    }
}

/// Direct delivery (ideal radio) gives what the radio's queue gives: a latency of 0.6
/// control periods takes the queue path yet delivers every frame at the next tick, in the
/// same order, so the two runs agree bit for bit (state and counters).
#[test]
fn direct_delivery_is_what_the_queue_delivers() {
    let run = |latency: f64| {
        let mut m = strip_model(60, 10.0).unwrap();
        m.radio.latency = latency;
        let direct = ph_formation_sim::engine::direct_radio(&m);
        let (bits, counts, _) = snapshot(&m, 200);
        (direct, bits, counts)
    };
    let (direct, a, ca) = run(0.0);
    let (queued, b, cb) = run(0.006);
    assert!(direct && !queued);
    assert_eq!(ca, cb);
    assert!(a == b, "direct and queued delivery differ");
}

/// A designed formation from `g` (default design and scenario options).
fn designed(g: Generator) -> ph_formation_sim::Model {
    let p = g.points().expect("points");
    let opts = DesignOptions::default();
    let c = construct(&p, &opts).expect("construct");
    let text = render_scenario(&p, &c, &opts, &ScenarioOptions::default()).expect("render");
    ph_formation_sim::load_toml(&text, "designed", &[]).expect("load")
}

/// Agents in the smallest capacity that holds them compute what agents of the standard
/// capacity compute, bit for bit: formations whose agents are in 1 to 8 triangles, so that
/// every class of `LOCAL_CAPACITIES` is used.
#[test]
fn the_capacity_class_of_an_agent_never_changes_a_result() {
    let models = [
        strip_model(30, 10.0).unwrap(),
        designed(Generator::TriangularLattice {
            n: 40,
            spacing: 1.0,
        }),
        designed(Generator::Polygon {
            n: 9,
            spacing: 1.0,
            centre: true,
        }),
    ];
    let mut used = [false; LOCAL_CAPACITIES.len()];
    for m in &models {
        for i in 0..m.n() {
            let t = m.triangles_of(i).count();
            let class = LOCAL_CAPACITIES
                .iter()
                .position(|c| t <= c.0)
                .expect("fits");
            used[class] = true;
        }
        let standard: Vec<Box<dyn AgentController>> = (0..m.n())
            .map(|i| Box::new(LocalCore::new(m.core_agent(i).expect("agent"))) as _)
            .collect();
        let reference = snapshot_of(SampledSim::with_controllers(m, standard).expect("sim"), 300);
        assert!(
            snapshot(m, 300) == reference,
            "{}: the classes differ",
            m.name
        );
    }
    assert_eq!(
        used,
        [true; LOCAL_CAPACITIES.len()],
        "a class is not exercised"
    );
}

/// A designed lattice (whose cores' slots are mostly not sorted by agent index) and the
/// built-in strip (whose are): every agent's bearings, measured in graph order, reach
/// its core as a prefix of its slots.
#[test]
fn every_agents_bearings_reach_its_core_in_slot_order() {
    use ph_formation_core::{BearingMeasurement, Vec2};
    use ph_formation_sim::engine::local_core;
    use ph_formation_sim::engine::slot_order::SlotOrder;
    let b = |id: u8| BearingMeasurement {
        neighbour: id,
        bearing: Vec2::new(1.0, 0.0),
        rate: None,
        range: None,
    };
    let lattice = designed(Generator::TriangularLattice {
        n: 40,
        spacing: 1.0,
    });
    for (m, reordered) in [(lattice, true), (strip_model(40, 1.0).unwrap(), false)] {
        let wire: Vec<u8> = m.agents.iter().map(|a| a.id).collect();
        let measured =
            |i: usize| -> Vec<u8> { m.graph.triangle.of(i).iter().map(|&j| wire[j]).collect() };
        let cores: Vec<_> = (0..m.n())
            .map(|i| local_core(&m, i).expect("core"))
            .collect();
        let o = SlotOrder::for_model(&m, |i| cores[i].neighbour_order());
        assert_eq!(o.reordered() > m.n() / 4, reordered, "{}", o.reordered());
        for (i, core) in cores.iter().enumerate() {
            let mut v: Vec<_> = measured(i).into_iter().map(b).collect();
            o.apply(i, &mut v);
            let slots = core.neighbour_order().expect("local core");
            let ids: Vec<u8> = v.iter().map(|x| x.neighbour).collect();
            assert_eq!(ids, slots[..v.len()], "agent {i}");
        }
    }
}
