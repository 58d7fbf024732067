//! Communication of one agent: what it broadcasts ([`Agent::frames`]) and how it takes in
//! its neighbours' broadcasts ([`Agent::receive`], [`Agent::receive_direct`]). The frame
//! layout is [`crate::wire`]'s.

use super::state::{AngleState, Remote, Side};
use super::{pick, Agent};
use crate::config::AgentId;
use crate::wire::{check_frame, mode_byte, quant, FrameError, RawAngle};
use crate::{Real, Vec2};

/// A broadcast item at full precision (the wire rounds the angle's values to binary16).
#[derive(Clone, Copy, Debug)]
enum Item<T: Real> {
    /// The sender's velocity.
    Velocity(Vec2<T>),
    /// An angle `(sender; far[0], far[1])`: `γ`, `σ` and the distances `ρ` (see
    /// [`crate::wire`]).
    Angle {
        far: [AgentId; 2],
        gamma: T,
        sigma: T,
        rho: [T; 2],
    },
}

impl<T: Real, const MT: usize, const NB: usize> Agent<T, MT, NB> {
    /// Encodes this tick's broadcast into frames of at most 60 bytes and passes each to
    /// `send`; returns the number of frames. The broadcast is the agent's velocity and,
    /// for every controlled angle it is the apex of and computed when it last sensed,
    /// what the angle's far vertices need (see [`crate::wire`]). Sends nothing (and
    /// returns 0) on the steps that [`crate::AgentConfig::comm_every`] skips.
    pub fn frames(&mut self, mut send: impl FnMut(&[u8])) -> usize {
        if !self.comm_due {
            return 0;
        }
        let (id, mode) = (
            self.config.id,
            mode_byte(self.config.integrity, self.config.estimator),
        );
        let velocity = [self.velocity.x.as_f32(), self.velocity.y.as_f32()];
        let mut seq = self.seq;
        let mut count = 0;
        let (writer, angles) = (&mut self.writer, &self.angles);
        writer.start(mode, id, seq, velocity);
        for a in angles.iter().flatten() {
            let Some((gamma, sigma, rho)) = sent_angle(a) else {
                continue;
            };
            let q = |x: T| quant::encode(x.as_f32()).0;
            let code = [q(gamma), q(sigma), q(rho[0]), q(rho[1])];
            if !writer.push_angle(a.far, code) {
                send(writer.finish());
                count += 1;
                seq = seq.wrapping_add(1);
                writer.start(mode, id, seq, velocity);
                // One item always fits in an empty frame.
                let _ = writer.push_angle(a.far, code);
            }
        }
        send(writer.finish());
        self.seq = seq.wrapping_add(1);
        count + 1
    }

    /// Checks and applies one received frame. Rejected frames change nothing but the
    /// counters. A neighbour that was stale may restart its sequence numbers.
    pub fn receive(&mut self, bytes: &[u8]) -> Result<(), FrameError> {
        let result = self.receive_inner(bytes);
        self.stats.record(&result);
        result
    }

    fn receive_inner(&mut self, bytes: &[u8]) -> Result<(), FrameError> {
        let frame = check_frame(bytes, self.config.integrity, self.config.estimator)?;
        let sender = frame.header.sender;
        if sender == self.config.id {
            return Err(FrameError::OwnFrame);
        }
        let slot = self.slot(sender).ok_or(FrameError::UnknownSender(sender))?;
        let timeout = self.config.limits.neighbour_timeout;
        let n = self
            .neighbours
            .get(slot)
            .ok_or(FrameError::UnknownSender(sender))?;
        let seq = frame.header.seq;
        if let Some(last) = n.last_seq {
            // Serial-number arithmetic: newer means ahead by 1..=32767. A neighbour not
            // heard within the timeout may have restarted.
            let ahead = seq.wrapping_sub(last);
            if (ahead == 0 || ahead >= 0x8000) && n.age <= timeout {
                return Err(FrameError::StaleSequence { sender, seq });
            }
        }
        // The whole frame is valid before anything is applied. With estimators, the
        // distances are estimates: at least r_min (as rounded: rounding is monotone).
        frame.validate(self.rho_min_code)?;
        if let Some(n) = self.neighbours.get_mut(slot) {
            n.last_seq = Some(seq);
            n.age = T::zero();
        }
        self.oldest = None;
        let [vx, vy] = frame.velocity;
        self.apply(
            slot,
            Item::Velocity(Vec2::new(T::of_f32(vx), T::of_f32(vy))),
        );
        let me = self.config.id;
        for RawAngle { far, codes } in frame.raw_items() {
            // Only the items for angles of which this agent is a far vertex (`apply`
            // checks it again; this saves decoding the others). Validated: finite.
            if far.contains(&me) {
                let v = |c: u16| T::of_f32(quant::from_code(c));
                let item = Item::Angle {
                    far,
                    gamma: v(codes[0]),
                    sigma: v(codes[1]),
                    rho: [v(codes[2]), v(codes[3])],
                };
                self.apply(slot, item);
            }
        }
        Ok(())
    }

    /// Takes a neighbour's broadcast directly, without the wire (no rounding, no sequence
    /// numbers): for in-process simulation and tests.
    pub fn receive_direct(&mut self, from: &Self) -> Result<(), FrameError> {
        let sender = from.id();
        let slot = self.slot(sender).ok_or(FrameError::UnknownSender(sender))?;
        if let Some(n) = self.neighbours.get_mut(slot) {
            n.age = T::zero();
        }
        self.oldest = None;
        self.apply(slot, Item::Velocity(from.velocity));
        for a in from.angles.iter().flatten() {
            if let Some((gamma, sigma, rho)) = sent_angle(a) {
                let far = a.far;
                self.apply(
                    slot,
                    Item::Angle {
                        far,
                        gamma,
                        sigma,
                        rho,
                    },
                );
            }
        }
        Ok(())
    }

    /// Stores one item from the neighbour in `slot`: its velocity, or the effort of an
    /// angle `(sender; far[0], far[1])` of which this agent is a far vertex.
    fn apply(&mut self, slot: usize, item: Item<T>) {
        match item {
            Item::Velocity(v) => {
                if let Some(n) = self.neighbours.get_mut(slot) {
                    n.velocity = Some(v);
                }
            }
            Item::Angle {
                far,
                gamma,
                sigma,
                rho,
            } => {
                let (me, velocity) = (self.config.id, self.velocity);
                let mine = if far[0] == me {
                    0
                } else if far[1] == me {
                    1
                } else {
                    return;
                };
                let other = pick(&far, 1 - mine);
                let Some(n) = self.neighbours.get(slot) else {
                    return;
                };
                // The angles whose apex is the sender and of which this agent is a far
                // vertex (at most one per triangle), matched by the other far vertex.
                for &flat in &n.apex_of {
                    let flat = usize::from(flat);
                    let Some(a) = self
                        .angles
                        .get_mut(flat / 2)
                        .and_then(|t| t.get_mut(flat % 2))
                    else {
                        continue;
                    };
                    if let Side::Far { k, remote, age } = &mut a.side {
                        if pick(&a.far, 1 - *k) == other && pick(&a.far, *k) == me {
                            *remote = Remote {
                                gamma,
                                sigma,
                                rho: pick(&rho, mine),
                                v_ref: velocity,
                            };
                            *age = T::zero();
                        }
                    }
                }
            }
        }
    }
}

/// What an apex sends of angle `a` (`γ`, `σ`, `ρ`): the values of its last sense, if it
/// computed them (they are then finite: see `sensing::apex_part`).
#[inline]
#[allow(clippy::type_complexity)]
fn sent_angle<T: Real>(a: &AngleState<T>) -> Option<(T, T, [T; 2])> {
    match &a.side {
        Side::Apex { part, fault: None } => Some((part.gamma, part.sigma, part.rho)),
        _ => None,
    }
}
