//! # host-sim
//!
//! N `controller-core` agents over simulated dynamics (S1 of `docs/spec.md`, fixed-step RK4) and simulated
//! radio links. Each agent is one [`ph_formation_core::Agent`] behind the
//! [`engine::AgentController`] trait: it sees only what its own sensors measure and the
//! frames its radio delivers, as real postcard bytes.
//!
//! ## The library
//!
//! [`load`] (a file or a built-in name) or [`load_toml`] gives a validated [`Model`];
//! [`Simulation`] runs it, in memory unless asked to write (`write_to`), and returns a
//! [`Run`]: the [`RunResult`] (outcome, reason, errors, extremes, counters), the
//! [`TimeSeries`] and `summary.json` as a value. `examples/paper.rs` shows it:
//! `cargo run -p ph-formation-sim --release --example paper`.
//!
//! ## The layers (`docs/architecture.md`), lowest first
//!
//! * [`model`]: the validated formation, resolved to agent indices and SI units.
//! * [`scenario`]: the TOML schema, built-ins, `--set`, validation, the strip generator.
//! * [`analysis`]: V (S13), errors, and the failure monitor the time loop stops on.
//! * [`engine`]: plant, sensors, radio, controllers (and [`engine::hil`], agents as
//!   firmware in QEMU), the sampled and continuous simulators, the driver.
//! * [`report`]: `timeseries.csv`, the in-memory series, `summary.json`, the table, plots.
//! * the API (re-exported here), [`sweep`] (Monte Carlo sweeps, a client of the API)
//!   and [`cli`], the command line.
//!
//! Imports point down only (checked by `tests/layers.rs`). Schemas: `docs/scenarios.md`
//! (input) and `docs/outputs.md` (output, exit codes: [`exit_code`]).

// `summary.json` is one large `serde_json::json!` literal.
#![recursion_limit = "256"]

pub use analysis::Outcome;
pub use api::{load, load_toml, Error, Progress, Run, Simulation, WriteOptions};
pub use engine::{RunError, RunResult};
pub use model::Model;
pub use report::TimeSeries;
pub use scenario::{ScenarioErrors, BUILTINS};

pub mod analysis;
mod api;
pub mod cli;
pub mod design;
pub mod engine;
pub mod exit_code;
pub mod model;
pub mod report;
pub mod scenario;
pub mod sweep;
