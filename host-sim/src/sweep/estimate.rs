//! Before a sweep starts: how much disk its `runs.csv` will take and how long it will run,
//! and the refusal of one above the limits unless `--allow-large` is given.

use super::error::{SweepError, INVALID};
use super::plan::Plan;
use super::shard::Shard;

/// Largest `runs.csv` a sweep may write without `--allow-large` (bytes).
pub const MAX_BYTES: f64 = 20e9;
/// Longest estimated wall time without `--allow-large` (s): one day.
pub const MAX_SECONDS: f64 = 86_400.0;
/// Bytes of a `runs.csv` row besides the axis values (a run's 14 figures in shortest
/// round-trip form, the outcome and its reason: 250–300 measured).
pub const ROW_BYTES: f64 = 320.0;
/// Agent-steps per second and thread the estimate assumes, on the low side of what the
/// built-in sweeps measure (a 4-agent 100 s run at dt = 1 ms: 4·10⁵ agent-steps in
/// 0.1–0.3 s, `docs/sweeps.md`), so the time is rather over- than underestimated.
pub const AGENT_STEPS_PER_SECOND: f64 = 1e6;

/// A sweep's estimated size.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Estimate {
    /// Runs of this shard.
    pub runs: u64,
    /// Bytes of its `runs.csv`.
    pub bytes: f64,
    /// Wall time on `threads` threads (s).
    pub seconds: f64,
    /// Threads assumed.
    pub threads: usize,
}

/// Estimates the runs of `shard` of `plan` on `threads` threads, from the base scenario's
/// duration, time step and number of agents.
pub fn estimate(plan: &Plan, shard: Shard, threads: usize) -> Estimate {
    let runs = shard.count(plan.jobs());
    let axes: usize = plan.points.first().map_or(0, |p| {
        p.iter().map(|v| super::plan::cell(v).len() + 1).sum()
    });
    let per_run = plan.model(&plan.base.set).map_or(1.0, |m| {
        m.duration / m.dt * m.n() as f64 / AGENT_STEPS_PER_SECOND
    });
    Estimate {
        runs,
        bytes: runs as f64 * (ROW_BYTES + axes as f64),
        seconds: runs as f64 * per_run / threads.max(1) as f64,
        threads: threads.max(1),
    }
}

impl Estimate {
    /// Refuses a sweep above [`MAX_BYTES`] or [`MAX_SECONDS`] (exit code 28), naming the
    /// estimate and `--allow-large`.
    pub fn check(&self, file: &str) -> Result<(), SweepError> {
        if self.bytes <= MAX_BYTES && self.seconds <= MAX_SECONDS {
            return Ok(());
        }
        Err(SweepError::new(
            INVALID,
            file,
            "runs",
            format!(
                "{} runs would write about {:.1} GB of runs.csv (limit {:.0} GB) and take \
                 about {:.1} h on {} thread(s) (limit {:.0} h): give --allow-large to run \
                 it anyway, or fewer --runs, or split it with --shard K/N",
                self.runs,
                self.bytes / 1e9,
                MAX_BYTES / 1e9,
                self.seconds / 3600.0,
                self.threads,
                MAX_SECONDS / 3600.0
            ),
        ))
    }
}
