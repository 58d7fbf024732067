//! The age of neighbour data: per radio link (receiver, sender), the production time of
//! the newest frame received, sampled at every control tick.

use super::ChannelStats;
use crate::model::graph::Adjacency;

/// Newest production time per link and the running age figures.
#[derive(Debug)]
pub(super) struct Ages {
    /// Where receiver `i`'s links start in `born`.
    start: Vec<usize>,
    /// Newest production time heard per link (NaN: nothing yet).
    born: Vec<f64>,
    sum: f64,
    max: f64,
    samples: u64,
}

impl Ages {
    pub(super) fn new(neighbours: &Adjacency) -> Self {
        let mut start = Vec::with_capacity(neighbours.len() + 1);
        let mut total = 0;
        for i in 0..neighbours.len() {
            start.push(total);
            total += neighbours.of(i).len();
        }
        start.push(total);
        Self {
            start,
            born: vec![f64::NAN; total],
            sum: 0.0,
            max: 0.0,
            samples: 0,
        }
    }

    pub(super) fn heard(&mut self, neighbours: &Adjacency, to: usize, from: usize, born: f64) {
        let Some(pos) = neighbours.of(to).iter().position(|&j| j == from) else {
            return;
        };
        let Some(slot) = self.start.get(to).and_then(|s| self.born.get_mut(s + pos)) else {
            return;
        };
        if slot.is_nan() || born > *slot {
            *slot = born;
        }
    }

    pub(super) fn sample(&mut self, now: f64) {
        for &b in &self.born {
            if !b.is_nan() {
                let age = now - b;
                self.sum += age;
                self.max = self.max.max(age);
                self.samples += 1;
            }
        }
    }

    pub(super) fn write(&self, s: &mut ChannelStats) {
        s.age_samples = self.samples;
        s.max_age = self.max;
        s.mean_age = if self.samples > 0 {
            self.sum / self.samples as f64
        } else {
            0.0
        };
    }
}
