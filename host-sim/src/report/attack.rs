//! The attackers' part of `summary.json` and of the summary table (only for scenarios
//! with `[[attacks]]`, so that other runs' outputs do not change): what each attacker
//! did, and why the agents rejected frames.

use crate::engine::FrameReasons;
use crate::engine::RunResult;
use crate::model::{AttackKind, Model};
use serde_json::{json, Map, Value};

/// The receivers' rejections by reason.
fn rejections(s: &FrameReasons) -> Value {
    json!({
        "bad_length": s.bad_length,
        "bad_crc": s.bad_crc,
        "unknown_version": s.unknown_version,
        "mode_mismatch": s.mode_mismatch,
        "malformed": s.malformed,
        "unknown_sender": s.unknown_sender,
        "stale_sequence": s.stale,
        "invalid_value": s.invalid_value,
        "bad_tag": s.bad_tag,
        "replayed": s.replayed,
        "unsynced": s.unsynced,
    })
}

/// Adds `attacks` (one entry per attacker) and `frames_rejected_by_reason` to
/// `summary.json`'s object, for scenarios with attackers.
pub(super) fn add_json(obj: &mut Map<String, Value>, m: &Model, r: &RunResult) {
    if m.attacks.is_empty() {
        return;
    }
    let id = |i: usize| {
        m.agents
            .get(i)
            .map_or(Value::Null, |a| super::summary::user_id(&a.name))
    };
    let list = m
        .attacks
        .iter()
        .zip(
            r.attacks
                .iter()
                .copied()
                .chain(std::iter::repeat(Default::default())),
        )
        .map(|(a, c)| {
            let mut e = json!({
                "kind": a.kind.as_str(),
                "start_s": a.start,
                "end_s": a.end,
                "position": a.position,
                "frames_overheard": c.overheard,
                "frames_injected": c.injected,
            });
            if let (Some(o), AttackKind::Forge { victim, gamma, .. }) = (e.as_object_mut(), &a.kind)
            {
                o.insert("victim".to_owned(), id(*victim));
                o.insert("gamma".to_owned(), json!(gamma));
            }
            e
        })
        .collect::<Vec<_>>();
    obj.insert("attacks".to_owned(), Value::Array(list));
    obj.insert(
        "frames_rejected_by_reason".to_owned(),
        rejections(&r.frames.by_reason),
    );
}

/// Rows of the summary table (none without attackers).
pub(super) fn rows(m: &Model, r: &RunResult) -> Vec<(&'static str, String)> {
    let mut rows = Vec::new();
    for (a, c) in m.attacks.iter().zip(&r.attacks) {
        rows.push((
            "attack",
            format!(
                "{} from {} s to {} s: {} frames injected ({} overheard)",
                a.kind.as_str(),
                a.start,
                a.end,
                c.injected,
                c.overheard
            ),
        ));
    }
    if !m.attacks.is_empty() {
        let s = &r.frames.by_reason;
        rows.push((
            "rejected frames",
            format!(
                "{} bad tag, {} replayed, {} unsynced, {} bad CRC, {} stale sequence, {} unknown sender, {} malformed/length, {} invalid value, {} mode mismatch",
                s.bad_tag,
                s.replayed,
                s.unsynced,
                s.bad_crc,
                s.stale,
                s.unknown_sender,
                s.malformed + s.bad_length + s.unknown_version,
                s.invalid_value,
                s.mode_mismatch
            ),
        ));
    }
    rows
}
