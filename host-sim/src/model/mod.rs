//! A validated scenario, resolved to agent indices and SI units: what the simulator runs.
//! The lowest layer: everything else speaks its vocabulary, and it imports no other
//! layer (`docs/architecture.md`).
//!
//! Agents are referred to by index (their position in the scenario's `[[agents]]` list);
//! `AgentModel::id` is the controller-core id used on the wire.

pub mod attack;
mod battery;
pub mod channel;
mod core_config;
mod criteria;
mod devices;
mod error;
pub mod estimates;
pub mod faults;
mod formation;
pub mod geometry;
pub mod graph;
mod options;
mod sensing;
pub mod shape;
pub mod target;
pub mod wire_ids;
pub mod world;

pub use attack::{AttackKind, AttackModel};
pub use battery::BatteryModel;
pub use channel::{Access, AutoRate, ChannelModel, IntegrityMode};
pub use core_config::{CoreAgent, MT, NB};
pub use criteria::Criteria;
pub use devices::PositionsModel;
pub use devices::{CameraModel, RadioDepartures, RadioModel, SensorDepartures, SensorModel};
pub use error::ModelError;
pub use estimates::{estimate_layout, resolve_estimates, EstimateInfo};
pub use faults::{FaultKind, FaultModel, FAULT_KINDS};
pub use formation::{AgentModel, AngleModel, LeaderModel, LeaderOrientation, TriangleModel};
pub use graph::Graph;
pub use options::{BearingRate, Estimator, Mode};
pub use sensing::SensingNoise;
pub use target::Target;
pub use world::{
    ClockModel, CrazyfliePid, HeadingModel, VehicleModel, VelocityTracking, WindModel, WorldModel,
};

use ph_formation_core::{Limits, Schedule};

/// A validated, resolved scenario.
#[derive(Clone, Debug, PartialEq)]
pub struct Model {
    /// Scenario name.
    pub name: String,
    /// Where it came from (file path or `builtin:<name>`).
    pub source: String,
    /// Free text.
    pub description: String,
    /// Simulated time (s).
    pub duration: f64,
    /// Random seed.
    pub seed: u64,
    /// Sampled or continuous.
    pub mode: Mode,
    /// RK4 step (s).
    pub dt: f64,
    /// RK4 steps per logged row.
    pub log_every: usize,
    /// RK4 steps per control tick (the control period is `steps_per_tick · dt`).
    pub steps_per_tick: usize,
    /// Control ticks per broadcast (`rate_hz / comm_rate_hz`, ≥ 1).
    pub comm_every: usize,
    /// `controller.comm_rate_hz = "auto"`: requested (and, once the API resolved it,
    /// what it chose); `None`: the file's rate.
    pub comm_auto: Option<AutoRate>,
    /// How frames are protected (the same for every agent).
    pub integrity: IntegrityMode,
    /// The swarm key of `auth` integrity (zero otherwise). Never written to any output.
    pub auth_key: [u8; 16],
    /// Estimator as named in the file.
    pub estimator: Estimator,
    /// `r̂(0)`.
    pub initial_estimate: f64,
    /// `r_min`.
    pub min_estimate: f64,
    /// Controller limits (force saturation, timeout, margin).
    pub limits: Limits<f64>,
    /// The agents.
    pub agents: Vec<AgentModel>,
    /// The triangles.
    pub triangles: Vec<TriangleModel>,
    /// The leader edge.
    pub leader: Option<LeaderModel>,

    /// `v*(t)`.
    pub velocity_reference: Schedule<f64>,
    /// Sensors.
    pub sensors: SensorModel,
    /// Radio.
    pub radio: RadioModel,
    /// Failure detection and convergence tolerances.
    pub criteria: Criteria,
    /// Edges and neighbour lists.
    pub graph: Graph,
    /// The shape the formation should take (compared with the final positions).
    pub target: Target,
    /// Adversaries on the radio (`[[attacks]]`; empty: none).
    pub attacks: Vec<AttackModel>,
    /// Faults of the flight (`[[faults]]`; empty: none).
    pub faults: Vec<FaultModel>,
    /// The robot's world: vehicle, wind, headings, clocks (`docs/world.md`).
    pub world: WorldModel,
    /// The vehicles' safety policies (`[policy]`; `None`: none run).
    pub policy: Option<ph_formation_core::policy::PolicyConfig<f64>>,
    /// The pre-flight check's radius around each agent's initial position (m,
    /// `policy.start_tolerance_m`): exported to the app, not simulated (a run starts in
    /// the air).
    pub start_tolerance: f64,
    /// The vehicles' battery (`[battery]`; `None`: none modelled, no low-battery policy).
    pub battery: Option<BatteryModel>,
}

impl Model {
    /// For each agent index, its leader partner's index (`None` for non-leaders).
    pub fn partners(&self) -> Vec<Option<usize>> {
        (0..self.agents.len())
            .map(|i| {
                self.leader.as_ref().and_then(|l| match i {
                    _ if i == l.a => Some(l.b),
                    _ if i == l.b => Some(l.a),
                    _ => None,
                })
            })
            .collect()
    }

    /// Communication period (s): `comm_every` control periods.
    pub fn comm_period(&self) -> f64 {
        self.control_period() * self.comm_every as f64
    }

    /// Agent `i`'s broadcast phase: agents take turns round-robin, so that with
    /// `comm_every = k` about `n / k` agents broadcast on each control tick.
    pub fn comm_phase(&self, i: usize) -> usize {
        i % self.comm_every.max(1)
    }

    /// Number of agents.
    pub fn n(&self) -> usize {
        self.agents.len()
    }

    /// Control period (s).
    pub fn control_period(&self) -> f64 {
        self.dt * self.steps_per_tick as f64
    }

    /// Time of RK4 step `k`: `k / (1/dt)` when `1/dt` is a whole number (so that
    /// `t = 0.35` prints as such), `k · dt` otherwise.
    #[inline]
    pub fn time(&self, k: usize) -> f64 {
        let rate = 1.0 / self.dt;
        if (rate - rate.round()).abs() < 1e-9 {
            k as f64 / rate.round()
        } else {
            k as f64 * self.dt
        }
    }

    /// The RK4 step at time `t` (the nearest; [`Self::time`] inverted).
    #[inline]
    pub fn step_of(&self, t: f64) -> usize {
        (t / self.dt).round().max(0.0) as usize
    }

    /// Total number of RK4 steps of the run.
    pub fn total_steps(&self) -> usize {
        // Round to the nearest step; a duration is always a whole number of steps.
        (self.duration / self.dt).round().max(0.0) as usize
    }

    /// Indices of the triangles agent `i` belongs to, in scenario order (the order of
    /// its controller-core configuration).
    pub fn triangles_of(&self, i: usize) -> impl Iterator<Item = usize> + '_ {
        self.graph.membership.of(i).iter().copied()
    }

    /// `v*(t)`.
    #[inline]
    pub fn v_star(&self, t: f64) -> [f64; 2] {
        self.velocity_reference.at(t)
    }

    /// `z*(t)`, if there is a leader edge.
    #[inline]
    pub fn z_star(&self, t: f64) -> Option<[f64; 2]> {
        self.leader.as_ref().map(|l| l.displacement.at(t))
    }

    /// Number of schedule steps (of `v*` and `z*`) that have started by `t`: changes
    /// exactly when a reference switches.
    pub fn schedule_epoch(&self, t: f64) -> usize {
        let count = |s: &Schedule<f64>| s.steps.iter().filter(|st| st.from <= t).count();
        count(&self.velocity_reference) + self.leader.as_ref().map_or(0, |l| count(&l.displacement))
    }
}
