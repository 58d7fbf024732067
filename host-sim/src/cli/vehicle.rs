//! `host-sim export --vehicle NAME`: the limits of a real vehicle, checked before a
//! configuration is flashed. The controller's force `U` acts on the virtual mass of
//! SPEC S1 (`ph_formation_core::actuate`), so a force limit `max_force` asks the vehicle
//! for accelerations up to `max_force / m`, and the reference velocity `v*` is a speed
//! it must fly. Each figure is sourced from the vehicle's firmware (docs/crazyflie.md).

use crate::model::{Model, ModelError};
use clap::ValueEnum;

/// A vehicle whose limits `export` checks.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum Vehicle {
    /// Crazyflie 2.x with the firmware's PID position/velocity controller.
    Crazyflie,
}

/// Standard gravity (m/s²).
const G: f64 = 9.806_65;

/// Limits of one vehicle, with where each figure comes from.
struct Limits {
    name: &'static str,
    /// Largest horizontal acceleration (m/s²).
    max_acceleration: f64,
    acceleration_source: &'static str,
    /// Largest horizontal speed (m/s).
    max_speed: f64,
    speed_source: &'static str,
}

impl Vehicle {
    fn limits(self) -> Limits {
        match self {
            // The velocity controller clamps roll and pitch to 20° each
            // (PID_VEL_ROLL_MAX / PID_VEL_PITCH_MAX), so thrust buys at least
            // g·tan(20°) = 3.57 m/s² along any axis (more on a diagonal: the clamp is per
            // axis). In velocity mode the firmware limits no speed (PID_POS_VEL_*_MAX
            // bound only the position loop's output); the limit is the app's own.
            Self::Crazyflie => Limits {
                name: "a Crazyflie 2.x",
                max_acceleration: G * 20_f64.to_radians().tan(),
                acceleration_source: "20° tilt limit per axis: crazyflie-firmware \
                    src/platform/interface/platform_defaults_cf2.h:152-153 PID_VEL_ROLL_MAX/PID_VEL_PITCH_MAX, \
                    applied in src/modules/src/controller/position_controller_pid.c:254-255",
                max_speed: 1.0,
                speed_source: "the Crazyflie app's FORMATION_MAX_SPEED \
                    (crazyflie-app/src/formation.h); the firmware has no speed limit in velocity mode",
            },
        }
    }

    /// The vehicle's largest horizontal acceleration (m/s²).
    pub fn max_acceleration(self) -> f64 {
        self.limits().max_acceleration
    }

    /// The vehicle's largest horizontal speed (m/s).
    pub fn max_speed(self) -> f64 {
        self.limits().max_speed
    }

    /// Checks agents `indices` of `model` against the vehicle: the force limit over the
    /// agent's mass and every step of the reference velocity. The error names the agent,
    /// the scenario field, the figure and its source.
    pub fn check(self, model: &Model, indices: &[usize]) -> Result<(), VehicleError> {
        let l = self.limits();
        for &i in indices {
            let Some(agent) = model.agents.get(i) else {
                continue;
            };
            let config = model.agent_config(i)?;
            let force = config.limits.max_force;
            let acceleration = force / agent.mass;
            if acceleration.is_nan() || acceleration > l.max_acceleration {
                return Err(VehicleError::Force {
                    source_file: model.source.clone(),
                    agent: agent.name.clone(),
                    force,
                    mass: agent.mass,
                    acceleration,
                    vehicle: l.name,
                    max_acceleration: l.max_acceleration,
                    figure_source: l.acceleration_source,
                });
            }
            for step in &config.velocity_reference.steps {
                let [x, y] = step.value;
                let speed = x.hypot(y);
                if speed.is_nan() || speed > l.max_speed {
                    return Err(VehicleError::Speed {
                        source_file: model.source.clone(),
                        velocity: [x, y],
                        from: step.from,
                        speed,
                        vehicle: l.name,
                        max_speed: l.max_speed,
                        figure_source: l.speed_source,
                    });
                }
            }
        }
        Ok(())
    }
}

/// Why a configuration does not fit the vehicle of `--vehicle`.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum VehicleError {
    /// The agent's configuration cannot be built.
    #[error("--vehicle: {0}")]
    Model(#[from] ModelError),
    /// The force limit asks for more acceleration than the vehicle has.
    #[error(
        "--vehicle: {source_file}: agent {agent}: controller.max_force = {force} N on its \
         {mass} kg virtual mass asks up to {acceleration:.3} m/s², more than {vehicle} \
         reaches ({max_acceleration:.2} m/s², {figure_source}); set controller.max_force to \
         at most {:.2} (e.g. --set controller.max_force={:.2})",
        .max_acceleration * .mass,
        (.max_acceleration * .mass * 100.0).floor() / 100.0
    )]
    Force {
        /// The scenario.
        source_file: String,
        /// The agent's id.
        agent: String,
        /// `controller.max_force` (N).
        force: f64,
        /// The agent's mass (kg).
        mass: f64,
        /// `force / mass` (m/s²).
        acceleration: f64,
        /// The vehicle's name.
        vehicle: &'static str,
        /// Its largest acceleration (m/s²).
        max_acceleration: f64,
        /// Where that figure comes from.
        figure_source: &'static str,
    },
    /// A reference velocity faster than the vehicle flies.
    #[error(
        "--vehicle: {source_file}: velocity_reference = ({}, {}) from t = {from} s is \
         {speed:.3} m/s, faster than {vehicle} flies ({max_speed} m/s, {figure_source})",
        .velocity[0],
        .velocity[1]
    )]
    Speed {
        /// The scenario.
        source_file: String,
        /// The step's velocity (m/s).
        velocity: [f64; 2],
        /// When the step starts (s).
        from: f64,
        /// Its speed (m/s).
        speed: f64,
        /// The vehicle's name.
        vehicle: &'static str,
        /// Its largest speed (m/s).
        max_speed: f64,
        /// Where that figure comes from.
        figure_source: &'static str,
    },
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_crazyflie_tilt_limit_is_about_3_6_m_per_s2() {
        let a = Vehicle::Crazyflie.max_acceleration();
        assert!((a - 3.569).abs() < 1e-3, "{a}");
        assert_eq!(Vehicle::Crazyflie.max_speed(), 1.0);
    }
}
