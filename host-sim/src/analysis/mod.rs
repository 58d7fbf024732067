//! Analysis of the true state, below the engine: what a run's state means. Diagnostics of
//! one instant (V of S13, errors, distances) and the failure monitor that decides when a
//! run has failed (the engine's time loop stops on it) and how it ended.
//!
//! It reads only the model and the states it is given, so the engine can consult it
//! every tick without depending on the reports above it (`docs/architecture.md`).

pub mod bands;
pub mod control;
mod min_distance;
mod monitor;
mod outcome;
pub mod shape_check;
mod snapshot;
pub mod steady;
mod verdict;

pub use min_distance::MinDistance;
pub use monitor::Monitor;
pub use outcome::{Event, Outcome};
pub use snapshot::{Diagnostics, Snapshot};
pub use verdict::{PoseReport, SteadyReport, Verdict};
