//! Running a sweep's jobs: each job (point, run) loads the base scenario with the point's
//! overrides and its own seed, perturbs the initial shape if asked, and runs it in memory
//! through the library API. Jobs run in parallel on rayon's pool; the rows come back in job
//! order whatever the number of threads.

use super::perturb;
use super::plan::Plan;
use super::shard::Shard;
use crate::api::Simulation;
use rayon::prelude::*;
use std::sync::atomic::{AtomicBool, Ordering};

/// The outcome name of a run that could not be made (its reason says why).
pub const ERROR: &str = "error";

/// One finished run: what `runs.csv` holds (besides the point's axis values).
#[derive(Clone, Debug, PartialEq)]
pub struct RunRow {
    /// Point index.
    pub point: usize,
    /// Run index within the point.
    pub run: u64,
    /// The scenario seed of the run ([`Plan::seed_of`]).
    pub seed: u64,
    /// The outcome's name (`summary.json`), or [`ERROR`].
    pub outcome: String,
    /// Settle time (s), if every angle settled.
    pub settle_time: Option<f64>,
    /// Time of the last evaluated instant (s).
    pub final_time: f64,
    /// Final `max |α − α*|` (rad).
    pub final_max_angle_error: f64,
    /// Final `|z − z*|` (m).
    pub final_displacement_error: f64,
    /// Final `max_n |v_n − v*|` (m/s).
    pub final_velocity_error: f64,
    /// Smallest inter-agent distance (m).
    pub min_distance: f64,
    /// Smallest estimate.
    pub min_estimate: Option<f64>,
    /// `V(0)`.
    pub v0: f64,
    /// Final `V`.
    pub v_final: f64,
    /// Rotation of the initial shape (degrees), when perturbed.
    pub rotation_deg: Option<f64>,
    /// Agents whose displacement was shortened, when perturbed.
    pub shortened: Option<u64>,
    /// The outcome's reason.
    pub reason: String,
}

impl RunRow {
    fn error(point: usize, run: u64, seed: u64, reason: String) -> Self {
        Self {
            point,
            run,
            seed,
            outcome: ERROR.to_owned(),
            settle_time: None,
            final_time: f64::NAN,
            final_max_angle_error: f64::NAN,
            final_displacement_error: f64::NAN,
            final_velocity_error: f64::NAN,
            min_distance: f64::NAN,
            min_estimate: None,
            v0: f64::NAN,
            v_final: f64::NAN,
            rotation_deg: None,
            shortened: None,
            reason,
        }
    }
}

/// Runs job `j` of `plan`.
pub fn run_job(plan: &Plan, j: u64) -> RunRow {
    let (p, r) = plan.job(j);
    let seed = plan.seed_of(p, r);
    let mut overrides = plan.overrides(p, Some(seed));
    let model = match plan.model(&overrides) {
        Ok(m) => m,
        Err(e) => return RunRow::error(p, r, seed, e.to_string()),
    };
    let mut shape = None;
    let model = match (&plan.perturbation, plan.fraction(p)) {
        (Some(pert), Some(fraction)) => {
            let s = match perturb::positions(&model, pert, fraction, seed) {
                Ok(s) => s,
                Err(e) => return RunRow::error(p, r, seed, format!("perturbation: {e}")),
            };
            overrides.extend(perturb::overrides(&s.positions));
            shape = Some(s);
            match plan.model(&overrides) {
                Ok(m) => m,
                Err(e) => return RunRow::error(p, r, seed, e.to_string()),
            }
        }
        _ => model,
    };
    let run = match Simulation::new(&model).keep_series(false).run() {
        Ok(run) => run,
        Err(e) => return RunRow::error(p, r, seed, e.to_string()),
    };
    let x = run.result;
    RunRow {
        point: p,
        run: r,
        seed,
        outcome: x.outcome.as_str().to_owned(),
        settle_time: x.settle_time,
        final_time: x.final_time,
        final_max_angle_error: x.final_max_angle_error,
        final_displacement_error: x.final_displacement_error,
        final_velocity_error: x.final_velocity_error,
        min_distance: x.min_distance.0,
        min_estimate: x.min_estimate,
        v0: x.v0,
        v_final: x.v_final,
        rotation_deg: shape.as_ref().map(|s| s.rotation.to_degrees()),
        shortened: shape.as_ref().map(|s| s.shortened as u64),
        reason: x.reason,
    }
}

/// What a (possibly interrupted) sweep produced.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Finished {
    /// The finished runs, in job order.
    pub rows: Vec<RunRow>,
    /// Jobs of this shard.
    pub jobs: u64,
    /// Whether it was stopped before every job ran.
    pub interrupted: bool,
}

/// Runs the jobs of `shard` on the current rayon pool, every row in memory (for small
/// sweeps and tests; the command streams them: [`super::execute()`]) (`ThreadPool::install` picks
/// another). Once `stop` is set no new job starts (the running ones finish and are kept).
/// `done` is called after each run, from the worker thread.
pub fn run_all(
    plan: &Plan,
    shard: Shard,
    stop: &AtomicBool,
    done: &(dyn Fn(&RunRow) + Sync),
) -> Finished {
    let jobs: Vec<u64> = shard.jobs(plan.jobs()).collect();
    let rows: Vec<Option<RunRow>> = jobs
        .par_iter()
        .map(|&j| {
            if stop.load(Ordering::Relaxed) {
                return None;
            }
            let row = run_job(plan, j);
            done(&row);
            Some(row)
        })
        .collect();
    let total = rows.len() as u64;
    let rows: Vec<RunRow> = rows.into_iter().flatten().collect();
    Finished {
        interrupted: (rows.len() as u64) < total,
        jobs: total,
        rows,
    }
}
