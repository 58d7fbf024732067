//! The logged rows that the figures and the replay page read: `timeseries.csv`, or the
//! same rows kept in memory by the run that wrote it (no re-reading: the CSV's numbers
//! are shortest round-trip decimals, so they read back as the very values kept; re-reading
//! the 8.8 MB of `paper` twice each was 0.56 G instructions, docs/outputs.md "What the
//! outputs cost").

use super::plot::PlotError;
use super::TimeSeries;
use std::fs::File;
use std::path::{Path, PathBuf};

/// One field of the current row.
pub(crate) enum Field<'r> {
    /// A value kept in memory.
    Value(f64),
    /// The CSV's text, and the row's line (for error messages).
    Text(&'r [u8], u64),
}

enum Source<'a> {
    Csv {
        reader: csv::Reader<File>,
        rec: csv::ByteRecord,
        last: csv::ByteRecord,
    },
    Memory {
        series: &'a TimeSeries,
        next: usize,
        last: usize,
    },
}

/// A reader of logged rows, row by row, from the file or from memory.
pub(crate) struct Rows<'a> {
    path: PathBuf,
    source: Source<'a>,
}

fn open(path: &Path) -> Result<csv::Reader<File>, PlotError> {
    let file = File::open(path).map_err(|source| PlotError::Io {
        path: path.to_path_buf(),
        source,
    })?;
    Ok(csv::ReaderBuilder::new()
        .has_headers(true)
        .from_reader(file))
}

impl<'a> Rows<'a> {
    /// The rows of `path` (`timeseries.csv`).
    pub(crate) fn csv(path: &Path) -> Result<Self, PlotError> {
        Ok(Self {
            path: path.to_path_buf(),
            source: Source::Csv {
                reader: open(path)?,
                rec: csv::ByteRecord::new(),
                last: csv::ByteRecord::new(),
            },
        })
    }

    /// The rows of `series`, standing for `path` (named in errors).
    pub(crate) fn memory(series: &'a TimeSeries, path: &Path) -> Self {
        Self {
            path: path.to_path_buf(),
            source: Source::Memory {
                series,
                next: 0,
                last: 0,
            },
        }
    }

    /// The column names, trimmed.
    pub(crate) fn names(&mut self) -> Result<Vec<String>, PlotError> {
        let path = self.path.clone();
        match &mut self.source {
            Source::Csv { reader, .. } => Ok(reader
                .headers()
                .map_err(|source| PlotError::Csv { path, source })?
                .iter()
                .map(|s| s.trim().to_owned())
                .collect()),
            Source::Memory { series, .. } => Ok(series.columns().to_vec()),
        }
    }

    /// Back to the first row.
    pub(crate) fn restart(&mut self) -> Result<(), PlotError> {
        match &mut self.source {
            Source::Csv { reader, .. } => *reader = open(&self.path)?,
            Source::Memory { next, .. } => *next = 0,
        }
        Ok(())
    }

    /// Moves to the next row; false after the last.
    pub(crate) fn next(&mut self) -> Result<bool, PlotError> {
        let path = &self.path;
        match &mut self.source {
            Source::Csv { reader, rec, .. } => {
                reader
                    .read_byte_record(rec)
                    .map_err(|source| PlotError::Csv {
                        path: path.clone(),
                        source,
                    })
            }
            Source::Memory { series, next, .. } => {
                let more = *next < series.len();
                *next += usize::from(more);
                Ok(more)
            }
        }
    }

    /// Keeps the current row as the last one seen ([`Self::last`]).
    pub(crate) fn keep_as_last(&mut self) {
        match &mut self.source {
            Source::Csv { rec, last, .. } => std::mem::swap(rec, last),
            Source::Memory { next, last, .. } => *last = next.saturating_sub(1),
        }
    }

    /// Column `col` of the current row.
    pub(crate) fn get(&self, col: usize) -> Field<'_> {
        match &self.source {
            Source::Csv { rec, .. } => csv_field(rec, col),
            Source::Memory { series, next, .. } => {
                memory_field(series, next.saturating_sub(1), col)
            }
        }
    }

    /// Column `col` of the row kept by [`Self::keep_as_last`].
    pub(crate) fn last(&self, col: usize) -> Field<'_> {
        match &self.source {
            Source::Csv { last, .. } => csv_field(last, col),
            Source::Memory { series, last, .. } => memory_field(series, *last, col),
        }
    }
}

fn csv_field(rec: &csv::ByteRecord, col: usize) -> Field<'_> {
    Field::Text(
        rec.get(col).unwrap_or(b""),
        rec.position().map_or(0, |p| p.line()),
    )
}

fn memory_field(series: &TimeSeries, row: usize, col: usize) -> Field<'static> {
    Field::Value(
        series
            .row(row)
            .and_then(|r| r.get(col))
            .copied()
            .unwrap_or(f64::NAN),
    )
}
