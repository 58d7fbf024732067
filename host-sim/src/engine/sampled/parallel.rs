//! The parallel tick of [`SampledSim`]: every agent's sensing, controller tick, force and
//! counters on every thread of the current rayon pool, bit-identical to the sequential
//! tick (`tests/scaling.rs`). Only the sensors' random draws (one stream, in agent order)
//! and the radio's broadcasts (idem) stay sequential; the draws of one block of agents
//! are made while the other threads tick the blocks drawn before.

use super::{own_measurement, prefetch_agent, quiet_own, MeasureMode, SampledSim, CHUNK};
use crate::engine::controller::AgentController;
use crate::engine::prefetch;
use crate::engine::radio::RadioFrame;
use crate::engine::sensors::{in_sight, quiet_bearing, BearingNoise, Sensors, Sight};
use crate::engine::stats::ControlStats;
use crate::model::graph::Adjacency;
use crate::model::SensorModel;
use controller_core::{BearingMeasurement, Measurements, Vec2, MAX_NEIGHBOURS};
use rayon::prelude::*;

/// What the parallel walk of a tick sums over the agents (in agent order).
#[derive(Clone, Copy, Debug, Default)]
pub(super) struct TickSums {
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

// An agent's triangle neighbours fit the bits of `SampledSim::in_sight` (a local core
// holds at most `MAX_NEIGHBOURS`; the parallel path runs only local cores).
const _: () = assert!(MAX_NEIGHBOURS <= 64);

/// Agents drawn before the other threads may tick them: a work item of the noisy tick
/// (small enough that the threads end a tick together, about 90 µs of work).
const BLOCK: usize = 256;

/// What an agent's tick reads of the others (shared by every thread).
struct Walk<'a> {
    t: f64,
    dt: f64,
    mode: MeasureMode,
    graph: &'a Adjacency,
    radio: &'a Adjacency,
    partner: &'a [Option<usize>],
    q: &'a [Vec2<f64>],
    v: &'a [Vec2<f64>],
    ids: &'a [u8],
    sensors: &'a SensorModel,
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

/// What agent `i` measured with drawn noise: its bearings' noise (graph order) and its
/// velocity and partner offset.
type Drawn<'d> = (&'d [Option<BearingNoise>], (Vec2<f64>, Option<Vec2<f64>>));

impl Walk<'_> {
    /// Agent `i`'s tick: its bearings ([`Sensors::bearing_with`], in its core's slot
    /// order) from the `drawn` noise, or without one from the state alone (sensors that
    /// draw nothing), its controller's tick, its force; returns its counters.
    fn agent(&self, i: usize, a: AgentSlots<'_>, drawn: Option<Drawn<'_>>) -> TickSums {
        // Within a work item, the agents ahead are this thread's next ones.
        prefetch_agent(self.footprints, self.sent, i + prefetch::AHEAD);
        let (q, v) = (self.q, self.v);
        // A local core holds every triangle neighbour in at most MAX_NEIGHBOURS slots: the
        // buffer holds every bearing.
        let mut bearings: heapless::Vec<BearingMeasurement<f64>, MAX_NEIGHBOURS> =
            heapless::Vec::new();
        for (k, &j) in self.graph.of(i).iter().enumerate() {
            let sight = Sight::between(self.ids, q, v, i, j);
            let b = match drawn {
                Some((noise, _)) => noise
                    .get(k)
                    .copied()
                    .flatten()
                    .map(|n| Sensors::bearing_with(self.sensors, n, &sight, self.mode.exact)),
                None => quiet_bearing(self.sensors, &sight, self.mode.exact, self.mode.ranged),
            };
            if let Some(b) = b {
                let _ = bearings.push(b);
            }
        }
        self.slot_order.apply(i, &mut bearings);
        let (velocity, partner_offset) = match drawn {
            Some((_, own)) => own,
            None => quiet_own(self.sensors, q, v, self.partner, i),
        };
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
    /// For every agent, on every thread, which of its triangle neighbours it can see
    /// ([`in_sight`]: no bearing, and no draw, for the others).
    fn find_in_sight(&mut self) {
        let graph = &self.model.graph.triangle;
        let (q, v, ids) = (&self.plant.q, &self.plant.v, &self.ids);
        self.in_sight
            .par_iter_mut()
            .enumerate()
            .with_min_len(CHUNK)
            .for_each(|(i, mask)| {
                // Bit k: the k-th triangle neighbour (at most MAX_NEIGHBOURS < 64).
                *mask = graph.of(i).iter().enumerate().fold(0, |m, (k, &j)| {
                    let seen = in_sight(&Sight::between(ids, q, v, i, j));
                    m | (u64::from(seen) << k)
                });
            });
    }

    /// Every agent's tick on every thread ([`Walk::agent`]), its force, and the counters
    /// and statistics of all, summed in agent order. Sensors that draw random numbers
    /// draw them in agent order (the stream as in [`Self::tick_sequential`]: each
    /// agent's bearings, then its velocity and offset), one block of agents at a time on
    /// this thread while the others tick the blocks already drawn; sensors that draw
    /// nothing are read on every thread.
    pub(super) fn tick_parallel(&mut self, t: f64, dt: f64) {
        let mode = self.measure_mode();
        let draws = !mode.quiet;
        if draws {
            self.find_in_sight();
        }
        let sensor_model = self.sensors.model().clone();
        let model = self.model;
        let walk = Walk {
            t,
            dt,
            mode,
            graph: &model.graph.triangle,
            radio: &model.graph.radio,
            partner: &self.partner,
            q: &self.plant.q,
            v: &self.plant.v,
            ids: &self.ids,
            sensors: &sensor_model,
            slot_order: &self.slot_order,
            sent: &self.sent,
            footprints: &self.footprints,
        };
        let agents = Agents {
            controllers: &mut self.controllers,
            inboxes: &mut self.inboxes,
            outboxes: &mut self.outboxes,
            forces: &mut self.forces,
        };
        let sums = if draws {
            let draw = Draw {
                sensors: &mut self.sensors,
                in_sight: &self.in_sight,
                noise_start: &self.noise_start,
                partner: &self.partner,
                q: &self.plant.q,
                v: &self.plant.v,
                ranged: mode.ranged,
            };
            let out = (&mut self.noise_all[..], &mut self.measured[..]);
            pipelined(&walk, draw, agents, out, &mut self.block_sums)
        } else {
            agents
                .par_slots()
                .enumerate()
                .with_min_len(CHUNK)
                .map(|(i, a)| walk.agent(i, a, None))
                .reduce(TickSums::default, TickSums::then)
        };
        self.count_direct(sums.delivered);
        if self.direct {
            self.radio.count_direct_sums(sums.broadcasts, sums.copies);
        }
        self.stats.merge(&sums.stats);
    }
}

/// What the sequential draws of a noisy tick need.
struct Draw<'a> {
    sensors: &'a mut Sensors,
    in_sight: &'a [u64],
    noise_start: &'a [usize],
    partner: &'a [Option<usize>],
    q: &'a [Vec2<f64>],
    v: &'a [Vec2<f64>],
    ranged: bool,
}

impl Draw<'_> {
    /// Agents `lo..lo + own.len()`'s draws, in agent order, into `noise` (their bearings',
    /// from `noise_start[lo]`) and `own` (velocity and partner offset).
    fn block(
        &mut self,
        lo: usize,
        noise: &mut [Option<BearingNoise>],
        own: &mut [(Vec2<f64>, Option<Vec2<f64>>)],
    ) {
        let base = self.noise_start.get(lo).copied().unwrap_or(0);
        for (i, own) in (lo..).zip(own.iter_mut()) {
            let (a, b) = (self.noise_start[i] - base, self.noise_start[i + 1] - base);
            let mask = self.in_sight[i];
            for (k, slot) in noise[a..b].iter_mut().enumerate() {
                *slot = (mask >> k & 1 == 1).then(|| self.sensors.draw_noise(self.ranged));
            }
            *own = own_measurement(self.sensors, self.q, self.v, self.partner, i);
        }
    }
}

/// Every agent's part of a tick, as slices in agent order.
struct Agents<'s> {
    controllers: &'s mut [Box<dyn AgentController>],
    inboxes: &'s mut [Vec<RadioFrame>],
    outboxes: &'s mut [Vec<RadioFrame>],
    forces: &'s mut [Vec2<f64>],
}

impl<'s> Agents<'s> {
    /// The first `len` agents, and the rest.
    fn split(self, len: usize) -> (Self, Self) {
        let (c0, c1) = self.controllers.split_at_mut(len);
        let (i0, i1) = self.inboxes.split_at_mut(len);
        let (o0, o1) = self.outboxes.split_at_mut(len);
        let (f0, f1) = self.forces.split_at_mut(len);
        let first = Self {
            controllers: c0,
            inboxes: i0,
            outboxes: o0,
            forces: f0,
        };
        let rest = Self {
            controllers: c1,
            inboxes: i1,
            outboxes: o1,
            forces: f1,
        };
        (first, rest)
    }

    /// Each agent's slots, on every thread (a block's walk takes them as one piece).
    fn par_slots(self) -> impl IndexedParallelIterator<Item = AgentSlots<'s>> {
        let Self {
            controllers,
            inboxes,
            outboxes,
            forces,
        } = self;
        let each = controllers
            .par_iter_mut()
            .zip(inboxes)
            .zip(outboxes)
            .zip(forces);
        each.map(AgentSlots::of)
    }
}

/// One agent's four parts, as the zipped walks give them.
type Zipped<'s> = (
    (
        (&'s mut Box<dyn AgentController>, &'s mut Vec<RadioFrame>),
        &'s mut Vec<RadioFrame>,
    ),
    &'s mut Vec2<f64>,
);

impl<'s> AgentSlots<'s> {
    /// The slots of one zipped agent.
    fn of((((controller, inbox), outbox), force): Zipped<'s>) -> Self {
        Self {
            controller,
            inbox,
            outbox,
            force,
        }
    }
}

/// What the draws of a noisy tick fill: every bearing's noise, every agent's velocity
/// and partner offset.
type DrawnAll<'a> = (
    &'a mut [Option<BearingNoise>],
    &'a mut [(Vec2<f64>, Option<Vec2<f64>>)],
);

/// The noisy tick: blocks of [`BLOCK`] agents drawn in agent order on this thread, each
/// handed to the pool as soon as it is drawn; the blocks' sums (in `block_sums`, one per
/// block) added in agent order.
fn pipelined(
    walk: &Walk<'_>,
    mut draw: Draw<'_>,
    agents: Agents<'_>,
    drawn: DrawnAll<'_>,
    block_sums: &mut Vec<TickSums>,
) -> TickSums {
    let n = agents.controllers.len();
    block_sums.clear();
    block_sums.resize(n.div_ceil(BLOCK), TickSums::default());
    let starts = draw.noise_start;
    rayon::scope(|s| {
        let (mut agents, (mut noise_rest, mut own_rest)) = (agents, drawn);
        for (b, sum) in block_sums.iter_mut().enumerate() {
            let lo = b * BLOCK;
            let len = BLOCK.min(n - lo);
            let (block, rest) = agents.split(len);
            agents = rest;
            let pairs = starts[lo + len] - starts[lo];
            let (noise, rest) = std::mem::take(&mut noise_rest).split_at_mut(pairs);
            noise_rest = rest;
            let (own, rest) = std::mem::take(&mut own_rest).split_at_mut(len);
            own_rest = rest;
            draw.block(lo, noise, own);
            let (noise, own) = (&*noise, &*own);
            s.spawn(move |_| {
                // One piece (`with_min_len`): this task walks its block in agent order.
                *sum = block
                    .par_slots()
                    .enumerate()
                    .with_min_len(BLOCK)
                    .map(|(k, a)| {
                        let i = lo + k;
                        let mine = &noise[starts[i] - starts[lo]..starts[i + 1] - starts[lo]];
                        walk.agent(i, a, Some((mine, own[k])))
                    })
                    .reduce(TickSums::default, TickSums::then);
            });
        }
    });
    block_sums
        .iter()
        .fold(TickSums::default(), |a, b| a.then(*b))
}
