//! The seam between the simulator and a vehicle: [`Plant`], what it holds between ticks
//! ([`Held`]), and the virtual mass the velocity-setpoint vehicles share. In a module of
//! its own so that every vehicle depends on it, and only `plant/mod.rs` (the registry)
//! on the vehicles.

use crate::engine::error::SetupError;
use crate::model::Model;
use ph_formation_core::actuate::{VelocityCommand, VirtualMass};
use ph_formation_core::Vec2;

/// What the plant holds between ticks: every agent's last force (N, world frame) and
/// the wind's acceleration on it (m/s²; empty: no wind).
#[derive(Clone, Copy, Debug)]
pub struct Held<'a> {
    /// The forces of the agents' last ticks, in agent order.
    pub forces: &'a [Vec2<f64>],
    /// The wind on each agent, in agent order, or empty.
    pub wind: &'a [Vec2<f64>],
}

/// Every agent's vehicle: its state, what it does with a tick's force, and its motion
/// between ticks.
pub trait Plant: Send + Sync {
    /// Positions `q_n` (m, world frame).
    fn q(&self) -> &[Vec2<f64>];
    /// Velocities `v_n` (m/s, world frame).
    fn v(&self) -> &[Vec2<f64>];
    /// Whether the plant needs [`Plant::command`] at every tick (a point mass reads the
    /// held forces in [`Plant::step`] and needs nothing more).
    fn takes_commands(&self) -> bool {
        false
    }
    /// Agent `i`'s force of its tick (N, world frame), `period` seconds by its own clock
    /// after its previous tick.
    fn command(&mut self, _i: usize, _force: Vec2<f64>, _period: f64) {}
    /// Holds agent `i`'s velocity setpoint (m/s, world frame) directly, bypassing the
    /// virtual mass (`host-sim vehicle step`); false if the vehicle has no velocity loop.
    fn set_velocity_setpoint(&mut self, _i: usize, _setpoint: Vec2<f64>) -> bool {
        false
    }
    /// Agent `i`'s actuation starts again from its measured velocity at its next
    /// command (a rebooted agent's state is lost; nothing for a point mass).
    fn restart(&mut self, _i: usize) {}
    /// Agent `i`'s actuation starts its next command from its measured velocity, its
    /// setpoint's lead going on (SPEC S21c: the safe output; nothing for a point mass).
    fn reseed(&mut self, _i: usize) {}
    /// Agent `i`'s tilt from vertical (rad), if the vehicle models one.
    fn tilt(&self, _i: usize) -> Option<f64> {
        None
    }
    /// `steps` RK4 steps of length `dt` under `held`; `chunk`: on every thread of the
    /// current rayon pool, `chunk` agents per work item (the same bits either way).
    fn step(&mut self, held: &Held<'_>, dt: f64, steps: usize, chunk: Option<usize>);
}

/// The velocity setpoints of a velocity-setpoint vehicle's agents and the virtual masses
/// that produce them (SPEC S20, with the leads of S21/S21b): the one implementation both
/// such plants hold.
#[derive(Clone, Debug)]
pub(crate) struct Setpoints {
    /// Each agent's virtual mass and its state (the setpoint it integrates).
    pub(crate) command: Vec<VelocityCommand<f64>>,
    /// The velocity setpoints (m/s, world frame).
    pub(crate) setpoint: Vec<Vec2<f64>>,
}

impl Setpoints {
    /// Every agent of `model` with its virtual mass (its mass and friction, the speed
    /// limit `max_speed`, the lead and, if given, the second-order lead with its jerk
    /// filter's time constant, S21b/S21d; the gap bound `max_gap` and, as the app's
    /// `ph_actuator_init`, the neighbour timeout as the stall limit, S21c), holding its
    /// initial velocity as its setpoint until its first tick.
    pub(crate) fn new(
        model: &Model,
        max_speed: f64,
        lead: f64,
        second_lead: Option<(f64, f64)>,
        max_gap: f64,
    ) -> Result<Self, SetupError> {
        let a = &model.agents;
        let stall = model.limits.neighbour_timeout;
        let command = a
            .iter()
            .enumerate()
            .map(|(i, x)| {
                VirtualMass::new(x.mass, x.friction, max_speed)
                    .and_then(|m| m.with_lead(lead))
                    .and_then(|m| m.with_max_gap(max_gap))
                    .and_then(|m| m.with_max_interval(stall))
                    .and_then(|m| {
                        second_lead.map_or(Ok(m), |(s, f)| {
                            m.with_second_lead(s).and_then(|m| m.with_jerk_filter(f))
                        })
                    })
                    .map(VelocityCommand::new)
                    .map_err(|error| SetupError::Vehicle { agent: i, error })
            })
            .collect::<Result<Vec<_>, _>>()?;
        let setpoint = a
            .iter()
            .map(|x| Vec2::new(x.velocity[0], x.velocity[1]))
            .collect();
        Ok(Self { command, setpoint })
    }

    /// Agent `i`'s new setpoint: its virtual mass integrates S1 over `period` under
    /// `force` from the vehicle's velocity `v` (at the first tick; its own after).
    pub(crate) fn command(&mut self, i: usize, force: Vec2<f64>, v: &[Vec2<f64>], period: f64) {
        let (c, v, sp) = (self.command.get_mut(i), v.get(i), self.setpoint.get_mut(i));
        if let (Some(c), Some(v), Some(sp)) = (c, v, sp) {
            let next = c.step([force.x, force.y], [v.x, v.y], period);
            *sp = Vec2::new(next[0], next[1]);
        }
    }

    /// Agent `i`'s virtual mass starts again from the measured velocity.
    pub(crate) fn restart(&mut self, i: usize) {
        if let Some(c) = self.command.get_mut(i) {
            c.restart();
        }
    }

    /// Agent `i`'s virtual mass starts from the measured velocity at its next command,
    /// keeping its virtual acceleration (SPEC S21c, the safe output).
    pub(crate) fn reseed(&mut self, i: usize) {
        if let Some(c) = self.command.get_mut(i) {
            c.reseed();
        }
    }

    /// Sets agent `i`'s setpoint (false: no agent `i`).
    pub(crate) fn set(&mut self, i: usize, setpoint: Vec2<f64>) -> bool {
        self.setpoint.get_mut(i).map(|sp| *sp = setpoint).is_some()
    }
}
