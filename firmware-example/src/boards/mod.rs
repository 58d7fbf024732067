//! Implementations of the [`hal`](crate::hal) traits.
//!
//! * [`demo`]: the paper's four robots simulated in `f32` (plant, bearing
//!   sensors, in-memory broadcast radio) for the `qemu-demo` binary.
//! * [`uart`]: one robot whose sensors and radio are a host at the
//!   other end of USART1, speaking `ph_formation_core::link` (the `qemu-uart`
//!   binary, host-in-the-loop).
//! * [`crate::stand_in`]: trivial drivers (the `firmware-example` binary).

pub mod demo;
pub mod uart;
