//! A Crazyflie 2.x flying the firmware's PID controller in velocity mode
//! (`[plant] model = "crazyflie_pid"`, `docs/world.md` "The Crazyflie's cascade"): every
//! agent's [`Crazyflie`] of the `ph-formation-vehicle` crate (one implementation of the
//! cascade, which the Crazyflie app's C tests fly too), driven by the agent's virtual
//! mass (S20, with the leads of S21 and S21b derived from the cascade).

use super::{Held, Plant, Setpoints};
use crate::engine::error::SetupError;
use crate::model::{CrazyfliePid, Model};
use ph_formation_core::Vec2;
use ph_formation_vehicle::crazyflie::Crazyflie;
pub use ph_formation_vehicle::crazyflie::{
    derived_lead, derived_second_lead, firmware, total_tilt,
};

/// Every agent's Crazyflie.
#[derive(Clone, Debug)]
pub struct CrazyfliePidPlant {
    q: Vec<Vec2<f64>>,
    v: Vec<Vec2<f64>>,
    /// The velocity setpoints and the virtual masses behind them.
    pub(crate) setpoints: Setpoints,
    drones: Vec<Crazyflie>,
}

impl CrazyfliePidPlant {
    /// The model's agents hovering at their initial positions and velocities, each
    /// holding its initial velocity as its setpoint until its first tick.
    pub fn new(model: &Model, vehicle: &CrazyfliePid) -> Result<Self, SetupError> {
        let setpoints = Setpoints::new(
            model,
            vehicle.max_speed,
            vehicle.lead.unwrap_or_else(derived_lead),
            Some((
                vehicle.second_lead.unwrap_or_else(derived_second_lead),
                vehicle.jerk_filter,
            )),
            vehicle.max_gap,
        )?;
        let drones: Vec<Crazyflie> = model
            .agents
            .iter()
            .map(|x| Crazyflie::new(x.position, x.velocity))
            .collect();
        Ok(Self {
            q: drones.iter().map(|d| Vec2::from(d.q)).collect(),
            v: drones.iter().map(|d| Vec2::from(d.v)).collect(),
            setpoints,
            drones,
        })
    }
}

#[cfg(test)]
impl CrazyfliePidPlant {
    /// `n` drones hovering at the origin, each with the virtual mass `mass`.
    pub(crate) fn with_virtual_mass(
        n: usize,
        mass: ph_formation_core::actuate::VirtualMass<f64>,
    ) -> Self {
        use ph_formation_core::actuate::VelocityCommand;
        Self {
            q: vec![Vec2::zeros(); n],
            v: vec![Vec2::zeros(); n],
            setpoints: Setpoints {
                command: vec![VelocityCommand::new(mass); n],
                setpoint: vec![Vec2::zeros(); n],
            },
            drones: vec![Crazyflie::default(); n],
        }
    }
}

impl Plant for CrazyfliePidPlant {
    fn q(&self) -> &[Vec2<f64>] {
        &self.q
    }

    fn v(&self) -> &[Vec2<f64>] {
        &self.v
    }

    fn takes_commands(&self) -> bool {
        true
    }

    /// The virtual mass integrates S1 over `period` under `force` (S20, with the lead of
    /// S21): the new velocity setpoint.
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

    fn tilt(&self, i: usize) -> Option<f64> {
        self.drones.get(i).map(Crazyflie::tilt)
    }

    /// `steps × dt` seconds, split at the firmware's attitude ticks (every agent's
    /// firmware in phase with the simulation's clock).
    fn step(&mut self, held: &Held<'_>, dt: f64, steps: usize, _chunk: Option<usize>) {
        for (i, (((drone, q), v), sp)) in self
            .drones
            .iter_mut()
            .zip(self.q.iter_mut())
            .zip(self.v.iter_mut())
            .zip(&self.setpoints.setpoint)
            .enumerate()
        {
            let w = held.wind.get(i).map_or([0.0; 2], |w| [w.x, w.y]);
            for _ in 0..steps {
                drone.step([sp.x, sp.y], w, dt);
            }
            *q = Vec2::from(drone.q);
            *v = Vec2::from(drone.v);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use ph_formation_core::actuate::{VelocityCommand, VirtualMass};

    /// The plant is the vehicle crate's Crazyflie, agent by agent: a setpoint step flown
    /// through the plant and through one `Crazyflie` agree exactly.
    #[test]
    fn the_plant_flies_the_vehicle_crates_cascade() {
        let mut p = CrazyfliePidPlant {
            q: vec![Vec2::zeros(); 2],
            v: vec![Vec2::zeros(); 2],
            setpoints: Setpoints {
                command: vec![
                    VelocityCommand::new(
                        VirtualMass::new(1.0, [0.0; 2], f64::INFINITY).unwrap()
                    );
                    2
                ],
                setpoint: vec![Vec2::zeros(); 2],
            },
            drones: vec![Crazyflie::default(); 2],
        };
        assert!(p.set_velocity_setpoint(1, Vec2::new(1.0, 0.5)));
        let held = Held {
            forces: &[Vec2::zeros(); 2],
            wind: &[],
        };
        p.step(&held, 1e-3, 200, None);
        let mut one = Crazyflie::default();
        for _ in 0..200 {
            one.step([1.0, 0.5], [0.0; 2], 1e-3);
        }
        assert_eq!(p.v()[1], Vec2::from(one.v));
        assert_eq!(p.q()[1], Vec2::from(one.q));
        assert_eq!(p.v()[0], Vec2::zeros(), "agent 0 holds its zero setpoint");
        assert!(p.tilt(1).unwrap() > 0.05 && p.tilt(2).is_none());
    }
}
