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
}

/// A sensor that measures bearings (directions, no distances) to neighbours.
pub trait BearingSensor {
    /// Error reported by the sensor.
    type Error;

    /// Writes the latest bearings into `out` and returns how many were
    /// written (at most `out.len()`; extra neighbours are dropped).
    ///
    /// Non-blocking: returns the most recent measurements, which may be the
    /// same as in the previous call.
    fn read_bearings(&mut self, out: &mut [Bearing]) -> Result<usize, Self::Error>;
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
        let ticks = self.now_ticks().saturating_sub(earlier);
        let ticks = u32::try_from(ticks).unwrap_or(u32::MAX);
        ticks as f32 / self.tick_hz() as f32
    }
}
