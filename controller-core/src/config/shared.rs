//! What the wire format and the configuration share: an agent's wire id ([`AgentId`])
//! and its estimator mode ([`EstimatorMode`], carried in the mode byte), in a module of
//! their own so that both depend on it and neither on the other.

use serde::{Deserialize, Serialize};

/// An agent identifier on the wire. It must be unique among the agents within two hops of
/// each agent in the graph (frames name neighbours and their neighbours by id) and among
/// the agents whose frames one receiver can hear; a formation of at most 256 agents can
/// simply number them, a larger one colours its graph (host-sim does).
pub type AgentId = u8;

/// How the controller gets the distances it needs in S8 (SPEC §6).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default, Serialize, Deserialize)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum EstimatorMode {
    /// One passive estimate per angle and edge, owned by the apex and sent to the far vertex (S9, S10).
    #[default]
    Shared,
    /// The paper's structure: every agent of an angle keeps its own copies (not passive).
    PerAgent,
    /// A range sensor measures the distances (e.g. UWB); no estimator.
    Measured,
}
