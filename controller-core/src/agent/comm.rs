//! Communication of one agent: what it broadcasts ([`Agent::frames`]) and how it takes
//! in its neighbours' frames ([`Agent::receive`]).

use super::{pick, Agent, Role};
use crate::config::{AgentId, EstimatorMode};
use crate::wire::{check_frame, FrameError, FrameWriter, WireItem};
use crate::{Real, Vec2};

impl<T: Real, const MT: usize, const NB: usize> Agent<T, MT, NB> {
    /// Calls `f` for everything this agent broadcasts: velocity, the bearings its
    /// neighbours need, and (shared mode) the estimates it owns.
    fn for_each_item(&self, mut f: impl FnMut(Item<T>)) {
        f(Item::Velocity(self.velocity));
        for n in &self.neighbours {
            if let (true, true, Some(s)) = (n.bearing_needed, n.fresh, n.bearing) {
                f(Item::Bearing {
                    to: n.id,
                    s,
                    rate: n.rate,
                });
            }
        }
        if self.config.estimator == EstimatorMode::Shared {
            for a in self
                .angles
                .iter()
                .flatten()
                .filter(|a| a.role == Role::Apex)
            {
                f(Item::Estimate {
                    far: a.far[0],
                    other: a.far[1],
                    r: a.estimate[0],
                });
                f(Item::Estimate {
                    far: a.far[1],
                    other: a.far[0],
                    r: a.estimate[1],
                });
            }
        }
    }

    /// Encodes this tick's broadcast into frames of at most 60 bytes and passes each to
    /// `send`. Returns the number of frames.
    pub fn frames(&mut self, mut send: impl FnMut(&[u8])) -> usize {
        let id = self.config.id;
        let mut seq = self.seq;
        let mut count = 0;
        let mut writer = FrameWriter::new(id, seq);
        self.for_each_item(|item| {
            let wire = item.to_wire();
            if !writer.push(&wire) {
                send(writer.finish());
                count += 1;
                seq = seq.wrapping_add(1);
                writer.reset(id, seq);
                // A single item always fits in an empty frame.
                let _ = writer.push(&wire);
            }
        });
        if writer.items() > 0 {
            send(writer.finish());
            count += 1;
            seq = seq.wrapping_add(1);
        }
        self.seq = seq;
        count
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
        // Whole frame valid before anything is applied.
        frame.validate(self.config.limits.bearing_tolerance.as_f32())?;
        if let Some(n) = self.neighbours.get_mut(slot) {
            n.last_seq = Some(seq);
            n.heard = true;
            n.age = T::zero();
        }
        for item in frame.items().flatten() {
            self.apply(sender, slot, Item::from_wire(&item));
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
        let me = self.config.id;
        let Some(n) = self.neighbours.get_mut(slot) else {
            return;
        };
        let (other, update): (AgentId, Item<T>) = match item {
            Item::Velocity(v) => {
                n.velocity = Some(v);
                return;
            }
            Item::Bearing { to, .. } => (to, item),
            Item::Estimate { far, other, .. } if far == me => (other, item),
            Item::Estimate { .. } => return,
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
            if a.apex != sender || pick(&a.far, 1 - k.min(1)) != other {
                continue;
            }
            match update {
                Item::Bearing { s, rate, .. } => a.remote_bearing = Some((s, rate)),
                Item::Estimate { r, .. } => a.remote_estimate = Some(r),
                Item::Velocity(_) => {}
            }
        }
    }
}

/// A broadcast item at full precision (the wire form is [`WireItem`]).
#[derive(Clone, Copy, Debug)]
enum Item<T: Real> {
    Velocity(Vec2<T>),
    Bearing {
        to: AgentId,
        s: Vec2<T>,
        rate: Vec2<T>,
    },
    Estimate {
        far: AgentId,
        other: AgentId,
        r: T,
    },
}

impl<T: Real> Item<T> {
    fn to_wire(self) -> WireItem {
        let w = |v: Vec2<T>| [v.x.as_f32(), v.y.as_f32()];
        match self {
            Item::Velocity(v) => WireItem::Velocity(w(v)),
            Item::Bearing { to, s, rate } => WireItem::Bearing {
                to,
                s: w(s),
                rate: w(rate),
            },
            Item::Estimate { far, other, r } => WireItem::Estimate {
                far,
                other,
                r: r.as_f32(),
            },
        }
    }

    fn from_wire(w: &WireItem) -> Self {
        let v = |a: [f32; 2]| Vec2::new(T::of_f32(a[0]), T::of_f32(a[1]));
        match *w {
            WireItem::Velocity(x) => Item::Velocity(v(x)),
            WireItem::Bearing { to, s, rate } => Item::Bearing {
                to,
                s: v(s),
                rate: v(rate),
            },
            WireItem::Estimate { far, other, r } => Item::Estimate {
                far,
                other,
                r: T::of_f32(r),
            },
        }
    }
}
