//! The vehicles: what every agent's body does with its controller's output between
//! ticks. One [`Plant`] per run, holding every agent's state; the paper's point mass S1
//! ([`PointMass`]), a generic velocity-tracking vehicle ([`VelocityTrackingPlant`]) and a
//! Crazyflie flying its firmware's PID cascade ([`CrazyfliePidPlant`]).
//! `docs/architecture.md` ("Add a vehicle") says how to add one: a file here that
//! implements [`Plant`] (the seam, `vehicle.rs`), declared below and given its line in
//! [`new_plant`], the registry.

mod crazyflie_pid;
mod point_mass;
mod vehicle;
mod velocity_tracking;

pub use crazyflie_pid::{
    derived_lead, derived_second_lead, firmware, total_tilt, CrazyfliePidPlant,
};
pub use point_mass::{acceleration, PointMass};
pub(crate) use vehicle::Setpoints;
pub use vehicle::{Held, Plant};
pub use velocity_tracking::{tracking_acceleration, VelocityTrackingPlant};

use super::error::SetupError;
use crate::model::{Model, VehicleModel};

/// The plant of `model`'s vehicle, at the model's initial state.
pub fn new_plant(model: &Model) -> Result<Box<dyn Plant>, SetupError> {
    Ok(match &model.world.vehicle {
        VehicleModel::PointMass => Box::new(PointMass::new(model)),
        VehicleModel::VelocityTracking(v) => Box::new(VelocityTrackingPlant::new(model, v)?),
        VehicleModel::CrazyfliePid(v) => Box::new(CrazyfliePidPlant::new(model, v)?),
    })
}
