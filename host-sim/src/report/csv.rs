//! `timeseries.csv`: one row per log instant, written without allocating after the first
//! row (`docs/outputs.md`).

use super::columns::{for_each_cell, header, Cell};
use crate::engine::{Recorder, Row};
use crate::model::{EstimateInfo, Model};
use std::fmt::Write as _;
use std::fs::File;
use std::io::{self, BufWriter, Write};
use std::path::Path;

/// Writes `timeseries.csv`.
pub struct CsvRecorder {
    out: BufWriter<File>,
    line: String,
}

impl CsvRecorder {
    /// Creates the file and writes the header row.
    pub fn create(path: &Path, model: &Model, estimates: &[EstimateInfo]) -> io::Result<Self> {
        let mut out = BufWriter::new(File::create(path)?);
        writeln!(out, "{}", header(model, estimates).join(","))?;
        Ok(Self {
            out,
            line: String::with_capacity(4096),
        })
    }
}

impl Recorder for CsvRecorder {
    /// Numbers in Rust's shortest round-trip form (`{:?}`: `0.35`, `1e-7`, `NaN`),
    /// counters as integers.
    fn record(&mut self, r: &Row<'_>) -> io::Result<()> {
        let l = &mut self.line;
        l.clear();
        for_each_cell(r, |c| {
            let _ = match c {
                Cell::Real(x) => write!(l, "{x:?},"),
                Cell::Count(n) => write!(l, "{n},"),
            };
        });
        l.pop();
        l.push('\n');
        self.out.write_all(l.as_bytes())
    }

    fn finish(&mut self) -> io::Result<()> {
        self.out.flush()
    }
}
