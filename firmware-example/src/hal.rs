//! Application-facing hardware traits.
//!
//! The formation application is generic over these five traits, so porting
//! it to a robot means implementing them for that robot's drivers (see
//! `docs/firmware.md`). They are deliberately small, synchronous and
//! non-blocking: the application calls them once per control step from its
//! main loop.
//!
//! Conventions:
//! * Units are SI (metres, seconds, newtons, radians).
//! * 2-D vectors are `[x, y]` in `f32` ([`Vec2`]); the FPU of a Cortex-M4F
//!   does single precision only, so nothing here uses `f64`.
//! * Every trait has its own `Error` type, left unconstrained; an
//!   application that logs errors adds its own bound (e.g. `defmt::Format`).

/// A 2-D vector `[x, y]`.
pub type Vec2 = [f32; 2];

/// Largest payload of one radio frame, in bytes.
///
/// This is the Crazyflie peer-to-peer limit; [`Radio`] implementations must
/// accept any frame up to this length.
pub const MAX_FRAME_LEN: usize = 60;

/// One bearing measurement to a neighbour.
#[derive(Clone, Copy, Debug, PartialEq, defmt::Format)]
pub struct Bearing {
    /// Identifier of the neighbour the bearing points to.
    pub neighbour: u8,
    /// Unit vector from this robot towards the neighbour, in the world frame
    /// (rotate body-frame measurements with the robot's attitude first).
    pub direction: Vec2,
    /// The bearing's rate of change (1/s), if the sensor measures it (e.g.
    /// optical flow). `None`: the controller takes the finite difference of
    /// successive bearings.
    pub rate: Option<Vec2>,
    /// The distance to the neighbour (m), if the robot has a range sensor
    /// (only used by the controller's `Measured` estimator mode).
    pub range: Option<f32>,
}

impl Bearing {
    /// A bearing without rate or range: what most sensors give.
    pub const fn new(neighbour: u8, direction: Vec2) -> Self {
        Bearing {
            neighbour,
            direction,
            rate: None,
            range: None,
        }
    }
}

impl Default for Bearing {
    fn default() -> Self {
        Bearing::new(0, [0.0; 2])
    }
}

/// A sensor that measures bearings (directions, no distances) to neighbours.
pub trait BearingSensor {
    /// Error reported by the sensor.
    type Error;

    /// Writes the latest bearings into `out` and returns how many were
    /// written (at most `out.len()`; extra neighbours are dropped).
    ///
    /// Non-blocking: returns the most recent measurements, which may be the
    /// same as in the previous call. Bearings to robots that are not this
    /// agent's neighbours are allowed (the control loop ignores them).
    fn read_bearings(&mut self, out: &mut [Bearing]) -> Result<usize, Self::Error>;

    /// Leaders only: the position of the leader partner minus this robot's
    /// own (m, world frame), from a relative-position sensor (SPEC S11).
    ///
    /// The default is `Ok(None)`: robots that are not leaders need not
    /// implement it. A leader without it gets the controller's safe output.
    fn partner_offset(&mut self) -> Result<Option<Vec2>, Self::Error> {
        Ok(None)
    }
}

/// A source of this robot's own velocity estimate (e.g. the state estimator
/// of the flight controller).
pub trait VelocitySource {
    /// Error reported by the source.
    type Error;

    /// Current velocity in the world frame, in m/s.
    fn velocity(&mut self) -> Result<Vec2, Self::Error>;
}

/// A broadcast radio carrying small byte frames between robots.
///
/// Frames are unacknowledged and may be lost; nothing here retries.
pub trait Radio {
    /// Error reported by the radio.
    type Error;

    /// Queues `frame` (at most [`MAX_FRAME_LEN`] bytes) for broadcast.
    ///
    /// Non-blocking. Implementations return an error for an over-long frame
    /// or a full transmit queue rather than waiting.
    fn send(&mut self, frame: &[u8]) -> Result<(), Self::Error>;

    /// Takes the oldest received frame, if any, copying it into `buf`.
    ///
    /// Returns `Ok(Some(len))` with the frame in `buf[..len]`, or `Ok(None)`
    /// when nothing is pending. Non-blocking.
    fn receive(&mut self, buf: &mut [u8; MAX_FRAME_LEN]) -> Result<Option<usize>, Self::Error>;
}

/// The actuator that turns a commanded 2-D force into motion (for a
/// quadrotor: a setpoint for its position/attitude controller).
pub trait Actuator {
    /// Error reported by the actuator.
    type Error;

    /// Applies `force` (world frame, newtons) until the next call.
    fn apply_force(&mut self, force: Vec2) -> Result<(), Self::Error>;
}

/// A monotonic clock.
pub trait Clock {
    /// Ticks per second of [`Clock::now_ticks`].
    fn tick_hz(&self) -> u32;

    /// Ticks since boot. Monotonic: never decreases (a `u64` does not wrap
    /// in practice).
    fn now_ticks(&self) -> u64;

    /// Seconds elapsed since the tick count `earlier` (0 if `earlier` is in
    /// the future). Precise for intervals below `u32::MAX` ticks.
    fn seconds_since(&self, earlier: u64) -> f32 {
        ticks_to_seconds(self.now_ticks().saturating_sub(earlier), self.tick_hz())
    }

    /// Seconds since boot (for the controller's schedules `v*(t)`, `z*(t)`).
    fn seconds(&self) -> f32 {
        ticks_to_seconds(self.now_ticks(), self.tick_hz())
    }
}

/// `ticks / hz` in seconds, in `f32` without 64-bit float conversions
/// (whole seconds and the remainder are converted separately).
pub fn ticks_to_seconds(ticks: u64, hz: u32) -> f32 {
    let hz64 = u64::from(hz.max(1));
    let whole = u32::try_from(ticks / hz64).unwrap_or(u32::MAX);
    // `ticks % hz64 < hz`, so it fits in a `u32`.
    let frac = (ticks % hz64) as u32;
    whole as f32 + frac as f32 / hz.max(1) as f32
}
