//! `Agent::receive_checked` with a CRC checked once per broadcast (`wire::CrcCheck`): the
//! same results, counters and state as `Agent::receive` for every frame, valid or not, and
//! a check of other bytes is never trusted.

mod testkit;

use ph_formation_core::wire::{mode_byte, CrcCheck, FrameWriter, Integrity, MAX_FRAME_LEN};
use ph_formation_core::{EstimatorMode, FrameError, Measurements, Vec2};
use proptest::prelude::*;
use testkit::{bearings, rng, strip, strip_positions, Formation, HostAgent, State};

const ONE: u16 = 0x3C00;

/// Agent 0 (id 1) of a sensed four-agent strip, whose neighbours are ids 2 and 3, with
/// `integrity`.
fn receiver(integrity: Integrity) -> HostAgent<f64> {
    let mut r = rng(7);
    let f = Formation::random(4, strip(4), &strip_positions(4, 0.1, &mut r), &mut r);
    let s = State {
        q: strip_positions(4, 0.2, &mut r),
        v: vec![Vec2::new(0.1, -0.2); 4],
    };
    let mut c = f.config::<f64>(0);
    c.integrity = integrity;
    let mut a = HostAgent::new(c).expect("valid configuration");
    a.sense(&Measurements {
        time: 0.0,
        dt: 0.0,
        velocity: s.v[0],
        bearings: &bearings::<f64>(&f, &s, 0, true),
        partner_offset: None,
    })
    .expect("valid");
    a
}

/// A valid frame of `integrity` from id 2 with sequence number `seq`, velocity `v` and
/// one angle item about the far vertices 1 and 3 (codes of `[γ, σ, r_v, r_w]`).
fn frame(integrity: Integrity, seq: u16, v: [f32; 2], codes: [u16; 4]) -> Vec<u8> {
    let mut w = FrameWriter::new(integrity);
    w.start(mode_byte(integrity, EstimatorMode::Shared), 2, seq, v);
    assert!(w.push_angle([1, 3], codes));
    w.finish().to_vec()
}

/// One frame as a radio might deliver it: a valid frame, then bit flips, a cut or an
/// extension, as the strategy drew them.
#[derive(Clone, Debug)]
struct Delivery {
    link: bool,
    seq: u16,
    codes: [u16; 4],
    flips: Vec<usize>,
    len: Option<usize>,
}

impl Delivery {
    fn bytes(&self) -> Vec<u8> {
        let integrity = if self.link {
            Integrity::Link
        } else {
            Integrity::Crc16
        };
        let mut b = frame(integrity, self.seq, [0.25, -0.5], self.codes);
        for &bit in &self.flips {
            let i = bit % (b.len() * 8);
            b[i / 8] ^= 1 << (i % 8);
        }
        if let Some(len) = self.len {
            b.resize(len, 0xA5);
        }
        b
    }
}

fn delivery() -> impl Strategy<Value = Delivery> {
    (
        prop::bool::weighted(0.1),
        0u16..6,
        prop::sample::select(vec![
            [ONE, 0xB800, ONE, ONE],
            [0, 0, ONE, ONE],
            [0x7E00, 0, ONE, ONE], // γ = NaN: invalid value behind a valid CRC
            [0, 0, 0, ONE],        // r = 0
        ]),
        prop::collection::vec(any::<usize>(), 0..3),
        prop::option::weighted(0.2, 0usize..=MAX_FRAME_LEN + 4),
    )
        .prop_map(|(link, seq, codes, flips, len)| Delivery {
            link,
            seq,
            codes,
            flips,
            len,
        })
}

proptest! {
    /// For crc16, link and auth receivers alike, a sequence of valid, corrupted, cut,
    /// extended and foreign-mode frames gives the same result per frame, the same
    /// counters and the same agent state through `receive_checked` (CRC checked once,
    /// as a simulator does per broadcast) as through `receive`.
    #[test]
    fn receive_checked_is_receive(
        deliveries in prop::collection::vec(delivery(), 1..8),
        integrity in prop::sample::select(vec![
            Integrity::Crc16,
            Integrity::Link,
            Integrity::Auth(ph_formation_core::wire::SwarmKey::new([7; 16])),
        ]),
    ) {
        let mut plain = receiver(integrity);
        let mut checked = plain.clone();
        for d in &deliveries {
            let b = d.bytes();
            let check = CrcCheck::of(&b);
            prop_assert_eq!(plain.receive(&b), checked.receive_checked(&b, check), "{:?}", d);
        }
        prop_assert_eq!(plain.stats(), checked.stats());
        prop_assert_eq!(format!("{plain:?}"), format!("{checked:?}"));
    }
}

/// Only a version-3 `crc16` frame of 2 ..= 60 bytes has a check.
#[test]
fn only_crc16_frames_have_a_check() {
    let crc = frame(Integrity::Crc16, 0, [0.0; 2], [0, 0, ONE, ONE]);
    assert!(CrcCheck::of(&crc).is_some());
    let link = frame(Integrity::Link, 0, [0.0; 2], [0, 0, ONE, ONE]);
    assert_eq!(CrcCheck::of(&link), None);
    let mut v2 = crc.clone();
    v2[0] = (2 << 4) | (v2[0] & 0x0F);
    assert_eq!(CrcCheck::of(&v2), None);
    assert_eq!(CrcCheck::of(&[]), None);
    assert_eq!(CrcCheck::of(&crc[..1]), None);
    let mut long = crc.clone();
    long.resize(MAX_FRAME_LEN + 1, 0);
    assert_eq!(CrcCheck::of(&long), None);
}

/// A check computed from other bytes (another length or trailer) is ignored: the
/// receiver computes the CRC itself and rejects the corrupt frame.
#[test]
fn a_check_of_other_bytes_is_not_trusted() {
    let good = frame(Integrity::Crc16, 1, [0.0; 2], [0, 0, ONE, ONE]);
    let check = CrcCheck::of(&good);
    let mut rx = receiver(Integrity::Crc16);
    // Another trailer.
    let mut bad = good.clone();
    let last = bad.len() - 1;
    bad[last] ^= 0x10;
    assert_eq!(rx.receive_checked(&bad, check), Err(FrameError::BadCrc));
    // Another length (one byte more, the good CRC's bytes still last).
    let mut longer = good[..good.len() - 2].to_vec();
    longer.push(0);
    longer.extend_from_slice(&good[good.len() - 2..]);
    assert_eq!(rx.receive_checked(&longer, check), Err(FrameError::BadCrc));
    assert_eq!(rx.stats().bad_crc, 2);
    // The check of a corrupt frame says so.
    assert_eq!(
        rx.receive_checked(&bad, CrcCheck::of(&bad)),
        Err(FrameError::BadCrc)
    );
    rx.receive_checked(&good, check).expect("valid");
    assert_eq!((rx.stats().bad_crc, rx.stats().accepted), (3, 1));
}

/// `frames_checked` sends the bytes of `frames`, each with the check `CrcCheck::of` them
/// gives (`crc16`), or none (`link`, `auth`).
#[test]
fn frames_checked_gives_the_frames_and_their_checks() {
    for integrity in [
        Integrity::Crc16,
        Integrity::Link,
        Integrity::Auth(ph_formation_core::wire::SwarmKey::new([7; 16])),
    ] {
        let agent = receiver(integrity);
        let (mut plain, mut checked) = (agent.clone(), agent);
        let mut frames = Vec::new();
        let n = plain.frames(|b| frames.push(b.to_vec()));
        let mut with_checks = Vec::new();
        let m = checked.frames_checked(|b, c| with_checks.push((b.to_vec(), c)));
        assert!(n >= 1);
        assert_eq!(n, m);
        for (bytes, (b, check)) in frames.iter().zip(&with_checks) {
            assert_eq!(bytes, b);
            let expected = CrcCheck::of(bytes);
            assert_eq!(expected.is_some(), integrity == Integrity::Crc16);
            assert_eq!(*check, expected, "{integrity:?}");
        }
        assert_eq!(format!("{plain:?}"), format!("{checked:?}"));
    }
}
