//! The scenario file: its TOML schema (documented in `docs/scenarios.md`), the built-in
//! scenarios embedded in the binary, loading and `--set key=value` overrides.
//!
//! This module only parses; [`crate::scenario::validate`] checks the meaning and resolves a
//! [`ScenarioFile`] into a [`crate::model::Model`].

pub mod error;
pub mod strip;
pub mod validate;

use crate::scenario::error::{ErrorKind, ScenarioError};
use serde::{Deserialize, Serialize};
use std::path::Path;

/// A built-in scenario: its name, one-line description and TOML text.
#[derive(Clone, Copy, Debug)]
pub struct Builtin {
    /// Name used on the command line (`host-sim run paper`).
    pub name: &'static str,
    /// One line for `host-sim list`.
    pub description: &'static str,
    /// The TOML text.
    pub text: &'static str,
}

/// The scenarios embedded in the binary (SPEC §9). The first is the default run.
pub const BUILTINS: &[Builtin] = &[
    Builtin {
        name: "paper",
        description: "SPEC §9 reference: c = 1000, d = 10, c_e = 1000, leader edge and v*, 100 s (converges)",
        text: include_str!("../../scenarios/paper.toml"),
    },
    Builtin {
        name: "paper-printed",
        description: "SPEC §9 with the printed gains c = 10, d = 1, c_e = 10 (fails: estimates collapse, agents collide)",
        text: include_str!("../../scenarios/paper-printed.toml"),
    },
    Builtin {
        name: "formation-only",
        description: "SPEC §9 printed gains without maneuvers (no leader edge, v* = 0, D^v = 0; converges)",
        text: include_str!("../../scenarios/formation-only.toml"),
    },
];

/// Looks up a built-in scenario by name.
pub fn builtin(name: &str) -> Option<&'static Builtin> {
    BUILTINS.iter().find(|b| b.name == name)
}

/// Simulation mode.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Mode {
    /// Controllers sampled with zero-order hold at their rate, frames over the radio model.
    #[default]
    Sampled,
    /// Controllers evaluated at every RK4 stage with exact rates, estimators inside the
    /// ODE state, no radio (for checking S14).
    Continuous,
}

impl Mode {
    /// The name used in files and `summary.json`.
    pub fn as_str(self) -> &'static str {
        match self {
            Mode::Sampled => "sampled",
            Mode::Continuous => "continuous",
        }
    }
}

/// Distance source of the controllers (SPEC §6).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Estimator {
    /// One passive estimate per angle and edge, owned by the apex (S9, S10).
    #[default]
    Shared,
    /// The paper's per-agent copies (not passive).
    PerAgent,
    /// A range sensor gives the distances.
    Measured,
}

impl Estimator {
    /// The name used in files and `summary.json`.
    pub fn as_str(self) -> &'static str {
        match self {
            Estimator::Shared => "shared",
            Estimator::PerAgent => "per_agent",
            Estimator::Measured => "measured",
        }
    }
}

/// How the bearing rates given to the controllers are obtained.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum BearingRate {
    /// Each agent differentiates its successive bearings (SPEC §2).
    #[default]
    FiniteDifference,
    /// The exact S2 rate from the true state (an ideal optical-flow sensor).
    Exact,
}

/// A diagonal 2×2 matrix: one number (`d·I`) or `[d_x, d_y]`.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(untagged)]
pub enum Diagonal {
    /// `d · I`.
    Scalar(f64),
    /// `diag(d_x, d_y)`.
    Pair([f64; 2]),
}

impl Diagonal {
    /// The diagonal as `[d_x, d_y]`.
    pub fn pair(self) -> [f64; 2] {
        match self {
            Diagonal::Scalar(d) => [d, d],
            Diagonal::Pair(p) => p,
        }
    }
}

/// One step of a piecewise-constant schedule.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct StepSpec {
    /// Start time (s).
    pub from: f64,
    /// The value `[x, y]` from then on.
    pub value: [f64; 2],
}

/// A schedule: a constant `[x, y]` or a list of `{ from, value }` steps.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(untagged)]
pub enum ScheduleSpec {
    /// The same value from `t = 0` on.
    Constant([f64; 2]),
    /// Piecewise constant, steps sorted by `from`.
    Steps(Vec<StepSpec>),
}

impl Default for ScheduleSpec {
    fn default() -> Self {
        ScheduleSpec::Constant([0.0, 0.0])
    }
}

impl ScheduleSpec {
    /// The steps (a constant is one step from `t = 0`).
    pub fn steps(&self) -> Vec<StepSpec> {
        match self {
            ScheduleSpec::Constant(v) => vec![StepSpec {
                from: 0.0,
                value: *v,
            }],
            ScheduleSpec::Steps(s) => s.clone(),
        }
    }
}

/// `[integration]`: the plant integrator and the log.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct Integration {
    /// Fixed RK4 step (s).
    pub dt: f64,
    /// Simulated time between two logged rows of `timeseries.csv` (s).
    pub log_interval: f64,
}

impl Default for Integration {
    fn default() -> Self {
        Self {
            dt: 1e-3,
            log_interval: 1e-2,
        }
    }
}

/// `[controller]`: what every agent's controller is configured with.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct ControllerSpec {
    /// Control rate (Hz); the period must be a whole number of RK4 steps.
    pub rate_hz: f64,
    /// Distance source.
    pub estimator: Estimator,
    /// `r̂(0)`.
    pub initial_estimate: f64,
    /// `r_min` of S10.
    pub min_estimate: f64,
    /// Force saturation (N).
    pub max_force: f64,
    /// A neighbour silent for longer than this (s) triggers the safe output.
    pub neighbour_timeout: f64,
    /// Safe output gain: `U = −safe_damping · v`.
    pub safe_damping: f64,
    /// Margin (degrees) that desired and current angles must keep from 0 and 180°.
    pub angle_margin_deg: f64,
}

impl Default for ControllerSpec {
    fn default() -> Self {
        Self {
            rate_hz: 100.0,
            estimator: Estimator::Shared,
            initial_estimate: 1.0,
            min_estimate: 0.1,
            max_force: 1e3,
            neighbour_timeout: 0.1,
            safe_damping: 1.0,
            angle_margin_deg: 5.0,
        }
    }
}

/// `[gains]`: default gains of every controlled angle (each angle may override them).
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct GainsSpec {
    /// `c_α`.
    pub stiffness: Option<f64>,
    /// `d_α`.
    pub damping: Option<f64>,
    /// `c_e`.
    pub estimator_gain: Option<f64>,
}

/// `[agent_defaults]`: values used by agents that do not give their own.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct AgentDefaults {
    /// Mass (kg).
    pub mass: f64,
    /// `D^r` (friction).
    pub friction: Diagonal,
    /// `D^v` (velocity-tracking damping of S12).
    pub velocity_damping: Diagonal,
}

impl Default for AgentDefaults {
    fn default() -> Self {
        Self {
            mass: 1.0,
            friction: Diagonal::Scalar(0.0),
            velocity_damping: Diagonal::Scalar(0.0),
        }
    }
}

/// One `[[agents]]` entry.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct AgentSpec {
    /// Identifier, 0–255, unique.
    pub id: i64,
    /// `q(0)` (m).
    pub position: [f64; 2],
    /// `v(0)` (m/s), default zero.
    #[serde(default)]
    pub velocity: Option<[f64; 2]>,
    /// Mass (kg), default from `[agent_defaults]`.
    #[serde(default)]
    pub mass: Option<f64>,
    /// `D^r`, default from `[agent_defaults]`.
    #[serde(default)]
    pub friction: Option<Diagonal>,
    /// `D^v`, default from `[agent_defaults]`.
    #[serde(default)]
    pub velocity_damping: Option<Diagonal>,
}

/// One controlled angle of a triangle.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct AngleSpec {
    /// The apex agent id.
    pub apex: i64,
    /// Desired angle in degrees (give this or `desired_rad`).
    #[serde(default)]
    pub desired_deg: Option<f64>,
    /// Desired angle in radians (give this or `desired_deg`).
    #[serde(default)]
    pub desired_rad: Option<f64>,
    /// `c_α`, default `[gains].stiffness`.
    #[serde(default)]
    pub stiffness: Option<f64>,
    /// `d_α`, default `[gains].damping`.
    #[serde(default)]
    pub damping: Option<f64>,
    /// `c_e`, default `[gains].estimator_gain`.
    #[serde(default)]
    pub estimator_gain: Option<f64>,
}

/// One `[[triangles]]` entry.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TriangleSpec {
    /// The three vertex ids.
    pub vertices: [i64; 3],
    /// Exactly two controlled angles with distinct apexes.
    pub angles: Vec<AngleSpec>,
}

/// `[leader]`: the leader edge maneuver (S11).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LeaderSpec {
    /// `[a, b]` with `z = q_a − q_b`.
    pub agents: [i64; 2],
    /// `k_z`.
    pub stiffness: f64,
    /// `D_z`.
    pub damping: Diagonal,
    /// `z*(t)`.
    pub displacement: ScheduleSpec,
}

/// `[sensors]`: what each agent's own sensors get wrong.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct SensorSpec {
    /// Standard deviation of the bearing angle noise (degrees).
    pub bearing_noise_deg: f64,
    /// Constant rotation added to every bearing (degrees).
    pub bearing_bias_deg: f64,
    /// Bearing rates: `finite_difference` or `exact`.
    pub bearing_rate: BearingRate,
    /// Standard deviation of each velocity component's noise (m/s).
    pub velocity_noise: f64,
    /// Constant velocity bias `[x, y]` (m/s).
    pub velocity_bias: [f64; 2],
    /// Standard deviation of each component of the leaders' relative-position noise (m).
    pub offset_noise: f64,
    /// Standard deviation of the range noise (m), `measured` estimator only.
    pub range_noise: f64,
}

impl Default for SensorSpec {
    fn default() -> Self {
        Self {
            bearing_noise_deg: 0.0,
            bearing_bias_deg: 0.0,
            bearing_rate: BearingRate::FiniteDifference,
            velocity_noise: 0.0,
            velocity_bias: [0.0, 0.0],
            offset_noise: 0.0,
            range_noise: 0.0,
        }
    }
}

/// `[radio]`: the link model between neighbours.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct RadioSpec {
    /// Fixed delivery latency (s).
    pub latency: f64,
    /// Extra delay, uniform in `[0, jitter]` (s).
    pub jitter: f64,
    /// Probability that one link copy of a frame is lost.
    pub loss: f64,
    /// Probability that a link copy is delivered twice.
    pub duplication: f64,
    /// Probability that a link copy is held back by an extra delay (reordering).
    pub reordering: f64,
    /// Largest extra delay of a reordered copy (s); default two control periods.
    pub reorder_delay: Option<f64>,
    /// Probability that a link copy has one random bit flipped.
    pub corruption: f64,
    /// Sender air-time limit in bytes per second (0 = unlimited).
    pub bandwidth: f64,
    /// Longest wait in a sender's transmit queue before a frame is dropped (s).
    pub queue_limit: f64,
}

impl Default for RadioSpec {
    fn default() -> Self {
        Self {
            latency: 0.0,
            jitter: 0.0,
            loss: 0.0,
            duplication: 0.0,
            reordering: 0.0,
            reorder_delay: None,
            corruption: 0.0,
            bandwidth: 0.0,
            queue_limit: 0.05,
        }
    }
}

/// `[criteria]`: failure detection and convergence tolerances.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct CriteriaSpec {
    /// Two agents closer than this (m) have collided.
    pub collision_distance: f64,
    /// An estimate held at `r_min` for this long (s) has collapsed.
    pub collapse_time: f64,
    /// Any speed above this (m/s), or a non-finite state, is divergence.
    pub divergence_speed: f64,
    /// `V` above this multiple of `max(V(0), 1)` is divergence.
    pub divergence_energy_factor: f64,
    /// Every angle error below this (rad) counts as settled.
    pub angle_tolerance: f64,
    /// Final `|z − z*|` below this (m) counts as converged.
    pub displacement_tolerance: f64,
    /// Final `max_n |v_n − v*|` below this (m/s) counts as converged.
    pub velocity_tolerance: f64,
}

impl Default for CriteriaSpec {
    fn default() -> Self {
        Self {
            collision_distance: 0.05,
            collapse_time: 0.25,
            divergence_speed: 1e3,
            divergence_energy_factor: 1e3,
            angle_tolerance: 1e-3,
            displacement_tolerance: 1e-2,
            velocity_tolerance: 1e-2,
        }
    }
}

/// A whole scenario file (schema in `docs/scenarios.md`).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ScenarioFile {
    /// Name (output directory and `summary.json`); default: the file stem.
    #[serde(default)]
    pub name: Option<String>,
    /// Free text.
    #[serde(default)]
    pub description: Option<String>,
    /// Simulated time (s).
    #[serde(default = "default_duration")]
    pub duration: f64,
    /// Seed of every random number (noise, radio).
    #[serde(default)]
    pub seed: u64,
    /// `sampled` or `continuous`.
    #[serde(default)]
    pub mode: Mode,
    /// `[integration]`.
    #[serde(default)]
    pub integration: Integration,
    /// `[controller]`.
    #[serde(default)]
    pub controller: ControllerSpec,
    /// `[gains]`.
    #[serde(default)]
    pub gains: GainsSpec,
    /// `[agent_defaults]`.
    #[serde(default)]
    pub agent_defaults: AgentDefaults,
    /// `[[agents]]`.
    pub agents: Vec<AgentSpec>,
    /// `[[triangles]]`.
    #[serde(default)]
    pub triangles: Vec<TriangleSpec>,
    /// `[leader]` (optional).
    #[serde(default)]
    pub leader: Option<LeaderSpec>,
    /// `v*(t)`, default zero.
    #[serde(default)]
    pub velocity_reference: ScheduleSpec,
    /// `[sensors]`.
    #[serde(default)]
    pub sensors: SensorSpec,
    /// `[radio]`.
    #[serde(default)]
    pub radio: RadioSpec,
    /// `[criteria]`.
    #[serde(default)]
    pub criteria: CriteriaSpec,
}

fn default_duration() -> f64 {
    100.0
}

/// A scenario's TOML text and where it came from.
#[derive(Clone, Debug)]
pub struct Source {
    /// A file path, or `builtin:<name>`.
    pub label: String,
    /// Default name (file stem or builtin name).
    pub default_name: String,
    /// The TOML text.
    pub text: String,
}

impl Source {
    /// Resolves `arg`: an existing file, else a built-in name.
    pub fn resolve(arg: &str) -> Result<Self, ScenarioError> {
        let path = Path::new(arg);
        if path.is_file() {
            return Self::from_file(path);
        }
        if let Some(b) = builtin(arg) {
            return Ok(Self::from_builtin(b));
        }
        let names: Vec<&str> = BUILTINS.iter().map(|b| b.name).collect();
        Err(ScenarioError::new(
            ErrorKind::Io,
            arg,
            "",
            format!(
                "no such file, and not a built-in scenario (built-ins: {})",
                names.join(", ")
            ),
        ))
    }

    /// Reads a scenario file.
    pub fn from_file(path: &Path) -> Result<Self, ScenarioError> {
        let label = path.display().to_string();
        let text = std::fs::read_to_string(path).map_err(|e| {
            ScenarioError::new(ErrorKind::Io, &label, "", format!("cannot read: {e}"))
        })?;
        let default_name = path
            .file_stem()
            .map(|s| s.to_string_lossy().into_owned())
            .unwrap_or_else(|| "scenario".to_owned());
        Ok(Self {
            label,
            default_name,
            text,
        })
    }

    /// A built-in scenario.
    pub fn from_builtin(b: &Builtin) -> Self {
        Self {
            label: format!("builtin:{}", b.name),
            default_name: b.name.to_owned(),
            text: b.text.to_owned(),
        }
    }

    /// Parses the text, applies `overrides` (`key=value`, dotted keys, array indices as
    /// numbers: `agents.0.mass=2`) and deserializes the schema.
    pub fn parse(&self, overrides: &[String]) -> Result<ScenarioFile, ScenarioError> {
        // Deserialize the file itself first: errors carry its line and column.
        let file: ScenarioFile = toml::from_str(&self.text).map_err(|e| self.toml_error(&e))?;
        if overrides.is_empty() {
            return Ok(file);
        }
        let mut value: toml::Value = toml::from_str(&self.text).map_err(|e| self.toml_error(&e))?;
        let mut parsed = file;
        for ov in overrides {
            let (key, raw) = ov.split_once('=').ok_or_else(|| {
                ScenarioError::new(
                    ErrorKind::Syntax,
                    &self.label,
                    ov,
                    "--set expects key=value (e.g. radio.loss=0.2)",
                )
            })?;
            let key = key.trim();
            let parsed_value = parse_override_value(raw.trim());
            set_path(&mut value, key, parsed_value).map_err(|reason| {
                ScenarioError::new(
                    ErrorKind::Syntax,
                    &self.label,
                    key,
                    format!("--set: {reason}"),
                )
            })?;
            parsed = value.clone().try_into().map_err(|e: toml::de::Error| {
                ScenarioError::new(
                    ErrorKind::Syntax,
                    &self.label,
                    key,
                    format!("--set {ov}: {}", one_line(&e.to_string())),
                )
            })?;
        }
        Ok(parsed)
    }

    fn toml_error(&self, e: &toml::de::Error) -> ScenarioError {
        let (field, location) = match e.span() {
            Some(span) => {
                let (line, col) = line_col(&self.text, span.start);
                (
                    field_at(&self.text, span.start),
                    format!(" (line {line}, column {col})"),
                )
            }
            None => (String::new(), String::new()),
        };
        ScenarioError::new(
            ErrorKind::Syntax,
            &self.label,
            &field,
            format!("{}{location}", one_line(e.message())),
        )
    }
}

fn one_line(s: &str) -> String {
    s.trim().replace('\n', " ")
}

/// Parses an override value as TOML (`0.2`, `"exact"`, `[1, 2]`, `true`), falling back to
/// a bare string (`exact`).
fn parse_override_value(raw: &str) -> toml::Value {
    let doc = format!("v = {raw}");
    match toml::from_str::<toml::Table>(&doc) {
        Ok(mut t) => t.remove("v").unwrap_or(toml::Value::String(raw.to_owned())),
        Err(_) => toml::Value::String(raw.to_owned()),
    }
}

fn set_path(root: &mut toml::Value, key: &str, value: toml::Value) -> Result<(), String> {
    let parts: Vec<&str> = key.split('.').collect();
    if parts.iter().any(|p| p.is_empty()) {
        return Err(format!("bad key `{key}`"));
    }
    let mut cur = root;
    for (i, part) in parts.iter().enumerate() {
        let last = i + 1 == parts.len();
        cur = match cur {
            toml::Value::Table(t) => {
                if last {
                    t.insert((*part).to_owned(), value);
                    return Ok(());
                }
                t.entry((*part).to_owned())
                    .or_insert_with(|| toml::Value::Table(toml::Table::new()))
            }
            toml::Value::Array(a) => {
                let idx: usize = part
                    .parse()
                    .map_err(|_| format!("`{part}` in `{key}` must be an array index"))?;
                let len = a.len();
                let slot = a.get_mut(idx).ok_or_else(|| {
                    format!("index {idx} in `{key}` is out of range (length {len})")
                })?;
                if last {
                    *slot = value;
                    return Ok(());
                }
                slot
            }
            _ => {
                return Err(format!(
                    "`{part}` in `{key}` is inside a value that is not a table"
                ))
            }
        };
    }
    Ok(())
}

/// 1-based line and column of byte offset `pos`.
fn line_col(text: &str, pos: usize) -> (usize, usize) {
    let before = text.get(..pos).unwrap_or(text);
    let line = before.matches('\n').count() + 1;
    let col = before.rsplit('\n').next().map_or(0, |l| l.chars().count()) + 1;
    (line, col)
}

/// Best guess of the dotted key at byte offset `pos`: the last table header before it
/// (with its index for an array of tables, `agents[2]`) and the key on its line.
fn field_at(text: &str, pos: usize) -> String {
    let before = text.get(..pos).unwrap_or(text);
    let line_start = before.rfind('\n').map_or(0, |i| i + 1);
    let line_end = text
        .get(pos..)
        .and_then(|r| r.find('\n'))
        .map_or(text.len(), |i| pos + i);
    let line = text.get(line_start..line_end).unwrap_or("").trim();
    // `[name]` → ("name", false); `[[name]]` → ("name", true).
    let header_of = |l: &str| -> Option<(String, bool)> {
        let l = l.trim();
        let array = l.starts_with("[[");
        let inner = l.strip_prefix('[')?.trim_start_matches('[');
        let end = inner.find(']')?;
        Some((inner.get(..end)?.trim().to_owned(), array))
    };
    let head = text.get(..line_end).unwrap_or("");
    let named = |name: &str, array: bool| -> String {
        if !array {
            return name.to_owned();
        }
        let count = head
            .lines()
            .filter(|l| header_of(l).is_some_and(|(n, a)| a && n == name))
            .count();
        format!("{name}[{}]", count.saturating_sub(1))
    };
    if let Some((h, array)) = header_of(line) {
        return named(&h, array);
    }
    let section = text
        .get(..line_start)
        .unwrap_or("")
        .lines()
        .rev()
        .find_map(header_of)
        .map(|(h, array)| named(&h, array))
        .unwrap_or_default();
    let key = line
        .split_once('=')
        .map(|(k, _)| k.trim().to_owned())
        .unwrap_or_default();
    match (section.is_empty(), key.is_empty()) {
        (true, _) => key,
        (false, true) => section,
        (false, false) => format!("{section}.{key}"),
    }
}
