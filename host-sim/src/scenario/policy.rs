//! `[policy]`: the vehicles' safety policies (controller-core's `policy` module, the
//! same code the Crazyflie app runs; docs/scenarios.md "Safety policies").

use serde::{Deserialize, Serialize};

/// `[policy]` (optional; without it no policy runs and a run is what it was).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PolicySpec {
    /// Lost neighbours or radio (the controller's safe output) for this long (s):
    /// land; holding until then.
    #[serde(default = "default_hold_timeout")]
    pub hold_timeout_s: f64,
    /// The flight volume's lower corner `[x, y]` (m; with `fence_max`).
    #[serde(default)]
    pub fence_min: Option<[f64; 2]>,
    /// Its upper corner (m; with `fence_min`).
    #[serde(default)]
    pub fence_max: Option<[f64; 2]>,
    /// Minimum separation (m): the force's component towards a closer neighbour is
    /// removed (0: off).
    #[serde(default)]
    pub min_separation: f64,
}

fn default_hold_timeout() -> f64 {
    2.0
}
