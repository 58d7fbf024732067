//! The noise-aware verdict (`docs/sensors.md`, "When a noisy run has converged"): with
//! noisy sensors no controller holds its angles to 1e-3 rad, so the convergence criteria
//! become bands derived from the declared noise, and the run reports its steady-state RMS
//! angle error.
//!
//! With `σ_b` the bearing noise (rad), `σ_v` the velocity noise (m/s per component) and
//! `σ_o` the leaders' offset noise (m per component):
//!
//! | criterion | band |
//! |---|---|
//! | every angle error | `max(angle_tolerance, √2 σ_b)`: one angle reading, from two bearings, has noise `√2 σ_b` |
//! | `|z − z*|` | `max(displacement_tolerance, √2 σ_b |z*| + 3 σ_o)`: an angle error of `√2 σ_b` across the leader edge, and the offset sensor's 3σ |
//! | `max_n |v_n − v*|` | `max(velocity_tolerance, √2 σ_b |v*| + 3 σ_v)`: the velocity turned by `√2 σ_b`, and the velocity sensor's 3σ |
//!
//! A noise-free run (every σ zero) keeps the criteria as they are.

use crate::model::Model;

/// The convergence bands of a noisy run.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct NoiseBands {
    /// Every angle error must stay below this (rad).
    pub angle: f64,
    /// Final `|z − z*|` below this (m).
    pub displacement: f64,
    /// Final `max_n |v_n − v*|` below this (m/s).
    pub velocity: f64,
}

impl NoiseBands {
    /// The bands of `model`'s sensors at the end of the run, or `None` for noise-free
    /// sensors (the criteria hold as they are).
    pub fn of(model: &Model) -> Option<Self> {
        let se = &model.sensors;
        if se.bearing_noise <= 0.0 && se.velocity_noise <= 0.0 && se.offset_noise <= 0.0 {
            return None;
        }
        let cr = &model.criteria;
        let angle = std::f64::consts::SQRT_2 * se.bearing_noise;
        let norm = |v: [f64; 2]| v[0].hypot(v[1]);
        let z = model.z_star(model.duration).map_or(0.0, norm);
        let v = norm(model.v_star(model.duration));
        Some(Self {
            angle: cr.angle_tolerance.max(angle),
            displacement: cr
                .displacement_tolerance
                .max(angle * z + 3.0 * se.offset_noise),
            velocity: cr
                .velocity_tolerance
                .max(angle * v + 3.0 * se.velocity_noise),
        })
    }
}

/// Mean square angle error of the instants in a window.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct MeanSquare {
    sum: f64,
    count: u64,
    /// The first instant of the window.
    pub from: Option<f64>,
}

impl MeanSquare {
    /// Adds one instant's angle errors (their mean square over the angles).
    pub fn add(&mut self, t: f64, angle_err: &[f64]) {
        if angle_err.is_empty() {
            return;
        }
        let ms = angle_err.iter().map(|e| e * e).sum::<f64>() / angle_err.len() as f64;
        self.sum += ms;
        self.count += 1;
        self.from.get_or_insert(t);
    }

    /// The RMS over the window (`None` when empty).
    pub fn rms(&self) -> Option<f64> {
        (self.count > 0).then(|| (self.sum / self.count as f64).sqrt())
    }
}

/// What a noisy run reports (`summary.json`'s `noise`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct NoiseReport {
    /// The bands the verdict used.
    pub bands: NoiseBands,
    /// RMS angle error over the angles and the instants of the steady state: from the
    /// settle time on, or over the last quarter of the run if it never settled (rad).
    pub steady_rms_angle_error: Option<f64>,
    /// The first instant of that window (s).
    pub window_start: Option<f64>,
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn mean_square_is_over_angles_then_instants() {
        let mut m = MeanSquare::default();
        assert_eq!(m.rms(), None);
        m.add(1.0, &[3.0, 4.0]); // mean square 12.5
        m.add(2.0, &[0.0, 0.0]); // 0
        assert_eq!(m.from, Some(1.0));
        assert!((m.rms().unwrap() - 6.25f64.sqrt()).abs() < 1e-15);
    }
}
