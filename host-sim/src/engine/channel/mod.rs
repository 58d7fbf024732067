//! The shared radio channel (`docs/radio.md`): every agent within radio range shares
//! one medium with a bit rate, a per-frame overhead and a transmitter turnaround.
//!
//! A broadcast becomes one *transmission* on the air, `[start, end)` with
//! `end − start = (payload + overhead) · 8 / bit_rate`. Its start follows the access
//! scheme ([`crate::model::Access`]):
//! - `aloha`: uniform in `[t, t + aloha_window)` after its tick `t` (unsynchronised
//!   clocks, no carrier sense), plus the turnaround; an agent's frames of one tick go
//!   back to back;
//! - `tdma`: agent `i` owns slot `i` of a superframe of `n` slots; a frame waits for the
//!   first own slot with room for its turnaround and air time.
//!
//! A copy of a transmission `f` to receiver `r` (one of the sender's radio neighbours
//! within range) is lost to a collision when another transmission overlapping `f` in
//! time comes from an agent `r` hears, or from `r` itself (half duplex). Transmissions
//! are resolved when they have ended: sorted by start time, each is compared with its
//! neighbours in that order only (those starting less than one longest air time
//! before it and those starting before it ends), so the cost is linear in the number
//! of transmissions when few overlap. Survivors then suffer the per-link faults of
//! [`super::radio`] (loss, corruption, latency, jitter, reordering, duplication).
//!
//! Deterministic: its own seeded random stream; no allocation per frame (the pending
//! list is preallocated and reused).

mod age;
mod stats;

pub use stats::{lossy_note, ChannelStats, ALOHA_LOAD_TARGET, LOSSY_SHARE, TIMEOUT_BROADCASTS};

use super::frame::RadioFrame;
use crate::model::graph::Adjacency;
use crate::model::{Access, ChannelModel};
use age::Ages;
use ph_formation_core::{Vec2, MAX_FRAME_LEN};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

/// Random stream of the channel (independent of the sensors' and the links').
const CHANNEL_STREAM: u64 = 3;
/// Tolerance on instants (s): intervals that only touch do not overlap.
const EPS: f64 = 1e-12;

/// One frame on the air.
#[derive(Clone, Copy, Debug)]
struct Transmission {
    start: f64,
    end: f64,
    /// Tick at which the sender produced it.
    born: f64,
    from: u32,
    order: u64,
    /// Already delivered (kept only as an interferer of later-ending transmissions).
    done: bool,
    frame: RadioFrame,
}

/// The shared medium between all agents.
#[derive(Debug)]
pub struct Channel {
    model: ChannelModel,
    rng: ChaCha8Rng,
    pending: Vec<Transmission>,
    next_free: Vec<f64>,
    positions: Vec<Vec2<f64>>,
    neighbours: Adjacency,
    ages: Ages,
    max_air: f64,
    superframe: f64,
    order: u64,
    stats: ChannelStats,
    /// Transmitters outside the swarm (attackers): their positions, `None` = heard by
    /// everyone. Transmitter `n + k` is `external[k]`.
    external: Vec<Option<Vec2<f64>>>,
    /// Each agent's link copies lost (collisions, out of range), by sender.
    lost_from: Vec<u64>,
}

impl Channel {
    /// A channel for the agents of `neighbours` (the radio graph), seeded; `period` is
    /// the control period (s), used to size the pending list.
    pub fn new(model: &ChannelModel, neighbours: &Adjacency, seed: u64, period: f64) -> Self {
        let n = neighbours.len();
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        rng.set_stream(CHANNEL_STREAM);
        let superframe = model.superframe(n);
        let span = model.aloha_window.max(superframe) + model.slot;
        let ticks = (span / period.max(1e-9)).ceil().min(1e4) as usize + 2;
        Self {
            model: model.clone(),
            rng,
            pending: Vec::with_capacity((n * 4 * ticks).min(1 << 20)),
            next_free: vec![f64::NEG_INFINITY; n],
            positions: vec![Vec2::zeros(); n],
            neighbours: neighbours.clone(),
            ages: Ages::new(neighbours),
            max_air: model.air_time(MAX_FRAME_LEN),
            superframe,
            order: 0,
            stats: ChannelStats::default(),
            external: Vec::new(),
            lost_from: vec![0; n],
        }
    }

    /// The counters so far.
    pub fn stats(&self) -> ChannelStats {
        let mut s = self.stats;
        self.ages.write(&mut s);
        s
    }

    /// Link copies each agent sent that were lost so far (collisions and out of range).
    pub fn lost_from(&self) -> &[u64] {
        &self.lost_from
    }

    /// Link copies lost so far (collisions and out of range).
    pub fn lost_copies(&self) -> u64 {
        self.stats.collided + self.stats.out_of_range
    }

    /// Agent positions, used for the radio range (call before [`Self::resolve`]).
    pub fn set_positions(&mut self, q: &[Vec2<f64>]) {
        for (p, x) in self.positions.iter_mut().zip(q) {
            *p = *x;
        }
    }

    fn in_range(&self, a: usize, b: usize) -> bool {
        match (self.model.range, self.position(a), self.position(b)) {
            (Some(r), Some(p), Some(q)) => (p - q).norm() <= r,
            _ => true,
        }
    }

    /// Where transmitter `i` is: an agent, or an external one with a position.
    fn position(&self, i: usize) -> Option<Vec2<f64>> {
        match i.checked_sub(self.positions.len()) {
            None => self.positions.get(i).copied(),
            Some(k) => self.external.get(k).copied().flatten(),
        }
    }

    /// Puts a transmission from outside the swarm (an attacker) of `len` bytes on the
    /// air at `start`, from `position` (heard by everyone without one). It collides with
    /// what overlaps it and is delivered to no one.
    pub fn transmit_external(&mut self, start: f64, position: Option<[f64; 2]>, len: usize) {
        let p = position.map(|p| Vec2::new(p[0], p[1]));
        let k = match self.external.iter().position(|e| *e == p) {
            Some(k) => k,
            None => {
                self.external.push(p);
                self.external.len() - 1
            }
        };
        let air = self.model.air_time(len);
        self.stats.external_transmissions += 1;
        self.stats.external_air_time += air;
        self.order += 1;
        self.pending.push(Transmission {
            start,
            end: start + air,
            born: start,
            from: (self.positions.len() + k) as u32,
            order: self.order,
            done: false,
            frame: RadioFrame::new(&[]),
        });
    }

    /// Earliest start on the air (after the turnaround) of a frame of agent `from`
    /// produced at `now`, ready no earlier than `ready`, lasting `air`.
    fn start_of(&mut self, now: f64, from: usize, ready: f64, air: f64) -> f64 {
        let turn = self.model.turnaround;
        match self.model.access {
            Access::Aloha => {
                let offset = if self.model.aloha_window > 0.0 {
                    self.model.aloha_window * self.rng.random::<f64>()
                } else {
                    0.0
                };
                (now + offset).max(ready) + turn
            }
            Access::Tdma => {
                let (slot, sf) = (self.model.slot, self.superframe);
                let own = from as f64 * slot;
                // The own slot that contains `ready`, or the next one.
                let m = ((ready - own) / sf).floor();
                let s = own + m * sf;
                if ready >= s - EPS && ready + turn + air <= s + slot + EPS {
                    ready + turn
                } else {
                    own + (m + 1.0) * sf + turn
                }
            }
        }
    }

    /// Puts a frame of agent `from`, produced at `now`, on the air. Returns `false`
    /// (and puts nothing on the air) when it would wait longer than `queue_limit` s
    /// for the medium.
    pub fn transmit(&mut self, now: f64, from: usize, frame: RadioFrame, queue_limit: f64) -> bool {
        let air = self.model.air_time(frame.as_bytes().len());
        let ready = self.next_free.get(from).copied().unwrap_or(now).max(now);
        let start = self.start_of(now, from, ready, air);
        let wait = start - self.model.turnaround - now;
        if wait > queue_limit + 1e-9 {
            self.stats.access_dropped += 1;
            return false;
        }
        if let Some(nf) = self.next_free.get_mut(from) {
            *nf = start + air;
        }
        self.stats.transmissions += 1;
        self.stats.air_time += air;
        self.stats.max_access_wait = self.stats.max_access_wait.max(wait);
        self.order += 1;
        self.pending.push(Transmission {
            start,
            end: start + air,
            born: now,
            from: from as u32,
            order: self.order,
            done: false,
            frame,
        });
        true
    }

    /// Whether the copy of transmission `k` to `to` is lost to an overlapping one that
    /// `to` hears (or sends itself), and how many transmissions were inspected.
    /// `pending` is sorted by start.
    fn collides(&self, k: usize, to: usize) -> (bool, u64) {
        let Some(f) = self.pending.get(k) else {
            return (false, 0);
        };
        let hears = |g: &Transmission| {
            let from = g.from as usize;
            from == to || self.in_range(to, from)
        };
        let mut seen = 0;
        let earlier = self.pending.get(..k).unwrap_or(&[]);
        for g in earlier.iter().rev() {
            if g.start < f.start - self.max_air - EPS {
                break;
            }
            seen += 1;
            if g.end > f.start + EPS && hears(g) {
                return (true, seen);
            }
        }
        let later = self.pending.get(k + 1..).unwrap_or(&[]);
        for g in later {
            if g.start >= f.end - EPS {
                break;
            }
            seen += 1;
            if hears(g) {
                return (true, seen);
            }
        }
        (false, seen)
    }

    /// Resolves every transmission that has ended by `now`: each copy to a radio
    /// neighbour that is in range and free of collisions is passed to
    /// `copy(end, born, from, to, frame)`, in start order, receivers in index order.
    pub fn resolve(&mut self, now: f64, mut copy: impl FnMut(f64, f64, usize, usize, RadioFrame)) {
        self.pending.sort_unstable_by(|a, b| {
            a.start
                .total_cmp(&b.start)
                .then_with(|| a.order.cmp(&b.order))
        });
        for k in 0..self.pending.len() {
            let Some(&f) = self.pending.get(k) else {
                break;
            };
            if f.done || f.end > now + 1e-9 {
                continue;
            }
            let from = f.from as usize;
            if from >= self.positions.len() {
                // From outside the swarm: interference only.
                if let Some(t) = self.pending.get_mut(k) {
                    t.done = true;
                }
                continue;
            }
            let mut lost = false;
            for &to in self.neighbours.of(from) {
                if !self.in_range(from, to) {
                    self.stats.out_of_range += 1;
                    bump(&mut self.lost_from, from, 1);
                    continue;
                }
                let (collided, seen) = self.collides(k, to);
                self.stats.inspected += seen;
                if collided {
                    self.stats.collided += 1;
                    bump(&mut self.lost_from, from, 1);
                    lost = true;
                } else {
                    copy(f.end, f.born, from, to, f.frame);
                }
            }
            self.stats.collided_transmissions += u64::from(lost);
            if let Some(t) = self.pending.get_mut(k) {
                t.done = true;
            }
        }
        // A pending transmission ends after `now`, so it started after
        // `now − max_air`: older delivered ones can no longer overlap anything.
        let keep_after = now - self.max_air - 1e-9;
        self.pending.retain(|t| !t.done || t.end > keep_after);
    }

    /// Records that `to` received a frame of `from` produced at `born`.
    pub fn heard(&mut self, to: usize, from: usize, born: f64) {
        self.ages.heard(&self.neighbours, to, from, born);
    }

    /// Samples the age of every link's newest data at control instant `now`.
    pub fn sample_ages(&mut self, now: f64) {
        self.ages.sample(now);
    }
}

#[cfg(test)]
mod tests;

/// `counts[i] += by` (nothing for an index outside: a transmitter outside the swarm).
pub(crate) fn bump(counts: &mut [u64], i: usize, by: u64) {
    if let Some(c) = counts.get_mut(i) {
        *c += by;
    }
}
