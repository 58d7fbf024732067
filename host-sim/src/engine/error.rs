//! Why a run stopped without a result: a setup failure, or a host-in-the-loop failure
//! (raised by the engine; converted upward into [`crate::Error`]).

use super::hil::HilError;
use crate::exit_code;
use crate::model::ModelError;
use std::fmt;
use thiserror::Error;

/// Why a simulator could not be built for a model.
#[derive(Clone, Debug, PartialEq, Error)]
pub enum SetupError {
    /// The model's agents could not be configured.
    #[error(transparent)]
    Model(#[from] ModelError),
    /// Not one controller per agent.
    #[error("{controllers} controllers for {agents} agents")]
    ControllerCount {
        /// Controllers given.
        controllers: usize,
        /// Agents of the model.
        agents: usize,
    },
    /// A controller's wire id is not its agent's.
    #[error("controller {index} has id {id}, expected {expected}")]
    ControllerId {
        /// The agent index.
        index: usize,
        /// The controller's id.
        id: u8,
        /// The agent's id.
        expected: u8,
    },
    /// An agent has more triangle neighbours than a controller holds (one bearing each).
    #[error("an agent has {degree} triangle neighbours, more than a controller holds ({max})")]
    TooManyNeighbours {
        /// The largest number of triangle neighbours of an agent.
        degree: usize,
        /// `ph_formation_core::MAX_NEIGHBOURS`.
        max: usize,
    },
    /// An agent's virtual mass (`ph_formation_core::actuate`) refused its plant's figures.
    #[error("agent {agent}: the vehicle's virtual mass refused its figures: {error:?}")]
    Vehicle {
        /// The agent index.
        agent: usize,
        /// What the core refused.
        error: ph_formation_core::actuate::ActuateError,
    },
}

/// Why a run stopped without a result.
#[derive(Clone, Debug, PartialEq)]
pub enum RunError {
    /// Setup failure (exit code [`exit_code::IO`]).
    Setup(SetupError),
    /// The recorder could not write a row (exit code [`exit_code::IO`]): the I/O error's
    /// kind and message (`io::Error` is neither `Clone` nor `PartialEq`).
    Record {
        /// The error's kind.
        kind: std::io::ErrorKind,
        /// Its message.
        message: String,
    },
    /// A host-in-the-loop failure (its own exit code).
    Hil(HilError),
}

impl RunError {
    /// The process exit code.
    pub fn exit_code(&self) -> u8 {
        match self {
            Self::Setup(_) | Self::Record { .. } => exit_code::IO,
            Self::Hil(e) => e.exit_code(),
        }
    }
}

impl fmt::Display for RunError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::Setup(e) => write!(f, "{e}"),
            Self::Record { message, .. } => write!(f, "cannot write the time series: {message}"),
            Self::Hil(e) => write!(f, "host-in-the-loop: {e}"),
        }
    }
}

impl std::error::Error for RunError {}

impl From<std::io::Error> for RunError {
    fn from(e: std::io::Error) -> Self {
        Self::Record {
            kind: e.kind(),
            message: e.to_string(),
        }
    }
}

impl From<SetupError> for RunError {
    fn from(e: SetupError) -> Self {
        Self::Setup(e)
    }
}

impl From<ModelError> for RunError {
    fn from(e: ModelError) -> Self {
        Self::Setup(SetupError::Model(e))
    }
}

impl From<HilError> for RunError {
    fn from(e: HilError) -> Self {
        Self::Hil(e)
    }
}
