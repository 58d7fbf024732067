//! The sampled simulator: controllers at their rate with zero-order hold, frames over the
//! radio model, the plant integrated by RK4 between ticks.
//!
//! Two delivery paths, with the same result: frames go through [`Radio`] (faults, delays,
//! the shared channel, attacks), or, when the radio is ideal in timing and faults
//! ([`direct_radio`]), each receiver reads its radio neighbours' frames of the previous
//! tick straight from their outboxes, in sender order, which is exactly what the radio's
//! queue would have delivered. Large runs with local controllers compute the agents'
//! ticks and the plant in parallel ([`PARALLEL_MIN_AGENTS`], `sampled/parallel.rs`): the
//! random streams are drawn in agent order (a block of agents at a time, while the other
//! threads tick the blocks drawn before), so the result does not depend on the number of
//! threads.

mod parallel;

use super::attack::{AttackCounts, Attacks};
use super::channel::ChannelStats;
use super::controller::{local_core, AgentController, Inbox};
use super::driver::Engine;
use super::hil::{HilError, LinkStats};
use super::huge_pages::Regions;
use super::plant::Plant;
use super::prefetch::{self, Footprint};
use super::radio::{Radio, RadioFrame};
use super::sensors::{offset_with, quiet_bearing, velocity_with, BearingNoise, Sensors, Sight};
use super::slot_order::SlotOrder;
use super::stats::{add_frame_stats, ControlStats, FrameCounts};
use crate::model::graph::Adjacency;
use crate::model::{resolve_estimates, BearingRate, EstimateInfo, Estimator, Model, SensorModel};
use controller_core::{BearingMeasurement, FrameStats, Measurements, StepOutput, Vec2};

/// Runs of at least this many agents compute ticks and plant steps on every thread of the
/// current rayon pool (below it the fork-join costs more than it saves).
pub const PARALLEL_MIN_AGENTS: usize = 2048;
/// Agents per parallel work item.
const CHUNK: usize = 256;

/// Whether every frame of a tick arrives, unchanged and in sender order, at the next tick:
/// no loss, duplication, corruption, reordering, jitter, bandwidth limit or shared channel,
/// a latency under half a control period, and no attacker.
pub fn direct_radio(model: &Model) -> bool {
    let r = &model.radio;
    r.loss == 0.0
        && r.duplication == 0.0
        && r.corruption == 0.0
        && (r.reordering == 0.0 || r.reorder_delay == 0.0)
        && r.jitter == 0.0
        && r.bandwidth == 0.0
        && r.channel.is_none()
        && r.latency < 0.5 * model.control_period()
        && model.attacks.is_empty()
}

/// The sampled-data simulator.
pub struct SampledSim<'m> {
    model: &'m Model,
    controllers: Vec<Box<dyn AgentController>>,
    /// Where each controller lies in memory ([`prefetch`]).
    footprints: Vec<Footprint>,
    /// The plant state.
    pub plant: Plant,
    sensors: Sensors,
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
    bearings: Vec<BearingMeasurement<f64>>,
    /// Each agent's bearings go to its core in slot order ([`SlotOrder`]).
    slot_order: SlotOrder,
    partner: Vec<Option<usize>>,
    ids: Vec<u8>,
    estimates: Vec<f64>,
    est_start: Vec<usize>,
    info: Vec<EstimateInfo>,
    last_tick: Option<f64>,
    stats: ControlStats,
    /// Frames bypass [`Radio`]'s queue ([`direct_radio`]).
    direct: bool,
    /// Every controller is a [`LocalCore`](super::LocalCore) (ticks may run in parallel).
    local: bool,
    /// The bearings' noise of every agent (parallel path), drawn in agent order: agent
    /// `i`'s `k`-th triangle neighbour at `noise_start[i] + k` (`noise_start`: `n + 1`
    /// offsets, fixed).
    noise_all: Vec<Option<BearingNoise>>,
    noise_start: Vec<usize>,
    /// Velocity and partner offset measured for every agent (parallel path).
    measured: Vec<(Vec2<f64>, Option<Vec2<f64>>)>,
    /// For every agent, bit `k`: its `k`-th triangle neighbour is in sight
    /// ([`in_sight`], parallel path).
    in_sight: Vec<u64>,
    /// The sums of each block of agents of a noisy parallel tick (reused).
    block_sums: Vec<parallel::TickSums>,
}

/// Frames one agent emits per tick, at most (used to preallocate).
const FRAMES_PER_TICK: usize = 4;

impl<'m> SampledSim<'m> {
    /// A sampled simulation with a [`LocalCore`](super::LocalCore) for every agent, each
    /// in the smallest capacity that holds it ([`local_core`]).
    pub fn new(model: &'m Model) -> Result<Self, String> {
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
    ) -> Result<Self, String> {
        let n = model.n();
        if controllers.len() != n {
            return Err(format!("{} controllers for {n} agents", controllers.len()));
        }
        let mut info = Vec::new();
        let mut est_start = Vec::with_capacity(n + 1);
        for (i, c) in controllers.iter().enumerate() {
            if c.id() != model.agents[i].id {
                return Err(format!(
                    "controller {i} has id {}, expected {}",
                    c.id(),
                    model.agents[i].id
                ));
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
        let direct = direct_radio(model);
        // Direct delivery reads the senders' frames in place: no inbox.
        let inboxes = (0..n)
            .map(|i| {
                let frames = model.graph.radio.of(i).len() * FRAMES_PER_TICK * 4 + 8;
                Vec::with_capacity(if direct { 0 } else { frames })
            })
            .collect();
        let outbox = || Vec::with_capacity(4 * FRAMES_PER_TICK);
        let partner = model.partners();
        let slot_order = SlotOrder::for_model(model, |i| controllers[i].neighbour_order());
        let mut radio = Radio::new(&model.radio, n, model.seed, capacity);
        radio.attach_channel(&model.graph.radio, period);
        let sim = Self {
            model,
            footprints: controllers.iter().map(|c| Footprint::of(&**c)).collect(),
            controllers,
            plant: Plant::new(model),
            sensors: Sensors::new(&model.sensors, model.seed),
            radio,
            attacks: Attacks::new(model),
            inboxes,
            outboxes: (0..n).map(|_| outbox()).collect(),
            sent: (0..if direct { n } else { 0 }).map(|_| outbox()).collect(),
            outputs: vec![None; n],
            error: None,
            forces: vec![Vec2::zeros(); n],
            bearings: Vec::with_capacity(model.graph.triangle.max_degree()),
            slot_order,
            partner,
            ids: model.agents.iter().map(|a| a.id).collect(),
            estimates: vec![model.initial_estimate; info.len()],
            est_start,
            info,
            last_tick: None,
            stats: ControlStats::default(),
            direct,
            local: false,
            noise_all: vec![None; model.graph.triangle.total()],
            noise_start: std::iter::once(0)
                .chain((0..n).scan(0, |at, i| {
                    *at += model.graph.triangle.of(i).len();
                    Some(*at)
                }))
                .collect(),
            measured: vec![(Vec2::zeros(), None); n],
            in_sight: vec![0; n],
            block_sums: Vec::new(),
        };
        sim.huge_pages();
        Ok(sim)
    }

    /// Backs the per-agent memory every tick walks (controllers, frame buffers) with huge
    /// pages where the system allows it ([`huge_pages`](super::huge_pages)): a hint, no
    /// value changes.
    fn huge_pages(&self) {
        let mut regions = Regions::new();
        for c in &self.controllers {
            regions.add(&**c);
        }
        for b in self.outboxes.iter().chain(&self.sent).chain(&self.inboxes) {
            regions.add_buffer(b);
        }
        regions.collapse();
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

    /// The link figures of the remote controllers, in agent order.
    pub fn link_stats(&self) -> Vec<LinkStats> {
        self.controllers
            .iter()
            .filter_map(|c| c.link_stats())
            .collect()
    }
}

impl SampledSim<'_> {
    /// `steps` RK4 steps of the plant under the held forces: on every thread when the
    /// ticks are, each work item taking every step of its agents (one fork-join);
    /// otherwise one step over all agents at a time (measured faster on one thread).
    fn plant_steps(&mut self, steps: usize) {
        let dt = self.model.dt;
        if self.parallel() {
            self.plant.step_parallel(&self.forces, dt, steps, CHUNK);
        } else {
            for _ in 0..steps {
                self.plant.step(&self.forces, dt);
            }
        }
    }

    /// Whether this tick runs on every thread of the current rayon pool.
    fn parallel(&self) -> bool {
        self.local && self.model.n() >= PARALLEL_MIN_AGENTS && rayon::current_num_threads() > 1
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

    /// Measures agent `i` (drawing its noise from the sensors' stream) into `bearings`,
    /// in its core's slot order; with `m.quiet` (the sensors draw nothing:
    /// [`Sensors::draws`]) the same measurements without the stream.
    fn measure(&mut self, i: usize, m: MeasureMode) -> (Vec2<f64>, Option<Vec2<f64>>) {
        let (q, v) = (&self.plant.q, &self.plant.v);
        for &j in self.model.graph.triangle.of(i) {
            let sight = Sight::between(&self.ids, q, v, i, j);
            let b = match m.quiet {
                true => quiet_bearing(self.sensors.model(), &sight, m.exact, m.ranged),
                false => self.sensors.bearing(&sight, m.exact, m.ranged),
            };
            if let Some(b) = b {
                self.bearings.push(b);
            }
        }
        self.slot_order.apply(i, &mut self.bearings);
        match m.quiet {
            true => quiet_own(self.sensors.model(), q, v, &self.partner, i),
            false => self.measure_own(i),
        }
    }

    /// How this run's agents measure.
    fn measure_mode(&self) -> MeasureMode {
        let ranged = self.model.estimator == Estimator::Measured;
        MeasureMode {
            exact: self.model.sensors.bearing_rate == BearingRate::Exact,
            ranged,
            quiet: !self.sensors.draws(ranged),
        }
    }

    /// Agent `i`'s own velocity and (a leader) its partner offset, drawn after its
    /// bearings ([`own_measurement`]).
    fn measure_own(&mut self, i: usize) -> (Vec2<f64>, Option<Vec2<f64>>) {
        own_measurement(
            &mut self.sensors,
            &self.plant.q,
            &self.plant.v,
            &self.partner,
            i,
        )
    }

    /// Every agent measured and its tick started, in agent order.
    fn tick_sequential(&mut self, t: f64, dt: f64) -> Result<(), HilError> {
        let mode = self.measure_mode();
        let mut delivered = 0;
        for i in 0..self.model.n() {
            prefetch_agent(&self.footprints, &self.sent, i + prefetch::AHEAD);
            self.bearings.clear();
            let (velocity, partner_offset) = self.measure(i, mode);
            let m = Measurements {
                time: t,
                dt,
                velocity,
                bearings: &self.bearings,
                partner_offset,
            };
            self.outboxes[i].clear();
            let inbox = Self::inbox(&self.inboxes[i], &self.sent, &self.model.graph.radio, i);
            delivered += inbox.len() as u64;
            self.outputs[i] = self.controllers[i].start_tick(inbox, &m, &mut self.outboxes[i])?;
            self.inboxes[i].clear();
        }
        self.count_direct(delivered);
        Ok(())
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
                    .overhear(t, i, f.as_bytes(), &self.plant.q, model, &mut self.radio);
            }
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
    /// Two phases: every agent is measured in agent order and its tick started (local
    /// controllers complete it at once, remote ones only send their inputs), then every
    /// output is collected and every agent's frames broadcast, in agent order (so the
    /// random streams are drawn in the same order as without remote controllers).
    fn control(&mut self, t: f64) {
        if self.error.is_some() {
            return;
        }
        let model = self.model;
        let parallel = self.parallel();
        if self.direct {
            // The frames of the last tick are read where their senders left them.
            std::mem::swap(&mut self.outboxes, &mut self.sent);
        } else {
            self.radio.observe(&self.plant.q);
            if !self.attacks.is_empty() {
                let period = model.dt * model.steps_per_tick as f64;
                self.attacks
                    .tick(t, period, &self.plant.q, model, &mut self.radio);
            }
            self.radio.deliver(t, &mut self.inboxes);
        }
        let dt = self.last_tick.map_or(0.0, |p| t - p);
        if parallel {
            // Forces, counters and statistics kept on every thread: only the radio's
            // broadcasts (one random stream, in agent order) remain.
            self.tick_parallel(t, dt);
            if !self.direct {
                for i in 0..model.n() {
                    self.broadcast(t, i);
                }
            }
            self.last_tick = Some(t);
            return;
        }
        if let Err(e) = self.tick_sequential(t, dt) {
            self.error = Some(e);
            return;
        }
        for i in 0..model.n() {
            let out = match self.outputs[i].take() {
                Some(out) => out,
                None => match self.controllers[i].finish_tick(&mut self.outboxes[i]) {
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
            self.forces[i] = out.force;
            self.stats.record(
                t,
                i,
                out.status,
                out.saturated,
                out.degenerate,
                out.force.norm(),
            );
        }
        self.last_tick = Some(t);
    }

    fn integrate(&mut self, _t: f64) {
        self.plant_steps(1);
    }

    /// The plant does not depend on `t`: all the steps at once.
    fn integrate_steps(&mut self, _model: &Model, _k: usize, steps: usize) {
        self.plant_steps(steps);
    }

    fn view(&mut self) -> (&[Vec2<f64>], &[Vec2<f64>], &[f64]) {
        let parallel = self.parallel();
        read_estimates(
            &mut self.controllers,
            &mut self.estimates,
            &self.est_start,
            parallel,
        );
        (&self.plant.q, &self.plant.v, &self.estimates)
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
            by_reason: FrameStats::default(),
        };
        for ctl in &self.controllers {
            let s = ctl.frame_stats();
            c.accepted += u64::from(s.accepted);
            c.rejected += u64::from(s.rejected());
            add_frame_stats(&mut c.by_reason, &s);
        }
        c
    }

    fn control_stats(&self) -> ControlStats {
        self.stats
    }

    fn channel_stats(&self) -> Option<ChannelStats> {
        self.radio.channel_stats()
    }

    fn attack_counts(&self) -> Vec<AttackCounts> {
        self.attacks.counts()
    }

    fn take_error(&mut self) -> Option<HilError> {
        if self.error.is_none() {
            self.error = self.controllers.iter_mut().find_map(|c| c.take_error());
        }
        self.error.take()
    }
}

/// Reads every controller's estimates into `est` (agent `i`'s at
/// `est[start[i] - start[0]..start[i + 1] - start[0]]`; `start` has one entry more than
/// `controllers`). `parallel`: halves on every thread of the current rayon pool, down to
/// [`CHUNK`] agents (each agent writes only its own slots: the same values on any number
/// of threads, without allocating).
fn read_estimates(
    controllers: &mut [Box<dyn AgentController>],
    est: &mut [f64],
    start: &[usize],
    parallel: bool,
) {
    if parallel && controllers.len() > CHUNK {
        let mid = controllers.len() / 2;
        let (c_lo, c_hi) = controllers.split_at_mut(mid);
        let split = start[mid] - start[0];
        let (e_lo, e_hi) = est.split_at_mut(split.min(est.len()));
        rayon::join(
            || read_estimates(c_lo, e_lo, &start[..=mid], true),
            || read_estimates(c_hi, e_hi, &start[mid..], true),
        );
        return;
    }
    let base = start.first().copied().unwrap_or(0);
    for (i, c) in controllers.iter().enumerate() {
        let (a, b) = (start[i] - base, start[i + 1] - base);
        if let Some(slot) = est.get_mut(a..b) {
            c.read_estimates(slot);
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

/// [`own_measurement`] when the sensors draw nothing ([`Sensors::draws`]): the same
/// values, without the stream.
fn quiet_own(
    model: &SensorModel,
    q: &[Vec2<f64>],
    v: &[Vec2<f64>],
    partner: &[Option<usize>],
    i: usize,
) -> (Vec2<f64>, Option<Vec2<f64>>) {
    let velocity = velocity_with(model, &v[i], [0.0; 2]);
    (
        velocity,
        partner[i].map(|p| offset_with(&q[i], &q[p], [0.0; 2])),
    )
}

/// Agent `i`'s measured own velocity, then (a leader) its partner offset, from the
/// sensors' stream in that order.
fn own_measurement(
    sensors: &mut Sensors,
    q: &[Vec2<f64>],
    v: &[Vec2<f64>],
    partner: &[Option<usize>],
    i: usize,
) -> (Vec2<f64>, Option<Vec2<f64>>) {
    let velocity = sensors.velocity(&v[i]);
    let partner_offset = partner[i].map(|p| sensors.offset(&q[i], &q[p]));
    (velocity, partner_offset)
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
