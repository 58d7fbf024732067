//! # controller-core
//!
//! ONE agent's angle-based port-Hamiltonian formation controller (Li, Borja, van der
//! Schaft, Scherpen), its passive distance estimators and its wire frames, as it runs on
//! one microcontroller. The math is `docs/spec.md` (equations cited as `S<n>`).
//!
//! * `no_std`, no heap, fixed capacity: [`Agent<T, MT, NB>`] holds at most `MT` triangles
//!   and `NB` neighbours.
//! * Generic over the scalar ([`Real`]): `f32` on target (hardware FPU and `vsqrt`),
//!   `f64` on the host. No trigonometry in the control step.
//! * Nothing reachable from the public API panics; bad input gives a typed error
//!   ([`FrameError`], [`Fault`], [`ConfigError`]) or the documented safe output.
//!
//! Per control tick:
//! 1. [`Agent::receive`] every frame heard since the last tick;
//! 2. [`Agent::step`] with [`Measurements`] (bearings, optional rates, own velocity, `Δt`,
//!    the leader's partner offset) → [`StepOutput`] (force, status);
//! 3. [`Agent::frames`] → one frame of at most 60 bytes to broadcast (more for the apex
//!    of more angles than a frame holds, [`wire::Integrity::max_angles`]: 4 with every
//!    integrity mode; none on the ticks [`AgentConfig::comm_every`] skips).
//!
//! Cargo features (none by default): `defmt` (`defmt::Format` for the public types, for
//! firmware logging); `std` (host builds: binary16 conversions with F16C); `sim`, the
//! simulator's entry points (`Agent::sense`, `evaluate`, `output`, `set_estimate`,
//! `copy_estimates`, `receive_direct`, `frames_checked`, `receive_checked`), which a
//! firmware never enables (`docs/core.md`, "Feature `sim`").
#![no_std]
#![deny(
    clippy::unwrap_used,
    clippy::expect_used,
    clippy::panic,
    clippy::indexing_slicing,
    clippy::unreachable,
    clippy::todo,
    clippy::unimplemented
)]
#![cfg_attr(
    test,
    allow(clippy::unwrap_used, clippy::expect_used, clippy::indexing_slicing)
)]
#![deny(missing_docs)]

pub mod actuate;
pub mod agent;
pub mod config;
pub mod crc16;
pub mod energy;
pub mod geometry;
pub mod law;
pub mod link;
pub mod policy;
pub mod scalar;
pub mod stats;
pub mod tracker;
pub mod wire;

#[cfg(any(feature = "sim", test))]
pub use agent::Evaluation;
pub use agent::{
    Agent, BearingMeasurement, Fault, LawOutput, MeasurementError, Measurements, OwnedEstimate,
    Status, StepOutput,
};
pub use config::{
    AgentConfig, AgentId, AngleConfig, BearingFilter, ConfigError, EstimatorMode, Integrity,
    LeaderConfig, LeaderRole, Limits, Schedule, ScheduleStep, TrackerConfig, TriangleConfig,
    MAX_SCHEDULE_STEPS,
};
pub use scalar::Real;
pub use stats::FrameStats;
pub use wire::{FrameError, SwarmKey, MAX_FRAME_LEN};

/// Triangles per agent of the standard agent type ([`StandardAgent`]): what the host
/// simulator, the C ABI and the tests use, and what `host-sim validate` checks a scenario
/// against. (Firmware may choose smaller capacities for its RAM: see
/// `firmware-example`'s boards.)
pub const MAX_TRIANGLES: usize = 8;
/// Neighbours per agent of the standard agent type ([`StandardAgent`]).
pub const MAX_NEIGHBOURS: usize = 12;
/// The standard agent: [`MAX_TRIANGLES`] triangles, [`MAX_NEIGHBOURS`] neighbours.
pub type StandardAgent<T> = Agent<T, MAX_TRIANGLES, MAX_NEIGHBOURS>;
/// The configuration of a [`StandardAgent`].
pub type StandardConfig<T> = AgentConfig<T, MAX_TRIANGLES>;

/// A 2-D column vector (world frame).
pub type Vec2<T> = nalgebra::Vector2<T>;
