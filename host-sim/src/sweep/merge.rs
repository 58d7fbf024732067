//! `host-sim sweep merge`: the outputs of the N shards of one sweep combined into exactly
//! what one unsharded run writes, streamed (one reader per shard).

use super::aggregate::PointStats;
use super::error::SweepError;
use super::journal::{merge_stretches, stretches_of};
use super::output::{write_summary, Manifest};
use super::run::RunRow;
use super::runs_csv;
use super::shard::Shard;
use std::path::{Path, PathBuf};

/// The shards of one sweep, checked against each other.
struct Checked {
    /// The merged sweep's manifest (`finished` and `interrupted` from the shards').
    merged: Manifest,
    /// Each folder and its manifest.
    shards: Vec<(PathBuf, Manifest)>,
}

/// Reads the shard folders `dirs` (every shard of one sweep, any order). Refuses folders
/// of different sweeps, a shard given twice, and missing shards (naming them).
fn check(dirs: &[PathBuf]) -> Result<Checked, SweepError> {
    let Some(first) = dirs.first() else {
        return Err(usage("no shard folder given".to_owned()));
    };
    let m0 = Manifest::read(first)?;
    let n = shard_of(first, &m0)?.n;
    let mut seen = vec![false; n as usize];
    let mut shards = Vec::new();
    let (mut interrupted, mut finished) = (false, 0);
    for d in dirs {
        let m = Manifest::read(d)?;
        let s = shard_of(d, &m)?;
        let label = d.join("sweep.json");
        let mismatch = |what: &str| {
            SweepError::output(
                &label,
                format!(
                    "{what} differs from {}'s: not a shard of the same sweep",
                    first.display()
                ),
            )
        };
        if m.fingerprint != m0.fingerprint || m.points != m0.points || m.axes != m0.axes {
            return Err(mismatch("the sweep"));
        }
        if m.outcomes != m0.outcomes {
            return Err(mismatch("the outcome list (another host-sim version)"));
        }
        if s.n != n {
            return Err(mismatch("the shard count"));
        }
        if std::mem::replace(&mut seen[(s.k - 1) as usize], true) {
            return Err(SweepError::output(
                &label,
                format!("shard {s} is given twice"),
            ));
        }
        interrupted |= m.interrupted;
        finished += m.finished;
        shards.push((d.clone(), m));
    }
    let missing: Vec<String> = (1..=n)
        .filter(|k| !seen[(k - 1) as usize])
        .map(|k| format!("{k}/{n}"))
        .collect();
    if !missing.is_empty() {
        return Err(usage(format!(
            "shard(s) {} missing: run them (the same command with --shard K/{n}), then merge \
             again",
            missing.join(", ")
        )));
    }
    let jobs = m0.points.len() as u64 * m0.runs;
    let merged = Manifest {
        shard: None,
        jobs,
        finished,
        interrupted: interrupted || finished < jobs,
        ..m0
    };
    Ok(Checked { merged, shards })
}

/// The shards of `dirs` that stopped before their last run, one sentence each (`shard
/// 2/3 (DIR): 5 of 8 runs`), for the command to name.
pub fn partial(dirs: &[PathBuf]) -> Vec<String> {
    dirs.iter()
        .filter_map(|d| {
            let m = Manifest::read(d).ok()?;
            m.interrupted.then(|| {
                format!(
                    "shard {} ({}): {} of {} runs",
                    m.shard.as_deref().unwrap_or("?"),
                    d.display(),
                    m.finished,
                    m.jobs
                )
            })
        })
        .collect()
}

/// Reads the shard folders `dirs` and returns the manifest and rows of the whole sweep,
/// in memory (for small sweeps and tests; the command uses [`merge_into`]).
pub fn merge(dirs: &[PathBuf]) -> Result<(Manifest, Vec<RunRow>), SweepError> {
    let c = check(dirs)?;
    let mut rows = Vec::new();
    for (d, m) in &c.shards {
        let got = runs_csv::read(&d.join("runs.csv"), m)?;
        if got.len() as u64 != m.finished {
            return Err(count_mismatch(d, got.len() as u64, m.finished));
        }
        rows.extend(got);
    }
    rows.sort_by_key(|r| (r.point, r.run));
    Ok((c.merged, rows))
}

/// Merges the shard folders `dirs` into `out` (every file one unsharded run writes;
/// figures if `plots`), streaming the rows. Returns the manifest, the points' statistics
/// and the files.
pub fn merge_into(
    dirs: &[PathBuf],
    out: &Path,
    plots: bool,
) -> Result<(Manifest, Vec<PointStats>, Vec<PathBuf>), SweepError> {
    let c = check(dirs)?;
    let mut all = Vec::new();
    for (d, m) in &c.shards {
        let (parts, rows) = stretches_of(&d.join("runs.csv"), m)?;
        if rows != m.finished {
            return Err(count_mismatch(d, rows, m.finished));
        }
        all.extend(parts);
    }
    std::fs::create_dir_all(out)
        .map_err(|e| SweepError::output(out, format!("cannot create: {e}")))?;
    let (_, stats) = merge_stretches(&all, &c.merged, &out.join("runs.csv"))?;
    let files = write_summary(out, &c.merged, &stats, plots)?;
    Ok((c.merged, stats, files))
}

fn count_mismatch(dir: &Path, rows: u64, said: u64) -> SweepError {
    SweepError::output(
        &dir.join("runs.csv"),
        format!(
            "has {rows} runs, sweep.json says {said}: the shard was killed before it could \
             finish writing; resume it: host-sim sweep --resume {}",
            dir.display()
        ),
    )
}

fn usage(reason: String) -> SweepError {
    SweepError::new(crate::exit_code::USAGE, "sweep merge", "", reason)
}

fn shard_of(dir: &Path, m: &Manifest) -> Result<Shard, SweepError> {
    let label = dir.join("sweep.json");
    match &m.shard {
        Some(s) => s
            .parse()
            .map_err(|e| SweepError::output(&label, format!("shard: {e}"))),
        None => Err(SweepError::output(
            &label,
            "not a shard's output (no `shard`)",
        )),
    }
}
