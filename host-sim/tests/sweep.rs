//! `host-sim sweep`: sweep-file errors (file, field, reason), the same results whatever the
//! number of threads, 3 shards + merge = one run, and the aggregation's statistics against
//! hand-computed values.

use ph_formation_sim::sweep::{
    aggregate, merge, quantile, run_all, run_seed, wilson, write_all, Manifest, Plan, RunRow,
    Shard, ShardArg, SweepError, SweepSource,
};
use std::path::Path;
use std::sync::atomic::{AtomicBool, Ordering};

/// 2 × 2 points, 3 runs each, 2 s of formation-only with bearing noise, radio loss and a
/// random initial shape: every run's figures depend on its seed.
const TINY: &str = include_str!("../sweeps/tiny.toml");

fn plan(text: &str) -> Result<Plan, SweepError> {
    Plan::from_source(&SweepSource::from_text("test.toml", text), None)
}

fn err(text: &str) -> SweepError {
    match plan(text) {
        Ok(_) => panic!("accepted:\n{text}"),
        Err(e) => e,
    }
}

fn with_axis(axis: &str) -> String {
    format!("[base]\nscenario = \"formation-only\"\n\n[[axes]]\n{axis}\n")
}

fn run_in_pool(p: &Plan, threads: usize, shard: Shard) -> ph_formation_sim::sweep::Finished {
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .unwrap();
    let stop = AtomicBool::new(false);
    pool.install(|| run_all(p, shard, &stop, &|_: &RunRow| {}))
}

const FILES: [&str; 4] = ["sweep.json", "runs.csv", "points.csv", "points.json"];

fn read(dir: &Path, f: &str) -> String {
    std::fs::read_to_string(dir.join(f)).unwrap()
}

#[path = "sweep/cli.rs"]
mod cli;
#[path = "sweep/env.rs"]
mod env;
#[path = "sweep/errors.rs"]
mod errors;
#[path = "sweep/resume.rs"]
mod resume;
#[path = "sweep/runs.rs"]
mod runs;
#[path = "sweep/stats.rs"]
mod stats;
