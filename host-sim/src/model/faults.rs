//! Faults of a real flight (`[[faults]]`, `docs/faults.md`), resolved to agent indices.

/// What happens to the agent (`[[faults]] kind`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum FaultKind {
    /// From `t` on, the agent neither ticks nor sends: its controller and radio are
    /// gone; its vehicle holds still (a zero velocity setpoint, or no force), an obstacle
    /// in the plane.
    AgentLoss,
    /// From `t` for `duration` the agent is down as above; then it rejoins with its
    /// controller's state lost (a new controller from its configuration, its actuator
    /// started again from the measured velocity).
    Reboot,
    /// From `t` for `duration` the agent's radio (or, without an agent, every radio)
    /// neither sends nor hears: frames and position packets.
    RadioBlackout,
    /// At `t` the agent's clock jumps by `jump` seconds (forward, or back when
    /// negative): every time its controller reads from then on is off by that much.
    ClockJump,
    /// From `t` for `duration` every bearing the agent measures points in a random
    /// direction (a detector gone wrong).
    OutlierBurst,
    /// From `t` for `duration` the agent's sensors stop updating: it reads, at every
    /// tick, the bearings, velocity and leader offset of its tick at `t`.
    SensorFreeze,
}

/// The `kind` names the schema accepts, in [`FaultKind`] order.
pub const FAULT_KINDS: &[&str] = &[
    "agent_loss",
    "reboot",
    "radio_blackout",
    "clock_jump",
    "outlier_burst",
    "sensor_freeze",
];

impl FaultKind {
    /// The name used in files and `summary.json`.
    pub fn as_str(self) -> &'static str {
        match self {
            Self::AgentLoss => "agent_loss",
            Self::Reboot => "reboot",
            Self::RadioBlackout => "radio_blackout",
            Self::ClockJump => "clock_jump",
            Self::OutlierBurst => "outlier_burst",
            Self::SensorFreeze => "sensor_freeze",
        }
    }
}

/// One fault, resolved.
#[derive(Clone, Debug, PartialEq)]
pub struct FaultModel {
    /// What happens.
    pub kind: FaultKind,
    /// The agent's index (`None`: every agent, `radio_blackout` only).
    pub agent: Option<usize>,
    /// When it strikes (s).
    pub t: f64,
    /// When it ends (s; infinity for `agent_loss`, `t` for `clock_jump`, an instant).
    pub end: f64,
    /// `clock_jump`: the jump (s); 0 for the other kinds.
    pub jump: f64,
}

impl FaultModel {
    /// Whether it is acting on agent `i` at time `t`.
    pub fn acts_on(&self, i: usize, t: f64) -> bool {
        self.agent.is_none_or(|a| a == i) && t >= self.t - 1e-9 && t < self.end - 1e-9
    }
}
