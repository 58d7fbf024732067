//! The order in which a sweep runs its jobs: interleaved over the points, so that a sweep
//! stopped part-way (Ctrl-C, SIGTERM, a time limit, `--max-runs`) has about as many runs
//! at every point. `runs.csv` is still written in job order (point-major) at the end
//! (`journal.rs`), so the order does not change any output.
//!
//! The runs of each point are cut into at most [`ROUNDS`] blocks of `B = ⌈runs / ROUNDS⌉`
//! consecutive runs; round `b` runs block `b` of every point, point after point. A
//! partial sweep therefore differs by at most `B` runs between points (1 up to 256 runs
//! per point), and the rows of one round are in job order: a run's `runs.csv` is at most
//! [`ROUNDS`] + 1 sorted stretches, merged in bounded memory.

use super::shard::Shard;

/// Most rounds a sweep's runs are cut into (bounds the sorted stretches of a journal).
pub const ROUNDS: u64 = 256;

/// Runs per point and round: `⌈runs / ROUNDS⌉`.
pub fn block(runs: u64) -> u64 {
    runs.div_ceil(ROUNDS).max(1)
}

/// The jobs (`j = point·runs + run`) of `shard` in execution order, lazily.
pub fn jobs(points: u64, runs: u64, shard: Shard) -> impl Iterator<Item = u64> {
    let b = block(runs);
    let rounds = runs.div_ceil(b);
    (0..rounds).flat_map(move |round| {
        (0..points).flat_map(move |p| {
            let lo = round * b;
            let hi = (lo + b).min(runs);
            (lo..hi)
                .map(move |r| p * runs + r)
                .filter(move |&j| shard.has(j))
        })
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_job_once_interleaved() {
        let s = Shard::ALL;
        let order: Vec<u64> = jobs(3, 2, s).collect();
        assert_eq!(
            order,
            [0, 2, 4, 1, 3, 5],
            "run 0 of every point, then run 1"
        );
        for (points, runs) in [(1, 1), (7, 100), (3, 130), (2, 64)] {
            for shard in [Shard::ALL, Shard { k: 2, n: 3 }] {
                let mut got: Vec<u64> = jobs(points, runs, shard).collect();
                got.sort_unstable();
                let want: Vec<u64> = shard.jobs(points * runs).collect();
                assert_eq!(got, want, "{points} × {runs} {shard}");
                assert_eq!(shard.count(points * runs), want.len() as u64);
            }
        }
        // 100 runs at 7 points (block 1): after 40 jobs the points have 5 or 6 runs; 1000
        // runs (block 4): after 100 jobs, 12 to 16.
        let mut per_point = [0; 7];
        for j in jobs(7, 100, Shard::ALL).take(40) {
            per_point[(j / 100) as usize] += 1;
        }
        let (lo, hi) = (per_point.iter().min(), per_point.iter().max());
        assert_eq!((lo, hi), (Some(&5), Some(&6)), "{per_point:?}");
        assert_eq!(block(1000), 4);
        let mut per_point = [0; 7];
        for j in jobs(7, 1000, Shard::ALL).take(100) {
            per_point[(j / 1000) as usize] += 1;
        }
        let (lo, hi) = (per_point.iter().min(), per_point.iter().max());
        assert_eq!((lo, hi), (Some(&12), Some(&16)), "{per_point:?}");
    }
}
