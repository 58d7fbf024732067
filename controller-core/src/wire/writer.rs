//! Building frames (layout in [`super`]).

use super::{offset, Integrity, ANGLE_ITEM_LEN, FIXED_LEN, MAX_FRAME_LEN};
use crate::{crc16, AgentId};

/// Writes `bytes` at `at` (in bounds by construction of every caller; out-of-bounds
/// writes are dropped, never a panic).
#[inline(always)]
fn put<const N: usize>(buf: &mut [u8], at: usize, bytes: [u8; N]) {
    if let Some(d) = buf.get_mut(at..at + N) {
        d.copy_from_slice(&bytes);
    }
}

/// Builds one frame at a time: [`FrameWriter::start`] (header and velocity), then
/// [`FrameWriter::push_angle`] while it fits, then [`FrameWriter::finish`] (trailer).
/// The buffer is reused from frame to frame (no zeroing).
#[derive(Clone, Debug)]
pub struct FrameWriter {
    buf: [u8; MAX_FRAME_LEN],
    len: usize,
    integrity: Integrity,
}

impl FrameWriter {
    /// A writer for frames with `integrity`.
    pub const fn new(integrity: Integrity) -> Self {
        Self {
            buf: [0; MAX_FRAME_LEN],
            len: 0,
            integrity,
        }
    }

    /// Starts a frame: the mode byte, sender, sequence number and velocity.
    #[inline]
    pub fn start(&mut self, mode: u8, sender: AgentId, seq: u16, velocity: [f32; 2]) {
        let b = &mut self.buf;
        put(b, offset::MODE, [mode, sender]);
        put(b, offset::SEQ, seq.to_le_bytes());
        put(b, offset::VELOCITY, velocity[0].to_le_bytes());
        put(b, offset::VELOCITY + 4, velocity[1].to_le_bytes());
        self.len = FIXED_LEN;
    }

    /// Appends one angle item: far vertices and the binary16 codes (see [`super::quant`])
    /// of `[γ, σ, ρ_v, ρ_w]`; `false`, and nothing written, if the frame is full.
    #[inline]
    pub fn push_angle(&mut self, far: [AgentId; 2], codes: [u16; 4]) -> bool {
        if self.len + ANGLE_ITEM_LEN + self.integrity.trailer_len() > MAX_FRAME_LEN {
            return false;
        }
        let at = self.len;
        let b = &mut self.buf;
        put(b, at + offset::ITEM_FAR0, far);
        put(b, at + offset::ITEM_GAMMA, codes[0].to_le_bytes());
        put(b, at + offset::ITEM_SIGMA, codes[1].to_le_bytes());
        put(b, at + offset::ITEM_RHO0, codes[2].to_le_bytes());
        put(b, at + offset::ITEM_RHO1, codes[3].to_le_bytes());
        self.len += ANGLE_ITEM_LEN;
        true
    }

    /// Angle items in the current frame.
    pub fn angles(&self) -> usize {
        (self.len.saturating_sub(FIXED_LEN)) / ANGLE_ITEM_LEN
    }

    /// Appends the integrity trailer and returns the finished frame.
    #[inline]
    pub fn finish(&mut self) -> &[u8] {
        let body = self.len;
        if self.integrity == Integrity::Crc16 {
            let crc = crc16::checksum(self.buf.get(..body).unwrap_or(&[]));
            put(&mut self.buf, body, crc.to_le_bytes());
        }
        let end = body + self.integrity.trailer_len();
        self.buf.get(..end).unwrap_or(&[])
    }
}
