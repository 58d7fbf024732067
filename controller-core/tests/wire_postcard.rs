//! The wire is postcard of `wire::Frame` (docs/core.md, "Wire format"), and the fast path
//! is proven equal to it: for arbitrary valid frames of every integrity and estimator
//! mode and every item count, the fast encoder's (`FrameWriter`) bytes are
//! `postcard::to_slice` of the frame and the trailer (for `crc16`: postcard's own CRC
//! flavour with CRC-16/IBM-SDLC); the fast decoders (`check_frame`, `decode_frame`) and
//! postcard's deserializer (`postcard::take_from_bytes`, `Frame::decode`) accept and
//! reject alike, and agree on what they accept, on those frames, corrupted copies of
//! them and random bytes, for receivers of every mode. And the claim is kept true: the
//! core depends on postcard while the documents say the frames are postcard.

use ph_formation_core::wire::auth::{self, Counter, TAG_LEN};
use ph_formation_core::wire::{
    check_frame, decode_frame, mode_byte, AngleItem, CounterExt, Frame, FrameHeader, FrameWriter,
    Integrity, SwarmKey, F16, MAX_FRAME_LEN,
};
use ph_formation_core::EstimatorMode;
use proptest::prelude::*;

const KEY: SwarmKey = SwarmKey::new(*b"postcard swarm k");
const CRC: crc::Crc<u16> = crc::Crc::<u16>::new(&crc::CRC_16_IBM_SDLC);

const INTEGRITIES: [Integrity; 3] = [Integrity::Crc16, Integrity::Link, Integrity::Auth(KEY)];
const ESTIMATORS: [EstimatorMode; 3] = [
    EstimatorMode::Shared,
    EstimatorMode::PerAgent,
    EstimatorMode::Measured,
];

/// A frame as its sender has it: modes, full counter and the frame.
#[derive(Clone, Debug)]
struct Sent {
    integrity: Integrity,
    counter: Counter,
    frame: Frame,
}

/// Valid binary16 codes of `[γ, σ, r_v, r_w]`: finite γ, |σ| ≤ 1, r > 0 finite.
fn codes() -> impl Strategy<Value = [u16; 4]> {
    (
        any::<u16>().prop_filter("finite", |c| c & 0x7C00 != 0x7C00),
        any::<u16>().prop_filter("|σ| ≤ 1", |c| c & 0x7FFF <= 0x3C00),
        1u16..0x7C00,
        1u16..0x7C00,
    )
        .prop_map(|(g, s, a, b)| [g, s, a, b])
}

fn item() -> impl Strategy<Value = AngleItem> {
    (any::<[u8; 2]>(), codes())
        .prop_filter("distinct far vertices", |(f, _)| f[0] != f[1])
        .prop_map(|(far, [g, s, a, b])| AngleItem {
            far,
            gamma: F16(g),
            sigma: F16(s),
            range: [F16(a), F16(b)],
        })
}

/// Arbitrary valid frames: every integrity and estimator mode, 0–4 items, any sender,
/// counter and finite velocity.
fn sent() -> impl Strategy<Value = Sent> {
    (
        0..3usize,
        0..3usize,
        any::<u8>(),
        any::<u64>(),
        proptest::array::uniform2(any::<f32>().prop_filter("finite", |v| v.is_finite())),
        proptest::collection::vec(item(), 0..=4),
    )
        .prop_map(|(i, e, sender, counter, velocity, items)| {
            let integrity = INTEGRITIES[i];
            let auth = matches!(integrity, Integrity::Auth(_));
            let frame = Frame {
                header: FrameHeader {
                    mode: mode_byte(integrity, ESTIMATORS[e]),
                    sender,
                    seq: counter as u16,
                },
                velocity,
                counter_ext: (auth && items.len() < 4).then(|| CounterExt::of_counter(counter)),
                angles: items.into_iter().collect(),
            };
            Sent {
                integrity,
                counter,
                frame,
            }
        })
}

/// The fast encoder's bytes of a frame.
fn fast_encode(s: &Sent) -> Vec<u8> {
    let f = &s.frame;
    let mut w = FrameWriter::new(s.integrity);
    w.start_counted(f.header.mode, f.header.sender, s.counter, f.velocity);
    for a in &f.angles {
        let codes = [a.gamma.0, a.sigma.0, a.range[0].0, a.range[1].0];
        assert!(w.push_angle(a.far, codes), "a valid frame's item fits");
    }
    w.finish().to_vec()
}

/// Frames equal field for field (the velocity bit for bit: a structural check passes
/// non-finite values on to the value check).
fn same(a: &Frame, b: &Frame) -> bool {
    a.header == b.header
        && a.velocity.map(f32::to_bits) == b.velocity.map(f32::to_bits)
        && a.angles == b.angles
        && a.counter_ext == b.counter_ext
}

/// postcard's structural decoding of `bytes` for a receiver: the trailer (`crc16`:
/// postcard's CRC flavour), `take_from_bytes` with nothing left over, the receiver's
/// modes. No tag, no values: what `check_frame` checks.
fn postcard_structure(bytes: &[u8], integrity: Integrity, est: EstimatorMode) -> Option<Frame> {
    if bytes.len() > MAX_FRAME_LEN {
        return None;
    }
    let (frame, rest) = match integrity {
        Integrity::Crc16 => {
            postcard::de_flavors::crc::take_from_bytes_u16::<Frame>(bytes, CRC.digest()).ok()?
        }
        Integrity::Link => postcard::take_from_bytes::<Frame>(bytes).ok()?,
        Integrity::Auth(_) => {
            let body = bytes.get(..bytes.len().checked_sub(TAG_LEN)?)?;
            postcard::take_from_bytes::<Frame>(body).ok()?
        }
    };
    (rest.is_empty() && frame.header.mode == mode_byte(integrity, est)).then_some(frame)
}

/// Both decoders on `bytes` for every receiver mode: the same acceptance and the same
/// frame, structurally (`check_frame` vs `postcard_structure`) and completely
/// (`decode_frame` vs `Frame::decode`, with the tag and the values).
fn decoders_agree(bytes: &[u8]) -> Result<(), TestCaseError> {
    for integrity in INTEGRITIES {
        for est in ESTIMATORS {
            let fast = check_frame(bytes, integrity, est);
            let slow = postcard_structure(bytes, integrity, est);
            prop_assert_eq!(
                fast.is_ok(),
                slow.is_some(),
                "{:?} {:?}: {:?}",
                integrity,
                est,
                fast
            );
            if let (Ok(view), Some(frame)) = (&fast, &slow) {
                let from_view = Frame {
                    header: view.header,
                    velocity: view.velocity,
                    angles: view.angles().collect(),
                    counter_ext: view.carried_counter().map(CounterExt::of_counter),
                };
                prop_assert!(same(&from_view, frame), "{:?} vs {:?}", from_view, frame);
                // postcard::from_bytes of the bytes before the trailer is the same frame.
                let body = &bytes[..bytes.len() - integrity.trailer_len()];
                let plain: Frame = postcard::from_bytes(body).expect("decodes");
                prop_assert!(same(&plain, frame));
            }
            let fast = decode_frame(bytes, integrity, est);
            let slow = Frame::decode(bytes, integrity, est);
            prop_assert_eq!(
                fast.is_ok(),
                slow.is_ok(),
                "{:?} {:?}: {:?} vs {:?}",
                integrity,
                est,
                fast,
                slow
            );
            if let (Ok(a), Ok(b)) = (&fast, &slow) {
                prop_assert!(same(a, b));
            }
        }
    }
    Ok(())
}

/// `bytes` with the `crc16` trailer recomputed over everything before it (so that a
/// corruption reaches the checks behind the CRC).
fn recrc(bytes: &[u8]) -> Vec<u8> {
    let mut v = bytes.to_vec();
    if v.len() >= 2 {
        let n = v.len() - 2;
        let crc = CRC.checksum(&v[..n]);
        v[n..].copy_from_slice(&crc.to_le_bytes());
    }
    v
}

/// One corruption of a frame's bytes.
#[derive(Clone, Debug)]
enum Corruption {
    /// Flip one bit.
    Flip(usize),
    /// Set one byte.
    Set(usize, u8),
    /// Cut to this length.
    Cut(usize),
    /// Append these bytes.
    Extend(Vec<u8>),
}

fn corruption() -> impl Strategy<Value = Corruption> {
    prop_oneof![
        (0..8 * MAX_FRAME_LEN).prop_map(Corruption::Flip),
        (0..MAX_FRAME_LEN, any::<u8>()).prop_map(|(i, b)| Corruption::Set(i, b)),
        (0..MAX_FRAME_LEN).prop_map(Corruption::Cut),
        proptest::collection::vec(any::<u8>(), 1..12).prop_map(Corruption::Extend),
    ]
}

fn corrupt(bytes: &[u8], c: &Corruption) -> Vec<u8> {
    let mut v = bytes.to_vec();
    let n = v.len();
    match c {
        Corruption::Flip(bit) => v[(bit / 8) % n] ^= 1 << (bit % 8),
        Corruption::Set(i, b) => v[i % n] = *b,
        Corruption::Cut(len) => v.truncate(*len),
        Corruption::Extend(more) => v.extend_from_slice(more),
    }
    v
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(2000))]

    /// The fast encoder writes exactly `postcard::to_slice` of the frame and the trailer,
    /// as `Frame::encode` does; `crc16` frames are postcard's CRC flavour; at most 60
    /// bytes.
    #[test]
    fn fast_encoder_bytes_are_postcard_of_the_frame(s in sent()) {
        let bytes = fast_encode(&s);
        prop_assert!(bytes.len() <= MAX_FRAME_LEN);
        let mut buf = [0u8; MAX_FRAME_LEN];
        let body = postcard::to_slice(&s.frame, &mut buf).expect("serializes").to_vec();
        let trailer = s.integrity.trailer_len();
        prop_assert_eq!(&bytes[..bytes.len() - trailer], &body[..]);
        match s.integrity {
            Integrity::Crc16 => {
                let mut buf = [0u8; MAX_FRAME_LEN];
                let flavour = postcard::ser_flavors::crc::to_slice_u16(&s.frame, &mut buf, CRC.digest())
                    .expect("serializes");
                prop_assert_eq!(&bytes[..], &flavour[..]);
            }
            Integrity::Link => prop_assert_eq!(bytes.len(), body.len()),
            Integrity::Auth(key) => {
                prop_assert_eq!(&bytes[body.len()..], &auth::tag(&key, s.counter, &body)[..]);
            }
        }
        let mut buf = [0u8; MAX_FRAME_LEN];
        let encoded = s.frame.encode(&s.integrity, s.counter, &mut buf).expect("encodes");
        prop_assert_eq!(&bytes[..], encoded);
    }

    /// Both decoders accept a valid frame (its sender's modes) and give it back; every
    /// receiver mode agrees.
    #[test]
    fn decoders_agree_on_valid_frames(s in sent()) {
        let bytes = fast_encode(&s);
        let est = ESTIMATORS.into_iter().find(|&e| mode_byte(s.integrity, e) == s.frame.header.mode).expect("a mode");
        let fast = decode_frame(&bytes, s.integrity, est);
        let auth_full = matches!(s.integrity, Integrity::Auth(_)) && s.frame.counter_ext.is_none();
        if auth_full {
            // No counter on board: a stateless decoder cannot verify the tag.
            prop_assert!(fast.is_err());
            prop_assert!(check_frame(&bytes, s.integrity, est).is_ok());
        } else {
            prop_assert!(same(&fast.expect("valid"), &s.frame));
        }
        decoders_agree(&bytes)?;
    }

    /// Corrupted frames (bit flips, bytes set, cut, extended), with the CRC left as it was
    /// or recomputed: the decoders accept and reject alike.
    #[test]
    fn decoders_agree_on_corrupted_frames(s in sent(), c in corruption(), fix_crc in any::<bool>()) {
        let bad = corrupt(&fast_encode(&s), &c);
        let bad = if fix_crc { recrc(&bad) } else { bad };
        decoders_agree(&bad)?;
    }

    /// Random bytes, and random bytes with a version-4 mode byte and a valid CRC: the
    /// decoders accept and reject alike.
    #[test]
    fn decoders_agree_on_random_bytes(
        bytes in proptest::collection::vec(any::<u8>(), 0..70),
        mode in 0x80u8..0xD0,
        plausible in any::<bool>(),
    ) {
        let mut bytes = bytes;
        if plausible && !bytes.is_empty() {
            bytes[0] = mode;
            bytes = recrc(&bytes);
        }
        decoders_agree(&bytes)?;
    }
}

/// Every frame kind's length: `crc16` 14 + 10k, `link` 12 + 10k, `auth` 26 + 10k (with
/// the counter extension, k ≤ 3) and 60 (k = 4): never more than 60 bytes.
#[test]
fn every_frame_kind_fits_60_bytes() {
    for integrity in INTEGRITIES {
        for est in ESTIMATORS {
            for k in 0..=4usize {
                let auth = matches!(integrity, Integrity::Auth(_));
                let frame = Frame {
                    header: FrameHeader {
                        mode: mode_byte(integrity, est),
                        sender: 1,
                        seq: 2,
                    },
                    velocity: [0.5, -0.5],
                    angles: (0..k)
                        .map(|i| AngleItem {
                            far: [2, 3 + i as u8],
                            gamma: F16(0x3C00),
                            sigma: F16(0x3800),
                            range: [F16(0x3C00); 2],
                        })
                        .collect(),
                    counter_ext: (auth && k < 4).then_some(CounterExt { epoch: 3, high: 0 }),
                };
                let mut buf = [0u8; MAX_FRAME_LEN];
                let len = frame
                    .encode(&integrity, 2 | 3 << 32, &mut buf)
                    .expect("fits")
                    .len();
                let expected = match integrity {
                    Integrity::Crc16 => 14 + 10 * k,
                    Integrity::Link => 12 + 10 * k,
                    Integrity::Auth(_) if k < 4 => 26 + 10 * k,
                    Integrity::Auth(_) => 60,
                };
                assert_eq!(len, expected, "{integrity:?} {est:?} {k} items");
                assert_eq!(usize::from(buf[0] >> 4), 8 + k);
                assert!(len <= MAX_FRAME_LEN);
            }
        }
    }
}

/// A frame the type does not allow is refused by postcard's serializer, not written:
/// a counter extension without `auth` or at 4 items, a mode byte with items.
#[test]
fn inconsistent_frames_are_not_serialized() {
    let mut frame = Frame {
        header: FrameHeader {
            mode: mode_byte(Integrity::Crc16, EstimatorMode::Shared),
            sender: 1,
            seq: 2,
        },
        velocity: [0.0; 2],
        angles: heapless::Vec::new(),
        counter_ext: Some(CounterExt { epoch: 0, high: 0 }),
    };
    let mut buf = [0u8; MAX_FRAME_LEN];
    assert!(postcard::to_slice(&frame, &mut buf).is_err());
    frame.counter_ext = None;
    assert!(postcard::to_slice(&frame, &mut buf).is_ok());
    frame.header.mode |= 0x10;
    assert!(postcard::to_slice(&frame, &mut buf).is_err());
}

/// The documents say the radio frames are postcard (README, docs/core.md,
/// docs/scenarios.md, host-sim's crate documentation): then the core must depend on
/// postcard (a normal dependency, not only a test's) and encode with it.
#[test]
fn the_postcard_claim_is_true() {
    let root = concat!(env!("CARGO_MANIFEST_DIR"), "/..");
    let read = |p: &str| std::fs::read_to_string(format!("{root}/{p}")).expect(p);
    let claims: Vec<&str> = [
        "README.md",
        "docs/core.md",
        "docs/scenarios.md",
        "host-sim/src/lib.rs",
    ]
    .into_iter()
    .filter(|p| read(p).contains("postcard"))
    .collect();
    assert!(
        read("docs/core.md").contains("postcard of `Frame`"),
        "docs/core.md defines the frame as postcard of `Frame`"
    );
    let manifest = read("controller-core/Cargo.toml");
    let deps = manifest
        .split("\n[")
        .find(|section| section.starts_with("dependencies]"))
        .expect("a [dependencies] table");
    assert!(
        deps.lines().any(|l| l.trim_start().starts_with("postcard")),
        "{claims:?} say the frames are postcard, but controller-core does not depend on it"
    );
    assert!(read("controller-core/src/wire/frame.rs").contains("postcard::to_slice(self"));
}
