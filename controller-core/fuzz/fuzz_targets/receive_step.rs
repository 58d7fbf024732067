//! Feeds arbitrary bytes to an agent as radio frames and as measurements, interleaved.
//! Invariants: no panic; the force is always finite and within `max_force`; every
//! outgoing frame is at most 60 bytes.
#![no_main]

use controller_core::{
    Agent, AgentConfig, AngleConfig, BearingMeasurement, Measurements, TriangleConfig, Vec2,
};
use libfuzzer_sys::fuzz_target;

fn agent() -> Agent<f32, 2, 4> {
    let angle = |apex, cos| AngleConfig {
        apex,
        cos_desired: cos,
        stiffness: 10.0,
        damping: 1.0,
        estimator_gain: 10.0,
    };
    let mut c = AgentConfig::<f32, 2>::new(3);
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

fuzz_target!(|data: &[u8]| {
    let mut a = agent();
    let limit = a.config().limits.max_force;
    // Chunks: first byte = length L (≤ 63) of a frame that follows, then 40 bytes of
    // measurement floats.
    let mut rest = data;
    while let Some((&len, tail)) = rest.split_first() {
        let len = usize::from(len & 63).min(tail.len());
        let (frame, tail) = tail.split_at(len);
        let _ = a.receive(frame);
        let m = tail.get(..40).unwrap_or(tail);
        let bearings: [BearingMeasurement<f32>; 3] = core::array::from_fn(|k| BearingMeasurement {
            neighbour: [1, 2, 4][k],
            bearing: Vec2::new(f32_at(m, 8 * k), f32_at(m, 8 * k + 4)),
            rate: None,
            range: None,
        });
        let out = a.step(&Measurements {
            time: f32_at(m, 24),
            dt: f32_at(m, 28),
            velocity: Vec2::new(f32_at(m, 32), f32_at(m, 36)),
            bearings: &bearings,
            partner_offset: None,
        });
        assert!(out.force.x.is_finite() && out.force.y.is_finite());
        assert!(out.force.norm() <= limit * 1.0001);
        a.frames(|f| assert!(f.len() <= 60));
        rest = tail.get(40..).unwrap_or(&[]);
    }
});
