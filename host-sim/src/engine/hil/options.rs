//! What a host-in-the-loop run needs (agents, launcher, timeout, pinning) and the checks
//! made before anything starts: agent ids against the scenario, the firmware ELF, QEMU.

use super::error::HilError;
#[cfg(feature = "fake-target")]
use super::fake::FakeBehaviour;
use super::firmware::default_firmware;
use super::qemu;
use crate::model::{Mode, Model};
use std::path::{Path, PathBuf};
use std::time::Duration;

/// Neighbour capacity of the firmware's agent (`Agent<f32, 4, 8>`).
pub const TARGET_NB: usize = 8;
/// Default per-reply timeout (s).
pub const DEFAULT_TIMEOUT_S: f64 = 10.0;
/// Time QEMU has to start and connect, at least (s).
pub const STARTUP_TIMEOUT_S: f64 = 10.0;

/// How the emulated targets are started.
#[derive(Clone, Debug, PartialEq)]
pub enum Launcher {
    /// `qemu-system-arm` with the firmware ELF.
    Qemu {
        /// The QEMU program (name on `PATH` or path).
        program: String,
        /// The firmware ELF.
        firmware: PathBuf,
        /// Where `qemu-agent-<id>.log` go.
        log_dir: PathBuf,
    },
    /// The host-side stand-in (host-sim's tests, feature `fake-target`; not public API).
    #[cfg(feature = "fake-target")]
    #[doc(hidden)]
    Fake(FakeBehaviour),
}

/// What a host-in-the-loop run needs.
#[derive(Clone, Debug, PartialEq)]
pub struct HilOptions {
    /// The user's ids of the agents to emulate (as written in the scenario: an integer or a
    /// short name; each once).
    pub agents: Vec<String>,
    /// How to start them.
    pub launcher: Launcher,
    /// Per-reply timeout.
    pub timeout: Duration,
    /// Pin each QEMU to one CPU, round robin over the CPUs this process may use (Linux;
    /// see [`qemu::allowed_cpus`]).
    pub pin: bool,
}

impl HilOptions {
    /// Emulates `agents` in QEMU with `firmware` (`None`: [`default_firmware`]), logs
    /// into `log_dir`, with a per-reply `timeout_s`.
    pub fn qemu(
        agents: Vec<String>,
        firmware: Option<PathBuf>,
        log_dir: &Path,
        timeout_s: f64,
    ) -> Result<Self, HilError> {
        Ok(Self {
            agents,
            launcher: Launcher::Qemu {
                program: qemu::qemu_program(),
                firmware: firmware.unwrap_or_else(default_firmware),
                log_dir: log_dir.to_owned(),
            },
            timeout: timeout(timeout_s)?,
            pin: true,
        })
    }
}

/// A validated timeout.
pub fn timeout(seconds: f64) -> Result<Duration, HilError> {
    if seconds.is_finite() && seconds > 0.0 && seconds <= 86_400.0 {
        Ok(Duration::from_secs_f64(seconds))
    } else {
        Err(HilError::Usage(format!(
            "--hil-timeout {seconds}: must be a number of seconds in (0, 86400]"
        )))
    }
}

/// Checks the requested agents against the scenario; returns their indices (in agent
/// order, each once).
pub fn agent_indices(model: &Model, ids: &[String]) -> Result<Vec<usize>, HilError> {
    if model.mode != Mode::Sampled {
        return Err(HilError::Usage(format!(
            "--hil needs mode = \"sampled\" (scenario {} is {})",
            model.name,
            model.mode.as_str()
        )));
    }
    let known: Vec<&str> = model.agents.iter().map(|a| a.name.as_str()).collect();
    let mut idx = Vec::new();
    for id in ids {
        let i = model
            .agents
            .iter()
            .position(|a| a.name == *id)
            .ok_or_else(|| {
                HilError::Usage(format!(
                    "--hil {id}: scenario {} has no agent {id} (its agents: {})",
                    model.name,
                    known.join(", ")
                ))
            })?;
        if !idx.contains(&i) {
            idx.push(i);
        }
    }
    idx.sort_unstable();
    Ok(idx)
}

/// Checks that the firmware ELF exists (and is an ELF file) and that the QEMU binary
/// exists; returns QEMU's path.
pub fn preflight(program: &str, firmware: &Path) -> Result<PathBuf, HilError> {
    if !firmware.is_file() {
        return Err(HilError::FirmwareMissing {
            path: firmware.to_owned(),
        });
    }
    let mut magic = [0u8; 4];
    let is_elf = std::fs::File::open(firmware)
        .and_then(|mut f| std::io::Read::read_exact(&mut f, &mut magic))
        .is_ok()
        && magic == *b"\x7fELF";
    if !is_elf {
        return Err(HilError::FirmwareInvalid {
            path: firmware.to_owned(),
        });
    }
    qemu::find_program(program).ok_or_else(|| HilError::QemuMissing {
        program: program.to_owned(),
    })
}
