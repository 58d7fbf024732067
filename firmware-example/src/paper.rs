//! The paper's reference scenario (SPEC §9, `paper` gains) in `f32`.
//!
//! Four agents (ids 1–4), triangles {1,2,3} and {2,3,4}; controlled angles
//! θ1 at 1 in {1,2,3} = 90°, φ1 at 3 in {1,2,3} = 45°, θ2 at 2 in {2,3,4} =
//! 45°, φ2 at 3 in {2,3,4} = 45° (target: the square 1-2-4-3). Leaders 1
//! and 2 with `z* = q1 − q2 = (10, −10)`, `v* = (3, 3)`, `c = 1000`, `d = 10`,
//! `c_e = 1000`, `D^r = 0.5 I`, `D^v = 1.8 I`, `k_z = 1`, `D_z = 0.8 I`,
//! `r̂(0) = 1`, `r_min = 0.1`, `m = 1`.
//!
//! The desired angles enter the controller as cosines; they are constants
//! here (no trigonometry on target).

use ph_formation_core::{
    AgentConfig, AgentId, AngleConfig, LeaderConfig, LeaderRole, Schedule, TriangleConfig,
};

/// Number of agents.
pub const AGENTS: usize = 4;
/// Agent ids, in the order of [`INITIAL_POSITIONS`].
pub const IDS: [AgentId; AGENTS] = [1, 2, 3, 4];
/// `q(0)` of agents 1–4 (m); `v(0) = 0`.
pub const INITIAL_POSITIONS: [[f32; 2]; AGENTS] = [[0.9, 2.2], [2.2, 2.8], [1.8, 1.1], [3.1, 1.9]];
/// Mass of every agent (kg).
pub const MASS: f32 = 1.0;
/// `D^r` (diagonal, same for every agent), N·s/m: the plant's friction.
pub const FRICTION: f32 = 0.5;
/// `D^v` (diagonal), N·s/m.
pub const VELOCITY_DAMPING: f32 = 1.8;
/// `v*` (m/s).
pub const V_STAR: [f32; 2] = [3.0, 3.0];
/// `z* = q1 − q2` (m).
pub const Z_STAR: [f32; 2] = [10.0, -10.0];
/// `k_z`.
pub const LEADER_STIFFNESS: f32 = 1.0;
/// `D_z` (diagonal).
pub const LEADER_DAMPING: f32 = 0.8;
/// `c_α` of every angle.
pub const STIFFNESS: f32 = 1000.0;
/// `d_α` of every angle.
pub const DAMPING: f32 = 10.0;
/// `c_e` of every angle.
pub const ESTIMATOR_GAIN: f32 = 1000.0;
/// `r̂(0)` (m).
pub const INITIAL_ESTIMATE: f32 = 1.0;
/// `r_min` (m).
pub const MIN_ESTIMATE: f32 = 0.1;
/// Force limit (N). The core's default (1e3) saturates the first ticks of
/// this scenario (`c = 1000` with `r̂(0) = 1`); the host simulator's `paper`
/// scenario uses 1e5, and so does the demo, so that both run the same law.
pub const MAX_FORCE: f32 = 1.0e5;

/// `cos 90°`.
pub const COS_90: f32 = 0.0;
/// `sin 90°`.
pub const SIN_90: f32 = 1.0;
/// `cos 45° = sin 45° = 1/√2`.
pub const COS_45: f32 = core::f32::consts::FRAC_1_SQRT_2;
/// `sin 45°`.
pub const SIN_45: f32 = core::f32::consts::FRAC_1_SQRT_2;

/// One controlled angle of the scenario, by agent index (0-based).
#[derive(Clone, Copy, Debug)]
pub struct Angle {
    /// Name in the paper.
    pub name: &'static str,
    /// Triangle index (0: {1,2,3}, 1: {2,3,4}).
    pub triangle: usize,
    /// Apex (agent index).
    pub apex: usize,
    /// The two far vertices (agent indices).
    pub far: [usize; 2],
    /// `cos α*`.
    pub cos: f32,
    /// `sin α*` (for the angle error, see [`angle_error`]).
    pub sin: f32,
}

/// Triangles by agent index.
pub const TRIANGLES: [[usize; 3]; 2] = [[0, 1, 2], [1, 2, 3]];

/// The four controlled angles θ1, φ1, θ2, φ2.
pub const ANGLES: [Angle; 4] = [
    Angle {
        name: "theta1",
        triangle: 0,
        apex: 0,
        far: [1, 2],
        cos: COS_90,
        sin: SIN_90,
    },
    Angle {
        name: "phi1",
        triangle: 0,
        apex: 2,
        far: [0, 1],
        cos: COS_45,
        sin: SIN_45,
    },
    Angle {
        name: "theta2",
        triangle: 1,
        apex: 1,
        far: [2, 3],
        cos: COS_45,
        sin: SIN_45,
    },
    Angle {
        name: "phi2",
        triangle: 1,
        apex: 2,
        far: [1, 3],
        cos: COS_45,
        sin: SIN_45,
    },
];

/// The controller configuration of agent index `i` (0..4, id `i + 1`), for an
/// agent with room for `MT ≥ 2` triangles.
pub fn config<const MT: usize>(i: usize) -> AgentConfig<f32, MT> {
    let id = IDS[i % AGENTS];
    let mut c = AgentConfig::new(id);
    c.initial_estimate = INITIAL_ESTIMATE;
    c.min_estimate = MIN_ESTIMATE;
    c.friction = [FRICTION; 2];
    c.velocity_damping = [VELOCITY_DAMPING; 2];
    c.velocity_reference = Schedule::constant(V_STAR);
    c.limits.max_force = MAX_FORCE;
    for (ti, tri) in TRIANGLES.iter().enumerate() {
        if !tri.contains(&(i % AGENTS)) {
            continue;
        }
        let mut angles = ANGLES
            .iter()
            .filter(|a| a.triangle == ti)
            .map(|a| AngleConfig {
                apex: IDS[a.apex],
                cos_desired: a.cos,
                stiffness: STIFFNESS,
                damping: DAMPING,
                estimator_gain: ESTIMATOR_GAIN,
            });
        if let (Some(a0), Some(a1)) = (angles.next(), angles.next()) {
            // Capacity MT ≥ 2 holds both triangles; a smaller MT is refused
            // later by the caller's `Agent::new` as an incomplete config.
            let _ = c.triangles.push(TriangleConfig {
                vertices: tri.map(|k| IDS[k]),
                angles: [a0, a1],
            });
        }
    }
    let leader = |role, partner| LeaderConfig {
        role,
        partner,
        stiffness: LEADER_STIFFNESS,
        damping: [LEADER_DAMPING; 2],
        displacement: Schedule::constant(Z_STAR),
    };
    c.leader = match i {
        0 => Some(leader(LeaderRole::A, IDS[1])),
        1 => Some(leader(LeaderRole::B, IDS[0])),
        _ => None,
    };
    c
}

/// `|sin(α − α*)|` for the current interior angle `α` between the unit
/// vectors `s_v`, `s_w` (from the apex) and the desired angle with
/// `cos α*`, `sin α*`: the angle error in radians to first order (below
/// 1e-3 rad the two differ by less than 2e-7 relative), computed without
/// trigonometry.
pub fn angle_error(s_v: [f32; 2], s_w: [f32; 2], cos_star: f32, sin_star: f32) -> f32 {
    let cos = s_v[0] * s_w[0] + s_v[1] * s_w[1];
    let sin = (s_v[0] * s_w[1] - s_v[1] * s_w[0]).abs();
    (sin * cos_star - cos * sin_star).abs()
}
