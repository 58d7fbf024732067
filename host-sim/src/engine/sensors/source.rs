//! The seam for bearing sensors: where an agent's bearing of a neighbour comes from.
//!
//! Without a bearing sensor (`sensors.camera` absent) every neighbour's bearing is seen at
//! once, by the omnidirectional ideal sensor of [`Draws::bearing`] and
//! [`quiet_bearing`](super::quiet_bearing): the simulator's fast path, untouched. A
//! [`BearingSensor`] replaces it for every bearing of a run:
//!
//! 1. [`BearingSensor::prepare`] once per control tick, sequentially, before any agent is
//!    measured, with the true state ([`World`]): a sensor keeps what it needs (a history
//!    for a latency, a spatial index for occlusion).
//! 2. [`BearingSensor::bearing`] for each agent and each of its triangle neighbours in
//!    graph order, possibly on many threads at once (hence `&self`), drawing from the
//!    agent's own stream of the tick ([`Draws`]): a sensor that draws the same numbers in
//!    the same order for the same state gives the same bits on any number of threads.
//!
//! A bearing sensor whose data comes over the radio (the shared positions,
//! `shared_positions.rs`) says so ([`BearingSensor::uses_radio`]); the simulator then hands
//! it the delivered inboxes at every tick ([`BearingSensor::hear_radio`]) and broadcasts
//! each agent's packet after its frames ([`BearingSensor::radio_packet`]): the engine
//! knows the seam, not the sensor.
//!
//! A new bearing sensor is one file beside this one that implements the trait, and one
//! line in [`bearing_sensor`](super::bearing_sensor) (`sensors.rs`, the registry, beside its
//! `mod` line) that picks it from the [`SensorModel`] (docs/architecture.md,
//! "Add a sensor").

use super::Draws;
use crate::engine::radio::RadioFrame;
use ph_formation_core::{BearingMeasurement, Vec2};

/// The true state of every agent at a control tick, as a bearing sensor reads it (world
/// frame).
#[derive(Clone, Copy, Debug)]
pub struct World<'a> {
    /// Positions (m).
    pub q: &'a [Vec2<f64>],
    /// Velocities (m/s).
    pub v: &'a [Vec2<f64>],
    /// Each agent's true heading (rad, world frame, counter-clockwise from `x`).
    pub headings: &'a [f64],
}

/// What a bearing carries besides its direction (the run's settings).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct BearingKind {
    /// The exact S2 rate of the (seen) state (`sensors.bearing_rate = "exact"`).
    pub exact_rate: bool,
    /// The (noisy) distance (the `measured` estimator).
    pub with_range: bool,
}

/// A model of the sensor through which every agent sees its neighbours' bearings.
pub trait BearingSensor: Send + Sync + std::fmt::Debug {
    /// Takes in the true state of this control tick, before any agent is measured.
    fn prepare(&mut self, world: &World<'_>);

    /// Agent `i`'s bearing of neighbour `j` at this tick (tagged with `ids[j]`), `None`
    /// when it is not measured, drawing from `draws`, agent `i`'s stream of the tick.
    /// `world` is the state given to the last [`Self::prepare`].
    fn bearing(
        &self,
        world: &World<'_>,
        ids: &[u8],
        i: usize,
        j: usize,
        kind: BearingKind,
        draws: &mut Draws<'_>,
    ) -> Option<BearingMeasurement<f64>>;

    /// A leader `i`'s offset `q_p − q_i` of its partner `p` at this tick, drawn from
    /// `draws` after its bearings (`None`: not measured). By default the sensors' own
    /// offset of the true state ([`Draws::offset`]).
    fn partner_offset(
        &self,
        world: &World<'_>,
        i: usize,
        p: usize,
        draws: &mut Draws<'_>,
    ) -> Option<Vec2<f64>> {
        Some(draws.offset(&world.q[i], &world.q[p]))
    }

    /// Whether this sensor sends packets of its own over the radio
    /// ([`Self::radio_packet`]): every frame then goes through the radio's queue (no
    /// direct delivery, `sampled/delivery.rs`). By default, no.
    fn uses_radio(&self) -> bool {
        false
    }

    /// At control tick `tick` (time `now`, the true positions `q`), before any agent is
    /// measured and after the radio delivered what is due: takes this sensor's packets
    /// out of the receivers' `inboxes` (the controllers never see them). By default,
    /// nothing.
    fn hear_radio(
        &mut self,
        _now: f64,
        _tick: u64,
        _q: &[Vec2<f64>],
        _inboxes: &mut [Vec<RadioFrame>],
    ) {
    }

    /// Agent `i`'s packet of this tick, which the radio broadcasts to its radio
    /// neighbours after its frames (`None`: none; the default). `&mut`: a packet may
    /// advance the sender's state (an `auth` counter).
    fn radio_packet(&mut self, _i: usize) -> Option<RadioFrame> {
        None
    }
}
