//! `world`, `[plant]`, `[wind]`, `[heading]`, `[clock]`: each value in range, resolved
//! into the model's [`WorldModel`] (`docs/world.md`).

use super::checker::Checker;
use crate::model::{
    ClockModel, CrazyfliePid, HeadingModel, Mode, VehicleModel, VelocityTracking, WindModel,
    WorldModel,
};
use crate::scenario::error::ErrorKind::InvalidValue;
use crate::scenario::world::{plant_spec, preset, PlantSpec};
use crate::scenario::ScenarioFile;

/// Standard gravity (m/s²): a tilt limit θ gives `g tan θ` of horizontal acceleration.
pub const G: f64 = 9.806_65;

/// Checks the world's tables and resolves them; `period` is the control period (s).
pub(super) fn check(c: &mut Checker<'_>, s: &ScenarioFile, period: f64) -> WorldModel {
    let mut world = WorldModel::ideal();
    if let Some(name) = &s.world {
        world.preset = name.clone();
        // `Source::parse` merged the preset (and refused an unknown name).
        if let Some(p) = preset(name) {
            world.assumptions = p.assumptions.iter().map(|a| (*a).to_owned()).collect();
        }
    }
    match plant_spec(&s.plant) {
        Err((field, why)) => c.err(InvalidValue, &field, why),
        Ok(PlantSpec::PointMass {}) => {}
        Ok(PlantSpec::VelocityTracking {
            time_constant_s,
            max_tilt_deg,
            max_speed,
            lead_s,
            max_gap,
        }) => {
            c.positive(InvalidValue, "plant.time_constant_s", time_constant_s);
            c.positive(InvalidValue, "plant.max_speed", max_speed);
            if !(max_tilt_deg.is_finite() && max_tilt_deg > 0.0 && max_tilt_deg < 90.0) {
                c.err(
                    InvalidValue,
                    "plant.max_tilt_deg",
                    format!("must be above 0 and below 90 degrees, got {max_tilt_deg}"),
                );
            }
            let lead = lead_s.unwrap_or(time_constant_s);
            c.non_negative(InvalidValue, "plant.lead_s", lead);
            world.vehicle = VehicleModel::VelocityTracking(VelocityTracking {
                time_constant: time_constant_s,
                max_acceleration: G * max_tilt_deg.to_radians().tan(),
                max_speed,
                lead,
                max_gap: gap(c, max_gap, f64::INFINITY),
            });
        }
        Ok(PlantSpec::CrazyfliePid {
            max_speed,
            lead_s,
            second_lead_s2,
            jerk_filter_s,
            max_gap,
        }) => {
            let jerk_filter = jerk_filter_s.unwrap_or(crate::model::world::JERK_FILTER_S);
            c.non_negative(InvalidValue, "plant.jerk_filter_s", jerk_filter);
            c.positive(InvalidValue, "plant.max_speed", max_speed);
            if let Some(lead) = lead_s {
                c.non_negative(InvalidValue, "plant.lead_s", lead);
            }
            if let Some(second) = second_lead_s2 {
                c.non_negative(InvalidValue, "plant.second_lead_s2", second);
            }
            world.vehicle = VehicleModel::CrazyfliePid(CrazyfliePid {
                max_speed,
                lead: lead_s,
                second_lead: second_lead_s2,
                jerk_filter,
                max_gap: gap(c, max_gap, crate::model::world::MAX_GAP),
            });
        }
    }
    if let Some(w) = &s.wind {
        c.finite2("wind.mean", w.mean);
        c.non_negative(InvalidValue, "wind.gust", w.gust);
        c.positive(
            InvalidValue,
            "wind.gust_time_constant_s",
            w.gust_time_constant_s,
        );
        world.wind = Some(WindModel {
            mean: w.mean,
            gust: w.gust,
            gust_time_constant: w.gust_time_constant_s,
        });
    }
    if let Some(h) = &s.heading {
        if !h.initial_deg.is_finite() {
            c.err(
                InvalidValue,
                "heading.initial_deg",
                format!("must be finite, got {}", h.initial_deg),
            );
        }
        if !(h.spread_deg.is_finite() && (0.0..=180.0).contains(&h.spread_deg)) {
            c.err(
                InvalidValue,
                "heading.spread_deg",
                format!("must be between 0 and 180 degrees, got {}", h.spread_deg),
            );
        }
        c.non_negative(InvalidValue, "heading.error_deg", h.error_deg);
        c.non_negative(InvalidValue, "heading.drift_deg_per_s", h.drift_deg_per_s);
        c.non_negative(InvalidValue, "heading.noise_deg", h.noise_deg);
        world.heading = Some(HeadingModel {
            initial: h.initial_deg.to_radians(),
            spread: h.spread_deg.to_radians(),
            error: h.error_deg.to_radians(),
            drift: h.drift_deg_per_s.to_radians(),
            noise: h.noise_deg.to_radians(),
        });
    }
    if let Some(k) = &s.clock {
        c.non_negative(InvalidValue, "clock.offset_s", k.offset_s);
        if !(k.ppm.is_finite() && (0.0..=1e5).contains(&k.ppm)) {
            c.err(
                InvalidValue,
                "clock.ppm",
                format!(
                    "must be a finite number of ppm in [0, 100000], got {}",
                    k.ppm
                ),
            );
        }
        c.non_negative(InvalidValue, "clock.jitter_s", k.jitter_s);
        let m = ClockModel {
            offset: k.offset_s,
            ppm: k.ppm,
            jitter: k.jitter_s,
        };
        if k.jitter_s > 0.45 * period {
            c.err(
                InvalidValue,
                "clock.jitter_s",
                format!(
                    "{} s is more than 0.45 of the control period ({period} s): ticks would \
                     overtake each other",
                    k.jitter_s
                ),
            );
        }
        if !m.is_ideal() {
            world.clock = Some(m);
        }
    }
    if world.heading.is_some()
        && s.sensors.bearing_source == crate::scenario::settings::BearingSource::SharedPositions
    {
        c.err(
            InvalidValue,
            "heading",
            "bearings from shared positions are computed in the positioning system's frame, \
             not the body frame: remove [heading] (or use sensors.bearing_source = \"onboard\")",
        );
    }
    if s.mode == Mode::Continuous && !world.is_ideal() {
        c.err(
            InvalidValue,
            "mode",
            "continuous mode checks the paper's system (S1, one frame, one clock): \
             [plant] model = \"point_mass\" and no [wind], [heading] or [clock]; \
             use mode = \"sampled\" for the robot's world",
        );
    }
    world
}

/// `plant.max_gap` (m/s, SPEC S21c): above 0, `inf` for none; `default` when absent.
fn gap(c: &mut Checker<'_>, max_gap: Option<f64>, default: f64) -> f64 {
    let g = max_gap.unwrap_or(default);
    if g.is_nan() || g <= 0.0 {
        c.err(
            InvalidValue,
            "plant.max_gap",
            format!("must be above 0 (inf for none), got {g}"),
        );
    }
    g
}
