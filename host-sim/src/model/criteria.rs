//! When a run has failed or converged: the thresholds of the failure monitor.

use serde::{Deserialize, Serialize};

/// Failure detection and convergence tolerances (the scenario file's `[criteria]`, used
/// as they are).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct Criteria {
    /// Two agents closer than this (m) have collided.
    pub collision_distance: f64,
    /// An estimate held at `r_min` for this long (s) has collapsed.
    pub collapse_time: f64,
    /// Any speed above this (m/s), or a non-finite state, is divergence.
    pub divergence_speed: f64,
    /// `V` above this multiple of `max(V(0), 1)` is divergence.
    pub divergence_energy_factor: f64,
    /// Every angle error below this (rad) counts as settled.
    pub angle_tolerance: f64,
    /// Final `|z − z*|` below this (m) counts as converged.
    pub displacement_tolerance: f64,
    /// Final `max_n |v_n − v*|` below this (m/s) counts as converged.
    pub velocity_tolerance: f64,
    /// The final formation, best fitted to the target shape (translation, rotation,
    /// scale, mirror), must have every agent within this fraction of the target's size
    /// (its RMS distance from the centroid) of its target point, and no triangle folded,
    /// to count as converged (`wrong_shape` otherwise).
    pub shape_tolerance: f64,
    /// The steady window `W` (s) that a run with random sensing or a random world is
    /// judged on: its last `W` seconds; 0 (the default) means a quarter of the run
    /// (`analysis::steady`, docs/outputs.md "Outcome").
    pub steady_window: f64,
    /// Largest share of the controllers' outputs in the steady window that may be the
    /// safe output; above it the run is `not_in_control` (every run, noisy or not).
    pub safe_share: f64,
    /// The largest angle band (rad) a calibration may set (default 1°): a scenario widens
    /// it only by saying so here.
    pub angle_band_cap: f64,
    /// The largest scale band of the leader edge (m) a calibration may set.
    pub scale_band_cap: f64,
    /// The largest velocity band (m/s) a calibration may set.
    pub velocity_band_cap: f64,
}

impl Default for Criteria {
    fn default() -> Self {
        Self {
            collision_distance: 0.05,
            collapse_time: 0.25,
            divergence_speed: 1e3,
            divergence_energy_factor: 1e3,
            angle_tolerance: 1e-3,
            displacement_tolerance: 1e-2,
            velocity_tolerance: 1e-2,
            shape_tolerance: 5e-2,
            steady_window: 0.0,
            safe_share: 0.05,
            angle_band_cap: 1f64.to_radians(),
            scale_band_cap: 5e-2,
            velocity_band_cap: 5e-2,
        }
    }
}
