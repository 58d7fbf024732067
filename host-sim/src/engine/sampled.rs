//! The sampled simulator: controllers at their rate with zero-order hold, frames over the
//! radio model, the plant integrated by RK4 between ticks.

use super::attack::{AttackCounts, Attacks};
use super::channel::ChannelStats;
use super::controller::{AgentController, LocalCore};
use super::driver::Engine;
use super::hil::{HilError, LinkStats};
use super::plant::Plant;
use super::radio::{Radio, RadioFrame};
use super::sensors::Sensors;
use super::stats::{add_frame_stats, ControlStats, FrameCounts};
use crate::model::{resolve_estimates, BearingRate, EstimateInfo, Estimator, Model};
use controller_core::{BearingMeasurement, FrameStats, Measurements, StepOutput, Vec2};

/// The sampled-data simulator.
pub struct SampledSim<'m> {
    model: &'m Model,
    controllers: Vec<Box<dyn AgentController>>,
    /// The plant state.
    pub plant: Plant,
    sensors: Sensors,
    radio: Radio,
    attacks: Attacks,
    inboxes: Vec<Vec<RadioFrame>>,
    outboxes: Vec<Vec<RadioFrame>>,
    outputs: Vec<Option<StepOutput<f64>>>,
    error: Option<HilError>,
    forces: Vec<Vec2<f64>>,
    bearings: Vec<BearingMeasurement<f64>>,
    partner: Vec<Option<usize>>,
    ids: Vec<u8>,
    estimates: Vec<f64>,
    est_start: Vec<usize>,
    info: Vec<EstimateInfo>,
    last_tick: Option<f64>,
    stats: ControlStats,
}

/// Frames one agent emits per tick, at most (used to preallocate).
const FRAMES_PER_TICK: usize = 4;

impl<'m> SampledSim<'m> {
    /// A sampled simulation with a [`LocalCore`] for every agent.
    pub fn new(model: &'m Model) -> Result<Self, String> {
        let mut controllers: Vec<Box<dyn AgentController>> = Vec::with_capacity(model.n());
        for i in 0..model.n() {
            controllers.push(Box::new(LocalCore::new(model.core_agent(i)?)));
        }
        Self::with_controllers(model, controllers)
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
        let inboxes = (0..n)
            .map(|i| Vec::with_capacity(model.graph.radio.of(i).len() * FRAMES_PER_TICK * 4 + 8))
            .collect();
        let partner = model.partners();
        let mut radio = Radio::new(&model.radio, n, model.seed, capacity);
        radio.attach_channel(&model.graph.radio, period);
        Ok(Self {
            model,
            controllers,
            plant: Plant::new(model),
            sensors: Sensors::new(&model.sensors, model.seed),
            radio,
            attacks: Attacks::new(model),
            inboxes,
            outboxes: (0..n)
                .map(|_| Vec::with_capacity(4 * FRAMES_PER_TICK))
                .collect(),
            outputs: vec![None; n],
            error: None,
            forces: vec![Vec2::zeros(); n],
            bearings: Vec::with_capacity(model.graph.triangle.max_degree()),
            partner,
            ids: model.agents.iter().map(|a| a.id).collect(),
            estimates: vec![model.initial_estimate; info.len()],
            est_start,
            info,
            last_tick: None,
            stats: ControlStats::default(),
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
            for s in 0..spt {
                self.integrate(t0 + s as f64 * dt);
            }
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
        self.radio.observe(&self.plant.q);
        if !self.attacks.is_empty() {
            let period = model.dt * model.steps_per_tick as f64;
            self.attacks
                .tick(t, period, &self.plant.q, model, &mut self.radio);
        }
        self.radio.deliver(t, &mut self.inboxes);
        let dt = self.last_tick.map_or(0.0, |p| t - p);
        let exact = model.sensors.bearing_rate == BearingRate::Exact;
        let ranged = model.estimator == Estimator::Measured;
        let q = &self.plant.q;
        let v = &self.plant.v;
        for i in 0..model.n() {
            self.bearings.clear();
            for &j in model.graph.triangle.of(i) {
                if let Some(b) =
                    self.sensors
                        .bearing(self.ids[j], &q[i], &q[j], &v[i], &v[j], exact, ranged)
                {
                    self.bearings.push(b);
                }
            }
            let velocity = self.sensors.velocity(&v[i]);
            let partner_offset = self.partner[i].map(|p| self.sensors.offset(&q[i], &q[p]));
            let m = Measurements {
                time: t,
                dt,
                velocity,
                bearings: &self.bearings,
                partner_offset,
            };
            self.outboxes[i].clear();
            match self.controllers[i].start_tick(&self.inboxes[i], &m, &mut self.outboxes[i]) {
                Ok(out) => self.outputs[i] = out,
                Err(e) => {
                    self.error = Some(e);
                    return;
                }
            }
            self.inboxes[i].clear();
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
            for f in &self.outboxes[i] {
                self.radio
                    .broadcast(t, i, model.graph.radio.of(i), f.as_bytes());
                if !self.attacks.is_empty() {
                    self.attacks.overhear(
                        t,
                        i,
                        f.as_bytes(),
                        &self.plant.q,
                        model,
                        &mut self.radio,
                    );
                }
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
        self.plant.step(&self.forces, self.model.dt);
    }

    fn view(&mut self) -> (&[Vec2<f64>], &[Vec2<f64>], &[f64]) {
        for (i, c) in self.controllers.iter().enumerate() {
            let (a, b) = (self.est_start[i], self.est_start[i + 1]);
            if let Some(slot) = self.estimates.get_mut(a..b) {
                c.read_estimates(slot);
            }
        }
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
