//! The size budget of the row files (`timeseries.csv`, `run.mcap`): a run whose full-rate
//! series would be larger than [`SeriesBudget::max_full_cells`] keeps every `stride`-th
//! logged row (and always the first and the last) in its files, so that a 100-agent,
//! 100 s run writes tens of megabytes instead of 274 MB (`docs/outputs.md`, "Size
//! budget"). The engine, its monitor and the verdict see every instant whatever the files
//! keep: thinning only chooses which rows are written.

use crate::analysis::Snapshot;
use crate::engine::{FrameCounts, Recorder, Row};
use crate::model::Model;
use ph_formation_core::Vec2;
use std::io;

/// How many cells (rows × columns) the row files may hold before they are thinned, and
/// how many a thinned series aims at.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct SeriesBudget {
    /// A series of at most this many cells is written whole (every logged row).
    pub max_full_cells: u64,
    /// A larger one keeps every `stride`-th row, the stride the smallest of 1, 2, 5,
    /// 10, 20, 50, … that brings it to at most this many cells.
    pub thinned_cells: u64,
}

impl SeriesBudget {
    /// The default: 8,000,000 cells (about 160 MB of CSV at ~20 bytes a cell) are
    /// written whole — every built-in and shipped scenario is (the largest, `tri50.toml`,
    /// has 6.93 M) — and a larger series is thinned to at most 1,000,000 cells (about
    /// 20 MB): a 100-agent, 100 s run (13.9 M cells) keeps every 20th row.
    pub const DEFAULT: Self = Self {
        max_full_cells: 8_000_000,
        thinned_cells: 1_000_000,
    };

    /// Every logged row, whatever the size (`host-sim run --full-rate`).
    pub const FULL_RATE: Self = Self {
        max_full_cells: u64::MAX,
        thinned_cells: u64::MAX,
    };

    /// The stride for a series of `rows` rows of `columns` cells: 1 (every row) when it
    /// fits [`Self::max_full_cells`], else the smallest of 2, 5, 10, 20, 50, … with which
    /// the rows kept (`⌈rows / stride⌉`, plus the last) hold at most
    /// [`Self::thinned_cells`] cells (at least one row).
    pub fn stride(&self, rows: u64, columns: u64) -> u64 {
        let cells = rows.saturating_mul(columns);
        if cells <= self.max_full_cells {
            return 1;
        }
        let fits = |s: u64| (rows.div_ceil(s) + 1).saturating_mul(columns) <= self.thinned_cells;
        let mut decade: u64 = 1;
        loop {
            for m in [1, 2, 5] {
                let s = decade.saturating_mul(m);
                if s > 1 && (fits(s) || s >= rows) {
                    return s;
                }
            }
            decade = decade.saturating_mul(10);
        }
    }
}

impl Default for SeriesBudget {
    fn default() -> Self {
        Self::DEFAULT
    }
}

/// The rows a run of `model` logs when it runs to its end: one every `log_every` steps
/// from step 0, and the last step.
pub fn expected_rows(model: &Model) -> u64 {
    let total = model.total_steps() as u64;
    let every = model.log_every.max(1) as u64;
    total / every + 1 + u64::from(!total.is_multiple_of(every))
}

/// A copy of a skipped row, kept until the next one (the run's last row is written even
/// when the stride skips it).
#[derive(Default)]
struct Kept {
    snap: Snapshot,
    q: Vec<Vec2<f64>>,
    v: Vec<Vec2<f64>>,
    estimates: Vec<f64>,
    frames: FrameCounts,
}

impl Kept {
    fn copy(&mut self, r: &Row<'_>) {
        self.snap.clone_from(r.snap);
        self.q.clear();
        self.q.extend_from_slice(r.q);
        self.v.clear();
        self.v.extend_from_slice(r.v);
        self.estimates.clear();
        self.estimates.extend_from_slice(r.estimates);
        self.frames = r.frames;
    }

    fn row(&self) -> Row<'_> {
        Row {
            snap: &self.snap,
            q: &self.q,
            v: &self.v,
            estimates: &self.estimates,
            frames: self.frames,
        }
    }
}

/// Passes rows 0, `stride`, 2·`stride`, … and the last one to `R` (every row with a
/// stride of 1, at the cost of one comparison).
pub struct Thinned<R> {
    inner: R,
    stride: u64,
    seen: u64,
    kept: Kept,
    pending: bool,
}

impl<R: Recorder> Thinned<R> {
    /// Thins the rows going to `inner` by `stride` (at least 1).
    pub fn new(inner: R, stride: u64) -> Self {
        Self {
            inner,
            stride: stride.max(1),
            seen: 0,
            kept: Kept::default(),
            pending: false,
        }
    }

    /// The recorder, once the run is over.
    pub fn into_inner(self) -> R {
        self.inner
    }
}

impl<R: Recorder> Recorder for Thinned<R> {
    fn record(&mut self, row: &Row<'_>) -> io::Result<()> {
        let i = self.seen;
        self.seen += 1;
        if i.is_multiple_of(self.stride) {
            self.pending = false;
            self.inner.record(row)
        } else {
            self.kept.copy(row);
            self.pending = true;
            Ok(())
        }
    }

    fn wants_rows(&self) -> bool {
        self.inner.wants_rows()
    }

    fn finish(&mut self) -> io::Result<()> {
        if std::mem::take(&mut self.pending) {
            self.inner.record(&self.kept.row())?;
        }
        self.inner.finish()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_stride_is_one_within_the_budget_and_a_round_number_beyond() {
        let b = SeriesBudget::DEFAULT;
        // paper (10,001 × 49), tri50 (10,001 × 693): whole.
        assert_eq!(b.stride(10_001, 49), 1);
        assert_eq!(b.stride(10_001, 693), 1);
        // A 100-agent lattice, 100 s (10,001 × 1,393 = 13.9 M cells): 501 rows kept.
        assert_eq!(b.stride(10_001, 1_393), 20);
        // 1,000 agents: 13,013 columns → 100 rows.
        assert_eq!(b.stride(10_001, 13_013), 200);
        // More columns than the budget: one row (the first) and the last.
        assert_eq!(b.stride(10, 2_000_000), 10);
        assert_eq!(SeriesBudget::FULL_RATE.stride(10_001, 1_000_000), 1);
        // The smallest round stride that fits: 2 rows of 4 cells allowed.
        let small = SeriesBudget {
            max_full_cells: 10,
            thinned_cells: 12,
        };
        // stride 2 keeps 6 + 1 rows (14 cells), 5 keeps 3 + 1 (8).
        assert_eq!(small.stride(11, 2), 5);
        assert_eq!(small.stride(5, 2), 1);
    }
}
