//! Where the driver sends each logged instant: a [`Recorder`] (the reports write
//! `timeseries.csv` or keep the rows in memory; the engine only defines the interface).

use super::stats::FrameCounts;
use crate::analysis::Snapshot;
use ph_formation_core::Vec2;
use std::io;

/// One logged instant.
#[derive(Clone, Copy, Debug)]
pub struct Row<'a> {
    /// Diagnostics of the instant.
    pub snap: &'a Snapshot,
    /// Positions.
    pub q: &'a [Vec2<f64>],
    /// Velocities.
    pub v: &'a [Vec2<f64>],
    /// Estimates (layout order).
    pub estimates: &'a [f64],
    /// Cumulative frame counters.
    pub frames: FrameCounts,
}

/// Where logged rows go.
pub trait Recorder {
    /// Records one row.
    fn record(&mut self, row: &Row<'_>) -> io::Result<()>;
    /// Whether [`Recorder::record`] keeps rows at all (a run skips assembling them, e.g.
    /// summing every agent's frame counters, when no recorder does).
    fn wants_rows(&self) -> bool {
        true
    }
    /// Flushes at the end of the run.
    fn finish(&mut self) -> io::Result<()> {
        Ok(())
    }
}

/// Discards every row (benchmarks, tests that only need the summary).
#[derive(Clone, Copy, Debug, Default)]
pub struct NullRecorder;

impl Recorder for NullRecorder {
    fn record(&mut self, _row: &Row<'_>) -> io::Result<()> {
        Ok(())
    }

    fn wants_rows(&self) -> bool {
        false
    }
}

/// Records into the recorder if there is one.
impl<R: Recorder> Recorder for Option<R> {
    fn record(&mut self, row: &Row<'_>) -> io::Result<()> {
        match self {
            Some(r) => r.record(row),
            None => Ok(()),
        }
    }

    fn wants_rows(&self) -> bool {
        self.as_ref().is_some_and(R::wants_rows)
    }

    fn finish(&mut self) -> io::Result<()> {
        match self {
            Some(r) => r.finish(),
            None => Ok(()),
        }
    }
}

/// Records into both, in order (the first error stops).
impl<A: Recorder, B: Recorder> Recorder for (A, B) {
    fn record(&mut self, row: &Row<'_>) -> io::Result<()> {
        self.0.record(row)?;
        self.1.record(row)
    }

    fn wants_rows(&self) -> bool {
        self.0.wants_rows() || self.1.wants_rows()
    }

    fn finish(&mut self) -> io::Result<()> {
        let a = self.0.finish();
        let b = self.1.finish();
        a.and(b)
    }
}
