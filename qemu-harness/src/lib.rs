//! # qemu-harness
//!
//! The host side of running `firmware-example` under QEMU, in one place: `cargo xtask`
//! (the on-target checks) and the QEMU tests of the `tests` crate use it.
//!
//! * [`qemu`]: the one QEMU launcher (`qemu-system-arm -machine netduinoplus2`,
//!   semihosting, USART1 over TCP, the instruction-count plugin, CPU pinning, a time
//!   limit, no QEMU left behind).
//! * [`firmware`]: the workspace, the target directory and the release firmware ELFs.
//! * [`defmt`]: decoding the firmware's defmt log with `defmt-print`.
//! * `link` (feature `link`): the host end of the UART link session
//!   (`ph_formation_core::link` messages, postcard in COBS frames).
//!
//! Host only (std). Nothing here starts QEMU by itself: the QEMU tests are `#[ignore]`d
//! and `cargo xtask firmware-check` runs them.

pub mod defmt;
pub mod firmware;
#[cfg(feature = "link")]
pub mod link;
mod os;
pub mod qemu;

pub use qemu::{Exit, Qemu, QemuProcess, Serial};
