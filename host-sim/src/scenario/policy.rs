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
    /// Land when the battery (`[battery]`) reads below this (V; 0: off), for
    /// `battery_land_s`.
    #[serde(default)]
    pub battery_land_v: f64,
    /// For this long (s).
    #[serde(default = "default_battery_land")]
    pub battery_land_s: f64,
    /// The app's pre-flight check: the drone within this of its initial position (m;
    /// exported in the blob, not simulated).
    #[serde(default = "default_start_tolerance")]
    pub start_tolerance_m: f64,
}

fn default_start_tolerance() -> f64 {
    0.3
}

fn default_battery_land() -> f64 {
    2.0
}

/// `[battery]`: every vehicle's battery, discharging linearly in flight (docs/scenarios.md
/// "Safety policies"). Each field defaults to the Crazyflie 2.x's ([`Default`]).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct BatterySpec {
    /// Voltage at the start (V, under flight load).
    pub full_v: f64,
    /// Voltage after `flight_time_s` (V).
    pub empty_v: f64,
    /// Flight time from `full_v` to `empty_v` (s).
    pub flight_time_s: f64,
}

fn default_hold_timeout() -> f64 {
    2.0
}

impl Default for BatterySpec {
    /// A Crazyflie 2.x on its stock battery: 7 minutes of flight (Bitcraze's Crazyflie
    /// 2.1 specification) down to the firmware's critical voltage, 3.0 V
    /// (`DEFAULT_BAT_CRITICAL_LOW_VOLTAGE`, crazyflie-firmware
    /// src/platform/interface/platform_defaults_cf2.h:38), from 4.0 V under hover load
    /// (an assumption: a full LiPo's 4.2 V less the sag of the motors' current).
    fn default() -> Self {
        Self {
            full_v: 4.0,
            empty_v: 3.0,
            flight_time_s: 420.0,
        }
    }
}
