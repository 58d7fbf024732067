//! The channel's offered load before a run (`host-sim validate`, docs/radio.md "The
//! overload warning"): the simulator's first broadcasts, measured. The agents run 40
//! communication periods (the first 20 left out: frames grow as the neighbours' data
//! and the bearing tracker's state arrive) and the air time their frames and position
//! packets took in the last 20 is the load (the strip in the Crazyflie world: 54 %, as
//! over its whole run).

use super::channel::{ALOHA_LOAD_TARGET, TIMEOUT_BROADCASTS};
use super::sampled::SampledSim;
use super::simulator::Engine;
use crate::model::{Access, AutoRate, Mode, Model};

/// Communication periods left out, then measured (fewer read the strip's load low: 48 %
/// over periods 3 to 6).
const WARM: usize = 20;
const SPAN: usize = 20;

/// The offered load `G` (share of the air time) of `model`'s agents on its shared
/// channel, measured over communication periods 21 to 40 of a run. `None` without a
/// `[radio.channel]`, in continuous mode, or when the engine cannot be built (the run
/// reports that).
pub fn offered_load(model: &Model) -> Option<f64> {
    measure(model).map(|m| m.load)
}

/// What the first broadcasts of a run put on the channel.
#[derive(Clone, Copy, Debug)]
struct Measured {
    /// The air time of the transmissions (share of the time).
    load: f64,
    /// The share of the frames never put on the air: they would have waited longer than
    /// `radio.queue_limit` for the medium (with TDMA, for the agent's own slot).
    dropped: f64,
}

/// [`offered_load`] and the share of frames the access dropped, over the same periods.
fn measure(model: &Model) -> Option<Measured> {
    model.radio.channel.as_ref()?;
    if model.mode != Mode::Sampled {
        return None;
    }
    let mut sim = SampledSim::new(model).ok()?;
    let spt = model.steps_per_tick.max(1);
    let comm = spt * model.comm_every.max(1);
    let stats = |sim: &SampledSim<'_>| sim.channel_stats().unwrap_or_default();
    let mut before = stats(&sim);
    for k in 0..(WARM + SPAN) * comm {
        if k == WARM * comm {
            before = stats(&sim);
        }
        if sim.ticks_at(model, k) {
            sim.control(model.time(k));
        }
        sim.integrate(model.time(k));
    }
    let after = stats(&sim);
    let span = (SPAN * comm) as f64 * model.dt;
    let sent = after.transmissions - before.transmissions;
    let dropped = after.access_dropped - before.access_dropped;
    Some(Measured {
        load: (after.air_time - before.air_time) / span,
        dropped: if sent + dropped == 0 {
            0.0
        } else {
            dropped as f64 / (sent + dropped) as f64
        },
    })
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

/// The offered load the channel is taken to carry: [`ALOHA_LOAD_TARGET`] with ALOHA
/// (collisions), the whole air time with TDMA.
fn load_target(model: &Model) -> f64 {
    match model.radio.channel.as_ref().map(|c| c.access) {
        Some(Access::Aloha) => ALOHA_LOAD_TARGET,
        _ => 1.0,
    }
}

/// The most broadcasts per control tick `resolve_auto` slows to (`rate_hz / 64`).
const MAX_EVERY: usize = 64;

/// The share of frames the access may drop at the rate `resolve_auto` picks: 1 %, a
/// twentieth of the 5 % of safe outputs the verdict allows, since a dropped frame is
/// lost to every neighbour.
const MAX_DROPPED: f64 = 0.01;

/// Resolves `controller.comm_rate_hz = "auto"` (docs/radio.md): the highest rate
/// `rate_hz / k` (whole `k`) whose offered load, measured as [`offered_load`], stays at or
/// under the channel's target ([`ALOHA_LOAD_TARGET`] with ALOHA, the whole air time with
/// TDMA); every tick without a shared channel or in continuous mode. The timeouts that
/// must span several broadcasts (`controller.neighbour_timeout`, and where used
/// `sensors.positions.max_age_s` and `controller.bearing_hold_s`) are raised to
/// [`TIMEOUT_BROADCASTS`] broadcast periods when shorter. A model without `"auto"` is
/// returned as it is.
pub fn resolve_auto(mut model: Model) -> Model {
    let Some(mut auto) = model.comm_auto.take() else {
        return model;
    };
    let period = model.control_period();
    let target = load_target(&model);
    model.comm_every = 1;
    let first = measure(&model);
    auto.load_every_tick = first.map(|m| m.load);
    auto.load = auto.load_every_tick;
    auto.dropped = first.map(|m| m.dropped);
    let fits = |m: &Measured| m.load <= target && m.dropped <= MAX_DROPPED;
    if let Some(m) = first.filter(|m| !fits(m)) {
        // The load scales with the broadcast rate; measure again, since frames at a
        // lower rate carry what more ticks gathered (a few per cent). Frames the access
        // drops (TDMA: an agent's packets wait for its own slot) are not load: halve the
        // rate while they are.
        let mut k = ((m.load / target).ceil() as usize).clamp(2, MAX_EVERY);
        loop {
            model.comm_every = k;
            raise_timeouts(&mut model, &mut auto.raised);
            let m = measure(&model).unwrap_or(Measured {
                load: 0.0,
                dropped: 0.0,
            });
            auto.load = Some(m.load);
            auto.dropped = Some(m.dropped);
            if fits(&m) || k == MAX_EVERY {
                break;
            }
            k = if m.load > target {
                (k + 1).max((k as f64 * m.load / target).ceil() as usize)
            } else {
                2 * k
            }
            .min(MAX_EVERY);
        }
    }
    if model.comm_every > 1 {
        let broadcasts = timeout_broadcasts(&model, auto.load.unwrap_or(0.0));
        raise_timeouts_to(&mut model, &mut auto.raised, broadcasts);
    }
    auto.rate_hz = 1.0 / (period * model.comm_every as f64);
    model.comm_auto = Some(auto);
    model
}

/// Broadcast periods the timeouts span at offered load `load` (docs/radio.md
/// "comm_rate_hz = auto"): a link copy is lost with probability
/// `ℓ = 1 − (1 − radio.loss) e^{−2G}` (ALOHA; `1 − (1 − radio.loss)` with TDMA), and a
/// neighbour goes silent after `n` losses in a row; `n` is the smallest whole number, at
/// least 3, with `ℓⁿ` at most what three losses in a row give at ALOHA's target load with
/// no other loss (`(1 − e^{−0.2})³` = 0.6 %), plus the half period of the clocks'
/// phases: [`TIMEOUT_BROADCASTS`] = 3.5 without random loss, 4.5 at 10 %, 5.5 at 20 %.
fn timeout_broadcasts(model: &Model, load: f64) -> f64 {
    let aloha = model
        .radio
        .channel
        .as_ref()
        .is_some_and(|c| c.access == Access::Aloha);
    let access = if aloha { (-2.0 * load).exp() } else { 1.0 };
    let lost = 1.0 - (1.0 - model.radio.loss) * access;
    let reference = (1.0 - (-2.0 * ALOHA_LOAD_TARGET).exp()).powi(3);
    let mut n = TIMEOUT_BROADCASTS - 0.5;
    // `lost` < 1 (the validated loss is below 1); at most 64 losses in a row.
    while lost.powf(n) > reference * (1.0 + 1e-9) && n < 64.0 {
        n += 1.0;
    }
    n + 0.5
}

/// Raises the timeouts shorter than [`TIMEOUT_BROADCASTS`] broadcast periods to that,
/// recording each in `raised` (once, with its file value).
fn raise_timeouts(model: &mut Model, raised: &mut Vec<(&'static str, f64, f64)>) {
    raise_timeouts_to(model, raised, TIMEOUT_BROADCASTS);
}

/// Raises the timeouts shorter than `broadcasts` broadcast periods to that, recording
/// each in `raised` (once, with its file value).
fn raise_timeouts_to(
    model: &mut Model,
    raised: &mut Vec<(&'static str, f64, f64)>,
    broadcasts: f64,
) {
    let need = broadcasts * model.comm_period();
    let mut raise = |key: &'static str, value: &mut f64| {
        let from = raised.iter().find(|r| r.0 == key).map_or(*value, |r| r.1);
        if from < need {
            *value = need;
            raised.retain(|r| r.0 != key);
            raised.push((key, from, need));
        }
    };
    raise(
        "controller.neighbour_timeout",
        &mut model.limits.neighbour_timeout,
    );
    if model.limits.bearing_hold > 0.0 {
        raise("controller.bearing_hold_s", &mut model.limits.bearing_hold);
    }
    if let Some(p) = model.sensors.positions.as_mut() {
        raise("sensors.positions.max_age_s", &mut p.max_age);
    }
}

/// The run's note on a resolved `"auto"` rate: the rate, the loads and the raised
/// timeouts.
pub fn auto_note(auto: &AutoRate) -> String {
    let mut s = format!(
        "controller.comm_rate_hz = \"auto\" chose {:.4} Hz",
        auto.rate_hz
    );
    match (auto.load_every_tick, auto.load) {
        (Some(g1), Some(g)) if g1 != g => s += &format!(
            " (the agents offer {:.0} % of the shared channel's air time at every tick, {:.1} % at this rate)",
            100.0 * g1,
            100.0 * g
        ),
        (Some(g), _) => s += &format!(" (every tick: {:.1} % of the shared channel's air time)", 100.0 * g),
        _ => s += " (every tick: no shared channel)",
    }
    if let Some(d) = auto.dropped.filter(|&d| d > MAX_DROPPED) {
        s += &format!(
            "; even so the access drops {:.0} % of the frames (they wait longer than \
             radio.queue_limit for the medium; with TDMA an agent's packets of one \
             broadcast wait for its own slot: raise radio.channel.slot or \
             radio.queue_limit)",
            100.0 * d
        );
    }
    for (key, from, to) in &auto.raised {
        s += &format!("; {key} raised from {from} s to {to:.3} s");
    }
    s
}
