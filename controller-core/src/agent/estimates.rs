//! The distance estimates an agent owns (SPEC §6): which they are, reading and setting
//! them, and the sampled integration of S9 with the S10 projection.

use super::state::{AngleState, Role};
use super::{pick, Agent, OwnedEstimate};
use crate::config::EstimatorMode;
use crate::{law, Real};

impl<T: Real, const MT: usize, const NB: usize> Agent<T, MT, NB> {
    /// Whether this agent owns (integrates) the estimate of `edge` of angle `a`: the apex
    /// owns both in shared and per-agent mode, a far vertex its own edge's copy in
    /// per-agent mode; nobody in measured mode.
    pub(super) fn owns(&self, a: &AngleState<T>, edge: usize) -> bool {
        match (self.config.estimator, a.role) {
            (EstimatorMode::Measured, _) => false,
            (_, Role::Apex) => true,
            (EstimatorMode::PerAgent, Role::Far(k)) => k == edge,
            (EstimatorMode::Shared, Role::Far(_)) => false,
        }
    }

    /// The estimates this agent owns and integrates, with where they belong.
    pub fn owned_estimates(&self) -> impl Iterator<Item = OwnedEstimate<T>> + '_ {
        self.angles.iter().enumerate().flat_map(move |(ti, tri)| {
            tri.iter().enumerate().flat_map(move |(ai, a)| {
                (0..2usize)
                    .filter(move |&e| self.owns(a, e))
                    .map(move |e| OwnedEstimate {
                        triangle: ti,
                        angle: ai,
                        edge: e,
                        apex: a.apex,
                        far: pick(&a.far, e),
                        value: pick(&a.estimate, e),
                    })
            })
        })
    }

    /// Overwrites an owned estimate (for simulators integrating S9 in continuous time; call
    /// it before [`Agent::sense`], which computes the apex kernels with the estimates).
    /// Values are clamped to `r_min`; returns `false` for an estimate this agent does not
    /// own or a non-finite value.
    pub fn set_estimate(&mut self, triangle: usize, angle: usize, edge: usize, value: T) -> bool {
        let owned = match self.angles.get(triangle).and_then(|t| t.get(angle)) {
            Some(a) => self.owns(a, edge),
            None => false,
        };
        let r_min = self.config.min_estimate;
        let slot = self
            .angles
            .get_mut(triangle)
            .and_then(|t| t.get_mut(angle))
            .and_then(|a| a.estimate.get_mut(edge));
        match slot {
            Some(s) if owned && value.finite() => {
                *s = if value > r_min { value } else { r_min };
                true
            }
            _ => false,
        }
    }

    /// One sampled step of every estimate with the flows the law left in `rate`:
    /// `r̂ ← max(r_min, r̂ + Δt·rate)` (S10). Estimates not owned have rate zero and stay as
    /// they are (they are never below `r_min`).
    pub(super) fn integrate(&mut self, dt: T) {
        let r_min = self.config.min_estimate;
        for a in self.angles.as_mut_slice().as_flattened_mut() {
            let rate = a.rate.get();
            for (est, rate) in a.estimate.iter_mut().zip(rate) {
                *est = law::estimator_step(*est, rate, dt, r_min);
            }
        }
    }
}
