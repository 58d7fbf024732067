//! `runs.csv` on disk while a sweep runs, and put in job order at the end, in memory
//! bounded by the plan (not by the number of runs).
//!
//! While running, finished rows are appended to `runs.csv` in execution order
//! (`order.rs`), a chunk at a time, flushed after each chunk: a sweep stopped by a
//! signal, a time limit or a crash keeps what it wrote, and `--resume` appends to it.
//! That file is a few stretches each in job order (one per round, one per earlier
//! session); [`sort_runs`] finds them in one pass and merges them (a k-way merge, one
//! buffered reader per stretch) into `runs.csv` in job order, aggregating the points as
//! the rows go by ([`Sorted`]). Two rows of the same run are refused.

use super::aggregate::{PointStats, Sorted};
use super::error::SweepError;
use super::output::Manifest;
use super::run::RunRow;
use super::runs_csv;
use std::cmp::Reverse;
use std::collections::BinaryHeap;
use std::fs::{File, OpenOptions};
use std::io::{Read, Seek, SeekFrom};
use std::path::{Path, PathBuf};

/// Most stretches a file may have (a journal has at most `order::ROUNDS` per session, plus
/// the sorted rows of the sessions before: [`sort_runs`] leaves one).
pub const MAX_STRETCHES: usize = 4096;
/// Most files open at once in a merge; more stretches (shards) are merged in passes.
pub const FAN_IN: usize = 128;

/// `runs.csv` open for appending rows.
pub struct Journal {
    path: PathBuf,
    w: csv::Writer<File>,
}

impl Journal {
    /// Starts a new `runs.csv` (the header only).
    pub fn create(path: &Path, m: &Manifest) -> Result<Self, SweepError> {
        let err =
            |e: &dyn std::fmt::Display| SweepError::output(path, format!("cannot write: {e}"));
        let mut w = csv::Writer::from_path(path).map_err(|e| err(&e))?;
        w.write_record(runs_csv::header(m)).map_err(|e| err(&e))?;
        w.flush().map_err(|e| err(&e))?;
        Ok(Self {
            path: path.to_owned(),
            w,
        })
    }

    /// Appends to an existing `runs.csv` (after [`sort_runs`] checked it).
    pub fn append(path: &Path) -> Result<Self, SweepError> {
        let f = OpenOptions::new()
            .append(true)
            .open(path)
            .map_err(|e| SweepError::output(path, format!("cannot append: {e}")))?;
        Ok(Self {
            path: path.to_owned(),
            w: csv::Writer::from_writer(f),
        })
    }

    /// Appends rows (written through the OS at the next [`Journal::flush`]).
    pub fn push(&mut self, m: &Manifest, r: &RunRow) -> Result<(), SweepError> {
        self.w
            .write_record(runs_csv::record(m, r))
            .map_err(|e| SweepError::output(&self.path, format!("cannot write: {e}")))
    }

    /// Hands the rows so far to the OS.
    pub fn flush(&mut self) -> Result<(), SweepError> {
        self.w
            .flush()
            .map_err(|e| SweepError::output(&self.path, format!("cannot write: {e}")))
    }
}

/// Cuts a last line left unfinished by a killed process (no newline at the end).
fn drop_torn_line(path: &Path) -> Result<(), SweepError> {
    let err = |e: std::io::Error| SweepError::output(path, format!("cannot repair: {e}"));
    let mut f = OpenOptions::new()
        .read(true)
        .write(true)
        .open(path)
        .map_err(err)?;
    let len = f.metadata().map_err(err)?.len();
    let tail = len.min(1 << 16);
    let mut buf = vec![0u8; tail as usize];
    f.seek(SeekFrom::Start(len - tail)).map_err(err)?;
    f.read_exact(&mut buf).map_err(err)?;
    if buf.last().is_some_and(|&b| b != b'\n') {
        if let Some(i) = buf.iter().rposition(|&b| b == b'\n') {
            f.set_len(len - tail + i as u64 + 1).map_err(err)?;
        }
    }
    Ok(())
}

/// A stretch of a `runs.csv` in job order: where it starts and how many rows.
#[derive(Clone, Debug)]
pub struct Stretch {
    path: PathBuf,
    start: csv::Position,
    rows: u64,
}

/// The stretches of `path` in job order, and its number of rows.
pub fn stretches_of(path: &Path, m: &Manifest) -> Result<(Vec<Stretch>, u64), SweepError> {
    let mut r = runs_csv::open(path, m)?;
    let mut out: Vec<Stretch> = Vec::new();
    let mut last: Option<(usize, u64)> = None;
    let mut rec = csv::StringRecord::new();
    let mut total = 0u64;
    loop {
        let pos = r.position().clone();
        let more = r
            .read_record(&mut rec)
            .map_err(|e| SweepError::output(path, format!("line {}: {e}", pos.line())))?;
        if !more {
            break;
        }
        let key = runs_csv::key(&rec).ok_or_else(|| {
            SweepError::output(path, format!("line {}: bad `point` or `run`", pos.line()))
        })?;
        total += 1;
        match (last, out.last_mut()) {
            (Some(prev), Some(s)) if key > prev => s.rows += 1,
            _ => {
                out.push(Stretch {
                    path: path.to_owned(),
                    start: pos,
                    rows: 1,
                });
                if out.len() > MAX_STRETCHES {
                    return Err(SweepError::output(
                        path,
                        format!("more than {MAX_STRETCHES} stretches out of job order"),
                    ));
                }
            }
        }
        last = Some(key);
    }
    Ok((out, total))
}

/// One stretch being read.
struct Cursor {
    r: csv::Reader<File>,
    left: u64,
    line: u64,
    path: PathBuf,
}

impl Cursor {
    fn next(&mut self, m: &Manifest) -> Result<Option<RunRow>, SweepError> {
        if self.left == 0 {
            return Ok(None);
        }
        self.left -= 1;
        let mut rec = csv::StringRecord::new();
        let line = self.r.position().line();
        self.line = line;
        match self.r.read_record(&mut rec) {
            Ok(true) => runs_csv::parse(&self.path, m, &rec, line).map(Some),
            Ok(false) => Err(SweepError::output(&self.path, "ends early")),
            Err(e) => Err(SweepError::output(&self.path, format!("line {line}: {e}"))),
        }
    }
}

/// Merges `stretches` (of one or more files written for `m`) into `out` in job order,
/// aggregating the points; returns the number of rows and the statistics. More than
/// [`FAN_IN`] stretches are first merged by groups into files beside `out`
/// (`<out>.pass<k>-<i>`, removed after).
pub fn merge_stretches(
    stretches: &[Stretch],
    m: &Manifest,
    out: &Path,
) -> Result<(u64, Vec<PointStats>), SweepError> {
    let mut level = stretches.to_vec();
    let mut temps: Vec<PathBuf> = Vec::new();
    let mut pass = 0;
    let result = loop {
        if level.len() <= FAN_IN {
            break merge_few(&level, m, out);
        }
        pass += 1;
        let mut next = Vec::new();
        for (i, group) in level.chunks(FAN_IN).enumerate() {
            let mut name = out.as_os_str().to_owned();
            name.push(format!(".pass{pass}-{i}"));
            let tmp = PathBuf::from(name);
            temps.push(tmp.clone());
            if let Err(e) = merge_few(group, m, &tmp) {
                remove(&temps);
                return Err(e);
            }
            next.extend(stretches_of(&tmp, m)?.0);
        }
        level = next;
    };
    remove(&temps);
    result
}

fn remove(files: &[PathBuf]) {
    for f in files {
        let _ = std::fs::remove_file(f);
    }
}

fn merge_few(
    stretches: &[Stretch],
    m: &Manifest,
    out: &Path,
) -> Result<(u64, Vec<PointStats>), SweepError> {
    let err = |e: &dyn std::fmt::Display| SweepError::output(out, format!("cannot write: {e}"));
    let mut cursors = Vec::with_capacity(stretches.len());
    let mut heap = BinaryHeap::new();
    for (i, s) in stretches.iter().enumerate() {
        let mut r = csv::ReaderBuilder::new()
            .has_headers(false)
            .from_path(&s.path)
            .map_err(|e| SweepError::output(&s.path, format!("cannot read: {e}")))?;
        r.seek(s.start.clone())
            .map_err(|e| SweepError::output(&s.path, format!("cannot read: {e}")))?;
        let mut c = Cursor {
            r,
            left: s.rows,
            line: 0,
            path: s.path.clone(),
        };
        if let Some(row) = c.next(m)? {
            heap.push(Reverse(((row.point, row.run), i, HeapRow(row))));
        }
        cursors.push(c);
    }
    let mut w = csv::Writer::from_path(out).map_err(|e| err(&e))?;
    w.write_record(runs_csv::header(m)).map_err(|e| err(&e))?;
    let mut agg = Sorted::new(m.points.len());
    let mut last = None;
    let mut n = 0u64;
    while let Some(Reverse((key, i, HeapRow(row)))) = heap.pop() {
        if last == Some(key) {
            let c = &cursors[i];
            return Err(SweepError::output(
                &c.path,
                format!(
                    "line {}: point {} run {} appears twice",
                    c.line, key.0, key.1
                ),
            ));
        }
        last = Some(key);
        w.write_record(runs_csv::record(m, &row))
            .map_err(|e| err(&e))?;
        agg.add(&row);
        n += 1;
        if let Some(next) = cursors[i].next(m)? {
            heap.push(Reverse(((next.point, next.run), i, HeapRow(next))));
        }
    }
    w.flush().map_err(|e| err(&e))?;
    Ok((n, agg.finish()))
}

/// A row in the heap: ordered by the key beside it only.
struct HeapRow(RunRow);

impl PartialEq for HeapRow {
    fn eq(&self, _: &Self) -> bool {
        true
    }
}
impl Eq for HeapRow {}
impl PartialOrd for HeapRow {
    fn partial_cmp(&self, other: &Self) -> Option<std::cmp::Ordering> {
        Some(self.cmp(other))
    }
}
impl Ord for HeapRow {
    fn cmp(&self, _: &Self) -> std::cmp::Ordering {
        std::cmp::Ordering::Equal
    }
}

/// Puts `dir/runs.csv` in job order (dropping a torn last line); returns its number of
/// rows and the points' statistics.
pub fn sort_runs(dir: &Path, m: &Manifest) -> Result<(u64, Vec<PointStats>), SweepError> {
    let path = dir.join("runs.csv");
    drop_torn_line(&path)?;
    let (parts, _) = stretches_of(&path, m)?;
    let tmp = dir.join("runs.csv.sorting");
    let got = merge_stretches(&parts, m, &tmp)?;
    std::fs::rename(&tmp, &path)
        .map_err(|e| SweepError::output(&path, format!("cannot replace: {e}")))?;
    Ok(got)
}
