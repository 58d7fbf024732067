//! A generated scenario of any size: a triangulated strip of near-equilateral triangles
//! `(i, i+1, i+2)` (for the benchmark and scaling tests).
//!
//! Wire ids are one byte, so with more than 256 agents they repeat (`id = i mod 256`).
//! That is enough for the controllers: an agent only talks to agents at most two places
//! away along the strip, whose ids are distinct. Such a model is built here directly; the
//! file validation would refuse the repeated ids.

use crate::model::graph::{strip_triangles, Graph};
use crate::model::{AgentModel, AngleModel, Model, RadioModel, SensorModel, TriangleModel};
use crate::model::{BearingRate, Criteria, Estimator, IntegrityMode, Mode, Target};
use controller_core::{Limits, Schedule};

/// A strip of `n ≥ 3` agents, printed-paper gains (c = 10, d = 1, c_e = 10), desired
/// angles 60°, initial positions perturbed from the equilateral strip, no maneuvers.
pub fn strip_model(n: usize, duration: f64) -> Model {
    let n = n.max(3);
    let h = 3f64.sqrt() / 2.0;
    let agents = (0..n)
        .map(|i| {
            let f = i as f64;
            AgentModel {
                name: i.to_string(),
                id: (i % 256) as u8,
                position: [
                    0.5 * f + 0.08 * (1.3 * f).sin(),
                    h * (i % 2) as f64 + 0.08 * (0.7 * f).cos(),
                ],
                velocity: [0.0, 0.0],
                mass: 1.0,
                friction: [0.5, 0.5],
                velocity_damping: [0.0, 0.0],
            }
        })
        .collect();
    let tri = strip_triangles(n);
    let angle = |apex: usize, far: [usize; 2]| AngleModel {
        apex,
        far,
        desired: 60f64.to_radians(),
        stiffness: 10.0,
        damping: 1.0,
        estimator_gain: 10.0,
    };
    let triangles = tri
        .iter()
        .map(|&[a, b, c]| TriangleModel {
            vertices: [a, b, c],
            angles: [angle(a, [b, c]), angle(b, [a, c])],
        })
        .collect();
    let dt = 1e-3;
    Model {
        name: format!("strip-{n}"),
        source: "generated:strip".to_owned(),
        description: format!("triangulated strip of {n} agents"),
        duration,
        seed: 1,
        mode: Mode::Sampled,
        dt,
        log_every: 10,
        steps_per_tick: 10,
        comm_every: 1,
        integrity: IntegrityMode::Crc16,
        auth_key: [0; 16],
        estimator: Estimator::Shared,
        initial_estimate: 1.0,
        min_estimate: 0.1,
        limits: Limits::default(),
        agents,
        triangles,
        leader: None,
        velocity_reference: Schedule::default(),
        sensors: SensorModel::ideal(BearingRate::FiniteDifference),
        radio: RadioModel::ideal(),
        criteria: Criteria::default(),
        graph: Graph::new(n, &tri, None),
        attacks: Vec::new(),
        world: crate::model::WorldModel::ideal(),
        // The equilateral strip the 60° angles encode.
        target: Target {
            positions: (0..n)
                .map(|i| [0.5 * i as f64, h * (i % 2) as f64])
                .collect(),
            from_file: false,
        },
    }
}
