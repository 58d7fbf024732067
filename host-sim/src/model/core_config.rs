//! From the model to `controller-core`: each agent's `AgentConfig` and core agent
//! (the host simulates `Agent<f64, MT, NB>`).

use super::{AngleModel, Estimator, LeaderOrientation, Model, ModelError};
use ph_formation_core::{
    AgentConfig, AngleConfig, BearingFilter, EstimatorMode, LeaderConfig, LeaderRole, Limits,
    Schedule, ScheduleStep, TrackerConfig, TriangleConfig,
};

/// Triangle capacity of one host agent (`MT` of `ph_formation_core::Agent`): the core's
/// standard capacity, stated once in `ph_formation_core::MAX_TRIANGLES`.
pub const MT: usize = ph_formation_core::MAX_TRIANGLES;
/// Neighbour capacity of one host agent (`NB` of `ph_formation_core::Agent`): the core's
/// `ph_formation_core::MAX_NEIGHBOURS`.
pub const NB: usize = ph_formation_core::MAX_NEIGHBOURS;
/// The controller-core agent the host simulates.
pub type CoreAgent = ph_formation_core::Agent<f64, MT, NB>;

impl Model {
    /// Whether the leaders leave the orientation free (S11b on both ends) under
    /// `[leader] orientation` (SPEC §7, "Heading disagreement"): `auto` does when the
    /// world's heading estimates disagree.
    pub fn orientation_free(&self, orientation: LeaderOrientation) -> bool {
        match orientation {
            LeaderOrientation::Held => false,
            LeaderOrientation::Free => true,
            LeaderOrientation::Auto => self.world.headings_disagree(),
        }
    }

    /// Core estimator mode.
    pub fn estimator_mode(&self) -> EstimatorMode {
        match self.estimator {
            Estimator::Shared => EstimatorMode::Shared,
            Estimator::PerAgent => EstimatorMode::PerAgent,
            Estimator::Measured => EstimatorMode::Measured,
        }
    }

    /// Agent `i`'s controller-core configuration. Fails only beyond the capacity `MT`.
    pub fn agent_config(&self, i: usize) -> Result<AgentConfig<f64, MT>, ModelError> {
        self.agent_config_in::<MT>(i)
    }

    /// Agent `i`'s controller-core configuration with triangle capacity `M`. Fails when
    /// the agent belongs to more than `M` triangles, naming the agent.
    pub fn agent_config_in<const M: usize>(
        &self,
        i: usize,
    ) -> Result<AgentConfig<f64, M>, ModelError> {
        let a = self.agents.get(i).ok_or(ModelError::NoAgent(i))?;
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
            c.triangles
                .push(tc)
                .map_err(|_| ModelError::TooManyTriangles {
                    agent: a.name.clone(),
                    capacity: M,
                })?;
        }
        c.estimator = self.estimator_mode();
        c.initial_estimate = self.initial_estimate;
        c.min_estimate = self.min_estimate;
        c.friction = a.friction;
        c.velocity_damping = a.velocity_damping;
        c.velocity_reference = self.velocity_reference.clone();
        c.limits = self.limits;
        c.bearing_filter = self.sensors.bearing_filter;
        c.integrity = self.integrity.core(&self.auth_key);
        c.comm_every =
            u16::try_from(self.comm_every).map_err(|_| ModelError::CommEvery(self.comm_every))?;
        c.comm_phase = u16::try_from(self.comm_phase(i)).unwrap_or(0);
        if let Some(l) = &self.leader {
            let (a, b) = if self.orientation_free(l.orientation) {
                (LeaderRole::Distance, LeaderRole::Distance)
            } else {
                (LeaderRole::A, LeaderRole::B)
            };
            let role = if l.a == i {
                Some((a, l.b))
            } else if l.b == i {
                Some((b, l.a))
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

    /// Agent `i`'s configuration as an `f32` agent with triangle capacity `M` (what a
    /// microcontroller runs: the firmware of `--hil`, the C API's blob of `host-sim
    /// export`): [`Model::agent_config`] with every number rounded to `f32`. Fails when
    /// the agent belongs to more than `M` triangles, naming the agent.
    pub fn agent_config_f32<const M: usize>(
        &self,
        i: usize,
    ) -> Result<AgentConfig<f32, M>, ModelError> {
        let c = self.agent_config(i)?;
        let f = |x: f64| x as f32;
        let mut t = AgentConfig::<f32, M>::new(c.id);
        for tri in &c.triangles {
            let ang = |a: &AngleConfig<f64>| AngleConfig {
                apex: a.apex,
                cos_desired: f(a.cos_desired),
                stiffness: f(a.stiffness),
                damping: f(a.damping),
                estimator_gain: f(a.estimator_gain),
            };
            t.triangles
                .push(TriangleConfig {
                    vertices: tri.vertices,
                    angles: [ang(&tri.angles[0]), ang(&tri.angles[1])],
                })
                .map_err(|_| ModelError::TooManyTrianglesF32 {
                    id: c.id,
                    triangles: c.triangles.len(),
                    capacity: M,
                })?;
        }
        t.estimator = c.estimator;
        t.initial_estimate = f(c.initial_estimate);
        t.min_estimate = f(c.min_estimate);
        t.friction = c.friction.map(f);
        t.velocity_damping = c.velocity_damping.map(f);
        t.velocity_reference = schedule_f32(&c.velocity_reference);
        t.leader = c.leader.as_ref().map(|l| LeaderConfig {
            role: l.role,
            partner: l.partner,
            stiffness: f(l.stiffness),
            damping: l.damping.map(f),
            displacement: schedule_f32(&l.displacement),
        });
        t.limits = Limits {
            max_force: f(c.limits.max_force),
            neighbour_timeout: f(c.limits.neighbour_timeout),
            safe_damping: f(c.limits.safe_damping),
            bearing_tolerance: f(c.limits.bearing_tolerance),
            margin_cos: f(c.limits.margin_cos),
            bearing_hold: f(c.limits.bearing_hold),
        };
        t.bearing_filter = match c.bearing_filter {
            BearingFilter::FiniteDifference => BearingFilter::FiniteDifference,
            BearingFilter::Tracker(k) => BearingFilter::Tracker(TrackerConfig {
                bearing_noise: f(k.bearing_noise),
                rate_noise: f(k.rate_noise),
                inverse_range_noise: f(k.inverse_range_noise),
                gate: f(k.gate),
            }),
        };
        t.integrity = c.integrity;
        t.comm_every = c.comm_every;
        t.comm_phase = c.comm_phase;
        Ok(t)
    }

    /// Builds agent `i`'s controller-core agent.
    pub fn core_agent(&self, i: usize) -> Result<CoreAgent, ModelError> {
        self.core_agent_in::<MT, NB>(i)
    }

    /// Builds agent `i`'s controller-core agent with capacity `M` triangles and `N`
    /// neighbours (same behaviour as [`Model::core_agent`] whenever it fits: the core
    /// walks only the triangles and neighbours it has).
    pub fn core_agent_in<const M: usize, const N: usize>(
        &self,
        i: usize,
    ) -> Result<ph_formation_core::Agent<f64, M, N>, ModelError> {
        let c = self.agent_config_in::<M>(i)?;
        ph_formation_core::Agent::new(c)
            .map_err(|error| ModelError::CoreRefused { index: i, error })
    }
}

/// A schedule rounded to `f32` (same capacity on both sides: never truncated).
fn schedule_f32(s: &Schedule<f64>) -> Schedule<f32> {
    let mut out = Schedule::default();
    for st in &s.steps {
        let _ = out.steps.push(ScheduleStep {
            from: st.from as f32,
            value: st.value.map(|x| x as f32),
        });
    }
    out
}
