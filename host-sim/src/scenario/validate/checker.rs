//! The error collector every check writes to, and the small checks they share.

use crate::scenario::error::{ErrorKind, ScenarioError};
use crate::scenario::ScheduleSpec;
use ph_formation_core::{Schedule, ScheduleStep, MAX_SCHEDULE_STEPS};

/// Collects errors while checking.
pub(super) struct Checker<'a> {
    pub(super) file: &'a str,
    /// The file's TOML text, when known: errors then name lines.
    pub(super) text: Option<&'a str>,
    pub(super) errors: Vec<ScenarioError>,
}

impl Checker<'_> {
    /// `" (line L)"`: where the `k`-th `[[table]]` entry starts in the file, or empty.
    pub(super) fn line_of(&self, table: &str, k: usize) -> String {
        self.text
            .and_then(|t| crate::scenario::toml_text::array_entry_line(t, table, k))
            .map_or_else(String::new, |l| format!(" (line {l})"))
    }

    pub(super) fn err(&mut self, kind: ErrorKind, field: &str, reason: impl Into<String>) {
        self.errors
            .push(ScenarioError::new(kind, self.file, field, reason));
    }

    /// `x` finite and `> 0`.
    pub(super) fn positive(&mut self, kind: ErrorKind, field: &str, x: f64) {
        if !(x.is_finite() && x > 0.0) {
            self.err(kind, field, format!("must be a finite number > 0, got {x}"));
        }
    }

    /// `x` finite and `≥ 0`.
    pub(super) fn non_negative(&mut self, kind: ErrorKind, field: &str, x: f64) {
        if !(x.is_finite() && x >= 0.0) {
            self.err(kind, field, format!("must be a finite number ≥ 0, got {x}"));
        }
    }

    pub(super) fn probability(&mut self, field: &str, p: f64) {
        if !(p.is_finite() && (0.0..=1.0).contains(&p)) {
            self.err(
                ErrorKind::InvalidValue,
                field,
                format!("must be a probability in [0, 1], got {p}"),
            );
        }
    }

    pub(super) fn finite2(&mut self, field: &str, v: [f64; 2]) {
        if !(v[0].is_finite() && v[1].is_finite()) {
            self.err(
                ErrorKind::InvalidValue,
                field,
                format!("must be two finite numbers, got {v:?}"),
            );
        }
    }

    pub(super) fn schedule(&mut self, field: &str, s: &ScheduleSpec) -> Schedule<f64> {
        let steps = s.steps();
        let mut out = Schedule::default();
        if steps.len() > MAX_SCHEDULE_STEPS {
            self.err(
                ErrorKind::InvalidValue,
                field,
                format!(
                    "has {} steps; the controller holds at most {MAX_SCHEDULE_STEPS}",
                    steps.len()
                ),
            );
        }
        let mut prev = f64::NEG_INFINITY;
        for (k, st) in steps.iter().enumerate() {
            let f = format!("{field}[{k}]");
            if !(st.from.is_finite() && st.from >= 0.0) {
                self.err(
                    ErrorKind::InvalidValue,
                    &format!("{f}.from"),
                    format!("must be a finite time ≥ 0, got {}", st.from),
                );
            } else if st.from <= prev {
                self.err(
                    ErrorKind::InvalidValue,
                    &format!("{f}.from"),
                    "steps must be sorted by strictly increasing `from`",
                );
            }
            prev = st.from;
            self.finite2(&format!("{f}.value"), st.value);
            let _ = out.steps.push(ScheduleStep {
                from: st.from,
                value: st.value,
            });
        }
        out
    }
}

/// Largest number of RK4 steps of one run.
pub(super) const MAX_STEPS: f64 = 1e12;

/// How many whole `dt` steps make `interval`, if it is a whole multiple.
pub(super) fn whole_steps(interval: f64, dt: f64) -> Option<usize> {
    let k = (interval / dt).round();
    if k >= 1.0 && ((k * dt - interval).abs() <= 1e-9 * interval.max(dt)) {
        Some(k as usize)
    } else {
        None
    }
}

/// Interior angle at `p` of the triangle `p, a, b` (rad, the model's
/// [`interior_angle`](crate::model::geometry::interior_angle)); NaN when `a` or `b`
/// coincides with `p` (which the checks name as such).
pub(super) fn interior_angle(p: [f64; 2], a: [f64; 2], b: [f64; 2]) -> f64 {
    if a == p || b == p {
        return f64::NAN;
    }
    crate::model::geometry::interior_angle(p, a, b)
}
