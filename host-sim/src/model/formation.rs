//! The formation, by agent index: the agents' plants and initial states, the triangles
//! with their controlled angles, and the leader edge.

use ph_formation_core::Schedule;

/// One agent's plant and initial state.
#[derive(Clone, Debug, PartialEq)]
pub struct AgentModel {
    /// The user's id as written in the scenario (an integer or a short name): what every
    /// output and message shows.
    pub name: String,
    /// Wire id (one byte): the user's id when every id is an integer 0–255, else assigned
    /// by a distance-2 colouring of the radio graph ([`super::wire_ids`]).
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
    /// The true initial heading (rad) given by the scenario (`[[agents]] heading_deg`):
    /// wins over the heading model's `initial` and spread; `None`: the model's draw (0
    /// without a heading model).
    pub heading: Option<f64>,
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
    /// Who controls the edge's orientation (`[leader] orientation`).
    pub orientation: LeaderOrientation,
}

/// `[leader] orientation`: whether the leader edge holds its orientation (SPEC §7,
/// "Heading disagreement"; docs/scenarios.md).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum LeaderOrientation {
    /// `free` when the world's heading estimates disagree (a `[heading]` with an error, a
    /// drift or noise), `held` otherwise.
    #[default]
    Auto,
    /// Both leaders apply S11, each in its own frame (the paper): `z*` sets the scale
    /// and the orientation.
    Held,
    /// Both leaders apply only the distance part (S11b), which needs no common frame:
    /// `|z*|` sets the scale; no one controls the orientation.
    Free,
}

impl LeaderOrientation {
    /// Whether this is the default (left out when a scenario is written).
    pub fn is_auto(&self) -> bool {
        *self == Self::Auto
    }
}
