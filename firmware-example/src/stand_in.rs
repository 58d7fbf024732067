//! Trivial implementations of the [`hal`](crate::hal) traits.
//!
//! They let the demo binary run the application loop under QEMU without any
//! peripherals, and show the shape of a port. Everything is deterministic:
//! the "world" advances by one tick per [`StepClock::advance`].

use crate::hal::{
    Actuator, Bearing, BearingSensor, Clock, Radio, Vec2, VelocitySource, MAX_FRAME_LEN,
};

/// Error of the stand-in drivers.
#[derive(Clone, Copy, Debug, PartialEq, Eq, defmt::Format)]
pub enum StandInError {
    /// A frame longer than [`MAX_FRAME_LEN`] was sent.
    FrameTooLong,
}

/// A clock that advances only when told to: one tick per control step.
#[derive(Debug)]
pub struct StepClock {
    ticks: u64,
    hz: u32,
}

impl StepClock {
    /// A clock at tick 0 with `hz` ticks per second.
    pub const fn new(hz: u32) -> Self {
        StepClock { ticks: 0, hz }
    }

    /// Advances by one tick.
    pub fn advance(&mut self) {
        self.ticks += 1;
    }
}

impl Clock for StepClock {
    fn tick_hz(&self) -> u32 {
        self.hz
    }

    fn now_ticks(&self) -> u64 {
        self.ticks
    }
}

/// Bearings to fixed neighbours from a fixed position.
#[derive(Debug)]
pub struct FixedBearings {
    /// Directions to report, indexed by neighbour id.
    pub directions: [Vec2; 3],
}

impl BearingSensor for FixedBearings {
    type Error = StandInError;

    fn read_bearings(&mut self, out: &mut [Bearing]) -> Result<usize, Self::Error> {
        let n = out.len().min(self.directions.len());
        for (i, (slot, dir)) in out.iter_mut().zip(&self.directions).enumerate() {
            *slot = Bearing {
                neighbour: i as u8,
                direction: *dir,
            };
        }
        Ok(n)
    }
}

/// A velocity source that integrates the applied force of a unit mass
/// (fed by [`RecordingActuator`]).
#[derive(Debug, Default)]
pub struct IntegratedVelocity {
    /// Current velocity, m/s.
    pub velocity: Vec2,
}

impl VelocitySource for IntegratedVelocity {
    type Error = StandInError;

    fn velocity(&mut self) -> Result<Vec2, Self::Error> {
        Ok(self.velocity)
    }
}

/// A radio that delivers every sent frame back to itself (one-frame queue).
#[derive(Debug)]
pub struct LoopbackRadio {
    buf: [u8; MAX_FRAME_LEN],
    len: Option<usize>,
}

impl LoopbackRadio {
    /// An empty loopback radio.
    pub const fn new() -> Self {
        LoopbackRadio {
            buf: [0; MAX_FRAME_LEN],
            len: None,
        }
    }
}

impl Default for LoopbackRadio {
    fn default() -> Self {
        Self::new()
    }
}

impl Radio for LoopbackRadio {
    type Error = StandInError;

    fn send(&mut self, frame: &[u8]) -> Result<(), Self::Error> {
        let dst = self
            .buf
            .get_mut(..frame.len())
            .ok_or(StandInError::FrameTooLong)?;
        dst.copy_from_slice(frame);
        self.len = Some(frame.len());
        Ok(())
    }

    fn receive(&mut self, buf: &mut [u8; MAX_FRAME_LEN]) -> Result<Option<usize>, Self::Error> {
        let pending = self.len.take();
        if let Some(n) = pending {
            buf[..n].copy_from_slice(&self.buf[..n]);
        }
        Ok(pending)
    }
}

/// An actuator that records the last applied force.
#[derive(Debug, Default)]
pub struct RecordingActuator {
    /// Last applied force, N.
    pub last: Vec2,
}

impl Actuator for RecordingActuator {
    type Error = StandInError;

    fn apply_force(&mut self, force: Vec2) -> Result<(), Self::Error> {
        self.last = force;
        Ok(())
    }
}
