//! The faults stage of [`super::SampledSim`] (`[[faults]]`, docs/faults.md): which agents
//! are down or deaf at a tick, the reboots' new controllers, and what the swarm did
//! after each fault (who went to its safe output, who came back, and when).

use crate::engine::stats::FaultReport;
use crate::model::{FaultKind, FaultModel, Model};
use ph_formation_core::Status;

/// The faults of a run and their reports.
#[derive(Debug)]
pub(super) struct Faults {
    faults: Vec<FaultModel>,
    /// Per fault: a reboot's controller already replaced.
    rebooted: Vec<bool>,
    reports: Vec<FaultReport>,
}

impl Faults {
    /// The faults of `model`.
    pub(super) fn new(model: &Model) -> Self {
        Self {
            faults: model.faults.clone(),
            rebooted: vec![false; model.faults.len()],
            reports: model
                .faults
                .iter()
                .map(|f| FaultReport {
                    fault: f.clone(),
                    went_safe: Vec::new(),
                    recovered: Vec::new(),
                })
                .collect(),
        }
    }

    /// Whether there is any fault.
    pub(super) fn any(&self) -> bool {
        !self.faults.is_empty()
    }

    /// Whether agent `i` is down at `t` (lost, or rebooting): it neither ticks nor sends.
    pub(super) fn down(&self, i: usize, t: f64) -> bool {
        self.faults
            .iter()
            .any(|f| f.kind != FaultKind::RadioBlackout && f.acts_on(i, t))
    }

    /// Whether agent `i`'s radio is off at `t` (down, or a blackout).
    pub(super) fn deaf(&self, i: usize, t: f64) -> bool {
        self.faults.iter().any(|f| f.acts_on(i, t))
    }

    /// The reboots that strike by `t` and have not been applied: their agents, once each
    /// (the caller gives each a new controller).
    pub(super) fn reboots_due(&mut self, t: f64) -> Vec<usize> {
        let mut due = Vec::new();
        for (f, done) in self.faults.iter().zip(&mut self.rebooted) {
            if f.kind == FaultKind::Reboot && !*done && t >= f.t - 1e-9 {
                *done = true;
                due.extend(f.agent);
            }
        }
        due
    }

    /// Agent `i`'s output status at its tick at `t`: recorded against every fault that
    /// struck before it.
    pub(super) fn observe(&mut self, i: usize, t: f64, status: Status) {
        let safe = matches!(status, Status::Safe(_));
        for r in &mut self.reports {
            let f = &r.fault;
            if t < f.t - 1e-9 {
                continue;
            }
            let listed = |v: &[(usize, f64)]| v.iter().any(|(a, _)| *a == i);
            if safe && !listed(&r.went_safe) {
                r.went_safe.push((i, t));
            }
            // Back to its law after the fault ended: a neighbour that went safe, or
            // the rebooted agent itself.
            let rebooted = f.kind == FaultKind::Reboot && f.agent == Some(i);
            if !safe
                && t >= f.end - 1e-9
                && (listed(&r.went_safe) || rebooted)
                && !listed(&r.recovered)
            {
                r.recovered.push((i, t));
            }
        }
    }

    /// What the swarm did after each fault, in `[[faults]]` order.
    pub(super) fn reports(&self) -> Vec<FaultReport> {
        self.reports.clone()
    }
}
