//! Feeds arbitrary bytes to agents as radio frames and as measurements, interleaved: one
//! agent with `crc16` integrity (the frame's CRC is sometimes made valid, so that the
//! fuzzer reaches past it) and one with `link` integrity (no CRC: every byte reaches the
//! decoder), and one with `auth` integrity (the frame is sometimes signed with the swarm
//! key and the counter its extension carries, so that the fuzzer reaches the replay
//! logic and the decoder behind the tag). Invariants: no panic; a frame the agent accepts
//! is one `decode_frame` accepts (`auth`: when it carries its counter); with `auth` the
//! carried counters accepted from one sender strictly increase; the force is always
//! finite and within `max_force`; every outgoing frame is at most 60 bytes and decodes.
//! And the two decoders agree on every frame, incoming and outgoing, for every agent:
//! the fast path (`check_frame`, `decode_frame`) and postcard's deserializer
//! (`postcard::take_from_bytes::<Frame>`, `Frame::decode`) accept and reject alike and
//! give the same frame. The `crc16` and `auth` agents run the bearing tracker (SPEC §11,
//! the default), the `link` agent the finite difference: arbitrary bearings, velocities
//! and time steps reach both, and the force stays finite and bounded. Half the chunks
//! (bit 7 of the chunk's first byte) give the bearings as angles (unit vectors, which
//! pass the unit-length check and reach the tracker, the hold and the law), the time step
//! and the velocity folded into plausible ranges (NaN and ∞ kept), and some bearings
//! missing; every agent's force also drives its actuator (SPEC S20–S21c, a gap bound and
//! a stall limit), whose setpoint must stay finite.
#![no_main]

use ph_formation_core::wire::{
    auth, check_frame, decode_frame, mode_byte, CounterExt, Frame, Integrity, SwarmKey,
};
use ph_formation_core::{
    Agent, AgentConfig, AngleConfig, BearingMeasurement, EstimatorMode, Measurements,
    TriangleConfig, Vec2,
};
use libfuzzer_sys::fuzz_target;
use ph_formation_core::actuate::{VelocityCommand, VirtualMass};

fn agent(integrity: Integrity) -> Agent<f32, 2, 4> {
    let angle = |apex, cos| AngleConfig {
        apex,
        cos_desired: cos,
        stiffness: 10.0,
        damping: 1.0,
        estimator_gain: 10.0,
    };
    let mut c = AgentConfig::<f32, 2>::new(3);
    if matches!(integrity, Integrity::Link) {
        c.bearing_filter = ph_formation_core::BearingFilter::FiniteDifference;
    }
    c.integrity = integrity;
    let _ = c.triangles.push(TriangleConfig {
        vertices: [1, 2, 3],
        angles: [angle(1, 0.0), angle(3, 0.707)],
    });
    let _ = c.triangles.push(TriangleConfig {
        vertices: [2, 3, 4],
        angles: [angle(2, 0.707), angle(3, 0.707)],
    });
    match Agent::new(c) {
        Ok(a) => a,
        Err(_) => unreachable!("the fuzz configuration is valid"),
    }
}

/// `x` folded into `(−m, m)` (NaN and ∞ kept: they must be refused).
fn fold(x: f32, m: f32) -> f32 {
    if x.is_finite() {
        x % m
    } else {
        x
    }
}

fn f32_at(data: &[u8], i: usize) -> f32 {
    let mut b = [0u8; 4];
    for (k, x) in b.iter_mut().enumerate() {
        *x = data.get(i + k).copied().unwrap_or(0);
    }
    f32::from_le_bytes(b)
}

const KEY: SwarmKey = SwarmKey::new(*b"fuzzing key 16 B");

/// Frames equal field for field, the velocity bit for bit.
fn same(a: &Frame, b: &Frame) -> bool {
    a.header == b.header
        && a.velocity.map(f32::to_bits) == b.velocity.map(f32::to_bits)
        && a.angles == b.angles
        && a.counter_ext == b.counter_ext
}

/// The fast decoders and postcard's agree on `bytes` for a receiver with `integrity`
/// (shared estimates): structurally (`check_frame` against `take_from_bytes` of the
/// bytes before the trailer, nothing left over, the receiver's modes, the CRC) and
/// completely (`decode_frame` against `Frame::decode`).
fn decoders_agree(bytes: &[u8], integrity: Integrity) {
    let est = EstimatorMode::Shared;
    let fast = check_frame(bytes, integrity, est);
    let trailer = integrity.trailer_len();
    let slow = (bytes.len() <= 60)
        .then(|| bytes.split_at_checked(bytes.len().checked_sub(trailer)?))
        .flatten()
        .filter(|(body, crc)| match integrity {
            Integrity::Crc16 => crc16(body) == **crc,
            _ => true,
        })
        .and_then(|(body, _)| postcard::take_from_bytes::<Frame>(body).ok())
        .filter(|(f, rest)| rest.is_empty() && f.header.mode == mode_byte(integrity, est));
    assert_eq!(
        fast.is_ok(),
        slow.is_some(),
        "{integrity}: {fast:?} {bytes:02x?}"
    );
    if let (Ok(view), Some((frame, _))) = (fast, slow) {
        let from_view = Frame {
            header: view.header,
            velocity: view.velocity,
            angles: view.angles().collect(),
            counter_ext: view.carried_counter().map(CounterExt::of_counter),
        };
        assert!(same(&from_view, &frame), "{from_view:?} {frame:?}");
    }
    let fast = decode_frame(bytes, integrity, est);
    let slow = Frame::decode(bytes, integrity, est);
    assert_eq!(
        fast.is_ok(),
        slow.is_ok(),
        "{integrity}: {fast:?} {slow:?} {bytes:02x?}"
    );
    if let (Ok(a), Ok(b)) = (&fast, &slow) {
        assert!(same(a, b), "{a:?} {b:?}");
    }
}

/// Re-signs an `auth` frame that carries its counter (tag over that counter and the bytes).
fn sign(bytes: &mut [u8]) {
    let Ok(view) = check_frame(bytes, Integrity::Auth(KEY), EstimatorMode::Shared) else {
        return;
    };
    let Some(c) = view.carried_counter() else {
        return;
    };
    let n = bytes.len() - auth::TAG_LEN;
    let tag = auth::tag(&KEY, c, &bytes[..n]);
    bytes[n..].copy_from_slice(&tag);
}

fn crc16(body: &[u8]) -> [u8; 2] {
    ph_formation_core::crc16::checksum(body).to_le_bytes()
}

fuzz_target!(|data: &[u8]| {
    let mut agents = [
        (agent(Integrity::Crc16), Integrity::Crc16),
        (agent(Integrity::Link), Integrity::Link),
        (agent(Integrity::Auth(KEY)), Integrity::Auth(KEY)),
    ];
    // `auth`: the last carried counter accepted per sender.
    let mut last = [None::<u64>; 256];
    let limit = agents[0].0.config().limits.max_force;
    let plant = VirtualMass::new(1.0f32, [0.5; 2], 2.0)
        .and_then(|p| p.with_lead(0.2))
        .and_then(|p| p.with_second_lead(0.04))
        .and_then(|p| p.with_max_gap(0.5))
        .and_then(|p| p.with_max_interval(0.1));
    let Ok(plant) = plant else {
        unreachable!("the fuzz plant is valid")
    };
    let mut commands = [VelocityCommand::new(plant); 3];
    // Chunks: one byte (bits 0–5: frame length L ≤ 63; bit 6: make the CRC or tag valid), the
    // frame's L bytes, then 40 bytes of measurement floats.
    let mut rest = data;
    while let Some((&head, tail)) = rest.split_first() {
        let len = usize::from(head & 63).min(tail.len());
        let (frame, tail) = tail.split_at(len);
        let m = tail.get(..40).unwrap_or(tail);
        // Bit 7: the math path (angles, plausible dt and velocity, bearings missing).
        let angles = head & 128 != 0;
        let missing = m.get(39).copied().unwrap_or(0);
        let all: [BearingMeasurement<f32>; 3] = core::array::from_fn(|k| BearingMeasurement {
            neighbour: [1, 2, 4][k],
            bearing: if angles {
                let a = f32_at(m, 8 * k);
                let (sin, cos) = (libm::sinf(a), libm::cosf(a));
                // A non-finite angle gives a NaN bearing: refused.
                Vec2::new(cos, sin) * (1.0 + f32_at(m, 8 * k + 4).abs().min(1.0) * 1e-4)
            } else {
                Vec2::new(f32_at(m, 8 * k), f32_at(m, 8 * k + 4))
            },
            rate: None,
            range: None,
        });
        let mut kept = [all[0]; 3];
        let mut n = 0;
        for (k, b) in all.iter().enumerate() {
            if !(angles && missing & (1 << k) != 0) {
                kept[n] = *b;
                n += 1;
            }
        }
        let bearings = &kept[..n];
        let (dt, vx, vy) = (f32_at(m, 28), f32_at(m, 32), f32_at(m, 36));
        let (dt, vx, vy) = if angles {
            (fold(dt.abs(), 0.3), fold(vx, 3.0), fold(vy, 3.0))
        } else {
            (dt, vx, vy)
        };
        let meas = Measurements {
            time: f32_at(m, 24),
            dt,
            velocity: Vec2::new(vx, vy),
            bearings,
            partner_offset: None,
        };
        for ((a, integrity), command) in agents.iter_mut().zip(&mut commands) {
            let mut bytes = frame.to_vec();
            if *integrity == Integrity::Crc16 && head & 64 != 0 && bytes.len() >= 2 {
                let n = bytes.len() - 2;
                let crc = crc16(&bytes[..n]);
                bytes[n..].copy_from_slice(&crc);
            }
            if matches!(integrity, Integrity::Auth(_)) && head & 64 != 0 {
                sign(&mut bytes);
            }
            decoders_agree(&bytes, *integrity);
            if a.receive(&bytes).is_ok() {
                let view = check_frame(&bytes, *integrity, EstimatorMode::Shared);
                let carried = view.ok().and_then(|v| v.carried_counter());
                match (&*integrity, carried) {
                    (Integrity::Auth(_), None) => {}
                    _ => assert!(decode_frame(&bytes, *integrity, EstimatorMode::Shared).is_ok()),
                }
                if let (Integrity::Auth(_), Some(c)) = (&*integrity, carried) {
                    let prev = &mut last[usize::from(bytes[1])];
                    assert!(prev.is_none_or(|p| c > p), "counter not increasing");
                    *prev = Some(c);
                }
            }
            let out = a.step(&meas);
            assert!(out.force.x.is_finite() && out.force.y.is_finite());
            assert!(out.force.norm() <= limit * 1.0001);
            let sp = command.step([out.force.x, out.force.y], [vx, vy], dt);
            assert!(sp.iter().all(|x| x.is_finite()), "{sp:?}");
            let integrity = *integrity;
            a.frames(|f| {
                assert!(f.len() <= 60);
                let d = decode_frame(f, integrity, EstimatorMode::Shared);
                assert!(d.is_ok(), "{integrity}: {d:?} {f:02x?}");
                decoders_agree(f, integrity);
            });
        }
        rest = tail.get(40..).unwrap_or(&[]);
    }
});
