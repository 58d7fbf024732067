//! The paper's plant S1 (`q̇ = v`, `m v̇ = −D^r v + U`) of every agent, integrated with
//! fixed-step RK4 while the controllers' forces are held (zero-order hold); with wind,
//! `m v̇ = −D^r v + U + m a_w`.

use super::{Held, Plant};
use crate::model::Model;
use ph_formation_core::Vec2;
use rayon::prelude::*;

/// Positions and velocities of all agents, with their masses and friction.
#[derive(Clone, Debug, PartialEq)]
pub struct PointMass {
    /// Positions `q_n`.
    pub q: Vec<Vec2<f64>>,
    /// Velocities `v_n`.
    pub v: Vec<Vec2<f64>>,
    mass: Vec<f64>,
    friction: Vec<[f64; 2]>,
    /// The held forces with the wind's (reused: no allocation per step).
    scratch: Vec<Vec2<f64>>,
}

/// `v̇ = (U − D v) / m` for one agent.
#[inline]
pub fn acceleration(v: &Vec2<f64>, u: &Vec2<f64>, mass: f64, friction: &[f64; 2]) -> Vec2<f64> {
    Vec2::new(
        (u.x - friction[0] * v.x) / mass,
        (u.y - friction[1] * v.y) / mass,
    )
}

impl PointMass {
    /// The initial state of the model's agents.
    pub fn new(model: &Model) -> Self {
        let a = &model.agents;
        Self {
            q: a.iter()
                .map(|x| Vec2::new(x.position[0], x.position[1]))
                .collect(),
            v: a.iter()
                .map(|x| Vec2::new(x.velocity[0], x.velocity[1]))
                .collect(),
            mass: a.iter().map(|x| x.mass).collect(),
            friction: a.iter().map(|x| x.friction).collect(),
            scratch: Vec::new(),
        }
    }

    /// Agent `i`'s mass.
    pub fn mass(&self, i: usize) -> f64 {
        self.mass.get(i).copied().unwrap_or(1.0)
    }

    /// Agent `i`'s friction `D^r`.
    pub fn friction(&self, i: usize) -> [f64; 2] {
        self.friction.get(i).copied().unwrap_or([0.0; 2])
    }

    /// One RK4 step of length `dt` with the forces held constant. The agents are
    /// uncoupled between control ticks, so each is integrated on its own.
    pub fn step_once(&mut self, forces: &[Vec2<f64>], dt: f64) {
        step_agents(
            Span {
                q: &mut self.q,
                v: &mut self.v,
                u: forces,
                m: &self.mass,
                d: &self.friction,
            },
            dt,
        );
    }

    /// `steps` of [`Self::step_once`] on every thread of the current rayon pool, `chunk`
    /// agents per work item, each taking all the steps of its agents (one fork-join for
    /// all the steps, and a run's state stays in its thread's cache); the same result bit
    /// for bit (each agent's step is independent).
    pub fn step_parallel(&mut self, forces: &[Vec2<f64>], dt: f64, steps: usize, chunk: usize) {
        let chunk = chunk.max(1);
        self.q
            .par_chunks_mut(chunk)
            .zip(self.v.par_chunks_mut(chunk))
            .zip(forces.par_chunks(chunk))
            .zip(
                self.mass
                    .par_chunks(chunk)
                    .zip(self.friction.par_chunks(chunk)),
            )
            .for_each(|(((q, v), u), (m, d))| {
                for _ in 0..steps {
                    let (q, v) = (&mut *q, &mut *v);
                    step_agents(Span { q, v, u, m, d }, dt);
                }
            });
    }
}

impl Plant for PointMass {
    fn q(&self) -> &[Vec2<f64>] {
        &self.q
    }

    fn v(&self) -> &[Vec2<f64>] {
        &self.v
    }

    /// With wind, the held force of agent `n` becomes `U_n + m_n a_w,n` (S1 with the
    /// wind's force), one step at a time over all agents.
    fn step(&mut self, held: &Held<'_>, dt: f64, steps: usize, chunk: Option<usize>) {
        if !held.wind.is_empty() {
            let mut with_wind = std::mem::take(&mut self.scratch);
            with_wind.clear();
            with_wind.extend(
                held.forces
                    .iter()
                    .zip(held.wind)
                    .zip(&self.mass)
                    .map(|((u, w), m)| u + w * *m),
            );
            for _ in 0..steps {
                self.step_once(&with_wind, dt);
            }
            self.scratch = with_wind;
            return;
        }
        match chunk {
            Some(chunk) => self.step_parallel(held.forces, dt, steps, chunk),
            None => {
                for _ in 0..steps {
                    self.step_once(held.forces, dt);
                }
            }
        }
    }
}

/// What one RK4 step of a run of agents reads and writes: positions, velocities, held
/// forces, masses, frictions (as far as the shortest slice reaches).
struct Span<'a> {
    q: &'a mut [Vec2<f64>],
    v: &'a mut [Vec2<f64>],
    u: &'a [Vec2<f64>],
    m: &'a [f64],
    d: &'a [[f64; 2]],
}

/// [`rk4`] for every agent of the span: two agents at a time in 256-bit AVX registers
/// where the processor has them ([`avx::step_pairs`]: the same operations in the same
/// order on each lane, so the same bits; the four divisions by the mass per step were a
/// fifth of an agent-step), the rest one by one.
fn step_agents(mut s: Span<'_>, dt: f64) {
    #[allow(unused_mut)]
    let mut done = 0;
    #[cfg(target_arch = "x86_64")]
    if std::arch::is_x86_feature_detected!("avx") {
        // SAFETY: the processor has AVX (checked just above).
        done = unsafe { avx::step_pairs(&mut s, dt) };
    }
    let rest =
        s.q.iter_mut()
            .zip(s.v.iter_mut())
            .zip(s.u)
            .zip(s.m.iter().zip(s.d))
            .skip(done);
    for (((q, v), u), (&m, d)) in rest {
        rk4(q, v, u, m, d, dt);
    }
}

/// One RK4 step of S1 for one agent under the held force `u`.
#[inline]
fn rk4(q: &mut Vec2<f64>, v: &mut Vec2<f64>, u: &Vec2<f64>, m: f64, d: &[f64; 2], dt: f64) {
    let a = |v: &Vec2<f64>| acceleration(v, u, m, d);
    let k1v = a(v);
    let v2 = *v + k1v * (0.5 * dt);
    let k2v = a(&v2);
    let v3 = *v + k2v * (0.5 * dt);
    let k3v = a(&v3);
    let v4 = *v + k3v * dt;
    let k4v = a(&v4);
    *q += (*v + v2 * 2.0 + v3 * 2.0 + v4) * (dt / 6.0);
    *v += (k1v + k2v * 2.0 + k3v * 2.0 + k4v) * (dt / 6.0);
}

/// [`rk4`] on two agents at once.
#[cfg(target_arch = "x86_64")]
mod avx {
    use super::{Span, Vec2};
    use std::arch::x86_64::{
        __m256d, _mm256_add_pd, _mm256_div_pd, _mm256_mul_pd, _mm256_set1_pd, _mm256_set_pd,
        _mm256_storeu_pd, _mm256_sub_pd,
    };

    /// Steps the span's agents `0, 1`, `2, 3`, … in pairs (lanes: x₀, y₀, x₁, y₁) and
    /// returns how many it stepped (its length rounded down to even). Each lane computes
    /// exactly [`super::rk4`]'s operations in its order (no fused multiply-add, `2·x` as
    /// `x + x`, which is exact), so the results are the scalar ones bit for bit.
    ///
    /// # Safety
    /// The processor must support AVX.
    #[target_feature(enable = "avx")]
    pub(super) unsafe fn step_pairs(s: &mut Span<'_>, dt: f64) -> usize {
        let pairs =
            s.q.chunks_exact_mut(2)
                .zip(s.v.chunks_exact_mut(2))
                .zip(s.u.chunks_exact(2))
                .zip(s.m.chunks_exact(2).zip(s.d.chunks_exact(2)));
        let mut done = 0;
        let (half, full, sixth) = (
            _mm256_set1_pd(0.5 * dt),
            _mm256_set1_pd(dt),
            _mm256_set1_pd(dt / 6.0),
        );
        for (((q, v), u), (m, d)) in pairs {
            let (&[q0, q1], &[v0, v1], &[u0, u1], &[m0, m1], &[d0, d1]) = (&*q, &*v, u, m, d)
            else {
                continue;
            };
            let load = |a: &Vec2<f64>, b: &Vec2<f64>| _mm256_set_pd(b.y, b.x, a.y, a.x);
            let (qv, vv, uv) = (load(&q0, &q1), load(&v0, &v1), load(&u0, &u1));
            let mass = _mm256_set_pd(m1, m1, m0, m0);
            let fric = _mm256_set_pd(d1[1], d1[0], d0[1], d0[0]);
            // S1: v̇ = (U − D v) / m.
            let acc = |v: __m256d| _mm256_div_pd(_mm256_sub_pd(uv, _mm256_mul_pd(fric, v)), mass);
            let twice = |x: __m256d| _mm256_add_pd(x, x);
            let k1 = acc(vv);
            let v2 = _mm256_add_pd(vv, _mm256_mul_pd(k1, half));
            let k2 = acc(v2);
            let v3 = _mm256_add_pd(vv, _mm256_mul_pd(k2, half));
            let k3 = acc(v3);
            let v4 = _mm256_add_pd(vv, _mm256_mul_pd(k3, full));
            let k4 = acc(v4);
            let sum =
                |a, b, c, d| _mm256_add_pd(_mm256_add_pd(_mm256_add_pd(a, twice(b)), twice(c)), d);
            let q_new = _mm256_add_pd(qv, _mm256_mul_pd(sum(vv, v2, v3, v4), sixth));
            let v_new = _mm256_add_pd(vv, _mm256_mul_pd(sum(k1, k2, k3, k4), sixth));
            store(q_new, q);
            store(v_new, v);
            done += 2;
        }
        done
    }

    /// Writes lanes x₀, y₀, x₁, y₁ into a pair of vectors.
    #[target_feature(enable = "avx")]
    fn store(x: __m256d, to: &mut [Vec2<f64>]) {
        let mut lanes = [0.0f64; 4];
        // SAFETY: `lanes` holds four f64, the 32 bytes an unaligned store writes.
        unsafe { _mm256_storeu_pd(lanes.as_mut_ptr(), x) };
        if let [a, b] = to {
            *a = Vec2::new(lanes[0], lanes[1]);
            *b = Vec2::new(lanes[2], lanes[3]);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn constant_force_matches_closed_form() {
        // m v̇ = −d v + U: v(t) = U/d (1 − e^{−d t / m}).
        let mut p = PointMass {
            q: vec![Vec2::zeros()],
            v: vec![Vec2::zeros()],
            mass: vec![2.0],
            friction: vec![[0.5, 0.5]],
            scratch: Vec::new(),
        };
        let u = [Vec2::new(1.0, -2.0)];
        for _ in 0..1000 {
            p.step_once(&u, 1e-3);
        }
        let k: f64 = 0.5 / 2.0;
        let v = (1.0 - (-k).exp()) / 0.5;
        let q = (1.0 - (1.0 - (-k).exp()) / k) / 0.5;
        assert!((p.v[0].x - v).abs() < 1e-12);
        assert!((p.v[0].y + 2.0 * v).abs() < 1e-12);
        assert!((p.q[0].x - q).abs() < 1e-12);
    }

    /// The paired AVX step gives the scalar RK4's bits on every lane, for an odd number
    /// of agents (the last one scalar) with different masses, frictions and forces.
    #[test]
    fn paired_step_is_the_scalar_step_bit_for_bit() {
        let n = 7;
        let f = |i: usize, k: f64| (i as f64 * 0.37 + k).sin() * (1.0 + k);
        let q: Vec<_> = (0..n).map(|i| Vec2::new(f(i, 1.0), f(i, 2.0))).collect();
        let v: Vec<_> = (0..n).map(|i| Vec2::new(f(i, 3.0), f(i, 4.0))).collect();
        let u: Vec<_> = (0..n).map(|i| Vec2::new(f(i, 5.0), f(i, 6.0))).collect();
        let m: Vec<_> = (0..n).map(|i| 0.3 + f(i, 7.0).abs()).collect();
        let d: Vec<_> = (0..n).map(|i| [f(i, 8.0).abs(), f(i, 9.0).abs()]).collect();
        let (mut q1, mut v1) = (q.clone(), v.clone());
        // A long step, so that any change of rounding shows in the last bits.
        let dt = 0.173;
        for _ in 0..20 {
            let span = Span {
                q: &mut q1,
                v: &mut v1,
                u: &u,
                m: &m,
                d: &d,
            };
            step_agents(span, dt);
        }
        let (mut q2, mut v2) = (q, v);
        for _ in 0..20 {
            for i in 0..n {
                rk4(&mut q2[i], &mut v2[i], &u[i], m[i], &d[i], dt);
            }
        }
        let bits = |x: &[Vec2<f64>]| -> Vec<[u64; 2]> {
            x.iter().map(|p| [p.x.to_bits(), p.y.to_bits()]).collect()
        };
        assert_eq!(bits(&q1), bits(&q2));
        assert_eq!(bits(&v1), bits(&v2));
    }

    /// Several steps a run of agents at a time on the pool give the bits of one step at
    /// a time over all agents (runs that do not divide the agents, more runs than
    /// threads).
    #[test]
    fn parallel_steps_in_runs_are_single_steps_bit_for_bit() {
        let n = 37;
        let f = |i: usize, k: f64| (i as f64 * 0.53 + k).cos() * (1.0 + k);
        let plant = PointMass {
            scratch: Vec::new(),
            q: (0..n).map(|i| Vec2::new(f(i, 1.0), f(i, 2.0))).collect(),
            v: (0..n).map(|i| Vec2::new(f(i, 3.0), f(i, 4.0))).collect(),
            mass: (0..n).map(|i| 0.3 + f(i, 7.0).abs()).collect(),
            friction: (0..n).map(|i| [f(i, 8.0).abs(), f(i, 9.0).abs()]).collect(),
        };
        let u: Vec<_> = (0..n).map(|i| Vec2::new(f(i, 5.0), f(i, 6.0))).collect();
        let dt = 0.071;
        let mut one = plant.clone();
        for _ in 0..10 {
            one.step_once(&u, dt);
        }
        let mut parallel = plant;
        parallel.step_parallel(&u, dt, 10, 4);
        let bits = |p: &PointMass| -> Vec<[u64; 4]> {
            p.q.iter()
                .zip(&p.v)
                .map(|(q, v)| [q.x, q.y, v.x, v.y].map(f64::to_bits))
                .collect()
        };
        assert_eq!(bits(&parallel), bits(&one));
    }
}
