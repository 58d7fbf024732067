//! `timeseries.csv`: one row per log instant, written without allocating after the first
//! row (`docs/outputs.md`).

use super::columns::{for_each_cell, header, Cell};
use super::number::write_f64;
use crate::engine::{Recorder, Row};
use crate::model::{EstimateInfo, Model};
use std::fs::File;
use std::io::{self, BufWriter, Write};
use std::path::Path;

/// Writes `timeseries.csv`.
pub struct CsvRecorder {
    out: BufWriter<File>,
    line: Vec<u8>,
}

impl CsvRecorder {
    /// Creates the file and writes the header row.
    pub fn create(path: &Path, model: &Model, estimates: &[EstimateInfo]) -> io::Result<Self> {
        let mut out = BufWriter::new(File::create(path)?);
        writeln!(out, "{}", header(model, estimates).join(","))?;
        Ok(Self {
            out,
            line: Vec::with_capacity(4096),
        })
    }
}

impl Recorder for CsvRecorder {
    /// Numbers in Rust's shortest round-trip form (the text of `{:?}`: `0.35`, `1e-7`,
    /// `NaN`; [`write_f64`]), counters as integers.
    fn record(&mut self, r: &Row<'_>) -> io::Result<()> {
        let l = &mut self.line;
        l.clear();
        for_each_cell(r, |c| {
            let _ = match c {
                Cell::Real(x) => {
                    write_f64(l, x);
                    Ok(())
                }
                Cell::Count(n) => write!(l, "{n}"),
            };
            l.push(b',');
        });
        l.pop();
        l.push(b'\n');
        self.out.write_all(l)
    }

    fn finish(&mut self) -> io::Result<()> {
        self.out.flush()
    }
}
