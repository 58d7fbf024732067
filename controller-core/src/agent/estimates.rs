//! The distance estimates an agent owns (SPEC §6): which they are, reading and setting
//! them, and the sampled integration of S9 with the S10 projection.

use super::state::{AngleState, Side};
use super::{pick, Agent, OwnedEstimate};
use crate::config::EstimatorMode;
use crate::Real;

impl<T: Real, const MT: usize, const NB: usize> Agent<T, MT, NB> {
    /// Whether this agent owns (integrates) the estimate of `edge` of angle `a` (see
    /// [`owns`]).
    pub(super) fn owns(&self, a: &AngleState<T>, edge: usize) -> bool {
        owns(self.config.estimator, a, edge)
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

    /// Writes the values of the estimates this agent owns into `out`, in
    /// [`Self::owned_estimates`] order, as far as `out` reaches; returns how many it wrote.
    /// (The same as taking `value` from [`Self::owned_estimates`], as a plain loop: a
    /// simulator reads every agent's estimates at every instant.) Feature `sim` only (not
    /// built for the firmware).
    #[cfg(any(feature = "sim", test))]
    pub fn copy_estimates(&self, out: &mut [T]) -> usize {
        let mode = self.config.estimator;
        let mut n = 0;
        for a in self.angles.iter().flatten() {
            for (e, &value) in a.estimate.iter().enumerate() {
                if owns(mode, a, e) {
                    match out.get_mut(n) {
                        Some(slot) => *slot = value,
                        None => return n,
                    }
                    n += 1;
                }
            }
        }
        n
    }

    /// Overwrites an owned estimate with `e.value` (for simulators integrating S9 in
    /// continuous time; call it before [`Agent::sense`], which computes the apex kernels
    /// with the estimates). `e` names the estimate as [`Agent::owned_estimates`] does
    /// (its `apex` and `far` are not read). Values are clamped to `r_min`; returns `false`
    /// for an estimate this agent does not own or a non-finite value. Feature `sim` only
    /// (not built for the firmware).
    #[cfg(any(feature = "sim", test))]
    pub fn set_estimate(&mut self, e: &OwnedEstimate<T>) -> bool {
        let OwnedEstimate {
            triangle,
            angle,
            edge,
            value,
            ..
        } = *e;
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
                *s = crate::law::estimate_floor(value, r_min);
                true
            }
            _ => false,
        }
    }
}

/// Whether an agent in `mode` owns (integrates) the estimate of `edge` of angle `a`: the
/// apex owns both in shared and per-agent mode, a far vertex its own edge's copy in
/// per-agent mode; nobody in measured mode.
pub(super) fn owns<T: Real>(mode: EstimatorMode, a: &AngleState<T>, edge: usize) -> bool {
    match (mode, &a.side) {
        (EstimatorMode::Measured, _) => false,
        (_, Side::Apex { .. }) => true,
        (EstimatorMode::PerAgent, Side::Far { k, .. }) => *k == edge,
        (EstimatorMode::Shared, Side::Far { .. }) => false,
    }
}

#[cfg(test)]
mod tests {
    use super::super::test_support::one_triangle;
    use crate::law::{at_floor, estimate_floor, estimator_step, projected_rate};
    use crate::{Agent, OwnedEstimate};

    /// S10 in its three uses agrees with the one floor: the sampled step, the projected
    /// flow and `Agent::set_estimate` (which clamped with its own comparison before).
    #[test]
    fn every_use_of_the_s10_floor_is_the_same_floor() {
        let r_min = 0.25f64;
        let below = f64::from_bits(r_min.to_bits() - 1);
        let above = f64::from_bits(r_min.to_bits() + 1);
        for r in [f64::NAN, -1.0, 0.0, below, r_min, above, 1.0, f64::INFINITY] {
            let floored = estimate_floor(r, r_min);
            assert!(floored >= r_min, "{r}: {floored}");
            assert_eq!(floored == r_min, at_floor(r, r_min), "{r}");
            assert_eq!(
                estimator_step(r, 0.0, 0.01, r_min).to_bits(),
                floored.to_bits()
            );
            let rate = projected_rate(r, -1.0, r_min);
            assert_eq!(rate == 0.0, at_floor(r, r_min), "{r}: {rate}");
        }
        assert_eq!(estimate_floor(f64::NAN, r_min), r_min);

        let mut c = one_triangle::<f64>(1, [1, 2], 0.0);
        c.min_estimate = r_min;
        let mut a = Agent::<f64, 1, 2>::new(c).unwrap();
        let e = a.owned_estimates().next().unwrap();
        for r in [below, r_min, above, 2.0] {
            assert!(a.set_estimate(&OwnedEstimate { value: r, ..e }));
            let got = a.owned_estimates().next().unwrap().value;
            assert_eq!(got.to_bits(), estimate_floor(r, r_min).to_bits(), "{r}");
        }
    }
}
