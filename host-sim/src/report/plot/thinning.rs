//! Which rows and which agents, angles or estimates are kept when a run is large.

use super::{MAX_POINTS, SNAPSHOTS};

/// Which valid rows (rows with a finite `t`) are kept.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) struct Thinning {
    pub(super) valid: usize,
    pub(super) stride: usize,
}

impl Thinning {
    pub(super) fn new(valid: usize) -> Self {
        Self {
            valid,
            stride: valid.div_ceil(MAX_POINTS).max(1),
        }
    }

    /// Whether valid row `v` (0-based) is kept: every `stride`-th and the last.
    pub(super) fn keeps(&self, v: usize) -> bool {
        v.is_multiple_of(self.stride) || v + 1 == self.valid
    }

    /// Number of kept rows.
    pub(super) fn kept(&self) -> usize {
        if self.valid == 0 {
            return 0;
        }
        let last = self.valid - 1;
        last / self.stride + 1 + usize::from(!last.is_multiple_of(self.stride))
    }

    /// Kept-row ordinals of the formation snapshots: evenly spread, first
    /// and last included, no duplicates.
    pub(super) fn snapshots(&self) -> Vec<usize> {
        let m = self.kept();
        let mut out: Vec<usize> = (0..SNAPSHOTS)
            .map(|k| ((k * m.saturating_sub(1)) as f64 / (SNAPSHOTS - 1) as f64).round() as usize)
            .collect();
        out.dedup();
        out
    }
}

/// Indices `0..n` thinned to at most `max`, evenly spaced, first and last
/// included.
pub(crate) fn spread(n: usize, max: usize) -> Vec<usize> {
    if n <= max {
        return (0..n).collect();
    }
    if max < 2 {
        return (0..max).collect();
    }
    let mut out: Vec<usize> = (0..max)
        .map(|k| ((k * (n - 1)) as f64 / (max - 1) as f64).round() as usize)
        .collect();
    out.dedup();
    out
}
