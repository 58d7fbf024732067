//! The boundary between the simulator and one agent's controller.
//!
//! The simulator gives a controller what the agent's own sensors measured and the frames
//! its radio received since the last tick; the controller returns a force and the frames
//! to broadcast. [`LocalCore`] runs a `controller-core` [`Agent`](controller_core::Agent)
//! in process; [`crate::engine::hil::controller::HilController`] runs it on an emulated target
//! behind a UART. Remote controllers answer in two phases ([`AgentController::start_tick`],
//! [`AgentController::finish_tick`]) so that several compute at once.

use crate::engine::hil::{HilError, LinkStats};
use crate::engine::radio::RadioFrame;
use crate::model::CoreAgent;
use controller_core::{FrameStats, Measurements, OwnedEstimate, StepOutput};

/// One agent's controller, as seen by the sampled simulator.
pub trait AgentController: Send {
    /// The agent's wire id.
    fn id(&self) -> u8;

    /// One control tick: consume `inbox` (frames received since the last tick, in arrival
    /// order), step with the agent's measurements `m`, append the frames to broadcast to
    /// `outbox`, and return the force command.
    fn tick(
        &mut self,
        inbox: &[RadioFrame],
        m: &Measurements<'_, f64>,
        outbox: &mut Vec<RadioFrame>,
    ) -> StepOutput<f64>;

    /// Where the estimates this controller owns belong (called once, at setup).
    fn estimate_layout(&self) -> Vec<OwnedEstimate<f64>>;

    /// Writes the current owned estimates into `out`, in [`Self::estimate_layout`] order
    /// (diagnostics only); returns how many were written.
    fn read_estimates(&self, out: &mut [f64]) -> usize;

    /// Counters of received frames.
    fn frame_stats(&self) -> FrameStats;

    /// First phase of a tick: like [`Self::tick`], but a remote controller only sends
    /// its inputs and returns `Ok(None)`; the simulator then collects the output with
    /// [`Self::finish_tick`] after starting every other agent's tick. The default runs
    /// the whole tick at once.
    fn start_tick(
        &mut self,
        inbox: &[RadioFrame],
        m: &Measurements<'_, f64>,
        outbox: &mut Vec<RadioFrame>,
    ) -> Result<Option<StepOutput<f64>>, HilError> {
        Ok(Some(self.tick(inbox, m, outbox)))
    }

    /// Second phase of a tick that [`Self::start_tick`] left pending: appends the frames
    /// to broadcast to `outbox` and returns the force command.
    fn finish_tick(&mut self, outbox: &mut Vec<RadioFrame>) -> Result<StepOutput<f64>, HilError> {
        let _ = outbox;
        Err(HilError::Usage(format!(
            "agent {}: finish_tick without a pending tick",
            self.id()
        )))
    }

    /// A failure kept by [`Self::tick`] (which cannot return one), if any.
    fn take_error(&mut self) -> Option<HilError> {
        None
    }

    /// End of the run (a remote controller says goodbye to its target).
    fn finish(&mut self) -> Result<(), HilError> {
        Ok(())
    }

    /// Link figures of a remote controller.
    fn link_stats(&self) -> Option<LinkStats> {
        None
    }
}

/// A `controller-core` agent running in the simulator's process.
#[derive(Clone, Debug)]
pub struct LocalCore {
    agent: CoreAgent,
}

impl LocalCore {
    /// Wraps a core agent.
    pub fn new(agent: CoreAgent) -> Self {
        Self { agent }
    }

    /// The wrapped agent.
    pub fn agent(&self) -> &CoreAgent {
        &self.agent
    }
}

impl AgentController for LocalCore {
    fn id(&self) -> u8 {
        self.agent.id()
    }

    fn tick(
        &mut self,
        inbox: &[RadioFrame],
        m: &Measurements<'_, f64>,
        outbox: &mut Vec<RadioFrame>,
    ) -> StepOutput<f64> {
        for f in inbox {
            // Rejections are counted in the agent's FrameStats.
            let _ = self.agent.receive(f.as_bytes());
        }
        let out = self.agent.step(m);
        self.agent
            .frames(|bytes| outbox.push(RadioFrame::new(bytes)));
        out
    }

    fn estimate_layout(&self) -> Vec<OwnedEstimate<f64>> {
        self.agent.owned_estimates().collect()
    }

    fn read_estimates(&self, out: &mut [f64]) -> usize {
        let mut n = 0;
        for (slot, e) in out.iter_mut().zip(self.agent.owned_estimates()) {
            *slot = e.value;
            n += 1;
        }
        n
    }

    fn frame_stats(&self) -> FrameStats {
        *self.agent.stats()
    }
}
