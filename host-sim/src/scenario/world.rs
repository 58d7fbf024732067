//! The robot's world in a scenario file (`docs/world.md`): `world = "<preset>"` and the
//! tables `[plant]`, `[wind]`, `[heading]` and `[clock]`. A preset is TOML merged under
//! the file (after `--set`): every key the file gives wins, every key it leaves out comes
//! from the preset.

use serde::{Deserialize, Serialize};

/// `[plant]` as the file writes it: a table whose `model` picks the vehicle (default
/// `point_mass`). [`plant_spec`] resolves it into a [`PlantSpec`], refusing every key that
/// is not the model's.
pub type PlantTable = toml::Table;

/// `[plant]`: the vehicle every agent is, one variant per `model` with its own keys.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(tag = "model", rename_all = "snake_case", deny_unknown_fields)]
pub enum PlantSpec {
    /// SPEC S1 (the default): no keys.
    PointMass {},
    /// A vehicle tracking velocity setpoints through a first-order lag.
    VelocityTracking {
        /// The velocity loop's time constant (s).
        #[serde(default = "default_time_constant")]
        time_constant_s: f64,
        /// The largest tilt (degrees); the largest acceleration is `g tan(max_tilt_deg)`.
        #[serde(default = "default_tilt")]
        max_tilt_deg: f64,
        /// The largest velocity setpoint (m/s).
        #[serde(default = "default_speed")]
        max_speed: f64,
        /// The lead of the agents' setpoints (s, SPEC S21); default `time_constant_s`.
        #[serde(default)]
        lead_s: Option<f64>,
        /// The gap bound between the virtual and the measured velocity (m/s, SPEC S21c);
        /// default none (`inf`).
        #[serde(default)]
        max_gap: Option<f64>,
    },
    /// A Crazyflie 2.x flying its firmware's PID cascade in velocity mode (the gains are
    /// the firmware's, `docs/world.md`).
    CrazyfliePid {
        /// The largest velocity setpoint the agent sends (m/s; the app's
        /// `FORMATION_MAX_SPEED`).
        #[serde(default = "default_speed")]
        max_speed: f64,
        /// The lead of the agents' setpoints (s, SPEC S21); default the cascade's
        /// derived lead `1 / (g K_p)` (0.234 s).
        #[serde(default)]
        lead_s: Option<f64>,
        /// The second-order lead (s², SPEC S21b); default the cascade's derived
        /// `τ / K_p^a` (0.039 s²).
        #[serde(default)]
        second_lead_s2: Option<f64>,
        /// The time constant of the filter on the second-order lead's jerk (s, SPEC
        /// S21d); default 0.03 s (docs/world.md).
        #[serde(default)]
        jerk_filter_s: Option<f64>,
        /// The gap bound between the virtual and the measured velocity (m/s, SPEC S21c;
        /// `inf` for none); default the app's 0.5 m/s.
        #[serde(default)]
        max_gap: Option<f64>,
    },
}

fn default_time_constant() -> f64 {
    0.2
}
fn default_tilt() -> f64 {
    20.0
}
fn default_speed() -> f64 {
    1.0
}

/// The models `plant.model` may name.
pub const PLANT_MODELS: &[&str] = &["point_mass", "velocity_tracking", "crazyflie_pid"];

/// `[plant]` resolved: the model's variant, or why not (a key that is not the model's,
/// an unknown model, a value of the wrong type), naming the key.
pub fn plant_spec(table: &PlantTable) -> Result<PlantSpec, (String, String)> {
    let mut t = table.clone();
    let model = match t.get("model") {
        None => "point_mass".to_owned(),
        Some(toml::Value::String(m)) => m.clone(),
        Some(other) => {
            return Err((
                "plant.model".into(),
                format!(
                    "must be a string, one of {}; got {other}",
                    PLANT_MODELS.join(", ")
                ),
            ))
        }
    };
    if !PLANT_MODELS.contains(&model.as_str()) {
        return Err((
            "plant.model".into(),
            format!(
                "unknown model `{model}`; the models are {}",
                PLANT_MODELS.join(", ")
            ),
        ));
    }
    t.insert("model".into(), toml::Value::String(model.clone()));
    toml::Value::Table(t).try_into().map_err(|e: toml::de::Error| {
        let msg = e.message().trim().to_owned();
        let key = msg
            .split('`')
            .nth(1)
            .filter(|_| msg.starts_with("unknown field"))
            .map(|k| format!("plant.{k}"))
            .unwrap_or_else(|| "plant".to_owned());
        (
            key,
            format!("{msg} (for model = \"{model}\"; each model takes only its own keys, docs/world.md)"),
        )
    })
}

/// `[wind]`: a constant part plus first-order gusts, as an acceleration on every agent.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct WindSpec {
    /// The constant part `[x, y]` (m/s²).
    pub mean: [f64; 2],
    /// The gusts' standard deviation per axis (m/s²).
    pub gust: f64,
    /// The gusts' correlation time (s).
    pub gust_time_constant_s: f64,
}

impl Default for WindSpec {
    fn default() -> Self {
        Self {
            mean: [0.0; 2],
            gust: 0.0,
            gust_time_constant_s: 1.0,
        }
    }
}

/// `[heading]`: body frames and each agent's heading estimate.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct HeadingSpec {
    /// The true heading of every agent (degrees).
    pub initial_deg: f64,
    /// Each agent's true heading is spread uniformly by up to ± this (degrees).
    pub spread_deg: f64,
    /// Standard deviation of each agent's initial heading-estimate error (degrees).
    pub error_deg: f64,
    /// Standard deviation of each agent's drift rate of that error (degrees/s).
    pub drift_deg_per_s: f64,
    /// Standard deviation of the estimate's white noise at each tick (degrees).
    pub noise_deg: f64,
}

/// `[clock]`: each agent's own clock.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct ClockSpec {
    /// Each agent's phase is drawn uniformly in `[0, offset_s)` (s).
    pub offset_s: f64,
    /// Each agent's rate error is drawn uniformly in ± this (parts per million).
    pub ppm: f64,
    /// Standard deviation of each tick's instant (s).
    pub jitter_s: f64,
}

/// A world preset: its name, its TOML, and which of its values are assumptions.
pub struct Preset {
    /// `world = "<name>"`.
    pub name: &'static str,
    /// Merged under the scenario file.
    pub toml: &'static str,
    /// `key: why it is an assumption` for every value no published figure gives.
    pub assumptions: &'static [&'static str],
}

/// The presets (`docs/world.md` gives each value's source).
pub const PRESETS: &[Preset] = &[
    Preset {
        name: "ideal",
        toml: "",
        assumptions: &[],
    },
    Preset {
        name: "crazyflie",
        toml: include_str!("../../worlds/crazyflie.toml"),
        assumptions: &[
            "plant: the rate loop is taken as ideal, the altitude as held and the estimator \
             as exact",
            "wind: indoor drafts and neighbours' downwash, not measured",
            "clock.jitter_s: the app task's tick jitter is not published",
            "sensors.positions.noise_m: Lighthouse precision rounded up to 1 mm; its \
             slowly varying accuracy error is not modelled",
            "sensors.velocity_noise: assumed estimator quality",
        ],
    },
    Preset {
        name: "crazyflie-camera",
        toml: include_str!("../../worlds/crazyflie-camera.toml"),
        assumptions: &[
            "plant: the rate loop is taken as ideal, the altitude as held and the estimator \
             as exact",
            "wind: indoor drafts and neighbours' downwash, not measured",
            "heading: spread, estimate error, drift and noise of a gyro-integrated yaw are \
             not published",
            "clock.jitter_s: the app task's tick jitter is not published",
            "sensors.camera: range, detection, outliers and latency of a detector on the \
             AI-deck are assumed",
            "sensors.bearing_noise_deg, sensors.velocity_noise: assumed sensor quality",
        ],
    },
];

/// The preset named `name`.
pub fn preset(name: &str) -> Option<&'static Preset> {
    PRESETS.iter().find(|p| p.name == name)
}

/// Merges `under` into `over`: every key of `under` missing from `over` is added, tables
/// merged recursively (what `over` gives wins).
pub(super) fn merge_under(over: &mut toml::Table, under: &toml::Table) {
    // A `[plant]` naming another model than the preset's takes none of the preset's
    // plant keys (they would be foreign to it).
    let model = |t: &toml::Table| {
        t.get("plant")
            .and_then(|p| p.get("model"))
            .and_then(|m| m.as_str())
            .map(str::to_owned)
    };
    if let (Some(mine), Some(theirs)) = (model(over), model(under)) {
        if mine != theirs {
            let mut under = under.clone();
            under.remove("plant");
            return merge_tables(over, &under);
        }
    }
    merge_tables(over, under);
}

fn merge_tables(over: &mut toml::Table, under: &toml::Table) {
    for (k, v) in under {
        match (over.get_mut(k), v) {
            (Some(toml::Value::Table(o)), toml::Value::Table(u)) => merge_tables(o, u),
            (Some(_), _) => {}
            (None, v) => {
                over.insert(k.clone(), v.clone());
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every preset parses, and the file's keys win over the preset's.
    #[test]
    fn presets_parse_and_merge_under_the_file() {
        for p in PRESETS {
            let t: toml::Table = toml::from_str(p.toml).unwrap();
            let mut file: toml::Table = toml::from_str("[plant]\nmax_speed = 0.5\n").unwrap();
            merge_under(&mut file, &t);
            if p.name == "crazyflie" {
                assert_eq!(file["plant"]["max_speed"].as_float(), Some(0.5));
                assert_eq!(
                    file["plant"]["model"].as_str(),
                    Some("crazyflie_pid"),
                    "{file:?}"
                );
            }
        }
    }
}

#[cfg(test)]
mod plant_tests {
    use super::*;

    fn spec(text: &str) -> Result<PlantSpec, (String, String)> {
        plant_spec(&toml::from_str(text).unwrap())
    }

    /// No `[plant]` is the point mass; each model takes its own keys with their defaults.
    #[test]
    fn each_model_resolves() {
        assert_eq!(spec(""), Ok(PlantSpec::PointMass {}));
        assert_eq!(
            spec("model = \"crazyflie_pid\""),
            Ok(PlantSpec::CrazyfliePid {
                max_speed: 1.0,
                lead_s: None,
                second_lead_s2: None,
                jerk_filter_s: None,
                max_gap: None,
            })
        );
        assert!(matches!(
            spec("model = \"velocity_tracking\"\ntime_constant_s = 0.3"),
            Ok(PlantSpec::VelocityTracking { time_constant_s, .. }) if time_constant_s == 0.3
        ));
    }

    /// A key of another model is refused, naming the key and the model.
    #[test]
    fn foreign_keys_are_refused() {
        let (key, why) = spec("time_constant_s = 0.3").unwrap_err();
        assert_eq!(key, "plant.time_constant_s");
        assert!(why.contains("point_mass"), "{why}");
        let (key, _) = spec("model = \"crazyflie_pid\"\nmax_tilt_deg = 30.0").unwrap_err();
        assert_eq!(key, "plant.max_tilt_deg");
        let (key, why) = spec("model = \"velocity_tracking\"\nsecond_lead_s2 = 0.1").unwrap_err();
        assert_eq!(key, "plant.second_lead_s2");
        assert!(why.contains("velocity_tracking"), "{why}");
        let (key, why) = spec("model = \"quadrotor\"").unwrap_err();
        assert_eq!(key, "plant.model");
        assert!(why.contains("crazyflie_pid"), "{why}");
        // Negative control: the model's own key passes.
        assert!(spec("model = \"crazyflie_pid\"\nmax_speed = 0.5").is_ok());
    }
}
