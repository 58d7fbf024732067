//! The parallel form of the control stage of `SampledSim`: every agent's sensing, controller tick, force and
//! counters on every thread of the current rayon pool, bit-identical to the sequential
//! tick (`tests/scaling.rs`): each agent draws its sensors' noise from its own stream of
//! the tick ([`crate::engine::sensors::Sensors::stream`]). Only the radio's broadcasts
//! (one random stream, in agent order) stay sequential. Each agent also copies its
//! estimates for the diagnostics while its state is in cache (a separate pass over
//! 100,000 agents' states costs a second walk through memory).

use super::tick::{world_force, AgentSlots, Walk};
use crate::engine::controller::AgentController;
use crate::engine::radio::RadioFrame;
use crate::engine::speed::CHUNK;
use crate::engine::stats::ControlStats;
use ph_formation_core::Vec2;

/// What the parallel walk of a tick sums over the agents (in agent order).
#[derive(Clone, Copy, Debug, Default)]
pub(super) struct TickSums {
    /// Frames read straight from the senders' outboxes.
    pub(super) delivered: u64,
    /// Frames broadcast, and their copies to every radio neighbour.
    pub(super) broadcasts: u64,
    pub(super) copies: u64,
    /// The controllers' outputs.
    pub(super) stats: ControlStats,
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

/// The agents `first..first + controllers.len()` with their parts of the simulator's
/// per-agent buffers: disjoint from every other `Agents`, so halves go to different
/// threads.
pub(super) struct Agents<'s> {
    pub(super) first: usize,
    pub(super) controllers: &'s mut [Box<dyn AgentController>],
    pub(super) inboxes: &'s mut [Vec<RadioFrame>],
    pub(super) outboxes: &'s mut [Vec<RadioFrame>],
    pub(super) forces: &'s mut [Vec2<f64>],
    /// Their estimates: agent `first + k`'s at `est_start[k] - est_start[0]..est_start[k + 1]
    /// - est_start[0]` (`est_start` has one entry more than the agents).
    pub(super) estimates: &'s mut [f64],
    pub(super) est_start: &'s [usize],
}

impl<'s> Agents<'s> {
    /// The first `mid` agents and the rest.
    fn split_at(self, mid: usize) -> (Self, Self) {
        let (c0, c1) = self.controllers.split_at_mut(mid);
        let (i0, i1) = self.inboxes.split_at_mut(mid);
        let (o0, o1) = self.outboxes.split_at_mut(mid);
        let (f0, f1) = self.forces.split_at_mut(mid);
        let cut = (self.est_start[mid] - self.est_start[0]).min(self.estimates.len());
        let (e0, e1) = self.estimates.split_at_mut(cut);
        let lo = Agents {
            first: self.first,
            controllers: c0,
            inboxes: i0,
            outboxes: o0,
            forces: f0,
            estimates: e0,
            est_start: &self.est_start[..=mid],
        };
        let hi = Agents {
            first: self.first + mid,
            controllers: c1,
            inboxes: i1,
            outboxes: o1,
            forces: f1,
            estimates: e1,
            est_start: &self.est_start[mid..],
        };
        (lo, hi)
    }
}

impl Walk<'_> {
    /// Agent `i`'s tick ([`Walk::start`]), its force, and its counters.
    fn agent(&self, i: usize, mut a: AgentSlots<'_>) -> TickSums {
        // Only in-process controllers take this walk (`SampledSim::parallel`): their tick
        // completes at once and never fails.
        let Ok((Some(out), delivered)) = self.start(i, &mut a, self.at) else {
            return TickSums::default();
        };
        *a.force = world_force(self.headings, i, &self.at, out.force);
        let mut sums = TickSums {
            delivered,
            broadcasts: a.outbox.len() as u64,
            copies: (a.outbox.len() * self.radio.of(i).len()) as u64,
            stats: ControlStats::default(),
        };
        let norm = out.force.norm();
        sums.stats.record(
            self.at.time,
            i,
            out.status,
            out.saturated,
            out.degenerate,
            norm,
        );
        sums
    }

    /// The ticks of `agents`: halves on every thread of the current rayon pool down to
    /// [`CHUNK`] agents, then in agent order; the sums in agent order.
    fn agents(&self, agents: Agents<'_>) -> TickSums {
        let n = agents.controllers.len();
        if n > CHUNK {
            let (lo, hi) = agents.split_at(n / 2);
            let (a, b) = rayon::join(|| self.agents(lo), || self.agents(hi));
            return a.then(b);
        }
        let Agents {
            first,
            controllers,
            inboxes,
            outboxes,
            forces,
            estimates,
            est_start,
        } = agents;
        let mut rest = estimates;
        let mut sums = TickSums::default();
        let each = controllers
            .iter_mut()
            .zip(inboxes)
            .zip(outboxes)
            .zip(forces);
        for (k, (((controller, inbox), outbox), force)) in each.enumerate() {
            let count = (est_start[k + 1] - est_start[k]).min(rest.len());
            let (own, later) = std::mem::take(&mut rest).split_at_mut(count);
            rest = later;
            let slots = AgentSlots {
                controller,
                inbox,
                outbox,
                force,
                estimates: own,
            };
            sums = sums.then(self.agent(first + k, slots));
        }
        sums
    }
}

/// Every agent's tick on every thread ([`Walk::agent`]), its force and estimates, and
/// the counters and statistics of all, summed in agent order.
pub(super) fn tick_all(walk: &Walk<'_>, agents: Agents<'_>) -> TickSums {
    walk.agents(agents)
}
