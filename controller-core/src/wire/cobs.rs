//! COBS framing of frames and link messages on byte streams (UART): each chunk is
//! COBS-encoded and ends with a `0` delimiter.

use super::{FrameError, MAX_FRAME_LEN};

/// Largest COBS-encoded frame including the trailing zero delimiter.
pub const MAX_COBS_LEN: usize = MAX_FRAME_LEN + MAX_FRAME_LEN / 254 + 2;

/// COBS-encodes `frame` into `out` and appends the `0` delimiter; returns the length.
pub fn cobs_encode(frame: &[u8], out: &mut [u8]) -> Option<usize> {
    let n = cobs::try_encode(frame, out).ok()?;
    let end = out.get_mut(n)?;
    *end = 0;
    Some(n + 1)
}

/// Decodes one COBS chunk (without its `0` delimiter) into `out`; returns the length.
pub fn cobs_decode(chunk: &[u8], out: &mut [u8]) -> Result<usize, FrameError> {
    if chunk.len() > out.len() + 1 {
        return Err(FrameError::TooLong);
    }
    cobs::decode(chunk, out).map_err(|_| FrameError::Cobs)
}

/// Splits a byte stream at `0` delimiters and COBS-decodes each chunk (for UARTs).
#[derive(Clone, Debug)]
pub struct CobsAccumulator<const N: usize> {
    buf: [u8; N],
    len: usize,
    overflow: bool,
}

impl<const N: usize> Default for CobsAccumulator<N> {
    fn default() -> Self {
        Self {
            buf: [0; N],
            len: 0,
            overflow: false,
        }
    }
}

impl<const N: usize> CobsAccumulator<N> {
    /// An empty accumulator.
    pub fn new() -> Self {
        Self::default()
    }

    /// Feeds one byte. At a delimiter, returns the decoded frame (written to `out`) or an
    /// error for a chunk that overflowed `N` bytes or does not decode.
    pub fn push(&mut self, byte: u8, out: &mut [u8]) -> Option<Result<usize, FrameError>> {
        if byte == 0 {
            let result = if self.overflow {
                Err(FrameError::TooLong)
            } else {
                cobs_decode(self.buf.get(..self.len).unwrap_or(&[]), out)
            };
            self.len = 0;
            self.overflow = false;
            return Some(result);
        }
        match self.buf.get_mut(self.len) {
            Some(slot) => {
                *slot = byte;
                self.len += 1;
            }
            None => self.overflow = true,
        }
        None
    }
}
