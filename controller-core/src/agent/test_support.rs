//! Unit-test support: the smallest configuration, one agent of the triangle (1, 2, 3).

use crate::config::{AgentConfig, AgentId, AngleConfig, TriangleConfig};
use crate::Real;

/// Agent `id` of the triangle (1, 2, 3) whose controlled angles are at `apexes`
/// (desired cosine 0.5, c = 1, d = `damping`, c_e = 1), other settings default.
pub(crate) fn one_triangle<T: Real>(
    id: AgentId,
    apexes: [AgentId; 2],
    damping: f64,
) -> AgentConfig<T, 1> {
    let angle = |apex| AngleConfig {
        apex,
        cos_desired: T::lit(0.5),
        stiffness: T::one(),
        damping: T::lit(damping),
        estimator_gain: T::one(),
    };
    let mut c = AgentConfig::new(id);
    let _ = c.triangles.push(TriangleConfig {
        vertices: [1, 2, 3],
        angles: apexes.map(angle),
    });
    c
}
