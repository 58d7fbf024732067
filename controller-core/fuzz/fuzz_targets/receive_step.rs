//! Feeds arbitrary bytes to agents as radio frames and as measurements, interleaved: one
//! agent with `crc16` integrity (the frame's CRC is sometimes made valid, so that the
//! fuzzer reaches past it) and one with `link` integrity (no CRC: every byte reaches the
//! decoder), and one with `auth` integrity (the frame is sometimes signed with the swarm
//! key and the counter its extension carries, so that the fuzzer reaches the replay
//! logic and the decoder behind the tag). Invariants: no panic; a frame the agent accepts
//! is one `decode_frame` accepts (`auth`: when it carries its counter); with `auth` the
//! carried counters accepted from one sender strictly increase; the force is always
//! finite and within `max_force`; every outgoing frame is at most 60 bytes and decodes.
#![no_main]

use controller_core::wire::{auth, check_frame, decode_frame, Integrity, SwarmKey};
use controller_core::{
    Agent, AgentConfig, AngleConfig, BearingMeasurement, EstimatorMode, Measurements,
    TriangleConfig, Vec2,
};
use libfuzzer_sys::fuzz_target;

fn agent(integrity: Integrity) -> Agent<f32, 2, 4> {
    let angle = |apex, cos| AngleConfig {
        apex,
        cos_desired: cos,
        stiffness: 10.0,
        damping: 1.0,
        estimator_gain: 10.0,
    };
    let mut c = AgentConfig::<f32, 2>::new(3);
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

fn f32_at(data: &[u8], i: usize) -> f32 {
    let mut b = [0u8; 4];
    for (k, x) in b.iter_mut().enumerate() {
        *x = data.get(i + k).copied().unwrap_or(0);
    }
    f32::from_le_bytes(b)
}

const KEY: SwarmKey = SwarmKey::new(*b"fuzzing key 16 B");

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
    controller_core::crc16::checksum(body).to_le_bytes()
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
    // Chunks: one byte (bits 0–5: frame length L ≤ 63; bit 6: make the CRC or tag valid), the
    // frame's L bytes, then 40 bytes of measurement floats.
    let mut rest = data;
    while let Some((&head, tail)) = rest.split_first() {
        let len = usize::from(head & 63).min(tail.len());
        let (frame, tail) = tail.split_at(len);
        let m = tail.get(..40).unwrap_or(tail);
        let bearings: [BearingMeasurement<f32>; 3] = core::array::from_fn(|k| BearingMeasurement {
            neighbour: [1, 2, 4][k],
            bearing: Vec2::new(f32_at(m, 8 * k), f32_at(m, 8 * k + 4)),
            rate: None,
            range: None,
        });
        let meas = Measurements {
            time: f32_at(m, 24),
            dt: f32_at(m, 28),
            velocity: Vec2::new(f32_at(m, 32), f32_at(m, 36)),
            bearings: &bearings,
            partner_offset: None,
        };
        for (a, integrity) in agents.iter_mut() {
            let mut bytes = frame.to_vec();
            if *integrity == Integrity::Crc16 && head & 64 != 0 && bytes.len() >= 2 {
                let n = bytes.len() - 2;
                let crc = crc16(&bytes[..n]);
                bytes[n..].copy_from_slice(&crc);
            }
            if matches!(integrity, Integrity::Auth(_)) && head & 64 != 0 {
                sign(&mut bytes);
            }
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
            let integrity = *integrity;
            a.frames(|f| {
                assert!(f.len() <= 60);
                let d = decode_frame(f, integrity, EstimatorMode::Shared);
                assert!(d.is_ok(), "{integrity}: {d:?} {f:02x?}");
            });
        }
        rest = tail.get(40..).unwrap_or(&[]);
    }
});
