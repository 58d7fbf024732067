//! The channel's offered load before a run (`host-sim validate`, docs/radio.md "The
//! overload warning"): the simulator's first broadcasts, measured. The agents run 40
//! communication periods (the first 20 left out: frames grow as the neighbours' data
//! and the bearing tracker's state arrive) and the air time their frames and position
//! packets took in the last 20 is the load (the strip in the Crazyflie world: 54 %, as
//! over its whole run).

use super::channel::{ALOHA_LOAD_TARGET, TIMEOUT_BROADCASTS};
use super::sampled::SampledSim;
use super::simulator::Engine;
use crate::model::{Access, Mode, Model};

/// Communication periods left out, then measured (fewer read the strip's load low: 48 %
/// over periods 3 to 6).
const WARM: usize = 20;
const SPAN: usize = 20;

/// The offered load `G` (share of the air time) of `model`'s agents on its shared
/// channel, measured over communication periods 21 to 40 of a run. `None` without a
/// `[radio.channel]`, in continuous mode, or when the engine cannot be built (the run
/// reports that).
pub fn offered_load(model: &Model) -> Option<f64> {
    model.radio.channel.as_ref()?;
    if model.mode != Mode::Sampled {
        return None;
    }
    let mut sim = SampledSim::new(model).ok()?;
    let spt = model.steps_per_tick.max(1);
    let comm = spt * model.comm_every.max(1);
    let air = |sim: &SampledSim<'_>| sim.channel_stats().map_or(0.0, |c| c.air_time);
    let mut before = 0.0;
    for k in 0..(WARM + SPAN) * comm {
        if k == WARM * comm {
            before = air(&sim);
        }
        if sim.ticks_at(model, k) {
            sim.control(model.time(k));
        }
        sim.integrate(model.time(k));
    }
    let span = (SPAN * comm) as f64 * model.dt;
    Some((air(&sim) - before) / span)
}

/// The warning of `host-sim validate` when the offered load is more than the channel
/// carries (any access) or, with ALOHA, more than [`ALOHA_LOAD_TARGET`]: the load and the
/// communication rate and timeouts that fit (as the run's `collision_note`).
pub fn overload_warning(model: &Model) -> Option<String> {
    let load = offered_load(model)?;
    let aloha = model
        .radio
        .channel
        .as_ref()
        .is_some_and(|c| c.access == Access::Aloha);
    let target = if aloha { ALOHA_LOAD_TARGET } else { 1.0 };
    if load <= target {
        return None;
    }
    let period = model.dt * model.steps_per_tick as f64;
    let rate = 1.0 / (period * model.comm_every.max(1) as f64 * (load / target).ceil());
    Some(format!(
        "the agents offer {:.0} % of the shared channel's air time ({}): \
         controller.comm_rate_hz = {rate} brings it to {:.0} % or less, with \
         controller.neighbour_timeout (and, as used, sensors.positions.max_age_s and \
         controller.bearing_hold_s) of {:.3} s or more (docs/radio.md)",
        100.0 * load,
        if aloha {
            "ALOHA loses a transmission with probability 1 − e^(−2G)"
        } else {
            "more than it carries"
        },
        100.0 * target,
        TIMEOUT_BROADCASTS / rate
    ))
}
