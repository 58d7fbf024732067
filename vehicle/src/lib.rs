//! # ph-formation-vehicle
//!
//! Vehicle models for simulating ph-formation agents, in one place for every simulator
//! of the project: host-sim's `[plant]` and the tests that fly the Crazyflie app's C code
//! (through ph-formation-ffi's `sim-vehicle` feature, host and QEMU). The flight build of
//! the C API does not enable that feature and carries no vehicle model.
//!
//! * [`crazyflie`]: a Crazyflie 2.x flying its firmware's PID cascade in velocity mode
//!   (docs/world.md, "The Crazyflie's cascade").
//!
//! `no_std`, no heap, `f64`; vectors are `[x, y]` arrays in the world frame, so the
//! model depends on no linear-algebra crate.
#![no_std]
#![deny(missing_docs)]
#![deny(
    clippy::unwrap_used,
    clippy::expect_used,
    clippy::panic,
    clippy::indexing_slicing
)]
#![cfg_attr(
    test,
    allow(clippy::unwrap_used, clippy::indexing_slicing, clippy::panic)
)]

#[cfg(test)]
extern crate std;

pub mod crazyflie;
