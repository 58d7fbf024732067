//! Wire frames between agents: round trip, size limit, rejection of corrupt, stale,
//! repeated, foreign and non-finite frames, and fuzzing of the decoder.

use controller_core::wire::{
    decode_frame, FrameHeader, FrameWriter, WireItem, MAX_FRAME_LEN, WIRE_VERSION,
};
use controller_core::{FrameError, Measurements, Vec2};
use ph_formation_tests::{
    bearings, fan, fan_positions, rng, sense_and_exchange, strip, strip_positions, Formation,
    HostAgent, State,
};
use proptest::prelude::*;

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

#[test]
fn frames_round_trip_between_agents() {
    for seed in 0..50 {
        let (f, s) = setup(seed, 6);
        // Reference: direct exchange at full precision.
        let mut direct = f.agents::<f64>();
        sense_and_exchange(&f, &s, &mut direct, 0.0, 0.0);
        // Over the wire.
        let mut wired = f.agents::<f64>();
        let frames = sense_and_encode(&f, &s, &mut wired);
        for (i, rx) in wired.iter_mut().enumerate() {
            for j in f.neighbours(i) {
                for fr in &frames[j] {
                    rx.receive(fr).expect("valid frame accepted");
                }
            }
        }
        for (d, w) in direct.iter().zip(&wired) {
            let (fd, fw) = (
                d.evaluate().expect("ok").force,
                w.evaluate().expect("ok").force,
            );
            // f32 on the wire: relative error ≤ ~1e-6 of the force scale.
            assert!(
                (fd - fw).norm() <= 1e-5 * (1.0 + fd.norm()),
                "seed {seed}: {fd:?} vs {fw:?}"
            );
            assert_eq!(w.stats().rejected(), 0);
        }
    }
}

#[test]
fn every_frame_fits_the_crazyflie_payload_for_up_to_8_triangles() {
    for k in 1..=8 {
        let mut r = rng(k as u64);
        let q = fan_positions(k, 0.1, &mut r);
        let f = Formation::random(k + 2, fan(k), &q, &mut r);
        let s = State {
            v: vec![Vec2::new(0.5, -0.25); k + 2],
            q,
        };
        let mut agents = f.agents::<f64>();
        let frames = sense_and_encode(&f, &s, &mut agents);
        let centre = &frames[0];
        assert!(!centre.is_empty());
        for fr in frames.iter().flatten() {
            assert!(
                fr.len() <= MAX_FRAME_LEN,
                "{k} triangles: a {}-byte frame",
                fr.len()
            );
        }
        eprintln!(
            "fan centre in {k} triangles: {} frames, {} bytes",
            centre.len(),
            centre.iter().map(Vec::len).sum::<usize>()
        );
    }
}

fn one_frame() -> (Formation, Vec<HostAgent<f64>>, Vec<u8>) {
    let (f, s) = setup(7, 4);
    let mut agents = f.agents::<f64>();
    let frames = sense_and_encode(&f, &s, &mut agents);
    // Agent 0 and 1 are neighbours in a strip.
    (f, agents, frames[1][0].clone())
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
    let mut w = FrameWriter::new(1, 0);
    assert!(w.push(&WireItem::Velocity([0.0, 0.0])));
    assert_eq!(agents[0].receive(w.finish()), Err(FrameError::OwnFrame));
    let mut w = FrameWriter::new(99, 0);
    assert!(w.push(&WireItem::Velocity([0.0, 0.0])));
    assert_eq!(
        agents[0].receive(w.finish()),
        Err(FrameError::UnknownSender(99))
    );
    assert_eq!(agents[0].stats().unknown_sender, 2);
}

/// An angle item from agent 2 for agent 1: its second bearing is `s1`, one rate `rate`, the
/// estimates `r`.
fn angle(s1: [f32; 2], rate: [f32; 2], r: [f32; 2]) -> WireItem {
    WireItem::Angle {
        far: [1, 3],
        s: [[1.0, 0.0], s1],
        rate: [[0.0; 2], rate],
        r,
    }
}

/// A frame with a valid CRC around arbitrary header and item bytes.
fn with_crc(body: &[u8]) -> Vec<u8> {
    let crc = crc::Crc::<u16>::new(&crc::CRC_16_IBM_SDLC).checksum(body);
    let mut v = body.to_vec();
    v.extend_from_slice(&crc.to_le_bytes());
    v
}

#[test]
fn unknown_version_and_invalid_values_are_rejected() {
    let (_, mut agents, _) = one_frame();
    let rx = &mut agents[0];
    let mut body = postcard::to_allocvec(&(WIRE_VERSION + 1, 2u8, 5u16)).expect("encode");
    body.extend(postcard::to_allocvec(&WireItem::Velocity([0.0, 0.0])).expect("encode"));
    assert_eq!(
        rx.receive(&with_crc(&body)),
        Err(FrameError::UnknownVersion(WIRE_VERSION + 1))
    );
    let bad_items = [
        WireItem::Velocity([f32::NAN, 0.0]),
        WireItem::Velocity([0.0, f32::INFINITY]),
        angle([0.0, 0.0], [0.0; 2], [1.0; 2]),
        angle([0.6, 0.9], [0.0; 2], [1.0; 2]),
        angle([1.0, 0.0], [f32::NAN, 0.0], [1.0; 2]),
        angle([1.0, 0.0], [0.0, f32::INFINITY], [1.0; 2]),
        angle([1.0, 0.0], [0.0; 2], [0.0, 1.0]),
        angle([1.0, 0.0], [0.0; 2], [1.0, -1.0]),
        angle([1.0, 0.0], [0.0; 2], [f32::NAN, 1.0]),
        WireItem::AngleBearings {
            far: [1, 3],
            s: [[1.0, 0.0], [0.0, 2.0]],
            rate: [[0.0; 2]; 2],
        },
    ];
    for (k, item) in bad_items.iter().enumerate() {
        let mut w = FrameWriter::new(2, 100 + k as u16);
        assert!(w.push(item));
        assert_eq!(
            rx.receive(w.finish()),
            Err(FrameError::InvalidValue),
            "{item:?}"
        );
    }
    assert_eq!(rx.stats().invalid_value, bad_items.len() as u32);
    assert_eq!(rx.stats().unknown_version, 1);
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

proptest! {
    #![proptest_config(ProptestConfig::with_cases(3000))]
    /// Random bytes never panic and are rejected.
    #[test]
    fn random_bytes_are_rejected(bytes in proptest::collection::vec(any::<u8>(), 0..80)) {
        let (_, mut agents, _) = one_frame();
        prop_assert!(agents[0].receive(&bytes).is_err());
        prop_assert!(decode_frame(&bytes, 1e-3).is_err() || bytes.len() <= MAX_FRAME_LEN);
    }

    /// The slice-by-4 CRC equals the `crc` crate's CRC-16/IBM-SDLC on every length.
    #[test]
    fn crc_matches_the_crc_crate(bytes in proptest::collection::vec(any::<u8>(), 0..80)) {
        let reference = crc::Crc::<u16>::new(&crc::CRC_16_IBM_SDLC);
        prop_assert_eq!(controller_core::crc16::checksum(&bytes), reference.checksum(&bytes));
    }

    /// Arbitrary well-formed item sequences round-trip through a frame exactly.
    #[test]
    fn writer_and_decoder_round_trip(
        sender in any::<u8>(), seq in any::<u16>(), item in item_strategy(),
        vel in proptest::array::uniform2(-1e3f32..1e3),
    ) {
        let items = [WireItem::Velocity(vel), item];
        let mut w = FrameWriter::new(sender, seq);
        for it in &items {
            prop_assert!(w.push(it));
        }
        let bytes = w.finish().to_vec();
        prop_assert!(bytes.len() <= MAX_FRAME_LEN);
        let frame = decode_frame(&bytes, 1e-3).expect("round trip");
        prop_assert_eq!(frame.header.sender, sender);
        prop_assert_eq!(frame.header.seq, seq);
        prop_assert_eq!(&frame.items[..], &items[..]);
    }

    /// The hand-written encoder writes exactly what `postcard` writes, and the CRC is
    /// CRC-16/IBM-SDLC as the `crc` crate computes it.
    #[test]
    fn frames_are_postcard_bytes(
        sender in any::<u8>(), seq in any::<u16>(),
        items in proptest::collection::vec(item_strategy(), 0..3),
    ) {
        let mut w = FrameWriter::new(sender, seq);
        let mut expected = postcard::to_allocvec(&FrameHeader { version: WIRE_VERSION, sender, seq }).expect("encode");
        for it in &items {
            if w.push(it) {
                expected.extend(postcard::to_allocvec(it).expect("encode"));
            }
        }
        let bytes = w.finish().to_vec();
        prop_assert_eq!(&bytes[..bytes.len() - 2], &expected[..]);
        prop_assert_eq!(bytes, with_crc(&expected));
    }

    /// On any bytes behind a valid CRC, the hand-written decoder accepts exactly what
    /// `postcard` accepts, with the same values (bit for bit, NaNs included).
    #[test]
    fn decoder_agrees_with_postcard(body in body_strategy()) {
        let frame = with_crc(&body);
        let ours = decode_frame(&frame, f32::INFINITY);
        let theirs = postcard_decode(&body);
        match (ours, theirs) {
            (Ok(f), Some((h, items))) => {
                prop_assert_eq!(f.header, h);
                prop_assert_eq!(bits(&f.items), bits(&items));
            }
            (Err(FrameError::InvalidValue), Some(_)) => {} // NaN/∞ values: postcard decodes them
            (Err(FrameError::UnknownVersion(_)), Some((h, _))) => prop_assert_ne!(h.version, WIRE_VERSION),
            (Err(_), None) => {}
            (ours, theirs) => prop_assert!(false, "ours {:?}, postcard {:?}", ours, theirs),
        }
    }
}

/// Valid items of every kind, with random values.
fn item_strategy() -> impl Strategy<Value = WireItem> {
    let unit = (0.0f32..std::f32::consts::TAU).prop_map(|a| [libm::cosf(a), libm::sinf(a)]);
    let pair = proptest::array::uniform2(-10f32..10.0);
    (
        0..3u8,
        proptest::array::uniform2(any::<u8>()),
        [unit.clone(), unit],
        [pair.clone(), pair],
        proptest::array::uniform2(0.01f32..100.0),
    )
        .prop_map(|(kind, far, s, rate, r)| match kind {
            0 => WireItem::Velocity(rate[0]),
            1 => WireItem::Angle { far, s, rate, r },
            _ => WireItem::AngleBearings { far, s, rate },
        })
}

/// Frame bodies: random bytes, and valid bodies with a few random byte changes, cuts and
/// non-canonical varints.
fn body_strategy() -> impl Strategy<Value = Vec<u8>> {
    prop_oneof![
        valid_body(),
        mutated_body(),
        proptest::collection::vec(any::<u8>(), 0..58),
        // A non-canonical (two-byte) variant index, or a long sequence number.
        Just(vec![
            WIRE_VERSION,
            1,
            0x81,
            0x80,
            0x01,
            0x80,
            0x00,
            0,
            0,
            0,
            0,
            0,
            0,
            0,
            0
        ]),
        Just(vec![WIRE_VERSION, 1, 0xff, 0xff, 0x03]),
        Just(vec![WIRE_VERSION, 1, 0xff, 0xff, 0x04]),
    ]
}

fn valid_body() -> impl Strategy<Value = Vec<u8>> {
    (
        any::<u8>(),
        any::<u16>(),
        proptest::collection::vec(item_strategy(), 0..2),
    )
        .prop_map(|(sender, seq, items)| {
            let mut b = postcard::to_allocvec(&FrameHeader {
                version: WIRE_VERSION,
                sender,
                seq,
            })
            .expect("encode");
            for it in &items {
                b.extend(postcard::to_allocvec(it).expect("encode"));
            }
            b
        })
}

fn mutated_body() -> impl Strategy<Value = Vec<u8>> {
    (
        valid_body(),
        proptest::collection::vec((any::<usize>(), any::<u8>()), 1..4),
        any::<usize>(),
        any::<bool>(),
    )
        .prop_map(|(mut b, changes, cut, do_cut)| {
            let n = b.len();
            for (at, v) in changes {
                b[at % n] = v;
            }
            if do_cut {
                b.truncate(cut % (n + 1));
            }
            b
        })
}

/// Header and items as `postcard` decodes them (`None`: it fails somewhere).
fn postcard_decode(body: &[u8]) -> Option<(FrameHeader, Vec<WireItem>)> {
    let (h, mut rest) = postcard::take_from_bytes::<FrameHeader>(body).ok()?;
    let mut items = Vec::new();
    while !rest.is_empty() {
        let (it, r) = postcard::take_from_bytes::<WireItem>(rest).ok()?;
        items.push(it);
        rest = r;
    }
    Some((h, items))
}

/// Items with every `f32` as its bits (so that NaNs compare).
fn bits(items: &[WireItem]) -> Vec<Vec<u32>> {
    items
        .iter()
        .map(|it| match *it {
            WireItem::Velocity(v) => v.iter().map(|x| x.to_bits()).collect(),
            WireItem::Angle { far, s, rate, r } => [far[0] as u32, far[1] as u32, 1]
                .into_iter()
                .chain(
                    s.iter()
                        .chain(&rate)
                        .flatten()
                        .chain(&r)
                        .map(|x| x.to_bits()),
                )
                .collect(),
            WireItem::AngleBearings { far, s, rate } => [far[0] as u32, far[1] as u32, 2]
                .into_iter()
                .chain(s.iter().chain(&rate).flatten().map(|x| x.to_bits()))
                .collect(),
        })
        .collect()
}

proptest! {
    /// COBS framing: a stream of encoded frames (with a corrupt chunk in between) splits
    /// back into exactly the frames, and the corrupt chunk is reported, not fatal.
    #[test]
    fn cobs_stream_round_trip(frames in proptest::collection::vec(proptest::collection::vec(any::<u8>(), 1..=MAX_FRAME_LEN), 1..5)) {
        use controller_core::wire::{cobs_encode, CobsAccumulator, MAX_COBS_LEN};
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
    use controller_core::link::{HostMsg, LinkBearing, LinkStep, MAX_LINK_BEARINGS, MAX_LINK_MSG};
    // The largest configuration the HIL link carries: 4 triangles, leader, schedules full.
    let mut r = rng(1);
    let f = Formation::random(6, fan(4), &fan_positions(4, 0.1, &mut r), &mut r);
    let mut cfg = f.config::<f32>(0);
    let full = |c: &mut controller_core::Schedule<f32>| {
        while c
            .steps
            .push(controller_core::ScheduleStep {
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
    let small: controller_core::AgentConfig<f32, 4> = controller_core::AgentConfig {
        triangles: cfg.triangles.iter().copied().collect(),
        ..controller_core::AgentConfig::new(cfg.id)
    };
    let small = controller_core::AgentConfig {
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
