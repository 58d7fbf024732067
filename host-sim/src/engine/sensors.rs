//! Each agent's own sensors: bearings from the true state plus rotation noise and bias,
//! optional exact bearing rates (S2), own velocity with noise and bias, the leaders'
//! relative position, and ranges for the `measured` estimator.

use crate::model::SensorModel;
use controller_core::{geometry, BearingMeasurement, Vec2};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use rand_distr::StandardNormal;

/// Random stream of the sensors (independent of the radio's stream).
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

/// The random part of one bearing measurement ([`Sensors::draw_noise`]).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct BearingNoise {
    /// Rotation noise (rad), without the bias.
    pub angle: f64,
    /// Range error (m), when a range is measured.
    pub range: Option<f64>,
}

/// The sensor model with its random number generator.
#[derive(Clone, Debug)]
pub struct Sensors {
    model: SensorModel,
    rng: ChaCha8Rng,
}

impl Sensors {
    /// Seeded sensors.
    pub fn new(model: &SensorModel, seed: u64) -> Self {
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        rng.set_stream(SENSOR_STREAM);
        Self {
            model: model.clone(),
            rng,
        }
    }

    /// The model.
    pub fn model(&self) -> &SensorModel {
        &self.model
    }

    fn gauss(&mut self, sigma: f64) -> f64 {
        if sigma > 0.0 {
            sigma * self.rng.sample::<f64, _>(StandardNormal)
        } else {
            0.0
        }
    }

    /// The bearing measured along `sight` (tagged with the neighbour's id), `None` if
    /// the agents coincide. `exact_rate` adds the S2 rate of the true state;
    /// `with_range` the (noisy) distance. (What [`in_sight`], [`Sensors::draw_noise`]
    /// and [`Sensors::bearing_with`] give, with the distance computed once: the draws in
    /// agent order and the geometry on any thread can be apart.)
    #[inline]
    pub fn bearing(
        &mut self,
        sight: &Sight<'_>,
        exact_rate: bool,
        with_range: bool,
    ) -> Option<BearingMeasurement<f64>> {
        let (d, r) = separation(sight)?;
        let noise = self.draw_noise(with_range);
        Some(measured(&self.model, noise, sight, d, r, exact_rate))
    }

    /// The bearing with the given noise (no random draws): the true bearing rotated by
    /// `bearing_bias + noise.angle`, the exact S2 rate with `exact_rate`, the distance
    /// plus `noise.range` when drawn. The agents must not coincide ([`in_sight`]).
    #[inline]
    pub fn bearing_with(
        model: &SensorModel,
        noise: BearingNoise,
        sight: &Sight<'_>,
        exact_rate: bool,
    ) -> BearingMeasurement<f64> {
        let d = sight.q_other - sight.q_self;
        let r = d.norm();
        measured(model, noise, sight, d, r, exact_rate)
    }

    /// The noise of one bearing: the rotation, then the range error if `with_range` (what
    /// [`Sensors::bearing`] draws for a sight [`in_sight`]).
    #[inline]
    pub fn draw_noise(&mut self, with_range: bool) -> BearingNoise {
        let angle = self.gauss(self.model.bearing_noise);
        let range = if with_range {
            Some(self.gauss(self.model.range_noise))
        } else {
            None
        };
        BearingNoise { angle, range }
    }

    /// The agent's measured own velocity.
    #[inline]
    pub fn velocity(&mut self, v: &Vec2<f64>) -> Vec2<f64> {
        let s = self.model.velocity_noise;
        let noise = [self.gauss(s), self.gauss(s)];
        velocity_with(&self.model, v, noise)
    }

    /// A leader's measured partner offset `q_partner − q_self`.
    #[inline]
    pub fn offset(&mut self, q_self: &Vec2<f64>, q_partner: &Vec2<f64>) -> Vec2<f64> {
        let s = self.model.offset_noise;
        let noise = [self.gauss(s), self.gauss(s)];
        offset_with(q_self, q_partner, noise)
    }

    /// Whether measuring draws from the random stream: some noise that applies is not
    /// zero (`with_range`: ranges are measured). When none does, every measurement is
    /// a function of the state alone ([`quiet_noise`], [`velocity_with`], [`offset_with`] with
    /// zero noise give what the drawing methods give, bit for bit) and can be taken on
    /// any thread in any order.
    pub fn draws(&self, with_range: bool) -> bool {
        let m = &self.model;
        m.bearing_noise > 0.0
            || (with_range && m.range_noise > 0.0)
            || m.velocity_noise > 0.0
            || m.offset_noise > 0.0
    }
}

/// The noise of a bearing when [`Sensors::draws`] is false (what
/// [`Sensors::draw_noise`] then returns): no rotation, and a zero range error when
/// ranges are measured.
pub fn quiet_noise(with_range: bool) -> BearingNoise {
    BearingNoise {
        angle: 0.0,
        range: with_range.then_some(0.0),
    }
}

/// The bearing along `sight` when [`Sensors::draws`] is false: what
/// [`Sensors::bearing`] then gives, without the stream (`None` if the agents coincide).
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

/// Whether a bearing can be measured along `sight`: the agents do not coincide (and
/// their distance is finite). No random draw.
#[inline]
pub fn in_sight(sight: &Sight<'_>) -> bool {
    separation(sight).is_some()
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
        let (sn, cs) = angle.sin_cos();
        Vec2::new(cs * s_true.x - sn * s_true.y, sn * s_true.x + cs * s_true.y)
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
        let mut s = Sensors::new(&SensorModel::ideal(BearingRate::Exact), 1);
        let sight = Sight {
            neighbour: 2,
            q_self: &Vec2::new(0.0, 0.0),
            q_other: &Vec2::new(3.0, 4.0),
            v_self: &Vec2::zeros(),
            v_other: &Vec2::new(1.0, 0.0),
        };
        let b = s.bearing(&sight, true, true).unwrap();
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
        let mut s = Sensors::new(&m, 7);
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
        for exact in [true, false] {
            assert_eq!(
                s.bearing(&sight, exact, false),
                quiet_bearing(&m, &sight, exact, false)
            );
        }
        let bits = |x: Vec2<f64>| [x.x.to_bits(), x.y.to_bits()];
        assert_eq!(bits(s.velocity(&v)), bits(velocity_with(&m, &v, [0.0; 2])));
        let offset = offset_with(&q[0], &q[1], [0.0; 2]);
        assert_eq!(bits(s.offset(&q[0], &q[1])), bits(offset));
        // Nothing was drawn: the stream is where a fresh one starts.
        assert_eq!(
            s.gauss(1.0).to_bits(),
            Sensors::new(&m, 7).gauss(1.0).to_bits()
        );
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
        let mut s = Sensors::new(&m, 1);
        let sight = Sight {
            neighbour: 1,
            q_self: &Vec2::zeros(),
            q_other: &Vec2::new(1.0, 1.0),
            v_self: &Vec2::zeros(),
            v_other: &Vec2::zeros(),
        };
        for _ in 0..100 {
            let b = s.bearing(&sight, false, false).unwrap();
            assert!((b.bearing.norm() - 1.0).abs() < 1e-12);
            assert!(b.rate.is_none());
        }
    }

    /// Drawing the noise and computing the bearing apart (the parallel path) gives the
    /// same bits and leaves the stream where `bearing` leaves it, ranges and coincident
    /// agents (no draw) included.
    #[test]
    fn noise_then_geometry_is_the_same_bearing() {
        let mut m = SensorModel::ideal(BearingRate::Exact);
        m.bearing_noise = 0.05;
        m.bearing_bias = 0.01;
        m.range_noise = 0.02;
        let (mut one, mut two) = (Sensors::new(&m, 7), Sensors::new(&m, 7));
        let q = [
            Vec2::new(0.0, 0.0),
            Vec2::new(1.0, 2.0),
            Vec2::new(1.0, 2.0),
        ];
        let v = [
            Vec2::new(0.1, 0.0),
            Vec2::new(0.0, -0.3),
            Vec2::new(0.2, 0.2),
        ];
        let mut drawn = 0;
        for k in 0..300 {
            let (i, j) = [(0, 1), (1, 2), (2, 0)][k % 3];
            let ranged = k % 2 == 0;
            let sight = Sight {
                neighbour: 9,
                q_self: &q[i],
                q_other: &q[j],
                v_self: &v[i],
                v_other: &v[j],
            };
            let a = one.bearing(&sight, true, ranged);
            let b = in_sight(&sight)
                .then(|| two.draw_noise(ranged))
                .map(|n| Sensors::bearing_with(&m, n, &sight, true));
            assert_eq!(a, b, "draw {k}");
            drawn += usize::from(a.is_some());
        }
        // Agents 1 and 2 coincide: a third of the sights measure nothing.
        assert_eq!(drawn, 200);
        assert_eq!(one.gauss(1.0).to_bits(), two.gauss(1.0).to_bits());
    }
}
