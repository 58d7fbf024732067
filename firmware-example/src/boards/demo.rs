//! The `qemu-demo` board: the paper's four robots (SPEC §9) simulated inside
//! the firmware, in `f32`.
//!
//! * Plant (S1): `q̇ = v`, `m v̇ = −D^r v + U`, integrated with RK4 at
//!   [`PLANT_HZ`] (1 ms), the force held between control ticks.
//!   Positions are kept in a frame that moves at `v*` (the formation's
//!   reference velocity): absolute positions grow by 3 m/s and after 100 s an
//!   `f32` resolves only ~3e-5 m at 300 m, which would turn every 1 ms
//!   increment of ~3 mm into a rounding error of ~1 %. The controller never
//!   sees absolute positions (only bearings, velocities and the leaders'
//!   relative position), so this changes nothing for it.
//! * Sensors: exact bearings to every other robot (the control loop keeps the
//!   neighbours'), no rates (the controller takes finite differences), exact
//!   velocities, and for the leaders 1 and 2 the partner's relative position.
//! * Radio: a broadcast medium of real encoded frames. Frames sent during
//!   control tick `k` reach every other robot's inbox at the end of the tick
//!   and are read at tick `k + 1` (one tick of latency); robots that are not
//!   neighbours reject them (`UnknownSender`), as on a real broadcast radio.
//! * Clock: the plant's time, [`PLANT_HZ`] ticks per second.
//!
//! Each robot runs its own `controller-core` agent through the generic
//! [`ControlLoop`] at [`CONTROL_HZ`].

use heapless::{Deque, Vec};
use ph_formation_core::Real;

use crate::app::{Board, ControlLoop, TickReport};
use crate::hal::{
    Actuator, Bearing, BearingSensor, Clock, Radio, Vec2, VelocitySource, MAX_FRAME_LEN,
};
use crate::paper;

/// Robots.
pub const N: usize = paper::AGENTS;
/// Plant integration rate (Hz): RK4 step of 1 ms.
pub const PLANT_HZ: u32 = 1000;
/// Control rate of every robot (Hz).
pub const CONTROL_HZ: u32 = 100;
/// Plant steps per control tick.
pub const SUBSTEPS: u32 = PLANT_HZ / CONTROL_HZ;
/// Frames that can be on the air in one control tick (all robots together).
/// (With wire v3 the paper's robots send one frame each: 4 frames per tick.)
pub const AIR_CAPACITY: usize = 8;
/// Frames one robot's radio can hold between two ticks.
pub const INBOX_CAPACITY: usize = 8;

/// Error of the demo drivers.
#[derive(Clone, Copy, Debug, PartialEq, Eq, defmt::Format)]
pub enum DemoError {
    /// A frame longer than [`MAX_FRAME_LEN`].
    FrameTooLong,
    /// Too many frames on the air this tick (the frame is lost).
    AirFull,
}

/// One frame on the simulated radio.
#[derive(Clone, Copy, Debug)]
struct Packet {
    /// Index of the sending robot.
    from: u8,
    len: u8,
    bytes: [u8; MAX_FRAME_LEN],
}

/// The broadcast medium shared by the robots.
#[derive(Debug, Default)]
pub struct RadioBus {
    air: Vec<Packet, AIR_CAPACITY>,
    inbox: [Deque<Packet, INBOX_CAPACITY>; N],
    /// Frames sent over the whole run.
    pub sent: u32,
    /// Frames lost because the air or an inbox was full.
    pub lost: u32,
}

impl RadioBus {
    /// Delivers the frames sent this tick to every other robot's inbox.
    pub fn deliver(&mut self) {
        for p in &self.air {
            for (j, inbox) in self.inbox.iter_mut().enumerate() {
                if j != usize::from(p.from) && inbox.push_back(*p).is_err() {
                    self.lost += 1;
                }
            }
        }
        self.air.clear();
    }
}

/// True state of the four robots, in a frame moving at [`paper::V_STAR`]
/// (see the module docs).
///
/// Positions are compensated (Kahan) sums: near convergence a robot moves by
/// far less than an `f32` ulp of its position per 1 ms step, and plain `f32`
/// accumulation would freeze the formation short of its equilibrium (about
/// 1e-4 rad of angle error and 3 mm of leader error in this scenario).
#[derive(Clone, Debug)]
pub struct Plant {
    /// Positions `q_i − v* t` (m), high part.
    p: [Vec2; N],
    /// Low part of the positions (the compensation of the sums).
    p_lo: [Vec2; N],
    /// Velocities relative to the frame, `v_i − v*` (m/s).
    w: [Vec2; N],
    /// Plant steps since the start ([`PLANT_HZ`] per second).
    pub ticks: u64,
}

impl Plant {
    /// The paper's initial state: `q(0)`, `v(0) = 0`, `t = 0`.
    pub fn paper() -> Self {
        let vs = paper::V_STAR;
        Plant {
            p: paper::INITIAL_POSITIONS,
            p_lo: [[0.0; 2]; N],
            w: [[-vs[0], -vs[1]]; N],
            ticks: 0,
        }
    }

    /// Time (s).
    pub fn time(&self) -> f32 {
        crate::hal::ticks_to_seconds(self.ticks, PLANT_HZ)
    }

    /// Velocity of robot `i` (m/s, world frame).
    pub fn velocity(&self, i: usize) -> Vec2 {
        let (w, vs) = (self.w[i], paper::V_STAR);
        [w[0] + vs[0], w[1] + vs[1]]
    }

    /// `v_i − v*` (m/s).
    pub fn velocity_error(&self, i: usize) -> Vec2 {
        self.w[i]
    }

    /// One RK4 step of `h` seconds with the forces `u` held constant.
    pub fn step(&mut self, u: &[Vec2; N], h: f32) {
        let robots = self
            .p
            .iter_mut()
            .zip(&mut self.p_lo)
            .zip(&mut self.w)
            .zip(u);
        for (((p, p_lo), w), f) in robots {
            for k in 0..2 {
                (p[k], p_lo[k], w[k]) = rk4_axis(p[k], p_lo[k], w[k], f[k], paper::V_STAR[k], h);
            }
        }
        self.ticks += 1;
    }

    /// `q_j − q_i` (m).
    pub fn offset(&self, i: usize, j: usize) -> Vec2 {
        let d = |k: usize| (self.p[j][k] - self.p[i][k]) + (self.p_lo[j][k] - self.p_lo[i][k]);
        [d(0), d(1)]
    }

    /// Unit bearing from robot `i` to robot `j`.
    pub fn bearing(&self, i: usize, j: usize) -> Vec2 {
        let d = self.offset(i, j);
        let r = (d[0] * d[0] + d[1] * d[1]).sqrt_fast();
        [d[0] / r, d[1] / r]
    }
}

/// One RK4 step of one axis of one robot: position `p` (with its Kahan
/// compensation `p_lo`) and velocity `w` relative to the frame moving at `vs`,
/// under the force `f`: `ṗ = w`, `m ẇ = f − D^r (vs + w)`.
fn rk4_axis(p: f32, p_lo: f32, w: f32, f: f32, vs: f32, h: f32) -> (f32, f32, f32) {
    let (m, d) = (paper::MASS, paper::FRICTION);
    let f = f - d * vs;
    let acc = |w: f32| (f - d * w) / m;
    let k1 = acc(w);
    let w2 = w + 0.5 * h * k1;
    let k2 = acc(w2);
    let w3 = w + 0.5 * h * k2;
    let k3 = acc(w3);
    let w4 = w + h * k3;
    let k4 = acc(w4);
    let dp = h / 6.0 * (w + 2.0 * w2 + 2.0 * w3 + w4);
    let w_next = w + h / 6.0 * (k1 + 2.0 * k2 + 2.0 * k3 + k4);
    // Kahan summation of the position.
    let y = dp + p_lo;
    let t = p + y;
    (t, y - (t - p), w_next)
}

/// How far the formation is from the paper's target.
#[derive(Clone, Copy, Debug, Default, PartialEq, defmt::Format)]
pub struct Metrics {
    /// Largest `|α − α*|` of the four controlled angles (rad; see
    /// [`paper::angle_error`]).
    pub angle_error: f32,
    /// `|(q1 − q2) − z*|` (m).
    pub leader_error: f32,
    /// Largest `|v_i − v*|` (m/s).
    pub velocity_error: f32,
}

impl Metrics {
    /// Evaluates the metrics on the true state.
    pub fn of(plant: &Plant) -> Self {
        let norm = |x: f32, y: f32| (x * x + y * y).sqrt_fast();
        let mut angle_error = 0.0f32;
        for a in &paper::ANGLES {
            let e = paper::angle_error(
                plant.bearing(a.apex, a.far[0]),
                plant.bearing(a.apex, a.far[1]),
                a.cos,
                a.sin,
            );
            angle_error = angle_error.max(e);
        }
        let z = plant.offset(1, 0); // q1 − q2
        let leader_error = norm(z[0] - paper::Z_STAR[0], z[1] - paper::Z_STAR[1]);
        let mut velocity_error = 0.0f32;
        for i in 0..N {
            let e = plant.velocity_error(i);
            velocity_error = velocity_error.max(norm(e[0], e[1]));
        }
        Metrics {
            angle_error,
            leader_error,
            velocity_error,
        }
    }

    /// Whether every metric is below the corresponding threshold.
    pub fn within(&self, angle: f32, leader: f32, velocity: f32) -> bool {
        self.angle_error < angle && self.leader_error < leader && self.velocity_error < velocity
    }
}

/// The bearing sensor of robot `me`.
#[derive(Debug)]
pub struct DemoBearings<'a> {
    plant: &'a Plant,
    me: usize,
}

impl BearingSensor for DemoBearings<'_> {
    type Error = DemoError;

    fn read_bearings(&mut self, out: &mut [Bearing]) -> Result<usize, Self::Error> {
        let mut n = 0;
        for j in (0..N).filter(|&j| j != self.me) {
            let Some(slot) = out.get_mut(n) else { break };
            *slot = Bearing::new(paper::IDS[j], self.plant.bearing(self.me, j));
            n += 1;
        }
        Ok(n)
    }

    fn partner_offset(&mut self) -> Result<Option<Vec2>, Self::Error> {
        Ok(match self.me {
            0 => Some(self.plant.offset(0, 1)),
            1 => Some(self.plant.offset(1, 0)),
            _ => None,
        })
    }
}

/// The velocity source of robot `me`.
#[derive(Debug)]
pub struct DemoVelocity<'a> {
    plant: &'a Plant,
    me: usize,
}

impl VelocitySource for DemoVelocity<'_> {
    type Error = DemoError;

    fn velocity(&mut self) -> Result<Vec2, Self::Error> {
        Ok(self.plant.velocity(self.me))
    }
}

/// The radio of robot `me` on the shared [`RadioBus`].
#[derive(Debug)]
pub struct DemoRadio<'a> {
    bus: &'a mut RadioBus,
    me: usize,
}

impl Radio for DemoRadio<'_> {
    type Error = DemoError;

    fn send(&mut self, frame: &[u8]) -> Result<(), Self::Error> {
        let mut p = Packet {
            from: self.me as u8,
            len: frame.len() as u8,
            bytes: [0; MAX_FRAME_LEN],
        };
        p.bytes
            .get_mut(..frame.len())
            .ok_or(DemoError::FrameTooLong)?
            .copy_from_slice(frame);
        self.bus.sent += 1;
        self.bus.air.push(p).map_err(|_| {
            self.bus.lost += 1;
            DemoError::AirFull
        })
    }

    fn receive(&mut self, buf: &mut [u8; MAX_FRAME_LEN]) -> Result<Option<usize>, Self::Error> {
        Ok(self.bus.inbox[self.me].pop_front().map(|p| {
            let len = usize::from(p.len);
            buf[..len].copy_from_slice(&p.bytes[..len]);
            len
        }))
    }
}

/// The actuator of one robot: sets the force the plant integrates.
#[derive(Debug)]
pub struct DemoActuator<'a> {
    force: &'a mut Vec2,
}

impl Actuator for DemoActuator<'_> {
    type Error = DemoError;

    fn apply_force(&mut self, force: Vec2) -> Result<(), Self::Error> {
        *self.force = force;
        Ok(())
    }
}

/// The plant's clock.
#[derive(Clone, Copy, Debug)]
pub struct DemoClock {
    ticks: u64,
}

impl Clock for DemoClock {
    fn tick_hz(&self) -> u32 {
        PLANT_HZ
    }

    fn now_ticks(&self) -> u64 {
        self.ticks
    }
}

/// The simulated world: plant, commanded forces, radio.
#[derive(Debug)]
pub struct World {
    /// True state.
    pub plant: Plant,
    /// Forces applied by the robots' actuators (held until their next tick).
    pub forces: [Vec2; N],
    /// The radio medium.
    pub radio: RadioBus,
}

impl World {
    /// The paper's initial state, no forces, nothing on the air.
    pub fn paper() -> Self {
        World {
            plant: Plant::paper(),
            forces: [[0.0; 2]; N],
            radio: RadioBus::default(),
        }
    }

    /// One control period: every robot runs one tick of its control loop
    /// (in id order, all at the same time instant), the frames they sent are
    /// delivered, then the plant advances by [`SUBSTEPS`] RK4 steps.
    pub fn control_period<const MT: usize, const NB: usize>(
        &mut self,
        loops: &mut [ControlLoop<MT, NB>; N],
    ) -> [TickReport; N] {
        let clock = DemoClock {
            ticks: self.plant.ticks,
        };
        let reports = core::array::from_fn(|me| {
            let mut board = Board {
                bearings: DemoBearings {
                    plant: &self.plant,
                    me,
                },
                velocity: DemoVelocity {
                    plant: &self.plant,
                    me,
                },
                radio: DemoRadio {
                    bus: &mut self.radio,
                    me,
                },
                actuator: DemoActuator {
                    force: &mut self.forces[me],
                },
                clock,
            };
            loops[me].tick(&mut board)
        });
        self.radio.deliver();
        let h = 1.0 / PLANT_HZ as f32;
        for _ in 0..SUBSTEPS {
            self.plant.step(&self.forces, h);
        }
        reports
    }
}
