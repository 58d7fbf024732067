//! Which [`Plant`] flies a run: one line per vehicle, matching the model's
//! [`VehicleModel`] (the registry a new vehicle adds its line to, docs/architecture.md
//! "Add a vehicle"). In a file of its own so that the vehicles depend on the seam
//! (`plant/mod.rs`) and only this file on the vehicles.

use super::crazyflie_pid::CrazyfliePidPlant;
use super::point_mass::PointMass;
use super::velocity_tracking::VelocityTrackingPlant;
use super::Plant;
use crate::engine::error::SetupError;
use crate::model::{Model, VehicleModel};

/// The plant of `model`'s vehicle, at the model's initial state.
pub fn new_plant(model: &Model) -> Result<Box<dyn Plant>, SetupError> {
    Ok(match &model.world.vehicle {
        VehicleModel::PointMass => Box::new(PointMass::new(model)),
        VehicleModel::VelocityTracking(v) => Box::new(VelocityTrackingPlant::new(model, v)?),
        VehicleModel::CrazyfliePid(v) => Box::new(CrazyfliePidPlant::new(model, v)?),
    })
}
