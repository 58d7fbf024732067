//! `host-sim sweep merge`: the outputs of the N shards of one sweep combined into exactly
//! what one unsharded run writes.

use super::error::SweepError;
use super::output::Manifest;
use super::run::RunRow;
use super::runs_csv;
use super::shard::Shard;
use std::path::PathBuf;

/// Reads the shard folders `dirs` (every shard of one sweep, any order) and returns the
/// manifest and rows of the whole sweep. Refuses folders of different sweeps, a shard
/// given twice, and missing shards.
pub fn merge(dirs: &[PathBuf]) -> Result<(Manifest, Vec<RunRow>), SweepError> {
    let Some(first) = dirs.first() else {
        return Err(SweepError::new(
            exit_usage(),
            "sweep merge",
            "",
            "no shard folder given",
        ));
    };
    let m0 = Manifest::read(first)?;
    let n = shard_of(first, &m0)?.n;
    let mut seen = vec![false; n as usize];
    let mut rows = Vec::new();
    let mut interrupted = false;
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
        let got = runs_csv::read(&d.join("runs.csv"), &m)?;
        if got.len() as u64 != m.finished {
            return Err(SweepError::output(
                &d.join("runs.csv"),
                format!("has {} runs, sweep.json says {}", got.len(), m.finished),
            ));
        }
        rows.extend(got);
    }
    let missing: Vec<String> = (1..=n)
        .filter(|k| !seen[(k - 1) as usize])
        .map(|k| format!("{k}/{n}"))
        .collect();
    if !missing.is_empty() {
        return Err(SweepError::new(
            exit_usage(),
            "sweep merge",
            "",
            format!("shard(s) {} missing", missing.join(", ")),
        ));
    }
    rows.sort_by_key(|r| (r.point, r.run));
    let jobs = m0.points.len() as u64 * m0.runs;
    let merged = Manifest {
        shard: None,
        jobs,
        finished: rows.len() as u64,
        interrupted: interrupted || (rows.len() as u64) < jobs,
        ..m0
    };
    Ok((merged, rows))
}

fn exit_usage() -> u8 {
    crate::exit_code::USAGE
}

fn shard_of(dir: &std::path::Path, m: &Manifest) -> Result<Shard, SweepError> {
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
