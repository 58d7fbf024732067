//! The `auth` integrity ([`super::Integrity::Auth`]): a pre-shared swarm key, a 64-bit
//! SipHash-2-4 tag over every frame and a 64-bit per-sender counter against replay.
//!
//! # Tag
//!
//! `tag = SipHash-2-4(key, counter ‖ frame)`: the 128-bit [`SwarmKey`], the sender's full
//! [`Counter`] as 8 bytes little-endian, then every byte of the frame before the tag
//! (header, velocity, items and the counter extension if any). The tag is the 64-bit
//! output, little-endian, in the last [`TAG_LEN`] bytes of the frame. It is compared in
//! constant time (`subtle`).
//!
//! # Counter
//!
//! A sender's counter is `epoch · 2³² + n`: its boot epoch (a `u32` the firmware keeps
//! in non-volatile memory and increments at every boot, see
//! [`crate::Agent::set_boot_epoch`]) and the number `n` of frames sent since boot. Only
//! the low 16 bits travel in every header (the sequence number); a frame with room for
//! it (at most 3 angle items) also carries the high 48 bits in a 6-byte extension
//! before the tag: `epoch` (`u32` LE) and `n >> 16` (`u16` LE). A receiver takes a
//! frame's counter from its extension, or, without one, as the counter nearest the last
//! one it accepted from that sender with the header's low 16 bits (within `−2¹⁵ … 2¹⁵`,
//! as SRTP does). A frame is accepted only if its counter is larger than the last one
//! accepted from that sender (and its tag verifies with it): every counter is accepted
//! at most once, and never out of order.
//!
//! A sender never reuses a counter: after `2³² − 1` frames in one boot it stops
//! broadcasting until it boots again with a larger epoch.

use subtle::ConstantTimeEq;

/// Bytes of the tag at the end of an `auth` frame.
pub const TAG_LEN: usize = 8;
/// Bytes of the counter extension (`epoch` `u32` LE, high 16 bits of the frame number
/// `u16` LE) that frames with room for it carry before the tag.
pub const COUNTER_EXT_LEN: usize = 6;

/// A sender's frame counter: `epoch · 2³² + frames sent since boot` (see the module
/// documentation).
pub type Counter = u64;

/// The full counter of a frame number `n` in boot epoch `epoch`.
pub const fn counter(epoch: u32, n: u32) -> Counter {
    ((epoch as u64) << 32) | n as u64
}

/// A counter stored as `[high, low]` 32-bit words: keeps the agent's alignment at 4
/// bytes on 32-bit targets (the C API promises it).
pub(crate) type StoredCounter = [u32; 2];

/// The stored form of a counter.
#[inline(always)]
pub(crate) const fn store(c: Counter) -> StoredCounter {
    [(c >> 32) as u32, c as u32]
}

/// The counter of its stored form.
#[inline(always)]
pub(crate) const fn load(s: StoredCounter) -> Counter {
    counter(s[0], s[1])
}

/// The counter with low 16 bits `seq` nearest to `last` (`last − 2¹⁵ … last + 2¹⁵ − 1`):
/// the counter of a frame without extension from a sender whose last accepted counter
/// is `last`.
#[inline]
pub const fn reconstruct(last: Counter, seq: u16) -> Counter {
    let ahead = seq.wrapping_sub(last as u16) as i16;
    last.wrapping_add_signed(ahead as i64)
}

/// A 128-bit pre-shared swarm key. Its `Debug`, `Display` and `defmt::Format` print
/// `<redacted>`; it is compared in constant time. It is serializable only so that a
/// configuration can be sent to a target over the host-in-the-loop link
/// ([`crate::link`]); never log a serialized configuration.
#[derive(Clone, Copy, serde::Serialize, serde::Deserialize)]
pub struct SwarmKey([u8; 16]);

impl SwarmKey {
    /// The key with these bytes (SipHash's `k0 ‖ k1`, little-endian).
    pub const fn new(bytes: [u8; 16]) -> Self {
        Self(bytes)
    }

    /// The key bytes, for storing the key (never for logging it).
    pub const fn expose_secret(&self) -> &[u8; 16] {
        &self.0
    }
}

impl PartialEq for SwarmKey {
    fn eq(&self, other: &Self) -> bool {
        self.0.ct_eq(&other.0).into()
    }
}

impl Eq for SwarmKey {}

impl core::fmt::Debug for SwarmKey {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        f.write_str("SwarmKey(<redacted>)")
    }
}

impl core::fmt::Display for SwarmKey {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        f.write_str("<redacted>")
    }
}

#[cfg(feature = "defmt")]
impl defmt::Format for SwarmKey {
    fn format(&self, f: defmt::Formatter<'_>) {
        defmt::write!(f, "SwarmKey(<redacted>)");
    }
}

/// SipHash-2-4 of the concatenation of `parts` under `key`, the 64-bit output as 8 bytes
/// little-endian (the byte order of the reference implementation's test vectors).
#[inline]
pub fn siphash24(key: &SwarmKey, parts: &[&[u8]]) -> [u8; TAG_LEN] {
    use core::hash::Hasher;
    let mut h = siphasher::sip::SipHasher24::new_with_key(&key.0);
    for p in parts {
        h.write(p);
    }
    h.finish().to_le_bytes()
}

/// The tag of a frame whose bytes before the tag are `signed`, sent with `counter`.
#[inline]
pub fn tag(key: &SwarmKey, counter: Counter, signed: &[u8]) -> [u8; TAG_LEN] {
    siphash24(key, &[&counter.to_le_bytes(), signed])
}

/// Whether `received` is the tag of `signed` with `counter`, compared in constant time:
/// as one 64-bit word (`subtle`'s `u64` comparison; the same answer as comparing the 8
/// bytes, with one optimisation barrier instead of one per byte: about 70 instructions
/// less per verified frame on the Cortex-M4).
#[inline]
pub fn verify(key: &SwarmKey, counter: Counter, signed: &[u8], received: &[u8; TAG_LEN]) -> bool {
    let expected = u64::from_le_bytes(tag(key, counter, signed));
    expected.ct_eq(&u64::from_le_bytes(*received)).into()
}
