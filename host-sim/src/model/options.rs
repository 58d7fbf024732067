//! How a run is set up: the simulation mode, the controllers' distance source and the
//! source of bearing rates. They are named the same in scenario files (serde) and in
//! `summary.json` (`as_str`).

use serde::{Deserialize, Serialize};

/// Simulation mode.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Mode {
    /// Controllers sampled with zero-order hold at their rate, frames over the radio model.
    #[default]
    Sampled,
    /// Controllers evaluated at every RK4 stage with exact rates, estimators inside the
    /// ODE state, no radio (for checking S14).
    Continuous,
}

impl Mode {
    /// The name used in files and `summary.json`.
    pub fn as_str(self) -> &'static str {
        match self {
            Mode::Sampled => "sampled",
            Mode::Continuous => "continuous",
        }
    }
}

/// Distance source of the controllers (SPEC §6).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Estimator {
    /// One passive estimate per angle and edge, owned by the apex (S9, S10).
    #[default]
    Shared,
    /// The paper's per-agent copies (not passive).
    PerAgent,
    /// A range sensor gives the distances.
    Measured,
}

impl Estimator {
    /// The name used in files and `summary.json`.
    pub fn as_str(self) -> &'static str {
        match self {
            Estimator::Shared => "shared",
            Estimator::PerAgent => "per_agent",
            Estimator::Measured => "measured",
        }
    }
}

/// How the bearing rates given to the controllers are obtained.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum BearingRate {
    /// Each agent differentiates its successive bearings (SPEC §2).
    #[default]
    FiniteDifference,
    /// The exact S2 rate from the true state (an ideal optical-flow sensor).
    Exact,
}
