//! Adversaries on the radio (`[[attacks]]`, `docs/attacks.md`): they overhear the
//! agents' broadcasts and inject frames of their own into the radio.
//!
//! * `replay`: every frame it overheard is re-broadcast, unchanged, `delay` seconds
//!   later to the receivers of its sender.
//! * `forge`: each broadcast of the victim is answered at once by a forged copy with the
//!   next sequence number (the victim's own next frame then looks like a replay to its
//!   neighbours), every angle item's `γ` replaced and optionally the velocity; the
//!   `crc16` trailer is recomputed (the CRC is public), an `auth` tag is kept as
//!   overheard (the attacker has no key).
//! * `flood`: random bytes, `rate_hz` frames per second; on a shared channel they occupy
//!   the medium from the attacker's position, otherwise every agent in reach receives
//!   them.
//!
//! Injected copies suffer the per-link faults of [`super::radio`] but do not take part in
//! the shared channel's collisions (only the flood's transmissions do). Deterministic:
//! its own random stream.

use super::radio::{Radio, RadioFrame};
use crate::model::{AttackKind, AttackModel, IntegrityMode, Model};
use ph_formation_core::wire::{offset, quant, ANGLE_ITEM_LEN, FIXED_LEN};
use ph_formation_core::{crc16, Vec2, MAX_FRAME_LEN};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use std::collections::VecDeque;

/// Random stream of the attackers (independent of the sensors', links' and channel's).
const ATTACK_STREAM: u64 = 4;
/// Most frames a replaying attacker keeps (the oldest are forgotten first).
const REPLAY_MEMORY: usize = 1 << 20;

/// Frames one attacker sent (each frame counted once, whatever its receivers).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct AttackCounts {
    /// Frames it overheard (replay and forge).
    pub overheard: u64,
    /// Frames it injected (replayed, forged or flooded).
    pub injected: u64,
}

/// One attacker and its memory.
#[derive(Debug)]
struct Attacker {
    model: AttackModel,
    /// `replay`: `(time overheard, sender, frame)`, oldest first.
    recorded: VecDeque<(f64, usize, RadioFrame)>,
    /// `flood`: frames owed (fractional).
    credit: f64,
    counts: AttackCounts,
}

/// Every attacker of a run.
#[derive(Debug)]
pub struct Attacks {
    list: Vec<Attacker>,
    rng: ChaCha8Rng,
    range: Option<f64>,
    integrity: IntegrityMode,
    /// Scratch: receivers of one injection.
    to: Vec<usize>,
}

impl Attacks {
    /// The attackers of `model` (none: nothing happens and nothing is drawn).
    pub fn new(model: &Model) -> Self {
        let mut rng = ChaCha8Rng::seed_from_u64(model.seed);
        rng.set_stream(ATTACK_STREAM);
        Self {
            list: model
                .attacks
                .iter()
                .map(|m| Attacker {
                    model: m.clone(),
                    recorded: VecDeque::new(),
                    credit: 0.0,
                    counts: AttackCounts::default(),
                })
                .collect(),
            rng,
            range: model.radio.channel.as_ref().and_then(|c| c.range),
            integrity: model.integrity,
            to: Vec::with_capacity(model.n()),
        }
    }

    /// Whether there is any attacker.
    pub fn is_empty(&self) -> bool {
        self.list.is_empty()
    }

    /// Frames each attacker overheard and injected, in `[[attacks]]` order.
    pub fn counts(&self) -> Vec<AttackCounts> {
        self.list.iter().map(|a| a.counts).collect()
    }

    /// Agent `from` (at `q[from]`) broadcast `bytes` at `t`: attackers in reach overhear
    /// it; a forger of `from` answers with its forgery.
    pub fn overhear(
        &mut self,
        t: f64,
        from: usize,
        bytes: &[u8],
        q: &[Vec2<f64>],
        model: &Model,
        radio: &mut Radio,
    ) {
        let range = self.range;
        for a in &mut self.list {
            if !a.model.active(t) || !reaches(range, a.model.position, q.get(from)) {
                continue;
            }
            match a.model.kind {
                AttackKind::Replay { .. } => {
                    a.counts.overheard += 1;
                    if a.recorded.len() == REPLAY_MEMORY {
                        a.recorded.pop_front();
                    }
                    a.recorded.push_back((t, from, RadioFrame::new(bytes)));
                }
                AttackKind::Forge {
                    victim,
                    gamma,
                    velocity,
                } if victim == from => {
                    a.counts.overheard += 1;
                    if let Some(forged) = forge(bytes, gamma, velocity, self.integrity) {
                        receivers(
                            &mut self.to,
                            range,
                            a.model.position,
                            model.graph.radio.of(from),
                            q,
                        );
                        radio.inject(t, &self.to, forged.as_bytes());
                        a.counts.injected += 1;
                    }
                }
                _ => {}
            }
        }
    }

    /// Control tick `t` (period `period`): replays what is due and floods.
    pub fn tick(&mut self, t: f64, period: f64, q: &[Vec2<f64>], model: &Model, radio: &mut Radio) {
        let range = self.range;
        for a in &mut self.list {
            match a.model.kind {
                AttackKind::Replay { delay } => {
                    while let Some(&(at, from, frame)) = a.recorded.front() {
                        if at > t - delay + 1e-9 {
                            break;
                        }
                        a.recorded.pop_front();
                        if !a.model.active(t) {
                            continue;
                        }
                        receivers(
                            &mut self.to,
                            range,
                            a.model.position,
                            model.graph.radio.of(from),
                            q,
                        );
                        radio.inject(t, &self.to, frame.as_bytes());
                        a.counts.injected += 1;
                    }
                }
                AttackKind::Flood { rate_hz, bytes } if a.model.active(t) => {
                    a.credit += rate_hz * period;
                    let owed = a.credit.floor();
                    a.credit -= owed;
                    let n = owed as usize;
                    for k in 0..n {
                        let mut junk = [0u8; MAX_FRAME_LEN];
                        let len = bytes.min(MAX_FRAME_LEN);
                        self.rng.fill(&mut junk[..len]);
                        // Spread evenly over the tick.
                        let at = t + period * k as f64 / n as f64;
                        if !radio.transmit_external(at, a.model.position, &junk[..len]) {
                            all_in_reach(&mut self.to, range, a.model.position, q);
                            radio.inject(at, &self.to, &junk[..len]);
                        }
                        a.counts.injected += 1;
                    }
                }
                _ => {}
            }
        }
    }
}

/// Whether an attacker at `at` and an agent at `agent` reach each other.
fn reaches(range: Option<f64>, at: Option<[f64; 2]>, agent: Option<&Vec2<f64>>) -> bool {
    match (range, at, agent) {
        (Some(r), Some(p), Some(q)) => (Vec2::new(p[0], p[1]) - q).norm() <= r,
        _ => true,
    }
}

/// The receivers among `candidates` that an attacker at `at` reaches, into `out`.
fn receivers(
    out: &mut Vec<usize>,
    range: Option<f64>,
    at: Option<[f64; 2]>,
    candidates: &[usize],
    q: &[Vec2<f64>],
) {
    out.clear();
    out.extend(
        candidates
            .iter()
            .copied()
            .filter(|&j| reaches(range, at, q.get(j))),
    );
}

/// Every agent an attacker at `at` reaches, into `out`.
fn all_in_reach(out: &mut Vec<usize>, range: Option<f64>, at: Option<[f64; 2]>, q: &[Vec2<f64>]) {
    out.clear();
    out.extend((0..q.len()).filter(|&j| reaches(range, at, q.get(j))));
}

/// The forgery of an overheard frame (`None` if it is too short to be one): sequence
/// number + 1, every angle item's `γ` = `gamma`, the velocity replaced if given, the
/// `crc16` trailer recomputed; any other trailer (an `auth` tag) kept as it was.
fn forge(
    bytes: &[u8],
    gamma: f64,
    velocity: Option<[f64; 2]>,
    integrity: IntegrityMode,
) -> Option<RadioFrame> {
    let mut f = [0u8; MAX_FRAME_LEN];
    let n = bytes.len().min(MAX_FRAME_LEN);
    f.get_mut(..n)?.copy_from_slice(bytes.get(..n)?);
    let trailer = match integrity {
        IntegrityMode::Crc16 => 2,
        _ => n.saturating_sub(FIXED_LEN) % ANGLE_ITEM_LEN,
    };
    let body = n.checked_sub(trailer)?;
    if body < FIXED_LEN {
        return None;
    }
    let seq = u16::from_le_bytes([*f.get(offset::SEQ)?, *f.get(offset::SEQ + 1)?]).wrapping_add(1);
    f.get_mut(offset::SEQ..offset::SEQ + 2)?
        .copy_from_slice(&seq.to_le_bytes());
    if let Some([vx, vy]) = velocity {
        f.get_mut(offset::VELOCITY..offset::VELOCITY + 4)?
            .copy_from_slice(&(vx as f32).to_le_bytes());
        f.get_mut(offset::VELOCITY + 4..offset::VELOCITY + 8)?
            .copy_from_slice(&(vy as f32).to_le_bytes());
    }
    let (code, _) = quant::encode(gamma as f32);
    let mut item = FIXED_LEN;
    while item + ANGLE_ITEM_LEN <= body {
        let g = item + offset::ITEM_GAMMA;
        f.get_mut(g..g + 2)?.copy_from_slice(&code.to_le_bytes());
        item += ANGLE_ITEM_LEN;
    }
    if integrity == IntegrityMode::Crc16 {
        let crc = crc16::checksum(f.get(..body)?);
        f.get_mut(body..body + 2)?
            .copy_from_slice(&crc.to_le_bytes());
    }
    Some(RadioFrame::new(f.get(..n)?))
}
