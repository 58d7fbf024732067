//! Bad input never panics and never produces NaN: typed errors or the documented safe
//! output `U = −safe_damping · v`.

mod testkit;

use ph_formation_core::{
    BearingMeasurement, EstimatorMode, Fault, MeasurementError, Measurements, Status, Vec2,
};
use proptest::prelude::*;
use testkit::{
    bearings, rng, sense_and_exchange, strip, strip_positions, Formation, HostAgent, State,
};

fn setup() -> (Formation, State, Vec<HostAgent<f64>>) {
    let mut r = rng(3);
    let f = Formation::random(4, strip(4), &strip_positions(4, 0.1, &mut r), &mut r);
    let q = strip_positions(4, 0.2, &mut r);
    let s = State {
        v: vec![Vec2::new(0.3, -0.4); 4],
        q,
    };
    let mut agents = f.agents::<f64>();
    sense_and_exchange(&f, &s, &mut agents, 0.0, 0.0);
    (f, s, agents)
}

fn meas<'a>(
    f: &Formation,
    s: &State,
    i: usize,
    b: &'a [BearingMeasurement<f64>],
    dt: f64,
) -> Measurements<'a, f64> {
    let partner = f
        .leader
        .and_then(|(la, lb, ..)| (i == la).then_some(lb).or((i == lb).then_some(la)));
    Measurements {
        time: 0.0,
        dt,
        velocity: s.v[i],
        bearings: b,
        partner_offset: partner.map(|p| s.q[p] - s.q[i]),
    }
}

fn assert_safe(out: &ph_formation_core::StepOutput<f64>, v: Vec2<f64>, fault: Fault) {
    assert_eq!(out.status, Status::Safe(fault));
    // Default safe damping 1: U = −v.
    assert!(
        (out.force + v).norm() < 1e-12,
        "safe force {:?} for v {v:?}",
        out.force
    );
}

#[test]
fn nominal_step_after_exchange() {
    let (f, s, mut agents) = setup();
    let b = bearings::<f64>(&f, &s, 1, true);
    let out = agents[1].step(&meas(&f, &s, 1, &b, 0.01));
    assert_eq!(out.status, Status::Nominal);
}

#[test]
fn a_silent_neighbour_makes_the_output_safe_and_names_it() {
    let (mut f, s, _) = setup();
    f.leader = None;
    let mut a = HostAgent::<f64>::new(f.config(1)).expect("valid");
    let b = bearings::<f64>(&f, &s, 1, true);
    // Nothing heard yet: the first neighbour is reported stale.
    let out = a.step(&meas(&f, &s, 1, &b, 0.01));
    assert_safe(&out, s.v[1], Fault::Stale(1));
}

#[test]
fn the_timeout_expires() {
    let (f, s, mut agents) = setup();
    let timeout = 0.1;
    let mut cfg = f.config::<f64>(2);
    cfg.limits.neighbour_timeout = timeout;
    agents[2] = HostAgent::<f64>::new(cfg).expect("valid");
    sense_and_exchange(&f, &s, &mut agents, 0.0, 0.0);
    let b = bearings::<f64>(&f, &s, 2, true);
    assert_eq!(
        agents[2].step(&meas(&f, &s, 2, &b, 0.01)).status,
        Status::Nominal
    );
    let mut t = 0.0;
    let mut last = Status::Nominal;
    while t < 2.0 * timeout {
        last = agents[2].step(&meas(&f, &s, 2, &b, 0.01)).status;
        t += 0.01;
    }
    assert!(matches!(last, Status::Safe(Fault::Stale(_))), "{last:?}");
}

#[test]
fn bad_measurements_give_typed_faults_and_finite_safe_output() {
    let (f, s, agents) = setup();
    let good = bearings::<f64>(&f, &s, 1, true);
    let v = s.v[1];
    let mut cases: Vec<(Vec<BearingMeasurement<f64>>, Fault)> = Vec::new();
    let mut zero = good.clone();
    zero[0].bearing = Vec2::zeros();
    cases.push((
        zero,
        Fault::Measurement(MeasurementError::BadBearing(good[0].neighbour)),
    ));
    let mut nan = good.clone();
    nan[1].bearing.x = f64::NAN;
    cases.push((
        nan,
        Fault::Measurement(MeasurementError::BadBearing(good[1].neighbour)),
    ));
    let mut nan_rate = good.clone();
    nan_rate[0].rate = Some(Vec2::new(f64::INFINITY, 0.0));
    cases.push((
        nan_rate,
        Fault::Measurement(MeasurementError::BadBearing(good[0].neighbour)),
    ));
    let mut unknown = good.clone();
    unknown[0].neighbour = 77;
    cases.push((
        unknown,
        Fault::Measurement(MeasurementError::UnknownNeighbour(77)),
    ));
    let mut dup = good.clone();
    dup[1].neighbour = dup[0].neighbour;
    cases.push((
        dup,
        Fault::Measurement(MeasurementError::DuplicateBearing(good[0].neighbour)),
    ));
    let mut bad_range = good.clone();
    bad_range[0].range = Some(-1.0);
    cases.push((
        bad_range,
        Fault::Measurement(MeasurementError::BadRange(good[0].neighbour)),
    ));
    let missing = good[1..].to_vec();
    cases.push((missing, Fault::MissingBearing(good[0].neighbour)));
    for (b, fault) in cases {
        let mut a = agents[1].clone();
        let out = a.step(&meas(&f, &s, 1, &b, 0.01));
        assert_safe(&out, v, fault);
    }
    // Non-finite velocity: zero force (nothing to damp against).
    let mut a = agents[1].clone();
    let mut m = meas(&f, &s, 1, &good, 0.01);
    m.velocity = Vec2::new(f64::NAN, 0.0);
    let out = a.step(&m);
    assert_eq!(
        out.status,
        Status::Safe(Fault::Measurement(MeasurementError::NonFinite))
    );
    assert_eq!(out.force, Vec2::zeros());
    // Negative dt: its own error (issue 29); an infinite one is not finite.
    let mut m = meas(&f, &s, 1, &good, -0.01);
    m.dt = -0.01;
    assert_eq!(
        a.step(&m).status,
        Status::Safe(Fault::Measurement(MeasurementError::NegativeDt))
    );
    m.dt = f64::NEG_INFINITY;
    assert_eq!(
        a.step(&m).status,
        Status::Safe(Fault::Measurement(MeasurementError::NonFinite))
    );
}

#[test]
fn leaders_need_the_partner_offset_and_measured_mode_needs_ranges() {
    let (f, s, agents) = setup();
    let b = bearings::<f64>(&f, &s, 0, true);
    let mut m = meas(&f, &s, 0, &b, 0.01);
    m.partner_offset = None;
    let mut a = agents[0].clone();
    assert_eq!(a.step(&m).status, Status::Safe(Fault::MissingPartnerOffset));

    let mut g = f.clone();
    g.mode = EstimatorMode::Measured;
    let mut agents = g.agents::<f64>();
    sense_and_exchange(&g, &s, &mut agents, 0.0, 0.0);
    let mut b = bearings::<f64>(&g, &s, 2, true);
    assert_eq!(
        agents[2].clone().step(&meas(&g, &s, 2, &b, 0.01)).status,
        Status::Nominal
    );
    let missing = b[0].neighbour;
    b[0].range = None;
    assert_eq!(
        agents[2].step(&meas(&g, &s, 2, &b, 0.01)).status,
        Status::Safe(Fault::MissingRange(missing))
    );
}

#[test]
fn the_force_is_saturated() {
    let (mut f, s, _) = setup();
    for a in f.angles.iter_mut() {
        a.stiffness = 1e9;
    }
    let mut cfg = f.config::<f64>(1);
    cfg.limits.max_force = 2.5;
    let mut agent = HostAgent::<f64>::new(cfg).expect("valid");
    let mut all = f.agents::<f64>();
    all[1] = agent.clone();
    sense_and_exchange(&f, &s, &mut all, 0.0, 0.0);
    agent = all[1].clone();
    let b = bearings::<f64>(&f, &s, 1, true);
    let out = agent.step(&meas(&f, &s, 1, &b, 0.01));
    assert_eq!(out.status, Status::Nominal);
    assert!(out.saturated);
    assert!((out.force.norm() - 2.5).abs() < 1e-9);
}

fn any_f64() -> impl Strategy<Value = f64> {
    prop_oneof![
        4 => -10.0..10.0f64,
        1 => Just(f64::NAN),
        1 => Just(f64::INFINITY),
        1 => Just(f64::NEG_INFINITY),
        1 => Just(0.0),
        1 => Just(1e300),
    ]
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(2000))]
    /// Fuzz: arbitrary (often invalid) measurements and frames, interleaved; the output
    /// is always finite and within the force limit.
    #[test]
    fn step_never_panics_or_emits_nan(
        steps in proptest::collection::vec(
            (any_f64(), any_f64(), proptest::collection::vec((0u8..6, any_f64(), any_f64(), any_f64()), 0..4),
             proptest::collection::vec(any::<u8>(), 0..62)),
            1..6),
    ) {
        let (f, _, agents) = setup();
        let mut a = agents[1].clone();
        let limit = f.config::<f64>(1).limits.max_force;
        for (vx, dt, bs, frame) in steps {
            let _ = a.receive(&frame);
            let b: Vec<_> = bs.iter().map(|&(n, x, y, r)| BearingMeasurement {
                neighbour: n, bearing: Vec2::new(x, y), rate: None, range: Some(r),
            }).collect();
            let out = a.step(&Measurements { time: 0.0, dt, velocity: Vec2::new(vx, 0.5), bearings: &b, partner_offset: None });
            prop_assert!(out.force.x.is_finite() && out.force.y.is_finite());
            prop_assert!(out.force.norm() <= limit * (1.0 + 1e-12));
            let mut count = 0;
            a.frames(|fr| { count += 1; assert!(fr.len() <= 60); });
            prop_assert!(count >= 1);
        }
    }
}
