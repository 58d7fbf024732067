//! `Agent::step` is, bit for bit, its definition: `sense`, then `evaluate`, then the owned
//! estimates integrated with the sampled S10 (`law::estimator_step`) and the force
//! saturated — or, on a fault, the same fault with the estimates held still. Checked on
//! random formations, states, estimates, measurement orders and faults, in f32 and f64
//! and every estimator mode, comparing the bits of every value (as `f64::to_bits`).

mod testkit;

use ph_formation_core::{law, EstimatorMode, Measurements, Real, Status, Vec2};
use rand::seq::SliceRandom;
use rand::Rng;
use rand_chacha::ChaCha8Rng;
use testkit::{
    bearings, fan, fan_positions, rng, sense_and_exchange, strip, strip_positions, Formation,
    HostAgent, State,
};

fn random_state(q0: &[Vec2<f64>], r: &mut ChaCha8Rng) -> State {
    State {
        q: q0
            .iter()
            .map(|q| q + Vec2::new(r.random_range(-0.1..0.1), r.random_range(-0.1..0.1)))
            .collect(),
        v: q0
            .iter()
            .map(|_| Vec2::new(r.random_range(-1.0..1.0), r.random_range(-1.0..1.0)))
            .collect(),
    }
}

/// The bits of `x` widened to `f64` (exact and one-to-one for `f32` and `f64`).
fn bits<T: Real>(x: T) -> u64 {
    let any: &dyn std::any::Any = &x;
    match (any.downcast_ref::<f64>(), any.downcast_ref::<f32>()) {
        (Some(x), _) => x.to_bits(),
        (_, Some(x)) => f64::from(*x).to_bits(),
        _ => unreachable!("the scalars are f32 and f64"),
    }
}

/// The same value, bit for bit.
fn same<T: Real>(a: T, b: T) -> bool {
    bits(a) == bits(b)
}

/// Counts of (nominal, safe) steps compared.
fn compare<T: Real>(f: &Formation, q0: &[Vec2<f64>], seed: u64) -> (usize, usize) {
    let mut r = rng(seed);
    let cv = |x: Vec2<f64>| Vec2::new(T::lit(x.x), T::lit(x.y));
    // Sometimes a short neighbour timeout, so that a long `dt` makes neighbours stale.
    let short_timeout = r.random_bool(0.3);
    let config = |i: usize| {
        let mut c = f.config::<T>(i);
        if short_timeout {
            c.limits.neighbour_timeout = T::lit(0.1);
        }
        c
    };
    let mut agents: Vec<_> = (0..f.n)
        .map(|i| HostAgent::<T>::new(config(i)).expect("valid"))
        .collect();
    for a in agents.iter_mut() {
        let owned: Vec<_> = a.owned_estimates().collect();
        for e in owned {
            let value = T::lit(r.random_range(0.05..3.0));
            assert!(a.set_estimate(&ph_formation_core::OwnedEstimate { value, ..e }));
        }
    }
    let s0 = random_state(q0, &mut r);
    sense_and_exchange(f, &s0, &mut agents, 0.0, 0.0);
    let (mut nominal, mut safe) = (0, 0);
    let dt = 0.01;
    let s1 = State {
        q: s0.q.iter().zip(&s0.v).map(|(q, v)| q + v * dt).collect(),
        v: s0.v.clone(),
    };
    for (i, agent) in agents.iter().enumerate() {
        // Exact rates or finite differences; slot order or shuffled; sometimes a fault.
        let mut b = bearings::<T>(f, &s1, i, r.random_bool(0.5));
        if r.random_bool(0.5) {
            b.shuffle(&mut r);
        }
        if f.mode != EstimatorMode::Measured {
            for x in b.iter_mut() {
                x.range = None;
            }
        }
        let partner = f
            .leader
            .and_then(|(la, lb, ..)| (i == la).then_some(lb).or((i == lb).then_some(la)));
        let mut m = Measurements {
            time: T::lit(dt),
            dt: T::lit(dt),
            velocity: cv(s1.v[i]),
            bearings: &b,
            partner_offset: partner.map(|p| cv(s1.q[p] - s1.q[i])),
        };
        let fault = r.random_range(0..10);
        let dropped: Vec<_>;
        match fault {
            0 if !b.is_empty() => {
                let k = r.random_range(0..b.len());
                dropped = b
                    .iter()
                    .enumerate()
                    .filter(|&(j, _)| j != k)
                    .map(|(_, x)| *x)
                    .collect();
                m.bearings = &dropped;
            }
            1 => m.partner_offset = None,
            2 => m.velocity = Vec2::new(T::lit(f64::NAN), T::zero()),
            3 => m.dt = T::lit(0.2), // beyond the short timeout, if set
            _ => {}
        }
        let mut fast = agent.clone();
        let mut reference = agent.clone();
        let out = fast.step(&m);
        let before: Vec<_> = reference.owned_estimates().collect();
        let expected = reference.sense(&m).and_then(|()| reference.evaluate());
        let r_min = config(i).min_estimate;
        let limit = config(i).limits.max_force;
        match expected {
            Ok(ev) => {
                nominal += 1;
                assert_eq!(out.status, Status::Nominal, "agent {i} seed {seed}");
                assert_eq!(out.degenerate, ev.degenerate);
                let (force, saturated) = law::saturate(&ev.force, limit);
                assert_eq!(out.saturated, saturated);
                assert!(
                    same(out.force.x, force.x) && same(out.force.y, force.y),
                    "agent {i} seed {seed}: step {:?} vs evaluate {:?}",
                    out.force,
                    force
                );
                let after: Vec<_> = fast.owned_estimates().collect();
                assert_eq!(after.len(), before.len());
                for (e, a) in before.iter().zip(&after) {
                    let rate = ev.estimate_rates[e.triangle][e.angle][e.edge];
                    let want = law::estimator_step(e.value, rate, m.dt, r_min);
                    assert!(
                        same(a.value, want),
                        "agent {i} seed {seed} estimate {e:?}: {:?} vs {:?}",
                        a.value,
                        want
                    );
                    assert!(reference
                        .set_estimate(&ph_formation_core::OwnedEstimate { value: want, ..*e }));
                }
            }
            Err(fault) => {
                safe += 1;
                assert_eq!(out.status, Status::Safe(fault), "agent {i} seed {seed}");
                let after: Vec<_> = fast.owned_estimates().collect();
                assert_eq!(after, before, "estimates hold still on a safe step");
            }
        }
        // The same broadcast next.
        let (mut a, mut b) = (Vec::new(), Vec::new());
        fast.frames(|x| a.push(x.to_vec()));
        reference.frames(|x| b.push(x.to_vec()));
        assert_eq!(a, b, "agent {i} seed {seed}: frames differ");
    }
    (nominal, safe)
}

fn run<T: Real>() {
    let (mut nominal, mut safe) = (0, 0);
    for seed in 0..150u64 {
        let mut r = rng(seed ^ 0xfa57);
        let (mut f, q0) = if seed % 2 == 0 {
            let n = r.random_range(3..9);
            let q = strip_positions(n, 0.1, &mut r);
            (Formation::random(n, strip(n), &q, &mut r), q)
        } else {
            let k = r.random_range(1..9);
            let q = fan_positions(k, 0.1, &mut r);
            (Formation::random(k + 2, fan(k), &q, &mut r), q)
        };
        f.mode = match seed % 5 {
            3 => EstimatorMode::PerAgent,
            4 => EstimatorMode::Measured,
            _ => EstimatorMode::Shared,
        };
        if seed % 7 == 0 {
            f.leader = None;
        }
        let (n, s) = compare::<T>(&f, &q0, seed);
        nominal += n;
        safe += s;
    }
    assert!(
        nominal > 500 && safe > 100,
        "nominal {nominal}, safe {safe}"
    );
}

#[test]
fn step_agrees_with_evaluate_f64() {
    run::<f64>();
}

#[test]
fn step_agrees_with_evaluate_f32() {
    run::<f32>();
}
