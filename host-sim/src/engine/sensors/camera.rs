//! The camera (`[sensors.camera]`, docs/sensors.md): every agent sees a neighbour's bearing
//! only within its field of view about its heading, within range, when no other agent's
//! body hides it ([`occlusion`](super::occlusion)), and when it is detected; a detected
//! bearing may be an outlier; and every bearing describes the geometry `latency` ago
//! ([`latency`](super::latency)).
//!
//! Agent `i`'s bearing of neighbour `j`, on the image (the state `latency` ago, or the
//! state of the tick without latency):
//!
//! 1. seen when `0 < r ≤ range` with `r = |q_j − q_i|`, when `d · b ≥ r cos(fov / 2)` with
//!    `d = q_j − q_i` and `b = (cos h_i, sin h_i)` the boresight along agent `i`'s heading
//!    (every direction for `fov = 360°`), and when nothing hides it;
//! 2. detected when a uniform draw `u < detection_probability` (no draw when it is 1);
//! 3. measured by the sensors' bearing (rotation noise and bias, range noise:
//!    [`Draws::bearing`], the same draws as without a camera);
//! 4. replaced, when a uniform draw `u < outlier_probability` (no draw when it is 0), by
//!    the direction `(cos θ, sin θ)` of a uniform `θ ∈ [0, 2π)` (another draw); its rate
//!    and range stay those of step 3.
//!
//! The draws come from agent `i`'s stream of the tick in that order, neighbour by
//! neighbour in graph order: a run gives the same bits on any number of threads.

use super::latency::Delay;
use super::occlusion::Occluders;
use super::source::{BearingKind, BearingSensor, World};
use super::{Draws, Sight};
use crate::model::CameraModel;
use ph_formation_core::{BearingMeasurement, Vec2};
use std::f64::consts::TAU;

/// Every agent's camera and what it keeps between ticks.
#[derive(Debug)]
pub struct Camera {
    /// `cos(fov / 2)`; `None` for a field of view all round.
    cos_half_fov: Option<f64>,
    range: f64,
    detection: f64,
    outlier: f64,
    /// The history of a latency above 0.
    delay: Option<Delay>,
    /// The bodies, with an occlusion radius above 0.
    occluders: Option<Occluders>,
}

impl Camera {
    /// The camera `model` of `n` agents, ticking every `period` seconds.
    pub fn new(model: &CameraModel, n: usize, period: f64) -> Self {
        Self {
            cos_half_fov: (model.fov < TAU).then(|| (0.5 * model.fov).cos()),
            range: model.range,
            detection: model.detection_probability,
            outlier: model.outlier_probability,
            delay: (model.latency > 0.0).then(|| Delay::new(model.latency, period, n)),
            occluders: (model.occlusion_radius > 0.0)
                .then(|| Occluders::new(model.occlusion_radius)),
        }
    }

    /// Whether `j` is in `i`'s view on `image` (step 1 of the module's list), with
    /// `d = q_j − q_i` and `r = |d|`.
    fn in_view(&self, image: &World<'_>, i: usize, j: usize, d: Vec2<f64>, r: f64) -> bool {
        if !(r > 0.0 && r <= self.range) {
            return false;
        }
        if let Some(cos_half) = self.cos_half_fov {
            let (s, c) = image.headings[i].sin_cos();
            if d.x * c + d.y * s < r * cos_half {
                return false;
            }
        }
        self.occluders
            .as_ref()
            .is_none_or(|o| !o.hides(image.q, i, j, r))
    }
}

impl BearingSensor for Camera {
    fn prepare(&mut self, world: &World<'_>) {
        if let Some(delay) = &mut self.delay {
            delay.push(world);
        }
        if let Some(occluders) = &mut self.occluders {
            let image = self.delay.as_ref().map_or(*world, Delay::image);
            occluders.rebuild(image.q);
        }
    }

    fn bearing(
        &self,
        world: &World<'_>,
        ids: &[u8],
        i: usize,
        j: usize,
        kind: BearingKind,
        draws: &mut Draws<'_>,
    ) -> Option<BearingMeasurement<f64>> {
        let image = self.delay.as_ref().map_or(*world, Delay::image);
        let d = image.q[j] - image.q[i];
        if !self.in_view(&image, i, j, d, d.norm()) {
            return None;
        }
        if self.detection < 1.0 && draws.uniform() >= self.detection {
            return None;
        }
        let sight = Sight::between(ids, image.q, image.v, i, j);
        let mut b = draws.bearing(&sight, kind.exact_rate, kind.with_range)?;
        if self.outlier > 0.0 && draws.uniform() < self.outlier {
            let (s, c) = (TAU * draws.uniform()).sin_cos();
            b.bearing = Vec2::new(c, s);
        }
        Some(b)
    }
}
