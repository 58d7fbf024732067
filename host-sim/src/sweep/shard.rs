//! `--shard K/N` and `--shard auto`: a deterministic share of a sweep's jobs, for running
//! one sweep as N independent processes (a Slurm job array, a Kubernetes Indexed Job, GNU
//! parallel) and merging their outputs.

use std::fmt;
use std::str::FromStr;

/// Shard `k` of `n` (1-based): jobs `j` with `j mod n = k − 1`, so every shard gets runs of
/// every point and the shards are about equally long.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Shard {
    /// This shard, `1..=n`.
    pub k: u64,
    /// Number of shards.
    pub n: u64,
}

/// Why a `--shard` value or the batch system's variables name no shard.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum ShardError {
    /// `--shard` is neither `K/N` with 1 ≤ K ≤ N nor `auto`.
    Syntax(String),
    /// `--shard auto` found no batch system's variables.
    NoBatchSystem,
    /// A variable is not a number.
    NotANumber {
        /// The variable.
        var: &'static str,
        /// Its value.
        value: String,
    },
    /// The variables (or `--shards`) contradict each other; the sentence says how.
    Inconsistent(String),
}

impl fmt::Display for ShardError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::Syntax(s) => write!(
                f,
                "expected K/N with 1 ≤ K ≤ N (e.g. 2/8) or `auto`, got `{s}`"
            ),
            Self::NoBatchSystem => write!(
                f,
                "--shard auto: neither SLURM_ARRAY_TASK_ID (a Slurm job array) nor \
                 JOB_COMPLETION_INDEX (a Kubernetes Indexed Job) is set"
            ),
            Self::NotANumber { var, value } => {
                write!(f, "--shard auto: {var} is `{value}`, not a whole number")
            }
            Self::Inconsistent(s) => write!(f, "--shard auto: {s}"),
        }
    }
}

impl std::error::Error for ShardError {}

/// The value of `--shard`: a fixed share, or `auto` (from the batch system's variables).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ShardArg {
    /// `K/N`.
    Fixed(Shard),
    /// `auto`: [`Shard::from_env`].
    Auto,
}

impl FromStr for ShardArg {
    type Err = ShardError;

    fn from_str(s: &str) -> Result<Self, ShardError> {
        if s.trim() == "auto" {
            Ok(Self::Auto)
        } else {
            s.parse().map(Self::Fixed)
        }
    }
}

impl Shard {
    /// The whole sweep.
    pub const ALL: Shard = Shard { k: 1, n: 1 };

    /// The jobs of this shard among `total`, ascending.
    pub fn jobs(self, total: u64) -> impl Iterator<Item = u64> {
        (self.k - 1..total).step_by(self.n as usize)
    }

    /// Whether job `j` belongs to this shard.
    pub fn has(self, j: u64) -> bool {
        j % self.n == self.k - 1
    }

    /// How many of `total` jobs this shard has.
    pub fn count(self, total: u64) -> u64 {
        total / self.n + u64::from(total % self.n >= self.k)
    }

    /// Whether this is the whole sweep.
    pub fn is_all(self) -> bool {
        self.n == 1
    }

    /// `--shard auto`: the shard from the batch system's variables, read through `var`
    /// (`std::env::var` in the program):
    ///
    /// * Slurm job array: `SLURM_ARRAY_TASK_ID`. Without `shards`, the array is the sweep:
    ///   `N = SLURM_ARRAY_TASK_COUNT`, `K = ID − SLURM_ARRAY_TASK_MIN + 1` (so `--array=0-7`
    ///   and `--array=1-8` both work), and the array must be contiguous (`MAX − MIN + 1 =
    ///   COUNT`). With `shards = N`, `K = ID` must be in `1..=N`: one task of the array can
    ///   then be resubmitted alone (`sbatch --array=5`).
    /// * Kubernetes Indexed Job: `JOB_COMPLETION_INDEX` (0-based) with `shards = N`
    ///   (`completions`): `K = index + 1`.
    pub fn from_env(
        shards: Option<u64>,
        var: impl Fn(&str) -> Option<String>,
    ) -> Result<Shard, ShardError> {
        let num = |name: &'static str| -> Result<Option<u64>, ShardError> {
            match var(name) {
                None => Ok(None),
                Some(v) => v
                    .trim()
                    .parse()
                    .map(Some)
                    .map_err(|_| ShardError::NotANumber {
                        var: name,
                        value: v,
                    }),
            }
        };
        let bad = |s: String| Err(ShardError::Inconsistent(s));
        if shards == Some(0) {
            return bad("--shards must be at least 1".to_owned());
        }
        if let Some(id) = num("SLURM_ARRAY_TASK_ID")? {
            if let Some(n) = shards {
                if !(1..=n).contains(&id) {
                    return bad(format!(
                        "SLURM_ARRAY_TASK_ID = {id} with --shards {n}: the array's task ids \
                         must be 1 to {n} (sbatch --array=1-{n})"
                    ));
                }
                return Ok(Shard { k: id, n });
            }
            let need = |name: &'static str| {
                num(name)?.ok_or_else(|| {
                    ShardError::Inconsistent(format!(
                        "SLURM_ARRAY_TASK_ID is set but {name} is not (give --shards N)"
                    ))
                })
            };
            let (count, min, max) = (
                need("SLURM_ARRAY_TASK_COUNT")?,
                need("SLURM_ARRAY_TASK_MIN")?,
                need("SLURM_ARRAY_TASK_MAX")?,
            );
            if count == 0 || max < min || max - min + 1 != count || !(min..=max).contains(&id) {
                return bad(format!(
                    "the job array is not one contiguous range containing its task \
                     (SLURM_ARRAY_TASK_ID = {id}, MIN = {min}, MAX = {max}, COUNT = {count}): \
                     submit --array=1-N, or give --shards N with task ids 1 to N"
                ));
            }
            return Ok(Shard {
                k: id - min + 1,
                n: count,
            });
        }
        if let Some(index) = num("JOB_COMPLETION_INDEX")? {
            let Some(n) = shards else {
                return bad(
                    "JOB_COMPLETION_INDEX is set: give the number of shards (the Job's \
                     `completions`) with --shards N"
                        .to_owned(),
                );
            };
            if index >= n {
                return bad(format!(
                    "JOB_COMPLETION_INDEX = {index} is not below --shards {n}"
                ));
            }
            return Ok(Shard { k: index + 1, n });
        }
        Err(ShardError::NoBatchSystem)
    }
}

impl FromStr for Shard {
    type Err = ShardError;

    fn from_str(s: &str) -> Result<Self, ShardError> {
        let bad = || ShardError::Syntax(s.to_owned());
        let (k, n) = s.split_once('/').ok_or_else(bad)?;
        let k: u64 = k.trim().parse().map_err(|_| bad())?;
        let n: u64 = n.trim().parse().map_err(|_| bad())?;
        if k == 0 || n == 0 || k > n || n > u64::from(u32::MAX) {
            return Err(bad());
        }
        Ok(Shard { k, n })
    }
}

impl fmt::Display for Shard {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}/{}", self.k, self.n)
    }
}
