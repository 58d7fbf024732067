//! The inner loop does not allocate: control ticks (sensing, the cores, frames through
//! the radio), RK4 steps (sampled and continuous), diagnostics, failure monitor and CSV
//! rows, once warmed up. A counting global allocator counts this thread's allocations.

use ph_formation_sim::analysis::{Diagnostics, Monitor};
use ph_formation_sim::engine::{ContinuousSim, Engine, Recorder, Row, SampledSim};
use ph_formation_sim::load;
use ph_formation_sim::model::Model;
use ph_formation_sim::report::CsvRecorder;
use ph_formation_sim::scenario::strip_model;
use std::alloc::{GlobalAlloc, Layout, System};
use std::cell::Cell;

struct Counting;

thread_local! {
    static COUNTING: Cell<bool> = const { Cell::new(false) };
    static COUNT: Cell<usize> = const { Cell::new(0) };
}

// SAFETY: forwards to the system allocator; only bumps a thread-local counter.
unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        if COUNTING.with(Cell::get) {
            COUNT.with(|c| c.set(c.get() + 1));
        }
        // SAFETY: same contract as the caller's.
        unsafe { System.alloc(layout) }
    }
    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        // SAFETY: same contract as the caller's.
        unsafe { System.dealloc(ptr, layout) }
    }
    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        if COUNTING.with(Cell::get) {
            COUNT.with(|c| c.set(c.get() + 1));
        }
        // SAFETY: same contract as the caller's.
        unsafe { System.realloc(ptr, layout, new_size) }
    }
}

#[global_allocator]
static GLOBAL: Counting = Counting;

fn allocations(f: impl FnOnce()) -> usize {
    COUNT.with(|c| c.set(0));
    COUNTING.with(|c| c.set(true));
    f();
    COUNTING.with(|c| c.set(false));
    COUNT.with(Cell::get)
}

fn faulty_paper(mode: &str) -> Model {
    let o: Vec<String> = [
        "radio.loss=0.2",
        "radio.latency=0.02",
        "radio.jitter=0.01",
        "radio.duplication=0.1",
        "radio.reordering=0.1",
        "radio.corruption=0.05",
        "radio.bandwidth_bps=160000",
        "sensors.bearing_noise_deg=0.05",
        "sensors.velocity_noise=0.01",
        "sensors.offset_noise=0.01",
    ]
    .iter()
    .map(|s| (*s).to_owned())
    .chain([format!("mode={mode}")])
    .collect();
    load("paper", &o).expect("paper")
}

/// Ticks, RK4 steps, diagnostics, monitor and CSV rows over `ticks` control periods.
fn full_loop(
    model: &Model,
    engine: &mut dyn Engine,
    start_tick: usize,
    ticks: usize,
    csv: &mut CsvRecorder,
) {
    let mut diag = Diagnostics::new(model, engine.estimate_info().to_vec());
    let mut monitor = Monitor::new(model, diag.estimates.len());
    let spt = model.steps_per_tick;
    let run = |diag: &mut Diagnostics,
               monitor: &mut Monitor,
               engine: &mut dyn Engine,
               csv: &mut CsvRecorder,
               from: usize,
               to: usize| {
        for k in from * spt..to * spt {
            let t = model.time(k);
            if k.is_multiple_of(spt) {
                engine.control(t);
                let frames = engine.frame_counts();
                let (q, v, est) = engine.view();
                diag.evaluate(model, t, q, v, est);
                assert!(!monitor.observe(model, diag, q, est));
                csv.record(&Row {
                    snap: &diag.snap,
                    q,
                    v,
                    estimates: est,
                    frames,
                })
                .expect("row");
            }
            engine.integrate(t);
        }
    };
    // Warm up (first rows, first events such as buffers growing), then count.
    run(
        &mut diag,
        &mut monitor,
        engine,
        csv,
        start_tick,
        start_tick + 200,
    );
    let n = allocations(|| {
        run(
            &mut diag,
            &mut monitor,
            engine,
            csv,
            start_tick + 200,
            start_tick + 200 + ticks,
        )
    });
    assert_eq!(n, 0, "{} allocations in {ticks} ticks", n);
}

#[test]
fn sampled_and_continuous_loops_do_not_allocate() {
    // The counter works.
    assert_eq!(allocations(|| drop(std::hint::black_box(vec![1u8; 10]))), 1);
    let dir = tempfile::tempdir().expect("tempdir");
    let m = faulty_paper("sampled");
    let mut sim = SampledSim::new(&m).expect("sim");
    let mut csv =
        CsvRecorder::create(&dir.path().join("a.csv"), &m, sim.estimate_info()).expect("csv");
    full_loop(&m, &mut sim, 0, 1000, &mut csv);

    let m = faulty_paper("continuous");
    let mut sim = ContinuousSim::new(&m).expect("sim");
    let mut csv =
        CsvRecorder::create(&dir.path().join("b.csv"), &m, sim.estimate_info()).expect("csv");
    full_loop(&m, &mut sim, 0, 100, &mut csv);

    // Strips (ideal radio: frames straight from the senders' outboxes), one thread.
    for n in [300, 1000] {
        let m = strip_model(n, 10.0).unwrap();
        assert!(ph_formation_sim::engine::direct_radio(&m));
        let mut sim = SampledSim::new(&m).expect("sim");
        sim.advance_ticks(0.0, 20);
        let n = allocations(|| sim.advance_ticks(0.2, 50));
        assert_eq!(n, 0);
    }
}

#[test]
fn the_shared_channel_does_not_allocate() {
    // Faults on top of a channel (ALOHA with collisions, and TDMA), 20 agents.
    let path = format!("{}/scenarios/strip20.toml", env!("CARGO_MANIFEST_DIR"));
    for access in ["aloha", "tdma"] {
        let o: Vec<String> = [
            "radio.channel.preset=crazyflie".to_owned(),
            format!("radio.channel.access={access}"),
            "radio.channel.range=6".to_owned(),
            "radio.loss=0.1".to_owned(),
            "radio.latency=0.003".to_owned(),
            "radio.jitter=0.002".to_owned(),
            "controller.comm_rate_hz=50".to_owned(),
        ]
        .to_vec();
        let m = load(&path, &o).expect("strip20");
        let mut sim = SampledSim::new(&m).expect("sim");
        sim.advance_ticks(0.0, 200);
        let n = allocations(|| sim.advance_ticks(2.0, 300));
        assert_eq!(n, 0, "{access}: {n} allocations in 300 ticks");
        assert!(sim.channel_stats().expect("channel").transmissions > 0);
    }
}
