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

/// Aggregates `rows` (any order) into one [`PointStats`] per point `0..points`.
pub fn aggregate(rows: &[RunRow], points: usize) -> Vec<PointStats> {
    let mut by_point: Vec<Vec<&RunRow>> = vec![Vec::new(); points];
    for r in rows {
        if let Some(v) = by_point.get_mut(r.point) {
            v.push(r);
        }
    }
    by_point
        .iter()
        .enumerate()
        .map(|(point, rs)| {
            let errors = rs.iter().filter(|r| r.outcome == ERROR).count() as u64;
            let n = rs.len() as u64 - errors;
            let fractions = Outcome::ALL
                .iter()
                .map(|o| {
                    let count = rs.iter().filter(|r| r.outcome == o.as_str()).count() as u64;
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
            let mut settle: Vec<f64> = rs
                .iter()
                .filter_map(|r| r.settle_time)
                .filter(|t| t.is_finite())
                .collect();
            settle.sort_by(f64::total_cmp);
            PointStats {
                point,
                n,
                errors,
                fractions,
                settled: settle.len() as u64,
                settle: SETTLE_QUANTILES
                    .iter()
                    .map(|(q, _)| quantile(&settle, *q))
                    .collect(),
            }
        })
        .collect()
}
