//! `[[attacks]]`: adversaries on the radio (`docs/attacks.md`).

use super::agents::lookup;
use super::checker::Checker;
use crate::model::{AttackKind, AttackModel};
use crate::scenario::error::ErrorKind::InvalidValue;
use crate::scenario::ScenarioFile;
use ph_formation_core::MAX_FRAME_LEN;
use std::collections::HashMap;

/// Checks every attacker; returns those that resolved.
pub(super) fn check(
    c: &mut Checker<'_>,
    s: &ScenarioFile,
    index: &HashMap<String, usize>,
) -> Vec<AttackModel> {
    let mut out = Vec::new();
    for (k, a) in s.attacks.iter().enumerate() {
        let field = |name: &str| format!("attacks[{k}].{name}");
        let end = a.end.unwrap_or(s.duration);
        c.non_negative(InvalidValue, &field("start"), a.start);
        if !(end.is_finite() && end > a.start) {
            c.err(
                InvalidValue,
                &field("end"),
                format!(
                    "must be a finite time after start = {} s, got {end}",
                    a.start
                ),
            );
        }
        if let Some(p) = a.position {
            c.finite2(&field("position"), p);
        }
        // Fields that belong to another kind are refused, so that a typo in `kind`
        // does not silently drop them.
        let foreign = |c: &mut Checker<'_>, name: &str, present: bool, kind: &str| {
            if present {
                c.err(
                    InvalidValue,
                    &field(name),
                    format!("only a `{kind}` attack has it (this one is `{}`)", a.kind),
                );
            }
        };
        let kind = match a.kind.as_str() {
            "replay" => {
                let delay = a.delay.unwrap_or(1.0);
                c.positive(InvalidValue, &field("delay"), delay);
                foreign(c, "victim", a.victim.is_some(), "forge");
                foreign(c, "gamma", a.gamma.is_some(), "forge");
                foreign(c, "velocity", a.velocity.is_some(), "forge");
                foreign(c, "rate_hz", a.rate_hz.is_some(), "flood");
                foreign(c, "bytes", a.bytes.is_some(), "flood");
                Some(AttackKind::Replay { delay })
            }
            "forge" => {
                foreign(c, "delay", a.delay.is_some(), "replay");
                foreign(c, "rate_hz", a.rate_hz.is_some(), "flood");
                foreign(c, "bytes", a.bytes.is_some(), "flood");
                let gamma = a.gamma.unwrap_or(5.0);
                if !gamma.is_finite() {
                    c.err(InvalidValue, &field("gamma"), "must be finite");
                }
                if let Some(v) = a.velocity {
                    c.finite2(&field("velocity"), v);
                }
                match &a.victim {
                    None => {
                        c.err(
                            InvalidValue,
                            &field("victim"),
                            "a `forge` attack needs the id of the agent whose frames it forges",
                        );
                        None
                    }
                    Some(id) => {
                        lookup(c, index, &field("victim"), id).map(|victim| AttackKind::Forge {
                            victim,
                            gamma,
                            velocity: a.velocity,
                        })
                    }
                }
            }
            "flood" => {
                foreign(c, "delay", a.delay.is_some(), "replay");
                foreign(c, "victim", a.victim.is_some(), "forge");
                foreign(c, "gamma", a.gamma.is_some(), "forge");
                foreign(c, "velocity", a.velocity.is_some(), "forge");
                let rate_hz = a.rate_hz.unwrap_or(1000.0);
                c.positive(InvalidValue, &field("rate_hz"), rate_hz);
                if rate_hz > 1e6 {
                    c.err(
                        InvalidValue,
                        &field("rate_hz"),
                        format!("at most 1e6 frames per second, got {rate_hz}"),
                    );
                }
                let bytes = a.bytes.unwrap_or(MAX_FRAME_LEN);
                if !(1..=MAX_FRAME_LEN).contains(&bytes) {
                    c.err(
                        InvalidValue,
                        &field("bytes"),
                        format!("must be 1 to {MAX_FRAME_LEN} (one radio frame), got {bytes}"),
                    );
                }
                Some(AttackKind::Flood { rate_hz, bytes })
            }
            other => {
                c.err(
                    InvalidValue,
                    &field("kind"),
                    format!("unknown attack `{other}`: expected `replay`, `forge` or `flood`"),
                );
                None
            }
        };
        if let Some(kind) = kind {
            out.push(AttackModel {
                kind,
                start: a.start,
                end,
                position: a.position,
            });
        }
    }
    out
}
