//! What the agents' sensors and radios get wrong, in SI units.

use super::{BearingRate, ChannelModel};
use ph_formation_core::BearingFilter;

/// Sensor imperfections, in SI units.
#[derive(Clone, Debug, PartialEq)]
pub struct SensorModel {
    /// Bearing angle noise standard deviation (rad).
    pub bearing_noise: f64,
    /// Bearing rotation bias (rad).
    pub bearing_bias: f64,
    /// Source of bearing rates.
    pub bearing_rate: BearingRate,
    /// The controllers' bearing filter (SPEC §11), resolved from `sensors.bearing_filter`.
    pub bearing_filter: BearingFilter<f64>,
    /// Velocity noise standard deviation per component (m/s).
    pub velocity_noise: f64,
    /// Velocity bias (m/s).
    pub velocity_bias: [f64; 2],
    /// Leader relative-position noise per component (m).
    pub offset_noise: f64,
    /// Range noise (m).
    pub range_noise: f64,
    /// The camera that limits which neighbours are seen (`[sensors.camera]`); `None`:
    /// every neighbour's bearing is seen, at once (the omnidirectional ideal sensor).
    pub camera: Option<CameraModel>,
    /// Bearings from positions shared over the radio (`sensors.bearing_source =
    /// "shared_positions"`); `None`: the agents' own bearing sensor.
    pub positions: Option<PositionsModel>,
}

impl SensorModel {
    /// No noise, no bias, the given rate source.
    pub fn ideal(bearing_rate: BearingRate) -> Self {
        Self {
            bearing_noise: 0.0,
            bearing_bias: 0.0,
            bearing_rate,
            bearing_filter: BearingFilter::FiniteDifference,
            velocity_noise: 0.0,
            velocity_bias: [0.0; 2],
            offset_noise: 0.0,
            range_noise: 0.0,
            camera: None,
            positions: None,
        }
    }

    /// How these sensors depart from ideal ones: the one classification of their fields,
    /// from which [`Self::is_noisy`] and the simulator's shortcut (sensors that draw
    /// nothing from the random streams) follow. It destructures every field, so a new
    /// field does not compile until it is classified here.
    pub fn departures(&self) -> SensorDepartures {
        let Self {
            bearing_noise,
            bearing_bias,
            bearing_rate: _, // how rates are measured, exact or not: no noise or bias
            bearing_filter: _, // what the controllers do with the bearings: not a sensor error
            velocity_noise,
            velocity_bias,
            offset_noise,
            range_noise,
            // which neighbours are seen and when: the engine's bearing sensor
            // (`engine/sensors/camera.rs`), which draws from the streams on its own
            camera: _,
            // the position noise and the packets' staleness: the engine's bearing sensor
            // (`engine/sensors/shared_positions.rs`), which draws from streams of its own
            positions: _,
        } = self;
        SensorDepartures {
            noise: *bearing_noise != 0.0 || *velocity_noise != 0.0 || *offset_noise != 0.0,
            range_noise: *range_noise != 0.0,
            bias: *bearing_bias != 0.0 || *velocity_bias != [0.0; 2],
        }
    }

    /// Whether any noise or bias is configured.
    pub fn is_noisy(&self) -> bool {
        let d = self.departures();
        d.noise || d.range_noise || d.bias
    }
}

/// Every agent's camera, its bearing sensor (`[sensors.camera]`, docs/sensors.md): which
/// neighbours it sees and how late, and how its detections go wrong. SI units.
#[derive(Clone, Debug, PartialEq)]
pub struct CameraModel {
    /// Field of view (rad), centred on the agent's heading; `2π` sees all round.
    pub fov: f64,
    /// Largest distance at which a neighbour is seen (m); `f64::INFINITY`: no limit.
    pub range: f64,
    /// Radius of the disc each agent's body occupies in the view of the others (m):
    /// a body closer than a neighbour that crosses the line of sight hides it; 0: nothing
    /// hides anything.
    pub occlusion_radius: f64,
    /// Probability that a visible neighbour is detected at a tick.
    pub detection_probability: f64,
    /// Probability that a detected bearing is replaced by a uniformly random direction.
    pub outlier_probability: f64,
    /// Age of the image (s): a bearing describes the geometry this long ago.
    pub latency: f64,
}

impl CameraModel {
    /// A camera that sees everything at once: 360°, no range limit, no occlusion,
    /// certain detection, no outliers, no latency (the ideal sensor, through the camera's
    /// code path).
    pub fn all_seeing() -> Self {
        Self {
            fov: std::f64::consts::TAU,
            range: f64::INFINITY,
            occlusion_radius: 0.0,
            detection_probability: 1.0,
            outlier_probability: 0.0,
            latency: 0.0,
        }
    }
}

/// Bearings from positions shared over the radio (`[sensors.positions]`, docs/sensors.md):
/// each agent's position estimate is the true position plus white Gaussian noise, and it
/// broadcasts that estimate in a packet of its own at every tick (the core's position
/// packet, protected by the scenario's integrity mode). SI units.
#[derive(Clone, Debug, PartialEq)]
pub struct PositionsModel {
    /// Standard deviation of the position noise per axis (m).
    pub noise: f64,
    /// A neighbour's position heard longer ago than this gives no bearing (s).
    pub max_age: f64,
}

/// How a [`SensorModel`] departs from ideal sensors ([`SensorModel::departures`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct SensorDepartures {
    /// Noise on what every agent measures (bearings, velocity, the leader's offset): each
    /// measurement draws from its agent's random stream.
    pub noise: bool,
    /// Noise on ranges, which only the `measured` estimator measures.
    pub range_noise: bool,
    /// A bias (bearing rotation or velocity offset): a function of the state, no draw.
    pub bias: bool,
}

/// The radio link model, in SI units.
#[derive(Clone, Debug, PartialEq)]
pub struct RadioModel {
    /// Fixed latency (s).
    pub latency: f64,
    /// Uniform extra delay bound (s).
    pub jitter: f64,
    /// Loss probability per link copy.
    pub loss: f64,
    /// Duplication probability per link copy.
    pub duplication: f64,
    /// Reordering probability per link copy.
    pub reordering: f64,
    /// Largest extra delay of a reordered copy (s).
    pub reorder_delay: f64,
    /// Corruption (one bit flip) probability per link copy.
    pub corruption: f64,
    /// Sender air-time limit in bits per second (0 = unlimited; scenario key
    /// `radio.bandwidth_bps`).
    pub bandwidth: f64,
    /// Longest transmit-queue wait before a drop (s).
    pub queue_limit: f64,
    /// The shared medium, if modelled (`None`: every link is independent).
    pub channel: Option<ChannelModel>,
}

impl RadioModel {
    /// A perfect radio (every frame delivered at the next tick).
    pub fn ideal() -> Self {
        Self {
            latency: 0.0,
            jitter: 0.0,
            loss: 0.0,
            duplication: 0.0,
            reordering: 0.0,
            reorder_delay: 0.0,
            corruption: 0.0,
            bandwidth: 0.0,
            queue_limit: 0.05,
            channel: None,
        }
    }

    /// How this radio departs from the ideal one: the one classification of its fields,
    /// from which [`Self::is_faulty`] and the simulator's direct delivery
    /// (`engine::direct_radio`) follow. It destructures every field, so a new field (a new
    /// fault, by the recipe of `docs/architecture.md`) does not compile until it is
    /// classified here.
    pub fn departures(&self) -> RadioDepartures {
        let Self {
            latency,
            jitter,
            loss,
            duplication,
            reordering,
            reorder_delay: _, // a reordered copy's delay bound: it acts only with `reordering`
            corruption,
            bandwidth,
            queue_limit: _, // the queue's longest wait: it acts only with a `bandwidth`
            channel,
        } = self;
        RadioDepartures {
            latency: *latency,
            // Each of these draws from the radio's stream or holds frames in its queue
            // (a reordering draws and counts even with no delay).
            alters_frames: *loss != 0.0
                || *duplication != 0.0
                || *corruption != 0.0
                || *reordering != 0.0
                || *jitter != 0.0
                || *bandwidth != 0.0
                || channel.is_some(),
        }
    }

    /// Whether any fault or delay is configured.
    pub fn is_faulty(&self) -> bool {
        let d = self.departures();
        d.alters_frames || d.latency != 0.0
    }
}

/// How a [`RadioModel`] departs from the ideal radio ([`RadioModel::departures`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RadioDepartures {
    /// The fixed latency (s): it delays every frame alike, so frames still arrive
    /// unchanged and in order (at the next tick while it is under half a period).
    pub latency: f64,
    /// Something changes which frames arrive, when, or in which order: loss,
    /// duplication, corruption, reordering, jitter, a bandwidth limit, a shared channel.
    pub alters_frames: bool,
}
