//! The statistics stage of [`super::SampledSim`]: the radio's and the controllers' frame
//! counters summed for a run's rows and summary ([`FrameCounts`]), and each tick's
//! controller output recorded ([`ControlStats`]).

use crate::engine::controller::AgentController;
use crate::engine::radio::Radio;
use crate::engine::stats::{ControlStats, FrameCounts, FrameReasons};
use ph_formation_core::StepOutput;

/// The frame counters of the radio and of every controller, summed.
pub(super) fn frame_counts(radio: &Radio, controllers: &[Box<dyn AgentController>]) -> FrameCounts {
    let r = radio.stats();
    let mut c = FrameCounts {
        broadcasts: r.broadcasts,
        sent: r.sent,
        dropped: r.dropped(),
        lost: r.lost,
        queue_dropped: r.queue_dropped,
        duplicated: r.duplicated,
        corrupted: r.corrupted,
        reordered: r.reordered,
        delivered: r.delivered,
        accepted: 0,
        rejected: 0,
        by_reason: FrameReasons::default(),
    };
    for ctl in controllers {
        let s = ctl.frame_stats();
        c.accepted += u64::from(s.accepted);
        c.rejected += u64::from(s.rejected());
        c.by_reason.add(&s);
    }
    c
}

/// Agent `i`'s output `out` of its tick at `t`, into `stats`.
#[inline]
pub(super) fn record(stats: &mut ControlStats, t: f64, i: usize, out: &StepOutput<f64>) {
    stats.record(
        t,
        i,
        out.status,
        out.saturated,
        out.degenerate,
        out.force.norm(),
    );
}
