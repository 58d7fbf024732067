//! Which [`BearingSensor`] a run's agents see through: one line per sensor, picked from
//! the [`SensorModel`](crate::model::SensorModel) (the registry a new sensor adds its line
//! to, docs/architecture.md "Add a sensor"). In a file of its own so that the sensors
//! depend on the seam (`source.rs`) and only this file on the sensors.

use super::camera::Camera;
use super::shared_positions::SharedPositions;
use super::source::BearingSensor;
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
