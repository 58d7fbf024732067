//! The run-wide sections of a scenario file: `[integration]`, `[controller]`,
//! `[sensors]` and `[radio]`, with their defaults (`docs/scenarios.md`).

use crate::model::{Access, BearingRate, Estimator, IntegrityMode};
use serde::{Deserialize, Serialize};

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
    /// A missing bearing is held or predicted for up to this long (s; SPEC §12, S18);
    /// 0: none.
    pub bearing_hold_s: f64,
    /// Safe output gain: `U = −safe_damping · v`.
    pub safe_damping: f64,
    /// Margin (degrees) that desired and current angles must keep from 0 and 180°.
    pub angle_margin_deg: f64,
    /// Broadcast rate (Hz): `≤ rate_hz`, and `rate_hz` a whole multiple of it, or
    /// `"auto"` (the highest such rate the shared channel carries, docs/radio.md);
    /// default `rate_hz` (broadcast every tick).
    pub comm_rate_hz: Option<CommRate>,
    /// Frame integrity of the swarm: `crc16`, `link` or `auth`.
    pub integrity: IntegrityMode,
    /// `auth`: the 128-bit swarm key as 32 hexadecimal digits.
    pub auth_key: Option<String>,
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
            bearing_hold_s: 0.0,
            safe_damping: 1.0,
            angle_margin_deg: 5.0,
            comm_rate_hz: None,
            integrity: IntegrityMode::Crc16,
            auth_key: None,
        }
    }
}

/// `controller.comm_rate_hz`: a rate in Hz, or `"auto"`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum CommRate {
    /// Broadcast at this rate (Hz).
    Hz(f64),
    /// The highest rate `rate_hz / k` whose offered load the shared channel carries
    /// (`engine::load::resolve_auto`, docs/radio.md "comm_rate_hz = auto").
    Auto,
}

impl Serialize for CommRate {
    fn serialize<S: serde::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        match self {
            Self::Hz(hz) => s.serialize_f64(*hz),
            Self::Auto => s.serialize_str("auto"),
        }
    }
}

impl<'de> Deserialize<'de> for CommRate {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        struct Visit;
        impl serde::de::Visitor<'_> for Visit {
            type Value = CommRate;
            fn expecting(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
                f.write_str("a rate in Hz or \"auto\"")
            }
            fn visit_f64<E: serde::de::Error>(self, v: f64) -> Result<CommRate, E> {
                Ok(CommRate::Hz(v))
            }
            fn visit_i64<E: serde::de::Error>(self, v: i64) -> Result<CommRate, E> {
                Ok(CommRate::Hz(v as f64))
            }
            fn visit_u64<E: serde::de::Error>(self, v: u64) -> Result<CommRate, E> {
                Ok(CommRate::Hz(v as f64))
            }
            fn visit_str<E: serde::de::Error>(self, v: &str) -> Result<CommRate, E> {
                match v {
                    "auto" => Ok(CommRate::Auto),
                    _ => Err(E::custom(format!(
                        "expected a rate in Hz or \"auto\", got \"{v}\""
                    ))),
                }
            }
        }
        d.deserialize_any(Visit)
    }
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
    /// How each controller filters its bearings (SPEC §11): `auto`, `tracker` or `none`.
    pub bearing_filter: FilterChoice,
    /// `[sensors.tracker]`: the tracker's settings.
    pub tracker: TrackerSpec,
    /// Standard deviation of each velocity component's noise (m/s).
    pub velocity_noise: f64,
    /// Constant velocity bias `[x, y]` (m/s).
    pub velocity_bias: [f64; 2],
    /// Standard deviation of each component of the leaders' relative-position noise (m).
    pub offset_noise: f64,
    /// Standard deviation of the range noise (m), `measured` estimator only.
    pub range_noise: f64,
    /// `[sensors.camera]`: the camera every agent sees its neighbours through (optional;
    /// absent: every neighbour's bearing is seen, at once).
    pub camera: Option<CameraSpec>,
    /// Where the bearings come from: `onboard` (the agents' own bearing sensor, ideal or
    /// `[sensors.camera]`) or `shared_positions` (from positions broadcast over the radio,
    /// `[sensors.positions]`).
    #[serde(skip_serializing_if = "BearingSource::is_onboard")]
    pub bearing_source: BearingSource,
    /// `[sensors.positions]`: the positioning system and its packets
    /// (`bearing_source = "shared_positions"` only).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub positions: Option<PositionsSpec>,
}

/// `sensors.bearing_source`: where every agent's bearings come from.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum BearingSource {
    /// The agents' own bearing sensor: the omnidirectional ideal one, or the camera.
    #[default]
    Onboard,
    /// Bearings computed from the agents' positions, each broadcast in a packet of its
    /// own over the radio (a positioning-system flight, docs/crazyflie.md).
    SharedPositions,
}

impl BearingSource {
    /// Whether this is the default, [`BearingSource::Onboard`].
    pub fn is_onboard(&self) -> bool {
        *self == Self::Onboard
    }
}

/// `[sensors.positions]`: each agent's position estimate and its packets (docs/sensors.md).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct PositionsSpec {
    /// Standard deviation of the white position noise per axis (m).
    pub noise_m: f64,
    /// A neighbour's position heard longer ago than this (s) gives no bearing.
    pub max_age_s: f64,
    /// Removed: the packet is the core's position packet, its length set by the
    /// integrity mode. Accepted only to say so (validation refuses it).
    pub packet_bytes: Option<usize>,
}

impl Default for PositionsSpec {
    fn default() -> Self {
        Self {
            noise_m: 0.0,
            max_age_s: 0.1,
            packet_bytes: None,
        }
    }
}

/// `[sensors.camera]`: every agent's camera (docs/sensors.md). Each field defaults to the
/// ideal camera's value.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct CameraSpec {
    /// Field of view (degrees), centred on the agent's heading; 360 sees all round.
    pub fov_deg: f64,
    /// Largest distance at which a neighbour is seen (m); default: no limit.
    pub range_m: Option<f64>,
    /// Radius of each agent's body as the others see it (m); 0: nothing hides anything.
    pub occlusion_radius_m: f64,
    /// Probability that a visible neighbour is detected at a tick.
    pub detection_probability: f64,
    /// Probability that a detected bearing is replaced by a uniformly random direction.
    pub outlier_probability: f64,
    /// Age of the image (s): a bearing describes the geometry this long ago.
    pub latency_s: f64,
}

impl Default for CameraSpec {
    fn default() -> Self {
        Self {
            fov_deg: 360.0,
            range_m: None,
            occlusion_radius_m: 0.0,
            detection_probability: 1.0,
            outlier_probability: 0.0,
            latency_s: 0.0,
        }
    }
}

impl Default for SensorSpec {
    fn default() -> Self {
        Self {
            bearing_noise_deg: 0.0,
            bearing_bias_deg: 0.0,
            bearing_rate: BearingRate::FiniteDifference,
            bearing_filter: FilterChoice::Auto,
            tracker: TrackerSpec::default(),
            velocity_noise: 0.0,
            velocity_bias: [0.0, 0.0],
            offset_noise: 0.0,
            range_noise: 0.0,
            camera: None,
            bearing_source: BearingSource::Onboard,
            positions: None,
        }
    }
}

/// `sensors.bearing_filter`: how the controllers turn bearings into bearings and rates.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum FilterChoice {
    /// The tracker when the bearings are noisy (`bearing_noise_deg > 0`), the finite
    /// difference for an ideal bearing sensor.
    #[default]
    Auto,
    /// The bearing tracker of SPEC §11.
    Tracker,
    /// Today's finite difference of successive bearings (SPEC §2).
    None,
}

/// `[sensors.tracker]`: the bearing tracker's settings (SPEC §11, S15–S17).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct TrackerSpec {
    /// `σ_b` the tracker assumes (degrees); default: `sensors.bearing_noise_deg`, at least
    /// 0.1°.
    pub bearing_noise_deg: Option<f64>,
    /// `σ_ω`: bearing rate the kinematic model cannot explain (rad/√s).
    pub rate_noise: f64,
    /// `σ_ρ`: random walk of the inverse distance (1/(m √s)).
    pub inverse_range_noise: f64,
    /// Innovation gate in standard deviations.
    pub gate: f64,
}

impl Default for TrackerSpec {
    fn default() -> Self {
        let c = ph_formation_core::TrackerConfig::<f64>::default();
        Self {
            bearing_noise_deg: None,
            rate_noise: c.rate_noise,
            inverse_range_noise: c.inverse_range_noise,
            gate: c.gate,
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
    /// Sender air-time limit in bits per second (0 = unlimited). Key `bandwidth_bps`; the
    /// old `bandwidth` (bytes/s) is refused with a message naming this one.
    pub bandwidth_bps: f64,
    /// Longest wait in a sender's transmit queue before a frame is dropped (s).
    pub queue_limit: f64,
    /// `[radio.channel]`: one shared medium (optional; `docs/radio.md`).
    pub channel: Option<ChannelSpec>,
}

/// `[radio.channel]`: a shared medium. A `preset` fills the radio's figures; fields
/// given here override it.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct ChannelSpec {
    /// `crazyflie` (2 Mbit/s nRF24-class Enhanced ShockBurst), or none.
    pub preset: Option<String>,
    /// `aloha` or `tdma`.
    pub access: Access,
    /// Bit rate on the air (bits per second); required without a preset. Key
    /// `bit_rate_bps`; the old `bit_rate` is refused with a message naming this one.
    pub bit_rate_bps: Option<f64>,
    /// Per-frame overhead on the air besides the payload (bytes, may be fractional).
    pub overhead_bytes: Option<f64>,
    /// Transmitter settling time before each frame (s).
    pub turnaround: Option<f64>,
    /// Radio range (m); default: everyone hears everyone.
    pub range: Option<f64>,
    /// ALOHA: each broadcast starts at a uniform random instant this long after its
    /// tick (s); default one control period.
    pub aloha_window: Option<f64>,
    /// TDMA: slot length (s); default the turnaround plus the air time of a
    /// largest frame.
    pub slot: Option<f64>,
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
            bandwidth_bps: 0.0,
            queue_limit: 0.05,
            channel: None,
        }
    }
}

/// `[[attacks]]`: one adversary on the radio (`docs/attacks.md`).
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct AttackSpec {
    /// `replay`, `forge` or `flood`.
    pub kind: String,
    /// Active from (s; default 0).
    #[serde(default)]
    pub start: f64,
    /// Active until (s; default: the end of the run).
    #[serde(default)]
    pub end: Option<f64>,
    /// Where the attacker is (m); default: within reach of every agent.
    #[serde(default)]
    pub position: Option<[f64; 2]>,
    /// `replay`: age of the replayed frames (s; default 1).
    #[serde(default)]
    pub delay: Option<f64>,
    /// `forge`: the id of the agent whose frames are forged.
    #[serde(default)]
    pub victim: Option<super::schema::AgentId>,
    /// `forge`: the `γ` written into every angle item (default 5).
    #[serde(default)]
    pub gamma: Option<f64>,
    /// `forge`: the velocity written into the frame (default: the victim's own).
    #[serde(default)]
    pub velocity: Option<[f64; 2]>,
    /// `flood`: frames per second (default 1000).
    #[serde(default)]
    pub rate_hz: Option<f64>,
    /// `flood`: bytes per frame (default 60).
    #[serde(default)]
    pub bytes: Option<usize>,
}
