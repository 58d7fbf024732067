//! `summary.json`'s `world` key (`docs/world.md`): the vehicle, wind, headings and clocks
//! a run had, and which of their values are assumptions. Only when the world is not the
//! paper's, so that an ideal run's summary is what it always was.

use crate::model::{Model, VehicleModel};
use serde_json::{json, Map, Value};

/// Adds `world` to a summary object when the model's world is not ideal.
pub fn add_json(obj: &mut Map<String, Value>, model: &Model) {
    let w = &model.world;
    if w.is_ideal() && w.preset == "ideal" {
        return;
    }
    let vehicle = match &w.vehicle {
        VehicleModel::PointMass => json!({ "model": "point_mass" }),
        VehicleModel::VelocityTracking(v) => json!({
            "model": "velocity_tracking",
            "time_constant_s": v.time_constant,
            "max_acceleration_m_s2": v.max_acceleration,
            "max_speed_m_s": v.max_speed,
            "lead_s": v.lead,
            "max_gap_m_s": v.max_gap.is_finite().then_some(v.max_gap),
        }),
        VehicleModel::CrazyfliePid(v) => json!({
            "model": "crazyflie_pid",
            "max_speed_m_s": v.max_speed,
            "lead_s": v.lead.unwrap_or_else(crate::engine::plant::derived_lead),
            "second_lead_s2": v
                .second_lead
                .unwrap_or_else(crate::engine::plant::derived_second_lead),
            "jerk_filter_s": v.jerk_filter,
            "max_gap_m_s": v.max_gap.is_finite().then_some(v.max_gap),
        }),
    };
    let wind = w.wind.map(|x| {
        json!({
            "mean_m_s2": x.mean,
            "gust_m_s2": x.gust,
            "gust_time_constant_s": x.gust_time_constant,
        })
    });
    let heading = w.heading.map(|h| {
        json!({
            "initial_deg": h.initial.to_degrees(),
            "spread_deg": h.spread.to_degrees(),
            "error_deg": h.error.to_degrees(),
            "drift_deg_per_s": h.drift.to_degrees(),
            "noise_deg": h.noise.to_degrees(),
        })
    });
    let clock = w
        .clock
        .map(|c| json!({ "offset_s": c.offset, "ppm": c.ppm, "jitter_s": c.jitter }));
    obj.insert(
        "world".to_owned(),
        json!({
            "preset": w.preset,
            "plant": vehicle,
            "wind": wind,
            "heading": heading,
            "clock": clock,
            "assumptions": w.assumptions,
        }),
    );
}
