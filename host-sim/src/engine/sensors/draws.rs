//! The sensors' noise model: bearings from the true state plus rotation noise and bias,
//! optional exact bearing rates (S2), own velocity with noise and bias, the leaders'
//! relative position, and ranges for the `measured` estimator, each agent drawing from
//! its own stream of the tick ([`Sensors::stream`]).

use crate::engine::world::{stream, stream_key, Turn};
use crate::model::SensorModel;
use ph_formation_core::{geometry, BearingMeasurement, Vec2};
use rand::Rng;
use rand_distr::StandardNormal;
use rand_xoshiro::Xoshiro256PlusPlus;

/// Tag of the sensors' streams (mixed into the run's seed: the radio's faults draw from
/// generators of their own).
const SENSOR_STREAM: u64 = 1;

/// Between whom a bearing is measured: an agent at `q_self` (velocity `v_self`) and its
/// neighbour with wire id `neighbour` at `q_other` (`v_other`), in the true state.
#[derive(Clone, Copy, Debug)]
pub struct Sight<'a> {
    /// The neighbour's wire id (the measurement's tag).
    pub neighbour: u8,
    /// The measuring agent's position.
    pub q_self: &'a Vec2<f64>,
    /// The neighbour's position.
    pub q_other: &'a Vec2<f64>,
    /// The measuring agent's velocity.
    pub v_self: &'a Vec2<f64>,
    /// The neighbour's velocity.
    pub v_other: &'a Vec2<f64>,
}

impl<'a> Sight<'a> {
    /// Agent `i`'s sight of agent `j`, from every agent's wire id, position and velocity.
    #[inline]
    pub fn between(ids: &[u8], q: &'a [Vec2<f64>], v: &'a [Vec2<f64>], i: usize, j: usize) -> Self {
        Self {
            neighbour: ids[j],
            q_self: &q[i],
            q_other: &q[j],
            v_self: &v[i],
            v_other: &v[j],
        }
    }
}

/// The random part of one bearing measurement.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
struct BearingNoise {
    /// Rotation noise (rad), without the bias.
    angle: f64,
    /// Range error (m), when a range is measured.
    range: Option<f64>,
}

/// The sensor model and the key of its random streams.
#[derive(Clone, Debug)]
pub struct Sensors {
    model: SensorModel,
    /// The run's seed mixed with [`SENSOR_STREAM`].
    key: u64,
}

impl Sensors {
    /// Seeded sensors.
    pub fn new(model: &SensorModel, seed: u64) -> Self {
        let key = stream_key(seed, SENSOR_STREAM);
        Self {
            model: model.clone(),
            key,
        }
    }

    /// The model.
    pub fn model(&self) -> &SensorModel {
        &self.model
    }

    /// Agent `agent`'s random stream at tick `tick` (draw its bearings in graph order,
    /// then its velocity, then its partner offset). A different generator for every
    /// agent index below 2³² and tick below 2³² (497 days at 100 Hz; ticks wrap after),
    /// seeded by SplitMix64 from `key ^ (agent · 2³² + tick)` ([`stream`], the one scheme
    /// of every per-agent stream).
    #[inline]
    pub fn stream(&self, agent: usize, tick: u64) -> Draws<'_> {
        Draws {
            model: &self.model,
            rng: stream(self.key, agent, tick),
        }
    }

    /// Whether measuring draws from the random stream: some noise that applies is not
    /// zero (`with_range`: ranges are measured). When none does, every measurement is
    /// a function of the state alone ([`quiet_bearing`], [`velocity_with`],
    /// [`offset_with`] with zero noise give what the drawing methods give, bit for bit).
    /// ([`SensorModel::departures`], the one classification of the sensors' fields.)
    pub fn draws(&self, with_range: bool) -> bool {
        let d = self.model.departures();
        d.noise || (with_range && d.range_noise)
    }
}

/// One agent's random stream of one tick ([`Sensors::stream`]) and the sensor model.
/// (Not `Clone`: a copy would draw the same numbers twice.)
#[derive(Debug)]
pub struct Draws<'a> {
    model: &'a SensorModel,
    rng: Xoshiro256PlusPlus,
}

impl Draws<'_> {
    fn gauss(&mut self, sigma: f64) -> f64 {
        if sigma > 0.0 {
            sigma * self.rng.sample::<f64, _>(StandardNormal)
        } else {
            0.0
        }
    }

    /// The bearing measured along `sight` (tagged with the neighbour's id), `None` (and
    /// no draw) if the agents coincide. `exact_rate` adds the S2 rate of the true state;
    /// `with_range` the (noisy) distance.
    #[inline]
    pub fn bearing(
        &mut self,
        sight: &Sight<'_>,
        exact_rate: bool,
        with_range: bool,
    ) -> Option<BearingMeasurement<f64>> {
        let (d, r) = separation(sight)?;
        let angle = self.gauss(self.model.bearing_noise);
        let range = with_range.then(|| self.gauss(self.model.range_noise));
        Some(measured(
            self.model,
            BearingNoise { angle, range },
            sight,
            d,
            r,
            exact_rate,
        ))
    }

    /// The agent's measured own velocity.
    #[inline]
    pub fn velocity(&mut self, v: &Vec2<f64>) -> Vec2<f64> {
        let s = self.model.velocity_noise;
        let noise = [self.gauss(s), self.gauss(s)];
        velocity_with(self.model, v, noise)
    }

    /// A Gaussian draw of standard deviation `sigma` (0, and no draw, when `sigma` is 0).
    #[inline]
    pub fn normal(&mut self, sigma: f64) -> f64 {
        self.gauss(sigma)
    }

    /// A uniform draw in `[0, 1)` (a bearing sensor's chances: detection, outliers).
    #[inline]
    pub fn uniform(&mut self) -> f64 {
        self.rng.random::<f64>()
    }

    /// A leader's measured partner offset `q_partner − q_self`.
    #[inline]
    pub fn offset(&mut self, q_self: &Vec2<f64>, q_partner: &Vec2<f64>) -> Vec2<f64> {
        let s = self.model.offset_noise;
        let noise = [self.gauss(s), self.gauss(s)];
        offset_with(q_self, q_partner, noise)
    }
}

/// The noise of a bearing when [`Sensors::draws`] is false (what [`Draws::bearing`]
/// then draws): no rotation, and a zero range error when ranges are measured.
fn quiet_noise(with_range: bool) -> BearingNoise {
    BearingNoise {
        angle: 0.0,
        range: with_range.then_some(0.0),
    }
}

/// The bearing along `sight` when [`Sensors::draws`] is false: what
/// [`Draws::bearing`] then gives, without a stream (`None` if the agents coincide).
#[inline]
pub fn quiet_bearing(
    model: &SensorModel,
    sight: &Sight<'_>,
    exact_rate: bool,
    with_range: bool,
) -> Option<BearingMeasurement<f64>> {
    let (d, r) = separation(sight)?;
    Some(measured(
        model,
        quiet_noise(with_range),
        sight,
        d,
        r,
        exact_rate,
    ))
}

/// The measured own velocity with the given noise (the bias added first).
#[inline]
pub fn velocity_with(model: &SensorModel, v: &Vec2<f64>, noise: [f64; 2]) -> Vec2<f64> {
    let b = model.velocity_bias;
    Vec2::new(v.x + b[0] + noise[0], v.y + b[1] + noise[1])
}

/// The measured partner offset `q_partner − q_self` with the given noise.
#[inline]
pub fn offset_with(q_self: &Vec2<f64>, q_partner: &Vec2<f64>, noise: [f64; 2]) -> Vec2<f64> {
    let d = q_partner - q_self;
    Vec2::new(d.x + noise[0], d.y + noise[1])
}

/// The displacement `d = q_other − q_self` and distance `r = |d|` of a sight, `None` when
/// no bearing can be measured (the agents coincide, or `r` is not finite).
#[inline]
fn separation(sight: &Sight<'_>) -> Option<(Vec2<f64>, f64)> {
    let d = sight.q_other - sight.q_self;
    let r = d.norm();
    (r > 0.0 && r.is_finite()).then_some((d, r))
}

/// The bearing along `sight` with displacement `d` and distance `r` and the given noise:
/// the true bearing `d / r` rotated by `bearing_bias + noise.angle`, the exact S2 rate
/// with `exact_rate`, the distance plus `noise.range` when drawn.
#[inline]
fn measured(
    model: &SensorModel,
    noise: BearingNoise,
    sight: &Sight<'_>,
    d: Vec2<f64>,
    r: f64,
    exact_rate: bool,
) -> BearingMeasurement<f64> {
    let s_true = d / r;
    let angle = model.bearing_bias + noise.angle;
    let bearing = if angle != 0.0 {
        Turn::by(angle).apply(&s_true)
    } else {
        s_true
    };
    let rate =
        exact_rate.then(|| geometry::bearing_rate(&s_true, &(sight.v_other - sight.v_self), r));
    let range = noise.range.map(|e| (r + e).max(1e-6));
    BearingMeasurement {
        neighbour: sight.neighbour,
        bearing,
        rate,
        range,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::BearingRate;

    #[test]
    fn ideal_bearing_is_exact() {
        let s = Sensors::new(&SensorModel::ideal(BearingRate::Exact), 1);
        let sight = Sight {
            neighbour: 2,
            q_self: &Vec2::new(0.0, 0.0),
            q_other: &Vec2::new(3.0, 4.0),
            v_self: &Vec2::zeros(),
            v_other: &Vec2::new(1.0, 0.0),
        };
        let b = s.stream(0, 0).bearing(&sight, true, true).unwrap();
        assert_eq!(b.bearing, Vec2::new(0.6, 0.8));
        assert_eq!(b.range, Some(5.0));
        // P(s) v / r with s = (0.6, 0.8), v = (1, 0): (1 − 0.36, −0.48) / 5.
        let rate = b.rate.unwrap();
        assert!((rate - Vec2::new(0.64 / 5.0, -0.48 / 5.0)).norm() < 1e-15);
    }

    /// Sensors without noise (but with biases) draw nothing, and the quiet functions give
    /// the drawing methods' bits (a -0.0 component included); any noise that applies
    /// makes them draw.
    #[test]
    fn quiet_measurements_are_the_drawn_ones_without_the_stream() {
        let mut m = SensorModel::ideal(BearingRate::Exact);
        m.bearing_bias = 0.01;
        m.velocity_bias = [0.02, -0.03];
        m.range_noise = 0.5; // applies only with ranges
        let s = Sensors::new(&m, 7);
        assert!(!s.draws(false) && s.draws(true));
        let (q, v) = (
            [Vec2::new(0.1, -0.0), Vec2::new(3.0, 4.0)],
            Vec2::new(-0.0, 1.5),
        );
        let sight = Sight {
            neighbour: 2,
            q_self: &q[0],
            q_other: &q[1],
            v_self: &v,
            v_other: &Vec2::new(1.0, 0.0),
        };
        let mut d = s.stream(3, 5);
        for exact in [true, false] {
            assert_eq!(
                d.bearing(&sight, exact, false),
                quiet_bearing(&m, &sight, exact, false)
            );
        }
        let bits = |x: Vec2<f64>| [x.x.to_bits(), x.y.to_bits()];
        assert_eq!(bits(d.velocity(&v)), bits(velocity_with(&m, &v, [0.0; 2])));
        let offset = offset_with(&q[0], &q[1], [0.0; 2]);
        assert_eq!(bits(d.offset(&q[0], &q[1])), bits(offset));
        // Nothing was drawn: the stream is where a fresh one starts.
        assert_eq!(d.gauss(1.0).to_bits(), s.stream(3, 5).gauss(1.0).to_bits());
        for noisy in [0, 1, 2] {
            let mut n = SensorModel::ideal(BearingRate::Exact);
            match noisy {
                0 => n.bearing_noise = 1e-3,
                1 => n.velocity_noise = 1e-3,
                _ => n.offset_noise = 1e-3,
            }
            assert!(Sensors::new(&n, 1).draws(false), "{n:?}");
        }
    }

    #[test]
    fn noisy_bearing_stays_unit() {
        let mut m = SensorModel::ideal(BearingRate::FiniteDifference);
        m.bearing_noise = 0.05;
        let s = Sensors::new(&m, 1);
        let sight = Sight {
            neighbour: 1,
            q_self: &Vec2::zeros(),
            q_other: &Vec2::new(1.0, 1.0),
            v_self: &Vec2::zeros(),
            v_other: &Vec2::zeros(),
        };
        let mut d = s.stream(0, 0);
        for _ in 0..100 {
            let b = d.bearing(&sight, false, false).unwrap();
            assert!((b.bearing.norm() - 1.0).abs() < 1e-12);
            assert!(b.rate.is_none());
        }
    }

    /// A stream is a function of seed, agent and tick alone: the same draws whenever it
    /// is made (so agents can be measured in any order), and different draws for another
    /// seed, agent or tick. Coincident agents measure nothing and draw nothing.
    #[test]
    fn each_agent_and_tick_has_its_own_reproducible_stream() {
        let mut m = SensorModel::ideal(BearingRate::Exact);
        m.bearing_noise = 0.05;
        let first = |s: &Sensors, agent, tick| s.stream(agent, tick).gauss(1.0).to_bits();
        let s = Sensors::new(&m, 7);
        let mut seen = std::collections::HashSet::new();
        for agent in [0, 1, 2, 99_999, (1 << 32) - 1] {
            for tick in [0, 1, 2, 10_000, (1 << 32) - 1] {
                assert_eq!(first(&s, agent, tick), first(&s, agent, tick));
                assert!(seen.insert(first(&s, agent, tick)), "{agent} {tick}");
            }
        }
        assert_ne!(first(&s, 4, 4), first(&Sensors::new(&m, 8), 4, 4));
        // Normal draws: mean ≈ 0 and variance ≈ 1 over many agents' first draws.
        let x: Vec<f64> = (0..20_000).map(|a| s.stream(a, 3).gauss(1.0)).collect();
        let mean = x.iter().sum::<f64>() / x.len() as f64;
        let var = x.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / x.len() as f64;
        assert!(
            mean.abs() < 0.03 && (var - 1.0).abs() < 0.05,
            "{mean} {var}"
        );
        let same = Vec2::new(1.0, 2.0);
        let sight = Sight {
            neighbour: 9,
            q_self: &same,
            q_other: &same,
            v_self: &same,
            v_other: &same,
        };
        let mut d = s.stream(5, 6);
        assert_eq!(d.bearing(&sight, true, true), None);
        assert_eq!(d.gauss(1.0).to_bits(), first(&s, 5, 6));
    }
}
