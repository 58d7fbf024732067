//! `host-sim export --vehicle NAME`: the limits of a real vehicle, checked before a
//! configuration is flashed. The controller's force `U` acts on the virtual mass of
//! SPEC S1 (`controller_core::actuate`), so a force limit `max_force` asks the vehicle
//! for accelerations up to `max_force / m`, and the reference velocity `v*` is a speed
//! it must fly. Each figure is sourced from the vehicle's firmware (docs/crazyflie.md).

use crate::model::Model;
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
            // The velocity controller tilts at most 20° in roll and pitch
            // (PID_VEL_ROLL_MAX / PID_VEL_PITCH_MAX), so thrust buys at most
            // g·tan(20°) = 3.57 m/s² sideways; the position controller commands at most
            // 1 m/s (PID_POS_VEL_X_MAX / _Y_MAX).
            Self::Crazyflie => Limits {
                name: "a Crazyflie 2.x",
                max_acceleration: G * 20_f64.to_radians().tan(),
                acceleration_source: "20° tilt limit: crazyflie-firmware \
                    src/platform/interface/platform_defaults_cf2.h PID_VEL_ROLL_MAX/PID_VEL_PITCH_MAX, \
                    applied in src/modules/src/controller/position_controller_pid.c",
                max_speed: 1.0,
                speed_source: "crazyflie-firmware src/platform/interface/platform_defaults_cf2.h \
                    PID_POS_VEL_X_MAX/PID_POS_VEL_Y_MAX",
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
    pub fn check(self, model: &Model, indices: &[usize]) -> Result<(), String> {
        let l = self.limits();
        for &i in indices {
            let Some(agent) = model.agents.get(i) else {
                continue;
            };
            let config = model.agent_config(i).map_err(|e| e.to_string())?;
            let force = config.limits.max_force;
            let acceleration = force / agent.mass;
            if acceleration.is_nan() || acceleration > l.max_acceleration {
                return Err(format!(
                    "--vehicle: {}: agent {}: controller.max_force = {force} N on its {} kg \
                     virtual mass asks up to {acceleration:.3} m/s², more than {} reaches \
                     ({:.2} m/s², {}); set controller.max_force to at most {:.2} \
                     (e.g. --set controller.max_force={:.2})",
                    model.source,
                    agent.name,
                    agent.mass,
                    l.name,
                    l.max_acceleration,
                    l.acceleration_source,
                    l.max_acceleration * agent.mass,
                    (l.max_acceleration * agent.mass * 100.0).floor() / 100.0,
                ));
            }
            for step in &config.velocity_reference.steps {
                let [x, y] = step.value;
                let speed = x.hypot(y);
                if speed.is_nan() || speed > l.max_speed {
                    return Err(format!(
                        "--vehicle: {}: velocity_reference = ({x}, {y}) from t = {} s is \
                         {speed:.3} m/s, faster than {} flies ({} m/s, {})",
                        model.source, step.from, l.name, l.max_speed, l.speed_source,
                    ));
                }
            }
        }
        Ok(())
    }
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
