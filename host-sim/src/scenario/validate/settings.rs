//! The run-wide sections: duration, `[integration]`, `[controller]`, `[sensors]`,
//! `[radio]` and `[criteria]`.

use super::checker::{whole_steps, Checker, MAX_STEPS};
use crate::scenario::error::ErrorKind::{InvalidValue, NonPositiveGain};
use crate::scenario::ScenarioFile;

/// The timing and margins the later checks and the model need.
pub(super) struct Timing {
    /// RK4 step (s).
    pub dt: f64,
    /// RK4 steps per control tick.
    pub steps_per_tick: usize,
    /// RK4 steps per logged row.
    pub log_every: usize,
    /// The angle margin (rad).
    pub margin: f64,
    /// `radio.reorder_delay`, defaulted (s).
    pub reorder_delay: f64,
}

/// The largest bearing noise a scenario may declare (degrees): 0.5 rad, the tracker's
/// limit ([`ph_formation_core::TrackerConfig::is_valid`]).
pub(super) const MAX_BEARING_NOISE_DEG: f64 = 28.0;

/// `[sensors.tracker]`: each setting in the range the core accepts.
fn check_tracker(c: &mut Checker<'_>, t: &crate::scenario::settings::TrackerSpec) {
    let mut within = |field: &str, x: f64, lo: f64, hi: f64, open_lo: bool| {
        let low_ok = if open_lo { x > lo } else { x >= lo };
        if !(x.is_finite() && low_ok && x <= hi) {
            let lo_s = if open_lo { "above" } else { "at least" };
            c.err(
                InvalidValue,
                &format!("sensors.tracker.{field}"),
                format!("{x} is out of range: must be finite, {lo_s} {lo} and at most {hi}"),
            );
        }
    };
    if let Some(b) = t.bearing_noise_deg {
        within("bearing_noise_deg", b, 0.0, MAX_BEARING_NOISE_DEG, true);
    }
    within("rate_noise", t.rate_noise, 0.0, 100.0, false);
    within(
        "inverse_range_noise",
        t.inverse_range_noise,
        0.0,
        100.0,
        false,
    );
    within("gate", t.gate, 1.0, 1000.0, false);
}

/// Checks the run-wide sections.
pub(super) fn check(c: &mut Checker<'_>, s: &ScenarioFile) -> Timing {
    c.positive(InvalidValue, "duration", s.duration);
    c.positive(InvalidValue, "integration.dt", s.integration.dt);
    c.positive(
        InvalidValue,
        "integration.log_interval",
        s.integration.log_interval,
    );
    let ctl = &s.controller;
    c.positive(InvalidValue, "controller.rate_hz", ctl.rate_hz);
    let dt = s.integration.dt;
    let mut steps_per_tick = 1;
    let mut log_every = 1;
    if c.errors.is_empty() {
        match whole_steps(1.0 / ctl.rate_hz, dt) {
            Some(k) => steps_per_tick = k,
            None => c.err(
                InvalidValue,
                "controller.rate_hz",
                format!(
                    "the control period 1/{} s must be a whole number (≥ 1) of integration.dt = {dt} s",
                    ctl.rate_hz
                ),
            ),
        }
        match whole_steps(s.integration.log_interval, dt) {
            Some(k) => log_every = k,
            None => c.err(
                InvalidValue,
                "integration.log_interval",
                format!("must be a whole number (≥ 1) of integration.dt = {dt} s"),
            ),
        }
        if s.duration / dt > MAX_STEPS {
            c.err(
                InvalidValue,
                "integration.dt",
                format!(
                    "duration / dt = {:.3e} RK4 steps; at most {MAX_STEPS:e}",
                    s.duration / dt
                ),
            );
        } else if whole_steps(s.duration, dt).is_none() {
            c.err(
                InvalidValue,
                "duration",
                format!("must be a whole number of integration.dt = {dt} s"),
            );
        }
    }
    c.non_negative(
        InvalidValue,
        "controller.bearing_hold_s",
        ctl.bearing_hold_s,
    );
    c.positive(InvalidValue, "controller.min_estimate", ctl.min_estimate);
    c.positive(
        InvalidValue,
        "controller.initial_estimate",
        ctl.initial_estimate,
    );
    if ctl.initial_estimate < ctl.min_estimate {
        c.err(
            InvalidValue,
            "controller.initial_estimate",
            format!(
                "r̂(0) = {} is below controller.min_estimate = {}",
                ctl.initial_estimate, ctl.min_estimate
            ),
        );
    }
    c.positive(InvalidValue, "controller.max_force", ctl.max_force);
    c.positive(
        InvalidValue,
        "controller.neighbour_timeout",
        ctl.neighbour_timeout,
    );
    c.non_negative(NonPositiveGain, "controller.safe_damping", ctl.safe_damping);
    let margin_ok = ctl.angle_margin_deg.is_finite()
        && ctl.angle_margin_deg > 0.0
        && ctl.angle_margin_deg < 45.0;
    if !margin_ok {
        c.err(
            InvalidValue,
            "controller.angle_margin_deg",
            format!("must be in (0, 45) degrees, got {}", ctl.angle_margin_deg),
        );
    }
    let margin = if margin_ok {
        ctl.angle_margin_deg.to_radians()
    } else {
        5f64.to_radians()
    };

    // Sensors, radio, criteria.
    let se = &s.sensors;
    c.non_negative(
        InvalidValue,
        "sensors.bearing_noise_deg",
        se.bearing_noise_deg,
    );
    c.finite2("sensors.velocity_bias", se.velocity_bias);
    if !se.bearing_bias_deg.is_finite() {
        c.err(InvalidValue, "sensors.bearing_bias_deg", "must be finite");
    }
    if se.bearing_noise_deg > MAX_BEARING_NOISE_DEG {
        c.err(
            InvalidValue,
            "sensors.bearing_noise_deg",
            format!(
                "{} is not a bearing sensor: at most {MAX_BEARING_NOISE_DEG}°",
                se.bearing_noise_deg
            ),
        );
    }
    check_tracker(c, &se.tracker);
    c.non_negative(InvalidValue, "sensors.velocity_noise", se.velocity_noise);
    c.non_negative(InvalidValue, "sensors.offset_noise", se.offset_noise);
    c.non_negative(InvalidValue, "sensors.range_noise", se.range_noise);
    let ra = &s.radio;
    c.non_negative(InvalidValue, "radio.latency", ra.latency);
    c.non_negative(InvalidValue, "radio.jitter", ra.jitter);
    c.probability("radio.loss", ra.loss);
    c.probability("radio.duplication", ra.duplication);
    c.probability("radio.reordering", ra.reordering);
    c.probability("radio.corruption", ra.corruption);
    c.non_negative(InvalidValue, "radio.bandwidth_bps", ra.bandwidth_bps);
    c.non_negative(InvalidValue, "radio.queue_limit", ra.queue_limit);
    let period = dt * steps_per_tick as f64;
    let reorder_delay = ra.reorder_delay.unwrap_or(2.0 * period);
    c.non_negative(InvalidValue, "radio.reorder_delay", reorder_delay);
    let cr = &s.criteria;
    c.non_negative(
        InvalidValue,
        "criteria.collision_distance",
        cr.collision_distance,
    );
    c.positive(InvalidValue, "criteria.collapse_time", cr.collapse_time);
    c.positive(
        InvalidValue,
        "criteria.divergence_speed",
        cr.divergence_speed,
    );
    c.positive(
        InvalidValue,
        "criteria.divergence_energy_factor",
        cr.divergence_energy_factor,
    );
    c.positive(InvalidValue, "criteria.angle_tolerance", cr.angle_tolerance);
    c.positive(
        InvalidValue,
        "criteria.displacement_tolerance",
        cr.displacement_tolerance,
    );
    c.positive(
        InvalidValue,
        "criteria.velocity_tolerance",
        cr.velocity_tolerance,
    );
    c.positive(InvalidValue, "criteria.shape_tolerance", cr.shape_tolerance);
    c.non_negative(InvalidValue, "criteria.steady_window", cr.steady_window);
    if cr.steady_window > s.duration {
        c.err(
            InvalidValue,
            "criteria.steady_window",
            format!(
                "{} s is longer than the run (duration = {} s)",
                cr.steady_window, s.duration
            ),
        );
    }
    c.probability("criteria.safe_share", cr.safe_share);
    c.positive(InvalidValue, "criteria.angle_band_cap", cr.angle_band_cap);
    c.positive(InvalidValue, "criteria.scale_band_cap", cr.scale_band_cap);
    c.positive(
        InvalidValue,
        "criteria.velocity_band_cap",
        cr.velocity_band_cap,
    );
    Timing {
        dt,
        steps_per_tick,
        log_every,
        margin,
        reorder_delay,
    }
}
