//! One agent's local configuration: its triangles, controlled angles, gains, maneuvers
//! and limits. Everything is fixed-capacity and `serde`-serializable.

use crate::Real;
use serde::{Deserialize, Serialize};

pub use crate::wire::Integrity;
pub use shared::{AgentId, EstimatorMode};

mod shared;

/// Capacity of a piecewise-constant schedule (`v*`, `z*`).
pub const MAX_SCHEDULE_STEPS: usize = 8;

/// How the agent turns successive bearings into the bearing and the bearing rate the law
/// uses (SPEC §2, §11). A bearing measured with its rate (an optical-flow sensor) is used
/// as it is in either mode.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum BearingFilter<T> {
    /// The finite difference of two successive bearings (SPEC §2): exact in the limit of
    /// noise-free bearings, but it turns 1° of noise at 100 Hz into about 140°/s of rate.
    FiniteDifference,
    /// The bearing tracker of SPEC §11 (S15–S17), one per sensed neighbour.
    Tracker(TrackerConfig<T>),
}

impl<T: Real> Default for BearingFilter<T> {
    /// The tracker with [`TrackerConfig::default`]: what works on real sensors.
    fn default() -> Self {
        Self::Tracker(TrackerConfig::default())
    }
}

/// The settings of the bearing tracker (SPEC §11, S15–S17).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct TrackerConfig<T> {
    /// `σ_b > 0`: standard deviation of the bearing noise (rad); `R = σ_b²` in S16.
    pub bearing_noise: T,
    /// `σ_ω ≥ 0`: the bearing rate the kinematic model cannot explain (stale neighbour
    /// velocity, own velocity noise), as white noise of density `σ_ω²` (rad²/s) in S15.
    pub rate_noise: T,
    /// `σ_ρ ≥ 0`: random walk of the inverse distance, density `σ_ρ²` (1/(m² s)) in S15.
    pub inverse_range_noise: T,
    /// `1 ≤ g ≤ 1000`: a bearing whose innovation exceeds `g` standard deviations is an outlier
    /// and is not used (S16); three in a row restart the track.
    pub gate: T,
}

impl<T: Real> Default for TrackerConfig<T> {
    /// A camera-grade bearing sensor: `σ_b = 2°`, `σ_ω = 5·10⁻⁴ rad/√s`,
    /// `σ_ρ = 0.05 /(m √s)`, gate 5σ (docs/sensors.md).
    fn default() -> Self {
        Self {
            bearing_noise: T::lit(0.034_906_585_039_886_59), // 2°
            rate_noise: T::lit(5.0e-4),
            inverse_range_noise: T::lit(0.05),
            gate: T::lit(5.0),
        }
    }
}

impl<T: Real> TrackerConfig<T> {
    /// Every setting finite and in range: `0 < σ_b ≤ 0.5 rad`, `0 ≤ σ_ω ≤ 100`,
    /// `0 ≤ σ_ρ ≤ 100`, `1 ≤ g ≤ 1000`.
    pub fn is_valid(&self) -> bool {
        let within = |x: T, lo: T, hi: T| x.finite() && x >= lo && x <= hi;
        self.bearing_noise.finite()
            && self.bearing_noise > T::zero()
            && self.bearing_noise <= T::lit(0.5)
            && within(self.rate_noise, T::zero(), T::lit(100.0))
            && within(self.inverse_range_noise, T::zero(), T::lit(100.0))
            && within(self.gate, T::one(), T::lit(1000.0))
    }
}

/// One controlled angle `α = (apex; v, w)` of a triangle.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct AngleConfig<T> {
    /// The apex `u`; the far vertices are the triangle's two other vertices.
    pub apex: AgentId,
    /// `y*_α = cos α*` (S4). The host converts degrees; the core never calls trigonometry.
    pub cos_desired: T,
    /// `c_α > 0` (S7), shared by the three agents of the angle.
    pub stiffness: T,
    /// `d_α ≥ 0` (S7), shared by the three agents of the angle.
    pub damping: T,
    /// `c_e > 0` (S9), for both edges of the angle.
    pub estimator_gain: T,
}

/// A triangle of the Laman graph with its two controlled angles.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct TriangleConfig<T> {
    /// The three vertices.
    pub vertices: [AgentId; 3],
    /// The two controlled angles (distinct apexes).
    pub angles: [AngleConfig<T>; 2],
}

/// One step of a piecewise-constant schedule: `value` holds from time `from` on.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct ScheduleStep<T> {
    /// Start time in seconds.
    pub from: T,
    /// The value `[x, y]`.
    pub value: [T; 2],
}

/// A piecewise-constant 2-D schedule, steps sorted by strictly increasing `from` (checked by
/// [`crate::Agent::new`]). Before the first step the first value holds; an empty schedule
/// is zero.
#[derive(Clone, Debug, PartialEq, Default, Serialize, Deserialize)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Schedule<T> {
    /// The steps.
    pub steps: heapless::Vec<ScheduleStep<T>, MAX_SCHEDULE_STEPS>,
}

impl<T: Real> Schedule<T> {
    /// A schedule with one constant value.
    pub fn constant(value: [T; 2]) -> Self {
        let mut steps = heapless::Vec::new();
        // Capacity is at least one: this push cannot fail.
        let _ = steps.push(ScheduleStep {
            from: T::zero(),
            value,
        });
        Self { steps }
    }

    /// Every time and value is finite and the times strictly increase.
    pub fn is_valid(&self) -> bool {
        let finite = self
            .steps
            .iter()
            .all(|st| st.from.finite() && st.value[0].finite() && st.value[1].finite());
        finite
            && self
                .steps
                .windows(2)
                .all(|w| matches!(w, [a, b] if a.from < b.from))
    }

    /// The value at time `t`.
    pub fn at(&self, t: T) -> [T; 2] {
        // The last step (in order) that has started, else the first.
        let (first, rest) = match self.steps.as_slice() {
            [] => return [T::zero(); 2],
            [only] => return only.value,
            [first, rest @ ..] => (first, rest),
        };
        let mut value = first.value;
        for s in rest {
            if s.from <= t {
                value = s.value;
            }
        }
        value
    }
}

/// Which end of the leader edge this agent is (SPEC S11 with `z = q_a − q_b`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum LeaderRole {
    /// Agent `a` (`z = q_a − q_b`, force `−k_z z̃ − D_z ż`).
    A,
    /// Agent `b` (force `+k_z z̃ + D_z ż`).
    B,
    /// Either end of an edge whose orientation no one controls (S11b): only the distance
    /// part, `(k_z (|p| − |z*|) + d_u u·ṗ) u` with `p` the partner offset and
    /// `u = p/|p|`, which needs no common frame. For agents whose heading estimates
    /// disagree (SPEC §7, "Heading disagreement").
    Distance,
}

/// The leader-edge maneuver (S11).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct LeaderConfig<T> {
    /// This agent's role.
    pub role: LeaderRole,
    /// The other leader.
    pub partner: AgentId,
    /// `k_z > 0`.
    pub stiffness: T,
    /// `D_z` (diagonal).
    pub damping: [T; 2],
    /// `z*(t)`: desired `q_a − q_b`.
    pub displacement: Schedule<T>,
}

/// Safety limits and input tolerances.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Limits<T> {
    /// The commanded force is scaled down to this norm (N).
    pub max_force: T,
    /// A neighbour not heard from for longer than this (s) is stale: safe output.
    pub neighbour_timeout: T,
    /// Safe output: `U = −safe_damping · v` (damp own velocity, no formation force).
    pub safe_damping: T,
    /// A bearing `s` is accepted when `| |s|² − 1 | ≤ bearing_tolerance`.
    pub bearing_tolerance: T,
    /// `cos` of the angle margin (default 5°): a current angle with `|cos α|` above this
    /// is reported as degenerate (the output is still computed).
    pub margin_cos: T,
    /// `T_h ≥ 0` (s): a neighbour's bearing missing from the measurements is still used
    /// while the last one measured is younger than this: held (finite differences) or
    /// predicted (the bearing tracker), SPEC §12 (S18). Past it the bearing is missing
    /// and the output is the safe one (S19). Default 0: a bearing missing for one tick
    /// is missing (no hold).
    pub bearing_hold: T,
}

impl<T: Real> Default for Limits<T> {
    fn default() -> Self {
        Self {
            max_force: T::lit(1.0e3),
            neighbour_timeout: T::lit(0.1),
            safe_damping: T::lit(1.0),
            bearing_tolerance: T::lit(1.0e-3),
            margin_cos: T::lit(0.996_194_698_091_745_5), // cos 5°
            bearing_hold: T::zero(),
        }
    }
}

/// One agent's complete local configuration, for up to `MT` triangles.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct AgentConfig<T, const MT: usize> {
    /// This agent's id.
    pub id: AgentId,
    /// The triangles this agent belongs to.
    pub triangles: heapless::Vec<TriangleConfig<T>, MT>,
    /// Distance source (SPEC §6).
    pub estimator: EstimatorMode,
    /// `r̂(0)` (SPEC §6, default 1.0).
    pub initial_estimate: T,
    /// `r_min > 0` of S10 (default 0.1).
    pub min_estimate: T,
    /// `D^r_n` (diagonal), used by S12 to cancel friction at `v*`.
    pub friction: [T; 2],
    /// `D^v_n` (diagonal) of S12.
    pub velocity_damping: [T; 2],
    /// `v*(t)` of S12.
    pub velocity_reference: Schedule<T>,
    /// The leader-edge maneuver, for the two leaders only.
    pub leader: Option<LeaderConfig<T>>,
    /// Safety limits.
    pub limits: Limits<T>,
    /// How bearings become the bearing and rate the law uses (SPEC §11).
    pub bearing_filter: BearingFilter<T>,
    /// How frames are protected ([`Integrity`]); the same for every agent of a swarm.
    pub integrity: Integrity,
    /// Broadcast every `comm_every`-th control step (`≥ 1`; 1 = every step). The agent
    /// controls every step on its own fresh measurements and the neighbour data it last
    /// heard; [`Limits::neighbour_timeout`] must exceed the communication period.
    pub comm_every: u16,
    /// Which step of each `comm_every` broadcasts (`< comm_every`): step `k` (counted from
    /// 0) broadcasts when `k mod comm_every = comm_phase`. Spreading the phases spreads the
    /// swarm's frames over the communication period.
    pub comm_phase: u16,
}

impl<T: Real, const MT: usize> AgentConfig<T, MT> {
    /// A configuration with the SPEC defaults and no triangles yet.
    pub fn new(id: AgentId) -> Self {
        Self {
            id,
            triangles: heapless::Vec::new(),
            estimator: EstimatorMode::Shared,
            initial_estimate: T::one(),
            min_estimate: T::lit(0.1),
            friction: [T::zero(); 2],
            velocity_damping: [T::zero(); 2],
            velocity_reference: Schedule::default(),
            leader: None,
            limits: Limits::default(),
            bearing_filter: BearingFilter::default(),
            integrity: Integrity::Crc16,
            comm_every: 1,
            comm_phase: 0,
        }
    }
}

/// Why a configuration was refused by [`crate::Agent::new`].
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum ConfigError {
    /// Triangle `triangle` does not contain this agent.
    NotInTriangle {
        /// Index in `triangles`.
        triangle: usize,
    },
    /// Triangle `triangle` repeats a vertex.
    RepeatedVertex {
        /// Index in `triangles`.
        triangle: usize,
    },
    /// A controlled angle's apex is not a vertex of its triangle, or both angles share it.
    BadApex {
        /// Index in `triangles`.
        triangle: usize,
    },
    /// A desired angle is outside `(margin, π − margin)`, or the two controlled angles of
    /// the triangle sum to `π` or more (SPEC §3 validity).
    InfeasibleAngles {
        /// Index in `triangles`.
        triangle: usize,
    },
    /// A gain is not finite, or `c_α ≤ 0`, `d_α < 0`, `c_e ≤ 0`.
    BadGain {
        /// Index in `triangles`.
        triangle: usize,
    },
    /// More distinct neighbours than the capacity `NB`.
    TooManyNeighbours,
    /// More triangles than the agent type can index (`MT` above
    /// [`crate::agent::MAX_MT`]).
    TooManyTriangles,
    /// A scalar parameter (estimate, limit, friction, damping, leader gain) is not finite
    /// or out of range.
    BadParameter,
    /// A `v*` or `z*` schedule has a non-finite entry or times that do not strictly
    /// increase.
    BadSchedule,
    /// `comm_every` is 0 or `comm_phase ≥ comm_every`.
    BadCommRate,
    /// The leader partner is this agent itself.
    BadLeader,
    /// A bearing tracker setting is not finite or out of range
    /// ([`TrackerConfig::is_valid`]).
    BadBearingFilter,
}

impl core::fmt::Display for ConfigError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        match self {
            Self::NotInTriangle { triangle } => write!(f, "triangle {triangle} does not contain this agent"),
            Self::RepeatedVertex { triangle } => write!(f, "triangle {triangle} repeats a vertex"),
            Self::BadApex { triangle } => write!(f, "triangle {triangle}: an apex is not a vertex, or both angles share it"),
            Self::InfeasibleAngles { triangle } => write!(f, "triangle {triangle}: desired angles outside (margin, 180° − margin) or summing to 180° or more"),
            Self::BadGain { triangle } => write!(f, "triangle {triangle}: a gain is not finite or not positive"),
            Self::TooManyNeighbours => write!(f, "more neighbours than the agent's capacity"),
            Self::TooManyTriangles => write!(f, "more triangles than the agent type can index"),
            Self::BadParameter => write!(f, "a scalar parameter is not finite or out of range"),
            Self::BadSchedule => write!(f, "a schedule has a non-finite entry or times that do not strictly increase"),
            Self::BadCommRate => write!(f, "comm_every is 0 or comm_phase is not below comm_every"),
            Self::BadLeader => write!(f, "the leader partner is the agent itself"),
            Self::BadBearingFilter => write!(f, "a bearing tracker setting is not finite or out of range"),
        }
    }
}
