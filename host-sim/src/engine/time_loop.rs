//! The time loop shared by both simulators: control ticks, RK4 steps, the diagnostics
//! cadence (every control instant and every log instant), logging, and early stopping on
//! a terminal failure found by [`crate::analysis::Monitor`].

use super::error::RunError;
use super::record::{Recorder, Row};
use super::simulator::Engine;
use super::stats::FrameCounts;
use crate::analysis::{Diagnostics, Monitor};
use crate::model::{geometry, Model};
use ph_formation_core::Vec2;

/// A simulated run before its verdict: the monitor that watched it and the last state.
pub(super) struct Simulated {
    /// The failure monitor, with every observed instant.
    pub(super) monitor: Monitor,
    /// The diagnostics of the last instant.
    pub(super) diag: Diagnostics,
    /// RK4 steps taken.
    pub(super) steps: usize,
    /// Each triangle's signed area at the start.
    pub(super) area0: Vec<f64>,
}

/// The first step after `k` that is a control tick (a multiple of `spt`), a log instant (a
/// multiple of `log_every`) or the last one (`total`).
fn next_instant(k: usize, spt: usize, log_every: usize, total: usize) -> usize {
    let after = |every: usize| (k / every + 1) * every;
    after(spt).min(after(log_every)).min(total)
}

/// Twice the signed area of triangle `t` in `q` ([`geometry::cross`]).
pub(super) fn signed_area(q: &[Vec2<f64>], t: [usize; 3]) -> f64 {
    let p = |v: usize| [q[v].x, q[v].y];
    geometry::cross(p(t[0]), p(t[1]), p(t[2]))
}

/// The time loop alone: the run up to its end or its terminal failure.
pub(super) fn simulate(
    model: &Model,
    engine: &mut dyn Engine,
    recorder: &mut dyn Recorder,
    progress: &mut dyn FnMut(f64),
) -> Result<Simulated, RunError> {
    let total = model.total_steps();
    let spt = model.steps_per_tick.max(1);
    let log_every = model.log_every.max(1);
    let progress_every = (total / 200).max(1);
    let mut diag = Diagnostics::new(model, engine.estimate_info().to_vec());
    let mut monitor = Monitor::new(model, diag.estimates.len());
    let area0: Vec<f64> = {
        let (q, _, _) = engine.view();
        model
            .triangles
            .iter()
            .map(|t| signed_area(q, t.vertices))
            .collect()
    };
    let rows = recorder.wants_rows();
    let mut steps = 0;
    let mut k = 0;
    loop {
        let t = model.time(k);
        // The diagnostics look at every control period (the common clock's ticks).
        let tick = k.is_multiple_of(spt);
        if engine.ticks_at(model, k) {
            engine.control(t);
            if let Some(e) = engine.take_error() {
                let _ = recorder.finish();
                return Err(RunError::Hil(e));
            }
        }
        let log = k.is_multiple_of(log_every) || k == total;
        if tick || log {
            // Only rows show the frame counters (summing them visits every agent).
            let frames = if rows {
                engine.frame_counts()
            } else {
                FrameCounts::default()
            };
            let (q, v, est) = engine.view();
            diag.evaluate(model, t, q, v, est);
            let stop = monitor.observe(model, &diag, q, est);
            if (log || stop) && rows {
                recorder.record(&Row {
                    snap: &diag.snap,
                    q,
                    v,
                    estimates: est,
                    frames,
                })?;
            }
            if stop {
                break;
            }
        }
        if k == total {
            break;
        }
        // The steps up to the next instant that looks at the state: a control tick, a log
        // instant or the end.
        let next = next_instant(k, spt, log_every, total).min(engine.next_tick_after(model, k));
        engine.integrate_steps(model, k, next - k);
        steps += next - k;
        // As at every step that is a multiple of `progress_every`.
        if k.next_multiple_of(progress_every) < next {
            progress(t);
        }
        k = next;
    }
    recorder.finish()?;
    progress(diag.snap.t);
    Ok(Simulated {
        monitor,
        diag,
        steps,
        area0,
    })
}

#[cfg(test)]
mod tests {
    use super::next_instant;

    /// The next instant is the nearest later tick, log instant or end, never `k` itself.
    #[test]
    fn next_instant_is_the_nearest_tick_log_or_end() {
        // Ticks every 10 steps, logs every 25, 100 steps.
        assert_eq!(next_instant(0, 10, 25, 100), 10);
        assert_eq!(next_instant(10, 10, 25, 100), 20);
        assert_eq!(next_instant(20, 10, 25, 100), 25);
        assert_eq!(next_instant(25, 10, 25, 100), 30);
        assert_eq!(next_instant(97, 10, 25, 100), 100);
        // The end before the next tick, and a log every step.
        assert_eq!(next_instant(95, 10, 25, 98), 98);
        assert_eq!(next_instant(3, 10, 1, 100), 4);
        // Walking from 0 visits every tick and every log instant.
        let (mut k, mut seen) = (0, vec![0]);
        while k < 100 {
            k = next_instant(k, 10, 25, 100);
            seen.push(k);
        }
        let expect: Vec<usize> = (0..=100).filter(|j| j % 10 == 0 || j % 25 == 0).collect();
        assert_eq!(seen, expect);
    }
}
