//! The sampled simulator (controllers at their rate with zero-order hold, frames over the
//! radio model) and the run driver shared with [`crate::engine::continuous`]: time loop,
//! diagnostics cadence, logging, failure detection and the run's result.

use crate::analysis::diagnostics::{
    resolve_estimates, Diagnostics, EstimateInfo, Event, Monitor, Outcome,
};
use crate::engine::continuous::ContinuousSim;
use crate::engine::controller::{AgentController, LocalCore};
use crate::engine::hil::{HilError, LinkStats};
use crate::engine::plant::Plant;
use crate::engine::radio::{Radio, RadioFrame};
use crate::engine::sensors::Sensors;
use crate::model::Model;
use crate::report::csv::{Recorder, Row};
use crate::scenario::error::RunError;
use crate::scenario::{BearingRate, Estimator, Mode};
use controller_core::{BearingMeasurement, Fault, Measurements, Status, StepOutput, Vec2};
use std::time::Instant;

/// Cumulative frame counters of a run (link copies; see `docs/outputs.md`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct FrameCounts {
    /// Frames produced by the controllers (each broadcast counted once).
    pub broadcasts: u64,
    /// Link copies sent (one per receiver per broadcast).
    pub sent: u64,
    /// Copies that never arrived (loss or transmit-queue overflow).
    pub dropped: u64,
    /// Copies lost at random.
    pub lost: u64,
    /// Copies dropped by a full transmit queue (bandwidth limit).
    pub queue_dropped: u64,
    /// Extra copies made by duplication.
    pub duplicated: u64,
    /// Copies with a flipped bit.
    pub corrupted: u64,
    /// Copies delayed for reordering.
    pub reordered: u64,
    /// Copies handed to receivers.
    pub delivered: u64,
    /// Delivered copies the receivers' cores accepted.
    pub accepted: u64,
    /// Delivered copies the receivers' cores rejected (CRC, stale sequence, …).
    pub rejected: u64,
}

/// What the controllers did over a run.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct ControlStats {
    /// Agent control ticks (sampled) or controller evaluations (continuous).
    pub ticks: u64,
    /// Of which produced the safe output.
    pub safe: u64,
    /// Safe outputs after `t = 0` (the first tick is always safe: nothing heard yet).
    pub safe_after_start: u64,
    /// Of which were saturated to `max_force`.
    pub saturated: u64,
    /// Of which reported a degenerate (near 0 or π) current angle.
    pub degenerate: u64,
    /// Largest commanded force norm.
    pub max_force: f64,
    /// The last fault after `t = 0`: time, agent index, fault.
    pub last_fault: Option<(f64, usize, Fault)>,
}

impl ControlStats {
    /// Counts one controller output at time `t` of agent `i`.
    pub fn record(
        &mut self,
        t: f64,
        i: usize,
        status: Status,
        saturated: bool,
        degenerate: bool,
        force: f64,
    ) {
        self.ticks += 1;
        if let Status::Safe(f) = status {
            self.safe += 1;
            if t > 0.0 {
                self.safe_after_start += 1;
                self.last_fault = Some((t, i, f));
            }
        }
        self.saturated += u64::from(saturated);
        self.degenerate += u64::from(degenerate);
        if force > self.max_force {
            self.max_force = force;
        }
    }
}

/// A simulation engine the driver advances: sampled or continuous.
pub trait Engine {
    /// Runs the controllers at a control instant `t` (sampled mode; no-op in continuous).
    fn control(&mut self, t: f64);
    /// Advances the state by one RK4 step from `t`.
    fn integrate(&mut self, t: f64);
    /// Refreshes the estimate values and returns `(q, v, estimates)`.
    fn view(&mut self) -> (&[Vec2<f64>], &[Vec2<f64>], &[f64]);
    /// The estimates' layout.
    fn estimate_info(&self) -> &[EstimateInfo];
    /// Frame counters so far.
    fn frame_counts(&self) -> FrameCounts;
    /// Controller counters so far.
    fn control_stats(&self) -> ControlStats;
    /// A controller failure that ends the run (a host-in-the-loop target that stopped
    /// answering or sent a corrupt frame), taken once; checked after every
    /// [`Self::control`].
    fn take_error(&mut self) -> Option<HilError> {
        None
    }
}

/// The sampled-data simulator.
pub struct SampledSim<'m> {
    model: &'m Model,
    controllers: Vec<Box<dyn AgentController>>,
    /// The plant state.
    pub plant: Plant,
    sensors: Sensors,
    radio: Radio,
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
        Ok(Self {
            model,
            controllers,
            plant: Plant::new(model),
            sensors: Sensors::new(&model.sensors, model.seed),
            radio: Radio::new(&model.radio, n, model.seed, capacity),
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
        };
        for ctl in &self.controllers {
            let s = ctl.frame_stats();
            c.accepted += u64::from(s.accepted);
            c.rejected += u64::from(s.rejected());
        }
        c
    }

    fn control_stats(&self) -> ControlStats {
        self.stats
    }

    fn take_error(&mut self) -> Option<HilError> {
        if self.error.is_none() {
            self.error = self.controllers.iter_mut().find_map(|c| c.take_error());
        }
        self.error.take()
    }
}

/// Everything a run found (written to `summary.json` by [`crate::report::csv`]).
#[derive(Clone, Debug, PartialEq)]
pub struct RunResult {
    /// How it ended.
    pub outcome: Outcome,
    /// Why, in words.
    pub reason: String,
    /// Failures detected, in order.
    pub events: Vec<Event>,
    /// Time of the last evaluated instant (s).
    pub final_time: f64,
    /// See [`Monitor::settle_time`].
    pub settle_time: Option<f64>,
    /// Final `max |α − α*|` (rad).
    pub final_max_angle_error: f64,
    /// Final `|z − z*|` (m).
    pub final_displacement_error: f64,
    /// Final `max_n |v_n − v*|` (m/s).
    pub final_velocity_error: f64,
    /// Smallest estimate over the run.
    pub min_estimate: Option<f64>,
    /// Smallest inter-agent distance over the run, with time and agent indices.
    pub min_distance: (f64, f64, usize, usize),
    /// `V(0)`.
    pub v0: f64,
    /// Final `V`.
    pub v_final: f64,
    /// Largest rise of `V` above its running minimum, divided by `V(0)`.
    pub v_max_increase_rel: f64,
    /// When that rise peaked.
    pub v_max_increase_t: f64,
    /// Final positions, agent order.
    pub final_positions: Vec<[f64; 2]>,
    /// Final velocities, agent order.
    pub final_velocities: Vec<[f64; 2]>,
    /// Final estimates (layout order) and their true distances.
    pub final_estimates: Vec<(f64, f64)>,
    /// Per triangle: the sign of its signed area at the end equals the one at the start
    /// (the formation did not flip into its mirror image).
    pub orientation_kept: Vec<bool>,
    /// Frame counters.
    pub frames: FrameCounts,
    /// Controller counters.
    pub control: ControlStats,
    /// Things the user should know (ignored settings, …).
    pub warnings: Vec<String>,
    /// RK4 steps taken.
    pub steps: usize,
    /// Wall-clock seconds.
    pub wall_seconds: f64,
    /// Link figures of the host-in-the-loop agents (empty without).
    pub hil: Vec<LinkStats>,
}

fn signed_area(q: &[Vec2<f64>], t: [usize; 3]) -> f64 {
    let a = q[t[1]] - q[t[0]];
    let b = q[t[2]] - q[t[0]];
    a.x * b.y - a.y * b.x
}

/// Runs `model` in its mode, logging rows to `recorder` and reporting the simulated time
/// to `progress`.
pub fn run(
    model: &Model,
    recorder: &mut dyn Recorder,
    progress: &mut dyn FnMut(f64),
) -> Result<RunResult, String> {
    let mut warnings = Vec::new();
    match model.mode {
        Mode::Sampled => {
            let mut e = SampledSim::new(model)?;
            drive(model, &mut e, recorder, progress, warnings).map_err(|e| e.to_string())
        }
        Mode::Continuous => {
            if model.sensors.is_noisy() {
                warnings.push(
                    "continuous mode: sensor noise and bias are ignored (exact measurements)"
                        .to_owned(),
                );
            }
            if model.radio.is_faulty() {
                warnings
                    .push("continuous mode: the radio settings are ignored (no radio)".to_owned());
            }
            let mut e = ContinuousSim::new(model)?;
            drive(model, &mut e, recorder, progress, warnings).map_err(|e| e.to_string())
        }
    }
}

/// The time loop: control ticks, RK4 steps, diagnostics at every control instant and
/// every log instant, logging, failure detection. A controller failure
/// ([`Engine::take_error`]) ends it with [`RunError::Hil`].
pub fn drive(
    model: &Model,
    engine: &mut dyn Engine,
    recorder: &mut dyn Recorder,
    progress: &mut dyn FnMut(f64),
    warnings: Vec<String>,
) -> Result<RunResult, RunError> {
    let started = Instant::now();
    let total = model.total_steps();
    let spt = model.steps_per_tick.max(1);
    let log_every = model.log_every.max(1);
    let progress_every = (total / 200).max(1);
    let mut diag = Diagnostics::new(model, engine.estimate_info().to_vec());
    let mut monitor = Monitor::new(diag.estimates.len());
    let tri: Vec<[usize; 3]> = model.triangles.iter().map(|t| t.vertices).collect();
    let area0: Vec<f64> = {
        let (q, _, _) = engine.view();
        tri.iter().map(|&t| signed_area(q, t)).collect()
    };
    let mut steps = 0;
    for k in 0..=total {
        let t = model.time(k);
        let tick = k.is_multiple_of(spt);
        if tick {
            engine.control(t);
            if let Some(e) = engine.take_error() {
                let _ = recorder.finish();
                return Err(RunError::Hil(e));
            }
        }
        let log = k.is_multiple_of(log_every) || k == total;
        if tick || log {
            let frames = engine.frame_counts();
            let (q, v, est) = engine.view();
            diag.evaluate(model, t, q, v, est);
            let stop = monitor.observe(model, &diag, est);
            if log || stop {
                recorder
                    .record(&Row {
                        snap: &diag.snap,
                        q,
                        v,
                        estimates: est,
                        frames,
                    })
                    .map_err(|e| format!("cannot write the time series: {e}"))?;
            }
            if stop {
                break;
            }
        }
        if k == total {
            break;
        }
        engine.integrate(t);
        steps += 1;
        if k.is_multiple_of(progress_every) {
            progress(t);
        }
    }
    recorder
        .finish()
        .map_err(|e| format!("cannot write the time series: {e}"))?;
    progress(diag.snap.t);
    let (q, v, est) = engine.view();
    let (outcome, reason) = monitor.verdict(model, &diag.snap);
    let s = &diag.snap;
    Ok(RunResult {
        outcome,
        reason,
        events: monitor.events.clone(),
        final_time: s.t,
        settle_time: monitor.settle_time(),
        final_max_angle_error: s.max_angle_err,
        final_displacement_error: s.disp_err,
        final_velocity_error: s.vel_err,
        min_estimate: monitor.min_estimate,
        min_distance: monitor.min_distance,
        v0: monitor.v0.unwrap_or(0.0),
        v_final: s.v,
        v_max_increase_rel: monitor.v_max_increase_rel(),
        v_max_increase_t: monitor.max_rise_t,
        final_positions: q.iter().map(|p| [p.x, p.y]).collect(),
        final_velocities: v.iter().map(|p| [p.x, p.y]).collect(),
        final_estimates: est
            .iter()
            .copied()
            .zip(s.est_true.iter().copied())
            .collect(),
        orientation_kept: tri
            .iter()
            .zip(&area0)
            .map(|(&t, &a0)| signed_area(q, t).signum() == a0.signum())
            .collect(),
        frames: engine.frame_counts(),
        control: engine.control_stats(),
        warnings,
        steps,
        wall_seconds: started.elapsed().as_secs_f64(),
        hil: Vec::new(),
    })
}
