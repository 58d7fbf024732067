//! Trivial implementations of the [`hal`](crate::hal) traits.
//!
//! They let the `firmware-example` binary run the application loop under
//! QEMU without any peripherals, and show the shape of a port. Everything is
//! deterministic: the clock advances by one tick per read.

use crate::hal::{
    Actuator, Bearing, BearingSensor, Clock, Radio, Vec2, VelocitySource, MAX_FRAME_LEN,
};

/// Error of the stand-in drivers.
#[derive(Clone, Copy, Debug, PartialEq, Eq, defmt::Format)]
pub enum StandInError {
    /// A frame longer than [`MAX_FRAME_LEN`] was sent.
    FrameTooLong,
}

/// A clock that advances by one tick every time it is read (stands in for a
/// free-running hardware timer, so that [`run_agent`](crate::app::run_agent)
/// can wait on it without interrupts).
#[derive(Debug)]
pub struct PollClock {
    ticks: core::cell::Cell<u64>,
    hz: u32,
}

impl PollClock {
    /// A clock at tick 0 with `hz` ticks per second.
    pub const fn new(hz: u32) -> Self {
        PollClock {
            ticks: core::cell::Cell::new(0),
            hz,
        }
    }
}

impl Clock for PollClock {
    fn tick_hz(&self) -> u32 {
        self.hz
    }

    fn now_ticks(&self) -> u64 {
        let t = self.ticks.get();
        self.ticks.set(t + 1);
        t
    }
}

/// Bearings to fixed neighbours from a fixed position.
#[derive(Debug)]
pub struct FixedBearings {
    /// Id of the neighbour of `directions[0]`; the others follow.
    pub first_id: u8,
    /// Directions to report, to neighbours `first_id`, `first_id + 1`, ….
    pub directions: [Vec2; 3],
}

impl BearingSensor for FixedBearings {
    type Error = StandInError;

    fn read_bearings(&mut self, out: &mut [Bearing]) -> Result<usize, Self::Error> {
        let n = out.len().min(self.directions.len());
        for (i, (slot, dir)) in out.iter_mut().zip(&self.directions).enumerate() {
            *slot = Bearing::new(self.first_id + i as u8, *dir);
        }
        Ok(n)
    }
}

/// A velocity source that reports a settable velocity.
#[derive(Debug, Default)]
pub struct FixedVelocity {
    /// Current velocity, m/s.
    pub velocity: Vec2,
}

impl VelocitySource for FixedVelocity {
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
