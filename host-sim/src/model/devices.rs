//! What the agents' sensors and radios get wrong, in SI units.

use super::{BearingRate, ChannelModel};
use controller_core::BearingFilter;

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
        }
    }

    /// Whether any noise or bias is configured.
    pub fn is_noisy(&self) -> bool {
        self.bearing_noise != 0.0
            || self.bearing_bias != 0.0
            || self.velocity_noise != 0.0
            || self.velocity_bias != [0.0; 2]
            || self.offset_noise != 0.0
            || self.range_noise != 0.0
    }
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
    /// Sender air time in bytes/s (0 = unlimited).
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

    /// Whether any fault or delay is configured.
    pub fn is_faulty(&self) -> bool {
        self.latency != 0.0
            || self.jitter != 0.0
            || self.loss != 0.0
            || self.duplication != 0.0
            || self.reordering != 0.0
            || self.corruption != 0.0
            || self.bandwidth != 0.0
            || self.channel.is_some()
    }
}
