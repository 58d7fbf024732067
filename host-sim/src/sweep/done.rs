//! Which runs a `runs.csv` in job order already has, asked in execution order (`--resume`),
//! with one file position per point instead of one entry per run.

use super::error::SweepError;
use super::output::Manifest;
use super::runs_csv;
use std::fs::File;
use std::path::{Path, PathBuf};

/// The finished runs of a sorted `runs.csv`: per point, the next finished run at or after
/// the last one asked about, and where the row after it starts.
pub struct Done {
    path: PathBuf,
    reader: Option<csv::Reader<File>>,
    runs: u64,
    next: Vec<Option<(u64, csv::Position)>>,
}

impl Done {
    /// Nothing finished.
    pub fn none(m: &Manifest) -> Self {
        Self {
            path: PathBuf::new(),
            reader: None,
            runs: m.runs,
            next: Vec::new(),
        }
    }

    /// The runs of `path`, a `runs.csv` for `m` in job order (`journal::sort_runs`).
    pub fn read(path: &Path, m: &Manifest) -> Result<Self, SweepError> {
        let mut r = runs_csv::open(path, m)?;
        let mut next = vec![None; m.points.len()];
        let mut rec = csv::StringRecord::new();
        let mut last = None;
        while r
            .read_record(&mut rec)
            .map_err(|e| SweepError::output(path, format!("cannot read: {e}")))?
        {
            let Some((p, run)) = runs_csv::key(&rec) else {
                return Err(SweepError::output(path, "bad `point` or `run`"));
            };
            if last.is_some_and(|l| l >= (p, run)) || p >= next.len() {
                return Err(SweepError::output(path, "not in job order"));
            }
            if last.is_none_or(|(lp, _)| lp != p) {
                next[p] = Some((run, r.position().clone()));
            }
            last = Some((p, run));
        }
        Ok(Self {
            path: path.to_owned(),
            reader: Some(r),
            runs: m.runs,
            next,
        })
    }

    /// Whether job `j` (`point·runs + run`) finished. Asked with ascending runs for each
    /// point (as in execution order).
    pub fn has(&mut self, j: u64) -> Result<bool, SweepError> {
        let (p, run) = ((j / self.runs) as usize, j % self.runs);
        let Some(reader) = self.reader.as_mut() else {
            return Ok(false);
        };
        let mut rec = csv::StringRecord::new();
        loop {
            match self.next.get(p).cloned().flatten() {
                None => return Ok(false),
                Some((r, _)) if r >= run => return Ok(r == run),
                Some((_, after)) => {
                    let err = |e: csv::Error| SweepError::output(&self.path, format!("{e}"));
                    reader.seek(after).map_err(err)?;
                    let more = reader.read_record(&mut rec).map_err(err)?;
                    self.next[p] = match runs_csv::key(&rec) {
                        Some((q, r)) if more && q == p => Some((r, reader.position().clone())),
                        _ => None,
                    };
                }
            }
        }
    }
}
