//! From the model to `controller-core`: each agent's `AgentConfig` and core agent
//! (the host simulates `Agent<f64, MT, NB>`).

use super::{AngleModel, Estimator, Model};
use controller_core::{
    AgentConfig, AngleConfig, EstimatorMode, LeaderConfig, LeaderRole, TriangleConfig,
};

/// Triangle capacity of one host agent (`MT` of `controller_core::Agent`): the core's
/// standard capacity, stated once in `controller_core::MAX_TRIANGLES`.
pub const MT: usize = controller_core::MAX_TRIANGLES;
/// Neighbour capacity of one host agent (`NB` of `controller_core::Agent`): the core's
/// `controller_core::MAX_NEIGHBOURS`.
pub const NB: usize = controller_core::MAX_NEIGHBOURS;
/// The controller-core agent the host simulates.
pub type CoreAgent = controller_core::Agent<f64, MT, NB>;

impl Model {
    /// Core estimator mode.
    pub fn estimator_mode(&self) -> EstimatorMode {
        match self.estimator {
            Estimator::Shared => EstimatorMode::Shared,
            Estimator::PerAgent => EstimatorMode::PerAgent,
            Estimator::Measured => EstimatorMode::Measured,
        }
    }

    /// Agent `i`'s controller-core configuration. Fails only beyond the capacity `MT`.
    pub fn agent_config(&self, i: usize) -> Result<AgentConfig<f64, MT>, String> {
        let a = self
            .agents
            .get(i)
            .ok_or_else(|| format!("no agent index {i}"))?;
        let mut c = AgentConfig::new(a.id);
        for k in self.triangles_of(i) {
            let t = &self.triangles[k];
            let ang = |m: &AngleModel| AngleConfig {
                apex: self.agents[m.apex].id,
                cos_desired: m.desired.cos(),
                stiffness: m.stiffness,
                damping: m.damping,
                estimator_gain: m.estimator_gain,
            };
            let tc = TriangleConfig {
                vertices: t.vertices.map(|v| self.agents[v].id),
                angles: [ang(&t.angles[0]), ang(&t.angles[1])],
            };
            c.triangles.push(tc).map_err(|_| {
                format!(
                    "agent {} belongs to more than {MT} triangles (controller capacity)",
                    a.name
                )
            })?;
        }
        c.estimator = self.estimator_mode();
        c.initial_estimate = self.initial_estimate;
        c.min_estimate = self.min_estimate;
        c.friction = a.friction;
        c.velocity_damping = a.velocity_damping;
        c.velocity_reference = self.velocity_reference.clone();
        c.limits = self.limits;
        if let Some(l) = &self.leader {
            let role = if l.a == i {
                Some((LeaderRole::A, l.b))
            } else if l.b == i {
                Some((LeaderRole::B, l.a))
            } else {
                None
            };
            c.leader = role.map(|(role, p)| LeaderConfig {
                role,
                partner: self.agents[p].id,
                stiffness: l.stiffness,
                damping: l.damping,
                displacement: l.displacement.clone(),
            });
        }
        Ok(c)
    }

    /// Builds agent `i`'s controller-core agent.
    pub fn core_agent(&self, i: usize) -> Result<CoreAgent, String> {
        let c = self.agent_config(i)?;
        CoreAgent::new(c).map_err(|e| format!("controller-core refused agent index {i}: {e:?}"))
    }
}
