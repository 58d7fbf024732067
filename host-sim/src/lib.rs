//! # host-sim
//!
//! N `controller-core` agents over simulated dynamics (S1 of `docs/spec.md`, fixed-step RK4) and simulated
//! radio links. Each agent is one [`ph_formation_core::Agent`] behind the engine's
//! controller trait: it sees only what its own sensors measure and the frames its radio
//! delivers, as real postcard bytes.
//!
//! ## The library's API
//!
//! What a Rust program embedding the simulator uses, and all it should rely on:
//!
//! * **Loading a scenario**: [`load`] (a file or a built-in name, [`BUILTINS`]) or
//!   [`load_toml`] gives a validated [`Model`] ([`model`]: the scenario resolved to agent
//!   indices and SI units) or every problem found ([`ScenarioErrors`]).
//! * **Running it**: [`Simulation`] runs a model, in memory unless asked to write
//!   ([`Simulation::write_to`], [`WriteOptions`]), reporting to a [`Progress`], optionally
//!   with some agents as firmware in QEMU ([`hil`]).
//! * **Results**: a [`Run`]: the [`RunResult`] (the [`Outcome`], its reason, errors,
//!   extremes, counters: [`results`]), the [`TimeSeries`] and `summary.json` as a value;
//!   or an [`Error`] ([`errors`]), each with the exit code of `docs/outputs.md`
//!   ([`exit_code`]).
//! * **Designing formations**: [`design`], from a target shape to a scenario (`host-sim
//!   design`).
//! * **Sweeps**: [`sweep`], Monte Carlo sweeps over a base scenario (`host-sim sweep`), a
//!   client of the API above.
//!
//! `examples/paper.rs` shows it: `cargo run -p ph-formation-sim --release --example
//! paper`.
//!
//! The other modules (the scenario schema, the engine, the analysis, the reports, the
//! command line) are public only for this crate's binary, tests, examples and benchmarks;
//! they are hidden from the documentation and may change at any time.
//!
//! ## The layers (`docs/architecture.md`), lowest first
//!
//! * `model`: the validated formation, resolved to agent indices and SI units.
//! * `scenario`: the TOML schema, built-ins, `--set`, validation, the strip generator.
//! * `analysis`: V (S13), errors, and the failure monitor the time loop stops on.
//! * `engine`: plant, sensors, radio, controllers (and `engine::hil`, agents as
//!   firmware in QEMU), the sampled and continuous simulators, the driver.
//! * `report`: `timeseries.csv`, the in-memory series, `summary.json`, the table, plots.
//! * the API (re-exported here), `sweep` (Monte Carlo sweeps, a client of the API)
//!   and `cli`, the command line.
//!
//! Imports point down only (checked by `tests/layers.rs`). Schemas: `docs/scenarios.md`
//! (input) and `docs/outputs.md` (output, exit codes: [`exit_code`]).

// `summary.json` is one large `serde_json::json!` literal.
#![recursion_limit = "256"]
#![deny(missing_docs)]

pub use analysis::Outcome;
pub use api::{load, load_toml, Error, Progress, Run, Simulation, Thinning, WriteOptions};
pub use engine::{RunError, RunResult};
pub use model::Model;
pub use report::{SeriesBudget, TimeSeries};
pub use scenario::{ScenarioErrors, BUILTINS};

/// What a run found, besides [`RunResult`] and [`TimeSeries`]: the types of their fields.
pub mod results {
    pub use crate::analysis::{Event, PoseReport, SteadyReport};
    pub use crate::engine::attack::AttackCounts;
    pub use crate::engine::channel::ChannelStats;
    pub use crate::engine::hil::LinkStats;
    pub use crate::engine::{ControlStats, FaultReport, FrameCounts, FrameReasons};
    pub use crate::model::EstimateInfo;
    pub use crate::model::{FaultKind, FaultModel};
    pub use crate::report::PlotError;
    pub use ph_formation_core::policy::PolicyCounts;
}

/// Why a library call failed: the parts of [`Error`].
pub mod errors {
    pub use crate::engine::hil::{HilError, When};
    pub use crate::engine::SetupError;
    pub use crate::model::ModelError;
    pub use crate::scenario::{ErrorKind, ScenarioError};
}

/// Agents as firmware on emulated targets ([`Simulation::hil`], `docs/hil.md`).
pub mod hil {
    pub use crate::engine::hil::{default_firmware, HilOptions, Launcher, DEFAULT_TIMEOUT_S};
}

pub mod design;
pub mod exit_code;
pub mod model;
pub mod sweep;

mod api;

// Not API (see the crate documentation): public for the binary (`cli`) and for the
// integration tests in `tests/`, which drive the engine, the schema, the analysis and the
// reports directly; hidden from the documentation.
#[doc(hidden)]
pub mod analysis;
#[doc(hidden)]
pub mod cli;
#[doc(hidden)]
pub mod engine;
#[doc(hidden)]
pub mod report;
#[doc(hidden)]
pub mod scenario;
