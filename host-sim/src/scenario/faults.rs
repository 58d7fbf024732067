//! `[[faults]]` as the file writes it (`docs/faults.md`).

use super::schema::AgentId;
use serde::{Deserialize, Serialize};

/// One fault of a flight: its `kind`, the agent it strikes (its id as the scenario names
/// it), when, and for how long.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FaultSpec {
    /// `agent_loss`, `reboot` or `radio_blackout` (the kinds simulated;
    /// `crate::model::FAULT_KINDS`).
    pub kind: String,
    /// The agent's id; `radio_blackout` without one silences every agent.
    #[serde(default)]
    pub agent: Option<AgentId>,
    /// When it strikes (s).
    pub t: f64,
    /// How long it lasts (s): `reboot` (the agent is down), `radio_blackout`.
    #[serde(default)]
    pub duration: Option<f64>,
}
