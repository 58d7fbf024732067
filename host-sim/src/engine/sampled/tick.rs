//! One agent's tick, the one implementation for the sequential walk (`SampledSim`'s
//! `tick_sequential`) and the parallel one (`parallel.rs`): its measurements
//! ([`Scene::measure`], the bearings in its core's slot order), its inbox, its controller's
//! tick, and the copy of its estimates while its state is in cache.

use super::delivery::inbox;
use super::sensing::Scene;
use crate::engine::controller::AgentController;
use crate::engine::hil::HilError;
use crate::engine::radio::RadioFrame;
use crate::engine::slot_order::SlotOrder;
use crate::engine::speed::prefetch::{self, Footprint};
use crate::engine::world::Headings;
use crate::model::graph::Adjacency;
use ph_formation_core::{BearingMeasurement, Measurements, StepOutput, Vec2, MAX_NEIGHBOURS};

/// When one agent ticks: its clock's reading, the time since its previous tick by its
/// clock, and the index of its tick (of its random streams).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub(super) struct AgentTick {
    pub(super) time: f64,
    pub(super) dt: f64,
    pub(super) tick: u64,
}

/// What an agent's tick reads of the others (shared by every thread).
pub(super) struct Walk<'a> {
    /// This tick on the common clock (every agent's when the clocks are ideal).
    pub(super) at: AgentTick,
    /// Every agent's heading estimate, when the world has body frames.
    pub(super) headings: Option<&'a Headings>,
    /// The state and sensors, with this tick's index.
    pub(super) scene: Scene<'a>,
    pub(super) radio: &'a Adjacency,
    pub(super) slot_order: &'a SlotOrder,
    pub(super) sent: &'a [Vec<RadioFrame>],
    pub(super) footprints: &'a [Footprint],
    /// Each agent copies its estimates after its tick (`SampledSim`'s `viewed`).
    pub(super) copy_estimates: bool,
    /// The faults that change what an agent measures or reads on its clock
    /// (`[[faults]]`: clock jumps, outlier bursts); `None` without faults.
    pub(super) faults: Option<&'a super::faults::Faults>,
}

/// One agent's part of a tick: its controller, mailboxes, force and estimates.
pub(super) struct AgentSlots<'s> {
    pub(super) controller: &'s mut Box<dyn AgentController>,
    pub(super) inbox: &'s mut Vec<RadioFrame>,
    pub(super) outbox: &'s mut Vec<RadioFrame>,
    pub(super) force: &'s mut Vec2<f64>,
    pub(super) estimates: &'s mut [f64],
}

impl Walk<'_> {
    /// Starts agent `i`'s tick: its measurements, its inbox (what the radio delivered, or
    /// its radio neighbours' frames of the last tick), its controller's
    /// [`AgentController::start_tick`], and its estimates copied if the tick completed.
    /// Returns the output (`None`: a remote controller completes it later) and how many
    /// frames it read.
    pub(super) fn start(
        &self,
        i: usize,
        a: &mut AgentSlots<'_>,
        at: AgentTick,
    ) -> Result<(Option<StepOutput<f64>>, u64), HilError> {
        // The agents ahead in this walk are the next ones.
        prefetch_agent(self.footprints, self.sent, i + prefetch::AHEAD);
        // `SampledSim::with_controllers` refused a model with an agent of more than
        // MAX_NEIGHBOURS triangle neighbours: one bearing each fits.
        let mut bearings: heapless::Vec<BearingMeasurement<f64>, MAX_NEIGHBOURS> =
            heapless::Vec::new();
        let (mut velocity, mut partner_offset) = self.scene.measure(i, at.tick, |b| {
            let _ = bearings.push(b);
        });
        if let Some(h) = self.headings {
            // Measured in the body frame, turned into the agent's world frame through its
            // heading estimate: the world rotated by its error e_i (docs/world.md).
            let f = h.frames(i, at.time, at.tick);
            for b in &mut bearings {
                b.bearing = f.sensed(&b.bearing);
                b.rate = b.rate.map(|r| f.sensed(&r));
            }
            velocity = f.sensed(&velocity);
            partner_offset = partner_offset.map(|p| f.sensed(&p));
        }
        self.slot_order.apply(i, &mut bearings);
        // A clock jump moves the agent's reading (and, once, its interval); an outlier
        // burst turns its bearings (docs/faults.md).
        let (mut time, mut dt) = (at.time, at.dt);
        if let Some(f) = self.faults {
            f.freeze(
                i,
                at.time,
                &mut bearings,
                &mut velocity,
                &mut partner_offset,
            );
            let off = f.clock_offset(i, at.time);
            time += off;
            dt += off - f.clock_offset(i, at.time - at.dt);
            f.corrupt(i, at.time, at.tick, &mut bearings);
        }
        let m = Measurements {
            time,
            dt,
            velocity,
            bearings: &bearings,
            partner_offset,
        };
        a.outbox.clear();
        let frames = inbox(a.inbox, self.sent, self.radio, i);
        let delivered = frames.len() as u64;
        let out = a.controller.start_tick(frames, &m, a.outbox)?;
        if self.copy_estimates && out.is_some() {
            a.controller.read_estimates(a.estimates);
        }
        a.inbox.clear();
        Ok((out, delivered))
    }
}

/// Agent `i`'s force `U` of its tick `at` in the world frame: the agent commands it in
/// its estimated world frame, its body applies it in the true one (`R(−e_i) U`,
/// docs/world.md); unchanged without body frames.
#[inline]
pub(super) fn world_force(
    headings: Option<&Headings>,
    i: usize,
    at: &AgentTick,
    force: Vec2<f64>,
) -> Vec2<f64> {
    match headings {
        Some(h) => h.frames(i, at.time, at.tick).applied(&force),
        None => force,
    }
}

/// Prefetches what agent `i`'s tick will read: its controller and, with direct delivery,
/// its frames of the last tick (read by its radio neighbours, the first of which ticks
/// about when `i` does). Takes the parts it reads, not the simulator: the parallel walk
/// holds the controllers mutably.
#[inline]
fn prefetch_agent(footprints: &[Footprint], sent: &[Vec<RadioFrame>], i: usize) {
    if let Some(f) = footprints.get(i) {
        f.prefetch();
    }
    if let Some(frames) = sent.get(i) {
        prefetch::prefetch(frames.as_slice());
    }
}
