//! The radio model: frames are the core's real wire bytes (version 3, at most 60), broadcast by a sender
//! and copied to each of its radio neighbours; every copy independently suffers loss,
//! latency + jitter, reordering, duplication and corruption. A sender's air time is
//! limited by an optional bandwidth with a bounded transmit queue.
//!
//! Receivers are the sender's radio neighbours (triangle neighbours and leader partner):
//! frames from other agents would be rejected by the receiver's core as an unknown
//! sender, so they are not delivered at all (this keeps the cost linear in N).
//!
//! Nothing here allocates after construction unless the preallocated capacity of the
//! in-flight queue is exceeded (it is sized from the scenario's rates and delays).
//!
//! With a shared medium ([`crate::model::ChannelModel`], [`Radio::attach_channel`]) a
//! broadcast goes on the air through [`super::channel`] instead of the per-sender
//! bandwidth limit; the copies that survive collisions and range then suffer the
//! per-link faults above, from the end of their transmission.

use super::channel::{bump, Channel, ChannelStats};
pub use super::frame::RadioFrame;
use crate::model::graph::Adjacency;
use crate::model::RadioModel;
use ph_formation_core::Vec2;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use std::cmp::Ordering;
use std::collections::BinaryHeap;

/// Random stream of the radio (independent of the sensors' stream).
const RADIO_STREAM: u64 = 2;
/// Tolerance on delivery times (s): a frame due at `t + 1e-9` is delivered at `t`.
const TIME_EPS: f64 = 1e-9;
/// The sender index of frames from outside the swarm ([`Radio::inject`]).
const EXTERNAL: usize = u32::MAX as usize;

/// Counters of the radio, per link copy (a broadcast to `k` neighbours is `k` copies).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct RadioStats {
    /// Frames produced by the controllers (each broadcast once).
    pub broadcasts: u64,
    /// Link copies put on the air (one per receiver per broadcast).
    pub sent: u64,
    /// Copies lost (random loss).
    pub lost: u64,
    /// Copies dropped because the sender's transmit queue was full (bandwidth).
    pub queue_dropped: u64,
    /// Extra copies created by duplication.
    pub duplicated: u64,
    /// Copies with a flipped bit.
    pub corrupted: u64,
    /// Copies held back by the reordering delay.
    pub reordered: u64,
    /// Copies handed to a receiver.
    pub delivered: u64,
    /// Copies the shared channel lost (collisions, out of range).
    pub channel_lost: u64,
}

impl RadioStats {
    /// Copies that never arrived (lost or dropped by the queue).
    pub fn dropped(&self) -> u64 {
        self.lost + self.queue_dropped + self.channel_lost
    }
}

#[derive(Clone, Copy, Debug)]
struct InFlight {
    at: f64,
    order: u64,
    to: u32,
    from: u32,
    /// When the sender produced it (s).
    born: f64,
    frame: RadioFrame,
}

impl PartialEq for InFlight {
    fn eq(&self, other: &Self) -> bool {
        self.cmp(other) == Ordering::Equal
    }
}
impl Eq for InFlight {}
impl PartialOrd for InFlight {
    fn partial_cmp(&self, other: &Self) -> Option<Ordering> {
        Some(self.cmp(other))
    }
}
impl Ord for InFlight {
    /// Reversed (earliest first in a max-heap), ties broken by send order: deterministic.
    fn cmp(&self, other: &Self) -> Ordering {
        other
            .at
            .total_cmp(&self.at)
            .then_with(|| other.order.cmp(&self.order))
    }
}

/// The radio between all agents.
#[derive(Debug)]
pub struct Radio {
    model: RadioModel,
    rng: ChaCha8Rng,
    queue: BinaryHeap<InFlight>,
    order: u64,
    seed: u64,
    busy_until: Vec<f64>,
    stats: RadioStats,
    channel: Option<Channel>,
    /// Each agent's link copies sent and, of those, lost (random loss, a full queue),
    /// by sender; the channel keeps its own losses ([`Radio::loss_by_sender`]).
    sent_from: Vec<u64>,
    lost_from: Vec<u64>,
}

impl Radio {
    /// A radio for `n` agents, seeded; `capacity` in-flight copies are preallocated.
    pub fn new(model: &RadioModel, n: usize, seed: u64, capacity: usize) -> Self {
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        rng.set_stream(RADIO_STREAM);
        Self {
            model: model.clone(),
            rng,
            queue: BinaryHeap::with_capacity(capacity),
            order: 0,
            seed,
            busy_until: vec![0.0; n],
            stats: RadioStats::default(),
            channel: None,
            sent_from: vec![0; n],
            lost_from: vec![0; n],
        }
    }

    /// Puts the agents on the model's shared medium, if it has one: `neighbours` is the
    /// radio graph, `period` the control period (s).
    pub fn attach_channel(&mut self, neighbours: &Adjacency, period: f64) {
        self.channel = self
            .model
            .channel
            .as_ref()
            .map(|c| Channel::new(c, neighbours, self.seed, period));
    }

    /// The shared channel's counters, if there is one.
    pub fn channel_stats(&self) -> Option<ChannelStats> {
        self.channel.as_ref().map(Channel::stats)
    }

    /// The agents' positions (for the channel's radio range; ignored without one).
    pub fn observe(&mut self, q: &[Vec2<f64>]) {
        if let Some(c) = &mut self.channel {
            c.set_positions(q);
        }
    }

    /// The counters.
    pub fn stats(&self) -> &RadioStats {
        &self.stats
    }

    /// Frames in flight.
    pub fn in_flight(&self) -> usize {
        self.queue.len()
    }

    fn chance(&mut self, p: f64) -> bool {
        p > 0.0 && self.rng.random::<f64>() < p
    }

    fn jitter(&mut self) -> f64 {
        if self.model.jitter > 0.0 {
            self.model.jitter * self.rng.random::<f64>()
        } else {
            0.0
        }
    }

    fn push(&mut self, at: f64, to: usize, from: usize, born: f64, frame: RadioFrame) {
        self.order += 1;
        self.queue.push(InFlight {
            at,
            order: self.order,
            to: to as u32,
            from: from as u32,
            born,
            frame,
        });
    }

    /// Broadcasts `bytes` from agent `from` at time `now` to `receivers`.
    pub fn broadcast(&mut self, now: f64, from: usize, receivers: &[usize], bytes: &[u8]) {
        self.broadcast_frame(now, from, receivers, RadioFrame::new(bytes));
    }

    /// [`Self::broadcast`] of a frame already made.
    pub fn broadcast_frame(
        &mut self,
        now: f64,
        from: usize,
        receivers: &[usize],
        frame: RadioFrame,
    ) {
        let bytes = frame.as_bytes();
        self.stats.broadcasts += 1;
        let copies = receivers.len() as u64;
        self.stats.sent += copies;
        bump(&mut self.sent_from, from, copies);
        if let Some(c) = &mut self.channel {
            if !c.transmit(now, from, frame, self.model.queue_limit) {
                self.stats.queue_dropped += copies;
                bump(&mut self.lost_from, from, copies);
            }
            return;
        }
        // Air time: the sender transmits one frame at a time.
        let mut on_air = now;
        if self.model.bandwidth > 0.0 {
            let busy = self.busy_until.get(from).copied().unwrap_or(now);
            let start = busy.max(now);
            if start - now > self.model.queue_limit + TIME_EPS {
                self.stats.queue_dropped += copies;
                bump(&mut self.lost_from, from, copies);
                return;
            }
            // Bits over bits per second (×8 and the old bytes/s ×8 give the same quotient).
            on_air = start + bytes.len() as f64 * 8.0 / self.model.bandwidth;
            if let Some(b) = self.busy_until.get_mut(from) {
                *b = on_air;
            }
        }
        for &to in receivers {
            self.link_copy(on_air, now, from, to, frame);
        }
    }

    /// Counts a sender's `frames` broadcast to `receivers` radio neighbours when the
    /// simulator delivers them itself (ideal radio, [`super::sampled::direct_radio`]).
    pub fn count_direct(&mut self, frames: usize, receivers: usize) {
        self.count_direct_sums(frames as u64, (frames * receivers) as u64);
    }

    /// [`Self::count_direct`] for many senders at once: `frames` broadcasts and their
    /// `copies` to all receivers.
    pub fn count_direct_sums(&mut self, frames: u64, copies: u64) {
        self.stats.broadcasts += frames;
        self.stats.sent += copies;
    }

    /// Counts copies the simulator delivered itself ([`Self::count_direct`]).
    pub fn count_delivered(&mut self, copies: u64) {
        self.stats.delivered += copies;
    }

    /// A frame from outside the swarm (an attacker, [`super::attack`]) at `now`: one link
    /// copy to each of `receivers`, with the per-link faults, outside the shared channel.
    pub fn inject(&mut self, now: f64, receivers: &[usize], bytes: &[u8]) {
        let frame = RadioFrame::new(bytes);
        for &to in receivers {
            self.link_copy(now, now, EXTERNAL, to, frame);
        }
    }

    /// A transmission from outside the swarm on the shared channel, starting at `at`
    /// from `position` (everyone hears it without one): it occupies the medium and
    /// collides, and is delivered to no one. `false` (nothing done) without a channel.
    pub fn transmit_external(&mut self, at: f64, position: Option<[f64; 2]>, bytes: &[u8]) -> bool {
        match &mut self.channel {
            Some(c) => {
                c.transmit_external(at, position, bytes.len());
                true
            }
            None => false,
        }
    }

    /// One link copy of a frame produced at `born` by `from`, off the air at `on_air`:
    /// loss, corruption, latency + jitter, reordering, duplication.
    fn link_copy(&mut self, on_air: f64, born: f64, from: usize, to: usize, frame: RadioFrame) {
        if self.chance(self.model.loss) {
            self.stats.lost += 1;
            bump(&mut self.lost_from, from, 1);
            return;
        }
        let mut copy = frame;
        if self.chance(self.model.corruption) {
            let bit = self.rng.random_range(0..copy.as_bytes().len().max(1) * 8);
            copy.flip(bit);
            self.stats.corrupted += 1;
        }
        let mut at = on_air + self.model.latency + self.jitter();
        if self.chance(self.model.reordering) {
            at += self.model.reorder_delay * (1.0 - self.rng.random::<f64>());
            self.stats.reordered += 1;
        }
        self.push(at, to, from, born, copy);
        if self.chance(self.model.duplication) {
            let again = on_air + self.model.latency + self.jitter();
            self.push(again, to, from, born, copy);
            self.stats.duplicated += 1;
        }
    }

    /// Each agent's link copies sent and, of those, never delivered (random loss, a
    /// full queue, the channel's collisions and range), in agent order. Empty when the
    /// simulator delivered the copies itself ([`Self::count_direct`]: nothing is lost).
    pub fn loss_by_sender(&self) -> Vec<(u64, u64)> {
        let channel = self.channel.as_ref().map(Channel::lost_from);
        self.sent_from
            .iter()
            .zip(&self.lost_from)
            .enumerate()
            .map(|(i, (&sent, &lost))| {
                let more = channel.and_then(|c| c.get(i)).copied().unwrap_or(0);
                (sent, lost + more)
            })
            .collect()
    }

    /// Hands every copy due by `now` to its receiver's inbox, in arrival order.
    pub fn deliver(&mut self, now: f64, inboxes: &mut [Vec<RadioFrame>]) {
        if let Some(mut c) = self.channel.take() {
            c.resolve(now, |end, born, from, to, frame| {
                self.link_copy(end, born, from, to, frame);
            });
            self.stats.channel_lost = c.lost_copies();
            self.channel = Some(c);
        }
        while let Some(top) = self.queue.peek() {
            if top.at > now + TIME_EPS {
                break;
            }
            if let Some(f) = self.queue.pop() {
                if let Some(inbox) = inboxes.get_mut(f.to as usize) {
                    inbox.push(f.frame);
                    self.stats.delivered += 1;
                    if let (Some(c), false) = (&mut self.channel, f.from as usize == EXTERNAL) {
                        c.heard(f.to as usize, f.from as usize, f.born);
                    }
                }
            }
        }
        if let Some(c) = &mut self.channel {
            c.sample_ages(now);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn model() -> RadioModel {
        RadioModel::ideal()
    }

    #[test]
    fn ideal_radio_delivers_in_order() {
        let mut r = Radio::new(&model(), 3, 1, 16);
        r.broadcast(0.0, 0, &[1, 2], &[1, 2, 3]);
        r.broadcast(0.0, 1, &[0], &[4]);
        let mut inboxes = vec![Vec::new(); 3];
        r.deliver(0.0, &mut inboxes);
        assert_eq!(inboxes[1][0].as_bytes(), &[1, 2, 3]);
        assert_eq!(inboxes[2][0].as_bytes(), &[1, 2, 3]);
        assert_eq!(inboxes[0][0].as_bytes(), &[4]);
        assert_eq!(r.stats().sent, 3);
        assert_eq!(r.stats().delivered, 3);
    }

    #[test]
    fn latency_and_loss() {
        let mut m = model();
        m.latency = 0.02;
        m.loss = 0.5;
        let mut r = Radio::new(&m, 2, 7, 16);
        for k in 0..1000 {
            r.broadcast(f64::from(k) * 0.01, 0, &[1], &[9]);
        }
        let mut inboxes = vec![Vec::new(); 2];
        r.deliver(0.015, &mut inboxes);
        assert!(inboxes[1].is_empty());
        r.deliver(100.0, &mut inboxes);
        let got = inboxes[1].len();
        assert!((400..600).contains(&got), "{got}");
        assert_eq!(r.stats().lost as usize + got, 1000);
    }

    #[test]
    fn bandwidth_queue_drops() {
        let mut m = model();
        m.bandwidth = 800.0; // bits/s: 60-byte frames take 0.6 s each
        m.queue_limit = 1.0;
        let mut r = Radio::new(&m, 2, 7, 16);
        for _ in 0..5 {
            r.broadcast(0.0, 0, &[1], &[0; 60]);
        }
        // Starts at 0, 0.6, 1.2 (> 1.0 queue limit: dropped), …
        assert_eq!(r.stats().queue_dropped, 3);
    }

    #[test]
    fn duplication_and_reordering() {
        let mut m = model();
        m.duplication = 1.0;
        let mut r = Radio::new(&m, 2, 3, 16);
        r.broadcast(0.0, 0, &[1], &[7]);
        let mut inboxes = vec![Vec::new(); 2];
        r.deliver(0.0, &mut inboxes);
        assert_eq!(inboxes[1].len(), 2);
        assert_eq!(r.stats().duplicated, 1);

        let mut m = model();
        m.reordering = 1.0;
        m.reorder_delay = 0.05;
        let mut r = Radio::new(&m, 2, 3, 16);
        r.broadcast(0.0, 0, &[1], &[1]);
        let mut inboxes = vec![Vec::new(); 2];
        r.deliver(0.0, &mut inboxes);
        assert!(inboxes[1].is_empty(), "held back");
        r.deliver(0.05, &mut inboxes);
        assert_eq!(inboxes[1].len(), 1);
        assert_eq!(r.stats().reordered, 1);
    }

    #[test]
    fn corruption_flips_one_bit() {
        let mut m = model();
        m.corruption = 1.0;
        let mut r = Radio::new(&m, 2, 3, 16);
        r.broadcast(0.0, 0, &[1], &[0; 10]);
        let mut inboxes = vec![Vec::new(); 2];
        r.deliver(0.0, &mut inboxes);
        let ones: u32 = inboxes[1][0]
            .as_bytes()
            .iter()
            .map(|b| b.count_ones())
            .sum();
        assert_eq!(ones, 1);
    }
}
