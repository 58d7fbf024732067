//! Host-in-the-loop: some agents' controllers run as firmware on an emulated STM32F405
//! (QEMU `netduinoplus2`, the `qemu-uart` binary of `firmware-example`) while host-sim
//! simulates the plant, the sensors, the radio and the other agents (`docs/hil.md`).
//!
//! * One QEMU per emulated agent; its USART1 is a TCP connection on loopback carrying the
//!   lock-step protocol of [`controller_core::link`] (postcard messages, one per COBS
//!   frame): `Configure` → `Ready` once, then per tick `Radio`* + `Step` →
//!   `Radio`* [+ `Estimates`] + `Output`, and `Finish` → `Finished` at the end.
//! * Lock-step: the simulator integrates past a control instant only after every
//!   emulated agent has answered it; all emulated agents are sent their tick first and
//!   answered second, so they compute in parallel. A run is deterministic: the firmware
//!   is a function of the bytes it receives.
//! * Every failure is a [`HilError`] with its own exit code (`docs/outputs.md`); no
//!   failure hangs (every read has a deadline) and no QEMU outlives the run.

pub mod controller;
pub mod fake;
pub mod link;
pub mod qemu;

use crate::analysis::diagnostics::resolve_estimates;
use crate::engine::controller::{AgentController, LocalCore};
use crate::engine::sampled::{drive, RunResult, SampledSim};
use crate::model::Model;
use crate::report::csv::Recorder;
use crate::scenario::error::{exit_code, RunError};
use crate::scenario::Mode;
use controller::{EstimateSlot, HilController, TargetHandle};
use controller_core::{
    Agent, AgentConfig, AngleConfig, LeaderConfig, Limits, Schedule, ScheduleStep, TriangleConfig,
};
use fake::FakeBehaviour;
use link::{Link, TARGET_MT};
use qemu::QemuProcess;
use std::fmt;
use std::net::TcpListener;
use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

/// Neighbour capacity of the firmware's agent (`Agent<f32, 4, 8>`).
pub const TARGET_NB: usize = 8;
/// Environment variable overriding the default firmware ELF.
pub const FIRMWARE_ENV: &str = "HOST_SIM_FIRMWARE";
/// The firmware ELF, relative to the cargo target directory.
pub const FIRMWARE_REL: &str = "thumbv7em-none-eabihf/release/qemu-uart";
/// The command that builds the firmware ELF.
pub const FIRMWARE_BUILD: &str =
    "cargo build -p firmware-example --target thumbv7em-none-eabihf --release --bin qemu-uart";
/// Default per-reply timeout (s).
pub const DEFAULT_TIMEOUT_S: f64 = 10.0;
/// Time QEMU has to start and connect, at least (s).
pub const STARTUP_TIMEOUT_S: f64 = 10.0;

/// The default firmware ELF: `$HOST_SIM_FIRMWARE`, else
/// `<target dir>/thumbv7em-none-eabihf/release/qemu-uart`, where the target directory is
/// `$CARGO_TARGET_DIR` (relative paths from the workspace root) or `<workspace>/target`.
pub fn default_firmware() -> PathBuf {
    if let Some(p) = std::env::var_os(FIRMWARE_ENV).filter(|p| !p.is_empty()) {
        return PathBuf::from(p);
    }
    let manifest = Path::new(env!("CARGO_MANIFEST_DIR"));
    let workspace = manifest.parent().unwrap_or(manifest);
    let target = std::env::var_os("CARGO_TARGET_DIR")
        .filter(|p| !p.is_empty())
        .map_or_else(|| workspace.join("target"), |t| workspace.join(t));
    target.join(FIRMWARE_REL)
}

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
        /// The agent's id.
        agent: u8,
        /// Why.
        reason: String,
    },
    /// The target closed the link or QEMU exited during the run.
    #[error("agent {agent}: the emulated target stopped {when}: {detail}")]
    Closed {
        /// The agent's id.
        agent: u8,
        /// When.
        when: When,
        /// QEMU's exit status and messages.
        detail: String,
    },
    /// No answer before the deadline.
    #[error("agent {agent}: the firmware did not answer within {timeout_s} s {when}: {detail}")]
    Timeout {
        /// The agent's id.
        agent: u8,
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
        /// The agent's id.
        agent: u8,
        /// When.
        when: When,
        /// What was received.
        what: String,
    },
    /// The agent's configuration does not fit the firmware, or the firmware refused it.
    #[error("agent {agent}: configuration refused: {reason}")]
    Refused {
        /// The agent's id.
        agent: u8,
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

/// One emulated agent's link figures (`summary.json` → `hil`).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct LinkStats {
    /// The agent's id.
    pub agent: u8,
    /// QEMU's pid (none for the test stand-in).
    pub pid: Option<u32>,
    /// Link messages (COBS frames) sent to the target.
    pub frames_to_target: u64,
    /// Link messages received from the target.
    pub frames_from_target: u64,
    /// Bytes sent on the serial line.
    pub bytes_to_target: u64,
    /// Bytes received from the serial line.
    pub bytes_from_target: u64,
    /// Radio frames delivered to the target (`HostMsg::Radio`).
    pub radio_to_target: u64,
    /// Radio frames the target broadcast (`TargetMsg::Radio`).
    pub radio_from_target: u64,
    /// Control ticks completed.
    pub ticks: u64,
    /// Wall-clock seconds between sending a tick and receiving its `Output`, summed.
    pub wall_s: f64,
    /// Wall-clock seconds from starting QEMU to `Ready`.
    pub startup_s: f64,
    /// Whether the estimates came from `TargetMsg::Estimates` (else from the agent's own
    /// broadcast frames).
    pub estimates_from_target: bool,
    /// Estimates the agent owns.
    pub estimates: usize,
    /// Frames the target's agent accepted over the run (`Finished`).
    pub target_accepted: Option<u32>,
    /// Frames the target's agent rejected over the run (`Finished`).
    pub target_rejected: Option<u32>,
    /// QEMU's exit code after `Finish` (0: the firmware exited cleanly; none: killed).
    pub exit_code: Option<i32>,
}

impl LinkStats {
    /// Where the agent's estimates in the outputs come from: `"estimates_message"`
    /// (`TargetMsg::Estimates`), `"radio_frames"` (the angle items of its own broadcast
    /// frames) or `"none"` (it owns no estimate).
    pub fn estimates_source(&self) -> &'static str {
        match (self.estimates, self.estimates_from_target) {
            (0, _) => "none",
            (_, true) => "estimates_message",
            (_, false) => "radio_frames",
        }
    }
}

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
    /// The host-side stand-in (tests).
    Fake(FakeBehaviour),
}

/// What a host-in-the-loop run needs.
#[derive(Clone, Debug, PartialEq)]
pub struct HilOptions {
    /// Ids of the agents to emulate (each once).
    pub agents: Vec<u8>,
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
        agents: Vec<u8>,
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
pub fn agent_indices(model: &Model, ids: &[u8]) -> Result<Vec<usize>, HilError> {
    if model.mode != Mode::Sampled {
        return Err(HilError::Usage(format!(
            "--hil needs mode = \"sampled\" (scenario {} is {})",
            model.name,
            model.mode.as_str()
        )));
    }
    let known: Vec<String> = model.agents.iter().map(|a| a.id.to_string()).collect();
    let mut idx = Vec::new();
    for &id in ids {
        let i = model
            .agents
            .iter()
            .position(|a| a.id == id)
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

fn schedule(s: &Schedule<f64>) -> Schedule<f32> {
    let mut out = Schedule::default();
    for st in &s.steps {
        // Same capacity on both sides: never full.
        let _ = out.steps.push(ScheduleStep {
            from: st.from as f32,
            value: st.value.map(|x| x as f32),
        });
    }
    out
}

/// Agent `i`'s configuration for the firmware: the host's `AgentConfig<f64, 8>` (built as
/// for every simulated agent) rounded to `f32`, checked against the firmware's capacity
/// (`Agent<f32, 4, 8>`).
pub fn target_config(model: &Model, i: usize) -> Result<AgentConfig<f32, TARGET_MT>, HilError> {
    let id = model.agents.get(i).map_or(0, |a| a.id);
    let refused = |reason: String| HilError::Refused { agent: id, reason };
    let c = model.agent_config(i).map_err(refused)?;
    let f = |x: f64| x as f32;
    let mut t = AgentConfig::<f32, TARGET_MT>::new(c.id);
    for tri in &c.triangles {
        let ang = |a: &AngleConfig<f64>| AngleConfig {
            apex: a.apex,
            cos_desired: f(a.cos_desired),
            stiffness: f(a.stiffness),
            damping: f(a.damping),
            estimator_gain: f(a.estimator_gain),
        };
        t.triangles
            .push(TriangleConfig {
                vertices: tri.vertices,
                angles: [ang(&tri.angles[0]), ang(&tri.angles[1])],
            })
            .map_err(|_| {
                refused(format!(
                    "agent {id} belongs to {} triangles; the firmware holds at most {TARGET_MT}",
                    c.triangles.len()
                ))
            })?;
    }
    t.estimator = c.estimator;
    t.initial_estimate = f(c.initial_estimate);
    t.min_estimate = f(c.min_estimate);
    t.friction = c.friction.map(f);
    t.velocity_damping = c.velocity_damping.map(f);
    t.velocity_reference = schedule(&c.velocity_reference);
    t.leader = c.leader.as_ref().map(|l| LeaderConfig {
        role: l.role,
        partner: l.partner,
        stiffness: f(l.stiffness),
        damping: l.damping.map(f),
        displacement: schedule(&l.displacement),
    });
    t.limits = Limits {
        max_force: f(c.limits.max_force),
        neighbour_timeout: f(c.limits.neighbour_timeout),
        safe_damping: f(c.limits.safe_damping),
        bearing_tolerance: f(c.limits.bearing_tolerance),
        margin_cos: f(c.limits.margin_cos),
    };
    Agent::<f32, TARGET_MT, TARGET_NB>::new(t.clone()).map_err(|e| {
        refused(format!(
            "{e} (the firmware's agent holds {TARGET_MT} triangles and {TARGET_NB} neighbours)"
        ))
    })?;
    Ok(t)
}

/// Starts one target connected to a fresh loopback listener.
fn launch(
    agent: u8,
    launcher: &Launcher,
    qemu_path: Option<&Path>,
    startup: Duration,
    cpu: Option<usize>,
) -> Result<(Link, TargetHandle, Instant, Instant), HilError> {
    let start_err = |reason: String| HilError::Start { agent, reason };
    let listener = TcpListener::bind(("127.0.0.1", 0))
        .map_err(|e| start_err(format!("cannot listen on loopback: {e}")))?;
    let port = listener
        .local_addr()
        .map_err(|e| start_err(format!("cannot read the listening port: {e}")))?
        .port();
    let started = Instant::now();
    let deadline = started + startup;
    let (stream, target) = match launcher {
        Launcher::Qemu {
            firmware, log_dir, ..
        } => {
            let qemu = qemu_path.ok_or_else(|| start_err("no QEMU binary".to_owned()))?;
            let mut p =
                QemuProcess::spawn(qemu, firmware, port, agent, log_dir, cpu).map_err(|e| {
                    start_err(format!(
                        "cannot run {} (logs in {}): {e}",
                        qemu.display(),
                        log_dir.display()
                    ))
                })?;
            let s = p.accept(&listener, deadline).map_err(|e| {
                start_err(format!(
                    "{e} (QEMU {}, port {port}, {} s; messages in {})",
                    qemu.display(),
                    startup.as_secs_f64(),
                    p.stderr_log.display()
                ))
            })?;
            (s, TargetHandle::Qemu(p))
        }
        Launcher::Fake(b) => {
            let h = fake::spawn(port, *b);
            let s = qemu::accept_until(&listener, deadline, || Ok(()))
                .map_err(|e| start_err(format!("the fake target did not connect: {e}")))?;
            (s, TargetHandle::Fake(Some(h)))
        }
    };
    let link = Link::new(stream)
        .map_err(|e| start_err(format!("cannot configure the connection: {e}")))?;
    Ok((link, target, started, deadline))
}

/// Estimate layout and frame slots of agent `i` (from the host's own core agent of the
/// same configuration, so the order is the one the target uses).
fn estimate_slots(
    model: &Model,
    i: usize,
) -> Result<(Vec<controller_core::OwnedEstimate<f64>>, Vec<EstimateSlot>), String> {
    let core = model.core_agent(i)?;
    let layout: Vec<_> = core.owned_estimates().collect();
    let infos = resolve_estimates(model, i, &layout)?;
    let slots = layout
        .iter()
        .zip(&infos)
        .map(|(e, info)| EstimateSlot {
            triangle: e.triangle,
            angle: e.angle,
            edge: e.edge,
            far: model.agents[info.far].id,
            other: model.agents[info.other].id,
        })
        .collect();
    Ok((layout, slots))
}

/// Builds the controllers of a host-in-the-loop run: the chosen agents on their targets
/// (started, configured, `Ready`), the others in process. Every target started so far is
/// stopped if one fails.
pub fn controllers(
    model: &Model,
    opts: &HilOptions,
) -> Result<Vec<Box<dyn AgentController>>, HilError> {
    let indices = agent_indices(model, &opts.agents)?;
    let configs = indices
        .iter()
        .map(|&i| target_config(model, i))
        .collect::<Result<Vec<_>, _>>()?;
    let qemu_path = match &opts.launcher {
        Launcher::Qemu {
            program, firmware, ..
        } => Some(preflight(program, firmware)?),
        Launcher::Fake(_) => None,
    };
    let startup = opts.timeout.max(Duration::from_secs_f64(STARTUP_TIMEOUT_S));
    // Start every target first (they boot in parallel), then configure each.
    let cpus = if opts.pin {
        qemu::allowed_cpus()
    } else {
        Vec::new()
    };
    let mut launched = Vec::with_capacity(indices.len());
    for (k, &i) in indices.iter().enumerate() {
        let id = model.agents[i].id;
        let cpu = match cpus.len() {
            0 | 1 => None,
            n => cpus.get(k % n).copied(),
        };
        launched.push(launch(
            id,
            &opts.launcher,
            qemu_path.as_deref(),
            startup,
            cpu,
        )?);
    }
    let mut hil: Vec<Option<HilController>> = Vec::with_capacity(indices.len());
    for ((&i, config), (link, target, started, startup)) in
        indices.iter().zip(&configs).zip(launched)
    {
        let (layout, slots) = estimate_slots(model, i).map_err(|reason| HilError::Refused {
            agent: config.id,
            reason,
        })?;
        hil.push(Some(HilController::configure(
            config,
            link,
            target,
            opts.timeout,
            startup,
            layout,
            slots,
            model.initial_estimate,
            started,
        )?));
    }
    let mut out: Vec<Box<dyn AgentController>> = Vec::with_capacity(model.n());
    for i in 0..model.n() {
        match indices.iter().position(|&k| k == i) {
            Some(k) => match hil.get_mut(k).and_then(Option::take) {
                Some(c) => out.push(Box::new(c)),
                None => return Err(HilError::Usage(format!("agent index {i} twice"))),
            },
            None => out.push(Box::new(LocalCore::new(model.core_agent(i).map_err(
                |reason| HilError::Refused {
                    agent: model.agents[i].id,
                    reason,
                },
            )?))),
        }
    }
    Ok(out)
}

/// Runs `model` with the agents of `opts` on emulated targets (sampled mode only):
/// starts them, runs lock-step, sends `Finish`, stops them, and returns the result with
/// the per-agent link figures in [`RunResult::hil`].
pub fn run(
    model: &Model,
    opts: &HilOptions,
    recorder: &mut dyn Recorder,
    progress: &mut dyn FnMut(f64),
) -> Result<RunResult, RunError> {
    let ctl = controllers(model, opts)?;
    let mut engine = SampledSim::with_controllers(model, ctl).map_err(RunError::Failed)?;
    let mut result = drive(model, &mut engine, recorder, progress, Vec::new())?;
    engine.finish_controllers()?;
    result.hil = engine.link_stats();
    Ok(result)
}
