//! One agent's tick, the one implementation for the sequential walk (`SampledSim`'s
//! `tick_sequential`) and the parallel one (`parallel.rs`): its measurements
//! ([`Scene::measure`], the bearings in its core's slot order), its inbox, its controller's
//! tick, and the copy of its estimates while its state is in cache.

use super::{prefetch_agent, SampledSim, Scene};
use crate::engine::controller::AgentController;
use crate::engine::hil::HilError;
use crate::engine::radio::RadioFrame;
use crate::engine::slot_order::SlotOrder;
use crate::engine::speed::prefetch::{self, Footprint};
use crate::model::graph::Adjacency;
use controller_core::{BearingMeasurement, Measurements, StepOutput, Vec2, MAX_NEIGHBOURS};

/// What an agent's tick reads of the others (shared by every thread).
pub(super) struct Walk<'a> {
    pub(super) t: f64,
    pub(super) dt: f64,
    /// The state and sensors, with this tick's index.
    pub(super) scene: Scene<'a>,
    pub(super) radio: &'a Adjacency,
    pub(super) slot_order: &'a SlotOrder,
    pub(super) sent: &'a [Vec<RadioFrame>],
    pub(super) footprints: &'a [Footprint],
    /// Each agent copies its estimates after its tick ([`SampledSim`]'s `viewed`).
    pub(super) copy_estimates: bool,
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
    ) -> Result<(Option<StepOutput<f64>>, u64), HilError> {
        // The agents ahead in this walk are the next ones.
        prefetch_agent(self.footprints, self.sent, i + prefetch::AHEAD);
        // `SampledSim::with_controllers` refused a model with an agent of more than
        // MAX_NEIGHBOURS triangle neighbours: one bearing each fits.
        let mut bearings: heapless::Vec<BearingMeasurement<f64>, MAX_NEIGHBOURS> =
            heapless::Vec::new();
        let (velocity, partner_offset) = self.scene.measure(i, |b| {
            let _ = bearings.push(b);
        });
        self.slot_order.apply(i, &mut bearings);
        let m = Measurements {
            time: self.t,
            dt: self.dt,
            velocity,
            bearings: &bearings,
            partner_offset,
        };
        a.outbox.clear();
        let frames = SampledSim::inbox(a.inbox, self.sent, self.radio, i);
        let delivered = frames.len() as u64;
        let out = a.controller.start_tick(frames, &m, a.outbox)?;
        if self.copy_estimates && out.is_some() {
            a.controller.read_estimates(a.estimates);
        }
        a.inbox.clear();
        Ok((out, delivered))
    }
}
