//! A generated scenario of any size: a triangulated strip of near-equilateral triangles
//! `(i, i+1, i+2)` (for the benchmark and scaling tests).
//!
//! Wire ids are one byte, so with more than 256 agents they repeat (`id = i mod 256`).
//! That is enough for the controllers: an agent only hears agents at most two places
//! away along the strip and is named in frames only with agents at most four places away,
//! whose ids are distinct. The model is built here directly (a file names its agents by
//! unique ids) and then passes the checks every model passes
//! ([`crate::scenario::check_model`]: the graph, the capacity, wire ids distinct within
//! two hops, the core's checks), so a bad strip is refused rather than run.

use crate::model::graph::{strip_triangles, Graph};
use crate::model::{AgentModel, AngleModel, Model, RadioModel, SensorModel, TriangleModel};
use crate::model::{BearingRate, Criteria, Estimator, IntegrityMode, Mode, Target};
use crate::scenario::{check_model, ScenarioErrors};
use ph_formation_core::{Limits, Schedule};

/// A strip of `n ≥ 3` agents, printed-paper gains (c = 10, d = 1, c_e = 10), desired
/// angles 60°, initial positions perturbed from the equilateral strip, no maneuvers;
/// checked as every model is ([`check_model`]: fewer than 3 agents are refused, for one).
pub fn strip_model(n: usize, duration: f64) -> Result<Model, ScenarioErrors> {
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
                heading: None,
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
    let model = Model {
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
        comm_auto: None,
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
        faults: Vec::new(),
        world: crate::model::WorldModel::ideal(),
        policy: None,
        start_tolerance: 0.3,
        battery: None,
        // The equilateral strip the 60° angles encode.
        target: Target {
            positions: (0..n)
                .map(|i| [0.5 * i as f64, h * (i % 2) as f64])
                .collect(),
            from_file: false,
        },
    };
    check_model(&model)?;
    Ok(model)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scenario::ErrorKind;

    #[test]
    fn a_strip_of_1000_agents_with_repeated_ids_validates() {
        let m = strip_model(1000, 1.0).expect("valid");
        assert_eq!(m.n(), 1000);
        // Ids repeat beyond two hops: agents 3 and 259 share id 3.
        assert_eq!(m.agents[3].id, m.agents[259].id);
    }

    #[test]
    fn fewer_than_three_agents_are_refused() {
        let e = strip_model(2, 1.0).expect_err("two agents");
        assert!(e.has(ErrorKind::NotLaman), "{e}");
    }

    #[test]
    fn an_id_repeated_within_two_hops_is_refused_naming_both_agents() {
        let base = strip_model(12, 1.0).expect("valid");
        // Agents 3 and 5 are neighbours (triangle (3, 4, 5)); 3 and 7 are both neighbours
        // of 5; 3 and 8 are three hops apart.
        for (other, how) in [(5, "are neighbours"), (7, "are neighbours of agent 5")] {
            let mut m = base.clone();
            m.agents[other].id = m.agents[3].id;
            let e = check_model(&m).expect_err("clash accepted").to_string();
            assert!(
                e.contains("generated:strip")
                    && e.contains(&format!("field `agents[{other}]`"))
                    && e.contains("agents 3 (agents[3])")
                    && e.contains(&format!("{other} (agents[{other}])"))
                    && e.contains("share wire id 3")
                    && e.contains(how),
                "{e}"
            );
        }
        let mut m = base;
        m.agents[8].id = m.agents[3].id;
        check_model(&m).expect("an id repeated three hops apart is unambiguous");
    }
}
