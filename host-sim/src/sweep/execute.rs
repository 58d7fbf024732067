//! A sweep run for the command line: jobs in interleaved order (`order.rs`), rows
//! streamed to `runs.csv` (`journal.rs`), stopped cleanly by a flag (Ctrl-C, SIGTERM) or
//! a run limit, resumed from what a folder holds. Memory: the plan, one chunk of rows,
//! one file position per point, and the settle times of one point while sorting.

use super::aggregate::PointStats;
use super::done::Done;
use super::error::SweepError;
use super::journal::{sort_runs, Journal};
use super::order;
use super::output::{write_manifest, write_summary, Manifest};
use super::plan::Plan;
use super::run::{run_job, RunRow};
use super::shard::Shard;
use rayon::prelude::*;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};

/// When to stop early, and what to tell after each run.
pub struct Control<'a> {
    /// Once set, no new run starts (the running ones finish and are kept).
    pub stop: &'a AtomicBool,
    /// Start at most this many runs in this session (`--max-runs`), then stop as `stop`.
    pub max_runs: Option<u64>,
    /// Called after each run, from the worker thread.
    pub done: &'a (dyn Fn(&RunRow) + Sync),
}

/// What [`execute`] did.
#[derive(Clone, Debug)]
pub struct Report {
    /// The folder's `sweep.json` as written at the end.
    pub manifest: Manifest,
    /// Per point.
    pub stats: Vec<PointStats>,
    /// The files written.
    pub files: Vec<PathBuf>,
    /// Runs already in the folder when it started (`--resume`).
    pub resumed: u64,
    /// Runs made in this session.
    pub ran: u64,
}

/// Runs `jobs` on the current rayon pool, started in their order (each thread takes the
/// next one), so that a stop leaves a prefix of them done but for the ones still running;
/// returns the finished rows in that order.
fn run_in_order(plan: &Plan, jobs: &[u64], ctl: &Control<'_>) -> Vec<RunRow> {
    let next = AtomicUsize::new(0);
    let mut rows: Vec<(usize, RunRow)> = (0..rayon::current_num_threads())
        .into_par_iter()
        .flat_map_iter(|_| {
            let mut mine = Vec::new();
            while !ctl.stop.load(Ordering::SeqCst) {
                let i = next.fetch_add(1, Ordering::SeqCst);
                let Some(&j) = jobs.get(i) else { break };
                let row = run_job(plan, j);
                (ctl.done)(&row);
                mine.push((i, row));
            }
            mine
        })
        .collect();
    rows.sort_by_key(|(i, _)| *i);
    rows.into_iter().map(|(_, r)| r).collect()
}

/// Runs the jobs of `shard` of `plan` into `dir`. With `resume` and a `dir/sweep.json`
/// of the same sweep and shard, the runs already in `dir/runs.csv` are kept and not run
/// again; otherwise `dir` starts afresh. The files at the end are those of an
/// uninterrupted run, byte for byte, however many sessions it took.
pub fn execute(
    plan: &Plan,
    shard: Shard,
    dir: &Path,
    resume: bool,
    plots: bool,
    ctl: &Control<'_>,
) -> Result<Report, SweepError> {
    std::fs::create_dir_all(dir)
        .map_err(|e| SweepError::output(dir, format!("cannot create: {e}")))?;
    let runs_path = dir.join("runs.csv");
    let jobs = shard.count(plan.jobs());
    let mut m = Manifest::of(plan, shard, jobs, 0, true);
    let mut done = Done::none(&m);
    if resume && dir.join("sweep.json").is_file() {
        let old = Manifest::read(dir)?;
        let label = dir.join("sweep.json");
        if old.fingerprint != m.fingerprint || old.points != m.points {
            return Err(SweepError::output(
                &label,
                format!(
                    "is another sweep (fingerprint {}, this one {}): nothing to resume",
                    old.fingerprint, m.fingerprint
                ),
            ));
        }
        if old.shard != m.shard {
            let name = |s: &Option<String>| s.clone().unwrap_or_else(|| "the whole sweep".into());
            return Err(SweepError::output(
                &label,
                format!("holds {}, not {}", name(&old.shard), name(&m.shard)),
            ));
        }
        if runs_path.is_file() {
            m.finished = sort_runs(dir, &m)?.0;
            done = Done::read(&runs_path, &m)?;
        } else {
            Journal::create(&runs_path, &m)?;
        }
    } else {
        Journal::create(&runs_path, &m)?;
    }
    let resumed = m.finished;
    write_manifest(dir, &m)?;
    let mut journal = Journal::append(&runs_path)?;
    let chunk_len = (16 * rayon::current_num_threads()).max(64);
    let budget = ctl.max_runs.unwrap_or(u64::MAX);
    let mut order = order::jobs(plan.points.len() as u64, plan.runs, shard);
    let mut chunk = Vec::with_capacity(chunk_len);
    let mut ran = 0u64;
    while !ctl.stop.load(Ordering::SeqCst) && ran < budget {
        chunk.clear();
        let want = (chunk_len as u64).min(budget - ran) as usize;
        while chunk.len() < want {
            let Some(j) = order.next() else { break };
            if !done.has(j)? {
                chunk.push(j);
            }
        }
        if chunk.is_empty() {
            break;
        }
        for r in run_in_order(plan, &chunk, ctl) {
            journal.push(&m, &r)?;
            ran += 1;
        }
        journal.flush()?;
    }
    drop(journal);
    let (finished, stats) = sort_runs(dir, &m)?;
    m.finished = finished;
    m.interrupted = finished < jobs;
    let files = write_summary(dir, &m, &stats, plots)?;
    Ok(Report {
        manifest: m,
        stats,
        files,
        resumed,
        ran,
    })
}
