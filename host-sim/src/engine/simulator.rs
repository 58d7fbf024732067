//! The seam between the run driver and a simulator: [`Engine`], which the sampled and
//! the continuous simulators implement and the driver's time loop advances (in a module of
//! its own, so that the simulators and the driver each depend on it and not on each
//! other).

use super::attack::AttackCounts;
use super::channel::ChannelStats;
use super::hil::HilError;
use super::stats::{ControlStats, FrameCounts};
use crate::model::{EstimateInfo, Model};
use ph_formation_core::Vec2;

/// A simulation engine the driver advances: sampled or continuous.
pub trait Engine {
    /// Runs the controllers at a control instant `t` (sampled mode; no-op in continuous):
    /// every agent, or with own clocks those due at `t`.
    fn control(&mut self, t: f64);
    /// Whether some agent ticks at RK4 step `k` (by default every `steps_per_tick`).
    fn ticks_at(&self, model: &Model, k: usize) -> bool {
        k.is_multiple_of(model.steps_per_tick.max(1))
    }
    /// The first RK4 step after `k` at which some agent ticks.
    fn next_tick_after(&self, model: &Model, k: usize) -> usize {
        let spt = model.steps_per_tick.max(1);
        (k / spt + 1) * spt
    }
    /// Advances the state by one RK4 step from `t`.
    fn integrate(&mut self, t: f64);
    /// Advances the state by the RK4 steps `k..k + steps` of `model` (step `j` starts at
    /// `model.time(j)`) with nothing observed in between: the same as
    /// [`Self::integrate`] at each (an engine may take them in another order where that
    /// gives the same bits).
    fn integrate_steps(&mut self, model: &Model, k: usize, steps: usize) {
        for j in k..k + steps {
            self.integrate(model.time(j));
        }
    }
    /// Refreshes the estimate values and returns `(q, v, estimates)`.
    fn view(&mut self) -> (&[Vec2<f64>], &[Vec2<f64>], &[f64]);
    /// The estimates' layout.
    fn estimate_info(&self) -> &[EstimateInfo];
    /// Frame counters so far.
    fn frame_counts(&self) -> FrameCounts;
    /// Controller counters so far.
    fn control_stats(&self) -> ControlStats;
    /// Frames each attacker overheard and injected (`[[attacks]]` order; none by default).
    fn attack_counts(&self) -> Vec<AttackCounts> {
        Vec::new()
    }
    /// The shared channel's counters, if there is one.
    fn channel_stats(&self) -> Option<ChannelStats> {
        None
    }
    /// Each agent's link copies sent and lost, in agent order (empty when nothing can
    /// be lost: no radio, or the simulator delivering the copies itself).
    fn loss_by_sender(&self) -> Vec<(u64, u64)> {
        Vec::new()
    }
    /// What the swarm did after each fault (`[[faults]]` order; none by default).
    fn fault_reports(&self) -> Vec<super::stats::FaultReport> {
        Vec::new()
    }
    /// What the safety policies did, per agent (empty without `[policy]`).
    fn policy_counts(&self) -> Vec<ph_formation_core::policy::PolicyCounts> {
        Vec::new()
    }
    /// A controller failure that ends the run (a host-in-the-loop target that stopped
    /// answering or sent a corrupt frame), taken once; checked after every
    /// [`Self::control`].
    fn take_error(&mut self) -> Option<HilError> {
        None
    }
}
