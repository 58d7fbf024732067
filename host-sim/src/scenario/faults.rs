//! `[[faults]]` as the file writes it (`docs/faults.md`).

use super::schema::AgentId;
use serde::{Deserialize, Serialize};

/// One fault of a flight: its `kind`, the agent it strikes (its id as the scenario names
/// it), when, and for how long.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FaultSpec {
    /// `agent_loss`, `reboot`, `radio_blackout`, `clock_jump`, `outlier_burst` or
    /// `sensor_freeze` (
    /// `crate::model::FAULT_KINDS`).
    pub kind: String,
    /// The agent's id; `radio_blackout` without one silences every agent.
    #[serde(default)]
    pub agent: Option<AgentId>,
    /// When it strikes (s).
    pub t: f64,
    /// How long it lasts (s): `reboot` (the agent is down), `radio_blackout`,
    /// `outlier_burst`, `sensor_freeze`.
    #[serde(default)]
    pub duration: Option<f64>,
    /// `clock_jump`: how far the agent's clock jumps (s; negative: back).
    #[serde(default)]
    pub jump_s: Option<f64>,
}
