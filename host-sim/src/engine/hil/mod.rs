//! Host-in-the-loop: some agents' controllers run as firmware on an emulated STM32F405
//! (QEMU `netduinoplus2`, the `qemu-uart` binary of `firmware-example`) while host-sim
//! simulates the plant, the sensors, the radio and the other agents (`docs/hil.md`).
//!
//! * One QEMU per emulated agent; its USART1 is a TCP connection on loopback carrying the
//!   lock-step protocol of [`ph_formation_core::link`] (postcard messages, one per COBS
//!   frame): `Configure` → `Ready` once, then per tick `Radio`* + `Step` →
//!   `Radio`* [+ `Estimates`] + `Output`, and `Finish` → `Finished` at the end.
//! * Lock-step: the simulator integrates past a control instant only after every
//!   emulated agent has answered it; all emulated agents are sent their tick first and
//!   answered second, so they compute in parallel. A run is deterministic: the firmware
//!   is a function of the bytes it receives.
//! * Every failure is a [`HilError`] with its own exit code (`docs/outputs.md`); no
//!   failure hangs (every read has a deadline) and no QEMU outlives the run.

mod config;
pub mod controller;
mod error;
#[cfg(feature = "fake-target")]
#[doc(hidden)]
pub mod fake;
mod firmware;
mod options;
mod stats;

use link::Link;
/// The host end of the UART link (one implementation: `qemu-harness`'s).
pub use qemu_harness::link;
/// The QEMU launcher (one implementation: `qemu-harness`'s).
pub use qemu_harness::qemu;

pub use config::target_config;
pub use error::{HilError, When};
pub use firmware::{default_firmware, FIRMWARE_BUILD, FIRMWARE_ENV, FIRMWARE_REL};
pub use options::{
    agent_indices, preflight, timeout, HilOptions, Launcher, DEFAULT_TIMEOUT_S, STARTUP_TIMEOUT_S,
    TARGET_NB,
};
pub use stats::LinkStats;

use crate::engine::controller::{local_core, AgentController};
use crate::engine::{drive, Recorder, RunError, RunResult, SampledSim};
use crate::model::{resolve_estimates, Model, ModelError};
use controller::{EstimateSlot, HilController, TargetHandle};
use qemu_harness::{Qemu, Serial};
use std::net::TcpListener;
use std::path::Path;
use std::time::{Duration, Instant};

/// Starts one target connected to a fresh loopback listener.
fn launch(
    agent: &str,
    launcher: &Launcher,
    qemu_path: Option<&Path>,
    startup: Duration,
    cpu: Option<usize>,
) -> Result<(Link, TargetHandle, Instant, Instant), HilError> {
    let start_err = |reason: String| HilError::Start {
        agent: agent.to_owned(),
        reason,
    };
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
            let mut p = Qemu::new(firmware, log_dir.join(format!("qemu-agent-{agent}")))
                .program(qemu)
                .log_files(
                    log_dir.join(format!("qemu-agent-{agent}.log")),
                    log_dir.join(format!("qemu-agent-{agent}.stderr.log")),
                )
                .serial(Serial::TcpClient { port })
                .pin(cpu)
                .spawn()
                .map_err(|e| {
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
        #[cfg(feature = "fake-target")]
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

/// What the target of agent `i` orders as its own core does, read from the host's core
/// agent of the same configuration: the estimate layout, its frame slots and the
/// neighbour slots (wire ids).
type TargetOrder = (
    Vec<ph_formation_core::OwnedEstimate<f64>>,
    Vec<EstimateSlot>,
    Vec<u8>,
);

/// [`TargetOrder`] of agent `i`.
fn target_order(model: &Model, i: usize) -> Result<TargetOrder, ModelError> {
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
    Ok((layout, slots, core.neighbours().collect()))
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
        #[cfg(feature = "fake-target")]
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
        let cpu = match cpus.len() {
            0 | 1 => None,
            n => cpus.get(k % n).copied(),
        };
        launched.push(launch(
            &model.agents[i].name,
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
        let (layout, slots, order) = target_order(model, i).map_err(|e| HilError::Refused {
            agent: model.agents[i].name.clone(),
            reason: e.to_string(),
        })?;
        hil.push(Some(
            HilController::configure(
                config,
                link,
                target,
                opts.timeout,
                startup,
                layout,
                slots,
                model.initial_estimate,
                started,
                &model.agents[i].name,
            )?
            .with_neighbour_order(order),
        ));
    }
    let mut out: Vec<Box<dyn AgentController>> = Vec::with_capacity(model.n());
    for i in 0..model.n() {
        match indices.iter().position(|&k| k == i) {
            Some(k) => match hil.get_mut(k).and_then(Option::take) {
                Some(c) => out.push(Box::new(c)),
                None => return Err(HilError::Usage(format!("agent index {i} twice"))),
            },
            None => out.push(local_core(model, i).map_err(|e| HilError::Refused {
                agent: model.agents[i].name.clone(),
                reason: e.to_string(),
            })?),
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
    let mut engine = SampledSim::with_controllers(model, ctl)?;
    let mut result = drive(model, &mut engine, recorder, progress, Vec::new())?;
    engine.finish_controllers()?;
    result.hil = engine.link_stats();
    Ok(result)
}
