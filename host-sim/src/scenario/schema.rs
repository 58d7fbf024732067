//! The scenario file's TOML schema (`docs/scenarios.md`): the whole file, the formation
//! (agents, triangles, leader, gains) and the schedule and matrix shorthands. The
//! run-wide sections are in [`super::settings`].

use super::settings::{AttackSpec, ControllerSpec, Integration, RadioSpec, SensorSpec};
use super::world::{ClockSpec, HeadingSpec, PlantTable, WindSpec};
use crate::model::{Criteria, LeaderOrientation, Mode};
use serde::{Deserialize, Serialize};

/// A diagonal 2×2 matrix: one number (`d·I`) or `[d_x, d_y]`.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(untagged)]
pub enum Diagonal {
    /// `d · I`.
    Scalar(f64),
    /// `diag(d_x, d_y)`.
    Pair([f64; 2]),
}

impl Diagonal {
    /// The diagonal as `[d_x, d_y]`.
    pub fn pair(self) -> [f64; 2] {
        match self {
            Diagonal::Scalar(d) => [d, d],
            Diagonal::Pair(p) => p,
        }
    }
}

/// One step of a piecewise-constant schedule.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct StepSpec {
    /// Start time (s).
    pub from: f64,
    /// The value `[x, y]` from then on.
    pub value: [f64; 2],
}

/// A schedule: a constant `[x, y]` or a list of `{ from, value }` steps.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(untagged)]
pub enum ScheduleSpec {
    /// The same value from `t = 0` on.
    Constant([f64; 2]),
    /// Piecewise constant, steps sorted by `from`.
    Steps(Vec<StepSpec>),
}

impl Default for ScheduleSpec {
    fn default() -> Self {
        ScheduleSpec::Constant([0.0, 0.0])
    }
}

impl ScheduleSpec {
    /// The steps (a constant is one step from `t = 0`).
    pub fn steps(&self) -> Vec<StepSpec> {
        match self {
            ScheduleSpec::Constant(v) => vec![StepSpec {
                from: 0.0,
                value: *v,
            }],
            ScheduleSpec::Steps(s) => s.clone(),
        }
    }
}

/// `[gains]`: default gains of every controlled angle (each angle may override them).
/// A gain given neither here nor by the angle is that of the built-in `formation-only`
/// ([`GainsSpec::DEFAULT_STIFFNESS`], …; docs/scenarios.md).
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct GainsSpec {
    /// `c_α`.
    pub stiffness: Option<f64>,
    /// `d_α`.
    pub damping: Option<f64>,
    /// `c_e`.
    pub estimator_gain: Option<f64>,
}

impl GainsSpec {
    /// `c_α` when neither `[gains]` nor the angle gives it: `formation-only`'s.
    pub const DEFAULT_STIFFNESS: f64 = 10.0;
    /// `d_α` when neither `[gains]` nor the angle gives it: `formation-only`'s.
    pub const DEFAULT_DAMPING: f64 = 1.0;
    /// `c_e` when neither `[gains]` nor the angle gives it: `formation-only`'s.
    pub const DEFAULT_ESTIMATOR_GAIN: f64 = 10.0;
}

/// `[agent_defaults]`: values used by agents that do not give their own.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct AgentDefaults {
    /// Mass (kg).
    pub mass: f64,
    /// `D^r` (friction).
    pub friction: Diagonal,
    /// `D^v` (velocity-tracking damping of S12).
    pub velocity_damping: Diagonal,
}

impl Default for AgentDefaults {
    fn default() -> Self {
        Self {
            mass: 1.0,
            friction: Diagonal::Scalar(0.0),
            velocity_damping: Diagonal::Scalar(0.0),
        }
    }
}

/// An agent's id as the user writes it: a non-negative integer or a short name.
#[derive(Clone, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(untagged)]
pub enum AgentId {
    /// `id = 7` (must be ≥ 0).
    Number(i64),
    /// `id = "north-3"` (1–32 letters, digits, `-`, `.`).
    Name(String),
}

impl std::fmt::Display for AgentId {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Self::Number(i) => write!(f, "{i}"),
            Self::Name(s) => f.write_str(s),
        }
    }
}

/// One `[[agents]]` entry.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct AgentSpec {
    /// Identifier, unique: a non-negative integer or a short name (the wire id is
    /// assigned from it, see `docs/scenarios.md`).
    pub id: AgentId,
    /// `q(0)` (m).
    pub position: [f64; 2],
    /// `v(0)` (m/s), default zero.
    #[serde(default)]
    pub velocity: Option<[f64; 2]>,
    /// Mass (kg), default from `[agent_defaults]`.
    #[serde(default)]
    pub mass: Option<f64>,
    /// `D^r`, default from `[agent_defaults]`.
    #[serde(default)]
    pub friction: Option<Diagonal>,
    /// `D^v`, default from `[agent_defaults]`.
    #[serde(default)]
    pub velocity_damping: Option<Diagonal>,
    /// The agent's true initial heading (degrees): its body x axis and its camera's
    /// boresight. Default: `heading.initial_deg` plus the spread draw (0 without
    /// `[heading]`); a given value wins over the spread.
    #[serde(default)]
    pub heading_deg: Option<f64>,
}

/// One controlled angle of a triangle.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct AngleSpec {
    /// The apex agent id.
    pub apex: AgentId,
    /// Desired angle in degrees (give this or `desired_rad`).
    #[serde(default)]
    pub desired_deg: Option<f64>,
    /// Desired angle in radians (give this or `desired_deg`).
    #[serde(default)]
    pub desired_rad: Option<f64>,
    /// `c_α`, default `[gains].stiffness`.
    #[serde(default)]
    pub stiffness: Option<f64>,
    /// `d_α`, default `[gains].damping`.
    #[serde(default)]
    pub damping: Option<f64>,
    /// `c_e`, default `[gains].estimator_gain`.
    #[serde(default)]
    pub estimator_gain: Option<f64>,
}

/// One `[[triangles]]` entry.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TriangleSpec {
    /// The three vertex ids.
    pub vertices: [AgentId; 3],
    /// Exactly two controlled angles with distinct apexes.
    pub angles: Vec<AngleSpec>,
}

/// `[leader]`: the leader edge maneuver (S11).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LeaderSpec {
    /// `[a, b]` with `z = q_a − q_b`.
    pub agents: [AgentId; 2],
    /// `k_z`.
    pub stiffness: f64,
    /// `D_z`.
    pub damping: Diagonal,
    /// `z*(t)`.
    pub displacement: ScheduleSpec,
    /// Who controls the edge's orientation: `auto` (default), `both`, `a`.
    #[serde(default, skip_serializing_if = "LeaderOrientation::is_auto")]
    pub orientation: LeaderOrientation,
}

/// A whole scenario file (schema in `docs/scenarios.md`).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ScenarioFile {
    /// Name (output directory and `summary.json`); default: the file stem.
    #[serde(default)]
    pub name: Option<String>,
    /// Free text.
    #[serde(default)]
    pub description: Option<String>,
    /// Simulated time (s).
    #[serde(default = "default_duration")]
    pub duration: f64,
    /// Seed of every random number (noise, radio).
    #[serde(default)]
    pub seed: u64,
    /// `sampled` or `continuous`.
    #[serde(default)]
    pub mode: Mode,
    /// `[integration]`.
    #[serde(default)]
    pub integration: Integration,
    /// `[controller]`.
    #[serde(default)]
    pub controller: ControllerSpec,
    /// `[gains]`.
    #[serde(default)]
    pub gains: GainsSpec,
    /// `[agent_defaults]`.
    #[serde(default)]
    pub agent_defaults: AgentDefaults,
    /// `[[agents]]`.
    pub agents: Vec<AgentSpec>,
    /// `[[triangles]]`.
    #[serde(default)]
    pub triangles: Vec<TriangleSpec>,
    /// `[leader]` (optional).
    #[serde(default)]
    pub leader: Option<LeaderSpec>,
    /// `v*(t)`, default zero.
    #[serde(default)]
    pub velocity_reference: ScheduleSpec,
    /// `[sensors]`.
    #[serde(default)]
    pub sensors: SensorSpec,
    /// `[radio]`.
    #[serde(default)]
    pub radio: RadioSpec,
    /// `[criteria]`.
    #[serde(default)]
    pub criteria: Criteria,
    /// `[target]`: the shape the formation should take (optional; `host-sim design`
    /// writes it).
    #[serde(default)]
    pub target: Option<TargetSpec>,
    /// `[[attacks]]`: adversaries on the radio (`docs/attacks.md`).
    #[serde(default)]
    pub attacks: Vec<AttackSpec>,
    /// `[[faults]]`: faults of a real flight (`docs/faults.md`).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub faults: Vec<super::faults::FaultSpec>,
    /// `world`: a preset of the robot's world (`ideal`, `crazyflie`; `docs/world.md`),
    /// merged under the file.
    #[serde(default)]
    pub world: Option<String>,
    /// `[plant]`: the vehicle, as written (resolved by `world::plant_spec`).
    #[serde(default)]
    pub plant: PlantTable,
    /// `[wind]` (optional).
    #[serde(default)]
    pub wind: Option<WindSpec>,
    /// `[heading]`: body frames and heading estimates (optional).
    #[serde(default)]
    pub heading: Option<HeadingSpec>,
    /// `[clock]`: each agent's own clock (optional).
    #[serde(default)]
    pub clock: Option<ClockSpec>,
    /// `[policy]`: the vehicles' safety policies (optional).
    #[serde(default)]
    pub policy: Option<super::policy::PolicySpec>,
    /// `[battery]`: the vehicles' battery (optional).
    #[serde(default)]
    pub battery: Option<super::policy::BatterySpec>,
}

/// `[target]`: the target shape, one `[x, y]` per agent in `[[agents]]` order; compared
/// with the final formation up to translation, rotation, scale and mirror.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TargetSpec {
    /// Target positions (m), in agent order.
    pub positions: Vec<[f64; 2]>,
}

fn default_duration() -> f64 {
    100.0
}
