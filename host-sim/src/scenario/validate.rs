//! Scenario validation: every check names the file, the field and the reason, and
//! resolves a [`ScenarioFile`] into a [`Model`].

use crate::model::graph::{laman_order, Graph, LamanError};
use crate::model::{
    AgentModel, AngleModel, LeaderModel, Model, RadioModel, SensorModel, TriangleModel, MT, NB,
};
use crate::scenario::error::{ErrorKind, ScenarioError, ScenarioErrors};
use crate::scenario::{ScenarioFile, ScheduleSpec, Source};
use controller_core::{Limits, Schedule, ScheduleStep, MAX_SCHEDULE_STEPS};
use std::collections::HashMap;
use std::f64::consts::PI;

/// Loads, parses and validates a scenario (a file path or a built-in name).
pub fn load(arg: &str, overrides: &[String]) -> Result<Model, ScenarioErrors> {
    let source = Source::resolve(arg)?;
    let file = source.parse(overrides)?;
    validate(&file, &source.label, &source.default_name)
}

/// Collects errors while checking.
struct Checker<'a> {
    file: &'a str,
    errors: Vec<ScenarioError>,
}

impl Checker<'_> {
    fn err(&mut self, kind: ErrorKind, field: &str, reason: impl Into<String>) {
        self.errors
            .push(ScenarioError::new(kind, self.file, field, reason));
    }

    /// `x` finite and `> 0`.
    fn positive(&mut self, kind: ErrorKind, field: &str, x: f64) {
        if !(x.is_finite() && x > 0.0) {
            self.err(kind, field, format!("must be a finite number > 0, got {x}"));
        }
    }

    /// `x` finite and `≥ 0`.
    fn non_negative(&mut self, kind: ErrorKind, field: &str, x: f64) {
        if !(x.is_finite() && x >= 0.0) {
            self.err(kind, field, format!("must be a finite number ≥ 0, got {x}"));
        }
    }

    fn probability(&mut self, field: &str, p: f64) {
        if !(p.is_finite() && (0.0..=1.0).contains(&p)) {
            self.err(
                ErrorKind::InvalidValue,
                field,
                format!("must be a probability in [0, 1], got {p}"),
            );
        }
    }

    fn finite2(&mut self, field: &str, v: [f64; 2]) {
        if !(v[0].is_finite() && v[1].is_finite()) {
            self.err(
                ErrorKind::InvalidValue,
                field,
                format!("must be two finite numbers, got {v:?}"),
            );
        }
    }

    fn schedule(&mut self, field: &str, s: &ScheduleSpec) -> Schedule<f64> {
        let steps = s.steps();
        let mut out = Schedule::default();
        if steps.len() > MAX_SCHEDULE_STEPS {
            self.err(
                ErrorKind::InvalidValue,
                field,
                format!(
                    "has {} steps; the controller holds at most {MAX_SCHEDULE_STEPS}",
                    steps.len()
                ),
            );
        }
        let mut prev = f64::NEG_INFINITY;
        for (k, st) in steps.iter().enumerate() {
            let f = format!("{field}[{k}]");
            if !(st.from.is_finite() && st.from >= 0.0) {
                self.err(
                    ErrorKind::InvalidValue,
                    &format!("{f}.from"),
                    format!("must be a finite time ≥ 0, got {}", st.from),
                );
            } else if st.from <= prev {
                self.err(
                    ErrorKind::InvalidValue,
                    &format!("{f}.from"),
                    "steps must be sorted by strictly increasing `from`",
                );
            }
            prev = st.from;
            self.finite2(&format!("{f}.value"), st.value);
            let _ = out.steps.push(ScheduleStep {
                from: st.from,
                value: st.value,
            });
        }
        out
    }
}

/// Largest number of RK4 steps of one run.
const MAX_STEPS: f64 = 1e12;

/// How many whole `dt` steps make `interval`, if it is a whole multiple.
fn whole_steps(interval: f64, dt: f64) -> Option<usize> {
    let k = (interval / dt).round();
    if k >= 1.0 && ((k * dt - interval).abs() <= 1e-9 * interval.max(dt)) {
        Some(k as usize)
    } else {
        None
    }
}

/// Interior angle at `p` of the triangle `p, a, b` (rad); NaN for coincident points.
fn interior_angle(p: [f64; 2], a: [f64; 2], b: [f64; 2]) -> f64 {
    let u = [a[0] - p[0], a[1] - p[1]];
    let w = [b[0] - p[0], b[1] - p[1]];
    let nu = u[0].hypot(u[1]);
    let nw = w[0].hypot(w[1]);
    if nu == 0.0 || nw == 0.0 {
        return f64::NAN;
    }
    ((u[0] * w[0] + u[1] * w[1]) / (nu * nw))
        .clamp(-1.0, 1.0)
        .acos()
}

/// Validates a parsed scenario file. `file` labels errors; `default_name` is used when the
/// file has no `name`.
pub fn validate(s: &ScenarioFile, file: &str, default_name: &str) -> Result<Model, ScenarioErrors> {
    let mut c = Checker {
        file,
        errors: Vec::new(),
    };
    use ErrorKind::{InvalidValue, NonPositiveGain};

    // ---- run, integration, controller
    c.positive(InvalidValue, "duration", s.duration);
    c.positive(InvalidValue, "integration.dt", s.integration.dt);
    c.positive(
        InvalidValue,
        "integration.log_interval",
        s.integration.log_interval,
    );
    let ctl = &s.controller;
    c.positive(InvalidValue, "controller.rate_hz", ctl.rate_hz);
    let dt = s.integration.dt;
    let mut steps_per_tick = 1;
    let mut log_every = 1;
    if c.errors.is_empty() {
        match whole_steps(1.0 / ctl.rate_hz, dt) {
            Some(k) => steps_per_tick = k,
            None => c.err(
                InvalidValue,
                "controller.rate_hz",
                format!(
                    "the control period 1/{} s must be a whole number (≥ 1) of integration.dt = {dt} s",
                    ctl.rate_hz
                ),
            ),
        }
        match whole_steps(s.integration.log_interval, dt) {
            Some(k) => log_every = k,
            None => c.err(
                InvalidValue,
                "integration.log_interval",
                format!("must be a whole number (≥ 1) of integration.dt = {dt} s"),
            ),
        }
        if s.duration / dt > MAX_STEPS {
            c.err(
                InvalidValue,
                "integration.dt",
                format!(
                    "duration / dt = {:.3e} RK4 steps; at most {MAX_STEPS:e}",
                    s.duration / dt
                ),
            );
        } else if whole_steps(s.duration, dt).is_none() {
            c.err(
                InvalidValue,
                "duration",
                format!("must be a whole number of integration.dt = {dt} s"),
            );
        }
    }
    c.positive(InvalidValue, "controller.min_estimate", ctl.min_estimate);
    c.positive(
        InvalidValue,
        "controller.initial_estimate",
        ctl.initial_estimate,
    );
    if ctl.initial_estimate < ctl.min_estimate {
        c.err(
            InvalidValue,
            "controller.initial_estimate",
            format!(
                "r̂(0) = {} is below controller.min_estimate = {}",
                ctl.initial_estimate, ctl.min_estimate
            ),
        );
    }
    c.positive(InvalidValue, "controller.max_force", ctl.max_force);
    c.positive(
        InvalidValue,
        "controller.neighbour_timeout",
        ctl.neighbour_timeout,
    );
    c.non_negative(NonPositiveGain, "controller.safe_damping", ctl.safe_damping);
    let margin_ok = ctl.angle_margin_deg.is_finite()
        && ctl.angle_margin_deg > 0.0
        && ctl.angle_margin_deg < 45.0;
    if !margin_ok {
        c.err(
            InvalidValue,
            "controller.angle_margin_deg",
            format!("must be in (0, 45) degrees, got {}", ctl.angle_margin_deg),
        );
    }
    let margin = if margin_ok {
        ctl.angle_margin_deg.to_radians()
    } else {
        5f64.to_radians()
    };

    // ---- sensors, radio, criteria
    let se = &s.sensors;
    c.non_negative(
        InvalidValue,
        "sensors.bearing_noise_deg",
        se.bearing_noise_deg,
    );
    c.finite2("sensors.velocity_bias", se.velocity_bias);
    if !se.bearing_bias_deg.is_finite() {
        c.err(InvalidValue, "sensors.bearing_bias_deg", "must be finite");
    }
    c.non_negative(InvalidValue, "sensors.velocity_noise", se.velocity_noise);
    c.non_negative(InvalidValue, "sensors.offset_noise", se.offset_noise);
    c.non_negative(InvalidValue, "sensors.range_noise", se.range_noise);
    let ra = &s.radio;
    c.non_negative(InvalidValue, "radio.latency", ra.latency);
    c.non_negative(InvalidValue, "radio.jitter", ra.jitter);
    c.probability("radio.loss", ra.loss);
    c.probability("radio.duplication", ra.duplication);
    c.probability("radio.reordering", ra.reordering);
    c.probability("radio.corruption", ra.corruption);
    c.non_negative(InvalidValue, "radio.bandwidth", ra.bandwidth);
    c.non_negative(InvalidValue, "radio.queue_limit", ra.queue_limit);
    let period = dt * steps_per_tick as f64;
    let reorder_delay = ra.reorder_delay.unwrap_or(2.0 * period);
    c.non_negative(InvalidValue, "radio.reorder_delay", reorder_delay);
    let cr = &s.criteria;
    c.non_negative(
        InvalidValue,
        "criteria.collision_distance",
        cr.collision_distance,
    );
    c.positive(InvalidValue, "criteria.collapse_time", cr.collapse_time);
    c.positive(
        InvalidValue,
        "criteria.divergence_speed",
        cr.divergence_speed,
    );
    c.positive(
        InvalidValue,
        "criteria.divergence_energy_factor",
        cr.divergence_energy_factor,
    );
    c.positive(InvalidValue, "criteria.angle_tolerance", cr.angle_tolerance);
    c.positive(
        InvalidValue,
        "criteria.displacement_tolerance",
        cr.displacement_tolerance,
    );
    c.positive(
        InvalidValue,
        "criteria.velocity_tolerance",
        cr.velocity_tolerance,
    );

    // ---- agents
    let d = &s.agent_defaults;
    c.positive(InvalidValue, "agent_defaults.mass", d.mass);
    let mut index: HashMap<i64, usize> = HashMap::new();
    let mut agents = Vec::with_capacity(s.agents.len());
    for (i, a) in s.agents.iter().enumerate() {
        let f = |x: &str| format!("agents[{i}].{x}");
        if !(0..=255).contains(&a.id) {
            c.err(
                InvalidValue,
                &f("id"),
                format!(
                    "id {} is out of range: ids are 0–255 (one byte on the wire)",
                    a.id
                ),
            );
        } else if let Some(&j) = index.get(&a.id) {
            c.err(
                ErrorKind::DuplicateId,
                &f("id"),
                format!("id {} is already used by agents[{j}]", a.id),
            );
        } else {
            index.insert(a.id, i);
        }
        c.finite2(&f("position"), a.position);
        let velocity = a.velocity.unwrap_or([0.0; 2]);
        c.finite2(&f("velocity"), velocity);
        let mass = a.mass.unwrap_or(d.mass);
        c.positive(InvalidValue, &f("mass"), mass);
        let friction = a.friction.unwrap_or(d.friction).pair();
        let velocity_damping = a.velocity_damping.unwrap_or(d.velocity_damping).pair();
        for k in 0..2 {
            c.non_negative(InvalidValue, &f("friction"), friction[k]);
            c.non_negative(NonPositiveGain, &f("velocity_damping"), velocity_damping[k]);
        }
        agents.push(AgentModel {
            id: u8::try_from(a.id).unwrap_or(0),
            position: a.position,
            velocity,
            mass,
            friction,
            velocity_damping,
        });
    }
    if s.agents.len() < 3 {
        c.err(
            ErrorKind::NotLaman,
            "agents",
            format!(
                "a formation needs at least 3 agents, got {}",
                s.agents.len()
            ),
        );
    }
    let lookup = |c: &mut Checker<'_>, field: &str, id: i64| -> Option<usize> {
        let found = index.get(&id).copied();
        if found.is_none() {
            c.err(ErrorKind::UnknownId, field, format!("no agent has id {id}"));
        }
        found
    };

    // ---- triangles and angles
    let g = &s.gains;
    let mut triangles = Vec::with_capacity(s.triangles.len());
    let mut ids_ok = true;
    for (ti, t) in s.triangles.iter().enumerate() {
        let tf = format!("triangles[{ti}]");
        let mut verts = [0usize; 3];
        let mut ok = true;
        for (k, &id) in t.vertices.iter().enumerate() {
            match lookup(&mut c, &format!("{tf}.vertices"), id) {
                Some(i) => verts[k] = i,
                None => ok = false,
            }
        }
        if ok && (verts[0] == verts[1] || verts[1] == verts[2] || verts[0] == verts[2]) {
            c.err(
                ErrorKind::NotLaman,
                &format!("{tf}.vertices"),
                format!("triangle {:?} repeats an agent", t.vertices),
            );
            ok = false;
        }
        if t.angles.len() != 2 {
            c.err(
                InvalidValue,
                &format!("{tf}.angles"),
                format!(
                    "a triangle controls exactly two of its angles, got {}",
                    t.angles.len()
                ),
            );
            ok = false;
        }
        let mut angle_models = Vec::new();
        let mut desired = Vec::new();
        for (ai, a) in t.angles.iter().enumerate() {
            let af = format!("{tf}.angles[{ai}]");
            let apex = if t.vertices.contains(&a.apex) {
                index.get(&a.apex).copied()
            } else {
                c.err(
                    ErrorKind::UnknownId,
                    &format!("{af}.apex"),
                    format!(
                        "apex {} is not a vertex of triangle {:?}",
                        a.apex, t.vertices
                    ),
                );
                None
            };
            let want = match (a.desired_deg, a.desired_rad) {
                (Some(deg), None) => Some(deg.to_radians()),
                (None, Some(rad)) => Some(rad),
                (Some(_), Some(_)) => {
                    c.err(
                        InvalidValue,
                        &af,
                        "give the desired angle once: desired_deg or desired_rad, not both",
                    );
                    None
                }
                (None, None) => {
                    c.err(
                        InvalidValue,
                        &af,
                        "missing desired angle: give desired_deg or desired_rad",
                    );
                    None
                }
            };
            if let Some(x) = want {
                let field = if a.desired_deg.is_some() {
                    format!("{af}.desired_deg")
                } else {
                    format!("{af}.desired_rad")
                };
                if !(x.is_finite() && x > margin && x < PI - margin) {
                    c.err(
                        ErrorKind::InfeasibleAngles,
                        &field,
                        format!(
                            "desired angle {:.4}° must lie strictly between {:.1}° and {:.1}° (the angle margin keeps it away from 0 and 180°)",
                            x.to_degrees(),
                            margin.to_degrees(),
                            180.0 - margin.to_degrees()
                        ),
                    );
                } else {
                    desired.push(x);
                }
            }
            let mut gain =
                |name: &str, own: Option<f64>, dflt: Option<f64>, zero_ok: bool| -> f64 {
                    match own.or(dflt) {
                        Some(x) => {
                            let good = x.is_finite() && (x > 0.0 || (zero_ok && x == 0.0));
                            if !good {
                                let need = if zero_ok { "≥ 0" } else { "> 0" };
                                let field = if own.is_some() {
                                    format!("{af}.{name}")
                                } else {
                                    format!("gains.{name}")
                                };
                                c.err(
                                    NonPositiveGain,
                                    &field,
                                    format!("gain must be finite and {need}, got {x}"),
                                );
                            }
                            x
                        }
                        None => {
                            c.err(
                                InvalidValue,
                                &format!("{af}.{name}"),
                                format!("no {name}: give it here or in [gains]"),
                            );
                            f64::NAN
                        }
                    }
                };
            let stiffness = gain("stiffness", a.stiffness, g.stiffness, false);
            let damping = gain("damping", a.damping, g.damping, true);
            let estimator_gain = gain("estimator_gain", a.estimator_gain, g.estimator_gain, false);
            if let Some(u) = apex {
                let mut far = [0usize; 2];
                let mut k = 0;
                for &v in &verts {
                    if v != u && k < 2 {
                        far[k] = v;
                        k += 1;
                    }
                }
                angle_models.push(AngleModel {
                    apex: u,
                    far,
                    desired: want.unwrap_or(f64::NAN),
                    stiffness,
                    damping,
                    estimator_gain,
                });
            }
        }
        if t.angles.len() == 2 && t.angles[0].apex == t.angles[1].apex {
            c.err(
                InvalidValue,
                &format!("{tf}.angles[1].apex"),
                format!(
                    "both controlled angles have apex {}; a triangle controls two different angles",
                    t.angles[0].apex
                ),
            );
            ok = false;
        }
        if let [a0, a1] = desired[..] {
            let third = PI - a0 - a1;
            if third <= 0.0 {
                c.err(
                    ErrorKind::InfeasibleAngles,
                    &format!("{tf}.angles"),
                    format!(
                        "the controlled angles {:.4}° + {:.4}° sum to 180° or more: no triangle has them",
                        a0.to_degrees(),
                        a1.to_degrees()
                    ),
                );
            } else if third <= margin {
                c.err(
                    ErrorKind::InfeasibleAngles,
                    &format!("{tf}.angles"),
                    format!(
                        "the controlled angles {:.4}° + {:.4}° leave {:.4}° for the third angle, within the {:.1}° margin of 0",
                        a0.to_degrees(),
                        a1.to_degrees(),
                        third.to_degrees(),
                        margin.to_degrees()
                    ),
                );
            }
        }
        match (ok, <[AngleModel; 2]>::try_from(angle_models)) {
            (true, Ok(angles)) => triangles.push(TriangleModel {
                vertices: verts,
                angles,
            }),
            _ => ids_ok = false,
        }
    }

    // ---- graph: triangulated Laman
    let tri_idx: Vec<[usize; 3]> = triangles.iter().map(|t| t.vertices).collect();
    let n = agents.len();
    let id_of = |i: usize| agents.get(i).map_or(-1, |a| i64::from(a.id));
    if ids_ok && n >= 3 && c.errors.iter().all(|e| e.kind != ErrorKind::DuplicateId) {
        if let Err(e) = laman_order(n, &tri_idx) {
            let (field, reason) = match e {
                LamanError::Empty => (
                    "triangles".to_owned(),
                    "no triangles: the graph must be built from triangles".to_owned(),
                ),
                LamanError::Isolated(i) => (
                    format!("agents[{i}]"),
                    format!("agent {} belongs to no triangle", id_of(i)),
                ),
                LamanError::Count { agents, triangles } => (
                    "triangles".to_owned(),
                    format!(
                        "{agents} agents need exactly {} triangles (N = M + 2), got {triangles}",
                        agents.saturating_sub(2)
                    ),
                ),
                LamanError::Unattached(rest) => {
                    let first = rest.first().copied().unwrap_or(0);
                    (
                        format!("triangles[{first}]"),
                        format!(
                            "triangle {:?} does not join exactly one new agent to an edge of the triangles before it (triangles {:?} cannot be attached)",
                            s.triangles.get(first).map(|t| t.vertices).unwrap_or_default(),
                            rest
                        ),
                    )
                }
            };
            c.err(ErrorKind::NotLaman, &field, reason);
        }
        // ---- collinear initial triangles
        for (ti, t) in triangles.iter().enumerate() {
            let p = t.vertices.map(|v| agents[v].position);
            for k in 0..3 {
                let ang = interior_angle(p[k], p[(k + 1) % 3], p[(k + 2) % 3]);
                if !(ang > margin && ang < PI - margin) {
                    let what = if ang.is_nan() {
                        "two vertices coincide".to_owned()
                    } else {
                        format!(
                            "the angle at agent {} is {:.3}°, within the {:.1}° margin of 0 or 180°",
                            id_of(t.vertices[k]),
                            ang.to_degrees(),
                            margin.to_degrees()
                        )
                    };
                    c.err(
                        ErrorKind::CollinearTriangle,
                        &format!("triangles[{ti}]"),
                        format!(
                            "triangle {:?} is (nearly) collinear in the initial positions: {what}",
                            t.vertices.map(id_of)
                        ),
                    );
                    break;
                }
            }
        }
    }

    // ---- leader and references
    let leader = match &s.leader {
        None => None,
        Some(l) => {
            let a = lookup(&mut c, "leader.agents", l.agents[0]);
            let b = lookup(&mut c, "leader.agents", l.agents[1]);
            if l.agents[0] == l.agents[1] {
                c.err(
                    InvalidValue,
                    "leader.agents",
                    "the two leaders must be different agents",
                );
            }
            c.positive(NonPositiveGain, "leader.stiffness", l.stiffness);
            for x in l.damping.pair() {
                c.non_negative(NonPositiveGain, "leader.damping", x);
            }
            let displacement = c.schedule("leader.displacement", &l.displacement);
            match (a, b) {
                (Some(a), Some(b)) => Some(LeaderModel {
                    a,
                    b,
                    stiffness: l.stiffness,
                    damping: l.damping.pair(),
                    displacement,
                }),
                _ => None,
            }
        }
    };
    let velocity_reference = c.schedule("velocity_reference", &s.velocity_reference);

    // ---- capacity of the controller
    let graph = Graph::new(n, &tri_idx, leader.as_ref().map(|l| [l.a, l.b]));
    for i in 0..n {
        let tris = tri_idx.iter().filter(|t| t.contains(&i)).count();
        if tris > MT {
            c.err(
                InvalidValue,
                &format!("agents[{i}]"),
                format!(
                    "agent {} belongs to {tris} triangles; the controller holds at most {MT}",
                    id_of(i)
                ),
            );
        }
        if graph.radio.of(i).len() > NB {
            c.err(
                InvalidValue,
                &format!("agents[{i}]"),
                format!(
                    "agent {} has {} neighbours; the controller holds at most {NB}",
                    id_of(i),
                    graph.radio.of(i).len()
                ),
            );
        }
    }

    if !c.errors.is_empty() {
        // A default gain used by several angles is reported once.
        let mut seen = std::collections::HashSet::new();
        c.errors.retain(|e| seen.insert(e.to_string()));
        return Err(ScenarioErrors(c.errors));
    }

    let limits = Limits {
        max_force: ctl.max_force,
        neighbour_timeout: ctl.neighbour_timeout,
        safe_damping: ctl.safe_damping,
        margin_cos: margin.cos(),
        ..Limits::default()
    };
    let model = Model {
        name: s.name.clone().unwrap_or_else(|| default_name.to_owned()),
        source: file.to_owned(),
        description: s.description.clone().unwrap_or_default(),
        duration: s.duration,
        seed: s.seed,
        mode: s.mode,
        dt,
        log_every,
        steps_per_tick,
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
            velocity_noise: se.velocity_noise,
            velocity_bias: se.velocity_bias,
            offset_noise: se.offset_noise,
            range_noise: se.range_noise,
        },
        radio: RadioModel {
            latency: ra.latency,
            jitter: ra.jitter,
            loss: ra.loss,
            duplication: ra.duplication,
            reordering: ra.reordering,
            reorder_delay,
            corruption: ra.corruption,
            bandwidth: ra.bandwidth,
            queue_limit: ra.queue_limit,
        },
        criteria: s.criteria.clone(),
        graph,
    };
    // Last line of defence: the core's own checks (should agree with the above).
    let mut core_errors = Vec::new();
    for i in 0..model.n() {
        if let Err(e) = model.core_agent(i) {
            core_errors.push(ScenarioError::new(
                InvalidValue,
                file,
                &format!("agents[{i}]"),
                e,
            ));
        }
    }
    if core_errors.is_empty() {
        Ok(model)
    } else {
        Err(ScenarioErrors(core_errors))
    }
}
