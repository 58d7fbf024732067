//! Sweep errors: each names the file, the field and the reason, as scenario errors do
//! (`crate::scenario::ScenarioError`), and carries the exit code of the command.

use crate::exit_code;
use crate::scenario::ScenarioErrors;
use std::fmt;

/// One problem with a sweep: its file, the field, why, and the exit code.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct SweepError {
    /// The sweep file (or `builtin:<name>`), or an output directory.
    pub file: String,
    /// The dotted field (`axes[1].values[2]`), or empty.
    pub field: String,
    /// A human sentence.
    pub reason: String,
    /// Exit code: 20 unreadable, 21 schema, 28 invalid value, a scenario error's own
    /// code when the base scenario refuses a point, 1 for output.
    pub code: u8,
}

/// Exit code of an unreadable sweep file (as an unreadable scenario).
pub const UNREADABLE: u8 = 20;
/// Exit code of a TOML or schema error (as a scenario's).
pub const SCHEMA: u8 = 21;
/// Exit code of an out-of-range value (as a scenario's).
pub const INVALID: u8 = 28;

impl SweepError {
    /// Builds an error.
    pub fn new(code: u8, file: &str, field: &str, reason: impl Into<String>) -> Self {
        Self {
            file: file.to_owned(),
            field: field.to_owned(),
            reason: reason.into(),
            code,
        }
    }

    /// An output that could not be written or read back (exit code 1).
    pub fn output(path: &std::path::Path, reason: impl fmt::Display) -> Self {
        Self::new(
            exit_code::IO,
            &path.display().to_string(),
            "",
            reason.to_string(),
        )
    }

    /// The base scenario refused the overrides of `field` (every problem, one per line).
    pub fn scenario(file: &str, field: &str, what: &str, e: &ScenarioErrors) -> Self {
        let inner: Vec<String> = e.0.iter().map(ToString::to_string).collect();
        Self::new(
            e.exit_code(),
            file,
            field,
            format!("{what}: the base scenario is invalid: {}", inner.join("; ")),
        )
    }
}

impl fmt::Display for SweepError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        if self.field.is_empty() {
            write!(f, "{}: {}", self.file, self.reason)
        } else {
            write!(f, "{}: field `{}`: {}", self.file, self.field, self.reason)
        }
    }
}

impl std::error::Error for SweepError {}
