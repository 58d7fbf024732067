//! `[policy]`: each value in range, resolved into the core's `PolicyConfig`.

use super::checker::Checker;
use crate::model::Mode;
use crate::scenario::error::ErrorKind::InvalidValue;
use crate::scenario::ScenarioFile;
use ph_formation_core::policy::PolicyConfig;

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
    #[allow(clippy::cast_possible_truncation, clippy::cast_sign_loss)] // checked above
    let hold_timeout_ms = hold_ms.clamp(0.0, f64::from(u32::MAX)) as u32;
    Some(PolicyConfig {
        hold_timeout_ms,
        fence,
        fence_min: lo,
        fence_max: hi,
        // The simulator has no battery.
        battery_land: 0.0,
        battery_ms: 0,
        min_separation: p.min_separation,
    })
}
