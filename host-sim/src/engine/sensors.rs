//! Each agent's own sensors: bearings from the true state plus rotation noise and bias,
//! optional exact bearing rates (S2), own velocity with noise and bias, the leaders'
//! relative position, and ranges for the `measured` estimator.
//!
//! Noise: every agent draws its measurements of one tick from its own random stream
//! ([`Sensors::stream`]: a xoshiro256++ generator seeded from the run's seed, the agent's
//! index and the tick's), so that a tick's agents can be measured on any thread in any
//! order and give the same bits.
//!
//! Which bearings are seen: every neighbour's, at once, unless a bearing sensor
//! ([`BearingSensor`], the seam in `sensors/source.rs`; the [`Camera`], or the
//! [`SharedPositions`] heard over the radio) says otherwise.
//!
//! This file is the registry: each sensor's `mod` line and its line in
//! [`bearing_sensor`]. The noise model every sensor draws from is in `sensors/draws.rs`.

mod camera;
mod draws;
mod latency;
pub(crate) mod occlusion;
mod shared_positions;
mod source;

pub use camera::Camera;
pub use draws::{offset_with, quiet_bearing, velocity_with, Draws, Sensors, Sight};
pub use shared_positions::{SharedPositions, POSITION_VERSION};
pub use source::{BearingKind, BearingSensor, World};

use crate::model::Model;

/// The bearing sensor of `model`'s run with control period `period` (s): the shared
/// positions (`sensors.bearing_source = "shared_positions"`), the camera, or `None` for
/// the omnidirectional ideal sensor.
pub fn bearing_sensor(model: &Model, period: f64) -> Option<Box<dyn BearingSensor>> {
    if let Some(p) = &model.sensors.positions {
        return Some(Box::new(SharedPositions::new(model, p)));
    }
    let camera = model.sensors.camera.as_ref()?;
    Some(Box::new(Camera::new(camera, model.n(), period)))
}
