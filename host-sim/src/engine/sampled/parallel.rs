//! The parallel tick of [`SampledSim`]: every agent's sensing, controller tick, force and
//! counters on every thread of the current rayon pool, bit-identical to the sequential
//! tick (`tests/scaling.rs`). Only the sensors' random draws (one stream, in agent order)
//! and the radio's broadcasts (idem) stay sequential.

use super::{prefetch_agent, SampledSim, CHUNK};
use crate::engine::prefetch;
use crate::engine::sensors::{in_sight, offset_with, quiet_noise, velocity_with, Sensors, Sight};
use crate::engine::stats::ControlStats;
use crate::model::{BearingRate, Estimator};
use controller_core::{BearingMeasurement, Measurements, MAX_NEIGHBOURS};
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

// An agent's triangle neighbours fit the bits of `SampledSim::in_sight` (a local core
// holds at most `MAX_NEIGHBOURS`; the parallel path runs only local cores).
const _: () = assert!(MAX_NEIGHBOURS <= 64);

impl SampledSim<'_> {
    /// Every random draw of the sensors in agent order, for [`Self::tick_parallel`] (the
    /// stream as in [`Self::tick_sequential`]: each agent's bearings, then its velocity
    /// and offset). Which neighbours each agent can see ([`in_sight`]: no draw for the
    /// others) is found first, on every thread; only the draws remain in order.
    fn draw_all(&mut self, ranged: bool) {
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
        self.noise_all.clear();
        self.noise_start.clear();
        for i in 0..self.model.n() {
            self.noise_start.push(self.noise_all.len());
            let mask = self.in_sight[i];
            for k in 0..graph.of(i).len() {
                let noise = (mask >> k & 1 == 1).then(|| self.sensors.draw_noise(ranged));
                self.noise_all.push(noise);
            }
            self.measured[i] = self.measure_own(i);
        }
    }

    /// Every agent's tick on every thread: its bearings ([`Sensors::bearing_with`], in
    /// its core's slot order) from the draws of [`Self::draw_all`] (or, when the sensors
    /// draw nothing, from the state alone: no sequential pass), its controller's tick,
    /// its force, and the counters and statistics of all (summed in agent order).
    pub(super) fn tick_parallel(&mut self, t: f64, dt: f64) {
        let exact = self.model.sensors.bearing_rate == BearingRate::Exact;
        let ranged = self.model.estimator == Estimator::Measured;
        let draws = self.sensors.draws(ranged);
        if draws {
            self.draw_all(ranged);
        }
        let graph = &self.model.graph.triangle;
        let partner = &self.partner;
        let (noise_all, noise_start, measured) =
            (&self.noise_all, &self.noise_start, &self.measured);
        let (q, v, ids) = (&self.plant.q, &self.plant.v, &self.ids);
        let (sensors, slot_order) = (self.sensors.model(), &self.slot_order);
        let (sent, radio) = (&self.sent, &self.model.graph.radio);
        let footprints = &self.footprints;
        let sums = self
            .controllers
            .par_iter_mut()
            .zip(self.inboxes.par_iter_mut())
            .zip(self.outboxes.par_iter_mut())
            .zip(self.forces.par_iter_mut())
            .enumerate()
            .with_min_len(CHUNK)
            .map(|(i, (((c, inbox), outbox), force))| {
                // Within a work item, the agents ahead are this thread's next ones.
                prefetch_agent(footprints, sent, i + prefetch::AHEAD);
                // A local core holds every triangle neighbour in at most MAX_NEIGHBOURS
                // slots: the buffer holds every bearing.
                let mut bearings: heapless::Vec<BearingMeasurement<f64>, MAX_NEIGHBOURS> =
                    heapless::Vec::new();
                let base = noise_start.get(i).copied().unwrap_or(0);
                for (k, &j) in graph.of(i).iter().enumerate() {
                    let sight = Sight::between(ids, q, v, i, j);
                    let noise = match draws {
                        true => noise_all.get(base + k).copied().flatten(),
                        false => in_sight(&sight).then(|| quiet_noise(ranged)),
                    };
                    if let Some(n) = noise {
                        let _ = bearings.push(Sensors::bearing_with(sensors, n, &sight, exact));
                    }
                }
                slot_order.apply(i, &mut bearings);
                let (velocity, partner_offset) = match draws {
                    true => measured[i],
                    false => (
                        velocity_with(sensors, &v[i], [0.0; 2]),
                        partner[i].map(|p| offset_with(&q[i], &q[p], [0.0; 2])),
                    ),
                };
                let m = Measurements {
                    time: t,
                    dt,
                    velocity,
                    bearings: &bearings,
                    partner_offset,
                };
                outbox.clear();
                let frames = Self::inbox(inbox, sent, radio, i);
                let delivered = frames.len() as u64;
                let out = c.tick(frames, &m, outbox);
                inbox.clear();
                *force = out.force;
                let mut sums = TickSums {
                    delivered,
                    broadcasts: outbox.len() as u64,
                    copies: (outbox.len() * radio.of(i).len()) as u64,
                    stats: ControlStats::default(),
                };
                sums.stats.record(
                    t,
                    i,
                    out.status,
                    out.saturated,
                    out.degenerate,
                    out.force.norm(),
                );
                sums
            })
            .reduce(TickSums::default, TickSums::then);
        self.count_direct(sums.delivered);
        if self.direct {
            self.radio.count_direct_sums(sums.broadcasts, sums.copies);
        }
        self.stats.merge(&sums.stats);
    }
}
