//! The statistics against hand-computed values.

use super::*;

fn close(a: f64, b: f64) -> bool {
    (a - b).abs() < 5e-6
}

#[test]
fn wilson_interval_against_hand_computed_values() {
    // z = 1.959964, z² = 3.841459. k = 3, n = 10: p̂ = 0.3, 1 + z²/n = 1.3841459,
    // centre = (0.3 + 0.1920729)/1.3841459 = 0.3555066,
    // half = 1.959964/1.3841459 · √(0.021 + 0.0096036) = 0.2477153: [0.1077913, 0.6032219]
    // (the textbook 3/10 interval, [0.108, 0.603]).
    let (p, lo, hi) = wilson(3, 10);
    assert!(
        close(p, 0.3) && close(lo, 0.1077913) && close(hi, 0.6032219),
        "{lo} {hi}"
    );
    // k = 0: centre = half = 0.1920729/1.3841459 = 0.1387664: [0, 0.2775328].
    let (p, lo, hi) = wilson(0, 10);
    assert!(p == 0.0 && lo == 0.0 && close(hi, 0.2775328), "{hi}");
    // k = n: the mirror image.
    let (p, lo, hi) = wilson(10, 10);
    assert!(p == 1.0 && close(lo, 1.0 - 0.2775328) && hi == 1.0, "{lo}");
    // k = 50, n = 100: centre 0.5, half = 1.959964/1.0384146 · √(0.0025 + 0.0000960) = 0.0961685.
    let (_, lo, hi) = wilson(50, 100);
    assert!(close(lo, 0.4038315) && close(hi, 0.5961685), "{lo} {hi}");
    let (p, lo, hi) = wilson(0, 0);
    assert!(p.is_nan() && lo == 0.0 && hi == 1.0);
}

#[test]
fn quantiles_interpolate_between_order_statistics() {
    let x = [1.0, 2.0, 3.0, 4.0];
    assert_eq!(quantile(&x, 0.5), Some(2.5));
    assert!(close(quantile(&x, 0.1).unwrap(), 1.3));
    assert!(close(quantile(&x, 0.9).unwrap(), 3.7));
    assert_eq!(quantile(&x, 0.0), Some(1.0));
    assert_eq!(quantile(&x, 1.0), Some(4.0));
    assert_eq!(quantile(&[7.0], 0.9), Some(7.0));
    assert_eq!(quantile(&[], 0.5), None);
}

fn row(point: usize, outcome: &str, settle: Option<f64>) -> RunRow {
    RunRow {
        point,
        run: 0,
        seed: 0,
        outcome: outcome.to_owned(),
        settle_time: settle,
        final_time: 1.0,
        final_max_angle_error: 0.0,
        final_displacement_error: 0.0,
        final_velocity_error: 0.0,
        min_distance: 1.0,
        min_estimate: None,
        v0: 1.0,
        v_final: 0.0,
        rotation_deg: None,
        shortened: None,
        reason: String::new(),
    }
}

#[test]
fn aggregation_counts_every_outcome_with_intervals_and_settle_quantiles() {
    let mut rows: Vec<RunRow> = (0..7)
        .map(|i| row(0, "converged", Some(f64::from(i + 1))))
        .collect();
    rows.extend((0..3).map(|_| row(0, "collision", None)));
    rows.push(row(0, "error", None));
    rows.push(row(1, "not_converged", Some(5.0)));
    let s = aggregate(&rows, 3);
    assert_eq!(s.len(), 3);
    assert_eq!((s[0].n, s[0].errors), (10, 1), "errors are not in n");
    let names: Vec<&str> = s[0].fractions.iter().map(|f| f.outcome).collect();
    let all: Vec<&str> = ph_formation_sim::Outcome::ALL
        .iter()
        .map(|o| o.as_str())
        .collect();
    assert_eq!(
        names, all,
        "every outcome the analysis defines, in its order"
    );
    let conv = &s[0].fractions[0];
    let (p, lo, hi) = wilson(7, 10);
    assert_eq!(
        (conv.count, conv.fraction, conv.lo, conv.hi),
        (7, p, lo, hi)
    );
    assert!(close(conv.lo, 1.0 - 0.6032219) && close(conv.hi, 1.0 - 0.1077913));
    let coll = s[0]
        .fractions
        .iter()
        .find(|f| f.outcome == "collision")
        .unwrap();
    assert_eq!(coll.count, 3);
    // Settle times 1..7: p10 = 1.6, p50 = 4, p90 = 6.4.
    assert_eq!(s[0].settled, 7);
    assert!(close(s[0].settle[0].unwrap(), 1.6) && close(s[0].settle[2].unwrap(), 6.4));
    assert_eq!(s[0].settle[1], Some(4.0));
    assert_eq!((s[1].n, s[1].settle[1]), (1, Some(5.0)));
    assert_eq!(s[2].n, 0);
    assert!(s[2].fractions[0].fraction.is_nan());
}
