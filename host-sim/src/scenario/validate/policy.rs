//! `[policy]`: each value in range, resolved into the core's `PolicyConfig`.

use super::checker::Checker;
use crate::model::{BatteryModel, Mode};
use crate::scenario::error::ErrorKind::InvalidValue;
use crate::scenario::ScenarioFile;
use ph_formation_core::policy::PolicyConfig;

/// `[battery]`, if the scenario has one: full above empty above 0, a positive flight
/// time.
pub(super) fn battery(c: &mut Checker<'_>, s: &ScenarioFile) -> Option<BatteryModel> {
    let b = s.battery.as_ref()?;
    c.positive(InvalidValue, "battery.empty_v", b.empty_v);
    c.positive(InvalidValue, "battery.flight_time_s", b.flight_time_s);
    if !(b.full_v.is_finite() && b.full_v > b.empty_v) {
        c.err(
            InvalidValue,
            "battery.full_v",
            format!(
                "must be a finite voltage above empty_v = {} V, got {}",
                b.empty_v, b.full_v
            ),
        );
    }
    Some(BatteryModel {
        full: b.full_v,
        empty: b.empty_v,
        flight_time: b.flight_time_s,
    })
}

/// The policies of `s`, if it has a `[policy]` table.
pub(super) fn check(c: &mut Checker<'_>, s: &ScenarioFile) -> Option<PolicyConfig<f64>> {
    let p = s.policy.as_ref()?;
    if s.mode != Mode::Sampled {
        c.err(
            InvalidValue,
            "policy",
            "the safety policies run at the control ticks: needs mode = \"sampled\"",
        );
    }
    c.non_negative(InvalidValue, "policy.hold_timeout_s", p.hold_timeout_s);
    c.non_negative(InvalidValue, "policy.min_separation", p.min_separation);
    let hold_ms = (p.hold_timeout_s * 1000.0).round();
    // NaN was reported by non_negative above.
    if hold_ms > f64::from(u32::MAX) {
        c.err(
            InvalidValue,
            "policy.hold_timeout_s",
            format!("must be at most 4294967 s, got {}", p.hold_timeout_s),
        );
    }
    let (fence, lo, hi) = match (p.fence_min, p.fence_max) {
        (None, None) => (false, [0.0; 2], [0.0; 2]),
        (Some(lo), Some(hi)) => {
            c.finite2("policy.fence_min", lo);
            c.finite2("policy.fence_max", hi);
            if !(lo[0] <= hi[0] && lo[1] <= hi[1]) {
                c.err(
                    InvalidValue,
                    "policy.fence_max",
                    format!("must be at least fence_min on both axes, got {hi:?} < {lo:?}"),
                );
            }
            (true, lo, hi)
        }
        (Some(_), None) | (None, Some(_)) => {
            c.err(
                InvalidValue,
                "policy.fence_min",
                "the fence needs both fence_min and fence_max",
            );
            (false, [0.0; 2], [0.0; 2])
        }
    };
    c.non_negative(InvalidValue, "policy.battery_land_v", p.battery_land_v);
    c.positive(
        InvalidValue,
        "policy.start_tolerance_m",
        p.start_tolerance_m,
    );
    c.non_negative(InvalidValue, "policy.battery_land_s", p.battery_land_s);
    let battery_ms = (p.battery_land_s * 1000.0).round();
    if battery_ms > f64::from(u32::MAX) {
        c.err(
            InvalidValue,
            "policy.battery_land_s",
            format!("must be at most 4294967 s, got {}", p.battery_land_s),
        );
    }
    if p.battery_land_v > 0.0 && s.battery.is_none() {
        c.err(
            InvalidValue,
            "policy.battery_land_v",
            "the low-battery landing reads the battery's voltage: add a [battery] table \
             (or world = \"crazyflie\", which has one), or set battery_land_v = 0",
        );
    }
    #[allow(clippy::cast_possible_truncation, clippy::cast_sign_loss)] // checked above
    let hold_timeout_ms = hold_ms.clamp(0.0, f64::from(u32::MAX)) as u32;
    #[allow(clippy::cast_possible_truncation, clippy::cast_sign_loss)] // checked above
    let battery_ms = battery_ms.clamp(0.0, f64::from(u32::MAX)) as u32;
    Some(PolicyConfig {
        hold_timeout_ms,
        fence,
        fence_min: lo,
        fence_max: hi,
        battery_land: p.battery_land_v,
        battery_ms,
        min_separation: p.min_separation,
    })
}
