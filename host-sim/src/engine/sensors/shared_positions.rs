//! Bearings from positions shared over the radio (`sensors.bearing_source =
//! "shared_positions"`, docs/sensors.md): the simulator's model of the Crazyflie app's
//! positioning-system flight (`crazyflie-app/src/formation.c`, docs/crazyflie.md).
//!
//! At every control tick `k`, before any agent is measured ([`SharedPositions::hear`]):
//!
//! 1. every position packet the radio delivered is taken out of its receiver's inbox (the
//!    controllers never see it, so their frame counters are those of the formation frames
//!    alone), and the receiver keeps the position and the time it heard it, for the sender
//!    among its radio neighbours whose wire id the packet carries;
//! 2. every agent's own position estimate is its true position plus white Gaussian noise
//!    `σ` per axis, drawn from its own stream of the tick (a stream of this sensor,
//!    independent of the bearing sensors'), rounded to `f32` as the packet carries it.
//!
//! Agent `i`'s bearing of neighbour `j` ([`BearingSensor::bearing`]) is S2's
//! `(q̂_j − q̂_i)/‖q̂_j − q̂_i‖` with `q̂_i` its own estimate and `q̂_j` the last position it
//! heard from `j`; none when it heard nothing from `j` or longer than `max_age` ago
//! (formation.c's `fresh`: `now − heard ≤ max_age`). The sensors' bearing rotation noise,
//! bias and range noise still apply on top ([`Draws::bearing`], zero by default). A
//! leader's partner offset is `q̂_p − q̂_i` the same way (plus the offset noise).
//!
//! After its tick each agent broadcasts its estimate through the radio
//! ([`SharedPositions::packet`]): the core's position packet
//! ([`ph_formation_core::wire::position`], the one the C API and the Crazyflie app use:
//! 13 bytes with `crc16`, 11 with `link`, 27 with `auth`), protected by the scenario's
//! integrity mode, a packet of its own on the radio model and the shared channel (loss,
//! latency, air time, collisions). It is told from a formation frame by its first byte
//! (the position packet's version, 2; a formation frame's mode byte is `0x80` or more;
//! the app sends it on a P2P port of its own). A receiver keeps only packets that decode
//! (CRC or tag, finite position) and, under `auth`, whose counter is above the last it
//! accepted from that sender: spoofed and replayed positions are refused
//! ([`SharedPositions::packets_refused`]).
//!
//! Everything is drawn from per-agent streams or from the radio's stream in agent order,
//! and the table is written only between ticks: a run gives the same bits on any number
//! of threads.

use super::source::{BearingKind, BearingSensor, World};
use super::{Draws, Sensors, Sight};
use crate::engine::radio::RadioFrame;
use crate::model::{Model, PositionsModel};
use ph_formation_core::wire::auth::Counter;
use ph_formation_core::wire::position::{accept_counter, PositionPacket, MAX_POSITION_LEN};
use ph_formation_core::{BearingMeasurement, Integrity, Vec2};

/// The first byte of a position packet: the core's layout version.
pub use ph_formation_core::wire::position::POSITION_VERSION;
/// Tag mixed into the run's seed for the position noise's streams (independent of the
/// sensors' and the radio's).
const POSITION_STREAM: u64 = 0x5053_4e00; // "PSN"
/// Tolerance on the age of a heard position (s).
const AGE_EPS: f64 = 1e-9;

/// One radio neighbour as a receiver knows it: its wire id, index, and the last
/// position heard from it with the time it was heard.
#[derive(Clone, Copy, Debug)]
struct Peer {
    id: u8,
    index: usize,
    heard: Option<(Vec2<f64>, f64)>,
    /// `auth`: the last counter accepted from it.
    counter: Option<Counter>,
}

/// Every agent's position estimate and the positions it heard.
#[derive(Debug)]
pub struct SharedPositions {
    model: PositionsModel,
    /// The position noise's per-agent streams (a [`Sensors`] of its own key).
    streams: Sensors,
    /// Every agent's wire id.
    ids: Vec<u8>,
    /// Each agent's own estimate of this tick (as broadcast).
    own: Vec<Vec2<f64>>,
    /// Each agent's radio neighbours and what it heard from them.
    peers: Vec<Vec<Peer>>,
    /// The time of this tick (s).
    now: f64,
    /// Position packets taken out of the inboxes (each a copy the radio delivered).
    heard: u64,
    /// Of those, the ones refused (bad CRC or tag, replayed, not finite, unknown sender).
    refused: u64,
    /// The packets' integrity (the formation frames').
    integrity: Integrity,
    /// Each agent's next `auth` counter (from 1).
    counters: Vec<Counter>,
}

impl SharedPositions {
    /// The shared positions of `model`'s agents, with `positions` its settings.
    pub fn new(model: &Model, positions: &PositionsModel) -> Self {
        let ids: Vec<u8> = model.agents.iter().map(|a| a.id).collect();
        let peers = (0..model.n())
            .map(|i| {
                let of = model.graph.radio.of(i);
                of.iter()
                    .map(|&j| Peer {
                        id: ids[j],
                        index: j,
                        heard: None,
                        counter: None,
                    })
                    .collect()
            })
            .collect();
        Self {
            model: positions.clone(),
            streams: Sensors::new(&model.sensors, model.seed ^ POSITION_STREAM),
            ids,
            own: vec![Vec2::zeros(); model.n()],
            peers,
            now: f64::NEG_INFINITY,
            heard: 0,
            refused: 0,
            integrity: model.integrity.core(&model.auth_key),
            counters: vec![1; model.n()],
        }
    }

    /// Step 1 and 2 of the module's list at time `now`, control tick `tick`, with the true
    /// positions `q`: the position packets leave `inboxes` for the table, and every
    /// agent's own estimate is drawn.
    pub fn hear(&mut self, now: f64, tick: u64, q: &[Vec2<f64>], inboxes: &mut [Vec<RadioFrame>]) {
        self.now = now;
        let integrity = &self.integrity;
        for (inbox, peers) in inboxes.iter_mut().zip(&mut self.peers) {
            inbox.retain(|f| {
                let b = f.as_bytes();
                if b.first() != Some(&POSITION_VERSION) {
                    return true;
                }
                self.heard += 1;
                let accepted = PositionPacket::decode(b, integrity)
                    .ok()
                    .and_then(|(p, c)| {
                        let peer = peers.iter_mut().find(|x| x.id == p.sender)?;
                        accept_counter(&mut peer.counter, c).then(|| {
                            let [x, y] = p.position.map(f64::from);
                            peer.heard = Some((Vec2::new(x, y), now));
                        })
                    });
                if accepted.is_none() {
                    self.refused += 1;
                }
                false
            });
        }
        let sigma = self.model.noise;
        for (i, (own, q)) in self.own.iter_mut().zip(q).enumerate() {
            let mut draws = self.streams.stream(i, tick);
            let noise = Vec2::new(draws.normal(sigma), draws.normal(sigma));
            *own = as_f32(&(q + noise));
        }
    }

    /// Agent `i`'s position packet of this tick: its estimate, tagged with its id, as
    /// the core encodes it (under `auth` with its next counter).
    pub fn packet(&mut self, i: usize) -> RadioFrame {
        let p = self.own.get(i).copied().unwrap_or_else(Vec2::zeros);
        let packet = PositionPacket {
            sender: self.ids.get(i).copied().unwrap_or(0),
            position: [p.x as f32, p.y as f32],
        };
        let counter = self.counters.get_mut(i).map_or(0, |c| {
            *c += 1;
            *c - 1
        });
        let mut bytes = [0u8; MAX_POSITION_LEN];
        // The buffer holds the longest packet: encode cannot fail.
        let len = packet
            .encode(&self.integrity, counter, &mut bytes)
            .unwrap_or(0);
        RadioFrame::checked(&bytes[..len], None)
    }

    /// Position packets refused so far (bad CRC or tag, replayed, not finite, or from
    /// an agent that is not a radio neighbour).
    pub fn packets_refused(&self) -> u64 {
        self.refused
    }

    /// Position packets taken out of the inboxes so far (link copies delivered).
    pub fn packets_heard(&self) -> u64 {
        self.heard
    }

    /// The position agent `i` last heard from agent `j`, if it is fresh (heard no more
    /// than `max_age` ago).
    fn fresh(&self, i: usize, j: usize) -> Option<Vec2<f64>> {
        let peer = self.peers.get(i)?.iter().find(|p| p.index == j)?;
        let (p, at) = peer.heard?;
        (self.now - at <= self.model.max_age + AGE_EPS).then_some(p)
    }
}

/// `p` rounded to `f32` per axis (what the packet and the app's `float`s hold).
fn as_f32(p: &Vec2<f64>) -> Vec2<f64> {
    Vec2::new(f64::from(p.x as f32), f64::from(p.y as f32))
}

impl BearingSensor for SharedPositions {
    fn prepare(&mut self, _world: &World<'_>) {}

    fn bearing(
        &self,
        world: &World<'_>,
        ids: &[u8],
        i: usize,
        j: usize,
        kind: BearingKind,
        draws: &mut Draws<'_>,
    ) -> Option<BearingMeasurement<f64>> {
        let other = self.fresh(i, j)?;
        // Coincident positions give no bearing: the core's one rule, as the app's.
        if (other - self.own[i]).norm() < ph_formation_core::policy::COINCIDENT {
            return None;
        }
        let sight = Sight {
            neighbour: ids[j],
            q_self: &self.own[i],
            q_other: &other,
            v_self: &world.v[i],
            v_other: &world.v[j],
        };
        // Validation refuses exact rates with shared positions.
        draws.bearing(&sight, false, kind.with_range)
    }

    fn partner_offset(
        &self,
        _world: &World<'_>,
        i: usize,
        p: usize,
        draws: &mut Draws<'_>,
    ) -> Option<Vec2<f64>> {
        let other = self.fresh(i, p)?;
        Some(draws.offset(&self.own[i], &other))
    }

    fn uses_radio(&self) -> bool {
        true
    }

    fn hear_radio(
        &mut self,
        now: f64,
        tick: u64,
        q: &[Vec2<f64>],
        inboxes: &mut [Vec<RadioFrame>],
    ) {
        self.hear(now, tick, q, inboxes);
    }

    fn radio_packet(&mut self, i: usize) -> Option<RadioFrame> {
        Some(self.packet(i))
    }
}
