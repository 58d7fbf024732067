//! The axes of a sweep: each checked (key, values or range), the points laid out (every
//! combination on a grid, or random draws), and every point checked against the base
//! scenario before anything runs.

use super::error::{SweepError, INVALID};
use super::plan::{number, run_seed, Plan, MAX_POINTS, PERTURBATION};
use super::spec::{AxisSpec, Sampling, SweepFile, SweepSource};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

/// Each axis' values: a list, or a range (grid: `steps` evenly spaced values).
pub(super) enum Values {
    List(Vec<toml::Value>),
    Range(f64, f64),
}

pub(super) fn check_axes(
    src: &SweepSource,
    f: &SweepFile,
    perturbed: bool,
) -> Result<Vec<Values>, SweepError> {
    let file = src.label.as_str();
    let bad = |field: String, reason: String| Err(SweepError::new(INVALID, file, &field, reason));
    let mut out = Vec::new();
    for (i, a) in f.axes.iter().enumerate() {
        let field = |x: &str| format!("axes[{i}].{x}");
        check_key(file, i, a, f, perturbed)?;
        let values = match (&a.values, a.from, a.to) {
            (Some(v), None, None) if a.steps.is_none() => {
                if v.is_empty() {
                    return bad(field("values"), "must not be empty".to_owned());
                }
                Values::List(v.clone())
            }
            (None, Some(lo), Some(hi)) => {
                if !(lo.is_finite() && hi.is_finite() && lo <= hi) {
                    return bad(
                        field("to"),
                        format!("needs finite from ≤ to, got {lo} and {hi}"),
                    );
                }
                match (f.sampling, a.steps) {
                    (Sampling::Grid, Some(n)) if (2..=MAX_POINTS).contains(&n) => Values::List(
                        (0..n)
                            .map(|k| toml::Value::Float(lo + (hi - lo) * k as f64 / (n - 1) as f64))
                            .collect(),
                    ),
                    (Sampling::Grid, _) => {
                        return bad(
                            field("steps"),
                            "a range on a grid needs steps ≥ 2".to_owned(),
                        )
                    }
                    (Sampling::Random, None) => Values::Range(lo, hi),
                    (Sampling::Random, Some(_)) => {
                        return bad(
                            field("steps"),
                            "random sampling draws from the range: no steps".to_owned(),
                        )
                    }
                }
            }
            _ => {
                return bad(
                    format!("axes[{i}]"),
                    "give either `values = [...]` or `from`, `to` (and `steps` on a grid)"
                        .to_owned(),
                )
            }
        };
        if a.key == PERTURBATION {
            let ok = |v: &toml::Value| number(v).is_some_and(|x| (0.0..=1.0).contains(&x));
            let fine = match &values {
                Values::List(v) => v.iter().all(ok),
                Values::Range(lo, hi) => (0.0..=1.0).contains(lo) && (0.0..=1.0).contains(hi),
            };
            if !fine {
                return bad(
                    field("values"),
                    "perturbation fractions must be numbers in [0, 1]".to_owned(),
                );
            }
        }
        out.push(values);
    }
    Ok(out)
}

fn check_key(
    file: &str,
    i: usize,
    a: &AxisSpec,
    f: &SweepFile,
    perturbed: bool,
) -> Result<(), SweepError> {
    let field = format!("axes[{i}].key");
    let bad = |reason: String| Err(SweepError::new(INVALID, file, &field, reason));
    let key = a.key.trim();
    if key.is_empty() || key.split('.').any(str::is_empty) {
        return bad(format!("`{}` is not a dotted key (e.g. radio.loss)", a.key));
    }
    if key == "seed" {
        return bad("the seed is not an axis: every run's seed derives from the sweep's `seed` (use `runs`)".to_owned());
    }
    if key == PERTURBATION && !perturbed {
        return bad("the perturbation axis needs a [perturbation] section".to_owned());
    }
    if let Some(j) = f.axes[..i].iter().position(|b| b.key.trim() == key) {
        return bad(format!("`{key}` is already axes[{j}]"));
    }
    Ok(())
}

pub(super) fn lay_out(
    file: &str,
    f: &SweepFile,
    axes: &[Values],
) -> Result<Vec<Vec<toml::Value>>, SweepError> {
    match f.sampling {
        Sampling::Grid => {
            if f.points.is_some() {
                return Err(SweepError::new(
                    INVALID,
                    file,
                    "points",
                    "only for sampling = \"random\" (a grid has every combination)",
                ));
            }
            let mut points: Vec<Vec<toml::Value>> = vec![Vec::new()];
            for a in axes {
                let Values::List(vs) = a else { continue };
                if points.len() as u64 * vs.len() as u64 > MAX_POINTS {
                    return Err(SweepError::new(
                        INVALID,
                        file,
                        "axes",
                        format!("more than {MAX_POINTS} points"),
                    ));
                }
                points = points
                    .into_iter()
                    .flat_map(|p| {
                        vs.iter().map(move |v| {
                            let mut q = p.clone();
                            q.push(v.clone());
                            q
                        })
                    })
                    .collect();
            }
            Ok(points)
        }
        Sampling::Random => {
            let n = match f.points {
                Some(n) if (1..=MAX_POINTS).contains(&n) => n,
                other => {
                    return Err(SweepError::new(
                        INVALID,
                        file,
                        "points",
                        format!("random sampling needs points = 1 to {MAX_POINTS}, got {other:?}"),
                    ))
                }
            };
            Ok((0..n)
                .map(|p| {
                    let mut rng = ChaCha8Rng::seed_from_u64(run_seed(f.seed, p, u64::MAX));
                    axes.iter()
                        .map(|a| match a {
                            Values::List(v) => v[rng.random_range(0..v.len())].clone(),
                            Values::Range(lo, hi) => {
                                toml::Value::Float(lo + (hi - lo) * rng.random::<f64>())
                            }
                        })
                        .collect()
                })
                .collect())
        }
    }
}

/// Every point must give a valid scenario: an axis value alone first (the error names
/// it), then each combination.
pub(super) fn check_points(plan: &Plan) -> Result<(), SweepError> {
    let file = plan.label.as_str();
    for (i, key) in plan.axes.iter().enumerate() {
        if key == PERTURBATION {
            continue;
        }
        let mut seen: Vec<&toml::Value> = Vec::new();
        for p in &plan.points {
            let v = &p[i];
            if seen.contains(&v) {
                continue;
            }
            seen.push(v);
            let mut o = plan.base.set.clone();
            o.push(format!("{key}={v}"));
            plan.model(&o).map_err(|e| {
                SweepError::scenario(
                    file,
                    &format!("axes[{i}].values"),
                    &format!("with {key} = {v}"),
                    &e,
                )
            })?;
        }
    }
    for (p, _) in plan.points.iter().enumerate() {
        plan.model(&plan.overrides(p, None)).map_err(|e| {
            SweepError::scenario(
                file,
                "axes",
                &format!("at point {p} ({})", plan.overrides(p, None).join(", ")),
                &e,
            )
        })?;
    }
    Ok(())
}
