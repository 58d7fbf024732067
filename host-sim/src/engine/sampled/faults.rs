//! The faults stage of [`super::SampledSim`] (`[[faults]]`, docs/faults.md): which agents
//! are down or deaf at a tick, the reboots' new controllers, and what the swarm did
//! after each fault (who went to its safe output, who came back, and when).

use crate::engine::stats::FaultReport;
use crate::model::{FaultKind, FaultModel, Model};
use ph_formation_core::Status;
use ph_formation_core::{BearingMeasurement, Vec2, MAX_NEIGHBOURS};
use std::sync::Mutex;

/// How long after a fault (its end; its start for a loss) a safe output is still taken as
/// its doing (s): ten neighbour timeouts of 0.1 s.
const ATTRIBUTION_S: f64 = 1.0;

/// Tag of the faults' random streams (mixed into the run's seed).
const FAULT_STREAM: u64 = 0x4641_554C; // "FAUL"

/// The faults of a run and their reports.
#[derive(Debug)]
pub(super) struct Faults {
    faults: Vec<FaultModel>,
    /// Per fault: a reboot's controller already replaced.
    rebooted: Vec<bool>,
    reports: Vec<FaultReport>,
    /// The key of the outlier bursts' streams.
    key: u64,
    /// Per agent, during a sensor freeze: what it measured at the freeze's first tick.
    frozen: Mutex<Vec<Option<Frozen>>>,
}

/// One agent's measurements held by a sensor freeze.
#[derive(Clone, Debug)]
pub(super) struct Frozen {
    bearings: heapless::Vec<BearingMeasurement<f64>, MAX_NEIGHBOURS>,
    velocity: Vec2<f64>,
    partner_offset: Option<Vec2<f64>>,
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
            key: crate::engine::world::stream_key(model.seed, FAULT_STREAM),
            frozen: Mutex::new(vec![None; model.n()]),
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
            .any(|f| matches!(f.kind, FaultKind::AgentLoss | FaultKind::Reboot) && f.acts_on(i, t))
    }

    /// Whether agent `i`'s radio is off at `t` (down, or a blackout).
    pub(super) fn deaf(&self, i: usize, t: f64) -> bool {
        self.down(i, t)
            || self
                .faults
                .iter()
                .any(|f| f.kind == FaultKind::RadioBlackout && f.acts_on(i, t))
    }

    /// How far agent `i`'s clock is off at `t`: the sum of its clock jumps by then (s).
    pub(super) fn clock_offset(&self, i: usize, t: f64) -> f64 {
        self.faults
            .iter()
            .filter(|f| f.kind == FaultKind::ClockJump && f.agent == Some(i) && t >= f.t - 1e-9)
            .map(|f| f.jump)
            .sum()
    }

    /// Agent `i`'s bearings at its tick `tick` (time `t`), turned into outliers during an
    /// outlier burst: each a direction drawn uniformly from the faults' own stream, its
    /// rate (if any) zero.
    pub(super) fn corrupt(
        &self,
        i: usize,
        t: f64,
        tick: u64,
        bearings: &mut [ph_formation_core::BearingMeasurement<f64>],
    ) {
        let burst = self
            .faults
            .iter()
            .any(|f| f.kind == FaultKind::OutlierBurst && f.acts_on(i, t));
        if !burst {
            return;
        }
        let mut rng = crate::engine::world::stream(self.key, i, tick);
        for b in bearings {
            let a = rand::Rng::random::<f64>(&mut rng) * std::f64::consts::TAU;
            b.bearing = ph_formation_core::Vec2::new(a.cos(), a.sin());
            b.rate = b.rate.map(|_| ph_formation_core::Vec2::zeros());
        }
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
            // Taken as the fault's doing: a safe output that starts while it acts or
            // within `ATTRIBUTION_S` after (after it struck, for a lasting loss), not the
            // background timeouts of a lossy channel later on.
            let window = if f.end.is_finite() { f.end } else { f.t } + ATTRIBUTION_S;
            if safe && t <= window + 1e-9 && !listed(&r.went_safe) {
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

    /// Agent `i`'s measurements at `t` under a sensor freeze: the first frozen tick's
    /// are kept and every later one reads them again; outside a freeze nothing changes
    /// (and what was kept is forgotten).
    pub(super) fn freeze(
        &self,
        i: usize,
        t: f64,
        bearings: &mut heapless::Vec<BearingMeasurement<f64>, MAX_NEIGHBOURS>,
        velocity: &mut Vec2<f64>,
        partner_offset: &mut Option<Vec2<f64>>,
    ) {
        let frozen = self
            .faults
            .iter()
            .any(|f| f.kind == FaultKind::SensorFreeze && f.acts_on(i, t));
        // A poisoned lock only means another agent's tick panicked: its data is whole.
        let mut held = self.frozen.lock().unwrap_or_else(|e| e.into_inner());
        let Some(slot) = held.get_mut(i) else {
            return;
        };
        match (frozen, slot.as_ref()) {
            (false, _) => *slot = None,
            (true, None) => {
                *slot = Some(Frozen {
                    bearings: bearings.clone(),
                    velocity: *velocity,
                    partner_offset: *partner_offset,
                })
            }
            (true, Some(f)) => {
                bearings.clone_from(&f.bearings);
                *velocity = f.velocity;
                *partner_offset = f.partner_offset;
            }
        }
    }

    /// What the swarm did after each fault, in `[[faults]]` order.
    pub(super) fn reports(&self) -> Vec<FaultReport> {
        self.reports.clone()
    }
}
