//! The robot's world during a run (`docs/world.md`): every agent's heading and its
//! estimate, its own clock, and the wind on it. Each random quantity is drawn from a
//! stream of its own per agent and per tick ([`stream`]), so that results do not depend
//! on the order in which agents are visited or on the number of threads.

use crate::model::{ClockModel, HeadingModel, Model, WindModel};
use ph_formation_core::Vec2;
use rand::{Rng, RngCore, SeedableRng};
use rand_distr::StandardNormal;
use rand_xoshiro::{SplitMix64, Xoshiro256PlusPlus};

/// Tags of the world's streams (mixed into the run's seed; the sensors use 1, the radio
/// its own generators).
const HEADING_STREAM: u64 = 0x4845_4144; // "HEAD"
const CLOCK_STREAM: u64 = 0x434C_4F4B; // "CLOK"
const WIND_STREAM: u64 = 0x5749_4E44; // "WIND"

/// The key of the streams tagged `tag` of a run seeded `seed`.
pub fn stream_key(seed: u64, tag: u64) -> u64 {
    SplitMix64::seed_from_u64(seed ^ tag).next_u64()
}

/// Agent `agent`'s stream number `index` (a tick, or a per-agent constant) under `key`:
/// a different xoshiro256++ generator for every agent below 2³² and index below 2³²
/// (every per-agent stream of the engine: the sensors', the world's).
#[inline]
pub fn stream(key: u64, agent: usize, index: u64) -> Xoshiro256PlusPlus {
    let word = ((agent as u64) << 32) | (index & 0xFFFF_FFFF);
    Xoshiro256PlusPlus::seed_from_u64(key ^ word)
}

/// A standard normal draw.
fn normal(rng: &mut Xoshiro256PlusPlus) -> f64 {
    rng.sample::<f64, _>(StandardNormal)
}

/// The index of every agent's constant draws (true heading, clock): past every tick.
const CONSTANTS: u64 = 0xFFFF_FFFF;

/// Every agent's heading and the error of its estimate (`HeadingModel`).
#[derive(Clone, Debug)]
pub struct Headings {
    /// True headings `ψ_i` (rad).
    pub truth: Vec<f64>,
    /// `R(ψ_i)`, turned once.
    truth_turn: Vec<Turn>,
    /// Initial estimate errors `e_i(0)` (rad).
    start: Vec<f64>,
    /// Drift rates `ω_i` (rad/s).
    drift: Vec<f64>,
    noise: f64,
    key: u64,
}

impl Headings {
    /// Every agent's draws for `model`.
    pub fn new(model: &Model, h: &HeadingModel) -> Self {
        let key = stream_key(model.seed, HEADING_STREAM);
        let n = model.n();
        let mut truth = Vec::with_capacity(n);
        let (mut start, mut drift) = (Vec::with_capacity(n), Vec::with_capacity(n));
        for i in 0..n {
            let mut r = stream(key, i, CONSTANTS);
            // The spread is drawn whether or not the agent's heading is given, so that the
            // draws after it (error, drift) do not depend on the scenario's headings.
            let drawn = h.initial + h.spread * (2.0 * r.random::<f64>() - 1.0);
            truth.push(model.agents.get(i).and_then(|a| a.heading).unwrap_or(drawn));
            start.push(h.error * normal(&mut r));
            drift.push(h.drift * normal(&mut r));
        }
        Self {
            truth_turn: truth.iter().map(|&x| Turn::by(x)).collect(),
            truth,
            start,
            drift,
            noise: h.noise,
            key,
        }
    }

    /// Agent `i`'s body frame and its estimate of it at its tick `tick` at time `t`.
    pub fn frames(&self, i: usize, t: f64, tick: u64) -> BodyFrame {
        let truth = self.truth.get(i).copied().unwrap_or(0.0);
        BodyFrame {
            truth: self.truth_turn.get(i).copied().unwrap_or(Turn::by(truth)),
            estimate: Turn::by(truth + self.error(i, t, tick)),
        }
    }

    /// Agent `i`'s estimate error `e_i(t) = e_i(0) + ω_i t + n_i` at its tick `tick` at
    /// time `t` (the noise drawn from its stream of that tick).
    pub fn error(&self, i: usize, t: f64, tick: u64) -> f64 {
        let base = self.start.get(i).copied().unwrap_or(0.0)
            + self.drift.get(i).copied().unwrap_or(0.0) * t;
        if self.noise > 0.0 {
            base + self.noise * normal(&mut stream(self.key, i, tick))
        } else {
            base
        }
    }
}

/// An agent's body frame at one tick: its true heading `ψ_i` and its estimate `ψ̂_i`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BodyFrame {
    /// `R(ψ_i)`: body to world.
    pub truth: Turn,
    /// `R(ψ̂_i)`: body to the agent's estimate of the world frame.
    pub estimate: Turn,
}

impl BodyFrame {
    /// A world-frame vector as the agent senses it: measured in its body frame
    /// (`R(−ψ) x`), turned into its world frame by its estimate (`R(ψ̂) ·`).
    #[inline]
    pub fn sensed(&self, x: &Vec2<f64>) -> Vec2<f64> {
        self.estimate.apply(&self.truth.undo(x))
    }

    /// A vector the agent commands in its world frame, as its body applies it in the
    /// world: turned into the body frame by its estimate (`R(−ψ̂) ·`), applied by the
    /// body (`R(ψ) ·`).
    #[inline]
    pub fn applied(&self, x: &Vec2<f64>) -> Vec2<f64> {
        self.truth.apply(&self.estimate.undo(x))
    }
}

/// A rotation by `θ`, as `(cos θ, sin θ)`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Turn {
    cos: f64,
    sin: f64,
}

impl Turn {
    /// The rotation by `theta` (rad).
    pub fn by(theta: f64) -> Self {
        let (sin, cos) = theta.sin_cos();
        Self { cos, sin }
    }

    /// `R(θ) x`.
    #[inline]
    pub fn apply(&self, x: &Vec2<f64>) -> Vec2<f64> {
        Vec2::new(
            self.cos * x.x - self.sin * x.y,
            self.sin * x.x + self.cos * x.y,
        )
    }

    /// `R(−θ) x`.
    #[inline]
    pub fn undo(&self, x: &Vec2<f64>) -> Vec2<f64> {
        Vec2::new(
            self.cos * x.x + self.sin * x.y,
            -self.sin * x.x + self.cos * x.y,
        )
    }
}

/// Every agent's own clock (`ClockModel`) and its schedule of ticks on the simulator's
/// RK4 grid: agent `i`'s `k`-th tick is due at `t = (k T − φ_i) / (1 + ε_i) + j_{i,k}`,
/// taken at the first RK4 step at or after it (the resolution is `dt`).
#[derive(Clone, Debug)]
pub struct Clocks {
    /// `1 + ε_i`.
    rate: Vec<f64>,
    /// `φ_i` (s).
    phase: Vec<f64>,
    jitter: f64,
    period: f64,
    dt: f64,
    key: u64,
    /// Each agent's next tick `k` (its own count: the index of its streams).
    next: Vec<u64>,
    /// The RK4 step of each agent's next tick.
    next_step: Vec<usize>,
    /// Each agent's clock reading at its last tick (`None` before the first).
    last: Vec<Option<f64>>,
}

impl Clocks {
    /// Every agent's clock for `model`, each scheduled for its first tick.
    pub fn new(model: &Model, c: &ClockModel) -> Self {
        let key = stream_key(model.seed, CLOCK_STREAM);
        let n = model.n();
        let period = model.control_period();
        let mut s = Self {
            rate: Vec::with_capacity(n),
            phase: Vec::with_capacity(n),
            jitter: c.jitter,
            period,
            dt: model.dt,
            key,
            next: vec![0; n],
            next_step: vec![0; n],
            last: vec![None; n],
        };
        for i in 0..n {
            let mut r = stream(key, i, CONSTANTS);
            s.phase.push(c.offset * r.random::<f64>());
            s.rate
                .push(1.0 + c.ppm * 1e-6 * (2.0 * r.random::<f64>() - 1.0));
            // The first tick: the first k with k T ≥ φ_i.
            let k = (s.phase[i] / period).ceil() as u64;
            s.next[i] = k;
            s.next_step[i] = s.step_of(i, k, 0);
        }
        s
    }

    /// The RK4 step of agent `i`'s tick `k`, not before step `not_before`.
    fn step_of(&self, i: usize, k: u64, not_before: usize) -> usize {
        let mut t = (k as f64 * self.period - self.phase[i]) / self.rate[i];
        if self.jitter > 0.0 {
            let j = self.jitter * normal(&mut stream(self.key, i, k));
            t += j.clamp(-0.45 * self.period, 0.45 * self.period);
        }
        let step = (t / self.dt - 1e-9).ceil().max(0.0) as usize;
        step.max(not_before)
    }

    /// Whether agent `i` ticks at RK4 step `step`.
    #[inline]
    pub fn due(&self, i: usize, step: usize) -> bool {
        self.next_step.get(i) == Some(&step)
    }

    /// Whether some agent ticks at RK4 step `step` (every next tick is at or after the
    /// current step).
    pub fn any_due(&self, step: usize) -> bool {
        self.next_step.contains(&step)
    }

    /// The first RK4 step after `step` at which some agent ticks.
    pub fn next_after(&self, step: usize) -> usize {
        self.next_step
            .iter()
            .copied()
            .filter(|&s| s > step)
            .min()
            .unwrap_or(usize::MAX)
    }

    /// Agent `i` ticks at time `t` (RK4 step `step`): its clock reading, the time since
    /// its previous tick by its clock (0 at the first), and its tick's index; its next
    /// tick is scheduled.
    pub fn tick(&mut self, i: usize, t: f64, step: usize) -> (f64, f64, u64) {
        let local = self.rate[i] * t + self.phase[i];
        let dt = self.last[i].map_or(0.0, |l| local - l);
        self.last[i] = Some(local);
        let k = self.next[i];
        self.next[i] = k + 1;
        self.next_step[i] = self.step_of(i, k + 1, step + 1);
        (local, dt, k)
    }

    /// Agent `i`'s rate `1 + ε_i`.
    pub fn rate(&self, i: usize) -> f64 {
        self.rate.get(i).copied().unwrap_or(1.0)
    }
}

/// The wind on every agent (`WindModel`): the mean plus each agent's gust, an
/// Ornstein–Uhlenbeck process per axis advanced exactly over each control period and
/// held in between.
#[derive(Clone, Debug)]
pub struct Wind {
    model: WindModel,
    key: u64,
    gust: Vec<Vec2<f64>>,
    /// The current wind on each agent (what the plant reads).
    pub now: Vec<Vec2<f64>>,
    updates: u64,
}

impl Wind {
    /// Every agent's wind at its stationary distribution.
    pub fn new(model: &Model, w: &WindModel) -> Self {
        let key = stream_key(model.seed, WIND_STREAM);
        let n = model.n();
        let mut s = Self {
            model: *w,
            key,
            gust: Vec::with_capacity(n),
            now: Vec::with_capacity(n),
            updates: 0,
        };
        for i in 0..n {
            let mut r = stream(key, i, CONSTANTS);
            s.gust
                .push(Vec2::new(normal(&mut r), normal(&mut r)) * w.gust);
        }
        s.refresh();
        s
    }

    fn refresh(&mut self) {
        let m = Vec2::new(self.model.mean[0], self.model.mean[1]);
        self.now.clear();
        self.now.extend(self.gust.iter().map(|g| m + g));
    }

    /// Advances every gust by `h` seconds: `g ← g e^{−h/τ} + σ √(1 − e^{−2h/τ}) N(0, 1)`
    /// per axis (the exact transition of the process).
    pub fn advance(&mut self, h: f64) {
        let w = self.model;
        if w.gust > 0.0 {
            let a = (-h / w.gust_time_constant).exp();
            let b = w.gust * (1.0 - a * a).max(0.0).sqrt();
            let k = self.updates;
            for (i, g) in self.gust.iter_mut().enumerate() {
                let mut r = stream(self.key, i, k);
                *g = *g * a + Vec2::new(normal(&mut r), normal(&mut r)) * b;
            }
        }
        self.updates += 1;
        self.refresh();
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A rotation undone gives the vector back, and turns by the angle.
    #[test]
    fn turn_rotates_and_undoes() {
        let r = Turn::by(0.3);
        let x = Vec2::new(1.0, 0.0);
        let y = r.apply(&x);
        assert!((y.y.atan2(y.x) - 0.3).abs() < 1e-15);
        assert!((r.undo(&y) - x).norm() < 1e-15);
    }
}
