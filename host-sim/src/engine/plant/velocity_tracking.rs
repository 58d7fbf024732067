//! A vehicle that tracks velocity setpoints with its own controller (a Crazyflie's
//! velocity loop, a rover's wheel controller), `docs/world.md`:
//!
//! `q̇ = v`, `v̇ = sat_{a_max}((v_sp − v) / τ) + a_w`
//!
//! (first order with time constant `τ`, the acceleration limited in norm to `a_max`, the
//! wind `a_w` acting on top: a proportional velocity loop leaves a steady error `τ a_w`).
//! At each of its ticks the agent's force `U` becomes the setpoint through the virtual
//! mass of SPEC S20 with the lead of S21 (`ph_formation_core::actuate::VelocityCommand`,
//! the same code the Crazyflie app calls through `ph_actuate`), limited to `v_max`.

use super::{Held, Plant, Setpoints};
use crate::engine::error::SetupError;
use crate::model::{Model, VelocityTracking};
use ph_formation_core::Vec2;

/// Every agent's velocity-tracking vehicle.
#[derive(Clone, Debug)]
pub struct VelocityTrackingPlant {
    q: Vec<Vec2<f64>>,
    v: Vec<Vec2<f64>>,
    /// The velocity setpoints and the virtual masses behind them.
    setpoints: Setpoints,
    vehicle: VelocityTracking,
}

/// `sat_{a_max}((v_sp − v) / τ)`: the vehicle's own acceleration.
#[inline]
pub fn tracking_acceleration(
    v: &Vec2<f64>,
    setpoint: &Vec2<f64>,
    p: &VelocityTracking,
) -> Vec2<f64> {
    let a = (setpoint - v) / p.time_constant;
    let norm = a.norm();
    if norm > p.max_acceleration {
        a * (p.max_acceleration / norm)
    } else {
        a
    }
}

impl VelocityTrackingPlant {
    /// The model's agents at their initial state, each holding its initial velocity
    /// until its first tick.
    pub fn new(model: &Model, vehicle: &VelocityTracking) -> Result<Self, SetupError> {
        let setpoints = Setpoints::new(
            model,
            vehicle.max_speed,
            vehicle.lead,
            None,
            vehicle.max_gap,
        )?;
        Ok(Self {
            q: model
                .agents
                .iter()
                .map(|x| Vec2::new(x.position[0], x.position[1]))
                .collect(),
            v: setpoints.setpoint.clone(),
            setpoints,
            vehicle: *vehicle,
        })
    }

    /// The current velocity setpoints.
    pub fn setpoints(&self) -> &[Vec2<f64>] {
        &self.setpoints.setpoint
    }
}

impl Plant for VelocityTrackingPlant {
    fn q(&self) -> &[Vec2<f64>] {
        &self.q
    }

    fn v(&self) -> &[Vec2<f64>] {
        &self.v
    }

    fn takes_commands(&self) -> bool {
        true
    }

    /// The virtual mass integrates S1 over `period` under `force` (from the vehicle's
    /// velocity at the first tick): the new setpoint.
    fn command(&mut self, i: usize, force: Vec2<f64>, period: f64) {
        self.setpoints.command(i, force, &self.v, period);
    }

    fn restart(&mut self, i: usize) {
        self.setpoints.restart(i);
    }

    fn reseed(&mut self, i: usize) {
        self.setpoints.reseed(i);
    }

    fn set_velocity_setpoint(&mut self, i: usize, setpoint: Vec2<f64>) -> bool {
        self.setpoints.set(i, setpoint)
    }

    /// RK4 per agent, the setpoint and wind held over the step.
    fn step(&mut self, held: &Held<'_>, dt: f64, steps: usize, _chunk: Option<usize>) {
        let p = self.vehicle;
        for _ in 0..steps {
            for (i, ((q, v), sp)) in self
                .q
                .iter_mut()
                .zip(self.v.iter_mut())
                .zip(&self.setpoints.setpoint)
                .enumerate()
            {
                let w = held.wind.get(i).copied().unwrap_or_else(Vec2::zeros);
                let a = |v: &Vec2<f64>| tracking_acceleration(v, sp, &p) + w;
                let k1 = a(v);
                let v2 = *v + k1 * (0.5 * dt);
                let k2 = a(&v2);
                let v3 = *v + k2 * (0.5 * dt);
                let k3 = a(&v3);
                let v4 = *v + k3 * dt;
                let k4 = a(&v4);
                *q += (*v + v2 * 2.0 + v3 * 2.0 + v4) * (dt / 6.0);
                *v += (k1 + k2 * 2.0 + k3 * 2.0 + k4) * (dt / 6.0);
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use ph_formation_core::actuate::{VelocityCommand, VirtualMass};

    fn plant(tau: f64, a_max: f64) -> VelocityTrackingPlant {
        VelocityTrackingPlant {
            q: vec![Vec2::zeros()],
            v: vec![Vec2::zeros()],
            setpoints: Setpoints {
                command: vec![VelocityCommand::new(
                    VirtualMass::new(1.0, [0.5; 2], 1.0).unwrap(),
                )],
                setpoint: vec![Vec2::new(0.6, -0.8)],
            },
            vehicle: VelocityTracking {
                time_constant: tau,
                max_acceleration: a_max,
                max_speed: 1.0,
                lead: 0.0,
                max_gap: f64::INFINITY,
            },
        }
    }

    /// Without saturation the step response is the first-order closed form:
    /// `v(t) = v_sp (1 − e^{−t/τ})`, `q(t) = v_sp (t − τ (1 − e^{−t/τ}))`.
    #[test]
    fn step_response_is_first_order() {
        let tau = 0.2;
        let mut p = plant(tau, 1e9);
        let held = Held {
            forces: &[Vec2::zeros()],
            wind: &[],
        };
        p.step(&held, 1e-3, 500, None);
        let t: f64 = 0.5;
        let e = 1.0 - (-t / tau).exp();
        let sp = Vec2::new(0.6, -0.8);
        // RK4 at h/τ = 0.005: a global error of order (h/τ)⁴ ≈ 1e-10.
        assert!((p.v[0] - sp * e).norm() < 1e-9, "{:?}", p.v[0]);
        assert!((p.q[0] - sp * (t - tau * e)).norm() < 1e-9, "{:?}", p.q[0]);
    }

    /// With a small acceleration limit the velocity ramps at exactly `a_max` along the
    /// setpoint's direction until `|v_sp − v| / τ = a_max`.
    #[test]
    fn saturated_response_ramps_at_the_limit() {
        let (tau, a_max) = (0.2, 1.0);
        let mut p = plant(tau, a_max);
        let held = Held {
            forces: &[Vec2::zeros()],
            wind: &[],
        };
        // |v_sp| / τ = 5 > a_max: saturated until |v_sp − v| = 0.2, i.e. t = 0.8 s.
        p.step(&held, 1e-3, 300, None);
        let dir = Vec2::new(0.6, -0.8);
        assert!((p.v[0] - dir * 0.3).norm() < 1e-12, "{:?}", p.v[0]);
        assert!((p.q[0] - dir * (0.5 * 0.3 * 0.3)).norm() < 1e-12);
    }

    /// A constant wind leaves the steady error `τ a_w` of a proportional loop.
    #[test]
    fn wind_leaves_the_proportional_steady_error() {
        let tau = 0.2;
        let mut p = plant(tau, 1e9);
        let wind = [Vec2::new(0.5, 0.0)];
        let held = Held {
            forces: &[Vec2::zeros()],
            wind: &wind,
        };
        p.step(&held, 1e-3, 5000, None);
        let want = Vec2::new(0.6 + tau * 0.5, -0.8);
        assert!((p.v[0] - want).norm() < 1e-9, "{:?}", p.v[0]);
    }

    /// The setpoint is the core's virtual mass: S1 integrated from the vehicle's
    /// velocity, limited to `v_max`.
    #[test]
    fn command_is_the_cores_virtual_mass() {
        let mut p = plant(0.2, 1e9);
        p.v[0] = Vec2::new(0.1, 0.0);
        p.command(0, Vec2::new(2.0, 0.0), 0.01);
        // (0.1 + 0.01 · 2) / (1 + 0.01 · 0.5).
        assert!((p.setpoints.setpoint[0].x - 0.12 / 1.005).abs() < 1e-15);
        p.command(0, Vec2::new(1e6, 0.0), 0.01);
        assert!((p.setpoints.setpoint[0].norm() - 1.0).abs() < 1e-12);
    }
}
