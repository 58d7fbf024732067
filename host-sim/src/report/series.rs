//! The time series in memory: the columns of `timeseries.csv` as numbers, for callers of
//! the library that want the rows without a file.

use super::columns::{for_each_cell, header};
use crate::engine::{Recorder, Row};
use crate::model::{EstimateInfo, Model};
use std::io;

/// Every logged row of a run, in memory, with the columns of `timeseries.csv` (counters
/// as `f64`).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct TimeSeries {
    columns: Vec<String>,
    values: Vec<f64>,
}

impl TimeSeries {
    /// An empty series with the columns of `model` with these estimates.
    pub fn new(model: &Model, estimates: &[EstimateInfo]) -> Self {
        Self {
            columns: header(model, estimates),
            values: Vec::new(),
        }
    }

    /// Reads a run's `timeseries.csv` back (an empty or non-numeric field is NaN).
    pub fn read_csv(path: &std::path::Path) -> io::Result<Self> {
        let mut reader = csv::Reader::from_path(path).map_err(io::Error::other)?;
        let columns: Vec<String> = reader
            .headers()
            .map_err(io::Error::other)?
            .iter()
            .map(|s| s.trim().to_owned())
            .collect();
        let mut values = Vec::new();
        for rec in reader.records() {
            let rec = rec.map_err(io::Error::other)?;
            values.extend((0..columns.len()).map(|k| {
                rec.get(k)
                    .and_then(|v| v.trim().parse().ok())
                    .unwrap_or(f64::NAN)
            }));
        }
        Ok(Self { columns, values })
    }

    /// The column names (the header of `timeseries.csv`).
    pub fn columns(&self) -> &[String] {
        &self.columns
    }

    /// Number of rows.
    pub fn len(&self) -> usize {
        self.values
            .len()
            .checked_div(self.columns.len())
            .unwrap_or(0)
    }

    /// No rows.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Row `i`, in column order.
    pub fn row(&self, i: usize) -> Option<&[f64]> {
        if i >= self.len() {
            return None;
        }
        let w = self.columns.len();
        self.values.get(i * w..(i + 1) * w)
    }

    /// The rows, in order.
    pub fn rows(&self) -> impl Iterator<Item = &[f64]> {
        self.values.chunks_exact(self.columns.len().max(1))
    }

    /// The index of the column `name`.
    pub fn index(&self, name: &str) -> Option<usize> {
        self.columns.iter().position(|c| c == name)
    }

    /// Every value of the column `name` (e.g. `"t"`, `"V"`, `"x_1"`), in row order.
    pub fn column(&self, name: &str) -> Option<Vec<f64>> {
        let k = self.index(name)?;
        Some(self.rows().map(|r| r[k]).collect())
    }
}

impl Recorder for TimeSeries {
    fn record(&mut self, row: &Row<'_>) -> io::Result<()> {
        for_each_cell(row, |c| self.values.push(c.as_f64()));
        Ok(())
    }
}
