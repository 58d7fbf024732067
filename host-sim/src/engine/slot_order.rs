//! Bearings in the order each agent's core keeps its neighbours (its slots,
//! `ph_formation_core::Agent::neighbours`). A core takes bearings in slot order in one pass;
//! in any other order it searches for each one (same result, more work). The sensors
//! measure in graph order, the order their random stream is drawn in (which fixes every
//! noisy run's result), so the measurements are put in slot order afterwards. A designed
//! formation's slots are mostly not sorted by agent index; the paper's and the built-in
//! strip's are.

use crate::model::Model;
use ph_formation_core::{BearingMeasurement, MAX_NEIGHBOURS};

/// Per agent, the permutation from measurement order to slot order (empty: already in
/// slot order, or unknown).
#[derive(Clone, Debug, Default)]
pub struct SlotOrder {
    start: Vec<usize>,
    /// `perm[start[i] + s]`: the measurement index of agent `i`'s slot `s`.
    perm: Vec<u8>,
}

impl SlotOrder {
    /// For each agent `i`: `measured(i)`, the wire ids of its triangle neighbours in the
    /// order they are measured, and `slots(i)`, the wire ids of its core's neighbours in
    /// slot order (`None` when the controller does not say, e.g. a remote target: the
    /// measurement order is kept).
    pub fn new(
        n: usize,
        measured: impl Fn(usize) -> Vec<u8>,
        slots: impl Fn(usize) -> Option<Vec<u8>>,
    ) -> Self {
        let mut start = Vec::with_capacity(n + 1);
        let mut perm = Vec::new();
        for i in 0..n {
            start.push(perm.len());
            let ids = measured(i);
            let Some(order) = slots(i) else { continue };
            // The triangle neighbours come first among the slots (the partner last).
            let p: Option<Vec<u8>> = order
                .iter()
                .take(ids.len())
                .map(|id| {
                    let k = ids.iter().position(|m| m == id)?;
                    u8::try_from(k).ok()
                })
                .collect();
            match p {
                Some(p)
                    if p.len() == ids.len()
                        && p.iter().enumerate().any(|(s, &k)| usize::from(k) != s) =>
                {
                    perm.extend_from_slice(&p);
                }
                // Already in slot order, or the slots do not start with the measured
                // neighbours (not a core this simulator built): keep the order.
                _ => {}
            }
        }
        start.push(perm.len());
        Self { start, perm }
    }

    /// [`SlotOrder::new`] for `model`'s agents, measured in the order of its triangle
    /// graph (as the engine's sensors measure them).
    pub fn for_model(model: &Model, slots: impl Fn(usize) -> Option<Vec<u8>>) -> Self {
        Self::new(
            model.n(),
            |i| {
                model
                    .graph
                    .triangle
                    .of(i)
                    .iter()
                    .map(|&j| model.agents[j].id)
                    .collect()
            },
            slots,
        )
    }

    /// Puts agent `i`'s bearings (measured in measurement order) in slot order, in place
    /// (no allocation). When a bearing is missing (coincident agents) the order is left
    /// as measured: the core then searches. (So is a list longer than a core's
    /// neighbour capacity, which no core built here has.)
    #[inline]
    pub fn apply(&self, i: usize, bearings: &mut [BearingMeasurement<f64>]) {
        let perm = match (self.start.get(i), self.start.get(i + 1)) {
            (Some(&a), Some(&b)) => self.perm.get(a..b).unwrap_or(&[]),
            _ => &[],
        };
        if perm.is_empty() || perm.len() != bearings.len() {
            return;
        }
        let mut measured: heapless::Vec<BearingMeasurement<f64>, MAX_NEIGHBOURS> =
            heapless::Vec::new();
        if measured.extend_from_slice(bearings).is_err() {
            return;
        }
        for (slot, &k) in bearings.iter_mut().zip(perm) {
            if let Some(b) = measured.get(usize::from(k)) {
                *slot = *b;
            }
        }
    }

    /// Agents whose bearings are reordered.
    pub fn reordered(&self) -> usize {
        self.start.windows(2).filter(|w| w[1] > w[0]).count()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use ph_formation_core::Vec2;

    fn b(id: u8) -> BearingMeasurement<f64> {
        BearingMeasurement {
            neighbour: id,
            bearing: Vec2::new(1.0, 0.0),
            rate: None,
            range: None,
        }
    }

    fn ids(v: &[BearingMeasurement<f64>]) -> Vec<u8> {
        v.iter().map(|x| x.neighbour).collect()
    }

    #[test]
    fn bearings_go_to_slot_order_and_sorted_agents_are_left_alone() {
        // Agent 0 measures [3, 5, 7], its core's slots are [5, 7, 3, 9 (partner)];
        // agent 1 is already in slot order; agent 2's controller does not say.
        let measured = |i: usize| match i {
            0 => vec![3, 5, 7],
            1 => vec![1, 2],
            _ => vec![4, 6],
        };
        let slots = |i: usize| match i {
            0 => Some(vec![5, 7, 3, 9]),
            1 => Some(vec![1, 2]),
            _ => None,
        };
        let o = SlotOrder::new(3, measured, slots);
        assert_eq!(o.reordered(), 1);
        let mut v = vec![b(3), b(5), b(7)];
        o.apply(0, &mut v);
        assert_eq!(ids(&v), [5, 7, 3]);
        // A missing bearing: left as measured.
        let mut v = vec![b(3), b(7)];
        o.apply(0, &mut v);
        assert_eq!(ids(&v), [3, 7]);
        for i in [1, 2] {
            let mut v: Vec<_> = measured(i).into_iter().map(b).collect();
            o.apply(i, &mut v);
            assert_eq!(ids(&v), measured(i));
        }
    }
}
