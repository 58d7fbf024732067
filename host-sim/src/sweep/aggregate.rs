//! Per point: how often each outcome happened, with its 95 % Wilson interval, and the
//! settle-time quantiles. Computed from the rows alone (as `runs.csv` holds them), so a
//! merge of shards aggregates exactly as one run does.

use super::run::{RunRow, ERROR};
use super::stats::{quantile, wilson};
use crate::analysis::Outcome;

/// The quantiles of the settle time reported per point.
pub const SETTLE_QUANTILES: [(f64, &str); 3] = [(0.1, "p10"), (0.5, "p50"), (0.9, "p90")];

/// One outcome at one point.
#[derive(Clone, Debug, PartialEq)]
pub struct Fraction {
    /// The outcome's name.
    pub outcome: &'static str,
    /// Runs that ended so.
    pub count: u64,
    /// `count / n` (NaN when no run finished).
    pub fraction: f64,
    /// 95 % Wilson interval, lower bound.
    pub lo: f64,
    /// 95 % Wilson interval, upper bound.
    pub hi: f64,
}

/// What the runs of one point found.
#[derive(Clone, Debug, PartialEq)]
pub struct PointStats {
    /// Point index.
    pub point: usize,
    /// Runs with an outcome (errors excluded): the `n` of the fractions.
    pub n: u64,
    /// Runs that could not be made (outcome `error`).
    pub errors: u64,
    /// Every outcome of [`Outcome::ALL`], in that order.
    pub fractions: Vec<Fraction>,
    /// Runs with a settle time.
    pub settled: u64,
    /// Settle-time quantiles [`SETTLE_QUANTILES`] (s) over the runs that settled.
    pub settle: Vec<Option<f64>>,
}

/// The runs of one point, accumulated one at a time (counts and settle times only).
#[derive(Clone, Debug)]
pub struct PointAcc {
    point: usize,
    rows: u64,
    errors: u64,
    counts: Vec<u64>,
    settle: Vec<f64>,
}

impl PointAcc {
    /// No run yet at `point`.
    pub fn new(point: usize) -> Self {
        Self {
            point,
            rows: 0,
            errors: 0,
            counts: vec![0; Outcome::ALL.len()],
            settle: Vec::new(),
        }
    }

    /// Counts one run (of this point).
    pub fn add(&mut self, r: &RunRow) {
        self.rows += 1;
        if r.outcome == ERROR {
            self.errors += 1;
        }
        if let Some(i) = Outcome::ALL.iter().position(|o| o.as_str() == r.outcome) {
            self.counts[i] += 1;
        }
        if let Some(t) = r.settle_time.filter(|t| t.is_finite()) {
            self.settle.push(t);
        }
    }

    /// The point's statistics.
    pub fn finish(mut self) -> PointStats {
        let n = self.rows - self.errors;
        let fractions = Outcome::ALL
            .iter()
            .zip(&self.counts)
            .map(|(o, &count)| {
                let (fraction, lo, hi) = wilson(count, n);
                Fraction {
                    outcome: o.as_str(),
                    count,
                    fraction,
                    lo,
                    hi,
                }
            })
            .collect();
        self.settle.sort_by(f64::total_cmp);
        PointStats {
            point: self.point,
            n,
            errors: self.errors,
            fractions,
            settled: self.settle.len() as u64,
            settle: SETTLE_QUANTILES
                .iter()
                .map(|(q, _)| quantile(&self.settle, *q))
                .collect(),
        }
    }
}

/// Aggregates rows that come in point order (as `runs.csv` holds them), holding one
/// point's settle times at a time.
#[derive(Clone, Debug)]
pub struct Sorted {
    points: usize,
    current: PointAcc,
    out: Vec<PointStats>,
}

impl Sorted {
    /// For points `0..points`.
    pub fn new(points: usize) -> Self {
        Self {
            points,
            current: PointAcc::new(0),
            out: Vec::new(),
        }
    }

    /// Counts the next row (its point not below the previous row's).
    pub fn add(&mut self, r: &RunRow) {
        while r.point > self.current.point && self.current.point < self.points {
            let next = PointAcc::new(self.current.point + 1);
            self.out
                .push(std::mem::replace(&mut self.current, next).finish());
        }
        if r.point == self.current.point {
            self.current.add(r);
        }
    }

    /// One [`PointStats`] per point.
    pub fn finish(mut self) -> Vec<PointStats> {
        while self.out.len() < self.points {
            let next = PointAcc::new(self.current.point + 1);
            self.out
                .push(std::mem::replace(&mut self.current, next).finish());
        }
        self.out
    }
}

/// Aggregates `rows` (any order) into one [`PointStats`] per point `0..points`.
pub fn aggregate(rows: &[RunRow], points: usize) -> Vec<PointStats> {
    let mut acc: Vec<PointAcc> = (0..points).map(PointAcc::new).collect();
    for r in rows {
        if let Some(a) = acc.get_mut(r.point) {
            a.add(r);
        }
    }
    acc.into_iter().map(PointAcc::finish).collect()
}
