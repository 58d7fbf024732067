//! The radio-delivery stage of [`super::SampledSim`]: every agent's inbox and outbox,
//! the radio model ([`Radio`]) with its attackers, and the frames a bearing sensor sends
//! over the radio ([`BearingSensor::radio_packet`], [`BearingSensor::hear_radio`]).
//!
//! Two delivery paths, with the same result: frames go through [`Radio`] (faults, delays,
//! the shared channel, attacks), or, when the radio is ideal in timing and faults
//! ([`direct_radio`]), each receiver reads its radio neighbours' frames of the previous
//! tick straight from their outboxes, in sender order, which is exactly what the radio's
//! queue would have delivered.

use crate::engine::attack::Attacks;
use crate::engine::controller::Inbox;
use crate::engine::radio::{Radio, RadioFrame};
use crate::engine::sensors::BearingSensor;
use crate::model::graph::Adjacency;
use crate::model::Model;
use ph_formation_core::Vec2;

/// Frames one agent emits per tick, at most, in the standard capacity (used to
/// preallocate; an outbox holds one tick's frames).
const FRAMES_PER_TICK: usize = ph_formation_core::StandardAgent::<f64>::MAX_FRAMES_PER_TICK;

/// Whether every frame of a tick arrives, unchanged and in sender order, at the next tick:
/// nothing in the radio alters frames ([`RadioModel::departures`](crate::model::RadioModel::departures),
/// the one classification of its fields), a latency under half a control period, no
/// attacker, and no position packets (`sensors.bearing_source = "shared_positions"`).
pub fn direct_radio(model: &Model) -> bool {
    let d = model.radio.departures();
    !d.alters_frames
        && d.latency < 0.5 * model.control_period()
        && model.attacks.is_empty()
        // Position packets (`sensors/shared_positions.rs`) go through the radio's queue.
        && model.sensors.positions.is_none()
}

/// The mailboxes and the radio between the agents.
pub(super) struct Delivery {
    pub(super) radio: Radio,
    pub(super) attacks: Attacks,
    pub(super) inboxes: Vec<Vec<RadioFrame>>,
    pub(super) outboxes: Vec<Vec<RadioFrame>>,
    /// Direct delivery: the outboxes of the last tick, which the receivers read in place
    /// (swapped with `outboxes` at every tick).
    pub(super) sent: Vec<Vec<RadioFrame>>,
    /// Frames bypass [`Radio`]'s queue ([`direct_radio`]).
    pub(super) direct: bool,
    /// Agents whose radio is off at this tick (`[[faults]]`): what the radio delivers to
    /// them is dropped before anyone reads it.
    pub(super) deaf: Vec<bool>,
}

impl Delivery {
    /// The radio of `model`'s run, every queue preallocated; `direct`: frames bypass the
    /// radio's queue.
    pub(super) fn new(model: &Model, direct: bool) -> Self {
        let n = model.n();
        let period = model.control_period();
        let r = &model.radio;
        let mut delay = r.latency + r.jitter + r.reorder_delay;
        if r.bandwidth > 0.0 {
            delay += r.queue_limit;
        }
        // Frames delayed beyond the run never arrive: size for at most the run.
        let ticks_in_flight = (delay.min(model.duration) / period).ceil().min(1e4) as usize + 2;
        let links = model.graph.radio.total();
        let capacity = (links * FRAMES_PER_TICK * 2)
            .saturating_mul(ticks_in_flight)
            .min(1 << 20);
        // Direct delivery reads the senders' frames in place: no inbox.
        let inboxes = (0..n)
            .map(|i| {
                let frames = model.graph.radio.of(i).len() * FRAMES_PER_TICK * 4 + 8;
                Vec::with_capacity(if direct { 0 } else { frames })
            })
            .collect();
        let outbox = || Vec::with_capacity(FRAMES_PER_TICK);
        let mut radio = Radio::new(&model.radio, n, model.seed, capacity);
        radio.attach_channel(&model.graph.radio, period);
        Self {
            radio,
            attacks: Attacks::new(model),
            inboxes,
            outboxes: (0..n).map(|_| outbox()).collect(),
            sent: (0..if direct { n } else { 0 }).map(|_| outbox()).collect(),
            direct,
            deaf: Vec::new(),
        }
    }

    /// The start of a control tick at `t` (index `tick`), with the true positions `q`:
    /// with direct delivery the frames of the last tick stay where their senders left
    /// them; otherwise the radio observes the state, the attackers act, the radio
    /// delivers what is due, and the bearing sensor takes its packets out of the inboxes.
    pub(super) fn receive(
        &mut self,
        model: &Model,
        t: f64,
        tick: u64,
        q: &[Vec2<f64>],
        sensor: &mut Option<Box<dyn BearingSensor>>,
    ) {
        if self.direct {
            // The frames of the last tick are read where their senders left them.
            std::mem::swap(&mut self.outboxes, &mut self.sent);
            return;
        }
        self.radio.observe(q);
        if !self.attacks.is_empty() {
            let period = model.dt * model.steps_per_tick as f64;
            self.attacks.tick(t, period, q, model, &mut self.radio);
        }
        self.radio.deliver(t, &mut self.inboxes);
        for (inbox, _) in self.inboxes.iter_mut().zip(&self.deaf).filter(|(_, d)| **d) {
            inbox.clear();
        }
        if let Some(s) = sensor.as_deref_mut() {
            s.hear_radio(t, tick, q, &mut self.inboxes);
        }
    }

    /// Agent `i`'s frames of this tick through the radio (and the attackers that
    /// overhear them), then the bearing sensor's packet of it; with direct delivery only
    /// counted (its receivers read them at the next tick).
    pub(super) fn send(
        &mut self,
        model: &Model,
        t: f64,
        i: usize,
        q: &[Vec2<f64>],
        sensor: Option<&mut (dyn BearingSensor + 'static)>,
    ) {
        let receivers = model.graph.radio.of(i);
        if self.direct {
            self.radio
                .count_direct(self.outboxes[i].len(), receivers.len());
            return;
        }
        for f in &self.outboxes[i] {
            self.radio.broadcast_frame(t, i, receivers, *f);
            if !self.attacks.is_empty() {
                self.attacks
                    .overhear(t, i, f.as_bytes(), q, model, &mut self.radio);
            }
        }
        // Its sensor's packet, after its frames, when it broadcast any: at the
        // communication rate, as the Crazyflie app sends its position
        // (`sensors/shared_positions.rs`, crazyflie-app/src/agent_loop.c).
        if self.outboxes[i].is_empty() {
            return;
        }
        if let Some(p) = sensor.and_then(|s| s.radio_packet(i)) {
            self.radio.broadcast_frame(t, i, receivers, p);
        }
    }

    /// Counts the frames `delivered` directly (none through the radio's queue).
    #[inline]
    pub(super) fn count_direct(&mut self, delivered: u64) {
        if self.direct {
            self.radio.count_delivered(delivered);
        }
    }
}

/// What agent `i` takes in at this tick: what the radio delivered, or with direct
/// delivery its radio neighbours' frames of the last tick in sender order (what
/// [`Radio`]'s queue delivers when nothing delays or changes them).
#[inline]
pub(super) fn inbox<'a>(
    delivered: &'a [RadioFrame],
    sent: &'a [Vec<RadioFrame>],
    radio: &'a Adjacency,
    i: usize,
) -> Inbox<'a> {
    let delivered = Inbox::new(delivered);
    if sent.is_empty() {
        delivered
    } else {
        delivered.with_sent(radio.of(i), sent)
    }
}
