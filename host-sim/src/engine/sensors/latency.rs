//! A camera's latency: the state of every agent at the last control ticks, and the image,
//! the state `latency` before the current tick.
//!
//! Resolution: the state is kept at the control ticks only. With `latency = (k + f) T`
//! (`T` the control period, `k` whole, `0 ≤ f < 1`), the image at tick `n` is the state
//! of tick `n − k` moved by `f` of the way to tick `n − k − 1`: positions, velocities and
//! headings (the shorter way round) interpolated linearly in time, which is exact for
//! motion at constant velocity and constant turn rate. A latency that is a whole number
//! of periods (`f = 0`, to 10⁻⁹ of a period) gives the stored state bit for bit. Before
//! the run has that much history, the image is the state of the first tick (the world is
//! taken to have stood still before the run).

use super::source::World;
use ph_formation_core::Vec2;
use std::f64::consts::{PI, TAU};

/// The state of the last control ticks and the delayed image.
#[derive(Clone, Debug)]
pub(super) struct Delay {
    /// Whole control periods in the latency (`k`).
    whole: usize,
    /// The fraction of a period beyond them (`f`, 0 for a whole number).
    frac: f64,
    /// Agents.
    n: usize,
    /// Ticks kept: `k + 1`, or `k + 2` to interpolate.
    slots: usize,
    /// The state of tick `t` at `(t mod slots) · n ..`, for the last `slots` ticks.
    q: Vec<Vec2<f64>>,
    v: Vec<Vec2<f64>>,
    h: Vec<f64>,
    /// Ticks taken in so far.
    ticks: usize,
    /// The image of the last tick taken in.
    image_q: Vec<Vec2<f64>>,
    image_v: Vec<Vec2<f64>>,
    image_h: Vec<f64>,
}

/// How close to a whole number of periods a latency counts as whole (in periods).
const WHOLE: f64 = 1e-9;

impl Delay {
    /// The history for `latency` (s, ≥ 0) at control period `period` (s) of `n` agents.
    pub(super) fn new(latency: f64, period: f64, n: usize) -> Self {
        let periods = (latency / period).max(0.0);
        let (whole, frac) = if (periods - periods.round()).abs() < WHOLE {
            (periods.round() as usize, 0.0)
        } else {
            (periods.floor() as usize, periods - periods.floor())
        };
        let slots = whole + if frac > 0.0 { 2 } else { 1 };
        Self {
            whole,
            frac,
            n,
            slots,
            q: vec![Vec2::zeros(); slots * n],
            v: vec![Vec2::zeros(); slots * n],
            h: vec![0.0; slots * n],
            ticks: 0,
            image_q: vec![Vec2::zeros(); n],
            image_v: vec![Vec2::zeros(); n],
            image_h: vec![0.0; n],
        }
    }

    /// The slot range of tick `t`.
    fn slot(&self, t: usize) -> std::ops::Range<usize> {
        let s = (t % self.slots) * self.n;
        s..s + self.n
    }

    /// Takes in this tick's state and makes its image.
    pub(super) fn push(&mut self, world: &World<'_>) {
        let now = self.ticks;
        self.ticks += 1;
        let at = self.slot(now);
        self.q[at.clone()].copy_from_slice(&world.q[..self.n]);
        self.v[at.clone()].copy_from_slice(&world.v[..self.n]);
        self.h[at].copy_from_slice(&world.headings[..self.n]);
        let a = self.slot(now.saturating_sub(self.whole));
        if self.frac == 0.0 {
            self.image_q.copy_from_slice(&self.q[a.clone()]);
            self.image_v.copy_from_slice(&self.v[a.clone()]);
            self.image_h.copy_from_slice(&self.h[a]);
            return;
        }
        let b = self.slot(now.saturating_sub(self.whole + 1));
        let f = self.frac;
        for k in 0..self.n {
            let (ia, ib) = (a.start + k, b.start + k);
            self.image_q[k] = self.q[ia] + (self.q[ib] - self.q[ia]) * f;
            self.image_v[k] = self.v[ia] + (self.v[ib] - self.v[ia]) * f;
            let turn = (self.h[ib] - self.h[ia] + PI).rem_euclid(TAU) - PI;
            self.image_h[k] = self.h[ia] + turn * f;
        }
    }

    /// The image of the last tick taken in.
    pub(super) fn image(&self) -> World<'_> {
        World {
            q: &self.image_q,
            v: &self.image_v,
            headings: &self.image_h,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// One agent at `x = t` (a tick every 0.01 s), heading `t` rad.
    fn run(latency: f64, ticks: usize) -> (f64, f64, f64) {
        let mut d = Delay::new(latency, 0.01, 1);
        for t in 0..ticks {
            let x = t as f64 * 0.01;
            let w = World {
                q: &[Vec2::new(x, 0.0)],
                v: &[Vec2::new(1.0, 0.0)],
                headings: &[x * 100.0],
            };
            d.push(&w);
        }
        let im = d.image();
        (im.q[0].x, im.v[0].x, im.headings[0])
    }

    #[test]
    fn the_image_is_the_state_latency_ago() {
        // Whole periods: the stored state, bit for bit.
        let (x, v, _) = run(0.03, 11);
        assert_eq!(x.to_bits(), (7.0f64 * 0.01).to_bits());
        assert_eq!(v, 1.0);
        // No latency: the state of this tick.
        assert_eq!(run(0.0, 11).0.to_bits(), (10.0f64 * 0.01).to_bits());
        // A fraction of a period: interpolated, exact at constant velocity.
        let (x, _, h) = run(0.025, 11);
        assert!((x - 0.075).abs() < 1e-15, "{x}");
        // The heading turns 1 rad per tick: interpolated the shorter way round.
        assert!((h - 7.5).abs() < 1e-12, "{h}");
        // Before the history is long enough: the first state.
        assert_eq!(run(0.05, 3).0, 0.0);
    }
}
