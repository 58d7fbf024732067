//! `[sensors.camera]`: each field in range, a camera only where the simulator models one
//! (sampled mode, bearings without exact rates), and bodies that fit between the agents.

use super::checker::Checker;
use crate::model::{AgentModel, BearingRate, CameraModel, Mode};
use crate::scenario::error::ErrorKind::InvalidValue;
use crate::scenario::ScenarioFile;
use rstar::primitives::GeomWithData;
use rstar::RTree;

/// The oldest image a camera may deliver (s): the simulator keeps every agent's state of
/// that many control periods.
pub(super) const MAX_LATENCY_S: f64 = 1.0;

/// Checks `[sensors.camera]` against the `agents` checked so far; the camera in SI units,
/// or `None` without one.
pub(super) fn check(
    c: &mut Checker<'_>,
    s: &ScenarioFile,
    agents: &[AgentModel],
) -> Option<CameraModel> {
    let cam = s.sensors.camera.as_ref()?;
    let f = |x: &str| format!("sensors.camera.{x}");
    if !(cam.fov_deg.is_finite() && cam.fov_deg > 0.0 && cam.fov_deg <= 360.0) {
        c.err(
            InvalidValue,
            &f("fov_deg"),
            format!("must be in (0, 360] degrees, got {}", cam.fov_deg),
        );
    }
    let range = cam.range_m.unwrap_or(f64::INFINITY);
    if range.is_nan() || range <= 0.0 {
        c.err(
            InvalidValue,
            &f("range_m"),
            format!("must be a distance > 0 (m; leave it out for no limit), got {range}"),
        );
    }
    c.non_negative(
        InvalidValue,
        &f("occlusion_radius_m"),
        cam.occlusion_radius_m,
    );
    c.probability(&f("detection_probability"), cam.detection_probability);
    c.probability(&f("outlier_probability"), cam.outlier_probability);
    c.non_negative(InvalidValue, &f("latency_s"), cam.latency_s);
    if cam.latency_s > MAX_LATENCY_S {
        c.err(
            InvalidValue,
            &f("latency_s"),
            format!(
                "{} s: the simulator keeps at most {MAX_LATENCY_S} s of history",
                cam.latency_s
            ),
        );
    }
    if s.sensors.bearing_rate == BearingRate::Exact {
        c.err(
            InvalidValue,
            "sensors.bearing_rate",
            "a camera measures no bearing rates: with [sensors.camera] use \"finite_difference\"",
        );
    }
    if s.mode == Mode::Continuous {
        c.err(
            InvalidValue,
            "sensors.camera",
            "continuous mode measures every bearing ideally: a camera needs mode = \"sampled\"",
        );
    }
    check_bodies(c, cam.occlusion_radius_m, agents);
    Some(CameraModel {
        fov: cam.fov_deg.to_radians(),
        range,
        occlusion_radius: cam.occlusion_radius_m,
        detection_probability: cam.detection_probability,
        outlier_probability: cam.outlier_probability,
        latency: cam.latency_s,
    })
}

/// An occlusion radius no larger than the smallest initial spacing between two agents
/// (a larger body would hide everything from the agents inside it). The closest pair from
/// an R*-tree of the initial positions: `O(N log N)`.
fn check_bodies(c: &mut Checker<'_>, radius: f64, agents: &[AgentModel]) {
    let finite = agents
        .iter()
        .all(|a| a.position.iter().all(|x| x.is_finite()));
    // Positions that are not numbers are reported by the agents' own checks.
    if radius.is_nan() || radius <= 0.0 || agents.len() < 2 || !finite {
        return;
    }
    let points = agents
        .iter()
        .enumerate()
        .map(|(k, a)| GeomWithData::new(a.position, k))
        .collect();
    let tree: RTree<GeomWithData<[f64; 2], usize>> = RTree::bulk_load(points);
    let mut closest: Option<(f64, usize, usize)> = None;
    for (i, a) in agents.iter().enumerate() {
        let nearest = tree
            .nearest_neighbor_iter_with_distance_2(a.position)
            .find(|(p, _)| p.data != i);
        if let Some((p, d2)) = nearest {
            let pair = (d2.sqrt(), i.min(p.data), i.max(p.data));
            if closest.is_none_or(|best| pair < best) {
                closest = Some(pair);
            }
        }
    }
    if let Some((d, i, j)) = closest.filter(|&(d, _, _)| radius > d) {
        c.err(
            InvalidValue,
            "sensors.camera.occlusion_radius_m",
            format!(
                "{radius} m is larger than the {d} m between agents {} and {} at the start: \
                 each agent's body would hide the other",
                agents[i].name, agents[j].name
            ),
        );
    }
}
