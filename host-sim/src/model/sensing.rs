//! One effective sensing noise per scenario (`docs/sensors.md`, "The effective sensing
//! noise"): what the whole sensing chain does to one bearing, and whether anything in it
//! (or in the world) is random. `sensors.bearing_filter = "auto"` and the verdict's
//! calibration (`docs/outputs.md`, "Outcome") both read it, so they cannot disagree.

use super::{Model, PositionsModel};

/// What a scenario's sensing chain does to the agents' measurements.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SensingNoise {
    /// Standard deviation of one bearing's direction from every source together (rad):
    /// `√(σ_b² + σ_h² + σ_p²)` with `σ_b` the bearing sensor's noise, `σ_h` the heading
    /// estimate's white noise (it turns every bearing the agent measures) and `σ_p` the
    /// bearing noise that shared positions give at the formation's shortest initial edge
    /// `d`, `√2 σ_pos / d` (two noisy positions, each across the edge).
    pub bearing: f64,
    /// Velocity noise per component (m/s).
    pub velocity: f64,
    /// Noise on the leader partner's offset (m) or on ranges (m).
    pub offset: f64,
    /// Bearings go missing or wrong at random: camera outliers or detection below 1, or
    /// shared positions over a radio that loses or delays them.
    pub lossy: bool,
    /// The world is random: gusts, drawn heading errors or drifts.
    pub random_world: bool,
}

impl SensingNoise {
    /// Whether the sensing chain is noisy or lossy: `bearing_filter = "auto"` then runs
    /// the tracker (SPEC §11).
    pub fn is_noisy(&self) -> bool {
        self.bearing > 0.0 || self.velocity > 0.0 || self.offset > 0.0 || self.lossy
    }

    /// Whether the verdict judges the steady window against calibrated bands (noisy
    /// sensing or a random world); otherwise the run keeps the noise-free criteria.
    pub fn needs_calibration(&self) -> bool {
        self.is_noisy() || self.random_world
    }
}

impl Model {
    /// The effective sensing noise of this scenario.
    pub fn sensing_noise(&self) -> SensingNoise {
        let se = &self.sensors;
        let heading = self.world.heading.as_ref();
        let sigma_h = heading.map_or(0.0, |h| h.noise);
        let sigma_p = se
            .positions
            .as_ref()
            .map_or(0.0, |p| positions_bearing_noise(p, self.shortest_edge()));
        let camera_lossy = se
            .camera
            .as_ref()
            .is_some_and(|c| c.detection_probability < 1.0 || c.outlier_probability > 0.0);
        let positions_lossy = se.positions.is_some() && self.radio.is_faulty();
        let gusts = self.world.wind.as_ref().is_some_and(|w| w.gust > 0.0);
        let headings_drawn = heading.is_some_and(|h| h.error > 0.0 || h.drift > 0.0);
        SensingNoise {
            bearing: (se.bearing_noise.powi(2) + sigma_h.powi(2) + sigma_p.powi(2)).sqrt(),
            velocity: se.velocity_noise,
            offset: se.offset_noise.max(se.range_noise),
            lossy: camera_lossy || positions_lossy,
            random_world: gusts || headings_drawn,
        }
    }

    /// The shortest edge of the graph at the initial positions (m; infinite without
    /// edges).
    fn shortest_edge(&self) -> f64 {
        self.graph
            .edges
            .iter()
            .map(|e| {
                let (a, b) = (self.agents[e[0]].position, self.agents[e[1]].position);
                (a[0] - b[0]).hypot(a[1] - b[1])
            })
            .fold(f64::INFINITY, f64::min)
    }
}

/// The bearing noise (rad) of shared positions of per-axis noise `σ` across an edge of
/// length `d`: each end's noise across the edge is `σ`, so the bearing's is `√2 σ / d`.
fn positions_bearing_noise(p: &PositionsModel, d: f64) -> f64 {
    if d > 0.0 && d.is_finite() {
        std::f64::consts::SQRT_2 * p.noise / d
    } else {
        0.0
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn position_noise_turns_into_bearing_noise_across_the_edge() {
        let p = PositionsModel {
            noise: 0.01,
            max_age: 0.1,
        };
        let s = positions_bearing_noise(&p, 2.0);
        assert!((s - 0.01 * 2f64.sqrt() / 2.0).abs() < 1e-15);
        assert_eq!(positions_bearing_noise(&p, 0.0), 0.0);
    }
}
