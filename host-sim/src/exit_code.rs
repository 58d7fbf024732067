//! Exit codes of the `host-sim` binary (the table of `docs/outputs.md`), shared by every
//! layer: the base of the layer order, importing nothing from the crate. Each error type
//! maps itself to one of these where it is defined (an invalid scenario's 20–28 by kind:
//! [`crate::scenario::ErrorKind::exit_code`]).

/// The run converged (or `validate`, `list`, `plot` succeeded).
pub const CONVERGED: u8 = 0;
/// Output could not be written, or another runtime error.
pub const IO: u8 = 1;
/// Bad command line (clap's usage errors).
pub const USAGE: u8 = 2;
/// `host-sim sweep` was stopped by Ctrl-C (the finished runs were written).
pub const INTERRUPTED: u8 = 130;
/// The run ended without converging.
pub const NOT_CONVERGED: u8 = 10;
/// Two agents came closer than the collision distance.
pub const COLLISION: u8 = 11;
/// An estimate was held at `r_min`.
pub const ESTIMATE_COLLAPSE: u8 = 12;
/// The state became non-finite, too fast, or `V` grew without bound.
pub const DIVERGED: u8 = 13;
/// Every angle is within tolerance but the formation is not the target shape (a
/// triangle folded across an edge, or the fitted shape off by more than the tolerance).
pub const WRONG_SHAPE: u8 = 14;
/// More than `criteria.safe_share` of the outputs in the steady window were the safe
/// output: the agents were not in control.
pub const NOT_IN_CONTROL: u8 = 15;
/// `host-sim design` refused its input (points, options or template), naming why.
pub const DESIGN_REFUSED: u8 = 29;
/// Host-in-the-loop: `qemu-system-arm` not found.
pub const HIL_NO_QEMU: u8 = 30;
/// Host-in-the-loop: the firmware ELF not found.
pub const HIL_NO_FIRMWARE: u8 = 31;
/// Host-in-the-loop: QEMU did not start or connect, exited, or closed the link.
pub const HIL_TARGET_FAILED: u8 = 32;
/// Host-in-the-loop: the firmware did not answer within the timeout.
pub const HIL_TIMEOUT: u8 = 33;
/// Host-in-the-loop: a corrupt link frame or a message out of protocol.
pub const HIL_CORRUPT: u8 = 34;
/// Host-in-the-loop: the agent's configuration does not fit the firmware, or the
/// firmware refused it.
pub const HIL_REFUSED: u8 = 35;
