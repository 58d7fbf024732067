//! Firmware infrastructure for `ph-formation` on STM32F405-class MCUs.
//!
//! The crate is the skeleton that a formation-control application runs on:
//!
//! * [`hal`]: the small traits an application is generic over (bearing
//!   sensor, velocity source, broadcast radio, force actuator, clock). A
//!   user ports the firmware to their robot by implementing these.
//! * [`workload`]: the control step that is measured on target, and the list
//!   of step configurations. Today it holds a stand-in f32 computation; the
//!   controller from `controller-core` replaces it there.
//! * [`measure`]: instruction-count markers (read by the QEMU plugin in
//!   `tools/qemu-insn/`) around a measured step.
//! * `stack` (MCU only): peak stack use from cortex-m-rt's stack painting.
//! * `rt` (MCU only): log transport selection, exit codes, panic and fault
//!   handlers.
//! * [`stand_in`]: trivial implementations of the [`hal`] traits for the demo
//!   binary and QEMU.
//!
//! Log transport (cargo features, exactly one): `qemu` (default; defmt over
//! semihosting, panics and faults exit QEMU with a failure code) or `rtt`
//! (defmt over RTT for a real board with probe-rs; build with
//! `--no-default-features --features rtt`).
//!
//! On the host this library builds (the traits and the workload are plain
//! `core` code) but the binaries are stubs; see `docs/firmware.md`.
#![no_std]

pub mod app;
pub mod boards;
pub mod hal;
pub mod measure;
pub mod paper;
pub mod stand_in;
pub mod workload;

#[cfg(target_os = "none")]
pub mod rt;
#[cfg(target_os = "none")]
pub mod stack;
