//! The actuation-and-plant stage of [`super::SampledSim`]: each agent's force after its
//! tick (the safety policies, its body frame), held until its next tick or commanded to
//! the vehicle, and the plant's RK4 steps under the held forces and the wind.

use super::tick::{world_force, AgentTick};
use crate::engine::plant::{Held, Plant};
use crate::engine::policy::PolicyRun;
use crate::engine::world::{Headings, Wind};
use crate::model::Model;
use ph_formation_core::{Status, StepOutput, Vec2};

/// Every agent's held force and the safety policies.
pub(super) struct Actuation {
    /// Each agent's force of its last tick (N, world frame).
    pub(super) forces: Vec<Vec2<f64>>,
    /// The safety policies (`[policy]`), applied to each force after its tick.
    pub(super) policy: Option<PolicyRun>,
    /// Each agent's current safe-output episode (SPEC S21c's re-seed).
    safe: Vec<SafeEpisode>,
    /// How long a safe output lasts before the re-seed: the neighbour timeout (s).
    reseed_after: f64,
}

impl Actuation {
    /// No force yet, and `model`'s policies.
    pub(super) fn new(model: &Model) -> Self {
        let n = model.n();
        Self {
            forces: vec![Vec2::zeros(); n],
            policy: model.policy.map(|c| PolicyRun::new(c, n, model.battery)),
            safe: vec![SafeEpisode::default(); n],
            reseed_after: model.limits.neighbour_timeout,
        }
    }

    /// Agent `i`'s output `out` of its tick `at` acted on: the policies' force (or the
    /// controller's), turned into the world frame, held, and commanded to a vehicle that
    /// takes commands, whose actuation starts again from the measured velocity once a
    /// safe output has lasted the neighbour timeout (SPEC S21c, as the Crazyflie app's
    /// `agent_loop.c`).
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
        if !plant.takes_commands() {
            return;
        }
        if let Some(episode) = self.safe.get_mut(i) {
            let reseed = episode.tick(out.status, at.dt, self.reseed_after);
            command(plant, i, force, reseed, at.dt);
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

/// An agent's run of safe outputs (SPEC S21c): how long it has lasted and whether its
/// actuation was re-seeded in it.
#[derive(Clone, Copy, Debug, Default)]
struct SafeEpisode {
    lasted: f64,
    reseeded: bool,
}

impl SafeEpisode {
    /// A tick of output `status`, `dt` after the last: whether the actuation starts
    /// again from the measured velocity now, once per episode when it has lasted `after`
    /// seconds (the neighbour timeout, as the Crazyflie app's `agent_loop.c`).
    fn tick(&mut self, status: Status, dt: f64, after: f64) -> bool {
        if !matches!(status, Status::Safe(_)) {
            *self = Self::default();
            return false;
        }
        self.lasted += dt;
        let due = !self.reseeded && self.lasted >= after;
        self.reseeded |= due;
        due
    }
}

/// Agent `i`'s force, `dt` after its last tick, commanded to a vehicle that takes
/// commands, its actuation first started again from the measured velocity when
/// `reseed` (SPEC S21c).
fn command(plant: &mut dyn Plant, i: usize, force: Vec2<f64>, reseed: bool, dt: f64) {
    if reseed {
        plant.reseed(i);
    }
    plant.command(i, force, dt);
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::engine::plant::{derived_lead, derived_second_lead, CrazyfliePidPlant, Held};
    use ph_formation_core::actuate::VirtualMass;
    use ph_formation_core::Fault;

    /// A Crazyflie pushed by a steady force for 0.3 s (its virtual velocity runs ahead of
    /// the drone, which lags by `τ_lead` times the acceleration), then one tick of output
    /// `status` with no force: its virtual velocity (S20) and the drone's. `gap`: the gap
    /// bound (S21c).
    fn setpoint_after(status: Status, gap: f64) -> (Vec2<f64>, Vec2<f64>) {
        let mass = VirtualMass::new(1.0, [0.0; 2], 1.0)
            .and_then(|m| m.with_lead(derived_lead()))
            .and_then(|m| m.with_second_lead(derived_second_lead()))
            .and_then(|m| m.with_jerk_filter(0.03))
            .and_then(|m| m.with_max_gap(gap))
            .unwrap();
        let mut plant = CrazyfliePidPlant::with_virtual_mass(1, mass);
        let forces = [Vec2::zeros()];
        let held = Held {
            forces: &forces,
            wind: &[],
        };
        let dt = 0.01;
        for _ in 0..30 {
            command(&mut plant, 0, Vec2::new(0.5, 0.0), false, dt);
            plant.step(&held, 1e-3, 10, None);
        }
        let reseed = SafeEpisode::default().tick(status, dt, 0.0);
        command(&mut plant, 0, Vec2::zeros(), reseed, dt);
        let c = plant.setpoints.command[0].command().unwrap();
        (Vec2::new(c[0], c[1]), plant.v()[0])
    }

    /// SPEC S21c: on the safe output a vehicle's actuation starts again from its measured
    /// velocity (the app's `agent_loop.c`), so the safe force damps the drone's own
    /// velocity; a nominal tick (the negative control) keeps the virtual velocity that ran
    /// ahead of the drone.
    #[test]
    fn the_safe_output_restarts_from_the_measured_velocity() {
        let safe = Status::Safe(Fault::Stale(2));
        let (sp, v) = setpoint_after(safe, f64::INFINITY);
        let (nominal, v_n) = setpoint_after(Status::Nominal, f64::INFINITY);
        assert!(
            (nominal - v_n).norm() > 0.03,
            "the virtual velocity ran ahead: {nominal:?} vs {v_n:?}"
        );
        // From the measured velocity, with no force: that velocity less one step of the
        // friction.
        assert!((sp - v).norm() < 0.005, "virtual {sp:?}, measured {v:?}");
    }

    /// SPEC S21c: with the gap bound, the nominal step starts within the bound of the
    /// measured velocity (negative control: without it, beyond).
    #[test]
    fn the_gap_bound_holds_the_virtual_velocity_near_the_drone() {
        let (free, v_free) = setpoint_after(Status::Nominal, f64::INFINITY);
        let (held, v_held) = setpoint_after(Status::Nominal, 0.01);
        assert!((free - v_free).norm() > 0.03);
        assert!((held - v_held).norm() < 0.015, "{held:?} vs {v_held:?}");
    }

    /// The re-seed is once per safe episode, when it has lasted the neighbour timeout:
    /// re-seeding at every safe tick hands the vehicle its own noisy measured velocity
    /// as the setpoint at every tick, a random walk the safe force barely damps, and
    /// re-seeding on every isolated safe tick of a lossy channel injects that noise too
    /// (measured in docs/spec.md S21c). Negative control: a nominal-only run re-seeds
    /// nothing; a short episode neither.
    #[test]
    fn the_safe_output_reseeds_once_per_long_episode() {
        let safe = Status::Safe(Fault::Stale(2));
        let count = |statuses: &[Status]| {
            let mut e = SafeEpisode::default();
            statuses.iter().filter(|s| e.tick(**s, 0.01, 0.02)).count()
        };
        let n = Status::Nominal;
        assert_eq!(count(&[n, safe, safe, safe, safe, n, safe, safe, n]), 2);
        assert_eq!(count(&[n, safe, n, safe, n]), 0);
        assert_eq!(count(&[n, n, n]), 0);
    }
}
