//! `sensors.bearing_source` and `[sensors.positions]`: bearings from positions shared over
//! the radio, with each field in range, one bearing source only, and only where the
//! simulator models it (sampled mode, bearings without exact rates).

use super::checker::Checker;
use crate::model::{BearingRate, Mode, PositionsModel};
use crate::scenario::error::ErrorKind::InvalidValue;
use crate::scenario::settings::BearingSource;
use crate::scenario::ScenarioFile;
use ph_formation_core::wire::position::{position_len, MAX_POSITION_LEN};
use ph_formation_core::Integrity;

/// Checks the bearing source; the shared positions in SI units, or `None` with the
/// agents' own bearing sensor.
pub(super) fn check(c: &mut Checker<'_>, s: &ScenarioFile) -> Option<PositionsModel> {
    let se = &s.sensors;
    if se.bearing_source == BearingSource::Onboard {
        if se.positions.is_some() {
            c.err(
                InvalidValue,
                "sensors.positions",
                "has no effect without sensors.bearing_source = \"shared_positions\"",
            );
        }
        return None;
    }
    let p = se.positions.clone().unwrap_or_default();
    let f = |x: &str| format!("sensors.positions.{x}");
    c.non_negative(InvalidValue, &f("noise_m"), p.noise_m);
    c.positive(InvalidValue, &f("max_age_s"), p.max_age_s);
    if let Some(bytes) = p.packet_bytes {
        c.err(
            InvalidValue,
            &f("packet_bytes"),
            format!(
                "no longer set (got {bytes}): the packet is the core's position packet \
                 (docs/core.md \"Position packets\"), {} bytes with integrity = \"crc16\", \
                 {} with \"link\", {} with \"auth\"; remove the key",
                position_len(&Integrity::Crc16),
                position_len(&Integrity::Link),
                MAX_POSITION_LEN
            ),
        );
    }
    if se.camera.is_some() {
        c.err(
            InvalidValue,
            "sensors.camera",
            "one bearing source: bearing_source = \"shared_positions\" computes every \
             bearing from the shared positions; remove [sensors.camera] or the source",
        );
    }
    if se.bearing_rate == BearingRate::Exact {
        c.err(
            InvalidValue,
            "sensors.bearing_rate",
            "positions give no bearing rates: with bearing_source = \"shared_positions\" \
             use \"finite_difference\"",
        );
    }
    if s.mode == Mode::Continuous {
        c.err(
            InvalidValue,
            "sensors.bearing_source",
            "continuous mode measures every bearing ideally: shared positions need \
             mode = \"sampled\"",
        );
    }
    Some(PositionsModel {
        noise: p.noise_m,
        max_age: p.max_age_s,
    })
}
