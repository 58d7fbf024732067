//! A validated scenario, resolved to agent indices and SI units: what the simulator runs.
//!
//! Agents are referred to by index (their position in the scenario's `[[agents]]` list);
//! `AgentModel::id` is the controller-core id used on the wire.

pub mod graph;

use crate::model::graph::Graph;
use crate::scenario::{BearingRate, CriteriaSpec, Estimator, Mode};
use controller_core::{
    AgentConfig, AngleConfig, EstimatorMode, LeaderConfig, LeaderRole, Limits, Schedule,
    TriangleConfig,
};

/// Triangle capacity of one host agent (`MT` of `controller_core::Agent`).
pub const MT: usize = 8;
/// Neighbour capacity of one host agent (`NB` of `controller_core::Agent`).
pub const NB: usize = 12;
/// The controller-core agent the host simulates.
pub type CoreAgent = controller_core::Agent<f64, MT, NB>;

/// One agent's plant and initial state.
#[derive(Clone, Debug, PartialEq)]
pub struct AgentModel {
    /// Wire id.
    pub id: u8,
    /// `q(0)`.
    pub position: [f64; 2],
    /// `v(0)`.
    pub velocity: [f64; 2],
    /// Mass.
    pub mass: f64,
    /// `D^r` (diagonal).
    pub friction: [f64; 2],
    /// `D^v` (diagonal).
    pub velocity_damping: [f64; 2],
}

/// One controlled angle, by agent index.
#[derive(Clone, Debug, PartialEq)]
pub struct AngleModel {
    /// Apex `u`.
    pub apex: usize,
    /// Far vertices `[v, w]`, in the triangle's vertex order (as controller-core orders
    /// them: edge 0 is `u–v`, edge 1 is `u–w`).
    pub far: [usize; 2],
    /// `α*` (rad).
    pub desired: f64,
    /// `c_α`.
    pub stiffness: f64,
    /// `d_α`.
    pub damping: f64,
    /// `c_e`.
    pub estimator_gain: f64,
}

/// One triangle, by agent index.
#[derive(Clone, Debug, PartialEq)]
pub struct TriangleModel {
    /// The three vertices.
    pub vertices: [usize; 3],
    /// The two controlled angles.
    pub angles: [AngleModel; 2],
}

/// The leader edge (S11), `z = q_a − q_b`.
#[derive(Clone, Debug, PartialEq)]
pub struct LeaderModel {
    /// Agent `a`.
    pub a: usize,
    /// Agent `b`.
    pub b: usize,
    /// `k_z`.
    pub stiffness: f64,
    /// `D_z` (diagonal).
    pub damping: [f64; 2],
    /// `z*(t)`.
    pub displacement: Schedule<f64>,
}

/// Sensor imperfections, in SI units.
#[derive(Clone, Debug, PartialEq)]
pub struct SensorModel {
    /// Bearing angle noise standard deviation (rad).
    pub bearing_noise: f64,
    /// Bearing rotation bias (rad).
    pub bearing_bias: f64,
    /// Source of bearing rates.
    pub bearing_rate: BearingRate,
    /// Velocity noise standard deviation per component (m/s).
    pub velocity_noise: f64,
    /// Velocity bias (m/s).
    pub velocity_bias: [f64; 2],
    /// Leader relative-position noise per component (m).
    pub offset_noise: f64,
    /// Range noise (m).
    pub range_noise: f64,
}

impl SensorModel {
    /// No noise, no bias, the given rate source.
    pub fn ideal(bearing_rate: BearingRate) -> Self {
        Self {
            bearing_noise: 0.0,
            bearing_bias: 0.0,
            bearing_rate,
            velocity_noise: 0.0,
            velocity_bias: [0.0; 2],
            offset_noise: 0.0,
            range_noise: 0.0,
        }
    }

    /// Whether any noise or bias is configured.
    pub fn is_noisy(&self) -> bool {
        self.bearing_noise != 0.0
            || self.bearing_bias != 0.0
            || self.velocity_noise != 0.0
            || self.velocity_bias != [0.0; 2]
            || self.offset_noise != 0.0
            || self.range_noise != 0.0
    }
}

/// The radio link model, in SI units.
#[derive(Clone, Debug, PartialEq)]
pub struct RadioModel {
    /// Fixed latency (s).
    pub latency: f64,
    /// Uniform extra delay bound (s).
    pub jitter: f64,
    /// Loss probability per link copy.
    pub loss: f64,
    /// Duplication probability per link copy.
    pub duplication: f64,
    /// Reordering probability per link copy.
    pub reordering: f64,
    /// Largest extra delay of a reordered copy (s).
    pub reorder_delay: f64,
    /// Corruption (one bit flip) probability per link copy.
    pub corruption: f64,
    /// Sender air time in bytes/s (0 = unlimited).
    pub bandwidth: f64,
    /// Longest transmit-queue wait before a drop (s).
    pub queue_limit: f64,
}

impl RadioModel {
    /// A perfect radio (every frame delivered at the next tick).
    pub fn ideal() -> Self {
        Self {
            latency: 0.0,
            jitter: 0.0,
            loss: 0.0,
            duplication: 0.0,
            reordering: 0.0,
            reorder_delay: 0.0,
            corruption: 0.0,
            bandwidth: 0.0,
            queue_limit: 0.05,
        }
    }

    /// Whether any fault or delay is configured.
    pub fn is_faulty(&self) -> bool {
        self.latency != 0.0
            || self.jitter != 0.0
            || self.loss != 0.0
            || self.duplication != 0.0
            || self.reordering != 0.0
            || self.corruption != 0.0
            || self.bandwidth != 0.0
    }
}

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
    pub criteria: CriteriaSpec,
    /// Edges and neighbour lists.
    pub graph: Graph,
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

    /// Total number of RK4 steps of the run.
    pub fn total_steps(&self) -> usize {
        // Round to the nearest step; a duration is always a whole number of steps.
        (self.duration / self.dt).round().max(0.0) as usize
    }

    /// Core estimator mode.
    pub fn estimator_mode(&self) -> EstimatorMode {
        match self.estimator {
            Estimator::Shared => EstimatorMode::Shared,
            Estimator::PerAgent => EstimatorMode::PerAgent,
            Estimator::Measured => EstimatorMode::Measured,
        }
    }

    /// Whether agent `i` is in triangle `t`.
    fn in_triangle(t: &TriangleModel, i: usize) -> bool {
        t.vertices.contains(&i)
    }

    /// Indices of the triangles agent `i` belongs to, in scenario order (the order of
    /// its controller-core configuration).
    pub fn triangles_of(&self, i: usize) -> impl Iterator<Item = usize> + '_ {
        self.triangles
            .iter()
            .enumerate()
            .filter(move |(_, t)| Self::in_triangle(t, i))
            .map(|(k, _)| k)
    }

    /// Agent `i`'s controller-core configuration. Fails only beyond the capacity `MT`.
    pub fn agent_config(&self, i: usize) -> Result<AgentConfig<f64, MT>, String> {
        let a = self
            .agents
            .get(i)
            .ok_or_else(|| format!("no agent index {i}"))?;
        let mut c = AgentConfig::new(a.id);
        for k in self.triangles_of(i) {
            let t = &self.triangles[k];
            let ang = |m: &AngleModel| AngleConfig {
                apex: self.agents[m.apex].id,
                cos_desired: m.desired.cos(),
                stiffness: m.stiffness,
                damping: m.damping,
                estimator_gain: m.estimator_gain,
            };
            let tc = TriangleConfig {
                vertices: t.vertices.map(|v| self.agents[v].id),
                angles: [ang(&t.angles[0]), ang(&t.angles[1])],
            };
            c.triangles.push(tc).map_err(|_| {
                format!(
                    "agent {} belongs to more than {MT} triangles (controller capacity)",
                    a.id
                )
            })?;
        }
        c.estimator = self.estimator_mode();
        c.initial_estimate = self.initial_estimate;
        c.min_estimate = self.min_estimate;
        c.friction = a.friction;
        c.velocity_damping = a.velocity_damping;
        c.velocity_reference = self.velocity_reference.clone();
        c.limits = self.limits;
        if let Some(l) = &self.leader {
            let role = if l.a == i {
                Some((LeaderRole::A, l.b))
            } else if l.b == i {
                Some((LeaderRole::B, l.a))
            } else {
                None
            };
            c.leader = role.map(|(role, p)| LeaderConfig {
                role,
                partner: self.agents[p].id,
                stiffness: l.stiffness,
                damping: l.damping,
                displacement: l.displacement.clone(),
            });
        }
        Ok(c)
    }

    /// Builds agent `i`'s controller-core agent.
    pub fn core_agent(&self, i: usize) -> Result<CoreAgent, String> {
        let c = self.agent_config(i)?;
        CoreAgent::new(c).map_err(|e| format!("controller-core refused agent index {i}: {e:?}"))
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
