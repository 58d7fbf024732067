//! Communication of one agent: what it broadcasts ([`Agent::frames`]) and how it takes
//! in its neighbours' frames ([`Agent::receive`]).

use super::{pick, Agent, AngleState, ApexBearings, Neighbour, Role};
use crate::config::{AgentId, EstimatorMode};
use crate::wire::{check_frame, FrameError, RawItem, WireItem, MAX_ITEMS_PER_FRAME};
use crate::{Real, Vec2};

impl<T: Real, const MT: usize, const NB: usize> Agent<T, MT, NB> {
    /// The fresh bearings `[s_uv, s_uw]` and rates of an angle this agent is the apex of
    /// (`None` without a fresh bearing to both far vertices).
    fn apex_bearings(
        neighbours: &[Neighbour<T, MT>],
        a: &AngleState<T>,
    ) -> Option<ApexBearings<T>> {
        let bearing = |slot: usize| match neighbours.get(slot) {
            Some(n) if n.fresh => n.bearing.map(|s| (s, n.rate)),
            _ => None,
        };
        let ((s0, d0), (s1, d1)) = (bearing(a.slots[1])?, bearing(a.slots[2])?);
        Some(([s0, s1], [d0, d1]))
    }

    /// Calls `f` for everything this agent broadcasts, at full precision: its velocity, and
    /// for every controlled angle it is the apex of (and has fresh bearings for), the
    /// bearings and rates its far vertices need, with the estimates it owns in shared mode.
    /// [`Agent::frames`] sends the same, rounded to `f32`.
    fn for_each_item(&self, mut f: impl FnMut(Item<T>)) {
        f(Item::Velocity(self.velocity));
        let shared = self.config.estimator == EstimatorMode::Shared;
        for a in self.angles.iter().flatten() {
            if a.role != Role::Apex {
                continue;
            }
            if let Some((s, rate)) = Self::apex_bearings(&self.neighbours, a) {
                f(Item::Angle {
                    far: a.far,
                    s,
                    rate,
                    r: shared.then_some(a.estimate),
                });
            }
        }
    }

    /// Encodes this tick's broadcast (what `for_each_item` lists, as [`WireItem`]s) into
    /// frames of at most 60 bytes and passes each to `send`. Returns the number of frames.
    pub fn frames(&mut self, mut send: impl FnMut(&[u8])) -> usize {
        let id = self.config.id;
        let shared = self.config.estimator == EstimatorMode::Shared;
        let w = |v: Vec2<T>| [v.x.as_f32(), v.y.as_f32()];
        let mut seq = self.seq;
        let mut count = 0;
        let (writer, angles, neighbours) = (&mut self.writer, &self.angles, &self.neighbours);
        writer.reset(id, seq);
        // The velocity always fits in an empty frame.
        let _ = writer.push(&WireItem::Velocity(w(self.velocity)));
        for a in angles.iter().flatten() {
            if a.role != Role::Apex {
                continue;
            }
            let Some((s, rate)) = Self::apex_bearings(neighbours, a) else {
                continue;
            };
            let (far, s, rate) = (a.far, [w(s[0]), w(s[1])], [w(rate[0]), w(rate[1])]);
            let item = if shared {
                let r = [a.estimate[0].as_f32(), a.estimate[1].as_f32()];
                WireItem::Angle { far, s, rate, r }
            } else {
                WireItem::AngleBearings { far, s, rate }
            };
            if !writer.push(&item) {
                send(writer.finish());
                count += 1;
                seq = seq.wrapping_add(1);
                writer.reset(id, seq);
                // A single item always fits in an empty frame.
                let _ = writer.push(&item);
            }
        }
        send(writer.finish());
        self.seq = seq.wrapping_add(1);
        count + 1
    }

    /// Decodes and applies one received frame. Rejected frames change nothing but the
    /// counters. A neighbour that was stale may restart its sequence numbers.
    pub fn receive(&mut self, bytes: &[u8]) -> Result<(), FrameError> {
        let result = self.receive_inner(bytes);
        self.stats.record(&result);
        result
    }

    fn receive_inner(&mut self, bytes: &[u8]) -> Result<(), FrameError> {
        let frame = check_frame(bytes)?;
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
            // Serial-number arithmetic: newer means ahead by 1..=32767.
            let ahead = seq.wrapping_sub(last);
            let resync = !n.heard || n.age > timeout;
            if (ahead == 0 || ahead >= 0x8000) && !resync {
                return Err(FrameError::StaleSequence { sender, seq });
            }
        }
        // One pass over the items: split, check, and keep (without copying) what concerns
        // this agent. The whole frame is valid before anything is applied.
        let me = self.config.id;
        let tol = self.config.limits.bearing_tolerance.as_f32();
        let mut kept: heapless::Vec<RawItem<'_>, MAX_ITEMS_PER_FRAME> = heapless::Vec::new();
        let mut rest = frame.item_bytes();
        while !rest.is_empty() {
            let item = RawItem::next(&mut rest).ok_or(FrameError::Malformed)?;
            if !item.valid(tol) {
                return Err(FrameError::InvalidValue);
            }
            if item.far().is_none_or(|far| far.contains(&me)) {
                // At most MAX_ITEMS_PER_FRAME items fit in a frame.
                kept.push(item).map_err(|_| FrameError::Malformed)?;
            }
        }
        if let Some(n) = self.neighbours.get_mut(slot) {
            n.last_seq = Some(seq);
            n.heard = true;
            n.age = T::zero();
        }
        let v = |a: [f32; 2]| Vec2::new(T::of_f32(a[0]), T::of_f32(a[1]));
        for item in &kept {
            if let Some(vel) = item.velocity() {
                self.apply(sender, slot, Item::Velocity(v(vel)));
            } else if let Some(far) = item.far() {
                self.for_far_angles(sender, slot, far, |a, mine| {
                    let (s, rate) = item.bearing(1 - mine);
                    a.remote_bearing = Some((v(s), v(rate)));
                    if let Some(r) = item.estimate(mine) {
                        a.remote_estimate = Some(T::of_f32(r));
                    }
                });
            }
        }
        Ok(())
    }

    /// Takes a neighbour's broadcast directly, without the wire (no `f32` rounding, no
    /// sequence numbers): for in-process simulation and tests.
    pub fn receive_direct(&mut self, from: &Self) -> Result<(), FrameError> {
        let sender = from.id();
        let slot = self.slot(sender).ok_or(FrameError::UnknownSender(sender))?;
        if let Some(n) = self.neighbours.get_mut(slot) {
            n.heard = true;
            n.age = T::zero();
        }
        from.for_each_item(|item| self.apply(sender, slot, item));
        Ok(())
    }

    fn apply(&mut self, sender: AgentId, slot: usize, item: Item<T>) {
        match item {
            Item::Velocity(v) => {
                if let Some(n) = self.neighbours.get_mut(slot) {
                    n.velocity = Some(v);
                }
            }
            Item::Angle { far, s, rate, r } => {
                self.for_far_angles(sender, slot, far, |a, mine| {
                    a.remote_bearing = Some((pick(&s, 1 - mine), pick(&rate, 1 - mine)));
                    if let Some(r) = r {
                        a.remote_estimate = Some(pick(&r, mine));
                    }
                });
            }
        }
    }

    /// Calls `f(angle, mine)` for the angle(s) `(sender; far[0], far[1])` of which this
    /// agent is the far vertex `far[mine]`: the other far vertex's bearing is what it
    /// needs (S4–S6), with the estimate of its own edge (S8).
    fn for_far_angles(
        &mut self,
        sender: AgentId,
        slot: usize,
        far: [AgentId; 2],
        mut f: impl FnMut(&mut AngleState<T>, usize),
    ) {
        let me = self.config.id;
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
        // Only the angles whose apex is the sender and of which this agent is a far vertex.
        for &flat in &n.apex_of {
            let flat = usize::from(flat);
            let Some(a) = self
                .angles
                .get_mut(flat / 2)
                .and_then(|t| t.get_mut(flat % 2))
            else {
                continue;
            };
            let Role::Far(k) = a.role else { continue };
            if a.apex == sender && pick(&a.far, 1 - k.min(1)) == other {
                f(a, mine);
            }
        }
    }
}

/// A broadcast item at full precision (the wire form is [`WireItem`]).
#[derive(Clone, Copy, Debug)]
enum Item<T: Real> {
    Velocity(Vec2<T>),
    /// A controlled angle of which the sender is the apex; `r` in shared mode only.
    Angle {
        far: [AgentId; 2],
        s: [Vec2<T>; 2],
        rate: [Vec2<T>; 2],
        r: Option<[T; 2]>,
    },
}
