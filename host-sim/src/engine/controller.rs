//! The boundary between the simulator and one agent's controller.
//!
//! The simulator gives a controller what the agent's own sensors measured and the frames
//! its radio received since the last tick; the controller returns a force and the frames
//! to broadcast. [`LocalCore`] runs a `controller-core` [`Agent`]
//! in process; [`crate::engine::hil::controller::HilController`] runs it on an emulated target
//! behind a UART. Remote controllers answer in two phases ([`AgentController::start_tick`],
//! [`AgentController::finish_tick`]) so that several compute at once.

use crate::engine::hil::{HilError, LinkStats};
use crate::engine::radio::RadioFrame;
use crate::model::{Model, ModelError, MT, NB};
use ph_formation_core::{Agent, FrameStats, Measurements, OwnedEstimate, StepOutput};

/// The frames an agent takes in at one tick, in arrival order: what the radio delivered
/// to it, then (direct delivery, [`crate::engine::sampled::direct_radio`]) its radio
/// neighbours' broadcasts of the last tick in sender order, read where their senders
/// left them (no copy per receiver).
#[derive(Clone, Copy, Debug)]
pub struct Inbox<'a> {
    delivered: &'a [RadioFrame],
    senders: &'a [usize],
    sent: &'a [Vec<RadioFrame>],
}

impl<'a> Inbox<'a> {
    /// The frames the radio `delivered`.
    pub fn new(delivered: &'a [RadioFrame]) -> Self {
        Self {
            delivered,
            senders: &[],
            sent: &[],
        }
    }

    /// Then the frames `sent[j]` of every sender `j` in `senders`, in that order.
    pub fn with_sent(self, senders: &'a [usize], sent: &'a [Vec<RadioFrame>]) -> Self {
        Self {
            senders,
            sent,
            ..self
        }
    }

    /// Every frame, in arrival order.
    pub fn frames(&self) -> impl Iterator<Item = &'a RadioFrame> + 'a {
        let sent = self.sent;
        let direct = self.senders.iter().filter_map(move |&j| sent.get(j));
        self.delivered.iter().chain(direct.flatten())
    }

    /// The number of frames.
    pub fn len(&self) -> usize {
        let sent = self.sent;
        let direct: usize = self
            .senders
            .iter()
            .filter_map(|&j| sent.get(j).map(Vec::len))
            .sum();
        self.delivered.len() + direct
    }

    /// No frame.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }
}

/// One agent's controller, as seen by the sampled simulator.
pub trait AgentController: Send {
    /// The agent's wire id.
    fn id(&self) -> u8;

    /// One control tick: consume `inbox` (frames received since the last tick, in arrival
    /// order), step with the agent's measurements `m`, append the frames to broadcast to
    /// `outbox`, and return the force command.
    fn tick(
        &mut self,
        inbox: Inbox<'_>,
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

    /// The wire ids of the agent's neighbours in its core's slot order
    /// (`ph_formation_core::Agent::neighbours`), if known: the simulator hands it its
    /// bearings in that order. The default (`None`) keeps the measurement order.
    fn neighbour_order(&self) -> Option<Vec<u8>> {
        None
    }

    /// First phase of a tick: like [`Self::tick`], but a remote controller only sends
    /// its inputs and returns `Ok(None)`; the simulator then collects the output with
    /// [`Self::finish_tick`] after starting every other agent's tick. The default runs
    /// the whole tick at once.
    fn start_tick(
        &mut self,
        inbox: Inbox<'_>,
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

/// A `controller-core` agent running in the simulator's process, with capacity `M`
/// triangles and `N` neighbours (by default the core's standard capacity; [`local_core`]
/// picks the smallest that holds an agent).
#[derive(Clone, Debug)]
pub struct LocalCore<const M: usize = MT, const N: usize = NB> {
    agent: Agent<f64, M, N>,
}

impl<const M: usize, const N: usize> LocalCore<M, N> {
    /// Wraps a core agent.
    pub fn new(agent: Agent<f64, M, N>) -> Self {
        Self { agent }
    }

    /// The wrapped agent.
    pub fn agent(&self) -> &Agent<f64, M, N> {
        &self.agent
    }
}

/// The capacities (triangles, neighbours) of the in-process agents, smallest first; the
/// last is the core's standard capacity. An agent takes the smallest that holds it: a
/// strip's agent (3 triangles, 4 neighbours) is 2.6 KB instead of the standard 6 KB, which
/// is what a 100,000-agent run walks through every tick (`docs/performance.md`).
pub const LOCAL_CAPACITIES: [(usize, usize); 4] = [(2, 4), (3, 6), (6, 8), (MT, NB)];

/// Agent `i`'s in-process controller in the smallest of [`LOCAL_CAPACITIES`] that holds
/// its triangles and neighbours. Every capacity runs the same code on the same data, so
/// the choice never changes a result (`tests/scaling.rs`).
pub fn local_core(model: &Model, i: usize) -> Result<Box<dyn AgentController>, ModelError> {
    let triangles = model.triangles_of(i).count();
    // One arm per capacity (const generics need literal indices); a refusal (more
    // neighbours than the class holds) moves on to the next class.
    macro_rules! try_class {
        ($k:literal) => {
            if triangles <= LOCAL_CAPACITIES[$k].0 {
                const M: usize = LOCAL_CAPACITIES[$k].0;
                const N: usize = LOCAL_CAPACITIES[$k].1;
                if let Ok(a) = model.core_agent_in::<M, N>(i) {
                    return Ok(Box::new(LocalCore::new(a)));
                }
            }
        };
    }
    try_class!(0);
    try_class!(1);
    try_class!(2);
    Ok(Box::new(LocalCore::new(model.core_agent(i)?)))
}

impl<const M: usize, const N: usize> AgentController for LocalCore<M, N> {
    fn id(&self) -> u8 {
        self.agent.id()
    }

    fn tick(
        &mut self,
        inbox: Inbox<'_>,
        m: &Measurements<'_, f64>,
        outbox: &mut Vec<RadioFrame>,
    ) -> StepOutput<f64> {
        for f in inbox.frames() {
            // Rejections are counted in the agent's FrameStats. The frame's CRC was
            // checked once for all its receivers (the same result as `receive`).
            let _ = self.agent.receive_checked(f.as_bytes(), f.crc_check());
        }
        let out = self.agent.step(m);
        // Each frame with its CRC check from the writer (no second CRC per broadcast).
        self.agent
            .frames_checked(|bytes, check| outbox.push(RadioFrame::checked(bytes, check)));
        out
    }

    fn estimate_layout(&self) -> Vec<OwnedEstimate<f64>> {
        self.agent.owned_estimates().collect()
    }

    fn read_estimates(&self, out: &mut [f64]) -> usize {
        self.agent.copy_estimates(out)
    }

    fn frame_stats(&self) -> FrameStats {
        *self.agent.stats()
    }

    fn neighbour_order(&self) -> Option<Vec<u8>> {
        Some(self.agent.neighbours().collect())
    }
}
