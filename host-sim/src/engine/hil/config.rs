//! An agent's configuration for the firmware: the host's configuration rounded to `f32`
//! ([`Model::agent_config_f32`]) and checked against the firmware's capacity.

use super::error::HilError;
use super::link::TARGET_MT;
use super::options::TARGET_NB;
use crate::model::Model;
use ph_formation_core::{Agent, AgentConfig};

/// Agent `i`'s configuration for the firmware: the host's `AgentConfig<f64, 8>` (built as
/// for every simulated agent) rounded to `f32`, checked against the firmware's capacity
/// (`Agent<f32, TARGET_MT, TARGET_NB>`).
pub fn target_config(model: &Model, i: usize) -> Result<AgentConfig<f32, TARGET_MT>, HilError> {
    let name = model.agents.get(i).map_or("?", |a| a.name.as_str());
    let refused = |reason: String| HilError::Refused {
        agent: name.to_owned(),
        reason,
    };
    let t = model
        .agent_config_f32::<TARGET_MT>(i)
        .map_err(|e| refused(e.to_string()))?;
    Agent::<f32, TARGET_MT, TARGET_NB>::new(t.clone()).map_err(|e| {
        refused(format!(
            "{e} (the firmware's agent holds {TARGET_MT} triangles and {TARGET_NB} neighbours)"
        ))
    })?;
    Ok(t)
}
