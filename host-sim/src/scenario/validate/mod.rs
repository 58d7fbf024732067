//! Scenario validation: every check names the file, the field and the reason, and
//! resolves a [`ScenarioFile`] into a [`Model`]. The checks run in the order of the
//! file's sections (errors are reported in that order; the first one's kind gives the
//! exit code).

mod agents;
mod attacks;
mod camera;
mod checker;
mod comm;
mod faults;
mod graph;
mod model;
mod policy;
mod positions;
mod references;
mod settings;
mod target;
mod triangles;
mod world;

use crate::model::{Graph, Model, RadioModel, SensorModel};
use crate::scenario::error::ScenarioErrors;
use crate::scenario::ScenarioFile;
use checker::Checker;
pub use model::check_model;
use ph_formation_core::{BearingFilter, Limits, TrackerConfig};

/// Validates a parsed scenario file. `file` labels errors; `default_name` is used when the
/// file has no `name`.
pub fn validate(s: &ScenarioFile, file: &str, default_name: &str) -> Result<Model, ScenarioErrors> {
    check(s, file, default_name, None)
}

/// [`validate`], with the file's TOML `text`, so that errors about `[[agents]]` or
/// `[[triangles]]` entries also name their line.
pub fn validate_text(
    s: &ScenarioFile,
    file: &str,
    default_name: &str,
    text: &str,
) -> Result<Model, ScenarioErrors> {
    check(s, file, default_name, Some(text))
}

fn check(
    s: &ScenarioFile,
    file: &str,
    default_name: &str,
    text: Option<&str>,
) -> Result<Model, ScenarioErrors> {
    let mut c = Checker {
        file,
        text,
        errors: Vec::new(),
    };
    let settings::Timing {
        dt,
        steps_per_tick,
        log_every,
        margin,
        reorder_delay,
    } = settings::check(&mut c, s);
    let period = dt * steps_per_tick as f64;
    let comm_every = comm::comm_every(&mut c, s, period);
    let channel = comm::channel(&mut c, s, period);
    let auth_key = comm::auth_key(&mut c, s);
    let world = world::check(&mut c, s, period);
    let policy = policy::check(&mut c, s);
    let battery = policy::battery(&mut c, s);
    let (mut agents, index) = agents::check(&mut c, s);
    let camera = camera::check(&mut c, s, &agents);
    let positions = positions::check(&mut c, s);
    let (triangles, ids_ok) = triangles::check(&mut c, s, &index, margin);
    let order = graph::check(&mut c, s, &agents, &triangles, ids_ok, margin);
    let leader = references::leader(&mut c, s, &index);
    let attacks = attacks::check(&mut c, s, &index);
    let faults = faults::check(&mut c, s, &index);
    let velocity_reference = c.schedule("velocity_reference", &s.velocity_reference);
    let tri_idx: Vec<[usize; 3]> = triangles.iter().map(|t| t.vertices).collect();
    let graph = Graph::new(agents.len(), &tri_idx, leader.as_ref().map(|l| [l.a, l.b]));
    graph::capacity(&mut c, &agents, &graph);
    if c.errors.is_empty() {
        agents::wire_ids(&mut c, s, &mut agents, &graph.radio);
    }
    let target = target::check(&mut c, s, &agents, &triangles, order.as_deref());

    if !c.errors.is_empty() {
        // A default gain used by several angles is reported once.
        let mut seen = std::collections::HashSet::new();
        c.errors.retain(|e| seen.insert(e.to_string()));
        return Err(ScenarioErrors(c.errors));
    }

    let (ctl, se, ra) = (&s.controller, &s.sensors, &s.radio);
    let limits = Limits {
        max_force: ctl.max_force,
        neighbour_timeout: ctl.neighbour_timeout,
        bearing_hold: ctl.bearing_hold_s,
        safe_damping: ctl.safe_damping,
        margin_cos: margin.cos(),
        ..Limits::default()
    };
    let mut model = Model {
        name: s.name.clone().unwrap_or_else(|| default_name.to_owned()),
        source: file.to_owned(),
        description: s.description.clone().unwrap_or_default(),
        duration: s.duration,
        seed: s.seed,
        mode: s.mode,
        dt,
        log_every,
        steps_per_tick,
        comm_every,
        comm_auto: (s.controller.comm_rate_hz == Some(crate::scenario::settings::CommRate::Auto))
            .then(crate::model::AutoRate::default),
        integrity: ctl.integrity,
        auth_key,
        estimator: ctl.estimator,
        initial_estimate: ctl.initial_estimate,
        min_estimate: ctl.min_estimate,
        limits,
        agents,
        triangles,
        leader,
        velocity_reference,
        sensors: SensorModel {
            bearing_noise: se.bearing_noise_deg.to_radians(),
            bearing_bias: se.bearing_bias_deg.to_radians(),
            bearing_rate: se.bearing_rate,
            // Resolved below from the whole model's effective sensing noise.
            bearing_filter: BearingFilter::FiniteDifference,
            velocity_noise: se.velocity_noise,
            velocity_bias: se.velocity_bias,
            offset_noise: se.offset_noise,
            range_noise: se.range_noise,
            camera,
            positions,
        },
        radio: RadioModel {
            latency: ra.latency,
            jitter: ra.jitter,
            loss: ra.loss,
            duplication: ra.duplication,
            reordering: ra.reordering,
            reorder_delay,
            corruption: ra.corruption,
            bandwidth: ra.bandwidth_bps,
            queue_limit: ra.queue_limit,
            channel,
        },
        criteria: s.criteria.clone(),
        graph,
        attacks,
        faults,
        target,
        world,
        start_tolerance: s.policy.as_ref().map_or(0.3, |p| p.start_tolerance_m),
        policy,
        battery,
    };
    model.sensors.bearing_filter = bearing_filter(se, &model.sensing_noise());
    // Last line of defence, shared with generated models (`model::check_model`): wire
    // ids a receiver can tell apart, and the core's own checks (should agree with the
    // above).
    let mut c = Checker {
        file,
        text,
        errors: Vec::new(),
    };
    model::built(&mut c, &model);
    if c.errors.is_empty() {
        Ok(model)
    } else {
        Err(ScenarioErrors(c.errors))
    }
}

/// The filter each controller runs, from `sensors.bearing_filter` (SPEC §11): `auto` is
/// the tracker whenever the sensing chain is noisy or lossy
/// ([`crate::model::SensingNoise::is_noisy`]) and the finite difference for an ideal
/// sensor; the tracker assumes the chain's effective bearing noise unless
/// `sensors.tracker.bearing_noise_deg` says otherwise.
fn bearing_filter(
    se: &crate::scenario::settings::SensorSpec,
    noise: &crate::model::SensingNoise,
) -> BearingFilter<f64> {
    use crate::scenario::settings::FilterChoice;
    let tracker = matches!(se.bearing_filter, FilterChoice::Tracker)
        || (se.bearing_filter == FilterChoice::Auto && noise.is_noisy());
    if !tracker {
        return BearingFilter::FiniteDifference;
    }
    let t = &se.tracker;
    let sigma_deg = t
        .bearing_noise_deg
        .unwrap_or(noise.bearing.to_degrees())
        .max(MIN_TRACKER_NOISE_DEG);
    BearingFilter::Tracker(TrackerConfig {
        bearing_noise: sigma_deg.to_radians(),
        rate_noise: t.rate_noise,
        inverse_range_noise: t.inverse_range_noise,
        gate: t.gate,
    })
}

/// The smallest bearing noise the tracker assumes (degrees): an ideal sensor's `σ = 0`
/// would make the tracker trust every bearing completely.
const MIN_TRACKER_NOISE_DEG: f64 = 0.1;
