//! The sampled simulator: controllers at their rate with zero-order hold, frames over the
//! radio model, the plant integrated by RK4 between ticks.
//!
//! A control tick runs through stages, each in a file of its own with one seam:
//!
//! | stage | file | what it owns |
//! |---|---|---|
//! | radio delivery | `sampled/delivery.rs` | inboxes, outboxes, the [`Radio`](super::radio::Radio) and its attackers, a bearing sensor's packets |
//! | world | `sampled/world_state.rs` | headings, own clocks, wind |
//! | sensing | `sampled/sensing.rs` | each agent's measurements (`Scene::measure`) |
//! | control | `sampled/tick.rs`, `sampled/parallel.rs` | each agent's tick of its controller |
//! | actuation and plant | `sampled/actuation.rs` | the policies, the held forces, the plant's RK4 steps |
//! | statistics | `sampled/statistics.rs`, `sampled/estimates.rs` | frame counters, control statistics, the estimates the diagnostics read |
//!
//! This file composes them ([`SampledSim::control`]); faults and attacks act through the
//! radio ([`Radio`](super::radio::Radio), [`crate::engine::attack`]), the sensors ([`crate::engine::sensors`])
//! and the world. Large runs with local controllers compute the agents' ticks and the
//! plant in parallel ([`PARALLEL_MIN_AGENTS`], `sampled/parallel.rs`): every agent draws
//! its sensors' noise from its own stream of the tick
//! ([`Sensors::stream`](crate::engine::sensors::Sensors::stream)), so the result does not
//! depend on the number of threads.

mod actuation;
mod delivery;
mod estimates;
mod faults;
mod parallel;
mod sensing;
mod statistics;
mod tick;
mod world_state;

pub use delivery::direct_radio;

use super::attack::AttackCounts;
use super::channel::ChannelStats;
use super::controller::{local_core, AgentController};
use super::error::SetupError;
use super::hil::{HilError, LinkStats};
use super::plant::{new_plant, Plant};
use super::simulator::Engine;
use super::slot_order::SlotOrder;
use super::speed::prefetch::Footprint;
use super::speed::{CHUNK, PARALLEL_MIN_AGENTS};
use super::stats::{ControlStats, FrameCounts};
use crate::model::{EstimateInfo, Model};
use actuation::Actuation;
use delivery::Delivery;
use estimates::Estimates;
use parallel::{tick_all, Agents};
use ph_formation_core::{StepOutput, Vec2, MAX_NEIGHBOURS};
use sensing::{Scene, Senses};
use tick::{AgentSlots, AgentTick, Walk};
use world_state::WorldState;

/// The sampled-data simulator.
pub struct SampledSim<'m> {
    model: &'m Model,
    /// Control: every agent's controller, where it lies in memory ([`prefetch`](super::speed::prefetch)),
    /// its output of the current tick, and the order of its bearings ([`SlotOrder`]).
    controllers: Vec<Box<dyn AgentController>>,
    footprints: Vec<Footprint>,
    outputs: Vec<Option<StepOutput<f64>>>,
    slot_order: SlotOrder,
    /// Every agent's vehicle ([`crate::engine::plant`]).
    pub plant: Box<dyn Plant>,
    /// Actuation: the held forces and the policies.
    actuation: Actuation,
    /// The robot's world besides the vehicle: headings, clocks, wind.
    world: WorldState,
    /// Who measures whom, and with which sensors.
    senses: Senses,
    /// The mailboxes and the radio.
    delivery: Delivery,
    /// Faults of the flight (`[[faults]]`) and what the swarm did about them.
    faults: faults::Faults,
    /// Statistics: the estimates the diagnostics read, and the controllers' outputs.
    estimates: Estimates,
    stats: ControlStats,
    error: Option<HilError>,
    last_tick: Option<f64>,
    /// Control ticks so far (the index of the sensors' streams).
    ticks: u64,
    /// Every controller is a [`LocalCore`](super::LocalCore) (ticks may run in parallel).
    local: bool,
}

impl<'m> SampledSim<'m> {
    /// A sampled simulation with a [`LocalCore`](super::LocalCore) for every agent, each
    /// in the smallest capacity that holds it ([`local_core`]).
    pub fn new(model: &'m Model) -> Result<Self, SetupError> {
        let mut controllers: Vec<Box<dyn AgentController>> = Vec::with_capacity(model.n());
        for i in 0..model.n() {
            controllers.push(local_core(model, i)?);
        }
        let mut sim = Self::with_controllers(model, controllers)?;
        sim.local = true;
        Ok(sim)
    }

    /// A sampled simulation with the given controllers (one per agent, in agent order).
    pub fn with_controllers(
        model: &'m Model,
        controllers: Vec<Box<dyn AgentController>>,
    ) -> Result<Self, SetupError> {
        let n = model.n();
        if controllers.len() != n {
            return Err(SetupError::ControllerCount {
                controllers: controllers.len(),
                agents: n,
            });
        }
        // An agent's tick holds one bearing per triangle neighbour ([`Walk::start`]).
        let degree = model.graph.triangle.max_degree();
        if degree > MAX_NEIGHBOURS {
            return Err(SetupError::TooManyNeighbours {
                degree,
                max: MAX_NEIGHBOURS,
            });
        }
        let estimates = Estimates::new(model, &controllers)?;
        let period = model.control_period();
        let senses = Senses::new(model, period);
        // Agents on their own clocks hear frames through the radio's queue, and so do
        // those of a bearing sensor that sends packets of its own.
        // And so do faulty agents' neighbours (a deaf agent's inbox is emptied).
        let direct = direct_radio(model)
            && model.world.clock.is_none()
            && !senses.uses_radio()
            && model.faults.is_empty();
        let slot_order = SlotOrder::for_model(model, |i| controllers[i].neighbour_order());
        Ok(Self {
            model,
            footprints: controllers.iter().map(|c| Footprint::of(&**c)).collect(),
            controllers,
            outputs: vec![None; n],
            slot_order,
            plant: new_plant(model)?,
            actuation: Actuation::new(model),
            world: WorldState::new(model),
            senses,
            delivery: Delivery::new(model, direct),
            faults: faults::Faults::new(model),
            estimates,
            stats: ControlStats::with_window(crate::analysis::steady::Window::of(model).from),
            error: None,
            last_tick: None,
            ticks: 0,
            local: false,
        })
    }

    /// Runs `ticks` control periods (control, then `steps_per_tick` RK4 steps) without
    /// diagnostics: the benchmark's inner loop. Starts at time `start`.
    pub fn advance_ticks(&mut self, start: f64, ticks: usize) {
        let spt = self.model.steps_per_tick;
        let dt = self.model.dt;
        for k in 0..ticks {
            let t0 = start + (k * spt) as f64 * dt;
            self.control(t0);
            self.plant_steps(spt);
        }
    }

    /// Ends every controller's session (host-in-the-loop targets get `Finish`).
    pub fn finish_controllers(&mut self) -> Result<(), HilError> {
        for c in &mut self.controllers {
            c.finish()?;
        }
        Ok(())
    }

    /// Agent `i`'s controller (`None` beyond the last agent).
    pub fn controller(&self, i: usize) -> Option<&dyn AgentController> {
        self.controllers.get(i).map(|c| &**c)
    }

    /// The link figures of the remote controllers, in agent order.
    pub fn link_stats(&self) -> Vec<LinkStats> {
        self.controllers
            .iter()
            .filter_map(|c| c.link_stats())
            .collect()
    }
}

impl SampledSim<'_> {
    /// `steps` RK4 steps of the plant under the held forces (and the wind): on every
    /// thread when the ticks are, each work item taking every step of its agents (one
    /// fork-join); otherwise one step over all agents at a time (measured faster on one
    /// thread).
    fn plant_steps(&mut self, steps: usize) {
        let chunk = self.parallel().then_some(CHUNK);
        let wind = self.world.wind.as_ref();
        self.actuation
            .step(&mut *self.plant, wind, self.model.dt, steps, chunk);
    }

    /// Whether this tick runs on every thread of the current rayon pool (agents on their
    /// own clocks tick one by one).
    fn parallel(&self) -> bool {
        self.local
            && self.model.n() >= PARALLEL_MIN_AGENTS
            && rayon::current_num_threads() > 1
            && self.world.clocks.is_none()
            && self.actuation.policy.is_none()
            && !self.plant.takes_commands()
            && !self.faults.any()
    }

    /// Every due agent's tick started ([`Walk::start`]), in agent order: every agent at
    /// `at`, or with own clocks those `self.world` says are due, each at its own tick.
    fn tick_sequential(&mut self, at: AgentTick) -> Result<(), HilError> {
        let mut delivered = 0;
        let model = self.model;
        let walk = Walk {
            at,
            headings: self.world.headings.as_ref(),
            scene: Scene::of(model, &*self.plant, &self.senses, &self.world.truth),
            radio: &model.graph.radio,
            slot_order: &self.slot_order,
            sent: &self.delivery.sent,
            footprints: &self.footprints,
            copy_estimates: self.estimates.viewed,
            faults: self.faults.any().then_some(&self.faults),
        };
        let each = self
            .controllers
            .iter_mut()
            .zip(&mut self.delivery.inboxes)
            .zip(&mut self.delivery.outboxes)
            .zip(&mut self.actuation.forces)
            .zip(&mut self.outputs);
        let est = &mut self.estimates;
        for (i, ((((controller, inbox), outbox), force), output)) in each.enumerate() {
            let Some(at) = self.world.tick_of(i, at) else {
                continue;
            };
            if self.faults.down(i, at.time) {
                inbox.clear();
                continue;
            }
            let (a, b) = (est.start[i], est.start[i + 1]);
            let mut slots = AgentSlots {
                controller,
                inbox,
                outbox,
                force,
                estimates: &mut est.values[a..b],
            };
            let (out, frames) = walk.start(i, &mut slots, at)?;
            delivered += frames;
            *output = out;
        }
        self.delivery.count_direct(delivered);
        Ok(())
    }

    /// Every agent's tick on every thread (`sampled/parallel.rs`): forces, counters and
    /// statistics kept on every thread; only the radio's broadcasts (one random stream,
    /// in agent order) remain.
    fn tick_parallel(&mut self, t: f64, at: AgentTick) {
        let model = self.model;
        let walk = Walk {
            at,
            headings: self.world.headings.as_ref(),
            scene: Scene::of(model, &*self.plant, &self.senses, &self.world.truth),
            radio: &model.graph.radio,
            slot_order: &self.slot_order,
            sent: &self.delivery.sent,
            footprints: &self.footprints,
            copy_estimates: self.estimates.viewed,
            faults: self.faults.any().then_some(&self.faults),
        };
        // Each agent's parts (the slices are disjoint fields).
        let sums = tick_all(
            &walk,
            Agents {
                first: 0,
                controllers: &mut self.controllers,
                inboxes: &mut self.delivery.inboxes,
                outboxes: &mut self.delivery.outboxes,
                forces: &mut self.actuation.forces,
                estimates: &mut self.estimates.values,
                est_start: &self.estimates.start,
            },
        );
        self.estimates.fresh = self.estimates.viewed;
        let d = &mut self.delivery;
        d.count_direct(sums.delivered);
        if d.direct {
            d.radio.count_direct_sums(sums.broadcasts, sums.copies);
        }
        self.stats.merge(&sums.stats);
        if !d.direct {
            for i in 0..model.n() {
                let sensor = self.senses.bearing.as_deref_mut();
                d.send(model, t, i, self.plant.q(), sensor);
            }
        }
    }

    /// The faults at `t`: a reboot gives its agent a new controller from its
    /// configuration (the core's state lost) and restarts its actuation; every agent's
    /// radio is on or off.
    fn apply_faults(&mut self, t: f64) {
        for i in self.faults.reboots_due(t) {
            if let (true, Ok(fresh)) = (self.local, local_core(self.model, i)) {
                self.controllers[i] = fresh;
                self.footprints[i] = Footprint::of(&*self.controllers[i]);
            }
            self.plant.restart(i);
        }
        let n = self.model.n();
        self.delivery.deaf.resize(n, false);
        for i in 0..n {
            self.delivery.deaf[i] = self.faults.deaf(i, t);
        }
    }

    /// Agent `i`'s output of its tick: the one its tick gave, or a remote controller's
    /// (its estimates copied when viewed); `None` after a failure (kept in `self.error`).
    fn output_of(&mut self, i: usize) -> Option<StepOutput<f64>> {
        if let Some(out) = self.outputs[i].take() {
            return Some(out);
        }
        match self.controllers[i].finish_tick(&mut self.delivery.outboxes[i]) {
            Ok(out) => {
                if self.estimates.viewed {
                    let e = &mut self.estimates;
                    Estimates::read_of(&*self.controllers[i], &mut e.values, &e.start, i);
                }
                Some(out)
            }
            Err(e) => {
                self.error = Some(e);
                None
            }
        }
    }
}

impl Engine for SampledSim<'_> {
    /// The stages in order: radio delivery, the bearing sensor's view of the world, then
    /// two phases of control: every due agent is measured in agent order and its tick
    /// started (local controllers complete it at once, remote ones only send their
    /// inputs), then every output is collected, every agent's frames sent, and its force
    /// acted on and recorded, in agent order (so the random streams are drawn in the same
    /// order as without remote controllers).
    fn control(&mut self, t: f64) {
        if self.error.is_some() {
            return;
        }
        let model = self.model;
        // Set again once every agent's tick copied its estimates.
        self.estimates.fresh = false;
        if self.faults.any() {
            self.apply_faults(t);
        }
        let sensor = &mut self.senses.bearing;
        self.delivery
            .receive(model, t, self.ticks, self.plant.q(), sensor);
        // At every control period of the common clock (with own clocks, the agents that
        // tick in between see the camera's history and occlusions of the last one).
        if model.step_of(t).is_multiple_of(model.steps_per_tick.max(1)) {
            self.senses.prepare(&*self.plant, &self.world.truth);
        }
        let dt = self.last_tick.map_or(0.0, |p| t - p);
        // Measured with this tick's streams; the next tick draws from new ones.
        let at = AgentTick {
            time: t,
            dt,
            tick: self.ticks,
        };
        self.ticks += 1;
        if self.parallel() {
            self.tick_parallel(t, at);
            self.last_tick = Some(t);
            return;
        }
        self.world.schedule_due(model.n(), t, model.step_of(t));
        if let Err(e) = self.tick_sequential(at) {
            self.error = Some(e);
            return;
        }
        for i in 0..model.n() {
            let Some(at) = self.world.tick_of(i, at) else {
                continue;
            };
            if self.faults.any() && self.faults.down(i, at.time) {
                // Down: no output, nothing sent; the vehicle holds still.
                self.delivery.outboxes[i].clear();
                self.actuation.forces[i] = Vec2::zeros();
                self.plant.set_velocity_setpoint(i, Vec2::zeros());
                continue;
            }
            let Some(out) = self.output_of(i) else {
                return;
            };
            if self.faults.any() {
                self.faults.observe(i, at.time, out.status);
            }
            if self.faults.any() && self.faults.deaf(i, at.time) {
                self.delivery.outboxes[i].clear();
            } else {
                let sensor = self.senses.bearing.as_deref_mut();
                self.delivery.send(model, t, i, self.plant.q(), sensor);
            }
            let headings = self.world.headings.as_ref();
            self.actuation
                .apply(model, &mut *self.plant, headings, i, &out, &at);
            statistics::record(&mut self.stats, t, i, &out);
        }
        self.estimates.fresh = self.estimates.viewed && self.world.clocks.is_none();
        self.last_tick = Some(t);
    }

    fn integrate(&mut self, _t: f64) {
        self.plant_steps(1);
    }

    /// The plant does not depend on `t`: all the steps at once (the wind advances at
    /// every control period).
    fn integrate_steps(&mut self, model: &Model, k: usize, steps: usize) {
        if let Some(w) = &mut self.world.wind {
            if k.is_multiple_of(model.steps_per_tick.max(1)) {
                w.advance(model.control_period());
            }
        }
        self.plant_steps(steps);
    }

    /// Every control period of the common clock (the radio delivers, the camera takes in
    /// the state), and with own clocks every step at which some agent ticks.
    fn ticks_at(&self, model: &Model, k: usize) -> bool {
        let common = k.is_multiple_of(model.steps_per_tick.max(1));
        match &self.world.clocks {
            Some(c) => common || c.any_due(k),
            None => common,
        }
    }

    fn next_tick_after(&self, model: &Model, k: usize) -> usize {
        let spt = model.steps_per_tick.max(1);
        let common = (k / spt + 1) * spt;
        match &self.world.clocks {
            Some(c) => c.next_after(k).min(common),
            None => common,
        }
    }

    fn view(&mut self) -> (&[Vec2<f64>], &[Vec2<f64>], &[f64]) {
        self.estimates.viewed = true;
        self.estimates.refresh(&self.controllers);
        (self.plant.q(), self.plant.v(), &self.estimates.values)
    }

    fn estimate_info(&self) -> &[EstimateInfo] {
        &self.estimates.info
    }

    fn frame_counts(&self) -> FrameCounts {
        statistics::frame_counts(&self.delivery.radio, &self.controllers)
    }

    fn control_stats(&self) -> ControlStats {
        self.stats
    }

    fn policy_counts(&self) -> Vec<ph_formation_core::policy::PolicyCounts> {
        self.actuation
            .policy
            .as_ref()
            .map_or_else(Vec::new, super::policy::PolicyRun::counts)
    }

    fn fault_reports(&self) -> Vec<super::stats::FaultReport> {
        self.faults.reports()
    }

    fn loss_by_sender(&self) -> Vec<(u64, u64)> {
        self.delivery.radio.loss_by_sender()
    }

    fn channel_stats(&self) -> Option<ChannelStats> {
        self.delivery.radio.channel_stats()
    }

    fn attack_counts(&self) -> Vec<AttackCounts> {
        self.delivery.attacks.counts()
    }

    fn take_error(&mut self) -> Option<HilError> {
        // A `LocalCore` never keeps a failure: no walk over 100,000 controllers per tick.
        if self.error.is_none() && !self.local {
            self.error = self.controllers.iter_mut().find_map(|c| c.take_error());
        }
        self.error.take()
    }
}
