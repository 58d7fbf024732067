//! A checked sweep: the base scenario resolved, every axis and point validated against it,
//! the points laid out (grid or random), and each run's seed derived.

use super::axes::{check_axes, check_points, lay_out};
use super::error::{SweepError, INVALID, SCHEMA};
use super::spec::{PerturbationSpec, Sampling, SweepFile, SweepSource};
use crate::api;
use crate::model::Model;
use crate::scenario::{ScenarioErrors, Source};
use rand::{RngCore, SeedableRng};
use rand_xoshiro::SplitMix64;

/// The axis key that varies the initial-shape perturbation instead of a scenario field.
pub const PERTURBATION: &str = "perturbation";
/// Most points a sweep may have.
pub const MAX_POINTS: u64 = 1_000_000;
/// Most runs a sweep may have.
pub const MAX_JOBS: u64 = 1_000_000_000;

/// The scenario every run starts from.
#[derive(Clone, Debug)]
pub struct Base {
    /// Where it came from (file path or `builtin:<name>`).
    pub label: String,
    /// Its TOML text (read once).
    pub text: String,
    /// Overrides applied to every run (`[base].set`).
    pub set: Vec<String>,
}

/// The checked perturbation: fraction (unless an axis gives it), rotation, reference.
#[derive(Clone, Debug, PartialEq)]
pub struct Perturb {
    /// Largest displacement / reference size, when no axis sets it.
    pub fraction: f64,
    /// Random rotation about the centroid.
    pub rotate: bool,
    /// Reference positions (agent order); `None`: the scenario's initial positions.
    pub shape: Option<Vec<[f64; 2]>>,
}

/// A sweep ready to run.
#[derive(Clone, Debug)]
pub struct Plan {
    /// Name (output folder `out/sweeps/<name>/`).
    pub name: String,
    /// Free text.
    pub description: String,
    /// The sweep file (or `builtin:<name>`).
    pub label: String,
    /// Sweep seed.
    pub seed: u64,
    /// Runs per point.
    pub runs: u64,
    /// Run `r` has the same seed at every point (common random numbers).
    pub common_seeds: bool,
    /// Grid or random.
    pub sampling: Sampling,
    /// The base scenario.
    pub base: Base,
    /// Initial-shape perturbation, if any.
    pub perturbation: Option<Perturb>,
    /// Axis keys, in file order.
    pub axes: Vec<String>,
    /// Each point's value on each axis.
    pub points: Vec<Vec<toml::Value>>,
    /// The command line's `--set` (also in `base.set`), kept for `--resume`.
    pub set: Vec<String>,
    /// Hash of the sweep text, the base text, seed and runs (shards must agree).
    pub fingerprint: String,
}

/// `splitmix64` (Steele, Lea & Flood 2014), a fixed, portable 64-bit mixer: the first
/// output of the generator whose state is `x` (`rand_xoshiro`'s, as the sensors' streams).
fn mix(x: u64) -> u64 {
    SplitMix64::seed_from_u64(x).next_u64()
}

/// The seed of run `run` at point `point`: `mix(mix(mix(seed) ^ point) ^ run) >> 1` (below
/// 2⁶³: TOML integers are signed). Independent of threads and shards.
pub fn run_seed(seed: u64, point: u64, run: u64) -> u64 {
    mix(mix(mix(seed) ^ point) ^ run) >> 1
}

/// FNV-1a, 64 bits, as 16 hex digits (identifies a sweep, not a security hash).
fn fingerprint(parts: &[&str]) -> String {
    let mut h: u64 = 0xcbf2_9ce4_8422_2325;
    for p in parts {
        for b in p.bytes().chain([0u8]) {
            h ^= u64::from(b);
            h = h.wrapping_mul(0x0100_0000_01b3);
        }
    }
    format!("{h:016x}")
}

/// An axis' values in the cells of `runs.csv` (strings without quotes).
pub fn cell(v: &toml::Value) -> String {
    match v {
        toml::Value::String(s) => s.clone(),
        other => other.to_string(),
    }
}

impl Plan {
    /// Reads, parses and checks a sweep (a file or a built-in name); `runs` replaces the
    /// file's runs per point.
    pub fn load(arg: &str, runs: Option<u64>) -> Result<Self, SweepError> {
        Self::load_with(arg, runs, &[])
    }

    /// As [`Plan::load`], with `set` appended to `[base].set` (the command line's
    /// `--set`; part of the fingerprint, so shards must be given the same).
    pub fn load_with(arg: &str, runs: Option<u64>, set: &[String]) -> Result<Self, SweepError> {
        let source = SweepSource::resolve(arg)?;
        let mut file = source.parse()?;
        file.base.set.extend(set.iter().cloned());
        let mut plan = check(&source, file, runs)?;
        plan.set = set.to_vec();
        Ok(plan)
    }

    /// Parses and checks a sweep's text.
    pub fn from_source(source: &SweepSource, runs: Option<u64>) -> Result<Self, SweepError> {
        let file = source.parse()?;
        check(source, file, runs)
    }

    /// Total number of runs.
    pub fn jobs(&self) -> u64 {
        self.points.len() as u64 * self.runs
    }

    /// Point and run index of job `j` (point-major order).
    pub fn job(&self, j: u64) -> (usize, u64) {
        ((j / self.runs) as usize, j % self.runs)
    }

    /// The scenario seed of run `r` at point `p`: [`run_seed`] of the sweep seed, `p` (0
    /// for every point with `common_seeds`) and `r`.
    pub fn seed_of(&self, p: usize, r: u64) -> u64 {
        run_seed(self.seed, if self.common_seeds { 0 } else { p as u64 }, r)
    }

    /// The perturbation fraction at point `p` (its axis, else the section's).
    pub fn fraction(&self, p: usize) -> Option<f64> {
        let base = self.perturbation.as_ref()?.fraction;
        Some(
            self.axes
                .iter()
                .position(|k| k == PERTURBATION)
                .and_then(|i| number(&self.points[p][i]))
                .unwrap_or(base),
        )
    }

    /// The overrides of point `p` (without perturbation) and, with `seed`, the run seed.
    pub fn overrides(&self, p: usize, seed: Option<u64>) -> Vec<String> {
        let mut v = self.base.set.clone();
        for (k, x) in self.axes.iter().zip(&self.points[p]) {
            if k != PERTURBATION {
                v.push(format!("{k}={x}"));
            }
        }
        if let Some(s) = seed {
            v.push(format!("seed={s}"));
        }
        v
    }

    /// Loads the base scenario with `overrides`.
    pub fn model(&self, overrides: &[String]) -> Result<Model, ScenarioErrors> {
        api::load_toml(&self.base.text, &self.base.label, overrides)
    }
}

pub(super) fn number(v: &toml::Value) -> Option<f64> {
    match v {
        toml::Value::Float(x) => Some(*x),
        toml::Value::Integer(i) => Some(*i as f64),
        _ => None,
    }
}

fn check(src: &SweepSource, f: SweepFile, runs: Option<u64>) -> Result<Plan, SweepError> {
    let file = src.label.as_str();
    let bad = |field: &str, reason: String| Err(SweepError::new(INVALID, file, field, reason));
    let runs = runs.unwrap_or(f.runs);
    if !(1..=MAX_JOBS).contains(&runs) {
        return bad("runs", format!("must be 1 to {MAX_JOBS}, got {runs}"));
    }
    let base = resolve_base(src, &f)?;
    let model = api::load_toml(&base.text, &base.label, &base.set).map_err(|e| {
        let field = if base.set.is_empty() {
            "base.scenario"
        } else {
            "base.set"
        };
        SweepError::scenario(file, field, "with [base]", &e)
    })?;
    let perturbation = f
        .perturbation
        .as_ref()
        .map(|p| check_perturbation(file, p, &model))
        .transpose()?;
    let axes = check_axes(src, &f, perturbation.is_some())?;
    let points = lay_out(file, &f, &axes)?;
    let keys: Vec<String> = f.axes.iter().map(|a| a.key.clone()).collect();
    let plan = Plan {
        name: f.name.clone().unwrap_or_else(|| src.default_name.clone()),
        description: f.description.clone().unwrap_or_default(),
        label: src.label.clone(),
        seed: f.seed,
        runs,
        common_seeds: f.common_seeds,
        sampling: f.sampling,
        set: Vec::new(),
        fingerprint: fingerprint(&[
            &src.text,
            &base.text,
            &f.seed.to_string(),
            &runs.to_string(),
            &f.base.set.join("\n"),
        ]),
        base,
        perturbation,
        axes: keys,
        points,
    };
    if plan.jobs() > MAX_JOBS {
        return bad(
            "runs",
            format!("{} runs in all, more than {MAX_JOBS}", plan.jobs()),
        );
    }
    check_points(&plan)?;
    Ok(plan)
}

fn resolve_base(src: &SweepSource, f: &SweepFile) -> Result<Base, SweepError> {
    let file = src.label.as_str();
    if f.base.design.is_some() {
        // The hook for a design generator as the base: `ph_formation_sim::design` renders a
        // scenario's TOML from a generator; the sweep would take that text here.
        return Err(SweepError::new(
            SCHEMA,
            file,
            "base.design",
            "a design generator as the base is not supported yet: render it with \
             `host-sim design` and give the file as `scenario`",
        ));
    }
    let Some(name) = &f.base.scenario else {
        return Err(SweepError::new(
            SCHEMA,
            file,
            "base.scenario",
            "missing: a scenario file or built-in name",
        ));
    };
    let near = src
        .dir
        .as_ref()
        .map(|d| d.join(name))
        .filter(|p| p.is_file());
    let source = match near {
        Some(p) => Source::from_file(&p),
        None => Source::resolve(name),
    }
    .map_err(|e| SweepError::new(e.kind.exit_code(), file, "base.scenario", e.reason))?;
    Ok(Base {
        label: source.label,
        text: source.text,
        set: f.base.set.clone(),
    })
}

fn check_perturbation(
    file: &str,
    p: &PerturbationSpec,
    model: &Model,
) -> Result<Perturb, SweepError> {
    let bad = |field: &str, reason: String| Err(SweepError::new(INVALID, file, field, reason));
    if !(p.fraction.is_finite() && (0.0..=1.0).contains(&p.fraction)) {
        return bad(
            "perturbation.fraction",
            format!("must be in [0, 1], got {}", p.fraction),
        );
    }
    if let Some(s) = &p.shape {
        if s.len() != model.n() {
            return bad(
                "perturbation.shape",
                format!(
                    "has {} positions, the scenario {} agents",
                    s.len(),
                    model.n()
                ),
            );
        }
        if s.iter().flatten().any(|x| !x.is_finite()) {
            return bad(
                "perturbation.shape",
                "every coordinate must be finite".to_owned(),
            );
        }
    }
    let out = Perturb {
        fraction: p.fraction,
        rotate: p.rotate,
        shape: p.shape.clone(),
    };
    super::perturb::positions(model, &out, 0.0, 0)
        .map_err(|e| SweepError::new(INVALID, file, "perturbation.shape", e.to_string()))?;
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::{mix, run_seed};

    /// `mix` is the reference splitmix64 (Vigna's `splitmix64.c`: state 0 gives
    /// 0xE220A8397B1DCDAF), and run seeds are what they were with the mixer written out
    /// (the value below), so that a sweep file gives the same runs as before.
    #[test]
    fn seeds_follow_the_reference_splitmix64() {
        assert_eq!(mix(0), 0xE220_A839_7B1D_CDAF);
        assert_eq!(run_seed(7, 2, 1), 3_828_502_499_322_697_697);
    }
}
