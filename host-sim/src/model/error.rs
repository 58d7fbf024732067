//! Why a model could not be turned into the agents' controller configurations (typed, so
//! that callers can tell the cases apart; the messages are the old texts).

use ph_formation_core::ConfigError;
use thiserror::Error;

/// Why [`super::Model`] could not configure or resolve an agent's controller.
#[derive(Clone, Debug, PartialEq, Error)]
pub enum ModelError {
    /// An agent index beyond the model's agents.
    #[error("no agent index {0}")]
    NoAgent(usize),
    /// The agent belongs to more triangles than the controller's capacity.
    #[error("agent {agent} belongs to more than {capacity} triangles (controller capacity)")]
    TooManyTriangles {
        /// The agent's name.
        agent: String,
        /// The capacity.
        capacity: usize,
    },
    /// An `f32` configuration (C export, emulated targets) holds fewer triangles.
    #[error(
        "agent {id} belongs to {triangles} triangles; an f32 agent of this build holds at most {capacity}"
    )]
    TooManyTrianglesF32 {
        /// The agent's wire id.
        id: u8,
        /// Its triangles.
        triangles: usize,
        /// The capacity.
        capacity: usize,
    },
    /// `comm_every` does not fit the core's `u16`.
    #[error("comm_every = {0} exceeds 65535")]
    CommEvery(usize),
    /// `ph_formation_core::Agent::new` refused the configuration.
    #[error("controller-core refused agent index {index}: {error:?}")]
    CoreRefused {
        /// The agent index.
        index: usize,
        /// The core's reason.
        error: ConfigError,
    },
    /// A core reported an estimate of a triangle the model does not give it.
    #[error("estimate of unknown triangle {0}")]
    UnknownTriangle(usize),
    /// A core reported an estimate of an angle its triangle does not have.
    #[error("estimate of unknown angle {0}")]
    UnknownAngle(usize),
    /// A core's estimate does not match the model's angle.
    #[error("estimate layout mismatch for agent index {owner}: core says apex {apex} far {far}")]
    LayoutMismatch {
        /// The agent index.
        owner: usize,
        /// The apex the core named.
        apex: u8,
        /// The far vertex the core named.
        far: u8,
    },
}
