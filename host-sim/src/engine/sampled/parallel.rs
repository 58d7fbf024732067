//! The parallel tick of [`SampledSim`]: every agent's sensing, controller tick, force and
//! counters on every thread of the current rayon pool, bit-identical to the sequential
//! tick (`tests/scaling.rs`): each agent draws its sensors' noise from its own stream of
//! the tick ([`crate::engine::sensors::Sensors::stream`]). Only the radio's broadcasts
//! (one random stream, in agent order) stay sequential.

use super::{prefetch_agent, SampledSim, Scene, CHUNK};
use crate::engine::controller::AgentController;
use crate::engine::prefetch;
use crate::engine::radio::RadioFrame;
use crate::engine::stats::ControlStats;
use crate::model::graph::Adjacency;
use controller_core::{BearingMeasurement, Measurements, Vec2, MAX_NEIGHBOURS};
use rayon::prelude::*;

/// What the parallel walk of a tick sums over the agents (in agent order).
#[derive(Clone, Copy, Debug, Default)]
struct TickSums {
    /// Frames read straight from the senders' outboxes.
    delivered: u64,
    /// Frames broadcast, and their copies to every radio neighbour.
    broadcasts: u64,
    copies: u64,
    /// The controllers' outputs.
    stats: ControlStats,
}

impl TickSums {
    /// These sums followed by `later`'s (agents after these).
    fn then(mut self, later: Self) -> Self {
        self.delivered += later.delivered;
        self.broadcasts += later.broadcasts;
        self.copies += later.copies;
        self.stats.merge(&later.stats);
        self
    }
}

/// What an agent's tick reads of the others (shared by every thread).
struct Walk<'a> {
    t: f64,
    dt: f64,
    /// The state and sensors, with this tick's index.
    scene: Scene<'a>,
    radio: &'a Adjacency,
    slot_order: &'a crate::engine::slot_order::SlotOrder,
    sent: &'a [Vec<RadioFrame>],
    footprints: &'a [crate::engine::prefetch::Footprint],
}

/// One agent's part of a tick: its controller, mailboxes and force.
struct AgentSlots<'s> {
    controller: &'s mut Box<dyn AgentController>,
    inbox: &'s mut Vec<RadioFrame>,
    outbox: &'s mut Vec<RadioFrame>,
    force: &'s mut Vec2<f64>,
}

impl Walk<'_> {
    /// Agent `i`'s tick: its measurements ([`Scene::measure`], the bearings in its core's
    /// slot order), its controller's tick, its force; returns its counters.
    fn agent(&self, i: usize, a: AgentSlots<'_>) -> TickSums {
        // Within a work item, the agents ahead are this thread's next ones.
        prefetch_agent(self.footprints, self.sent, i + prefetch::AHEAD);
        // A local core holds every triangle neighbour in at most MAX_NEIGHBOURS slots: the
        // buffer holds every bearing.
        let mut bearings: heapless::Vec<BearingMeasurement<f64>, MAX_NEIGHBOURS> =
            heapless::Vec::new();
        let (velocity, partner_offset) = self.scene.measure(i, |b| {
            let _ = bearings.push(b);
        });
        self.slot_order.apply(i, &mut bearings);
        let m = Measurements {
            time: self.t,
            dt: self.dt,
            velocity,
            bearings: &bearings,
            partner_offset,
        };
        a.outbox.clear();
        let frames = SampledSim::inbox(a.inbox, self.sent, self.radio, i);
        let delivered = frames.len() as u64;
        let out = a.controller.tick(frames, &m, a.outbox);
        a.inbox.clear();
        *a.force = out.force;
        let mut sums = TickSums {
            delivered,
            broadcasts: a.outbox.len() as u64,
            copies: (a.outbox.len() * self.radio.of(i).len()) as u64,
            stats: ControlStats::default(),
        };
        let norm = out.force.norm();
        sums.stats
            .record(self.t, i, out.status, out.saturated, out.degenerate, norm);
        sums
    }
}

impl SampledSim<'_> {
    /// Every agent's tick on every thread ([`Walk::agent`]), its force, and the counters
    /// and statistics of all, summed in agent order.
    pub(super) fn tick_parallel(&mut self, t: f64, dt: f64, tick: u64) {
        let model = self.model;
        let walk = Walk {
            t,
            dt,
            scene: Scene::of(model, &self.plant, &self.senses, tick),
            radio: &model.graph.radio,
            slot_order: &self.slot_order,
            sent: &self.sent,
            footprints: &self.footprints,
        };
        // Each agent's four parts, zipped (the slices are disjoint fields).
        let sums = self
            .controllers
            .par_iter_mut()
            .zip(&mut self.inboxes)
            .zip(&mut self.outboxes)
            .zip(&mut self.forces)
            .enumerate()
            .with_min_len(CHUNK)
            .map(|(i, (((controller, inbox), outbox), force))| {
                let slots = AgentSlots {
                    controller,
                    inbox,
                    outbox,
                    force,
                };
                walk.agent(i, slots)
            })
            .reduce(TickSums::default, TickSums::then);
        self.count_direct(sums.delivered);
        if self.direct {
            self.radio.count_direct_sums(sums.broadcasts, sums.copies);
        }
        self.stats.merge(&sums.stats);
    }
}
