//! The controllers' outputs as the verdict reads them: safe outputs in the steady window
//! by cause, and the first agents that gave them (counted by the engine, judged by
//! [`super::Monitor::verdict`]).

use ph_formation_core::Fault;

/// How many kinds of [`Fault`] [`FaultTally`] tells apart.
pub const FAULT_KINDS: usize = 8;
/// How many agents [`FaultTally`] names.
pub const FAULT_EXAMPLES: usize = 8;

/// One fault of each kind, in [`fault_kind`]'s order (for words and keys by kind).
pub const FAULT_SAMPLES: [Fault; FAULT_KINDS] = [
    Fault::Measurement(ph_formation_core::MeasurementError::NonFinite),
    Fault::MissingBearing(0),
    Fault::Stale(0),
    Fault::MissingData(0),
    Fault::MissingPartnerOffset,
    Fault::MissingRange(0),
    Fault::NonFinite,
    Fault::Internal,
];

/// The kind of a fault, `0..FAULT_KINDS`, and its name in words.
pub fn fault_kind(f: &Fault) -> (usize, &'static str) {
    match f {
        Fault::Measurement(_) => (0, "measurements refused"),
        Fault::MissingBearing(_) => (1, "bearings missing"),
        Fault::Stale(_) => (2, "a neighbour silent"),
        Fault::MissingData(_) => (3, "a neighbour's frames lacking data"),
        Fault::MissingPartnerOffset => (4, "the leader partner's offset missing"),
        Fault::MissingRange(_) => (5, "ranges missing"),
        Fault::NonFinite => (6, "a non-finite force"),
        Fault::Internal => (7, "an internal inconsistency"),
    }
}

/// Safe outputs by the fault that caused them, and the first agents that gave them.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct FaultTally {
    /// Safe outputs per fault kind ([`fault_kind`]).
    pub counts: [u64; FAULT_KINDS],
    /// The first distinct agents (index) in safe output, in the order of their first
    /// safe output, each with that fault.
    pub examples: [Option<(usize, Fault)>; FAULT_EXAMPLES],
}

impl FaultTally {
    /// Counts one safe output of agent `i`.
    pub fn add(&mut self, i: usize, f: Fault) {
        self.counts[fault_kind(&f).0] += 1;
        self.example(i, f);
    }

    fn example(&mut self, i: usize, f: Fault) {
        for slot in &mut self.examples {
            match slot {
                Some((j, _)) if *j == i => return,
                Some(_) => {}
                None => {
                    *slot = Some((i, f));
                    return;
                }
            }
        }
    }

    /// Adds `later`'s (outputs after these): the same as adding them here, in order.
    pub fn merge(&mut self, later: &FaultTally) {
        for (a, b) in self.counts.iter_mut().zip(&later.counts) {
            *a += *b;
        }
        for &(i, f) in later.examples.iter().flatten() {
            self.example(i, f);
        }
    }

    /// Safe outputs of every kind.
    pub fn total(&self) -> u64 {
        self.counts.iter().sum()
    }
}

/// The controllers' outputs in the steady window (`analysis::steady`).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct WindowCounts {
    /// Outputs.
    pub ticks: u64,
    /// Of which the safe output, by cause.
    pub safe: FaultTally,
}
