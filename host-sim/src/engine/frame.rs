//! One frame on the air ([`RadioFrame`]): what the radio ([`super::radio`]), the shared
//! channel ([`super::channel`]), the attackers and the controllers pass between them, in
//! a module of its own so that each of them depends on it and none on another.

use ph_formation_core::wire::CrcCheck;
use ph_formation_core::MAX_FRAME_LEN;

/// One frame on the air: up to [`MAX_FRAME_LEN`] bytes, stored inline (no heap), with
/// its CRC check ([`CrcCheck`], for `crc16` frames), done once when the frame is made
/// (or corrupted) instead of once by every receiver: every copy of a broadcast carries
/// it ([`Self::crc_check`], `ph_formation_core::Agent::receive_checked`).
///
/// 64 bytes, aligned to 64: one cache line per frame.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[repr(align(64))]
pub struct RadioFrame {
    len: u8,
    bytes: [u8; MAX_FRAME_LEN],
    crc: Option<CrcCheck>,
}

// One cache line: the length byte, 60 bytes and the 3-byte check.
const _: () = assert!(std::mem::size_of::<RadioFrame>() == 64);

impl RadioFrame {
    /// Copies `bytes` (truncated to [`MAX_FRAME_LEN`]; the core never produces more) and
    /// checks their CRC if they are a `crc16` frame.
    pub fn new(bytes: &[u8]) -> Self {
        let mut f = Self::copy(bytes);
        f.crc = CrcCheck::of(f.as_bytes());
        f
    }

    /// Copies `bytes` (truncated to [`MAX_FRAME_LEN`]), without a CRC check.
    fn copy(bytes: &[u8]) -> Self {
        let n = bytes.len().min(MAX_FRAME_LEN);
        let mut f = Self {
            len: n as u8,
            bytes: [0; MAX_FRAME_LEN],
            crc: None,
        };
        if let (Some(dst), Some(src)) = (f.bytes.get_mut(..n), bytes.get(..n)) {
            dst.copy_from_slice(src);
        }
        f
    }

    /// A frame of `bytes` whose CRC check its writer gave
    /// (`ph_formation_core::Agent::frames_checked`).
    pub fn checked(bytes: &[u8], crc: Option<CrcCheck>) -> Self {
        let mut f = Self::copy(bytes);
        f.crc = crc;
        f
    }

    /// The frame's CRC check, if it is a `crc16` frame.
    pub fn crc_check(&self) -> Option<CrcCheck> {
        self.crc
    }

    /// The frame's bytes.
    pub fn as_bytes(&self) -> &[u8] {
        self.bytes.get(..usize::from(self.len)).unwrap_or(&[])
    }

    /// Flips bit `bit` (modulo the frame length in bits).
    pub(crate) fn flip(&mut self, bit: usize) {
        let n = usize::from(self.len) * 8;
        if n > 0 {
            let b = bit % n;
            if let Some(byte) = self.bytes.get_mut(b / 8) {
                *byte ^= 1 << (b % 8);
            }
            self.crc = CrcCheck::of(self.as_bytes());
        }
    }
}
