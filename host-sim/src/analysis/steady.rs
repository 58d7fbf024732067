//! The steady window: what a run held over its last part, judged on percentiles of the
//! true errors rather than on one instant (`docs/outputs.md`, "Outcome").
//!
//! A run with random sensing or a random world never holds its angles to 1e-3 rad; its
//! verdict looks at the **steady window** `[T − W, T]` (`W` = `criteria.steady_window`,
//! by default a quarter of the run) cut into **sub-windows** of `W/4`. A quantity is *in
//! band* over a sub-window when at least 95 % of the observed instants in it are at or
//! below the band ([`PERCENTILE`]). The **settle time** is the start of the first
//! sub-window from which every later sub-window is in band; the run *held* the quantity
//! when it settled at or before `T − W`.
//!
//! Every function here reads a [`Series`] of observed instants; nothing allocates per
//! instant beyond the series itself.

use crate::model::Model;

/// The share of a sub-window's instants that must be in band, and the percentile the
/// calibration reads.
pub const PERCENTILE: f64 = 0.95;

/// One observed instant: what the verdict judges and the pose it reports.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Instant {
    /// Time (s).
    pub t: f64,
    /// `max |α − α*|` over the controlled angles (rad).
    pub angle: f64,
    /// Scale error of the leader edge, `| |z| − |z*| |` (m; 0 without a leader edge).
    pub scale: f64,
    /// `max_n |v_n − v*|` (m/s).
    pub velocity: f64,
    /// `|z − z*|` (m; 0 without a leader edge).
    pub displacement: f64,
    /// Signed angle from `z*` to `z` (rad; 0 without a leader edge).
    pub orientation: f64,
    /// Distance of the centroid from the reference trajectory `c(0) + ∫ v*` (m).
    pub translation: f64,
}

/// Which quantity of an [`Instant`].
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Quantity {
    /// [`Instant::angle`].
    Angle,
    /// [`Instant::scale`].
    Scale,
    /// [`Instant::velocity`].
    Velocity,
    /// `|`[`Instant::orientation`]`|`.
    Orientation,
    /// [`Instant::translation`].
    Translation,
}

impl Quantity {
    /// Its value at instant `i`.
    pub fn of(self, i: &Instant) -> f64 {
        match self {
            Self::Angle => i.angle,
            Self::Scale => i.scale,
            Self::Velocity => i.velocity,
            Self::Orientation => i.orientation.abs(),
            Self::Translation => i.translation,
        }
    }
}

/// The observed instants of a run, in time order.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Series {
    /// The instants.
    pub instants: Vec<Instant>,
}

/// The steady window of a run and its sub-windows.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Window {
    /// `T − W` (s).
    pub from: f64,
    /// `T`, the run's duration (s).
    pub to: f64,
    /// The sub-window length `W/4` (s).
    pub sub: f64,
}

impl Window {
    /// The steady window of `model`: its last `criteria.steady_window` seconds, or its last
    /// quarter when that is 0.
    pub fn of(model: &Model) -> Self {
        let t = model.duration;
        let w = match model.criteria.steady_window {
            w if w > 0.0 => w.min(t),
            _ => 0.25 * t,
        };
        Self {
            from: t - w,
            to: t,
            sub: 0.25 * w,
        }
    }

    /// Its length `W` (s).
    pub fn length(&self) -> f64 {
        self.to - self.from
    }
}

impl Series {
    /// Appends an instant (times must not decrease).
    pub fn push(&mut self, i: Instant) {
        self.instants.push(i);
    }

    /// The settle time of `q` against `band`: the start of the first sub-window (length
    /// `sub`) from which every later full sub-window has at least [`PERCENTILE`] of its
    /// instants at or below `band`. `Some(first instant)` when every sub-window is in
    /// band; `None` when the last one is not (or there is no full sub-window).
    pub fn settle_time(&self, q: Quantity, band: f64, sub: f64) -> Option<f64> {
        let xs = &self.instants;
        let first = xs.first()?.t;
        // Two pointers: instants (t_k − sub, t_k] for each k whose window is full.
        let (mut lo, mut above) = (0usize, 0usize);
        let mut last_bad: Option<usize> = None;
        let mut any_full = false;
        for (k, x) in xs.iter().enumerate() {
            if q.of(x) > band {
                above += 1;
            }
            while xs[lo].t <= x.t - sub {
                if q.of(&xs[lo]) > band {
                    above -= 1;
                }
                lo += 1;
            }
            if x.t - first < sub * (1.0 - 1e-9) {
                continue; // not a full sub-window yet
            }
            any_full = true;
            let count = k + 1 - lo;
            if (above as f64) > (1.0 - PERCENTILE) * count as f64 {
                last_bad = Some(k);
            }
        }
        if !any_full {
            return None;
        }
        match last_bad {
            None => Some(first),
            Some(k) if k + 1 == xs.len() => None,
            Some(k) => Some((xs[k + 1].t - sub).max(first)),
        }
    }

    /// The instants with `from ≤ t ≤ to`.
    fn between(&self, from: f64, to: f64) -> impl Iterator<Item = &Instant> {
        self.instants
            .iter()
            .filter(move |i| i.t >= from && i.t <= to)
    }

    /// The [`PERCENTILE`] of `q` over the instants in `[from, to]` (`None` if none).
    pub fn percentile(&self, q: Quantity, from: f64, to: f64) -> Option<f64> {
        let mut v: Vec<f64> = self.between(from, to).map(|i| q.of(i)).collect();
        quantile(&mut v, PERCENTILE)
    }

    /// The largest [`PERCENTILE`] of `q` over the sub-windows of `w` (starting every
    /// `sub / 8`): what a steady run's sub-windows reach (the calibration's statistic).
    pub fn worst_sub_window(&self, q: Quantity, w: &Window) -> Option<f64> {
        let step = 0.125 * w.sub;
        if step.is_nan() || step <= 0.0 {
            return self.percentile(q, w.from, w.to);
        }
        let mut worst: Option<f64> = None;
        let mut start = w.from;
        while start + w.sub <= w.to + 1e-9 * w.to.max(1.0) {
            if let Some(p) = self.percentile(q, start, start + w.sub) {
                worst = Some(worst.map_or(p, |m: f64| m.max(p)));
            }
            start += step;
        }
        worst
    }

    /// The last instant.
    pub fn last(&self) -> Option<&Instant> {
        self.instants.last()
    }
}

/// The `p`-quantile of `v` (nearest rank: the smallest value with at least `p` of the
/// values at or below it); NaN counts as larger than every number. `None` when empty.
pub fn quantile(v: &mut [f64], p: f64) -> Option<f64> {
    if v.is_empty() {
        return None;
    }
    v.sort_by(|a, b| a.total_cmp(b));
    let rank = ((p * v.len() as f64).ceil() as usize).clamp(1, v.len());
    Some(v[rank - 1])
}

/// `∫₀ᵗ` of a piecewise-constant schedule (`ph_formation_core::Schedule::at`: the first
/// value before the first step).
pub fn schedule_integral(s: &ph_formation_core::Schedule<f64>, t: f64) -> [f64; 2] {
    let steps = s.steps.as_slice();
    let Some(first) = steps.first() else {
        return [0.0; 2];
    };
    let mut acc = [0.0; 2];
    let mut value = first.value;
    let mut from = 0.0f64;
    for st in &steps[1..] {
        if st.from >= t {
            break;
        }
        let until = st.from.max(from);
        acc[0] += value[0] * (until - from);
        acc[1] += value[1] * (until - from);
        from = until;
        value = st.value;
    }
    if t > from {
        acc[0] += value[0] * (t - from);
        acc[1] += value[1] * (t - from);
    }
    acc
}

#[cfg(test)]
mod tests {
    use super::*;
    use ph_formation_core::{Schedule, ScheduleStep};

    fn series(values: &[(f64, f64)]) -> Series {
        Series {
            instants: values
                .iter()
                .map(|&(t, a)| Instant {
                    t,
                    angle: a,
                    ..Instant::default()
                })
                .collect(),
        }
    }

    /// A step into the band at t = 10 s settles there (within one instant's share).
    #[test]
    fn a_clean_step_settles_where_it_entered() {
        let s = series(
            &(0..=2000)
                .map(|k| {
                    let t = k as f64 * 0.01;
                    (t, if t < 10.0 { 1.0 } else { 0.0 })
                })
                .collect::<Vec<_>>(),
        );
        let t = s.settle_time(Quantity::Angle, 0.5, 2.0).unwrap();
        // The first good window may hold 5 % of bad instants: it starts 0.1 s early.
        assert!((t - 9.9).abs() < 0.02, "{t}");
        // Against a band nothing meets, no settle time.
        assert_eq!(s.settle_time(Quantity::Angle, -1.0, 2.0), None);
        // Against a band everything meets, the first instant.
        assert_eq!(s.settle_time(Quantity::Angle, 2.0, 2.0), Some(0.0));
    }

    /// Sparse excursions (under 5 % of any sub-window) do not unsettle; a burst does.
    #[test]
    fn excursions_count_by_share() {
        let mk = |burst: bool| {
            series(
                &(0..=2000)
                    .map(|k| {
                        let t = k as f64 * 0.01;
                        let spike = k % 50 == 0; // 2 %
                        let b = burst && (15.0..15.5).contains(&t);
                        (t, if spike || b { 1.0 } else { 0.0 })
                    })
                    .collect::<Vec<_>>(),
            )
        };
        assert_eq!(mk(false).settle_time(Quantity::Angle, 0.5, 2.0), Some(0.0));
        let t = mk(true).settle_time(Quantity::Angle, 0.5, 2.0).unwrap();
        assert!(t > 14.0 && t < 16.0, "{t}");
    }

    #[test]
    fn quantile_is_nearest_rank() {
        let mut v: Vec<f64> = (1..=100).map(f64::from).rev().collect();
        assert_eq!(quantile(&mut v, 0.95), Some(95.0));
        assert_eq!(quantile(&mut [], 0.95), None);
        assert_eq!(quantile(&mut [3.0], 0.95), Some(3.0));
    }

    /// The integral against a closed form: 1 m/s for 2 s, then 3 m/s.
    #[test]
    fn schedule_integral_is_piecewise_linear() {
        let mut s = Schedule::constant([1.0, 0.0]);
        s.steps
            .push(ScheduleStep {
                from: 2.0,
                value: [3.0, -1.0],
            })
            .unwrap();
        assert_eq!(schedule_integral(&s, 1.0), [1.0, 0.0]);
        assert_eq!(schedule_integral(&s, 2.0), [2.0, 0.0]);
        assert_eq!(schedule_integral(&s, 4.0), [8.0, -2.0]);
        assert_eq!(schedule_integral(&Schedule::default(), 4.0), [0.0, 0.0]);
    }

    #[test]
    fn worst_sub_window_reads_the_noisiest_part() {
        let s = series(
            &(0..=1000)
                .map(|k| {
                    let t = k as f64 * 0.01;
                    (t, if (6.0..8.0).contains(&t) { 2.0 } else { 1.0 })
                })
                .collect::<Vec<_>>(),
        );
        let w = Window {
            from: 2.0,
            to: 10.0,
            sub: 2.0,
        };
        assert_eq!(s.worst_sub_window(Quantity::Angle, &w), Some(2.0));
        let early = Window {
            from: 0.0,
            to: 5.0,
            sub: 1.0,
        };
        assert_eq!(s.worst_sub_window(Quantity::Angle, &early), Some(1.0));
    }
}
