//! `auth` integrity: the MAC primitive against its published test vectors (through this
//! crate's wrapper), the frame layout (counter extension, tag), key redaction, and the
//! agent's counter rules (first contact, sync frames, reboot). The 10⁶-attempt rejection
//! campaigns are in `tests/auth_reject.rs`.

mod testkit;

use ph_formation_core::wire::auth::{self, counter, reconstruct, COUNTER_EXT_LEN, TAG_LEN};
use ph_formation_core::wire::{decode_frame, mode_byte, FrameWriter, Integrity, SwarmKey};
use ph_formation_core::{Agent, AgentConfig, AgentId, EstimatorMode, FrameError};
use testkit::{fan, fan_positions, rng, sense_and_exchange, Formation, HostAgent, State};

/// SipHash-2-4 with key `00 01 … 0f` of the messages `00 01 … (n−1)`, `n = 0..63`: the
/// 64-bit outputs (little-endian bytes) of the reference implementation's `vectors.h`
/// (`vectors_sip64`; Aumasson & Bernstein, "SipHash: a fast short-input PRF", 2012, whose
/// Appendix A gives the `n = 15` one: `a129ca6149be45e5`).
const SIPHASH24_VECTORS: [[u8; 8]; 64] = [
    [0x31, 0x0e, 0x0e, 0xdd, 0x47, 0xdb, 0x6f, 0x72],
    [0xfd, 0x67, 0xdc, 0x93, 0xc5, 0x39, 0xf8, 0x74],
    [0x5a, 0x4f, 0xa9, 0xd9, 0x09, 0x80, 0x6c, 0x0d],
    [0x2d, 0x7e, 0xfb, 0xd7, 0x96, 0x66, 0x67, 0x85],
    [0xb7, 0x87, 0x71, 0x27, 0xe0, 0x94, 0x27, 0xcf],
    [0x8d, 0xa6, 0x99, 0xcd, 0x64, 0x55, 0x76, 0x18],
    [0xce, 0xe3, 0xfe, 0x58, 0x6e, 0x46, 0xc9, 0xcb],
    [0x37, 0xd1, 0x01, 0x8b, 0xf5, 0x00, 0x02, 0xab],
    [0x62, 0x24, 0x93, 0x9a, 0x79, 0xf5, 0xf5, 0x93],
    [0xb0, 0xe4, 0xa9, 0x0b, 0xdf, 0x82, 0x00, 0x9e],
    [0xf3, 0xb9, 0xdd, 0x94, 0xc5, 0xbb, 0x5d, 0x7a],
    [0xa7, 0xad, 0x6b, 0x22, 0x46, 0x2f, 0xb3, 0xf4],
    [0xfb, 0xe5, 0x0e, 0x86, 0xbc, 0x8f, 0x1e, 0x75],
    [0x90, 0x3d, 0x84, 0xc0, 0x27, 0x56, 0xea, 0x14],
    [0xee, 0xf2, 0x7a, 0x8e, 0x90, 0xca, 0x23, 0xf7],
    [0xe5, 0x45, 0xbe, 0x49, 0x61, 0xca, 0x29, 0xa1],
    [0xdb, 0x9b, 0xc2, 0x57, 0x7f, 0xcc, 0x2a, 0x3f],
    [0x94, 0x47, 0xbe, 0x2c, 0xf5, 0xe9, 0x9a, 0x69],
    [0x9c, 0xd3, 0x8d, 0x96, 0xf0, 0xb3, 0xc1, 0x4b],
    [0xbd, 0x61, 0x79, 0xa7, 0x1d, 0xc9, 0x6d, 0xbb],
    [0x98, 0xee, 0xa2, 0x1a, 0xf2, 0x5c, 0xd6, 0xbe],
    [0xc7, 0x67, 0x3b, 0x2e, 0xb0, 0xcb, 0xf2, 0xd0],
    [0x88, 0x3e, 0xa3, 0xe3, 0x95, 0x67, 0x53, 0x93],
    [0xc8, 0xce, 0x5c, 0xcd, 0x8c, 0x03, 0x0c, 0xa8],
    [0x94, 0xaf, 0x49, 0xf6, 0xc6, 0x50, 0xad, 0xb8],
    [0xea, 0xb8, 0x85, 0x8a, 0xde, 0x92, 0xe1, 0xbc],
    [0xf3, 0x15, 0xbb, 0x5b, 0xb8, 0x35, 0xd8, 0x17],
    [0xad, 0xcf, 0x6b, 0x07, 0x63, 0x61, 0x2e, 0x2f],
    [0xa5, 0xc9, 0x1d, 0xa7, 0xac, 0xaa, 0x4d, 0xde],
    [0x71, 0x65, 0x95, 0x87, 0x66, 0x50, 0xa2, 0xa6],
    [0x28, 0xef, 0x49, 0x5c, 0x53, 0xa3, 0x87, 0xad],
    [0x42, 0xc3, 0x41, 0xd8, 0xfa, 0x92, 0xd8, 0x32],
    [0xce, 0x7c, 0xf2, 0x72, 0x2f, 0x51, 0x27, 0x71],
    [0xe3, 0x78, 0x59, 0xf9, 0x46, 0x23, 0xf3, 0xa7],
    [0x38, 0x12, 0x05, 0xbb, 0x1a, 0xb0, 0xe0, 0x12],
    [0xae, 0x97, 0xa1, 0x0f, 0xd4, 0x34, 0xe0, 0x15],
    [0xb4, 0xa3, 0x15, 0x08, 0xbe, 0xff, 0x4d, 0x31],
    [0x81, 0x39, 0x62, 0x29, 0xf0, 0x90, 0x79, 0x02],
    [0x4d, 0x0c, 0xf4, 0x9e, 0xe5, 0xd4, 0xdc, 0xca],
    [0x5c, 0x73, 0x33, 0x6a, 0x76, 0xd8, 0xbf, 0x9a],
    [0xd0, 0xa7, 0x04, 0x53, 0x6b, 0xa9, 0x3e, 0x0e],
    [0x92, 0x59, 0x58, 0xfc, 0xd6, 0x42, 0x0c, 0xad],
    [0xa9, 0x15, 0xc2, 0x9b, 0xc8, 0x06, 0x73, 0x18],
    [0x95, 0x2b, 0x79, 0xf3, 0xbc, 0x0a, 0xa6, 0xd4],
    [0xf2, 0x1d, 0xf2, 0xe4, 0x1d, 0x45, 0x35, 0xf9],
    [0x87, 0x57, 0x75, 0x19, 0x04, 0x8f, 0x53, 0xa9],
    [0x10, 0xa5, 0x6c, 0xf5, 0xdf, 0xcd, 0x9a, 0xdb],
    [0xeb, 0x75, 0x09, 0x5c, 0xcd, 0x98, 0x6c, 0xd0],
    [0x51, 0xa9, 0xcb, 0x9e, 0xcb, 0xa3, 0x12, 0xe6],
    [0x96, 0xaf, 0xad, 0xfc, 0x2c, 0xe6, 0x66, 0xc7],
    [0x72, 0xfe, 0x52, 0x97, 0x5a, 0x43, 0x64, 0xee],
    [0x5a, 0x16, 0x45, 0xb2, 0x76, 0xd5, 0x92, 0xa1],
    [0xb2, 0x74, 0xcb, 0x8e, 0xbf, 0x87, 0x87, 0x0a],
    [0x6f, 0x9b, 0xb4, 0x20, 0x3d, 0xe7, 0xb3, 0x81],
    [0xea, 0xec, 0xb2, 0xa3, 0x0b, 0x22, 0xa8, 0x7f],
    [0x99, 0x24, 0xa4, 0x3c, 0xc1, 0x31, 0x57, 0x24],
    [0xbd, 0x83, 0x8d, 0x3a, 0xaf, 0xbf, 0x8d, 0xb7],
    [0x0b, 0x1a, 0x2a, 0x32, 0x65, 0xd5, 0x1a, 0xea],
    [0x13, 0x50, 0x79, 0xa3, 0x23, 0x1c, 0xe6, 0x60],
    [0x93, 0x2b, 0x28, 0x46, 0xe4, 0xd7, 0x06, 0x66],
    [0xe1, 0x91, 0x5f, 0x5c, 0xb1, 0xec, 0xa4, 0x6c],
    [0xf3, 0x25, 0x96, 0x5c, 0xa1, 0x6d, 0x62, 0x9f],
    [0x57, 0x5f, 0xf2, 0x8e, 0x60, 0x38, 0x1b, 0xe5],
    [0x72, 0x45, 0x06, 0xeb, 0x4c, 0x32, 0x8a, 0x95],
];

const KEY: SwarmKey = SwarmKey::new(*b"swarm key 128bit");

#[test]
fn siphash24_matches_the_published_vectors() {
    let key = SwarmKey::new(core::array::from_fn(|i| i as u8));
    let msg: Vec<u8> = (0..64).collect();
    assert_eq!(
        u64::from_le_bytes(SIPHASH24_VECTORS[15]),
        0xa129_ca61_49be_45e5,
        "the paper's example"
    );
    for (n, want) in SIPHASH24_VECTORS.iter().enumerate() {
        assert_eq!(&auth::siphash24(&key, &[&msg[..n]]), want, "length {n}");
        // The wrapper hashes the concatenation of its parts, wherever they are split.
        for cut in 0..=n {
            assert_eq!(
                &auth::siphash24(&key, &[&msg[..cut], &msg[cut..n]]),
                want,
                "length {n} split at {cut}"
            );
        }
    }
}

#[test]
fn frames_carry_the_counter_when_it_fits_and_a_tag_over_counter_and_bytes() {
    let mode = mode_byte(Integrity::Auth(KEY), EstimatorMode::Shared);
    let c = counter(0x0102_0304, 0x0506_0708);
    for items in 0..=4 {
        let mut w = FrameWriter::new(Integrity::Auth(KEY));
        w.start_counted(mode, 9, c, [1.0, 2.0]);
        for _ in 0..items {
            assert!(w.push_angle([1, 2], [0x3800, 0x3800, 0x3C00, 0x3C00]));
        }
        if items == 4 {
            assert!(!w.push_angle([1, 2], [0; 4]), "at most 4 items");
        }
        let f = w.finish().to_vec();
        let ext = if items <= 3 { COUNTER_EXT_LEN } else { 0 };
        assert_eq!(f.len(), 12 + 10 * items + ext + TAG_LEN, "{items} items");
        assert!(f.len() <= 60);
        assert_eq!(f[0] >> 2 & 3, 2, "integrity code 2");
        assert_eq!(
            usize::from(f[0] >> 4),
            8 + items,
            "bits 7-4: 8 + the item count"
        );
        assert_eq!(&f[2..4], &[0x08, 0x07], "low 16 bits of the counter");
        if ext > 0 {
            let e = 12 + 10 * items;
            assert_eq!(&f[e..e + 6], &[0x04, 0x03, 0x02, 0x01, 0x06, 0x05]);
        }
        let (signed, tag) = f.split_at(f.len() - TAG_LEN);
        assert_eq!(tag, auth::siphash24(&KEY, &[&c.to_le_bytes(), signed]));
        // The stateless decoder verifies frames that carry their counter.
        let decoded = decode_frame(&f, Integrity::Auth(KEY), EstimatorMode::Shared);
        if ext > 0 {
            assert_eq!(decoded.expect("authentic").angles.len(), items);
            let other = SwarmKey::new(*b"another key 128b");
            assert_eq!(
                decode_frame(&f, Integrity::Auth(other), EstimatorMode::Shared),
                Err(FrameError::BadTag)
            );
        } else {
            assert_eq!(decoded, Err(FrameError::Unsynced(9)));
        }
    }
}

/// `verify` accepts exactly the tag: every single-bit change of the received tag, of the
/// counter or of a signed byte is refused.
#[test]
fn verify_accepts_the_tag_and_refuses_every_bit_flip() {
    let key = SwarmKey::new(*b"0123456789abcdef");
    let bytes: Vec<u8> = (0..40u8).map(|i| i.wrapping_mul(37)).collect();
    let c = counter(7, 123_456);
    let t = auth::tag(&key, c, &bytes);
    assert!(auth::verify(&key, c, &bytes, &t));
    for bit in 0..8 * TAG_LEN {
        let mut bad = t;
        bad[bit / 8] ^= 1 << (bit % 8);
        assert!(!auth::verify(&key, c, &bytes, &bad), "tag bit {bit}");
    }
    for bit in 0..64 {
        assert!(
            !auth::verify(&key, c ^ (1 << bit), &bytes, &t),
            "counter bit {bit}"
        );
    }
    for bit in 0..8 * bytes.len() {
        let mut b = bytes.clone();
        b[bit / 8] ^= 1 << (bit % 8);
        assert!(!auth::verify(&key, c, &b, &t), "byte bit {bit}");
    }
}

#[test]
fn reconstruction_recovers_every_counter_within_half_the_sequence_space() {
    for last in [
        counter(0, 5),
        counter(3, 0xFFFF),
        counter(3, 0x1_0000),
        counter(7, 0xFFFF_FF00),
        counter(8, 0x8000),
    ] {
        for d in -0x8000i64..0x8000 {
            let c = last.wrapping_add_signed(d);
            assert_eq!(reconstruct(last, c as u16), c, "last {last:#x}, offset {d}");
        }
    }
}

#[test]
fn the_key_never_appears_in_debug_or_display() {
    let secret = *KEY.expose_secret();
    let bytes_debug = format!("{secret:?}");
    let bytes_hex: String = secret.iter().map(|b| format!("{b:02x}")).collect();
    let config = config(3);
    let agent = Receiver::new(config.clone()).expect("valid");
    for text in [
        format!("{KEY:?}"),
        format!("{KEY}"),
        format!("{:?}", config.integrity),
        format!("{}", config.integrity),
        format!("{config:?}"),
        format!("{config:#?}"),
        format!("{agent:?}"),
    ] {
        assert!(text.contains("<redacted>"), "{text}");
        assert!(!text.contains(&bytes_debug), "key bytes in {text}");
        assert!(!text.contains(&bytes_hex), "key hex in {text}");
        assert!(!text.contains("swarm key"), "key text in {text}");
    }
}

type Receiver = Agent<f32, 1, 2>;

/// Agent `id` of triangle (1, 2, 3) with angles at 1 and 2, `auth` integrity.
fn config(id: AgentId) -> AgentConfig<f32, 1> {
    testkit::one_triangle(id, Integrity::Auth(KEY))
}

fn broadcast<const MT: usize, const NB: usize>(a: &mut Agent<f32, MT, NB>) -> Vec<Vec<u8>> {
    let mut out = Vec::new();
    a.frames(|b| out.push(b.to_vec()));
    out
}

#[test]
fn a_rebooted_neighbour_is_heard_again_only_with_a_larger_epoch() {
    let mut rx = Receiver::new(config(3)).expect("valid");
    let mut tx = Receiver::new(config(1)).expect("valid");
    tx.set_boot_epoch(4);
    assert_eq!(tx.next_counter(), counter(4, 0));
    let first = broadcast(&mut tx);
    let second = broadcast(&mut tx);
    assert_eq!(tx.next_counter(), counter(4, 2));
    rx.receive(&first[0])
        .expect("first contact: the frame carries its counter");
    rx.receive(&second[0]).expect("newer");
    assert!(matches!(
        rx.receive(&first[0]),
        Err(FrameError::Replayed { sender: 1, counter: c }) if c == counter(4, 0)
    ));

    // Reboot that forgot to advance its epoch: not heard (its counters are old).
    let mut same = Receiver::new(config(1)).expect("valid");
    same.set_boot_epoch(4);
    assert!(matches!(
        rx.receive(&broadcast(&mut same)[0]),
        Err(FrameError::Replayed { .. })
    ));
    // Reboot with the next epoch: heard at once; everything of epoch 4 is now old.
    let mut rebooted = Receiver::new(config(1)).expect("valid");
    rebooted.set_boot_epoch(5);
    rx.receive(&broadcast(&mut rebooted)[0]).expect("new epoch");
    assert!(matches!(
        rx.receive(&second[0]),
        Err(FrameError::Replayed { .. })
    ));
    let s = rx.stats();
    assert_eq!((s.accepted, s.replayed, s.rejected()), (3, 3, 3));
}

#[test]
fn full_broadcasts_add_a_sync_frame_and_receivers_sync_on_it() {
    // A fan of 4 triangles: agent 0 is the apex of 4 angles, one full frame per
    // broadcast with no room for the counter extension.
    let mut agents = auth_fan(4, 10);
    let (centre, rims) = agents.split_at_mut(1);
    let centre = &mut centre[0];
    centre.set_boot_epoch(2);
    let rim = &mut rims[0];
    for b in 0..17u64 {
        let frames: Vec<Vec<u8>> = {
            let mut out = Vec::new();
            centre.frames(|x| out.push(x.to_vec()));
            out
        };
        let lens: Vec<usize> = frames.iter().map(Vec::len).collect();
        if b % 8 == 0 {
            assert_eq!(lens, [60, 12 + COUNTER_EXT_LEN + TAG_LEN], "broadcast {b}");
        } else {
            assert_eq!(lens, [60], "broadcast {b}");
        }
        let results: Vec<_> = frames.iter().map(|x| rim.receive(x)).collect();
        if b == 0 {
            // First contact: the full frame cannot be placed, the sync frame can.
            assert_eq!(results, [Err(FrameError::Unsynced(1)), Ok(())]);
        } else {
            assert!(
                results.iter().all(Result::is_ok),
                "broadcast {b}: {results:?}"
            );
        }
    }
    assert_eq!(rim.stats().unsynced, 1);
}

#[test]
fn the_centre_of_a_full_fan_sends_at_most_max_frames_per_tick() {
    // A fan of MAX_TRIANGLES triangles under `auth`: agent 0 is the apex of one angle
    // per triangle, items fill whole frames, and every eighth broadcast adds a sync frame:
    // the bound of `MAX_FRAMES_PER_TICK` is reached and never passed.
    let mut agents = auth_fan(ph_formation_core::MAX_TRIANGLES, 11);
    let counts: Vec<usize> = (0..9).map(|_| agents[0].frames(|_| ())).collect();
    let bound = HostAgent::<f64>::MAX_FRAMES_PER_TICK;
    assert_eq!(bound, 3);
    assert_eq!(counts.iter().max(), Some(&bound), "{counts:?}");
}

/// The agents of a fan of `k` triangles around agent 0 (random formation from `seed`)
/// with `auth` integrity, after one sensing and exchange.
fn auth_fan(k: usize, seed: u64) -> Vec<HostAgent<f64>> {
    let mut r = rng(seed);
    let q = fan_positions(k, 0.05, &mut r);
    let f = Formation::random(k + 2, fan(k), &q, &mut r);
    let s = State {
        q: q.clone(),
        v: vec![ph_formation_core::Vec2::new(0.1, 0.0); k + 2],
    };
    let mut agents: Vec<HostAgent<f64>> = (0..k + 2)
        .map(|i| {
            let mut c = f.config::<f64>(i);
            c.integrity = Integrity::Auth(KEY);
            HostAgent::new(c).expect("valid")
        })
        .collect();
    sense_and_exchange(&f, &s, &mut agents, 0.0, 0.0);
    agents
}
