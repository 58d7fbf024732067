//! Wire frames (version 4) between agents: round trip within the documented rounding,
//! one compact frame per agent and tick, rejection of corrupt, stale, repeated, foreign,
//! misconfigured and non-finite frames, an independent decoder of the documented layout,
//! and fuzzing of the decoder.

mod testkit;

use ph_formation_core::wire::{
    check_frame, decode_frame, mode_byte, mode_with_items, quant, FrameWriter, Integrity,
    MAX_FRAME_LEN,
};
use ph_formation_core::{EstimatorMode, FrameError, Measurements, Vec2};
use proptest::prelude::*;
use testkit::{
    bearings, fan, fan_positions, rng, sense_and_exchange, strip, strip_positions, Formation,
    HostAgent, State,
};

/// Senses the true state on every agent, then returns each agent's encoded frames.
fn sense_and_encode(f: &Formation, s: &State, agents: &mut [HostAgent<f64>]) -> Vec<Vec<Vec<u8>>> {
    for (i, a) in agents.iter_mut().enumerate() {
        let b = bearings::<f64>(f, s, i, true);
        let partner = f
            .leader
            .and_then(|(la, lb, ..)| (i == la).then_some(lb).or((i == lb).then_some(la)));
        a.sense(&Measurements {
            time: 0.0,
            dt: 0.0,
            velocity: s.v[i],
            bearings: &b,
            partner_offset: partner.map(|p| s.q[p] - s.q[i]),
        })
        .expect("valid");
    }
    agents
        .iter_mut()
        .map(|a| {
            let mut out = Vec::new();
            a.frames(|bytes| out.push(bytes.to_vec()));
            out
        })
        .collect()
}

fn setup(seed: u64, n: usize) -> (Formation, State) {
    let mut r = rng(seed);
    let f = Formation::random(n, strip(n), &strip_positions(n, 0.1, &mut r), &mut r);
    let q = strip_positions(n, 0.2, &mut r);
    let v = q
        .iter()
        .enumerate()
        .map(|(i, _)| Vec2::new(0.1 * i as f64, -0.2))
        .collect();
    (f, State { q, v })
}

const SHARED: u8 = mode_byte(Integrity::Crc16, EstimatorMode::Shared);

/// The frames over the wire give the same forces as a direct exchange, within the
/// documented rounding (relative 2⁻¹¹ per value, `wire::quant`): a far vertex's S8 force
/// `γσ/r` then carries a relative error of at most about 3·2⁻¹¹ (γ, σ, r each rounded),
/// so an agent's force is off by at most that times the far-vertex forces it received.
#[test]
fn frames_round_trip_between_agents_within_the_rounding_bound() {
    for mode in [
        EstimatorMode::Shared,
        EstimatorMode::PerAgent,
        EstimatorMode::Measured,
    ] {
        for seed in 0..50 {
            let (mut f, s) = setup(seed, 6);
            f.mode = mode;
            let mut direct = f.agents::<f64>();
            sense_and_exchange(&f, &s, &mut direct, 0.0, 0.0);
            let mut wired = f.agents::<f64>();
            let frames = sense_and_encode(&f, &s, &mut wired);
            for (i, rx) in wired.iter_mut().enumerate() {
                let me = testkit::id(i);
                let mut received = 0.0;
                for j in f.neighbours(i) {
                    for fr in &frames[j] {
                        rx.receive(fr).expect("valid frame accepted");
                        let frame = decode_frame(fr, Integrity::Crc16, mode).expect("decodes");
                        for it in frame.angles.iter().filter(|it| it.far.contains(&me)) {
                            let k = usize::from(it.far[1] == me);
                            // |γ σ / r| with the distance the far vertex divides by (the
                            // test's distances and estimates are ≥ 0.3).
                            let r = if mode == EstimatorMode::Shared {
                                f32::from(it.range[k])
                            } else {
                                0.3
                            };
                            let (g, s) = (f32::from(it.gamma), f32::from(it.sigma));
                            received += f64::from((g * s / r).abs());
                        }
                    }
                }
                let (fd, fw) = (
                    direct[i].evaluate().expect("ok").force,
                    rx.evaluate().expect("ok").force,
                );
                let bound = received * 3.01 * f64::from(quant::REL_ERROR) + 1e-6;
                assert!(
                    (fd - fw).norm() <= bound,
                    "{mode:?} seed {seed} agent {i}: {fd:?} vs {fw:?} (bound {bound:e})"
                );
                assert_eq!(rx.stats().rejected(), 0);
            }
        }
    }
}

/// Frames per agent and tick, and their size, by role: an apex of up to 4 angles sends
/// ONE frame of at most 60 bytes, the centre of an 8-triangle fan at most 2, every agent
/// that is the apex of at most one angle one frame of at most 32 bytes; with either
/// integrity mode. (With 8 bytes of authentication tag, a 4-angle frame is 60 bytes.)
#[test]
fn one_compact_frame_per_agent_and_tick() {
    for integrity in [Integrity::Crc16, Integrity::Link] {
        for k in 1..=8 {
            let mut r = rng(k as u64);
            let q = fan_positions(k, 0.1, &mut r);
            let f = Formation::random(k + 2, fan(k), &q, &mut r);
            let s = State {
                v: vec![Vec2::new(0.5, -0.25); k + 2],
                q,
            };
            let mut agents: Vec<HostAgent<f64>> = (0..f.n)
                .map(|i| {
                    let mut c = f.config::<f64>(i);
                    c.integrity = integrity;
                    HostAgent::new(c).expect("valid")
                })
                .collect();
            let frames = sense_and_encode(&f, &s, &mut agents);
            for (i, fr) in frames.iter().enumerate() {
                // Formation::random puts the controlled angles at the first two vertices
                // of each triangle: the centre (index 0) is the apex of all k angles.
                let apex_of = f.angles.iter().filter(|a| a.apex == i).count();
                let bytes: Vec<usize> = fr.iter().map(Vec::len).collect();
                assert!(bytes.iter().all(|&b| b <= MAX_FRAME_LEN), "{bytes:?}");
                match apex_of {
                    0 | 1 => assert!(
                        fr.len() == 1 && bytes[0] <= 32,
                        "{integrity:?} k={k} agent {i}: {bytes:?}"
                    ),
                    2..=4 => assert_eq!(fr.len(), 1, "{integrity:?} k={k} agent {i}: {bytes:?}"),
                    _ => assert!(fr.len() <= 2, "{integrity:?} k={k} agent {i}: {bytes:?}"),
                }
            }
            eprintln!(
                "{integrity:?}: fan centre (apex of {k} angles): {} frame(s), {} bytes; a rim agent: {:?} bytes",
                frames[0].len(),
                frames[0].iter().map(Vec::len).sum::<usize>(),
                frames[2].iter().map(Vec::len).collect::<Vec<_>>()
            );
        }
    }
}

fn one_frame() -> (Formation, Vec<HostAgent<f64>>, Vec<u8>) {
    let (f, s) = setup(7, 4);
    let mut agents = f.agents::<f64>();
    let frames = sense_and_encode(&f, &s, &mut agents);
    // Agent 0 and 1 are neighbours in a strip.
    (f, agents, frames[1][0].clone())
}

/// A frame from `sender` with `seq`, velocity `v` and the given angle items (codes of
/// `[γ, σ, r_v, r_w]`).
fn frame(sender: u8, seq: u16, v: [f32; 2], items: &[([u8; 2], [u16; 4])]) -> Vec<u8> {
    let mut w = FrameWriter::new(Integrity::Crc16);
    w.start(SHARED, sender, seq, v);
    for &(far, e) in items {
        assert!(w.push_angle(far, e));
    }
    w.finish().to_vec()
}

/// Bytes with a valid CRC-16/IBM-SDLC (the `crc` crate's) appended.
fn with_crc(body: &[u8]) -> Vec<u8> {
    let crc = crc::Crc::<u16>::new(&crc::CRC_16_IBM_SDLC).checksum(body);
    let mut v = body.to_vec();
    v.extend_from_slice(&crc.to_le_bytes());
    v
}

#[test]
fn repeated_and_stale_sequence_numbers_are_rejected_and_counted() {
    let (_, mut agents, frame) = one_frame();
    let rx = &mut agents[0];
    rx.receive(&frame).expect("first copy accepted");
    assert!(matches!(
        rx.receive(&frame),
        Err(FrameError::StaleSequence { sender: 2, .. })
    ));
    assert_eq!(rx.stats().accepted, 1);
    assert_eq!(rx.stats().stale, 1);
}

#[test]
fn own_and_unknown_senders_are_rejected() {
    let (_, mut agents, _) = one_frame();
    assert_eq!(
        agents[0].receive(&frame(1, 0, [0.0; 2], &[])),
        Err(FrameError::OwnFrame)
    );
    assert_eq!(
        agents[0].receive(&frame(99, 0, [0.0; 2], &[])),
        Err(FrameError::UnknownSender(99))
    );
    assert_eq!(agents[0].stats().unknown_sender, 2);
}

#[test]
fn wrong_version_mode_length_and_values_are_rejected_and_counted() {
    let (_, mut agents, _) = one_frame();
    let rx = &mut agents[0];
    const ONE: u16 = 0x3C00;
    let good = frame(2, 1, [0.5, 0.5], &[([1, 3], [ONE, 0xB800, ONE, ONE])]);
    // Version: bits 7–4 of the mode byte are 8 + the item count (here 9); a version-3
    // frame's nibble (3) and the nibbles no count gives (13: 5 items) are other versions.
    assert_eq!(good[0] >> 4, 9);
    for nibble in [3, 13] {
        let mut other = good[..good.len() - 2].to_vec();
        other[0] = (nibble << 4) | (SHARED & 0x0F);
        assert_eq!(
            rx.receive(&with_crc(&other)),
            Err(FrameError::UnknownVersion(nibble))
        );
    }
    // Integrity and estimator bits that differ from the receiver's.
    for mode in [
        mode_byte(Integrity::Link, EstimatorMode::Shared),
        mode_byte(Integrity::Crc16, EstimatorMode::PerAgent),
        mode_byte(Integrity::Crc16, EstimatorMode::Measured),
        SHARED | 0x03,
    ] {
        let mut b = good[..good.len() - 2].to_vec();
        b[0] = mode_with_items(mode, 1);
        assert_eq!(
            rx.receive(&with_crc(&b)),
            Err(FrameError::ModeMismatch(b[0]))
        );
    }
    // Lengths: not the announced number of items (one byte more; one item more or
    // fewer than announced), too short, too long.
    let mut odd = good[..good.len() - 2].to_vec();
    odd.push(0);
    assert_eq!(rx.receive(&with_crc(&odd)), Err(FrameError::Malformed));
    for count in [0, 2] {
        let mut b = good[..good.len() - 2].to_vec();
        b[0] = mode_with_items(SHARED, count);
        assert_eq!(rx.receive(&with_crc(&b)), Err(FrameError::Malformed));
    }
    assert_eq!(
        rx.receive(&with_crc(&good[..11])),
        Err(FrameError::TooShort)
    );
    assert_eq!(rx.receive(&good[..3]), Err(FrameError::TooShort));
    assert_eq!(rx.receive(&[0u8; 61]), Err(FrameError::TooLong));
    // The same far vertex twice.
    assert_eq!(
        rx.receive(&frame(2, 2, [0.0; 2], &[([3, 3], [0, 0, ONE, ONE])])),
        Err(FrameError::Malformed)
    );
    // Values out of range: non-finite, |σ| > 1, distances ≤ 0 or below r_min = 0.1
    // (the receiver's default; 0x2E66 is 0.0999756, the rounding of 0.1 itself, accepted).
    let bad: [([f32; 2], [u16; 4]); 11] = [
        ([f32::NAN, 0.0], [0, 0, ONE, ONE]),
        ([0.0, f32::INFINITY], [0, 0, ONE, ONE]),
        ([0.0, f32::NEG_INFINITY], [0, 0, ONE, ONE]),
        ([0.0; 2], [0x7C00, 0, ONE, ONE]), // γ = +∞
        ([0.0; 2], [0x7E00, 0, ONE, ONE]), // γ = NaN
        ([0.0; 2], [0, 0x3C01, ONE, ONE]), // σ just above 1
        ([0.0; 2], [0, 0xBC01, ONE, ONE]), // σ just below −1
        ([0.0; 2], [0, 0, 0, ONE]),        // r = 0
        ([0.0; 2], [0, 0, ONE, 0xBC00]),   // r = −1
        ([0.0; 2], [0, 0, ONE, 0xFC00]),   // r = −∞
        ([0.0; 2], [0, 0, 0x2E65, ONE]),   // r just below r_min as rounded
    ];
    for (k, (v, e)) in bad.iter().enumerate() {
        assert_eq!(
            rx.receive(&frame(2, 10 + k as u16, *v, &[([1, 3], *e)])),
            Err(FrameError::InvalidValue),
            "{v:?} {e:?}"
        );
    }
    let st = rx.stats();
    assert_eq!(
        (
            st.unknown_version,
            st.mode_mismatch,
            st.malformed,
            st.bad_length,
            st.invalid_value,
            st.accepted
        ),
        (2, 4, 4, 3, 11, 0)
    );
    // Nothing of the rejected frames was applied; σ = ±1 and r = r_min (rounded) are in
    // range.
    rx.receive(&good).expect("valid");
    rx.receive(&frame(
        2,
        100,
        [0.0; 2],
        &[([1, 3], [0, 0xBC00, 0x2E66, ONE])],
    ))
    .expect("valid");
}

#[test]
fn every_single_and_double_bit_flip_is_rejected() {
    let (_, agents, frame) = one_frame();
    let bits = frame.len() * 8;
    let mut rejected = 0;
    for i in 0..bits {
        for j in i..bits {
            let mut bad = frame.clone();
            bad[i / 8] ^= 1 << (i % 8);
            if j != i {
                bad[j / 8] ^= 1 << (j % 8);
            }
            let mut rx = agents[0].clone();
            assert!(rx.receive(&bad).is_err(), "flip {i},{j} accepted");
            rejected += 1;
        }
    }
    assert_eq!(rejected, bits * (bits + 1) / 2);
}

/// binary16 as IEEE 754 defines it, written from the standard (not from the `half` crate
/// the core uses): sign, 5-bit exponent with bias 15, 10-bit fraction, subnormals.
fn f16_reference(code: u16) -> Option<f64> {
    let sign = if code & 0x8000 != 0 { -1.0 } else { 1.0 };
    let exp = i32::from((code >> 10) & 0x1F);
    let frac = f64::from(code & 0x3FF);
    match exp {
        0x1F => None,
        0 => Some(sign * frac / 1024.0 * 2f64.powi(-14)),
        e => Some(sign * (1.0 + frac / 1024.0) * 2f64.powi(e - 15)),
    }
}

/// An independent decoder of the layout table in `wire`'s documentation: byte offsets
/// and types as documented, binary16 from the standard. Returns the mode byte's bits
/// 3–0 and its item count (bits 7–4 minus 8) first.
#[allow(clippy::type_complexity)]
fn reference_decode(b: &[u8]) -> (u8, usize, u8, u16, [f32; 2], Vec<([u8; 2], [f64; 4])>) {
    let f32_at = |i: usize| f32::from_le_bytes([b[i], b[i + 1], b[i + 2], b[i + 3]]);
    let u16_at = |i: usize| u16::from_le_bytes([b[i], b[i + 1]]);
    let items = (12..b.len() - 2)
        .step_by(10)
        .map(|i| {
            let v = |at: usize| f16_reference(u16_at(i + at)).expect("finite");
            ([b[i], b[i + 1]], [v(2), v(4), v(6), v(8)])
        })
        .collect();
    (
        b[0] & 0x0F,
        usize::from(b[0] >> 4) - 8,
        b[1],
        u16_at(2),
        [f32_at(4), f32_at(8)],
        items,
    )
}

/// Valid codes of `[γ, σ, r_v, r_w]`: finite γ, |σ| ≤ 1, r ≥ 0.1.
fn item_codes() -> impl Strategy<Value = [u16; 4]> {
    (
        any::<u16>().prop_filter("finite", |c| c & 0x7C00 != 0x7C00),
        any::<u16>().prop_filter("|σ| ≤ 1", |c| c & 0x7FFF <= 0x3C00),
        0x2E66u16..0x7C00,
        0x2E66u16..0x7C00,
    )
        .prop_map(|(g, s, a, b)| [g, s, a, b])
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(3000))]
    /// Random bytes never panic and are rejected.
    #[test]
    fn random_bytes_are_rejected(bytes in proptest::collection::vec(any::<u8>(), 0..80)) {
        let (_, mut agents, _) = one_frame();
        prop_assert!(agents[0].receive(&bytes).is_err());
        let _ = decode_frame(&bytes, Integrity::Link, EstimatorMode::Shared);
    }

    /// The slice-by-4 CRC equals the `crc` crate's CRC-16/IBM-SDLC on every length.
    #[test]
    fn crc_matches_the_crc_crate(bytes in proptest::collection::vec(any::<u8>(), 0..80)) {
        let reference = crc::Crc::<u16>::new(&crc::CRC_16_IBM_SDLC);
        prop_assert_eq!(ph_formation_core::crc16::checksum(&bytes), reference.checksum(&bytes));
    }

    /// Frames are exactly the documented bytes (checked by an independent decoder and the
    /// `crc` crate), and the core's decoder gives back every field bit for bit.
    #[test]
    fn frames_are_the_documented_bytes(
        sender in any::<u8>(), seq in any::<u16>(),
        vel in proptest::array::uniform2(-1e3f32..1e3),
        items in proptest::collection::vec((any::<u8>(), any::<u8>(), item_codes()), 0..=4),
    ) {
        let items: Vec<([u8; 2], [u16; 4])> = items
            .into_iter()
            .filter(|(a, b, _)| a != b)
            .map(|(a, b, c)| ([a, b], c))
            .collect();
        let bytes = frame(sender, seq, vel, &items);
        prop_assert_eq!(bytes.len(), 12 + 10 * items.len() + 2);
        prop_assert_eq!(&bytes, &with_crc(&bytes[..bytes.len() - 2]));
        let (mode, count, s, q, v, its) = reference_decode(&bytes);
        prop_assert_eq!((mode, count, s, q, v[0].to_bits(), v[1].to_bits()), (SHARED & 0x0F, items.len(), sender, seq, vel[0].to_bits(), vel[1].to_bits()));
        prop_assert_eq!(its.len(), items.len());
        let decoded = decode_frame(&bytes, Integrity::Crc16, EstimatorMode::Shared).expect("valid");
        prop_assert_eq!(decoded.header.sender, sender);
        prop_assert_eq!(decoded.header.seq, seq);
        prop_assert_eq!(decoded.velocity.map(f32::to_bits), vel.map(f32::to_bits));
        prop_assert_eq!(decoded.angles.len(), items.len());
        for ((it, (far, codes)), (rf, re)) in decoded.angles.iter().zip(&items).zip(&its) {
            prop_assert_eq!(it.far, *far);
            prop_assert_eq!(*rf, *far);
            let got = [it.gamma, it.sigma, it.range[0], it.range[1]];
            for k in 0..4 {
                prop_assert_eq!(f64::from(got[k]), re[k]);
                prop_assert_eq!(got[k].0, codes[k]);
                prop_assert_eq!(quant::encode(f32::from(got[k])).0 & 0x7FFF, codes[k] & 0x7FFF);
            }
        }
    }

    /// Any bytes behind a valid CRC: the core's decoder accepts a frame exactly when the
    /// documented layout holds (version 4: bits 7–4 of the mode byte are 8 + the item
    /// count, the receiver's modes in bits 3–0, the announced number of items with two
    /// distinct far vertices, finite values, |σ| ≤ 1, r > 0).
    #[test]
    fn decoder_accepts_exactly_the_documented_frames(
        body in proptest::collection::vec(any::<u8>(), 0..60),
        fix_mode in any::<bool>(),
    ) {
        let mut body = body;
        if fix_mode && !body.is_empty() {
            body[0] = mode_with_items(SHARED, (body.len().saturating_sub(12) / 10).min(4));
        }
        let bytes = with_crc(&body);
        let ours = decode_frame(&bytes, Integrity::Crc16, EstimatorMode::Shared);
        let documented = bytes.len() <= MAX_FRAME_LEN
            && body.len() >= 12
            && body[0] & 0x0F == SHARED & 0x0F
            && (8..=12).contains(&(body[0] >> 4))
            && body.len() == 12 + 10 * usize::from((body[0] >> 4) - 8)
            && f32::from_le_bytes([body[4], body[5], body[6], body[7]]).is_finite()
            && f32::from_le_bytes([body[8], body[9], body[10], body[11]]).is_finite()
            && body[12..].chunks(10).all(|c| {
                let v = |i: usize| f16_reference(u16::from_le_bytes([c[i], c[i + 1]]));
                c[0] != c[1]
                    && v(2).is_some()
                    && v(4).is_some_and(|s| s.abs() <= 1.0)
                    && v(6).is_some_and(|r| r > 0.0)
                    && v(8).is_some_and(|r| r > 0.0)
            });
        prop_assert_eq!(ours.is_ok(), documented, "{:?}", ours);
        if body.len() >= 12 && !(8..=12).contains(&(body[0] >> 4)) && bytes.len() <= MAX_FRAME_LEN {
            prop_assert_eq!(ours, Err(FrameError::UnknownVersion(body[0] >> 4)));
        }
    }
}

/// A link-integrity frame is the crc16 frame without its trailer.
#[test]
fn link_integrity_frames_carry_no_trailer() {
    let mut w = FrameWriter::new(Integrity::Link);
    let mode = mode_byte(Integrity::Link, EstimatorMode::Shared);
    w.start(mode, 2, 7, [1.0, -1.0]);
    assert!(w.push_angle([1, 3], [0x3C00, 0, 0x3C00, 0x3C00]));
    let link = w.finish().to_vec();
    let crc = frame(2, 7, [1.0, -1.0], &[([1, 3], [0x3C00, 0, 0x3C00, 0x3C00])]);
    assert_eq!(link.len() + 2, crc.len());
    assert_eq!(&link[1..], &crc[1..crc.len() - 2]);
    assert!(check_frame(&link, Integrity::Link, EstimatorMode::Shared).is_ok());
    assert_eq!(
        check_frame(&link, Integrity::Crc16, EstimatorMode::Shared).err(),
        Some(FrameError::BadCrc)
    );
}

proptest! {
    /// COBS framing: a stream of encoded frames (with a corrupt chunk in between) splits
    /// back into exactly the frames, and the corrupt chunk is reported, not fatal.
    #[test]
    fn cobs_stream_round_trip(frames in proptest::collection::vec(proptest::collection::vec(any::<u8>(), 1..=MAX_FRAME_LEN), 1..5)) {
        use ph_formation_core::wire::{cobs_encode, CobsAccumulator, MAX_COBS_LEN};
        let mut stream = Vec::new();
        for f in &frames {
            let mut buf = [0u8; MAX_COBS_LEN];
            let n = cobs_encode(f, &mut buf).expect("fits");
            prop_assert_eq!(buf[n - 1], 0);
            prop_assert!(buf[..n - 1].iter().all(|&b| b != 0));
            stream.extend_from_slice(&buf[..n]);
        }
        stream.extend_from_slice(&[0xff; 100]); // overlong garbage chunk
        stream.push(0);
        let mut acc = CobsAccumulator::<MAX_COBS_LEN>::new();
        let mut out = [0u8; MAX_FRAME_LEN];
        let mut got = Vec::new();
        let mut errors = 0;
        for b in stream {
            match acc.push(b, &mut out) {
                Some(Ok(n)) => got.push(out[..n].to_vec()),
                Some(Err(_)) => errors += 1,
                None => {}
            }
        }
        prop_assert_eq!(got, frames);
        prop_assert_eq!(errors, 1);
    }
}

#[test]
fn link_messages_round_trip_within_their_size_limit() {
    use ph_formation_core::link::{
        HostMsg, LinkBearing, LinkStep, MAX_LINK_BEARINGS, MAX_LINK_MSG,
    };
    // The largest configuration the HIL link carries: 4 triangles, leader, schedules full.
    let mut r = rng(1);
    let f = Formation::random(6, fan(4), &fan_positions(4, 0.1, &mut r), &mut r);
    let mut cfg = f.config::<f32>(0);
    let full = |c: &mut ph_formation_core::Schedule<f32>| {
        while c
            .steps
            .push(ph_formation_core::ScheduleStep {
                from: 1.5,
                value: [1.0, -2.0],
            })
            .is_ok()
        {}
    };
    full(&mut cfg.velocity_reference);
    if let Some(l) = cfg.leader.as_mut() {
        full(&mut l.displacement);
    }
    let small: ph_formation_core::AgentConfig<f32, 4> = ph_formation_core::AgentConfig {
        triangles: cfg.triangles.iter().copied().collect(),
        ..ph_formation_core::AgentConfig::new(cfg.id)
    };
    let small = ph_formation_core::AgentConfig {
        leader: cfg.leader.clone(),
        velocity_reference: cfg.velocity_reference.clone(),
        ..small
    };
    let mut bearings = heapless::Vec::new();
    for k in 0..MAX_LINK_BEARINGS {
        let _ = bearings.push(LinkBearing {
            neighbour: k as u8,
            s: [0.6, 0.8],
            rate: Some([0.1, 0.2]),
            range: Some(3.0),
        });
    }
    let msgs: [HostMsg<4>; 3] = [
        HostMsg::Configure(small),
        HostMsg::Step(LinkStep {
            time: 1.0,
            dt: 0.01,
            velocity: [1.0, 2.0],
            bearings,
            partner_offset: Some([1.0, 1.0]),
        }),
        HostMsg::Radio(heapless::Vec::from_slice(&[7u8; MAX_FRAME_LEN]).expect("fits")),
    ];
    for m in &msgs {
        let mut buf = [0u8; MAX_LINK_MSG];
        let bytes = postcard::to_slice(m, &mut buf).expect("fits in MAX_LINK_MSG");
        let back: HostMsg<4> = postcard::from_bytes(bytes).expect("decodes");
        assert_eq!(&back, m);
    }
}
