#![allow(dead_code)] // Each test file uses a part of the kit.
//! Test support: random triangulated formations built from several `controller-core`
//! [`Agent`]s, their true state, and the exact measurements each agent would take.
//!
//! Agent `i` (index) has id `i + 1`.

use ph_formation_core::wire::Integrity;
use ph_formation_core::{
    geometry, AgentConfig, AgentId, AngleConfig, BearingMeasurement, EstimatorMode, LeaderConfig,
    LeaderRole, Measurements, Schedule, TriangleConfig, Vec2,
};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

/// The agent type of the tests: the standard capacities (`ph_formation_core::MAX_TRIANGLES`, `MAX_NEIGHBOURS`).
pub type HostAgent<T> = ph_formation_core::StandardAgent<T>;

/// One controlled angle: triangle index, apex (agent index), desired cosine, gains.
#[derive(Clone, Copy, Debug)]
pub struct AngleSpec {
    /// Triangle index.
    pub triangle: usize,
    /// Apex agent index.
    pub apex: usize,
    /// The two far vertices (agent indices) in triangle order.
    pub far: [usize; 2],
    /// `cos α*`.
    pub cos_desired: f64,
    /// `c_α`.
    pub stiffness: f64,
    /// `d_α`.
    pub damping: f64,
    /// `c_e`.
    pub estimator_gain: f64,
}

/// Leader pair `(a, b)` as agent indices, `k_z`, `D_z` (diagonal), `z*`.
pub type Leader = (usize, usize, f64, [f64; 2], [f64; 2]);

/// A formation: graph, gains and maneuver parameters.
#[derive(Clone, Debug)]
pub struct Formation {
    /// Number of agents.
    pub n: usize,
    /// Triangles as agent indices.
    pub triangles: Vec<[usize; 3]>,
    /// Two controlled angles per triangle, in triangle order.
    pub angles: Vec<AngleSpec>,
    /// `D^r` per agent.
    pub friction: Vec<[f64; 2]>,
    /// `D^v` per agent.
    pub velocity_damping: Vec<[f64; 2]>,
    /// `v*`.
    pub v_star: [f64; 2],
    /// The leader edge, if any.
    pub leader: Option<Leader>,
    /// The leaders hold only the distance (S11b, [`LeaderRole::Distance`]), not S11.
    pub leader_distance: bool,
    /// Estimator mode.
    pub mode: EstimatorMode,
}

/// True positions and velocities.
#[derive(Clone, Debug)]
pub struct State {
    /// Positions.
    pub q: Vec<Vec2<f64>>,
    /// Velocities.
    pub v: Vec<Vec2<f64>>,
}

/// Agent `id` of the triangle (1, 2, 3) with controlled angles at 1 and 2 (desired
/// cosine 0.5, c = 1, d = 0.5, c_e = 1) and `integrity`: the smallest formation.
pub fn one_triangle(id: AgentId, integrity: Integrity) -> AgentConfig<f32, 1> {
    let angle = |apex| AngleConfig {
        apex,
        cos_desired: 0.5,
        stiffness: 1.0,
        damping: 0.5,
        estimator_gain: 1.0,
    };
    let mut c = AgentConfig::new(id);
    c.triangles
        .push(TriangleConfig {
            vertices: [1, 2, 3],
            angles: [angle(1), angle(2)],
        })
        .expect("capacity 1");
    c.integrity = integrity;
    c
}

/// Id of agent index `i`.
pub fn id(i: usize) -> AgentId {
    AgentId::try_from(i + 1).unwrap_or(AgentId::MAX)
}

/// A triangulated strip: triangles `(i, i+1, i+2)`.
pub fn strip(n: usize) -> Vec<[usize; 3]> {
    (0..n.saturating_sub(2))
        .map(|i| [i, i + 1, i + 2])
        .collect()
}

/// A fan: agent 0 is in all `k` triangles `(0, i, i+1)`.
pub fn fan(k: usize) -> Vec<[usize; 3]> {
    (1..=k).map(|i| [0, i, i + 1]).collect()
}

/// Points of a triangular lattice along a strip, jittered by up to `jitter`.
pub fn strip_positions(n: usize, jitter: f64, rng: &mut ChaCha8Rng) -> Vec<Vec2<f64>> {
    (0..n)
        .map(|i| {
            let base = Vec2::new(0.5 * i as f64, if i % 2 == 0 { 0.0 } else { 0.866 });
            base + Vec2::new(
                rng.random_range(-jitter..jitter),
                rng.random_range(-jitter..jitter),
            )
        })
        .collect()
}

/// Points around a fan centre at the origin (spanning less than π), jittered.
pub fn fan_positions(k: usize, jitter: f64, rng: &mut ChaCha8Rng) -> Vec<Vec2<f64>> {
    let mut q = vec![Vec2::zeros()];
    let step = 2.6 / k as f64;
    for i in 0..=k {
        let a = step * i as f64 + rng.random_range(-0.2 * step..0.2 * step);
        let r = 1.0 + rng.random_range(-jitter..jitter);
        q.push(Vec2::new(r * a.cos(), r * a.sin()));
    }
    q
}

/// Cosine of the interior angle at `u` between `v` and `w`.
pub fn cos_at(q: &[Vec2<f64>], u: usize, v: usize, w: usize) -> f64 {
    let a = (q[v] - q[u]).normalize();
    let b = (q[w] - q[u]).normalize();
    a.dot(&b)
}

impl Formation {
    /// A formation on `triangles` whose desired shape is `target`, with random gains.
    /// The controlled angles of each triangle are at its first two vertices.
    pub fn random(
        n: usize,
        triangles: Vec<[usize; 3]>,
        target: &[Vec2<f64>],
        rng: &mut ChaCha8Rng,
    ) -> Self {
        let mut angles = Vec::new();
        for (ti, t) in triangles.iter().enumerate() {
            for k in 0..2 {
                let apex = t[k];
                let far: Vec<usize> = t.iter().copied().filter(|&x| x != apex).collect();
                angles.push(AngleSpec {
                    triangle: ti,
                    apex,
                    far: [far[0], far[1]],
                    cos_desired: cos_at(target, apex, far[0], far[1]),
                    stiffness: rng.random_range(0.5..20.0),
                    damping: rng.random_range(0.0..5.0),
                    estimator_gain: rng.random_range(0.5..20.0),
                });
            }
        }
        let diag = |rng: &mut ChaCha8Rng| [rng.random_range(0.0..2.0), rng.random_range(0.0..2.0)];
        Self {
            n,
            triangles,
            angles,
            friction: (0..n).map(|_| diag(rng)).collect(),
            velocity_damping: (0..n).map(|_| diag(rng)).collect(),
            v_star: [rng.random_range(-2.0..2.0), rng.random_range(-2.0..2.0)],
            leader: Some((
                0,
                1,
                rng.random_range(0.5..5.0),
                diag(rng),
                [rng.random_range(-2.0..2.0), rng.random_range(-2.0..2.0)],
            )),
            leader_distance: false,
            mode: EstimatorMode::Shared,
        }
    }

    /// Pure formation control: no leader, `v* = 0`, no velocity damping.
    pub fn formation_only(mut self) -> Self {
        self.leader = None;
        self.v_star = [0.0; 2];
        self.velocity_damping = vec![[0.0; 2]; self.n];
        self
    }

    /// The configuration of agent index `i` (scalar `T`).
    pub fn config<T: ph_formation_core::Real>(
        &self,
        i: usize,
    ) -> ph_formation_core::StandardConfig<T> {
        let t = |x: f64| T::lit(x);
        let mut c = AgentConfig::new(id(i));
        c.estimator = self.mode;
        c.friction = self.friction[i].map(t);
        c.velocity_damping = self.velocity_damping[i].map(t);
        c.velocity_reference = Schedule::constant(self.v_star.map(t));
        c.limits.max_force = t(1e12);
        c.limits.neighbour_timeout = t(1e9);
        c.limits.margin_cos = t(0.9999);
        for (ti, tri) in self.triangles.iter().enumerate() {
            if !tri.contains(&i) {
                continue;
            }
            let mut angles = self
                .angles
                .iter()
                .filter(|a| a.triangle == ti)
                .map(|a| AngleConfig {
                    apex: id(a.apex),
                    cos_desired: t(a.cos_desired),
                    stiffness: t(a.stiffness),
                    damping: t(a.damping),
                    estimator_gain: t(a.estimator_gain),
                });
            let (Some(a0), Some(a1)) = (angles.next(), angles.next()) else {
                continue;
            };
            let _ = c.triangles.push(TriangleConfig {
                vertices: tri.map(id),
                angles: [a0, a1],
            });
        }
        if let Some((a, b, k, dz, z)) = self.leader {
            if i == a || i == b {
                c.leader = Some(LeaderConfig {
                    role: match (self.leader_distance, i == a) {
                        (true, _) => LeaderRole::Distance,
                        (false, true) => LeaderRole::A,
                        (false, false) => LeaderRole::B,
                    },
                    partner: id(if i == a { b } else { a }),
                    stiffness: t(k),
                    damping: dz.map(t),
                    displacement: Schedule::constant(z.map(t)),
                });
            }
        }
        c
    }

    /// All agents.
    pub fn agents<T: ph_formation_core::Real>(&self) -> Vec<HostAgent<T>> {
        (0..self.n)
            .map(|i| HostAgent::<T>::new(self.config(i)).expect("valid test configuration"))
            .collect()
    }

    /// Neighbour indices of agent `i` (triangle neighbours and leader partner).
    pub fn neighbours(&self, i: usize) -> Vec<usize> {
        let mut out: Vec<usize> = self
            .triangles
            .iter()
            .filter(|t| t.contains(&i))
            .flat_map(|t| t.iter().copied())
            .filter(|&j| j != i)
            .collect();
        if let Some((a, b, ..)) = self.leader {
            if i == a {
                out.push(b);
            }
            if i == b {
                out.push(a);
            }
        }
        out.sort_unstable();
        out.dedup();
        out
    }
}

/// Exact bearings (and rates, S2, and ranges) that agent `i` measures.
pub fn bearings<T: ph_formation_core::Real>(
    f: &Formation,
    s: &State,
    i: usize,
    exact_rates: bool,
) -> Vec<BearingMeasurement<T>> {
    let cv = |x: Vec2<f64>| Vec2::new(T::lit(x.x), T::lit(x.y));
    f.neighbours(i)
        .into_iter()
        .filter(|&j| f.triangles.iter().any(|t| t.contains(&i) && t.contains(&j)))
        .map(|j| {
            let d = s.q[j] - s.q[i];
            let r = d.norm();
            let b = d / r;
            BearingMeasurement {
                neighbour: id(j),
                bearing: cv(b),
                rate: exact_rates.then(|| cv(geometry::bearing_rate(&b, &(s.v[j] - s.v[i]), r))),
                range: Some(T::lit(r)),
            }
        })
        .collect()
}

/// Senses the true state on every agent (exact rates, `dt`), then exchanges every
/// agent's broadcast with its neighbours directly (no wire).
pub fn sense_and_exchange<T: ph_formation_core::Real>(
    f: &Formation,
    s: &State,
    agents: &mut [HostAgent<T>],
    time: f64,
    dt: f64,
) {
    let cv = |x: Vec2<f64>| Vec2::new(T::lit(x.x), T::lit(x.y));
    for (i, a) in agents.iter_mut().enumerate() {
        let b = bearings::<T>(f, s, i, true);
        let partner = f
            .leader
            .and_then(|(la, lb, ..)| (i == la).then_some(lb).or((i == lb).then_some(la)));
        let m = Measurements {
            time: T::lit(time),
            dt: T::lit(dt),
            velocity: cv(s.v[i]),
            bearings: &b,
            partner_offset: partner.map(|p| cv(s.q[p] - s.q[i])),
        };
        a.sense(&m).expect("valid measurements");
    }
    exchange(f, agents);
}

/// Exchanges every agent's broadcast with its neighbours directly (no wire).
pub fn exchange<T: ph_formation_core::Real>(f: &Formation, agents: &mut [HostAgent<T>]) {
    for i in 0..agents.len() {
        for j in f.neighbours(i) {
            let (src, dst) = if i < j {
                let (l, r) = agents.split_at_mut(j);
                (&l[i], &mut r[0])
            } else {
                let (l, r) = agents.split_at_mut(i);
                (&r[0], &mut l[j])
            };
            dst.receive_direct(src).expect("neighbour");
        }
    }
}

/// A deterministic RNG for test case `seed`.
pub fn rng(seed: u64) -> ChaCha8Rng {
    ChaCha8Rng::seed_from_u64(seed)
}
