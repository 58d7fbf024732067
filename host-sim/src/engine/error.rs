//! Why a run stopped without a result: a setup or output failure, or a host-in-the-loop
//! failure (raised by the engine; converted upward into [`crate::Error`]).

use super::hil::HilError;
use crate::exit_code;
use std::fmt;

/// Why a run stopped without a result.
#[derive(Clone, Debug, PartialEq)]
pub enum RunError {
    /// Setup or output failure (exit code [`exit_code::IO`]).
    Failed(String),
    /// A host-in-the-loop failure (its own exit code).
    Hil(HilError),
}

impl RunError {
    /// The process exit code.
    pub fn exit_code(&self) -> u8 {
        match self {
            Self::Failed(_) => exit_code::IO,
            Self::Hil(e) => e.exit_code(),
        }
    }
}

impl fmt::Display for RunError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::Failed(s) => f.write_str(s),
            Self::Hil(e) => write!(f, "host-in-the-loop: {e}"),
        }
    }
}

impl std::error::Error for RunError {}

impl From<String> for RunError {
    fn from(s: String) -> Self {
        Self::Failed(s)
    }
}

impl From<HilError> for RunError {
    fn from(e: HilError) -> Self {
        Self::Hil(e)
    }
}
