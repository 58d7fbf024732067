//! Counters of received frames, by outcome.

use crate::wire::FrameError;

/// How many frames were accepted, and how many were rejected for each reason.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct FrameStats {
    /// Accepted frames.
    pub accepted: u32,
    /// Too short or too long.
    pub bad_length: u32,
    /// CRC mismatch.
    pub bad_crc: u32,
    /// Unknown wire version.
    pub unknown_version: u32,
    /// Integrity or estimator mode different from this agent's.
    pub mode_mismatch: u32,
    /// Undecodable body.
    pub malformed: u32,
    /// Sender not a neighbour, or this agent itself.
    pub unknown_sender: u32,
    /// Stale or repeated sequence number.
    pub stale: u32,
    /// Non-finite or out-of-range values.
    pub invalid_value: u32,
    /// `auth`: tag does not verify.
    pub bad_tag: u32,
    /// `auth`: counter not newer than the sender's last accepted one.
    pub replayed: u32,
    /// `auth`: no counter known for the sender and none in the frame.
    pub unsynced: u32,
}

impl FrameStats {
    /// Counts one receive outcome.
    pub fn record(&mut self, result: &Result<(), FrameError>) {
        let c = match result {
            Ok(()) => &mut self.accepted,
            Err(FrameError::TooShort | FrameError::TooLong) => &mut self.bad_length,
            Err(FrameError::BadCrc) => &mut self.bad_crc,
            Err(FrameError::UnknownVersion(_)) => &mut self.unknown_version,
            Err(FrameError::ModeMismatch(_)) => &mut self.mode_mismatch,
            Err(FrameError::Malformed | FrameError::Cobs) => &mut self.malformed,
            Err(FrameError::UnknownSender(_) | FrameError::OwnFrame) => &mut self.unknown_sender,
            Err(FrameError::StaleSequence { .. }) => &mut self.stale,
            Err(FrameError::InvalidValue) => &mut self.invalid_value,
            Err(FrameError::BadTag) => &mut self.bad_tag,
            Err(FrameError::Replayed { .. }) => &mut self.replayed,
            Err(FrameError::Unsynced(_)) => &mut self.unsynced,
        };
        *c = c.saturating_add(1);
    }

    /// All rejected frames.
    pub fn rejected(&self) -> u32 {
        self.bad_length
            .saturating_add(self.bad_crc)
            .saturating_add(self.unknown_version)
            .saturating_add(self.mode_mismatch)
            .saturating_add(self.malformed)
            .saturating_add(self.unknown_sender)
            .saturating_add(self.stale)
            .saturating_add(self.invalid_value)
            .saturating_add(self.bad_tag)
            .saturating_add(self.replayed)
            .saturating_add(self.unsynced)
    }
}
