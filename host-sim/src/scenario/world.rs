//! The robot's world in a scenario file (`docs/world.md`): `world = "<preset>"` and the
//! tables `[plant]`, `[wind]`, `[heading]` and `[clock]`. A preset is TOML merged under
//! the file (after `--set`): every key the file gives wins, every key it leaves out comes
//! from the preset.

use serde::{Deserialize, Serialize};

/// `[plant]`: the vehicle every agent is.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct PlantSpec {
    /// `point_mass` (SPEC S1, the default) or `velocity_tracking`.
    pub model: PlantKind,
    /// `velocity_tracking`: the velocity loop's time constant (s).
    pub time_constant_s: f64,
    /// `velocity_tracking`: the largest tilt (degrees); the largest acceleration is
    /// `g tan(max_tilt_deg)`.
    pub max_tilt_deg: f64,
    /// `velocity_tracking`: the largest velocity setpoint (m/s).
    pub max_speed: f64,
    /// `velocity_tracking`: the lead of the agents' setpoints (s, SPEC S21); default
    /// `time_constant_s` (the agents know their vehicle's loop).
    pub lead_s: Option<f64>,
}

impl Default for PlantSpec {
    fn default() -> Self {
        Self {
            model: PlantKind::PointMass,
            time_constant_s: 0.2,
            max_tilt_deg: 20.0,
            max_speed: 1.0,
            lead_s: None,
        }
    }
}

/// `plant.model`.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum PlantKind {
    /// SPEC S1.
    #[default]
    PointMass,
    /// A vehicle tracking velocity setpoints.
    VelocityTracking,
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
            "plant.time_constant_s: the velocity loop's time constant is not published",
            "wind: indoor drafts and neighbours' downwash, not measured",
            "heading: spread, estimate error, drift and noise of a Crazyflie without an \
             absolute heading source are not published",
            "clock.jitter_s: the app task's tick jitter is not published",
            "sensors.camera: no bearing camera ships with the Crazyflie; field of view, \
             range, detection, outliers and latency are assumed",
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
    for (k, v) in under {
        match (over.get_mut(k), v) {
            (Some(toml::Value::Table(o)), toml::Value::Table(u)) => merge_under(o, u),
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
                    Some("velocity_tracking"),
                    "{file:?}"
                );
            }
        }
    }
}
