//! The robot's world (`docs/world.md`): the vehicle each agent is, the wind on it, its
//! heading and body frame, and its own clock. The ideal world ([`WorldModel::ideal`]) is
//! the paper's: point masses pushed by the ideal force, one world frame, one clock.

/// The vehicle model of every agent (`[plant] model`).
#[derive(Clone, Debug, PartialEq)]
pub enum VehicleModel {
    /// SPEC S1: `m v̇ = −D^r v + U` (the paper's plant).
    PointMass,
    /// A vehicle whose own controller tracks a velocity setpoint (a Crazyflie in
    /// position/velocity mode, a rover's wheel controller); the agent's force becomes the
    /// setpoint through the virtual mass of `ph_formation_core::actuate`.
    VelocityTracking(VelocityTracking),
    /// A Crazyflie 2.x flying its firmware's PID cascade in velocity mode
    /// (`engine::plant::CrazyfliePidPlant`); the agent's force becomes the setpoint as for
    /// [`VehicleModel::VelocityTracking`].
    CrazyfliePid(CrazyfliePid),
}

/// The Crazyflie's cascade: its gains are the firmware's (`engine::plant::firmware`);
/// what the agent adds is its setpoint limit and lead.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CrazyfliePid {
    /// The largest velocity setpoint the agent sends (m/s, > 0; the app's
    /// `FORMATION_MAX_SPEED`: the firmware has none in velocity mode).
    pub max_speed: f64,
    /// The lead of the agent's setpoints (s, ≥ 0; SPEC S21); `None`: the cascade's
    /// derived `engine::plant::derived_lead`.
    pub lead: Option<f64>,
    /// The second-order lead of the agent's setpoints (s², ≥ 0; SPEC S21b); `None`: the
    /// derived `engine::plant::derived_second_lead`.
    pub second_lead: Option<f64>,
    /// The time constant of the filter on that lead's jerk (s, ≥ 0; SPEC S21d).
    pub jerk_filter: f64,
    /// The gap bound between the virtual and the measured velocity (m/s, > 0, infinity
    /// for none; SPEC S21c): the app's `FORMATION_MAX_GAP`, [`MAX_GAP`] by default.
    pub max_gap: f64,
}

/// The default [`CrazyfliePid::max_gap`] (m/s, SPEC S21c): the Crazyflie app's
/// `FORMATION_MAX_GAP` (crazyflie-app/src/formation.h), well above the lag of a drone that
/// follows (`τ_lead` 0.23 s times the largest virtual acceleration `max_force / m`,
/// docs/spec.md S21c).
pub const MAX_GAP: f64 = 0.5;

/// The default [`CrazyfliePid::jerk_filter`] (s, SPEC S21d): three of the velocity loop's
/// 10 ms periods, a sixth of the attitude loop's `τ_a` = 1/6 s (docs/world.md measures
/// 0, 0.02, 0.03, 0.05 and 0.1 s).
pub const JERK_FILTER_S: f64 = 0.03;

/// A velocity-tracking vehicle: `v̇ = sat_{a_max}((v_sp − v) / τ)`, `|v_sp| ≤ v_max`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct VelocityTracking {
    /// `τ`, the time constant of the vehicle's velocity loop (s, > 0).
    pub time_constant: f64,
    /// `a_max`, the largest acceleration the vehicle can give itself (m/s², > 0; from a
    /// tilt limit θ: `g tan θ`).
    pub max_acceleration: f64,
    /// `v_max`, the largest velocity setpoint (m/s, > 0).
    pub max_speed: f64,
    /// The lead the agent's actuation gives its setpoints (s, ≥ 0; SPEC S21): what the
    /// agent believes `τ` to be.
    pub lead: f64,
    /// The gap bound between the virtual and the measured velocity (m/s, > 0; infinity,
    /// the default, for none; SPEC S21c).
    pub max_gap: f64,
}

/// Wind on every agent: a constant part plus gusts, each agent's gust an independent
/// first-order (Ornstein–Uhlenbeck) process per axis. In units of acceleration (the
/// wind's force per unit mass).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct WindModel {
    /// The constant part (m/s²).
    pub mean: [f64; 2],
    /// The gusts' stationary standard deviation per axis (m/s²).
    pub gust: f64,
    /// The gusts' correlation time (s, > 0).
    pub gust_time_constant: f64,
}

/// Every agent's heading (the direction of its body x axis) and the agent's own
/// estimate of it. Bearings, velocity and the partner offset are measured in the body
/// frame; the agent turns them into its world frame, and its command back into the body
/// frame, through its estimate, whose error `e_i(t) = e_i(0) + ω_i t + n_i(t)` rotates
/// everything it senses and commands.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct HeadingModel {
    /// The true heading of every agent (rad).
    pub initial: f64,
    /// Each agent's true heading is `initial` plus a uniform draw in `±spread` (rad).
    pub spread: f64,
    /// Standard deviation of each agent's initial estimate error `e_i(0)` (rad).
    pub error: f64,
    /// Standard deviation of each agent's drift rate `ω_i` of its estimate error (rad/s).
    pub drift: f64,
    /// Standard deviation of the white estimate noise `n_i` at each tick (rad).
    pub noise: f64,
}

/// Every agent's own clock: it ticks at its own instants. Agent `i`'s clock reads
/// `τ_i(t) = (1 + ε_i) t + φ_i`; its `k`-th tick is due when `τ_i = k T` (`T` the
/// control period), jittered.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ClockModel {
    /// Each agent's phase `φ_i` is drawn uniformly in `[0, offset)` (s).
    pub offset: f64,
    /// Each agent's rate error `ε_i` is drawn uniformly in `±ppm · 10⁻⁶`.
    pub ppm: f64,
    /// Standard deviation of each tick's instant (s; clamped to ±0.45 T).
    pub jitter: f64,
}

impl ClockModel {
    /// Whether every clock is the simulator's: no phase, rate error or jitter.
    pub fn is_ideal(&self) -> bool {
        self.offset == 0.0 && self.ppm == 0.0 && self.jitter == 0.0
    }
}

/// The world of a run.
#[derive(Clone, Debug, PartialEq)]
pub struct WorldModel {
    /// The preset the world was filled from (`ideal` or `crazyflie`).
    pub preset: String,
    /// The vehicle.
    pub vehicle: VehicleModel,
    /// Wind, if any.
    pub wind: Option<WindModel>,
    /// Headings and body frames, if modelled (`None`: every agent measures and acts in
    /// the world frame).
    pub heading: Option<HeadingModel>,
    /// Own clocks, if any is not ideal (`None`: every agent ticks at the same instants).
    pub clock: Option<ClockModel>,
    /// Settings that are assumptions rather than published figures, as `key: reason`
    /// (written to `summary.json`).
    pub assumptions: Vec<String>,
}

impl WorldModel {
    /// The paper's world: point masses, no wind, one frame, one clock.
    pub fn ideal() -> Self {
        Self {
            preset: "ideal".to_owned(),
            vehicle: VehicleModel::PointMass,
            wind: None,
            heading: None,
            clock: None,
            assumptions: Vec::new(),
        }
    }

    /// Whether this is the paper's world (the simulator's fast paths apply).
    pub fn is_ideal(&self) -> bool {
        let Self {
            preset: _, // a name: the models below are what counts
            vehicle,
            wind,
            heading,
            clock,
            assumptions: _, // documentation of the values
        } = self;
        *vehicle == VehicleModel::PointMass
            && wind.is_none()
            && heading.is_none()
            && clock.is_none()
    }

    /// Whether the agents' heading estimates can differ from one another (an error, a
    /// drift or noise): then no two agents share a frame exactly.
    pub fn headings_disagree(&self) -> bool {
        self.heading
            .is_some_and(|h| h.error > 0.0 || h.drift > 0.0 || h.noise > 0.0)
    }

    /// The vehicle's speed limit, if it has one (m/s).
    pub fn max_speed(&self) -> Option<f64> {
        match &self.vehicle {
            VehicleModel::PointMass => None,
            VehicleModel::VelocityTracking(v) => Some(v.max_speed),
            VehicleModel::CrazyfliePid(v) => Some(v.max_speed),
        }
    }

    /// The largest horizontal acceleration the vehicle gives itself per axis, if it has a
    /// tilt limit (m/s²): `velocity_tracking`'s `g tan θ_max`; the Crazyflie cascade's
    /// `g tan 20°` = 3.57 m/s² (`PID_VEL_ROLL_MAX`, docs/world.md).
    pub fn max_acceleration(&self) -> Option<f64> {
        match &self.vehicle {
            VehicleModel::PointMass => None,
            VehicleModel::VelocityTracking(v) => Some(v.max_acceleration),
            VehicleModel::CrazyfliePid(_) => {
                use ph_formation_vehicle::crazyflie::{firmware, G};
                Some(G * firmware::TILT_MAX_DEG.to_radians().tan())
            }
        }
    }
}
