//! [`HilController`]: one agent whose controller runs on an emulated target, behind a
//! [`Link`]. It implements [`AgentController`] like the in-process agents, in two phases
//! so that several targets compute at once: [`AgentController::start_tick`] sends the
//! tick's `Radio` messages and its `Step`, [`AgentController::finish_tick`] reads the
//! target's `Radio` messages, optional `Estimates` and the `Output`.

use super::link::{Link, LinkCounters, RecvError, TARGET_MT};
use super::qemu::QemuProcess;
use super::{HilError, LinkStats, When};
use crate::controller::AgentController;
use crate::radio::RadioFrame;
use controller_core::link::{
    HostMsg, LinkBearing, LinkError, LinkOutput, LinkStep, TargetMsg, LINK_VERSION,
};
use controller_core::{
    AgentConfig, Fault, FrameStats, Measurements, OwnedEstimate, Status, StepOutput, Vec2,
};
use std::thread::JoinHandle;
use std::time::{Duration, Instant};

/// What runs the target: a QEMU process, or (tests) a thread.
#[derive(Debug)]
pub enum TargetHandle {
    /// `qemu-system-arm` with the firmware (killed on drop).
    Qemu(QemuProcess),
    /// The host-side stand-in of [`super::fake`].
    Fake(Option<JoinHandle<Result<(), String>>>),
}

impl TargetHandle {
    /// QEMU's pid, for a QEMU target.
    pub fn pid(&self) -> Option<u32> {
        match self {
            Self::Qemu(p) => Some(p.pid()),
            Self::Fake(_) => None,
        }
    }

    /// A description of how the target ended, if it did (QEMU's exit status and stderr).
    fn ended(&mut self, wait: Duration) -> Option<String> {
        match self {
            Self::Qemu(p) => {
                let end = Instant::now() + wait;
                loop {
                    if let Some(s) = p.try_exit() {
                        let tail = p.stderr_tail();
                        return Some(if tail.is_empty() {
                            format!("QEMU exited ({s})")
                        } else {
                            format!("QEMU exited ({s}): {tail}")
                        });
                    }
                    if Instant::now() >= end {
                        return None;
                    }
                    std::thread::sleep(Duration::from_millis(5));
                }
            }
            Self::Fake(h) => h
                .as_ref()
                .is_some_and(|h| h.is_finished())
                .then(|| "the fake target ended".to_owned()),
        }
    }

    fn log_hint(&self) -> String {
        match self {
            Self::Qemu(p) => format!(
                "; firmware log (raw defmt): {}, QEMU messages: {}",
                p.log.display(),
                p.stderr_log.display()
            ),
            Self::Fake(_) => String::new(),
        }
    }
}

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
    link: Link,
    target: TargetHandle,
    timeout: Duration,
    layout: Vec<OwnedEstimate<f64>>,
    slots: Vec<EstimateSlot>,
    estimates: Vec<f64>,
    estimates_from_target: bool,
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
    /// was started.
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
    ) -> Result<Self, HilError> {
        let id = config.id;
        let mut c = Self {
            id,
            link,
            target,
            timeout,
            estimates: vec![initial; layout.len()],
            layout,
            slots,
            estimates_from_target: false,
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
                agent: id,
                reason: format!("cannot configure the connection: {e}"),
            })?;
        match c.link.wait_announcement(startup) {
            Ok(()) => {}
            Err(RecvError::Timeout { .. }) => {
                let ended = c.target.ended(Duration::ZERO);
                return Err(HilError::Start {
                    agent: id,
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
                agent: id,
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
                agent: id,
                when: When::Configure,
                what: format!(
                    "Ready {{ id: {got}, version: {version} }} (expected id {id}, link version {LINK_VERSION})"
                ),
            }),
            TargetMsg::Error(e) => Err(HilError::Refused {
                agent: id,
                reason: format!(
                    "the firmware answered Configure with Error({e:?}){}",
                    match e {
                        LinkError::Config(e) => format!(" ({e})"),
                        _ => String::new(),
                    }
                ),
            }),
            other => Err(HilError::Corrupt {
                agent: id,
                when: When::Configure,
                what: format!("{other:?} (expected Ready)"),
            }),
        }
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
            agent: self.id,
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
                        agent: self.id,
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
                    agent: self.id,
                    when,
                    timeout_s: self.timeout.as_secs_f64(),
                    detail: format!("{waiting}{partial}{}", self.target.log_hint()),
                    pid: self.target.pid(),
                }
            }
            RecvError::Closed => {
                let ended = self.target.ended(Duration::from_secs(1));
                HilError::Closed {
                    agent: self.id,
                    when,
                    detail: format!(
                        "the target closed the link while {waiting}{}{}",
                        ended.map_or(String::new(), |s| format!(": {s}")),
                        self.target.log_hint()
                    ),
                }
            }
            RecvError::Corrupt(what) => HilError::Corrupt {
                agent: self.id,
                when,
                what,
            },
            RecvError::Io(e) => self.io_error(when, &e),
        }
    }

    fn send_tick(
        &mut self,
        inbox: &[RadioFrame],
        m: &Measurements<'_, f64>,
    ) -> Result<(), HilError> {
        self.time = m.time;
        let when = self.when();
        let internal = |what: String| HilError::Corrupt {
            agent: self.id,
            when,
            what,
        };
        for f in inbox {
            let mut v = heapless::Vec::new();
            v.extend_from_slice(f.as_bytes())
                .map_err(|_| internal("a radio frame longer than 60 bytes".to_owned()))?;
            self.link
                .queue(&HostMsg::Radio(v))
                .map_err(|e| internal(format!("cannot encode a Radio message: {e}")))?;
            self.radio_to_target += 1;
        }
        let f = |v: &Vec2<f64>| [v.x as f32, v.y as f32];
        let mut bearings = heapless::Vec::new();
        for b in m.bearings {
            bearings
                .push(LinkBearing {
                    neighbour: b.neighbour,
                    s: f(&b.bearing),
                    rate: b.rate.as_ref().map(f),
                    range: b.range.map(|r| r as f32),
                })
                .map_err(|_| internal("more bearings than a Step carries (12)".to_owned()))?;
        }
        let step = LinkStep {
            time: m.time as f32,
            dt: m.dt as f32,
            velocity: f(&m.velocity),
            bearings,
            partner_offset: m.partner_offset.as_ref().map(f),
        };
        self.link
            .queue(&HostMsg::Step(step))
            .map_err(|e| internal(format!("cannot encode the Step message: {e}")))?;
        let write_limit = self.timeout;
        if let Err(e) = self.link.flush() {
            return Err(
                if matches!(
                    e.kind(),
                    std::io::ErrorKind::WouldBlock | std::io::ErrorKind::TimedOut
                ) {
                    HilError::Timeout {
                        agent: self.id,
                        when,
                        timeout_s: write_limit.as_secs_f64(),
                        detail: format!(
                            "the target stopped reading (sending the tick's messages){}",
                            self.target.log_hint()
                        ),
                        pid: self.target.pid(),
                    }
                } else {
                    self.io_error(when, &e.to_string())
                },
            );
        }
        self.sent_at = Some(Instant::now());
        Ok(())
    }

    fn receive_tick(&mut self, outbox: &mut Vec<RadioFrame>) -> Result<StepOutput<f64>, HilError> {
        let when = self.when();
        let start = self.sent_at.take().ok_or_else(|| HilError::Corrupt {
            agent: self.id,
            when,
            what: "nothing (no tick was sent)".to_owned(),
        })?;
        let deadline = start + self.timeout;
        let mut frames = 0usize;
        let mut messages = 0usize;
        let out = loop {
            let waiting = format!(
                "waiting for the Output of tick {} ({messages} messages of this tick received)",
                self.ticks
            );
            let msg = self.recv(deadline, when, &waiting)?;
            match msg {
                TargetMsg::Radio(v) => {
                    outbox.push(RadioFrame::new(&v));
                    frames += 1;
                }
                TargetMsg::Estimates(list) => {
                    self.estimates_from_target = true;
                    for e in &list {
                        if let Some(k) = self.slots.iter().position(|s| {
                            s.triangle == usize::from(e.triangle)
                                && s.angle == usize::from(e.angle)
                                && s.edge == usize::from(e.edge)
                        }) {
                            if let Some(slot) = self.estimates.get_mut(k) {
                                *slot = f64::from(e.value);
                            }
                        }
                    }
                }
                TargetMsg::Output(o) => break o,
                // Informational: a radio frame the target's agent rejected.
                TargetMsg::Error(LinkError::Frame(_)) => {}
                TargetMsg::Error(e) => {
                    return Err(HilError::Corrupt {
                        agent: self.id,
                        when,
                        what: format!(
                            "Error({e:?}) from the firmware: it refused a message the host sent"
                        ),
                    })
                }
                other => {
                    return Err(HilError::Corrupt {
                        agent: self.id,
                        when,
                        what: format!("{other:?} (expected Radio, Estimates or Output)"),
                    })
                }
            }
            messages += 1;
        };
        if usize::try_from(out.frames) != Ok(frames) {
            return Err(HilError::Corrupt {
                agent: self.id,
                when,
                what: format!(
                    "an Output announcing {} radio frames after {frames} Radio messages",
                    out.frames
                ),
            });
        }
        self.radio_from_target += frames as u64;
        self.rejected = out.rejected;
        self.wall += start.elapsed();
        self.ticks += 1;
        Ok(step_output(&out))
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
            agent: self.id,
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

/// The host form of a target's output (the link carries the status with its fault).
pub fn step_output(o: &LinkOutput) -> StepOutput<f64> {
    StepOutput {
        force: Vec2::new(f64::from(o.force[0]), f64::from(o.force[1])),
        status: o.status,
        saturated: o.saturated,
        degenerate: o.degenerate,
    }
}

impl AgentController for HilController {
    fn id(&self) -> u8 {
        self.id
    }

    /// Both phases at once. A link failure cannot be returned here: it is kept (see
    /// [`AgentController::take_error`]) and the output is zero force, safe.
    fn tick(
        &mut self,
        inbox: &[RadioFrame],
        m: &Measurements<'_, f64>,
        outbox: &mut Vec<RadioFrame>,
    ) -> StepOutput<f64> {
        let r = self
            .send_tick(inbox, m)
            .and_then(|()| self.receive_tick(outbox));
        r.unwrap_or_else(|e| {
            self.error.get_or_insert(e);
            StepOutput {
                force: Vec2::zeros(),
                status: Status::Safe(Fault::NonFinite),
                saturated: false,
                degenerate: false,
            }
        })
    }

    fn start_tick(
        &mut self,
        inbox: &[RadioFrame],
        m: &Measurements<'_, f64>,
        _outbox: &mut Vec<RadioFrame>,
    ) -> Result<Option<StepOutput<f64>>, HilError> {
        self.send_tick(inbox, m)?;
        Ok(None)
    }

    fn finish_tick(&mut self, outbox: &mut Vec<RadioFrame>) -> Result<StepOutput<f64>, HilError> {
        self.receive_tick(outbox)
    }

    fn take_error(&mut self) -> Option<HilError> {
        self.error.take()
    }

    fn estimate_layout(&self) -> Vec<OwnedEstimate<f64>> {
        self.layout.clone()
    }

    fn read_estimates(&self, out: &mut [f64]) -> usize {
        let mut n = 0;
        for (slot, v) in out.iter_mut().zip(&self.estimates) {
            *slot = *v;
            n += 1;
        }
        n
    }

    /// The link reports only totals: rejected frames are counted as `malformed`, and
    /// accepted = delivered − rejected.
    fn frame_stats(&self) -> FrameStats {
        let delivered = u32::try_from(self.radio_to_target).unwrap_or(u32::MAX);
        FrameStats {
            accepted: delivered.saturating_sub(self.rejected),
            malformed: self.rejected,
            ..FrameStats::default()
        }
    }

    /// Sends `Finish`, reads `Finished` and lets QEMU exit (killed after 2 s).
    fn finish(&mut self) -> Result<(), HilError> {
        let when = When::Finish {
            ticks: self.ticks,
            time: self.time,
        };
        self.link
            .queue(&HostMsg::Finish)
            .map_err(|e| HilError::Corrupt {
                agent: self.id,
                when,
                what: e,
            })?;
        if let Err(e) = self.link.flush() {
            return Err(self.io_error(when, &e.to_string()));
        }
        let deadline = Instant::now() + self.timeout;
        loop {
            match self.recv(deadline, when, "waiting for Finished")? {
                TargetMsg::Finished { accepted, rejected } => {
                    self.finished = Some((accepted, rejected));
                    break;
                }
                // Left over from a target that answers more than asked: not an error.
                TargetMsg::Error(LinkError::Frame(_)) => {}
                other => {
                    return Err(HilError::Corrupt {
                        agent: self.id,
                        when,
                        what: format!("{other:?} (expected Finished)"),
                    })
                }
            }
        }
        match &mut self.target {
            TargetHandle::Qemu(p) => {
                self.exit_code = p
                    .wait_or_kill(Duration::from_secs(2))
                    .and_then(|s| s.code());
            }
            TargetHandle::Fake(h) => {
                if let Some(h) = h.take() {
                    self.exit_code = Some(match h.join() {
                        Ok(Ok(())) => 0,
                        _ => 1,
                    });
                }
            }
        }
        Ok(())
    }

    fn link_stats(&self) -> Option<LinkStats> {
        Some(self.stats())
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
