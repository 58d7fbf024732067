//! Why plotting a run failed.

use super::FONT_ASSET;
use std::path::PathBuf;

/// Why plotting a run failed. Every variant names the file concerned.
#[derive(Debug, thiserror::Error)]
pub enum PlotError {
    /// An input file could not be opened or read.
    #[error("{}: cannot read: {source}", path.display())]
    Io {
        /// The file.
        path: PathBuf,
        /// The underlying error.
        #[source]
        source: std::io::Error,
    },
    /// `timeseries.csv` is not well-formed CSV (e.g. a row has the wrong
    /// number of fields).
    #[error("{}: malformed CSV: {source}", path.display())]
    Csv {
        /// The file.
        path: PathBuf,
        /// The underlying error, with its position.
        #[source]
        source: csv::Error,
    },
    /// `summary.json` is not valid JSON or lacks a required field.
    #[error("{}: malformed summary: {source}", path.display())]
    Json {
        /// The file.
        path: PathBuf,
        /// The underlying error, with its position or the field name.
        #[source]
        source: serde_json::Error,
    },
    /// A column that the plots need is not in the CSV header.
    #[error("{}: missing column `{column}`", path.display())]
    MissingColumn {
        /// The file.
        path: PathBuf,
        /// Name of the missing column.
        column: String,
    },
    /// The CSV has no header or no data row with a finite `t`.
    #[error("{}: no data: {reason}", path.display())]
    Empty {
        /// The file.
        path: PathBuf,
        /// What exactly is missing.
        reason: &'static str,
    },
    /// A field is neither a number nor empty.
    #[error("{}: line {line}, column `{column}`: `{value}` is not a number", path.display())]
    BadValue {
        /// The file.
        path: PathBuf,
        /// 1-based line number in the file.
        line: u64,
        /// Column name.
        column: String,
        /// The offending text (at most 40 characters of it).
        value: String,
    },
    /// Drawing or writing an output image failed.
    #[error("{}: cannot draw: {reason}", path.display())]
    Draw {
        /// The output file.
        path: PathBuf,
        /// What the plotting library reported.
        reason: String,
    },
    /// The embedded font could not be loaded (a build problem).
    #[error("{FONT_ASSET}: embedded font is not a valid TrueType font")]
    Font,
}
