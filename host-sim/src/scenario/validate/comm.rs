//! `controller.comm_rate_hz` and `[radio.channel]`: how often agents broadcast and the
//! shared medium they broadcast on (`docs/radio.md`).

use super::checker::Checker;
use crate::model::channel::{CRAZYFLIE_BIT_RATE, CRAZYFLIE_OVERHEAD_BYTES, CRAZYFLIE_TURNAROUND};
use crate::model::{Access, ChannelModel, IntegrityMode};
use crate::scenario::error::ErrorKind::InvalidValue;
use crate::scenario::settings::CommRate;
use crate::scenario::ScenarioFile;
use ph_formation_core::MAX_FRAME_LEN;

/// Ticks per broadcast from `controller.comm_rate_hz` (1 when absent, `"auto"` or
/// invalid: the API resolves `"auto"` after validation, `engine::load::resolve_auto`).
pub(super) fn comm_every(c: &mut Checker<'_>, s: &ScenarioFile, period: f64) -> usize {
    let ctl = &s.controller;
    let Some(CommRate::Hz(comm)) = ctl.comm_rate_hz else {
        return 1;
    };
    let field = "controller.comm_rate_hz";
    if !(comm.is_finite() && comm > 0.0) {
        c.err(
            InvalidValue,
            field,
            format!("must be a finite number > 0, got {comm}"),
        );
        return 1;
    }
    if !(ctl.rate_hz.is_finite() && ctl.rate_hz > 0.0) {
        return 1; // reported with controller.rate_hz
    }
    let ratio = ctl.rate_hz / comm;
    let k = ratio.round();
    if comm > ctl.rate_hz * (1.0 + 1e-9) {
        c.err(
            InvalidValue,
            field,
            format!(
                "{comm} Hz exceeds controller.rate_hz = {} Hz (an agent broadcasts at most once per control tick)",
                ctl.rate_hz
            ),
        );
        return 1;
    }
    if (ratio - k).abs() > 1e-9 * ratio || k > f64::from(u16::MAX) {
        c.err(
            InvalidValue,
            field,
            format!(
                "controller.rate_hz = {} Hz must be a whole multiple (≤ 65535) of it; {comm} Hz gives {ratio}",
                ctl.rate_hz
            ),
        );
        return 1;
    }
    let k = k as usize;
    let comm_period = period * k as f64;
    if ctl.neighbour_timeout.is_finite() && ctl.neighbour_timeout <= comm_period {
        c.err(
            InvalidValue,
            "controller.neighbour_timeout",
            format!(
                "{} s must exceed the communication period 1/comm_rate_hz = {comm_period} s (every neighbour would time out between broadcasts)",
                ctl.neighbour_timeout
            ),
        );
    }
    k
}

/// The shared medium of `[radio.channel]`, if any; `period` is the control period (s).
pub(super) fn channel(c: &mut Checker<'_>, s: &ScenarioFile, period: f64) -> Option<ChannelModel> {
    let ch = s.radio.channel.as_ref()?;
    if s.radio.bandwidth_bps != 0.0 {
        c.err(
            InvalidValue,
            "radio.bandwidth_bps",
            "not used with [radio.channel] (the channel's bit rate limits the air time); remove one",
        );
    }
    let (mut bit_rate, mut overhead, mut turnaround) = (None, 0.0, 0.0);
    let preset = match ch.preset.as_deref() {
        None => "custom",
        Some("crazyflie") => {
            bit_rate = Some(CRAZYFLIE_BIT_RATE);
            overhead = CRAZYFLIE_OVERHEAD_BYTES;
            turnaround = CRAZYFLIE_TURNAROUND;
            "crazyflie"
        }
        Some(other) => {
            c.err(
                InvalidValue,
                "radio.channel.preset",
                format!("unknown preset `{other}`; the built-in one is `crazyflie`"),
            );
            "custom"
        }
    };
    let bit_rate = match ch.bit_rate_bps.or(bit_rate) {
        Some(b) => b,
        None => {
            c.err(
                InvalidValue,
                "radio.channel.bit_rate_bps",
                "required (bits per second) unless a preset gives it (preset = \"crazyflie\")",
            );
            return None;
        }
    };
    let mut m = ChannelModel {
        preset: preset.to_owned(),
        access: ch.access,
        bit_rate,
        overhead_bytes: ch.overhead_bytes.unwrap_or(overhead),
        turnaround: ch.turnaround.unwrap_or(turnaround),
        range: ch.range,
        aloha_window: ch.aloha_window.unwrap_or(period),
        slot: 0.0,
    };
    let errors = c.errors.len();
    c.positive(InvalidValue, "radio.channel.bit_rate_bps", m.bit_rate);
    c.non_negative(
        InvalidValue,
        "radio.channel.overhead_bytes",
        m.overhead_bytes,
    );
    c.non_negative(InvalidValue, "radio.channel.turnaround", m.turnaround);
    c.non_negative(InvalidValue, "radio.channel.aloha_window", m.aloha_window);
    if let Some(r) = m.range {
        c.positive(InvalidValue, "radio.channel.range", r);
    }
    if c.errors.len() > errors {
        return None;
    }
    let fits = m.turnaround + m.air_time(MAX_FRAME_LEN);
    m.slot = ch.slot.unwrap_or(fits);
    if !(m.slot.is_finite() && m.slot >= fits * (1.0 - 1e-12)) {
        c.err(
            InvalidValue,
            "radio.channel.slot",
            format!(
                "{} s is shorter than the turnaround plus the air time of a {MAX_FRAME_LEN}-byte frame ({fits:.3e} s)",
                m.slot
            ),
        );
        return None;
    }
    if m.access == Access::Tdma && ch.aloha_window.is_some() {
        c.err(
            InvalidValue,
            "radio.channel.aloha_window",
            "only used by access = \"aloha\"",
        );
    }
    if m.access == Access::Aloha && ch.slot.is_some() {
        c.err(
            InvalidValue,
            "radio.channel.slot",
            "only used by access = \"tdma\"",
        );
    }
    Some(m)
}

/// The swarm key of `controller.auth_key` (32 hexadecimal digits): required with
/// `integrity = "auth"`, refused with the other modes. Zero when absent or invalid.
pub(super) fn auth_key(c: &mut Checker<'_>, s: &ScenarioFile) -> [u8; 16] {
    let ctl = &s.controller;
    let field = "controller.auth_key";
    let mut key = [0u8; 16];
    match (ctl.integrity, &ctl.auth_key) {
        (IntegrityMode::Auth, None) => c.err(
            InvalidValue,
            field,
            "integrity = \"auth\" needs the swarm key: 32 hexadecimal digits (128 bits)",
        ),
        (IntegrityMode::Auth, Some(hex)) => {
            let digits: Vec<u8> = hex
                .chars()
                .filter_map(|ch| ch.to_digit(16).map(|d| d as u8))
                .collect();
            if digits.len() != 32 || hex.chars().count() != 32 {
                c.err(
                    InvalidValue,
                    field,
                    format!(
                        "must be exactly 32 hexadecimal digits (128 bits), got {} characters",
                        hex.chars().count()
                    ),
                );
            } else {
                for (k, pair) in digits.chunks(2).enumerate() {
                    if let (Some(b), [hi, lo]) = (key.get_mut(k), pair) {
                        *b = hi << 4 | lo;
                    }
                }
            }
        }
        (mode, Some(_)) => c.err(
            InvalidValue,
            field,
            format!(
                "only integrity = \"auth\" uses a key (this swarm's integrity is \"{}\")",
                mode.as_str()
            ),
        ),
        (_, None) => {}
    }
    key
}
