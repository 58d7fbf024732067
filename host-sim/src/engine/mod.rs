//! The engine: everything that moves during a run. The plant (S1, RK4), each agent's
//! sensors, the radio between agents (per-link faults, and optionally one shared
//! medium: [`channel`]), the agents' controllers (in process, or as
//! firmware in QEMU: [`hil`]), the sampled and continuous simulators, and the driver's
//! time loop that advances them, consults [`crate::analysis`] and hands each logged
//! instant to a [`Recorder`].
//!
//! It reads the [`crate::model::Model`] only: nothing here knows the scenario file, the
//! reports or the command line (`docs/architecture.md`).

pub mod attack;
pub mod calibrate;
pub mod channel;
pub mod continuous;
pub mod controller;
mod driver;
mod error;
mod frame;
pub mod hil;
pub mod load;
pub mod plant;
pub mod policy;
pub mod radio;
mod record;
mod result;
pub mod sampled;
pub mod sensors;
mod simulator;
pub mod slot_order;
pub mod speed;
mod stats;
mod time_loop;
pub mod world;

pub use continuous::ContinuousSim;
pub use controller::{local_core, AgentController, LocalCore, LOCAL_CAPACITIES};
pub use driver::{drive, model_notes, run, view_note};
pub use error::{RunError, SetupError};
pub use record::{NullRecorder, Recorder, Row};
pub use result::RunResult;
pub use sampled::{direct_radio, SampledSim};
pub use simulator::Engine;
pub use speed::PARALLEL_MIN_AGENTS;
pub use stats::{ControlStats, FaultReport, FrameCounts, FrameReasons};
