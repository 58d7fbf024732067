//! [`HilController`]: one agent whose controller runs on an emulated target, behind a
//! [`Link`]. It implements [`AgentController`](crate::engine::AgentController) like the in-process agents, in two phases
//! so that several targets compute at once: [`AgentController::start_tick`](crate::engine::AgentController::start_tick) sends the
//! tick's `Radio` messages and its `Step`, [`AgentController::finish_tick`](crate::engine::AgentController::finish_tick) reads the
//! target's `Radio` messages, optional `Estimates` and the `Output`.

mod target;
mod tick;

pub use target::TargetHandle;
pub use tick::step_output;

use super::link::{Link, LinkCounters, RecvError, TARGET_MT};
use super::{HilError, LinkStats, When};
use ph_formation_core::link::{HostMsg, LinkError, TargetMsg, LINK_VERSION};
use ph_formation_core::{AgentConfig, EstimatorMode, Integrity, OwnedEstimate};
use std::time::{Duration, Instant};

/// Where one owned estimate of the HIL agent sits: its frame item `(far, other)` ids and
/// its `(triangle, angle, edge)` in the agent's configuration.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct EstimateSlot {
    /// Triangle index in the agent's configuration.
    pub triangle: usize,
    /// Angle index.
    pub angle: usize,
    /// Edge index.
    pub edge: usize,
    /// Far vertex id of the edge.
    pub far: u8,
    /// The angle's other far vertex id.
    pub other: u8,
}

/// One agent's controller on an emulated target.
#[derive(Debug)]
pub struct HilController {
    id: u8,
    /// The agent's id as the scenario writes it (messages and figures).
    name: String,
    link: Link,
    target: TargetHandle,
    timeout: Duration,
    layout: Vec<OwnedEstimate<f64>>,
    slots: Vec<EstimateSlot>,
    /// The target's neighbour slots (wire ids), when known: bearings go in this order.
    neighbour_order: Option<Vec<u8>>,
    estimates: Vec<f64>,
    estimates_from_target: bool,
    /// The frames' integrity and estimator mode (to read the agent's own frames).
    modes: (Integrity, EstimatorMode),
    /// Ticks completed.
    ticks: u64,
    time: f64,
    sent_at: Option<Instant>,
    wall: Duration,
    startup: Duration,
    radio_to_target: u64,
    radio_from_target: u64,
    rejected: u32,
    finished: Option<(u32, u32)>,
    exit_code: Option<i32>,
    error: Option<HilError>,
}

impl HilController {
    /// Waits for the target's start-up announcement (until `startup`), configures it
    /// with `config` and waits for `Ready` (within `timeout`). `layout` and `slots`
    /// describe the agent's owned estimates (as the host's own core agent of the same
    /// configuration orders them); `initial` is `r̂(0)`; `started` is when the target
    /// was started; `name` is the agent's id as the scenario writes it (for messages).
    #[allow(clippy::too_many_arguments)]
    pub fn configure(
        config: &AgentConfig<f32, TARGET_MT>,
        link: Link,
        target: TargetHandle,
        timeout: Duration,
        startup: Instant,
        layout: Vec<OwnedEstimate<f64>>,
        slots: Vec<EstimateSlot>,
        initial: f64,
        started: Instant,
        name: &str,
    ) -> Result<Self, HilError> {
        let id = config.id;
        let name = name.to_owned();
        let mut c = Self {
            id,
            name: name.clone(),
            link,
            target,
            timeout,
            estimates: vec![initial; layout.len()],
            layout,
            slots,
            neighbour_order: None,
            estimates_from_target: false,
            modes: (config.integrity, config.estimator),
            ticks: 0,
            time: 0.0,
            sent_at: None,
            wall: Duration::ZERO,
            startup: Duration::ZERO,
            radio_to_target: 0,
            radio_from_target: 0,
            rejected: 0,
            finished: None,
            exit_code: None,
            error: None,
        };
        c.link
            .set_write_timeout(timeout)
            .map_err(|e| HilError::Start {
                agent: name.clone(),
                reason: format!("cannot configure the connection: {e}"),
            })?;
        match c.link.wait_announcement(startup) {
            Ok(()) => {}
            Err(RecvError::Timeout { .. }) => {
                let ended = c.target.ended(Duration::ZERO);
                return Err(HilError::Start {
                    agent: name.clone(),
                    reason: format!(
                        "no start-up announcement (a 0x00 byte on USART1) within {:.1} s of starting{}{}",
                        started.elapsed().as_secs_f64(),
                        ended.map_or(String::new(), |s| format!(": {s}")),
                        c.target.log_hint()
                    ),
                });
            }
            Err(e) => {
                return Err(c.recv_error(
                    e,
                    When::Configure,
                    "waiting for the start-up announcement",
                ))
            }
        }
        c.link
            .queue(&HostMsg::Configure(config.clone()))
            .map_err(|e| HilError::Start {
                agent: name.clone(),
                reason: format!("the configuration does not encode: {e}"),
            })?;
        if let Err(e) = c.link.flush() {
            return Err(c.io_error(When::Configure, &e.to_string()));
        }
        let deadline = Instant::now() + timeout;
        match c.recv(deadline, When::Configure, "waiting for Ready")? {
            TargetMsg::Ready {
                id: got, version, ..
            } if got == id && version == LINK_VERSION => {
                c.startup = started.elapsed();
                Ok(c)
            }
            TargetMsg::Ready {
                id: got, version, ..
            } => Err(HilError::Corrupt {
                agent: name.clone(),
                when: When::Configure,
                what: format!(
                    "Ready {{ id: {got}, version: {version} }} (expected id {id}, link version {LINK_VERSION})"
                ),
            }),
            TargetMsg::Error(e) => Err(HilError::Refused {
                agent: name.clone(),
                reason: format!(
                    "the firmware answered Configure with Error({e:?}){}",
                    match e {
                        LinkError::Config(e) => format!(" ({e})"),
                        _ => String::new(),
                    }
                ),
            }),
            other => Err(HilError::Corrupt {
                agent: name.clone(),
                when: When::Configure,
                what: format!("{other:?} (expected Ready)"),
            }),
        }
    }

    /// The target's neighbour slots in order (wire ids, as
    /// `ph_formation_core::Agent::neighbours` gives them for its configuration): the
    /// simulator then sends the bearings in that order, the one the target's core takes
    /// in one pass.
    pub fn with_neighbour_order(mut self, order: Vec<u8>) -> Self {
        self.neighbour_order = Some(order);
        self
    }

    /// QEMU's pid, for a QEMU target.
    pub fn pid(&self) -> Option<u32> {
        self.target.pid()
    }

    fn when(&self) -> When {
        When::Tick {
            tick: self.ticks,
            time: self.time,
        }
    }

    fn io_error(&mut self, when: When, e: &str) -> HilError {
        let ended = self.target.ended(Duration::from_millis(500));
        HilError::Closed {
            agent: self.name.clone(),
            when,
            detail: format!(
                "{}{}",
                ended.map_or_else(|| format!("link error: {e}"), |s| format!("{s} ({e})")),
                self.target.log_hint()
            ),
        }
    }

    /// Reads one message, mapping every failure to a [`HilError`].
    fn recv(
        &mut self,
        deadline: Instant,
        when: When,
        waiting: &str,
    ) -> Result<TargetMsg, HilError> {
        match self.link.recv(deadline) {
            Ok(m) => Ok(m),
            Err(e) => Err(self.recv_error(e, when, waiting)),
        }
    }

    /// The [`HilError`] of a failed read.
    fn recv_error(&mut self, e: RecvError, when: When, waiting: &str) -> HilError {
        match e {
            RecvError::Timeout { partial } => {
                if let Some(s) = self.target.ended(Duration::ZERO) {
                    return HilError::Closed {
                        agent: self.name.clone(),
                        when,
                        detail: format!("{s} while {waiting}{}", self.target.log_hint()),
                    };
                }
                let partial = if partial > 0 {
                    format!(", {partial} bytes of an unfinished frame received")
                } else {
                    String::new()
                };
                HilError::Timeout {
                    agent: self.name.clone(),
                    when,
                    timeout_s: self.timeout.as_secs_f64(),
                    detail: format!("{waiting}{partial}{}", self.target.log_hint()),
                    pid: self.target.pid(),
                }
            }
            RecvError::Closed => {
                let ended = self.target.ended(Duration::from_secs(1));
                HilError::Closed {
                    agent: self.name.clone(),
                    when,
                    detail: format!(
                        "the target closed the link while {waiting}{}{}",
                        ended.map_or(String::new(), |s| format!(": {s}")),
                        self.target.log_hint()
                    ),
                }
            }
            RecvError::Corrupt(what) => HilError::Corrupt {
                agent: self.name.clone(),
                when,
                what,
            },
            RecvError::Io(e) => self.io_error(when, &e),
        }
    }

    /// The counters and timings of this agent's link.
    pub fn stats(&self) -> LinkStats {
        let LinkCounters {
            frames_to_target,
            frames_from_target,
            bytes_to_target,
            bytes_from_target,
        } = self.link.counters;
        LinkStats {
            agent: self.name.clone(),
            pid: self.target.pid(),
            frames_to_target,
            frames_from_target,
            bytes_to_target,
            bytes_from_target,
            radio_to_target: self.radio_to_target,
            radio_from_target: self.radio_from_target,
            ticks: self.ticks,
            wall_s: self.wall.as_secs_f64(),
            startup_s: self.startup.as_secs_f64(),
            estimates_from_target: self.estimates_from_target,
            estimates: self.layout.len(),
            target_accepted: self.finished.map(|f| f.0),
            target_rejected: self.finished.map(|f| f.1),
            exit_code: self.exit_code,
        }
    }
}

impl Drop for HilController {
    fn drop(&mut self) {
        // Closing the socket first lets a fake target's thread end; QEMU is killed by
        // its own guard.
        self.link.shutdown();
        if let TargetHandle::Fake(h) = &mut self.target {
            if let Some(h) = h.take() {
                let _ = h.join();
            }
        }
    }
}
