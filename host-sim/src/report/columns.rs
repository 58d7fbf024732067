//! The columns of the time series (`timeseries.csv`, and [`super::TimeSeries`] in
//! memory): their names and the values of one logged row, in that order. The one place
//! that knows the column layout (`docs/outputs.md`).

use crate::engine::Row;
use crate::model::{EstimateInfo, Model};

/// The columns of `timeseries.csv` before the per-agent, per-angle and per-estimate ones
/// (docs/outputs.md).
pub const BASE_COLUMNS: [&str; 13] = [
    "t",
    "V",
    "V_kin",
    "V_ang",
    "V_lead",
    "V_est",
    "max_angle_err",
    "disp_err",
    "vel_err",
    "min_dist",
    "frames_sent",
    "frames_dropped",
    "frames_rejected",
];

/// The column names of `timeseries.csv` for `model` with these estimates.
pub fn header(model: &Model, estimates: &[EstimateInfo]) -> Vec<String> {
    let id = |i: usize| model.agents[i].name.as_str();
    let mut h: Vec<String> = BASE_COLUMNS.iter().map(|s| (*s).to_owned()).collect();
    for a in &model.agents {
        for c in ["x", "y", "vx", "vy"] {
            h.push(format!("{c}_{}", a.name));
        }
    }
    for t in &model.triangles {
        for a in &t.angles {
            let (v, w) = (id(a.far[0]), id(a.far[1]));
            h.push(format!(
                "angle_err_{}_{}_{}",
                id(a.apex),
                v.min(w),
                v.max(w)
            ));
        }
    }
    for e in estimates {
        let tag = format!(
            "{}_{}_{}_{}",
            id(e.owner),
            id(e.apex),
            id(e.far),
            id(e.other)
        );
        h.push(format!("rhat_{tag}"));
        h.push(format!("r_{tag}"));
    }
    h
}

/// One value of a row.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Cell {
    /// A real number.
    Real(f64),
    /// A counter (frames).
    Count(u64),
}

impl Cell {
    /// The value as a number.
    pub fn as_f64(self) -> f64 {
        match self {
            Cell::Real(x) => x,
            Cell::Count(n) => n as f64,
        }
    }
}

/// Calls `f` with every value of `row`, in column order ([`header`]), without
/// allocating.
pub fn for_each_cell(r: &Row<'_>, mut f: impl FnMut(Cell)) {
    let s = r.snap;
    for x in [
        s.t,
        s.v,
        s.v_kin,
        s.v_ang,
        s.v_lead,
        s.v_est,
        s.max_angle_err,
        s.disp_err,
        s.vel_err,
        s.min_dist,
    ] {
        f(Cell::Real(x));
    }
    for n in [r.frames.sent, r.frames.dropped, r.frames.rejected] {
        f(Cell::Count(n));
    }
    for (q, v) in r.q.iter().zip(r.v) {
        for x in [q.x, q.y, v.x, v.y] {
            f(Cell::Real(x));
        }
    }
    for &e in &s.angle_err {
        f(Cell::Real(e));
    }
    for (&rh, &rt) in r.estimates.iter().zip(&s.est_true) {
        f(Cell::Real(rh));
        f(Cell::Real(rt));
    }
}
