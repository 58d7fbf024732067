//! `--shard K/N`: a deterministic share of a sweep's jobs, for running one sweep as N
//! independent processes (a Slurm job array, GNU parallel) and merging their outputs.

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

impl Shard {
    /// The whole sweep.
    pub const ALL: Shard = Shard { k: 1, n: 1 };

    /// The jobs of this shard among `total`, ascending.
    pub fn jobs(self, total: u64) -> impl Iterator<Item = u64> {
        (self.k - 1..total).step_by(self.n as usize)
    }

    /// Whether this is the whole sweep.
    pub fn is_all(self) -> bool {
        self.n == 1
    }
}

impl FromStr for Shard {
    type Err = String;

    fn from_str(s: &str) -> Result<Self, String> {
        let bad = || format!("expected K/N with 1 ≤ K ≤ N (e.g. 2/8), got `{s}`");
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
