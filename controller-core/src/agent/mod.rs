//! The stateful controller of one agent.
//!
//! | file | what |
//! |---|---|
//! | `types.rs` | the public types of a tick: measurements, output, faults |
//! | `state.rs` | the internal state: angles and neighbours |
//! | `setup.rs` | [`Agent::new`]: configuration checks (SPEC §3) and the neighbour table |
//! | `sensing.rs` | `Agent::sense` (feature `sim`), sensing within [`Agent::step`]: own measurements, bearing rates (SPEC §2), the apex kernels (S4–S8) |
//! | `control.rs` | [`Agent::step`], `Agent::evaluate` (feature `sim`): far-vertex forces (S8), S9/S10, S11, S12, saturation |
//! | `estimates.rs` | owned estimates (S9, S10): reading, setting, integrating |
//! | `comm.rs` | [`Agent::frames`], [`Agent::receive`]; `Agent::receive_direct` (feature `sim`) |
//!
//! Who computes what, for an angle `α = (u; v, w)`: the apex `u` computes the angle from
//! its own bearings and rates when it senses (S4–S7), its own S8 force, and the efforts
//! its far vertices need (see [`crate::wire`]); it owns and integrates the shared
//! estimates (S9, S10). A far vertex turns the effort it last received into its S8 force
//! along its own fresh bearing to the apex.

mod comm;
mod control;
mod estimates;
mod sensing;
mod setup;
mod state;
#[cfg(test)]
mod test_support;
mod types;

#[cfg(any(feature = "sim", test))]
pub use types::Evaluation;
pub use types::{
    BearingMeasurement, Fault, LawOutput, MeasurementError, Measurements, OwnedEstimate, Status,
    StepOutput,
};

use crate::config::{AgentConfig, AgentId};
use crate::wire::FrameWriter;
use crate::{FrameStats, Real, Vec2};
use state::{AngleState, Neighbour};

/// The largest `MT` (triangles per agent) an [`Agent`] can index.
pub const MAX_MT: usize = u16::MAX as usize / 2;

/// One agent's controller: `MT` triangles at most, `NB` neighbours at most.
///
/// Per control tick: [`Agent::receive`] each frame heard since the last tick, then
/// [`Agent::step`] with the own measurements, then [`Agent::frames`] to broadcast.
/// Nothing here allocates or panics.
#[derive(Clone, Debug)]
pub struct Agent<T: Real, const MT: usize, const NB: usize> {
    config: AgentConfig<T, MT>,
    angles: heapless::Vec<[AngleState<T>; 2], MT>,
    neighbours: heapless::Vec<Neighbour<T, MT>, NB>,
    partner_slot: usize,
    time: T,
    velocity: Vec2<T>,
    partner_offset: Option<Vec2<T>>,
    /// The full counter of the next frame (see [`crate::wire::auth`]): the boot epoch in
    /// the high 32 bits, frames sent since boot in the low 32; the header carries its low
    /// 16 bits as the sequence number.
    counter: crate::wire::auth::StoredCounter,
    /// `auth`: broadcasts with only full frames (no room for the counter extension) until
    /// the next one that adds a sync frame.
    sync_countdown: u8,
    /// The largest neighbour age when last sensed (`None` after a frame arrived since, or
    /// when it is NaN): lets [`Agent::check_fresh`] skip its loop.
    oldest: Option<T>,
    /// Steps until the next broadcast (0: the last step broadcasts).
    comm_countdown: u16,
    /// [`Agent::frames`] broadcasts after the last step.
    comm_due: bool,
    /// Frame buffer reused by [`Agent::frames`] (no zeroing per tick).
    writer: FrameWriter,
    /// Smallest binary16 code of a received distance: `r_min` as rounded (estimator
    /// modes), or the smallest positive value (measured ranges).
    range_min_code: u16,
    /// The mode byte of this agent's frames (and of the frames it accepts).
    mode: u8,
    /// The neighbour slot after the sender of the last frame received: where
    /// [`Agent::receive`] looks for the next sender first (neighbours are usually heard
    /// in the same order every tick, so the look-up takes one comparison).
    next_slot: u8,
    stats: FrameStats,
}

impl<T: Real, const MT: usize, const NB: usize> Agent<T, MT, NB> {
    /// This agent's id.
    pub fn id(&self) -> AgentId {
        self.config.id
    }

    /// The configuration it was built with.
    pub fn config(&self) -> &AgentConfig<T, MT> {
        &self.config
    }

    /// Ids of all neighbours in slot order: the triangle neighbours in order of first
    /// appearance in the configuration (per triangle, per angle: apex, then the far
    /// vertices in vertex order), then the leader partner if it is not one of them.
    /// Bearings given to [`Agent::step`] in this order (a prefix of it) are taken in one
    /// pass; any other order gives the same result after a search per bearing.
    pub fn neighbours(&self) -> impl Iterator<Item = AgentId> + '_ {
        self.neighbours.iter().map(|n| n.id)
    }

    /// Counters of accepted and rejected frames.
    pub fn stats(&self) -> &FrameStats {
        &self.stats
    }

    /// The reset counters of the bearing trackers (SPEC §11a, S15c–S15d), per neighbour
    /// in slot order ([`Agent::neighbours`]): how many times each track restarted after
    /// its first bearing (a long interval, or agreeing outliers). Always 0 with the
    /// finite difference.
    pub fn track_resets(&self) -> impl Iterator<Item = (AgentId, u32)> + '_ {
        self.neighbours.iter().map(|n| (n.id, n.track.resets))
    }

    /// The bearing to `neighbour` the law uses this tick and its rate (measured, the finite
    /// difference of SPEC §2 or the tracker's of §11; held or predicted within
    /// [`crate::Limits::bearing_hold`] when none was measured, §12), if there is one.
    pub fn bearing(&self, neighbour: AgentId) -> Option<(Vec2<T>, Vec2<T>)> {
        self.neighbours
            .iter()
            .find(|n| n.id == neighbour)
            .and_then(|n| n.bearing().ok())
    }

    fn slot(&self, id: AgentId) -> Option<usize> {
        self.neighbours.iter().position(|n| n.id == id)
    }

    /// [`Agent::slot`] of a frame's sender: [`Agent::next_slot`] first, the search only
    /// if that is not it.
    #[inline(always)]
    fn sender_slot(&self, id: AgentId) -> Option<usize> {
        let hint = usize::from(self.next_slot);
        match self.neighbours.get(hint) {
            Some(n) if n.id == id => Some(hint),
            _ => self.slot(id),
        }
    }

    fn neighbour(&self, slot: usize) -> Result<&Neighbour<T, MT>, Fault> {
        self.neighbours.get(slot).ok_or(Fault::Internal)
    }

    /// Checks that every neighbour has been heard recently (or reports the stale one).
    fn check_fresh(&self) -> Result<(), Fault> {
        let timeout = self.config.limits.neighbour_timeout;
        // The oldest age found when sensing, if no frame arrived since: one comparison.
        if let Some(oldest) = self.oldest {
            if within(oldest, timeout) {
                return Ok(());
            }
        }
        for n in &self.neighbours {
            // Never heard: `age` is ∞.
            if !within(n.age, timeout) {
                return Err(Fault::Stale(n.id));
            }
        }
        Ok(())
    }
}

/// `age ≤ timeout` (false for NaN and for `∞`, "never").
#[inline(always)]
fn within<T: Real>(age: T, timeout: T) -> bool {
    age <= timeout
}

/// `[x, y]` as a vector.
fn vec2<T: Real>(a: [T; 2]) -> Vec2<T> {
    Vec2::new(a[0], a[1])
}

/// Both components finite: `(x − x) + (y − y)` is 0 exactly for finite `x`, `y` and NaN
/// otherwise (cheaper on the FPU than the bit tests of `is_finite`).
#[inline(always)]
#[allow(clippy::eq_op)] // `x − x` on purpose: NaN for NaN and ±∞.
fn finite_vec<T: Real>(v: &Vec2<T>) -> bool {
    (v.x - v.x) + (v.y - v.y) == T::zero()
}

/// `x[k]` for `k ∈ {0, 1}` (any other `k` reads index 1): panic-free pair indexing.
#[inline]
fn pick<X: Copy>(x: &[X; 2], k: usize) -> X {
    if k == 0 {
        x[0]
    } else {
        x[1]
    }
}
