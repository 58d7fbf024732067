//! Host-in-the-loop failures: when they happened and what went wrong, each kind with its
//! exit code (`docs/outputs.md`).

use super::firmware::{FIRMWARE_BUILD, FIRMWARE_ENV};
use super::qemu;
use crate::exit_code;
use std::fmt;
use std::path::PathBuf;

/// When a failure happened.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum When {
    /// Starting the target or sending its configuration.
    Configure,
    /// During control tick `tick` (0-based) at simulated time `time`.
    Tick {
        /// Tick number of this agent (0 at `t = 0`).
        tick: u64,
        /// Simulated time (s).
        time: f64,
    },
    /// At the end of the run (`Finish`).
    Finish {
        /// Ticks completed.
        ticks: u64,
        /// Simulated time of the last tick (s).
        time: f64,
    },
}

impl fmt::Display for When {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::Configure => write!(f, "during start-up"),
            Self::Tick { tick, time } => write!(f, "at tick {tick} (t = {time:.3} s)"),
            Self::Finish { ticks, time } => {
                write!(
                    f,
                    "at the end of the run (after {ticks} ticks, t = {time:.3} s)"
                )
            }
        }
    }
}

/// A host-in-the-loop failure. Each kind has its exit code ([`HilError::exit_code`]).
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum HilError {
    /// A bad `--hil` request (unknown agent id, continuous mode, bad timeout).
    #[error("{0}")]
    Usage(String),
    /// The QEMU binary is not there.
    #[error("`{program}` not found (not on PATH, nor set by ${env}): host-in-the-loop runs need QEMU; install it with `sudo bash scripts/firmware-deps.sh` (Debian: `apt-get install qemu-system-arm`) or set ${env} to the binary", env = qemu::QEMU_ENV)]
    QemuMissing {
        /// The program looked for.
        program: String,
    },
    /// The firmware ELF is not there.
    #[error("firmware ELF {} not found: build it with `{build}` (or pass --firmware PATH, or set ${env})", path.display(), build = FIRMWARE_BUILD, env = FIRMWARE_ENV)]
    FirmwareMissing {
        /// The path looked for.
        path: PathBuf,
    },
    /// The firmware file is not an ELF.
    #[error("firmware {} is not an ELF file: build the firmware with `{build}` (or pass --firmware PATH, or set ${env})", path.display(), build = FIRMWARE_BUILD, env = FIRMWARE_ENV)]
    FirmwareInvalid {
        /// The file.
        path: PathBuf,
    },
    /// QEMU could not be started or did not connect.
    #[error("agent {agent}: cannot start the emulated target: {reason}")]
    Start {
        /// The agent's id as the scenario writes it.
        agent: String,
        /// Why.
        reason: String,
    },
    /// The target closed the link or QEMU exited during the run.
    #[error("agent {agent}: the emulated target stopped {when}: {detail}")]
    Closed {
        /// The agent's id as the scenario writes it.
        agent: String,
        /// When.
        when: When,
        /// QEMU's exit status and messages.
        detail: String,
    },
    /// No answer before the deadline.
    #[error("agent {agent}: the firmware did not answer within {timeout_s} s {when}: {detail}")]
    Timeout {
        /// The agent's id as the scenario writes it.
        agent: String,
        /// When.
        when: When,
        /// The timeout (s).
        timeout_s: f64,
        /// What was awaited.
        detail: String,
        /// QEMU's pid.
        pid: Option<u32>,
    },
    /// A frame that does not decode, or a message out of protocol.
    #[error("agent {agent}: corrupt link frame {when}: received {what}")]
    Corrupt {
        /// The agent's id as the scenario writes it.
        agent: String,
        /// When.
        when: When,
        /// What was received.
        what: String,
    },
    /// The agent's configuration does not fit the firmware, or the firmware refused it.
    #[error("agent {agent}: configuration refused: {reason}")]
    Refused {
        /// The agent's id as the scenario writes it.
        agent: String,
        /// Why.
        reason: String,
    },
}

impl HilError {
    /// The process exit code of this failure (`docs/outputs.md`).
    pub fn exit_code(&self) -> u8 {
        match self {
            Self::Usage(_) => exit_code::USAGE,
            Self::QemuMissing { .. } => exit_code::HIL_NO_QEMU,
            Self::FirmwareMissing { .. } | Self::FirmwareInvalid { .. } => {
                exit_code::HIL_NO_FIRMWARE
            }
            Self::Start { .. } | Self::Closed { .. } => exit_code::HIL_TARGET_FAILED,
            Self::Timeout { .. } => exit_code::HIL_TIMEOUT,
            Self::Corrupt { .. } => exit_code::HIL_CORRUPT,
            Self::Refused { .. } => exit_code::HIL_REFUSED,
        }
    }
}
