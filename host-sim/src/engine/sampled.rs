//! The sampled simulator: controllers at their rate with zero-order hold, frames over the
//! radio model, the plant integrated by RK4 between ticks.
//!
//! Two delivery paths, with the same result: frames go through [`Radio`] (faults, delays,
//! the shared channel, attacks), or, when the radio is ideal in timing and faults
//! ([`direct_radio`]), each receiver reads its radio neighbours' frames of the previous
//! tick straight from their outboxes, in sender order, which is exactly what the radio's
//! queue would have delivered. Large runs with local controllers compute the agents'
//! ticks and the plant in parallel ([`PARALLEL_MIN_AGENTS`], `sampled/parallel.rs`): every
//! agent draws its sensors' noise from its own stream of the tick ([`Sensors::stream`]), so
//! the result does not depend on the number of threads.

mod parallel;
mod tick;

use super::attack::{AttackCounts, Attacks};
use super::channel::ChannelStats;
use super::controller::{local_core, AgentController, Inbox};
use super::driver::Engine;
use super::error::SetupError;
use super::hil::{HilError, LinkStats};
use super::plant::{new_plant, Held, Plant};
use super::radio::{Radio, RadioFrame};
use super::sensors::{
    bearing_sensor, offset_with, quiet_bearing, velocity_with, BearingKind, BearingSensor, Sensors,
    Sight, World,
};
use super::slot_order::SlotOrder;
use super::speed::prefetch::{self, Footprint};
use super::speed::{CHUNK, PARALLEL_MIN_AGENTS};
use super::stats::{ControlStats, FrameCounts, FrameReasons};
use super::world::{Clocks, Headings, Wind};
use crate::model::graph::Adjacency;
use crate::model::{resolve_estimates, BearingRate, EstimateInfo, Estimator, Model};
use ph_formation_core::{BearingMeasurement, StepOutput, Vec2, MAX_NEIGHBOURS};
use tick::{world_force, AgentSlots, AgentTick, Walk};

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

/// The sampled-data simulator.
pub struct SampledSim<'m> {
    model: &'m Model,
    controllers: Vec<Box<dyn AgentController>>,
    /// Where each controller lies in memory ([`prefetch`]).
    footprints: Vec<Footprint>,
    /// Every agent's vehicle ([`crate::engine::plant`]).
    pub plant: Box<dyn Plant>,
    /// The robot's world besides the vehicle: headings, clocks, wind.
    world: WorldState,
    /// Who measures whom, and with which sensors.
    senses: Senses,
    radio: Radio,
    attacks: Attacks,
    inboxes: Vec<Vec<RadioFrame>>,
    outboxes: Vec<Vec<RadioFrame>>,
    /// Direct delivery: the outboxes of the last tick, which the receivers read in place
    /// (swapped with `outboxes` at every tick).
    sent: Vec<Vec<RadioFrame>>,
    outputs: Vec<Option<StepOutput<f64>>>,
    error: Option<HilError>,
    forces: Vec<Vec2<f64>>,
    /// Each agent's bearings go to its core in slot order ([`SlotOrder`]).
    slot_order: SlotOrder,
    estimates: Vec<f64>,
    est_start: Vec<usize>,
    /// `estimates` holds every controller's current values: the tick copied them (an
    /// estimate changes only at a tick), so [`Engine::view`] need not.
    estimates_fresh: bool,
    /// [`Engine::view`] was called: from then on each agent's tick copies its estimates
    /// while its state is in cache (a run's diagnostics view every control instant; the
    /// benchmark's [`SampledSim::advance_ticks`] never views, and copies nothing).
    viewed: bool,
    info: Vec<EstimateInfo>,
    last_tick: Option<f64>,
    /// Control ticks so far (the index of the sensors' streams, [`Sensors::stream`]).
    ticks: u64,
    stats: ControlStats,
    /// Frames bypass [`Radio`]'s queue ([`direct_radio`]).
    direct: bool,
    /// Every controller is a [`LocalCore`](super::LocalCore) (ticks may run in parallel).
    local: bool,
    /// The safety policies (`[policy]`), applied to each force after its tick.
    policy: Option<super::policy::PolicyRun>,
}

/// Frames one agent emits per tick, at most, in the standard capacity (used to
/// preallocate; an outbox holds one tick's frames).
const FRAMES_PER_TICK: usize = ph_formation_core::StandardAgent::<f64>::MAX_FRAMES_PER_TICK;

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
        let mut info = Vec::new();
        let mut est_start = Vec::with_capacity(n + 1);
        for (i, c) in controllers.iter().enumerate() {
            if c.id() != model.agents[i].id {
                return Err(SetupError::ControllerId {
                    index: i,
                    id: c.id(),
                    expected: model.agents[i].id,
                });
            }
            est_start.push(info.len());
            info.extend(resolve_estimates(model, i, &c.estimate_layout())?);
        }
        est_start.push(info.len());
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
        // Agents on their own clocks hear frames through the radio's queue.
        let direct = direct_radio(model) && model.world.clock.is_none();
        // Direct delivery reads the senders' frames in place: no inbox.
        let inboxes = (0..n)
            .map(|i| {
                let frames = model.graph.radio.of(i).len() * FRAMES_PER_TICK * 4 + 8;
                Vec::with_capacity(if direct { 0 } else { frames })
            })
            .collect();
        let outbox = || Vec::with_capacity(FRAMES_PER_TICK);
        let slot_order = SlotOrder::for_model(model, |i| controllers[i].neighbour_order());
        let mut radio = Radio::new(&model.radio, n, model.seed, capacity);
        radio.attach_channel(&model.graph.radio, period);
        Ok(Self {
            model,
            footprints: controllers.iter().map(|c| Footprint::of(&**c)).collect(),
            controllers,
            plant: new_plant(model)?,
            world: WorldState::new(model),
            senses: Senses {
                sensors: Sensors::new(&model.sensors, model.seed),
                bearing: bearing_sensor(model, period),
                ids: model.agents.iter().map(|a| a.id).collect(),
                partner: model.partners(),
            },
            radio,
            attacks: Attacks::new(model),
            inboxes,
            outboxes: (0..n).map(|_| outbox()).collect(),
            sent: (0..if direct { n } else { 0 }).map(|_| outbox()).collect(),
            outputs: vec![None; n],
            error: None,
            forces: vec![Vec2::zeros(); n],
            slot_order,
            estimates: vec![model.initial_estimate; info.len()],
            est_start,
            estimates_fresh: false,
            viewed: false,
            info,
            last_tick: None,
            ticks: 0,
            stats: ControlStats::with_window(crate::analysis::steady::Window::of(model).from),
            direct,
            local: false,
            policy: model
                .policy
                .map(|c| super::policy::PolicyRun::new(c, n, model.battery)),
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
        let dt = self.model.dt;
        let chunk = self.parallel().then_some(CHUNK);
        let held = Held {
            forces: &self.forces,
            wind: self.world.wind.as_ref().map_or(&[], |w| w.now.as_slice()),
        };
        self.plant.step(&held, dt, steps, chunk);
    }

    /// Whether this tick runs on every thread of the current rayon pool (agents on their
    /// own clocks tick one by one).
    fn parallel(&self) -> bool {
        self.local
            && self.model.n() >= PARALLEL_MIN_AGENTS
            && rayon::current_num_threads() > 1
            && self.world.clocks.is_none()
            && self.policy.is_none()
    }

    /// What agent `i` takes in at this tick: what the radio delivered, or with direct
    /// delivery its radio neighbours' frames of the last tick in sender order (what
    /// [`Radio`]'s queue delivers when nothing delays or changes them).
    fn inbox<'a>(
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

    /// Every due agent's tick started ([`Walk::start`]), in agent order: every agent at
    /// `at`, or with own clocks those `self.world.due` lists, each at its own tick.
    fn tick_sequential(&mut self, at: AgentTick) -> Result<(), HilError> {
        let mut delivered = 0;
        let model = self.model;
        // Field by field: the walk reads the state while the loop writes the agents' parts.
        let walk = Walk {
            at,
            headings: self.world.headings.as_ref(),
            scene: Scene::of(model, &*self.plant, &self.senses, &self.world.truth),
            radio: &model.graph.radio,
            slot_order: &self.slot_order,
            sent: &self.sent,
            footprints: &self.footprints,
            copy_estimates: self.viewed,
        };
        let each = self
            .controllers
            .iter_mut()
            .zip(&mut self.inboxes)
            .zip(&mut self.outboxes)
            .zip(&mut self.forces)
            .zip(&mut self.outputs);
        for (i, ((((controller, inbox), outbox), force), output)) in each.enumerate() {
            let Some(at) = self.world.tick_of(i, at) else {
                continue;
            };
            let (a, b) = (self.est_start[i], self.est_start[i + 1]);
            let mut slots = AgentSlots {
                controller,
                inbox,
                outbox,
                force,
                estimates: &mut self.estimates[a..b],
            };
            let (out, frames) = walk.start(i, &mut slots, at)?;
            delivered += frames;
            *output = out;
        }
        self.count_direct(delivered);
        Ok(())
    }

    /// With own clocks: which agents tick at RK4 step `step` (time `t`), each at its own
    /// clock's reading (`self.world.due`); their next ticks are scheduled.
    fn schedule_due(&mut self, t: f64, step: usize) {
        let w = &mut self.world;
        let Some(clocks) = &mut w.clocks else {
            return;
        };
        w.due.clear();
        for i in 0..self.model.n() {
            w.due.push(clocks.due(i, step).then(|| {
                let (time, dt, tick) = clocks.tick(i, t, step);
                AgentTick { time, dt, tick }
            }));
        }
    }

    /// Agent `i`'s frames of this tick through the radio (and the attackers that
    /// overhear them).
    fn broadcast(&mut self, t: f64, i: usize) {
        let model = self.model;
        let receivers = model.graph.radio.of(i);
        for f in &self.outboxes[i] {
            self.radio.broadcast_frame(t, i, receivers, *f);
            if !self.attacks.is_empty() {
                self.attacks
                    .overhear(t, i, f.as_bytes(), self.plant.q(), model, &mut self.radio);
            }
        }
        // Its position packet, after its frames (`sensors/shared_positions.rs`).
        if let Some(p) = self.senses.bearing.as_mut().and_then(|s| s.positions()) {
            self.radio.broadcast_frame(t, i, receivers, p.packet(i));
        }
    }

    /// Copies agent `i`'s current estimates into its slots of `estimates`
    /// (`est_start[i]..est_start[i + 1]`).
    fn read_estimates_of(
        controller: &dyn AgentController,
        estimates: &mut [f64],
        est_start: &[usize],
        i: usize,
    ) {
        let (a, b) = (est_start[i], est_start[i + 1]);
        if let Some(slot) = estimates.get_mut(a..b) {
            controller.read_estimates(slot);
        }
    }

    /// Counts the frames `delivered` directly (none through the radio's queue).
    fn count_direct(&mut self, delivered: u64) {
        if self.direct {
            self.radio.count_delivered(delivered);
        }
    }
}

impl Engine for SampledSim<'_> {
    /// Two phases: every due agent is measured in agent order and its tick started (local
    /// controllers complete it at once, remote ones only send their inputs), then every
    /// output is collected and every agent's frames broadcast, in agent order (so the
    /// random streams are drawn in the same order as without remote controllers).
    fn control(&mut self, t: f64) {
        if self.error.is_some() {
            return;
        }
        let model = self.model;
        let parallel = self.parallel();
        // Set again once every agent's tick copied its estimates.
        self.estimates_fresh = false;
        if self.direct {
            // The frames of the last tick are read where their senders left them.
            std::mem::swap(&mut self.outboxes, &mut self.sent);
        } else {
            self.radio.observe(self.plant.q());
            if !self.attacks.is_empty() {
                let period = model.dt * model.steps_per_tick as f64;
                self.attacks
                    .tick(t, period, self.plant.q(), model, &mut self.radio);
            }
            self.radio.deliver(t, &mut self.inboxes);
            if let Some(p) = self.senses.bearing.as_mut().and_then(|s| s.positions()) {
                p.hear(t, self.ticks, self.plant.q(), &mut self.inboxes);
            }
        }
        // At every control period of the common clock (with own clocks, the agents that
        // tick in between see the camera's history and occlusions of the last one).
        let common = model.step_of(t).is_multiple_of(model.steps_per_tick.max(1));
        if let (Some(sensor), true) = (&mut self.senses.bearing, common) {
            sensor.prepare(&World {
                q: self.plant.q(),
                v: self.plant.v(),
                headings: &self.world.truth,
            });
        }
        let dt = self.last_tick.map_or(0.0, |p| t - p);
        // Measured with this tick's streams; the next tick draws from new ones.
        let at = AgentTick {
            time: t,
            dt,
            tick: self.ticks,
        };
        self.ticks += 1;
        if parallel {
            // Forces, counters and statistics kept on every thread: only the radio's
            // broadcasts (one random stream, in agent order) remain.
            self.tick_parallel(t, dt, at.tick);
            if !self.direct {
                for i in 0..model.n() {
                    self.broadcast(t, i);
                }
            }
            self.last_tick = Some(t);
            return;
        }
        self.schedule_due(t, model.step_of(t));
        if let Err(e) = self.tick_sequential(at) {
            self.error = Some(e);
            return;
        }
        let clocked = self.world.clocks.is_some();
        for i in 0..model.n() {
            let Some(at) = self.world.tick_of(i, at) else {
                continue;
            };
            let out = match self.outputs[i].take() {
                Some(out) => out,
                None => match self.controllers[i].finish_tick(&mut self.outboxes[i]) {
                    Ok(out) if self.viewed => {
                        let c = &*self.controllers[i];
                        Self::read_estimates_of(c, &mut self.estimates, &self.est_start, i);
                        out
                    }
                    Ok(out) => out,
                    Err(e) => {
                        self.error = Some(e);
                        return;
                    }
                },
            };
            if self.direct {
                let receivers = model.graph.radio.of(i);
                self.radio
                    .count_direct(self.outboxes[i].len(), receivers.len());
            } else {
                self.broadcast(t, i);
            }
            let own = match self.policy.as_mut() {
                Some(p) => p.force(
                    i,
                    &out,
                    at.dt,
                    self.plant.q(),
                    self.plant.v(),
                    model.graph.radio.of(i),
                    model.limits.safe_damping,
                ),
                None => out.force,
            };
            let force = world_force(self.world.headings.as_ref(), i, &at, own);
            self.forces[i] = force;
            if self.plant.takes_commands() {
                self.plant.command(i, force, at.dt);
            }
            self.stats.record(
                t,
                i,
                out.status,
                out.saturated,
                out.degenerate,
                out.force.norm(),
            );
        }
        self.estimates_fresh = self.viewed && !clocked;
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
        self.viewed = true;
        if !self.estimates_fresh {
            // The first view, or after a tick that did not copy them (about once a run:
            // from now on every tick copies them).
            for (i, c) in self.controllers.iter().enumerate() {
                Self::read_estimates_of(&**c, &mut self.estimates, &self.est_start, i);
            }
            self.estimates_fresh = true;
        }
        (self.plant.q(), self.plant.v(), &self.estimates)
    }

    fn estimate_info(&self) -> &[EstimateInfo] {
        &self.info
    }

    fn frame_counts(&self) -> FrameCounts {
        let r = self.radio.stats();
        let mut c = FrameCounts {
            broadcasts: r.broadcasts,
            sent: r.sent,
            dropped: r.dropped(),
            lost: r.lost,
            queue_dropped: r.queue_dropped,
            duplicated: r.duplicated,
            corrupted: r.corrupted,
            reordered: r.reordered,
            delivered: r.delivered,
            accepted: 0,
            rejected: 0,
            by_reason: FrameReasons::default(),
        };
        for ctl in &self.controllers {
            let s = ctl.frame_stats();
            c.accepted += u64::from(s.accepted);
            c.rejected += u64::from(s.rejected());
            c.by_reason.add(&s);
        }
        c
    }

    fn control_stats(&self) -> ControlStats {
        self.stats
    }

    fn policy_counts(&self) -> Vec<ph_formation_core::policy::PolicyCounts> {
        self.policy
            .as_ref()
            .map_or_else(Vec::new, super::policy::PolicyRun::counts)
    }

    fn channel_stats(&self) -> Option<ChannelStats> {
        self.radio.channel_stats()
    }

    fn attack_counts(&self) -> Vec<AttackCounts> {
        self.attacks.counts()
    }

    fn take_error(&mut self) -> Option<HilError> {
        // A `LocalCore` never keeps a failure: no walk over 100,000 controllers per tick.
        if self.error.is_none() && !self.local {
            self.error = self.controllers.iter_mut().find_map(|c| c.take_error());
        }
        self.error.take()
    }
}

/// The robot's world besides the vehicle (`docs/world.md`): each agent's heading
/// estimate, its own clock, the wind; `None` where the world is ideal.
struct WorldState {
    headings: Option<Headings>,
    clocks: Option<Clocks>,
    wind: Option<Wind>,
    /// With own clocks: the agents that tick at the current step, each at its tick.
    due: Vec<Option<AgentTick>>,
    /// Each agent's true heading (rad; 0 without a heading model): the camera's
    /// boresight.
    truth: Vec<f64>,
}

impl WorldState {
    fn new(model: &Model) -> Self {
        let w = &model.world;
        let headings = w.heading.as_ref().map(|h| Headings::new(model, h));
        Self {
            truth: headings
                .as_ref()
                .map_or_else(|| vec![0.0; model.n()], |h| h.truth.clone()),
            headings,
            clocks: w.clock.as_ref().map(|c| Clocks::new(model, c)),
            wind: w.wind.as_ref().map(|x| Wind::new(model, x)),
            due: Vec::new(),
        }
    }

    /// When agent `i` ticks at this step: at the common tick `common`, or with own clocks
    /// at its own tick if it is due (`None`: not this step).
    fn tick_of(&self, i: usize, common: AgentTick) -> Option<AgentTick> {
        match &self.clocks {
            None => Some(common),
            Some(_) => self.due.get(i).copied().flatten(),
        }
    }
}

/// How a tick measures: exact bearing rates, ranges, sensors that draw nothing.
#[derive(Clone, Copy, Debug)]
struct MeasureMode {
    exact: bool,
    ranged: bool,
    quiet: bool,
}

/// What a run's agents measure with: the sensors, the bearing sensor (`None`: the
/// omnidirectional ideal one, [`Scene::measure`]'s own loops), every agent's wire id (a
/// bearing's tag) and leader partner.
struct Senses {
    sensors: Sensors,
    bearing: Option<Box<dyn BearingSensor>>,
    ids: Vec<u8>,
    partner: Vec<Option<usize>>,
}

/// What one tick's measurements read: the state, who sees whom and the sensors.
struct Scene<'a> {
    graph: &'a Adjacency,
    q: &'a [Vec2<f64>],
    v: &'a [Vec2<f64>],
    /// Each agent's true heading (rad).
    headings: &'a [f64],
    senses: &'a Senses,
    mode: MeasureMode,
}

impl<'a> Scene<'a> {
    /// The scene of a simulator's parts (taken one by one, so that the caller may write
    /// its other fields meanwhile).
    fn of(model: &'a Model, plant: &'a dyn Plant, senses: &'a Senses, headings: &'a [f64]) -> Self {
        let ranged = model.estimator == Estimator::Measured;
        Self {
            graph: &model.graph.triangle,
            q: plant.q(),
            v: plant.v(),
            headings,
            senses,
            mode: MeasureMode {
                exact: model.sensors.bearing_rate == BearingRate::Exact,
                ranged,
                quiet: !senses.sensors.draws(ranged),
            },
        }
    }

    /// Agent `i`'s measurements at its tick `tick`: its bearings in graph order (to
    /// `push`), then its own velocity and (a leader) its partner offset, drawn in that
    /// order from its stream of the tick ([`Sensors::stream`]); with sensors that draw nothing
    /// ([`MeasureMode::quiet`]) the same values from the state alone, without a stream.
    /// With a bearing sensor, the bearings are its ([`Self::measure_through`]).
    #[inline]
    fn measure(
        &self,
        i: usize,
        tick: u64,
        mut push: impl FnMut(BearingMeasurement<f64>),
    ) -> (Vec2<f64>, Option<Vec2<f64>>) {
        if let Some(sensor) = self.senses.bearing.as_deref() {
            return self.measure_through(sensor, i, tick, push);
        }
        let (q, v, m) = (self.q, self.v, self.mode);
        let Senses {
            sensors,
            ids,
            partner,
            bearing: _,
        } = self.senses;
        let model = sensors.model();
        let partner = partner[i];
        let sight = |j: usize| Sight::between(ids, q, v, i, j);
        // Two loops rather than a test per bearing: the quiet one is the common case.
        if m.quiet {
            for &j in self.graph.of(i) {
                if let Some(b) = quiet_bearing(model, &sight(j), m.exact, m.ranged) {
                    push(b);
                }
            }
            let velocity = velocity_with(model, &v[i], [0.0; 2]);
            return (
                velocity,
                partner.map(|p| offset_with(&q[i], &q[p], [0.0; 2])),
            );
        }
        let mut draws = sensors.stream(i, tick);
        for &j in self.graph.of(i) {
            if let Some(b) = draws.bearing(&sight(j), m.exact, m.ranged) {
                push(b);
            }
        }
        let velocity = draws.velocity(&v[i]);
        (velocity, partner.map(|p| draws.offset(&q[i], &q[p])))
    }

    /// [`Self::measure`] with the bearings of `sensor` ([`BearingSensor::bearing`]), then
    /// the velocity and partner offset, all from agent `i`'s stream of this tick.
    #[inline(never)]
    fn measure_through(
        &self,
        sensor: &dyn BearingSensor,
        i: usize,
        tick: u64,
        mut push: impl FnMut(BearingMeasurement<f64>),
    ) -> (Vec2<f64>, Option<Vec2<f64>>) {
        let (q, v, m) = (self.q, self.v, self.mode);
        let s = self.senses;
        let world = World {
            q,
            v,
            headings: self.headings,
        };
        let kind = BearingKind {
            exact_rate: m.exact,
            with_range: m.ranged,
        };
        let mut draws = s.sensors.stream(i, tick);
        for &j in self.graph.of(i) {
            if let Some(b) = sensor.bearing(&world, &s.ids, i, j, kind, &mut draws) {
                push(b);
            }
        }
        let velocity = draws.velocity(&v[i]);
        let offset = s.partner[i].and_then(|p| sensor.partner_offset(&world, i, p, &mut draws));
        (velocity, offset)
    }
}

/// Prefetches what agent `i`'s tick will read: its controller and, with direct delivery,
/// its frames of the last tick (read by its radio neighbours, the first of which ticks
/// about when `i` does). Takes the parts it reads, not the simulator: the parallel walk
/// holds the controllers mutably.
#[inline]
fn prefetch_agent(footprints: &[Footprint], sent: &[Vec<RadioFrame>], i: usize) {
    if let Some(f) = footprints.get(i) {
        f.prefetch();
    }
    if let Some(frames) = sent.get(i) {
        prefetch::prefetch(frames.as_slice());
    }
}
