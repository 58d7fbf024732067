//! Equivariance of the force under rotation and scaling, and f32/f64 agreement.

mod testkit;

use nalgebra::Rotation2;
use ph_formation_core::Measurements;
use ph_formation_core::Vec2;
use rand::Rng;
use testkit::{
    bearings, exchange, rng, sense_and_exchange, strip, strip_positions, Formation, HostAgent,
    State,
};

/// The agents of `f`, every owned estimate set to `estimates` of its key.
fn agents_with<T: ph_formation_core::Real>(
    f: &Formation,
    estimates: &dyn Fn(usize) -> f64,
) -> Vec<HostAgent<T>> {
    let mut agents: Vec<HostAgent<T>> = f.agents::<T>();
    for a in agents.iter_mut() {
        let owned: Vec<_> = a.owned_estimates().collect();
        for e in owned {
            let key = usize::from(e.apex) * 1000 + usize::from(e.far) * 10 + e.triangle;
            assert!(a.set_estimate(&ph_formation_core::OwnedEstimate {
                value: T::lit(estimates(key)),
                ..e
            }));
        }
    }
    agents
}

fn forces<T: ph_formation_core::Real>(
    f: &Formation,
    s: &State,
    estimates: &dyn Fn(usize) -> f64,
) -> Vec<Vec2<f64>> {
    let mut agents = agents_with::<T>(f, estimates);
    sense_and_exchange(f, s, &mut agents, 0.0, 0.0);
    agents
        .iter_mut()
        .map(|a| {
            let ev = a.evaluate().expect("nominal");
            let x: f64 = nalgebra::try_convert(ev.force.x).unwrap_or(f64::NAN);
            let y: f64 = nalgebra::try_convert(ev.force.y).unwrap_or(f64::NAN);
            Vec2::new(x, y)
        })
        .collect()
}

fn setup(seed: u64) -> (Formation, State) {
    let mut r = rng(seed);
    let n = 4 + (seed as usize) % 5;
    let f = Formation::random(n, strip(n), &strip_positions(n, 0.1, &mut r), &mut r);
    let q = strip_positions(n, 0.2, &mut r);
    let v = q
        .iter()
        .map(|_| Vec2::new(r.random_range(-1.0..1.0), r.random_range(-1.0..1.0)))
        .collect();
    (f, State { q, v })
}

fn est(key: usize) -> f64 {
    0.5 + (key % 97) as f64 / 40.0
}

#[test]
fn rotating_the_world_rotates_the_force() {
    for seed in 0..100u64 {
        let (mut f, s) = setup(seed);
        // Friction and damping must be isotropic for the law to be rotation-equivariant.
        for d in f.friction.iter_mut().chain(f.velocity_damping.iter_mut()) {
            *d = [d[0]; 2];
        }
        if let Some(l) = f.leader.as_mut() {
            l.3 = [l.3[0]; 2];
        }
        let before = forces::<f64>(&f, &s, &est);
        // Rotate (and translate) the world, including v* and z*.
        let rot = Rotation2::new(0.1 + seed as f64 * 0.37);
        let rs = State {
            q: s.q.iter().map(|q| rot * q + Vec2::new(3.0, -7.0)).collect(),
            v: s.v.iter().map(|v| rot * v).collect(),
        };
        f.v_star = (rot * Vec2::from(f.v_star)).into();
        if let Some(l) = f.leader.as_mut() {
            l.4 = (rot * Vec2::from(l.4)).into();
        }
        let after = forces::<f64>(&f, &rs, &est);
        for (b, a) in before.iter().zip(&after) {
            assert!(
                (rot * b - a).norm() <= 1e-9 * (1.0 + b.norm()),
                "seed {seed}: {b:?} → {a:?}"
            );
        }
    }
}

#[test]
fn scaling_distances_and_estimates_scales_formation_force_inversely() {
    for seed in 0..100u64 {
        let (f, mut s) = setup(seed);
        let f = f.formation_only();
        s.v.iter_mut().for_each(|v| *v = Vec2::zeros());
        let lambda = 0.3 + (seed % 7) as f64 * 0.6;
        let before = forces::<f64>(&f, &s, &est);
        let scaled = State {
            q: s.q.iter().map(|q| q * lambda).collect(),
            v: s.v.clone(),
        };
        let after = forces::<f64>(&f, &scaled, &|k| est(k) * lambda);
        for (b, a) in before.iter().zip(&after) {
            assert!(
                (b / lambda - a).norm() <= 1e-9 * (1.0 + b.norm()),
                "seed {seed}: {b:?} / {lambda} ≠ {a:?}"
            );
        }
    }
}

/// f32 (target) and f64 (host) agree to within 1e-4 of the largest force component
/// (f32 has 24-bit mantissas; cancellation in S8 sums costs a few bits).
#[test]
fn f32_and_f64_agree() {
    let mut worst = 0.0f64;
    for seed in 0..300u64 {
        let (f, s) = setup(seed);
        let a64 = forces::<f64>(&f, &s, &est);
        let a32 = forces::<f32>(&f, &s, &est);
        let scale = a64.iter().map(|x| x.norm()).fold(1.0, f64::max);
        for (x, y) in a64.iter().zip(&a32) {
            let rel = (x - y).norm() / scale;
            worst = worst.max(rel);
            assert!(rel <= 1e-4, "seed {seed}: f64 {x:?} vs f32 {y:?}");
        }
    }
    eprintln!("worst f32/f64 relative difference {worst:e}");
}

/// The forces of formation `f` at rest at `q`, each agent measuring in its own frame, the
/// world turned by `turn[i]` (its heading error), and each force turned back into the
/// world as its body applies it.
fn forces_in_own_frames(f: &Formation, q: &[Vec2<f64>], turn: &[f64]) -> Vec<Vec2<f64>> {
    let s = State {
        q: q.to_vec(),
        v: vec![Vec2::zeros(); q.len()],
    };
    let mut agents = agents_with::<f64>(f, &est);
    for (i, a) in agents.iter_mut().enumerate() {
        let rot = Rotation2::new(turn[i]);
        let mut b = bearings::<f64>(f, &s, i, true);
        for m in &mut b {
            m.bearing = rot * m.bearing;
            m.rate = m.rate.map(|r| rot * r);
        }
        let partner = f
            .leader
            .and_then(|(la, lb, ..)| (i == la).then_some(lb).or((i == lb).then_some(la)));
        let m = Measurements {
            time: 0.0,
            dt: 0.0,
            velocity: Vec2::zeros(),
            bearings: &b,
            partner_offset: partner.map(|p| rot * (q[p] - q[i])),
        };
        a.sense(&m).expect("valid measurements");
    }
    exchange(f, &mut agents);
    agents
        .iter_mut()
        .enumerate()
        .map(|(i, a)| Rotation2::new(-turn[i]) * a.evaluate().expect("nominal").force)
        .collect()
}

/// SPEC §7, "Heading disagreement": at rest with `v* = 0`, the angle law and S11b need no
/// common frame: every agent may measure in its own turned frame and the forces in the
/// world are the same. S11 is not (the negative control): each leader turns `z*`.
#[test]
fn distance_leaders_need_no_common_frame_and_s11_leaders_do() {
    let (mut held_differs, mut worst) = (0, 0.0f64);
    for seed in 0..100u64 {
        let (mut f, s) = setup(seed);
        f.v_star = [0.0; 2];
        let mut r = rng(seed ^ 0xf7a3);
        let turn: Vec<f64> = (0..f.n).map(|_| r.random_range(-0.5..0.5)).collect();
        let zero = vec![0.0; f.n];
        f.leader_distance = true;
        let common = forces_in_own_frames(&f, &s.q, &zero);
        let own = forces_in_own_frames(&f, &s.q, &turn);
        for (c, o) in common.iter().zip(&own) {
            let rel = (c - o).norm() / (1.0 + c.norm());
            worst = worst.max(rel);
            assert!(
                rel <= 1e-9,
                "seed {seed}: {c:?} in one frame, {o:?} in own frames"
            );
        }
        f.leader_distance = false;
        let common = forces_in_own_frames(&f, &s.q, &zero);
        let own = forces_in_own_frames(&f, &s.q, &turn);
        if common
            .iter()
            .zip(&own)
            .any(|(c, o)| (c - o).norm() > 1e-6 * (1.0 + c.norm()))
        {
            held_differs += 1;
        }
    }
    assert_eq!(
        held_differs, 100,
        "S11 leaders were frame-free in some states"
    );
    eprintln!("worst relative difference with S11b {worst:e}");
}
