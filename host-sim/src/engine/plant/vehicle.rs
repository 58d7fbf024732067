//! The seam between the simulator and a vehicle: [`Plant`], what it holds between ticks
//! ([`Held`]), and the virtual mass the velocity-setpoint vehicles share. In a module of
//! its own so that every vehicle depends on it, and only `plant/mod.rs` (the registry)
//! on the vehicles.

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
    /// Agent `i`'s tilt from vertical (rad), if the vehicle models one.
    fn tilt(&self, _i: usize) -> Option<f64> {
        None
    }
    /// `steps` RK4 steps of length `dt` under `held`; `chunk`: on every thread of the
    /// current rayon pool, `chunk` agents per work item (the same bits either way).
    fn step(&mut self, held: &Held<'_>, dt: f64, steps: usize, chunk: Option<usize>);
}

/// The velocity setpoint of agent `i` of a velocity-setpoint vehicle: its virtual mass
/// (`command`, SPEC S20 with the leads of S21/S21b) integrates S1 over `period` under
/// `force` from the vehicle's velocity `v`. The one implementation both such plants call.
pub(crate) fn command_setpoint(
    command: &mut [ph_formation_core::actuate::VelocityCommand<f64>],
    v: &[Vec2<f64>],
    setpoint: &mut [Vec2<f64>],
    i: usize,
    force: Vec2<f64>,
    period: f64,
) {
    if let (Some(c), Some(v), Some(sp)) = (command.get_mut(i), v.get(i), setpoint.get_mut(i)) {
        let next = c.step([force.x, force.y], [v.x, v.y], period);
        *sp = Vec2::new(next[0], next[1]);
    }
}
