//! Counters of a run: frames through the radio and what the controllers did.

use ph_formation_core::FrameStats;

use crate::analysis::control::WindowCounts;
use crate::model::FaultModel;
use ph_formation_core::{Fault, Status};

/// Cumulative frame counters of a run (link copies; see `docs/outputs.md`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct FrameCounts {
    /// Frames produced by the controllers (each broadcast counted once).
    pub broadcasts: u64,
    /// Link copies sent (one per receiver per broadcast).
    pub sent: u64,
    /// Copies that never arrived (loss or transmit-queue overflow).
    pub dropped: u64,
    /// Copies lost at random.
    pub lost: u64,
    /// Copies dropped by a full transmit queue (bandwidth limit).
    pub queue_dropped: u64,
    /// Extra copies made by duplication.
    pub duplicated: u64,
    /// Copies with a flipped bit.
    pub corrupted: u64,
    /// Copies delayed for reordering.
    pub reordered: u64,
    /// Copies handed to receivers.
    pub delivered: u64,
    /// Delivered copies the receivers' cores accepted.
    pub accepted: u64,
    /// Delivered copies the receivers' cores rejected (CRC, stale sequence, …).
    pub rejected: u64,
    /// The receivers' cores' counters, summed: accepted and rejected by reason.
    pub by_reason: FrameReasons,
}

/// The receivers' cores' frame counters summed over the agents, in `u64` (each core
/// counts its own in `u32`, [`FrameStats`]; a sum over 100,000 agents would saturate).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct FrameReasons {
    /// Frames accepted.
    pub accepted: u64,
    /// Rejected: wrong length.
    pub bad_length: u64,
    /// Rejected: CRC mismatch.
    pub bad_crc: u64,
    /// Rejected: unknown wire version.
    pub unknown_version: u64,
    /// Rejected: another integrity or estimator mode.
    pub mode_mismatch: u64,
    /// Rejected: malformed body.
    pub malformed: u64,
    /// Rejected: a sender that is not a neighbour.
    pub unknown_sender: u64,
    /// Rejected: a stale sequence number.
    pub stale: u64,
    /// Rejected: a value out of range.
    pub invalid_value: u64,
    /// Rejected (`auth`): a wrong tag.
    pub bad_tag: u64,
    /// Rejected (`auth`): a replayed counter.
    pub replayed: u64,
    /// Rejected (`auth`): no counter known yet.
    pub unsynced: u64,
}

impl FrameReasons {
    /// Adds one core's counters.
    pub fn add(&mut self, b: &FrameStats) {
        let FrameStats {
            accepted,
            bad_length,
            bad_crc,
            unknown_version,
            mode_mismatch,
            malformed,
            unknown_sender,
            stale,
            invalid_value,
            bad_tag,
            replayed,
            unsynced,
        } = *b;
        self.accepted += u64::from(accepted);
        self.bad_length += u64::from(bad_length);
        self.bad_crc += u64::from(bad_crc);
        self.unknown_version += u64::from(unknown_version);
        self.mode_mismatch += u64::from(mode_mismatch);
        self.malformed += u64::from(malformed);
        self.unknown_sender += u64::from(unknown_sender);
        self.stale += u64::from(stale);
        self.invalid_value += u64::from(invalid_value);
        self.bad_tag += u64::from(bad_tag);
        self.replayed += u64::from(replayed);
        self.unsynced += u64::from(unsynced);
    }
}

/// What the controllers did over a run.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct ControlStats {
    /// Agent control ticks (sampled) or controller evaluations (continuous).
    pub ticks: u64,
    /// Of which produced the safe output.
    pub safe: u64,
    /// Safe outputs after `t = 0` (the first tick is always safe: nothing heard yet).
    pub safe_after_start: u64,
    /// Of which were saturated to `max_force`.
    pub saturated: u64,
    /// Of which reported a degenerate (near 0 or π) current angle.
    pub degenerate: u64,
    /// Largest commanded force norm.
    pub max_force: f64,
    /// The last fault after `t = 0`: time, agent index, fault.
    pub last_fault: Option<(f64, usize, Fault)>,
    /// Where the steady window starts (s; [`Self::with_window`]); 0 by default.
    pub window_from: f64,
    /// The outputs at or after `window_from`.
    pub window: WindowCounts,
    /// Time of the last output recorded (s).
    last_t: f64,
}

impl ControlStats {
    /// Counters whose window starts at `from` (s).
    pub fn with_window(from: f64) -> Self {
        Self {
            window_from: from,
            ..Self::default()
        }
    }

    /// Counts one controller output at time `t` of agent `i`.
    pub fn record(
        &mut self,
        t: f64,
        i: usize,
        status: Status,
        saturated: bool,
        degenerate: bool,
        force: f64,
    ) {
        self.ticks += 1;
        self.last_t = t;
        let in_window = t >= self.window_from;
        self.window.ticks += u64::from(in_window);
        if let Status::Safe(f) = status {
            self.safe += 1;
            if t > 0.0 {
                self.safe_after_start += 1;
                self.last_fault = Some((t, i, f));
                if in_window {
                    self.window.safe.add(i, f);
                }
            }
        }
        self.saturated += u64::from(saturated);
        self.degenerate += u64::from(degenerate);
        if force > self.max_force {
            self.max_force = force;
        }
    }

    /// Adds what was recorded in `later` (of outputs after these, as a parallel walk's
    /// part, all at one instant or recorded with this window): the same as recording them
    /// here, in order.
    pub fn merge(&mut self, later: &ControlStats) {
        self.ticks += later.ticks;
        self.safe += later.safe;
        self.safe_after_start += later.safe_after_start;
        self.saturated += later.saturated;
        self.degenerate += later.degenerate;
        // `>` as in `record`: NaN never enters, the maximum does not depend on the order.
        if later.max_force > self.max_force {
            self.max_force = later.max_force;
        }
        if later.last_fault.is_some() {
            self.last_fault = later.last_fault;
        }
        if later.ticks > 0 {
            // A part recorded with another window (a tick's per-agent sums, window 0)
            // belongs to this one when its instant does.
            if later.window_from == self.window_from || later.last_t >= self.window_from {
                self.window.ticks += later.window.ticks;
                self.window.safe.merge(&later.window.safe);
            }
            self.last_t = later.last_t;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use ph_formation_core::Fault;

    /// The window counts only outputs at or after its start, directly or through a
    /// tick's merged per-agent sums; the examples name each agent once, in order.
    #[test]
    fn window_counts_follow_the_instant() {
        let safe = |id| Status::Safe(Fault::MissingBearing(id));
        let mut direct = ControlStats::with_window(1.0);
        let mut merged = ControlStats::with_window(1.0);
        for (t, i) in [(0.5, 0), (1.0, 1), (1.0, 2), (1.5, 1)] {
            direct.record(t, i, safe(7), false, false, 0.0);
            let mut part = ControlStats::default();
            part.record(t, i, safe(7), false, false, 0.0);
            merged.merge(&part);
        }
        for s in [&direct, &merged] {
            assert_eq!(s.ticks, 4);
            assert_eq!(s.window.ticks, 3);
            assert_eq!(s.window.safe.total(), 3);
            assert_eq!(s.window.safe.counts[1], 3);
            let named: Vec<usize> = s
                .window
                .safe
                .examples
                .iter()
                .flatten()
                .map(|e| e.0)
                .collect();
            assert_eq!(named, [1, 2]);
        }
        assert_eq!(direct, merged);
    }
}

/// What the swarm did after one fault.
#[derive(Clone, Debug, PartialEq)]
pub struct FaultReport {
    /// The fault.
    pub fault: FaultModel,
    /// The agents (indices) that took their safe output while it acted or within 1 s
    /// after (after it struck, for a loss), with the time of their first safe tick.
    pub went_safe: Vec<(usize, f64)>,
    /// Of those, and of a rebooted agent, the ones whose control law ran again after
    /// the fault ended, with the time of their first nominal tick since.
    pub recovered: Vec<(usize, f64)>,
}

impl FaultReport {
    /// The fault and what the swarm did, in words, with the agents' scenario ids
    /// `names`: "reboot of agent 10 at 30 s for 2 s: agents 9, 11 went to their safe
    /// output (30.01–30.02 s); 9, 10, 11 came back (32.3–33.1 s)".
    pub fn note(&self, names: &[&str]) -> String {
        let f = &self.fault;
        let name = |i: usize| names.get(i).copied().unwrap_or("?").to_owned();
        let who = f.agent.map_or_else(
            || "every agent".to_owned(),
            |a| format!("agent {}", name(a)),
        );
        let mut s = format!("{} of {who} at {} s", f.kind.as_str(), f.t);
        if f.jump != 0.0 {
            s += &format!(" by {} s", f.jump);
        } else if f.end.is_finite() {
            // The duration as written (the subtraction's last bits dropped).
            s += &format!(" for {} s", ((f.end - f.t) * 1e9).round() / 1e9);
        }
        let list = |v: &[(usize, f64)]| {
            let ids: Vec<String> = v.iter().map(|(a, _)| name(*a)).collect();
            let lo = v.iter().map(|x| x.1).fold(f64::INFINITY, f64::min);
            let hi = v.iter().map(|x| x.1).fold(f64::NEG_INFINITY, f64::max);
            let span = if hi > lo {
                format!("{lo:.2}–{hi:.2} s")
            } else {
                format!("{lo:.2} s")
            };
            (ids.join(", "), span)
        };
        if self.went_safe.is_empty() {
            s += ": no agent went to its safe output";
        } else {
            let (ids, span) = list(&self.went_safe);
            s += &format!(": agents {ids} went to their safe output ({span})");
        }
        if self.recovered.is_empty() {
            if f.end.is_finite() && !self.went_safe.is_empty() {
                s += "; none came back to its control law";
            }
        } else {
            let (ids, span) = list(&self.recovered);
            s += &format!("; {ids} came back to the control law ({span})");
        }
        s
    }
}
