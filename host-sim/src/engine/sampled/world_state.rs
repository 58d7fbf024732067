//! The world stage of [`super::SampledSim`]: the robot's world besides the vehicle
//! (`docs/world.md`), each agent's heading estimate, its own clock and the wind, and with
//! own clocks which agents tick at a step.

use super::tick::AgentTick;
use crate::engine::world::{Clocks, Headings, Wind};
use crate::model::Model;

/// The robot's world besides the vehicle: each agent's heading estimate, its own clock,
/// the wind; `None` where the world is ideal.
pub(super) struct WorldState {
    pub(super) headings: Option<Headings>,
    pub(super) clocks: Option<Clocks>,
    pub(super) wind: Option<Wind>,
    /// With own clocks: the agents that tick at the current step, each at its tick.
    due: Vec<Option<AgentTick>>,
    /// Each agent's true heading (rad; without a heading model the scenario's
    /// `heading_deg`, else 0): the camera's boresight.
    pub(super) truth: Vec<f64>,
}

impl WorldState {
    /// The world of `model` at its start.
    pub(super) fn new(model: &Model) -> Self {
        let w = &model.world;
        let headings = w.heading.as_ref().map(|h| Headings::new(model, h));
        Self {
            truth: headings.as_ref().map_or_else(
                || {
                    model
                        .agents
                        .iter()
                        .map(|a| a.heading.unwrap_or(0.0))
                        .collect()
                },
                |h| h.truth.clone(),
            ),
            headings,
            clocks: w.clock.as_ref().map(|c| Clocks::new(model, c)),
            wind: w.wind.as_ref().map(|x| Wind::new(model, x)),
            due: Vec::new(),
        }
    }

    /// When agent `i` ticks at this step: at the common tick `common`, or with own clocks
    /// at its own tick if it is due (`None`: not this step).
    #[inline]
    pub(super) fn tick_of(&self, i: usize, common: AgentTick) -> Option<AgentTick> {
        match &self.clocks {
            None => Some(common),
            Some(_) => self.due.get(i).copied().flatten(),
        }
    }

    /// With own clocks: which of the `n` agents tick at RK4 step `step` (time `t`), each
    /// at its own clock's reading ([`Self::tick_of`]); their next ticks are scheduled.
    pub(super) fn schedule_due(&mut self, n: usize, t: f64, step: usize) {
        let Some(clocks) = &mut self.clocks else {
            return;
        };
        self.due.clear();
        for i in 0..n {
            self.due.push(clocks.due(i, step).then(|| {
                let (time, dt, tick) = clocks.tick(i, t, step);
                AgentTick { time, dt, tick }
            }));
        }
    }
}
