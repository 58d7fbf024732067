//! The position packet: one agent's position estimate, broadcast every tick so that its
//! neighbours compute their bearings from shared positions (the Crazyflie app's P2P
//! port 1; host-sim's `sensors.bearing_source = "shared_positions"`), protected like the
//! formation's frames ([`Integrity`]).
//!
//! Layout (little-endian):
//!
//! | bytes | field |
//! |---|---|
//! | 0 | [`POSITION_VERSION`] |
//! | 1 | integrity code ([`Integrity::code`]) |
//! | 2 | sender id |
//! | 3–6, 7–10 | `x`, `y` (m, `f32`) |
//! | `auth`: 11–18 | the sender's counter ([`auth::Counter`], 64 bits: never reconstructed) |
//! | trailer | `crc16`: CRC-16 of the bytes before (2); `link`: none; `auth`: SipHash-2-4 tag over the counter and the bytes before (8) |
//!
//! So 13 bytes with `crc16`, 11 with `link`, 27 with `auth`. A receiver refuses a packet
//! of another integrity, a bad CRC or tag, a non-finite position, and (`auth`) a counter
//! not above the last one it accepted from that sender ([`accept_counter`]): a spoofed
//! position fails the tag, a replayed one the counter.

use super::auth::{self, Counter, TAG_LEN};
use super::Integrity;
use crate::crc16;

/// Version byte of the position packet (1 was the Crazyflie app's unprotected
/// 10-byte packet).
pub const POSITION_VERSION: u8 = 2;
/// Bytes before the counter or trailer.
const BODY: usize = 11;
/// The longest packet (`auth`).
pub const MAX_POSITION_LEN: usize = BODY + 8 + TAG_LEN;

/// One agent's position.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PositionPacket {
    /// The sender's wire id.
    pub sender: u8,
    /// Its position estimate (m, world frame).
    pub position: [f32; 2],
}

/// Why a position packet was refused.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum PositionError {
    /// Not a position packet of this version and length for the integrity mode.
    Malformed,
    /// Sent with another integrity mode.
    ModeMismatch,
    /// `crc16`: the CRC does not match.
    BadCrc,
    /// `auth`: the tag does not verify (a spoofed or corrupted packet).
    BadTag,
    /// `auth`: the counter is not above the last accepted one (a replay).
    Replayed,
    /// A coordinate is not finite.
    NonFinite,
    /// The output buffer is too short.
    BufferTooSmall,
}

/// The packet's length under `integrity`.
pub const fn position_len(integrity: &Integrity) -> usize {
    match integrity {
        Integrity::Crc16 => BODY + 2,
        Integrity::Link => BODY,
        Integrity::Auth(_) => BODY + 8 + TAG_LEN,
    }
}

impl PositionPacket {
    /// Writes the packet into `out` (`counter`: the sender's next counter, used with
    /// `auth` only; the caller increments it per packet). Returns its length.
    pub fn encode(
        &self,
        integrity: &Integrity,
        counter: Counter,
        out: &mut [u8],
    ) -> Result<usize, PositionError> {
        let len = position_len(integrity);
        let out = out.get_mut(..len).ok_or(PositionError::BufferTooSmall)?;
        let (body, rest) = out.split_at_mut(BODY);
        body.copy_from_slice(&self.body(integrity));
        match integrity {
            Integrity::Crc16 => rest.copy_from_slice(&crc16::checksum(body).to_le_bytes()),
            Integrity::Link => {}
            Integrity::Auth(key) => {
                let (c, t) = rest.split_at_mut(8);
                c.copy_from_slice(&counter.to_le_bytes());
                t.copy_from_slice(&auth::tag(key, counter, body));
            }
        }
        Ok(len)
    }

    fn body(&self, integrity: &Integrity) -> [u8; BODY] {
        let mut b = [0u8; BODY];
        let [x, y] = self.position;
        let (head, xy) = b.split_at_mut(3);
        head.copy_from_slice(&[POSITION_VERSION, integrity.code(), self.sender]);
        let (bx, by) = xy.split_at_mut(4);
        bx.copy_from_slice(&x.to_le_bytes());
        by.copy_from_slice(&y.to_le_bytes());
        b
    }

    /// Reads a packet sent with `integrity`: the position and (`auth`) its counter,
    /// which the receiver checks with [`accept_counter`] against the sender's last.
    pub fn decode(
        bytes: &[u8],
        integrity: &Integrity,
    ) -> Result<(Self, Option<Counter>), PositionError> {
        if bytes.first() != Some(&POSITION_VERSION) {
            return Err(PositionError::Malformed);
        }
        if bytes.get(1) != Some(&integrity.code()) {
            return Err(PositionError::ModeMismatch);
        }
        if bytes.len() != position_len(integrity) {
            return Err(PositionError::Malformed);
        }
        let (body, rest) = bytes.split_at(BODY);
        let counter = match integrity {
            Integrity::Crc16 => {
                if rest != crc16::checksum(body).to_le_bytes() {
                    return Err(PositionError::BadCrc);
                }
                None
            }
            Integrity::Link => None,
            Integrity::Auth(key) => {
                let (c, t) = rest.split_at(8);
                let c: [u8; 8] = c.try_into().map_err(|_| PositionError::Malformed)?;
                let t: [u8; TAG_LEN] = t.try_into().map_err(|_| PositionError::Malformed)?;
                let counter = Counter::from_le_bytes(c);
                if !auth::verify(key, counter, body, &t) {
                    return Err(PositionError::BadTag);
                }
                Some(counter)
            }
        };
        let f = |k: usize| -> Result<f32, PositionError> {
            let w: [u8; 4] = body
                .get(k..k + 4)
                .and_then(|s| s.try_into().ok())
                .ok_or(PositionError::Malformed)?;
            let x = f32::from_le_bytes(w);
            if x.is_finite() {
                Ok(x)
            } else {
                Err(PositionError::NonFinite)
            }
        };
        let sender = *body.get(2).ok_or(PositionError::Malformed)?;
        Ok((
            Self {
                sender,
                position: [f(3)?, f(7)?],
            },
            counter,
        ))
    }
}

/// `auth`: accepts `counter` from a sender whose last accepted counter is `*last`
/// (`None`: none yet) when it is larger, and records it; a replay leaves `*last` as it
/// was. Without `auth` (`counter` `None`) every packet is accepted.
pub fn accept_counter(last: &mut Option<Counter>, counter: Option<Counter>) -> bool {
    match (counter, *last) {
        (None, _) => true,
        (Some(c), Some(l)) if c <= l => false,
        (Some(c), _) => {
            *last = Some(c);
            true
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::SwarmKey;

    const KEY: SwarmKey = SwarmKey::new(*b"position key 16b");
    const P: PositionPacket = PositionPacket {
        sender: 7,
        position: [1.25, -0.5],
    };

    fn modes() -> [Integrity; 3] {
        [Integrity::Crc16, Integrity::Link, Integrity::Auth(KEY)]
    }

    #[test]
    fn round_trips_in_every_mode_with_its_length() {
        for (m, len) in modes().into_iter().zip([13, 11, 27]) {
            let mut b = [0u8; MAX_POSITION_LEN];
            let n = P.encode(&m, 5, &mut b).unwrap();
            assert_eq!(n, len, "{m}");
            let (q, c) = PositionPacket::decode(&b[..n], &m).unwrap();
            assert_eq!(q, P);
            assert_eq!(c, matches!(m, Integrity::Auth(_)).then_some(5));
        }
    }

    #[test]
    fn corruption_and_spoofing_are_refused() {
        for m in [Integrity::Crc16, Integrity::Auth(KEY)] {
            let mut b = [0u8; MAX_POSITION_LEN];
            let n = P.encode(&m, 5, &mut b).unwrap();
            // A spoofed position: another x with the original trailer.
            b[3] ^= 0x40;
            let e = PositionPacket::decode(&b[..n], &m).unwrap_err();
            assert_eq!(
                e,
                if m == Integrity::Crc16 {
                    PositionError::BadCrc
                } else {
                    PositionError::BadTag
                }
            );
        }
        // A forger without the key signs with another one.
        let mut b = [0u8; MAX_POSITION_LEN];
        let wrong = Integrity::Auth(SwarmKey::new(*b"not the swarm ke"));
        let n = P.encode(&wrong, 99, &mut b).unwrap();
        assert_eq!(
            PositionPacket::decode(&b[..n], &Integrity::Auth(KEY)).unwrap_err(),
            PositionError::BadTag
        );
        // Another mode, another version, a short packet, a NaN.
        let n = P.encode(&Integrity::Link, 0, &mut b).unwrap();
        assert_eq!(
            PositionPacket::decode(&b[..n], &Integrity::Crc16).unwrap_err(),
            PositionError::ModeMismatch
        );
        assert_eq!(
            PositionPacket::decode(&b[..n - 1], &Integrity::Link).unwrap_err(),
            PositionError::Malformed
        );
        let nan = PositionPacket {
            position: [f32::NAN, 0.0],
            ..P
        };
        let n = nan.encode(&Integrity::Link, 0, &mut b).unwrap();
        assert_eq!(
            PositionPacket::decode(&b[..n], &Integrity::Link).unwrap_err(),
            PositionError::NonFinite
        );
        b[0] = 1;
        assert_eq!(
            PositionPacket::decode(&b[..n], &Integrity::Link).unwrap_err(),
            PositionError::Malformed
        );
        assert_eq!(
            P.encode(&Integrity::Auth(KEY), 0, &mut b[..26]),
            Err(PositionError::BufferTooSmall)
        );
    }

    #[test]
    fn replays_are_refused_and_newer_counters_taken() {
        let m = Integrity::Auth(KEY);
        let mut last = None;
        let mut b = [0u8; MAX_POSITION_LEN];
        let n = P.encode(&m, auth::counter(3, 10), &mut b).unwrap();
        let (_, c) = PositionPacket::decode(&b[..n], &m).unwrap();
        assert!(accept_counter(&mut last, c));
        // The same packet again: a replay.
        let (_, c) = PositionPacket::decode(&b[..n], &m).unwrap();
        assert!(!accept_counter(&mut last, c));
        // An older one too; the next one, and the first of a new boot epoch, are taken.
        assert!(!accept_counter(&mut last, Some(auth::counter(3, 9))));
        assert!(accept_counter(&mut last, Some(auth::counter(3, 11))));
        assert!(accept_counter(&mut last, Some(auth::counter(4, 0))));
        assert_eq!(last, Some(auth::counter(4, 0)));
        // Without auth every packet passes.
        assert!(accept_counter(&mut last, None));
    }
}
