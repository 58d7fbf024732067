//! The plant S1 (`q̇ = v`, `m v̇ = −D^r v + U`) of every agent, integrated with
//! fixed-step RK4 while the controllers' forces are held (zero-order hold).

use crate::model::Model;
use controller_core::Vec2;
use rayon::prelude::*;

/// Positions and velocities of all agents, with their masses and friction.
#[derive(Clone, Debug, PartialEq)]
pub struct Plant {
    /// Positions `q_n`.
    pub q: Vec<Vec2<f64>>,
    /// Velocities `v_n`.
    pub v: Vec<Vec2<f64>>,
    mass: Vec<f64>,
    friction: Vec<[f64; 2]>,
}

/// `v̇ = (U − D v) / m` for one agent.
#[inline]
pub fn acceleration(v: &Vec2<f64>, u: &Vec2<f64>, mass: f64, friction: &[f64; 2]) -> Vec2<f64> {
    Vec2::new(
        (u.x - friction[0] * v.x) / mass,
        (u.y - friction[1] * v.y) / mass,
    )
}

impl Plant {
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
    pub fn step(&mut self, forces: &[Vec2<f64>], dt: f64) {
        let agents = self
            .q
            .iter_mut()
            .zip(self.v.iter_mut())
            .zip(forces)
            .zip(self.mass.iter().zip(&self.friction));
        for (((q, v), u), (&m, d)) in agents {
            rk4(q, v, u, m, d, dt);
        }
    }

    /// [`Self::step`] on every thread of the current rayon pool, `chunk` agents per work
    /// item; the same result bit for bit (each agent's step is independent).
    pub fn step_parallel(&mut self, forces: &[Vec2<f64>], dt: f64, chunk: usize) {
        self.q
            .par_iter_mut()
            .zip(self.v.par_iter_mut())
            .zip(forces.par_iter())
            .zip(self.mass.par_iter().zip(self.friction.par_iter()))
            .with_min_len(chunk)
            .for_each(|(((q, v), u), (&m, d))| rk4(q, v, u, m, d, dt));
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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn constant_force_matches_closed_form() {
        // m v̇ = −d v + U: v(t) = U/d (1 − e^{−d t / m}).
        let mut p = Plant {
            q: vec![Vec2::zeros()],
            v: vec![Vec2::zeros()],
            mass: vec![2.0],
            friction: vec![[0.5, 0.5]],
        };
        let u = [Vec2::new(1.0, -2.0)];
        for _ in 0..1000 {
            p.step(&u, 1e-3);
        }
        let k: f64 = 0.5 / 2.0;
        let v = (1.0 - (-k).exp()) / 0.5;
        let q = (1.0 - (1.0 - (-k).exp()) / k) / 0.5;
        assert!((p.v[0].x - v).abs() < 1e-12);
        assert!((p.v[0].y + 2.0 * v).abs() < 1e-12);
        assert!((p.q[0].x - q).abs() < 1e-12);
    }
}
