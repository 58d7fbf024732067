//! # host-sim
//!
//! N `controller-core` agents over simulated dynamics (S1, fixed-step RK4) and simulated
//! radio links. Each agent is one [`controller_core::Agent`] behind the
//! [`controller::AgentController`] trait: it sees only what its own sensors measure and
//! the frames its radio delivers, as real postcard bytes.
//!
//! * [`scenario`]: the TOML schema and the built-in scenarios (`paper`, `paper-printed`,
//!   `formation-only`); [`validate`] turns a file into a [`model::Model`].
//! * [`sim`]: the sampled simulator and the run driver; [`continuous`]: the
//!   continuous-time mode for checking S14.
//! * [`plant`], [`sensors`], [`radio`], [`controller`]: the pieces of one run.
//! * [`diagnostics`]: V (S13), errors, failure detection; [`output`]: `timeseries.csv`
//!   and `summary.json`; [`plot`]: the figures; [`cli`]: the command line.
//! * [`hil`]: host-in-the-loop, some agents' controllers as firmware in QEMU behind an
//!   emulated UART (`docs/hil.md`).
//!
//! Schemas: `docs/scenarios.md` (input) and `docs/outputs.md` (output, exit codes).

// `summary.json` is one large `serde_json::json!` literal.
#![recursion_limit = "256"]

pub use analysis::Outcome;
pub use api::{load, load_toml, Error, Progress, Run, Simulation};
pub use engine::{RunError, RunResult};
pub use model::Model;
pub use report::TimeSeries;
pub use scenario::{ScenarioErrors, BUILTINS};

pub mod analysis;
mod api;
pub mod cli;
pub mod engine;
pub mod exit_code;
pub mod model;
pub mod report;
pub mod scenario;
