//! One control tick over the link, in two phases (send the tick's `Radio` messages and
//! its `Step`; read the target's `Radio` messages, optional `Estimates` and `Output`),
//! and [`HilController`] as an [`AgentController`].

use super::{HilController, TargetHandle};
use crate::engine::controller::{AgentController, Inbox};
use crate::engine::hil::{HilError, LinkStats, When};
use crate::engine::radio::RadioFrame;
use ph_formation_core::link::{HostMsg, LinkBearing, LinkError, LinkOutput, LinkStep, TargetMsg};
use ph_formation_core::wire::decode_frame;
use ph_formation_core::{Fault, FrameStats, Measurements, OwnedEstimate, Status, StepOutput, Vec2};
use std::time::{Duration, Instant};

impl HilController {
    fn send_tick(&mut self, inbox: Inbox<'_>, m: &Measurements<'_, f64>) -> Result<(), HilError> {
        self.time = m.time;
        let when = self.when();
        let internal = |what: String| HilError::Corrupt {
            agent: self.name.clone(),
            when,
            what,
        };
        for f in inbox.frames() {
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
                        agent: self.name.clone(),
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
            agent: self.name.clone(),
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
                    if !self.estimates_from_target {
                        self.estimates_from_frame(&v);
                    }
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
                        agent: self.name.clone(),
                        when,
                        what: format!(
                            "Error({e:?}) from the firmware: it refused a message the host sent"
                        ),
                    })
                }
                other => {
                    return Err(HilError::Corrupt {
                        agent: self.name.clone(),
                        when,
                        what: format!("{other:?} (expected Radio, Estimates or Output)"),
                    })
                }
            }
            messages += 1;
        };
        if usize::try_from(out.frames) != Ok(frames) {
            return Err(HilError::Corrupt {
                agent: self.name.clone(),
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
}

impl HilController {
    /// Reads the owned estimates from one of the agent's own broadcast frames (used when
    /// the target does not send `Estimates`): an angle item carries the distances its
    /// apex used in S8, its estimates as they were before this step's integration (one
    /// control period behind; the far vertices' copies of per-agent mode are not sent).
    fn estimates_from_frame(&mut self, bytes: &[u8]) {
        let (integrity, estimator) = self.modes;
        let Ok(frame) = decode_frame(bytes, integrity, estimator) else {
            return;
        };
        for item in &frame.angles {
            let [v, w] = item.far;
            for (far, other, r) in [(v, w, item.range[0]), (w, v, item.range[1])] {
                if let Some(k) = self
                    .slots
                    .iter()
                    .position(|s| s.far == far && s.other == other)
                {
                    if let Some(slot) = self.estimates.get_mut(k) {
                        *slot = f64::from(r);
                    }
                }
            }
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
        inbox: Inbox<'_>,
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
        inbox: Inbox<'_>,
        m: &Measurements<'_, f64>,
        _outbox: &mut Vec<RadioFrame>,
    ) -> Result<Option<StepOutput<f64>>, HilError> {
        self.send_tick(inbox, m)?;
        Ok(None)
    }

    fn finish_tick(&mut self, outbox: &mut Vec<RadioFrame>) -> Result<StepOutput<f64>, HilError> {
        self.receive_tick(outbox)
    }

    fn neighbour_order(&self) -> Option<Vec<u8>> {
        self.neighbour_order.clone()
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
                agent: self.name.clone(),
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
                        agent: self.name.clone(),
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
