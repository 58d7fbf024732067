//! A frame's CRC-16 checked once for several receivers ([`CrcCheck`]).

use super::{items_of_mode, Integrity, MAX_FRAME_LEN};
use crate::crc16;
use core::num::NonZeroU8;

/// The result of the CRC-16 check of one `crc16` frame, computed once
/// ([`CrcCheck::of`]) for bytes that several receivers take in: a simulator delivers each
/// broadcast to every agent in radio range, and each would compute the same CRC of the
/// same bytes. `Agent::receive_checked` (feature `sim`) uses it instead of computing the CRC
/// again, and only for the bytes it was computed from (same length and trailer;
/// otherwise it computes the CRC itself). Everything else about the frame is checked by
/// each receiver as in [`crate::Agent::receive`], with the same result.
///
/// A microcontroller hears each frame once: it calls [`crate::Agent::receive`].
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct CrcCheck {
    /// Its last two bytes (the CRC it carries).
    trailer: [u8; 2],
    /// Bits 0–6: the frame's length (2 ..= [`MAX_FRAME_LEN`], so never zero); bit 7: the
    /// CRC-16 of the bytes before the trailer equals the trailer. (Three bytes in all,
    /// `Option<CrcCheck>` too: a simulator's frame of 60 bytes, its length and its check
    /// fit one 64-byte cache line.)
    len_ok: NonZeroU8,
}

/// Bit 7 of [`CrcCheck::len_ok`].
const OK: u8 = 0x80;

/// The integrity bits of the mode byte (3–2).
const INTEGRITY_BITS: u8 = 0b1100;

impl CrcCheck {
    /// The CRC check of `bytes` if they are a version-4 `crc16` frame of at most
    /// [`MAX_FRAME_LEN`] bytes (mode byte and length); `None` otherwise (then a
    /// receiver checks the frame itself, as always).
    pub fn of(bytes: &[u8]) -> Option<Self> {
        let mode = *bytes.first()?;
        if items_of_mode(mode).is_none() || mode & INTEGRITY_BITS != Integrity::Crc16.code() << 2 {
            return None;
        }
        let (body, trailer) = bytes.split_last_chunk::<2>()?;
        Self::new(bytes, crc16::checksum(body) == u16::from_le_bytes(*trailer))
    }

    /// The check of a frame this crate has just finished (its trailer is its CRC, by
    /// construction): no CRC computed. (For `Agent::frames_checked`, feature `sim`.)
    #[cfg(any(feature = "sim", test))]
    pub(crate) fn written(bytes: &[u8]) -> Option<Self> {
        Self::new(bytes, true)
    }

    /// The check of `bytes` with the CRC's result `ok`; `None` for lengths outside
    /// 2 ..= [`MAX_FRAME_LEN`].
    fn new(bytes: &[u8], ok: bool) -> Option<Self> {
        let trailer = *bytes.last_chunk::<2>()?;
        // 2 ..= 60: fits bits 0–6 and is not zero.
        let len = u8::try_from(bytes.len())
            .ok()
            .filter(|&n| usize::from(n) <= MAX_FRAME_LEN)?;
        Some(Self {
            trailer,
            len_ok: NonZeroU8::new(len | if ok { OK } else { 0 })?,
        })
    }

    /// The check's result if it was computed from `bytes` (same length and trailer).
    /// (For `Agent::receive_checked`, feature `sim`.)
    #[cfg(any(feature = "sim", test))]
    #[inline]
    pub(crate) fn result_for(&self, bytes: &[u8]) -> Option<bool> {
        let len_ok = self.len_ok.get();
        let same = usize::from(len_ok & !OK) == bytes.len()
            && bytes.last_chunk::<2>().is_some_and(|t| *t == self.trailer);
        same.then_some(len_ok & OK != 0)
    }
}
