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

pub mod cli;
pub mod continuous;
pub mod controller;
pub mod design;
pub mod diagnostics;
pub mod error;
pub mod graph;
pub mod hil;
pub mod model;
pub mod output;
pub mod plant;
pub mod plot;
pub mod radio;
pub mod scenario;
pub mod sensors;
pub mod sim;
pub mod strip;
pub mod validate;
