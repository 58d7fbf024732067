//! One `ph-formation` agent on an STM32F405-class MCU (Cortex-M4F,
//! `thumbv7em-none-eabihf`), in `f32` throughout.
//!
//! * [`hal`]: the small traits the application is generic over (bearing
//!   sensor, velocity source, broadcast radio, force actuator, clock). A
//!   user ports the firmware to their robot by implementing these.
//! * [`app`]: the application: one agent's control loop over those traits
//!   ([`app::ControlLoop::tick`], [`app::run_agent`] at a fixed rate).
//! * [`boards`]: implementations of the traits: the paper's four robots
//!   simulated in the firmware ([`boards::demo`], binary `qemu-demo`) and a
//!   host-in-the-loop robot over USART1 ([`boards::uart`], binary
//!   `qemu-uart`); [`stand_in`]: trivial drivers (binary `firmware-example`,
//!   the template for a real board).
//! * [`keys`]: where a real board keeps the `auth` swarm key and its boot
//!   epoch, and the QEMU placeholders.
//! * [`paper`]: the paper's scenario (SPEC §9) as `f32` constants.
//! * [`workload`]: the measured control step (decode and receive the
//!   neighbours' frames, `Agent::step`, encode the own frames) for an agent in
//!   1, 2, 4 and 8 triangles; [`measure`]: the instruction-count markers read
//!   by the QEMU plugin in `tools/qemu-insn/` (binary `measure`).
//! * `stack` (MCU only): peak stack use from cortex-m-rt's stack painting.
//! * `rt` (MCU only): log transport selection, exit codes, panic and fault
//!   handlers.
//!
//! Log transport (cargo features, exactly one): `qemu` (default; defmt over
//! semihosting, panics and faults exit QEMU with a failure code) or `rtt`
//! (defmt over RTT for a real board with probe-rs; build with
//! `--no-default-features --features rtt`).
//!
//! On the host this library builds (everything but `Usart1`, `rt` and
//! `stack` is plain `core` code) but the binaries are stubs; see
//! `docs/firmware.md`.
#![no_std]

pub mod app;
pub mod boards;
pub mod hal;
pub mod keys;
pub mod measure;
pub mod paper;
pub mod stand_in;
pub mod workload;

#[cfg(target_os = "none")]
pub mod rt;
#[cfg(target_os = "none")]
pub mod stack;
