//! The actuation-and-plant stage of [`super::SampledSim`]: each agent's force after its
//! tick (the safety policies, its body frame), held until its next tick or commanded to
//! the vehicle, and the plant's RK4 steps under the held forces and the wind.

use super::tick::{world_force, AgentTick};
use crate::engine::plant::{Held, Plant};
use crate::engine::policy::PolicyRun;
use crate::engine::world::{Headings, Wind};
use crate::model::Model;
use ph_formation_core::{StepOutput, Vec2};

/// Every agent's held force and the safety policies.
pub(super) struct Actuation {
    /// Each agent's force of its last tick (N, world frame).
    pub(super) forces: Vec<Vec2<f64>>,
    /// The safety policies (`[policy]`), applied to each force after its tick.
    pub(super) policy: Option<PolicyRun>,
}

impl Actuation {
    /// No force yet, and `model`'s policies.
    pub(super) fn new(model: &Model) -> Self {
        let n = model.n();
        Self {
            forces: vec![Vec2::zeros(); n],
            policy: model.policy.map(|c| PolicyRun::new(c, n, model.battery)),
        }
    }

    /// Agent `i`'s output `out` of its tick `at` acted on: the policies' force (or the
    /// controller's), turned into the world frame, held, and commanded to a vehicle that
    /// takes commands.
    #[inline]
    pub(super) fn apply(
        &mut self,
        model: &Model,
        plant: &mut dyn Plant,
        headings: Option<&Headings>,
        i: usize,
        out: &StepOutput<f64>,
        at: &AgentTick,
    ) {
        let own = match self.policy.as_mut() {
            Some(p) => p.force(
                i,
                out,
                at.dt,
                plant.q(),
                plant.v(),
                model.graph.radio.of(i),
                model.limits.safe_damping,
            ),
            None => out.force,
        };
        let force = world_force(headings, i, at, own);
        self.forces[i] = force;
        if plant.takes_commands() {
            plant.command(i, force, at.dt);
        }
    }

    /// Every agent's held force commanded to a vehicle that takes commands, `dt` after
    /// the last tick (the parallel tick sets the forces itself).
    pub(super) fn command_all(&self, plant: &mut dyn Plant, dt: f64) {
        if plant.takes_commands() {
            for (i, f) in self.forces.iter().enumerate() {
                plant.command(i, *f, dt);
            }
        }
    }

    /// `steps` RK4 steps of length `dt` of `plant` under the held forces and the wind;
    /// `chunk`: on every thread, that many agents per work item (the plant may ignore it,
    /// [`Plant::step`]).
    #[inline]
    pub(super) fn step(
        &self,
        plant: &mut dyn Plant,
        wind: Option<&Wind>,
        dt: f64,
        steps: usize,
        chunk: Option<usize>,
    ) {
        let held = Held {
            forces: &self.forces,
            wind: wind.map_or(&[], |w| w.now.as_slice()),
        };
        plant.step(&held, dt, steps, chunk);
    }
}
