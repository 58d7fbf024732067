//! The usage example of README.md (kept equal to it by xtask's `package` tests).
use ph_formation_core::{
    AgentConfig, AngleConfig, BearingMeasurement, Fault, Measurements, StandardAgent, Status,
    TriangleConfig, Vec2,
};

fn main() {
    // Agent 1 of the triangle (1, 2, 3), holding 60° at vertices 1 and 2.
    let angle = |apex| AngleConfig {
        apex,
        cos_desired: 0.5_f32, // cos 60°
        stiffness: 1.0,
        damping: 0.5,
        estimator_gain: 1.0,
    };
    let mut config = AgentConfig::new(1);
    let triangle = TriangleConfig {
        vertices: [1, 2, 3],
        angles: [angle(1), angle(2)],
    };
    config.triangles.push(triangle).expect("one triangle fits");
    let mut agent = StandardAgent::<f32>::new(config).expect("a valid configuration");

    // One control tick: the bearings to both neighbours (unit vectors, world frame).
    let bearing = |neighbour, x: f32, y: f32| BearingMeasurement {
        neighbour,
        bearing: Vec2::new(x, y),
        rate: None,
        range: None,
    };
    let bearings = [bearing(2, 1.0, 0.0), bearing(3, 0.6, 0.8)];
    let out = agent.step(&Measurements {
        time: 0.0,
        dt: 0.01,
        velocity: Vec2::zeros(),
        bearings: &bearings,
        partner_offset: None,
    });
    // Nothing heard from the neighbours yet (`agent.receive(frame)` takes what they
    // broadcast): the documented safe output, never a panic.
    assert_eq!(out.status, Status::Safe(Fault::Stale(2)));
    println!("force {:?}", out.force);

    // The frame to broadcast to the neighbours (at most 60 bytes).
    let sent = agent.frames(|bytes| assert!(bytes.len() <= 60));
    println!("{sent} frame(s)");
}
