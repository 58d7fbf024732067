//! The failure monitor's estimate-collapse rule (`docs/outputs.md`, "Outcome") on a made-up
//! sequence of estimates: an estimate held at `r_min` for `collapse_time` collapses, from
//! the instant it first reached it; release restarts its clock; NaN is never "held"; only
//! the first collapse is recorded.

use host_sim::analysis::{Diagnostics, Monitor, Outcome};
use host_sim::engine::{Engine, SampledSim};
use host_sim::load;

#[test]
fn an_estimate_held_at_r_min_for_the_collapse_time_collapses_from_when_it_reached_it() {
    let model = load("paper", &[]).expect("paper");
    let mut sim = SampledSim::new(&model).expect("sim");
    let info = sim.estimate_info().to_vec();
    let (q, v, est) = sim.view();
    let (q, v, normal) = (q.to_vec(), v.to_vec(), est.to_vec());
    assert!(normal.len() >= 4, "{} estimates", normal.len());
    let r_min = model.min_estimate;
    let wait = model.criteria.collapse_time;
    let mut diag = Diagnostics::new(&model, info);
    let mut monitor = Monitor::new(normal.len());
    // At each instant: the estimates at r_min, and one that is NaN.
    let mut observe = |t: f64, held: &[usize]| {
        let mut est = normal.clone();
        for &k in held {
            est[k] = r_min;
        }
        diag.evaluate(&model, t, &q, &v, &est);
        // The monitor's copy only (a NaN in V would end the run as diverged).
        est[2] = f64::NAN;
        assert!(!monitor.observe(&model, &diag, &est), "no terminal failure");
        monitor
            .events
            .iter()
            .filter(|e| e.kind == Outcome::EstimateCollapse)
            .map(|e| e.t)
            .collect::<Vec<_>>()
    };
    // In steps of a quarter of the wait: 1 held from 0, 3 from h; 1 released at 2h and
    // held again from 3h; 0 from 2h.
    let h = wait / 4.0;
    assert!(observe(0.0, &[1]).is_empty());
    assert!(observe(h, &[1, 3]).is_empty());
    assert!(observe(2.0 * h, &[0, 3]).is_empty());
    assert!(observe(3.0 * h, &[0, 1, 3]).is_empty());
    assert!(observe(4.5 * h, &[0, 1, 3]).is_empty());
    // 3 has been held for more than the wait since h (0 since 2h, 1 only since 3h): it
    // collapses, dated h.
    assert_eq!(observe(5.5 * h, &[0, 1, 3]), [h]);
    // 0 and 1 come due later, but only the first collapse is recorded.
    assert_eq!(observe(9.0 * h, &[0, 1, 3]), [h]);
    assert_eq!(monitor.min_estimate, Some(r_min));
}
