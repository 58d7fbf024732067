//! The communication part of `summary.json` and of the summary table: the broadcast
//! rate and integrity when not the defaults, the shared channel when there is one
//! (`docs/outputs.md`, `docs/radio.md`). Runs without them print nothing new.

use crate::engine::RunResult;
use crate::model::{IntegrityMode, Model};
use serde_json::{json, Map, Value};

fn fin(x: f64) -> Value {
    if x.is_finite() {
        json!(x)
    } else {
        Value::Null
    }
}

/// Adds `comm_period_s`, `integrity` and `channel` to `summary.json`'s object, each
/// only when it differs from the default (so other summaries keep their bytes).
pub(super) fn add_json(obj: &mut Map<String, Value>, m: &Model, r: &RunResult) {
    if m.comm_every != 1 {
        obj.insert("comm_period_s".to_owned(), fin(m.comm_period()));
        obj.insert("comm_every_ticks".to_owned(), json!(m.comm_every));
    }
    if m.integrity != IntegrityMode::Crc16 {
        obj.insert("integrity".to_owned(), json!(m.integrity.as_str()));
    }
    let (Some(c), Some(s)) = (&m.radio.channel, &r.channel) else {
        return;
    };
    let mut channel = json!({
            "preset": c.preset,
            "access": c.access.as_str(),
            "bit_rate_bps": fin(c.bit_rate),
            "overhead_bytes": fin(c.overhead_bytes),
            "turnaround_s": fin(c.turnaround),
            "range_m": c.range.map_or(Value::Null, fin),
            "aloha_window_s": fin(c.aloha_window),
            "slot_s": fin(c.slot),
            "superframe_s": fin(c.superframe(m.n())),
            "transmissions": s.transmissions,
            "air_time_s": fin(s.air_time),
            "utilisation": fin(s.utilisation(r.final_time)),
            "collided_copies": s.collided,
            "collided_transmissions": s.collided_transmissions,
            "out_of_range_copies": s.out_of_range,
            "access_dropped": s.access_dropped,
            "max_access_wait_s": fin(s.max_access_wait),
            "mean_neighbour_age_s": fin(s.mean_age),
            "max_neighbour_age_s": fin(s.max_age),
    });
    // Transmitters outside the swarm (a flood): only for scenarios with attackers, so
    // other summaries keep their bytes.
    if !m.attacks.is_empty() {
        if let Value::Object(ch) = &mut channel {
            ch.insert(
                "external_transmissions".to_owned(),
                json!(s.external_transmissions),
            );
            ch.insert("external_air_time_s".to_owned(), fin(s.external_air_time));
            ch.insert(
                "total_utilisation".to_owned(),
                fin(s.total_utilisation(r.final_time)),
            );
        }
    }
    obj.insert("channel".to_owned(), channel);
}

/// Rows of the summary table (none without a channel or a reduced broadcast rate).
pub(super) fn rows(m: &Model, r: &RunResult) -> Vec<(&'static str, String)> {
    let mut rows = Vec::new();
    if m.comm_every != 1 || m.integrity != IntegrityMode::Crc16 {
        rows.push((
            "broadcast",
            format!(
                "every {} tick(s) ({:.4} s), integrity {}",
                m.comm_every,
                m.comm_period(),
                m.integrity.as_str()
            ),
        ));
    }
    if let (Some(c), Some(s)) = (&m.radio.channel, &r.channel) {
        rows.push((
            "channel",
            format!(
                "{} ({}), {} bit/s, {} bytes overhead, {} µs turnaround{}",
                c.access.as_str(),
                c.preset,
                c.bit_rate,
                c.overhead_bytes,
                c.turnaround * 1e6,
                c.range.map_or(String::new(), |x| format!(", range {x} m"))
            ),
        ));
        rows.push((
            "air time / utilisation",
            format!(
                "{:.4} s / {:.2} %",
                s.air_time,
                100.0 * s.utilisation(r.final_time)
            ),
        ));
        if s.external_transmissions > 0 {
            rows.push((
                "outside transmitters",
                format!(
                    "{} frames, {:.4} s on the air; total utilisation {:.2} %",
                    s.external_transmissions,
                    s.external_air_time,
                    100.0 * s.total_utilisation(r.final_time)
                ),
            ));
        }
        rows.push((
            "lost to collisions",
            format!(
                "{} copies ({} of {} transmissions), {} out of range, {} not sent",
                s.collided,
                s.collided_transmissions,
                s.transmissions,
                s.out_of_range,
                s.access_dropped
            ),
        ));
        rows.push((
            "neighbour data age",
            format!(
                "mean {:.2} ms, worst {:.2} ms",
                1e3 * s.mean_age,
                1e3 * s.max_age
            ),
        ));
    }
    rows
}
