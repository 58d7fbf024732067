//! The closest pair of agents, in expected linear time.

use ph_formation_core::Vec2;
use rayon::prelude::*;

/// Exact minimum pairwise distance on a uniform grid: agents are keyed by their cell
/// `(⌊x/h⌋, ⌊y/h⌋)` and sorted, and each agent is compared with the agents of its own and
/// the next cells (the half-neighbourhood: every pair once). Two agents closer than `h`
/// are in neighbouring cells, so when the closest pair found is within `h` it is the
/// closest of all; otherwise `h` doubles and the search repeats. `h` follows the answer
/// (1.5 × the last distance, again when the answer falls below `h / 2`), so a call costs
/// O(N) plus the pairs in neighbouring cells, for lines, lattices or any spread of the
/// agents (a sweep along `x` alone costs O(N √N) on a 2-D lattice, whose columns share
/// one `x`). The key vector is reused (no allocation) and kept in the last call's order:
/// with the same `h`, only the agents that changed cell are out of order, and sorting
/// them by insertion takes about linear time. Equal distances go to the smallest pair
/// `(i, j)`, whatever the order of the search.
///
/// When the caller asks (the diagnostics of a large formation), the cells, the extent and
/// the search run on every thread of the current rayon pool (the search in runs of
/// `SEARCH_CHUNK` (2,048) keys): the closest pair is the least `(distance, i, j)`, which
/// does not depend on the order it is found in, so the answer is the same on any number of
/// threads.
#[derive(Clone, Debug, Default)]
pub struct MinDistance {
    /// Cell size of the next call (0: not known yet).
    h: f64,
    /// `(cell x, cell y, agent)`, sorted.
    keys: Vec<(i64, i64, usize)>,
    /// The cell size `keys` was last sorted for (0: none).
    sorted_h: f64,
}

/// The smallest cell size the grid uses (m): coincident agents would otherwise shrink it
/// to zero.
const MIN_CELL: f64 = 1e-6;

/// Keys per task of a parallel search (and agents per task for the cells and the extent).
const SEARCH_CHUNK: usize = 2048;

/// No pair: what a search returns when it compares nothing.
const NO_PAIR: (f64, usize, usize) = (f64::INFINITY, 0, 0);

impl MinDistance {
    /// For `n` agents.
    pub fn new(n: usize) -> Self {
        Self {
            h: 0.0,
            keys: Vec::with_capacity(n),
            sorted_h: 0.0,
        }
    }

    /// `(distance, i, j)` of the closest pair, `i < j` (`inf` with fewer than two agents
    /// or when no distance is a number). `parallel`: on every thread of the current rayon
    /// pool (the same answer).
    pub fn compute(&mut self, q: &[Vec2<f64>], parallel: bool) -> (f64, usize, usize) {
        let none = NO_PAIR;
        if q.len() < 2 {
            return none;
        }
        let side = extent(q, parallel);
        let mut h = self.h;
        if !(h.is_finite() && h >= MIN_CELL) {
            h = (side / (q.len() as f64).sqrt()).max(MIN_CELL);
        }
        loop {
            let best = self.search(q, h, parallel);
            // Within h: exact. With h beyond the extent every pair of finite agents was
            // compared (they share neighbouring cells): exact too, or none is finite.
            if best.0 <= h || h >= side || !h.is_finite() {
                // The same cells next time while they still fit the answer (at most a
                // few agents per cell): the keys then stay nearly sorted between calls.
                let fits = best.0 <= h && best.0 >= 0.5 * h;
                self.h = if fits {
                    h
                } else {
                    (1.5 * best.0).max(MIN_CELL)
                };
                return if best.0.is_finite() { best } else { none };
            }
            h *= 2.0;
        }
    }

    /// The closest pair among agents in neighbouring cells of size `h`.
    fn search(&mut self, q: &[Vec2<f64>], h: f64, parallel: bool) -> (f64, usize, usize) {
        // `as` saturates (NaN → 0): such agents only give NaN distances, never the best.
        let cell = |p: &Vec2<f64>| ((p.x / h).floor() as i64, (p.y / h).floor() as i64);
        if self.keys.len() == q.len() {
            // The agents in the order of the last call, with their new cells.
            let recell = |k: &mut (i64, i64, usize)| (k.0, k.1) = cell(&q[k.2]);
            if parallel {
                let keys = self.keys.par_iter_mut().with_min_len(SEARCH_CHUNK);
                keys.for_each(recell);
            } else {
                self.keys.iter_mut().for_each(recell);
            }
        } else {
            let key = |(i, p): (usize, &Vec2<f64>)| {
                let (cx, cy) = cell(p);
                (cx, cy, i)
            };
            self.keys.clear();
            if parallel {
                self.keys.par_extend(q.par_iter().enumerate().map(key));
            } else {
                self.keys.extend(q.iter().enumerate().map(key));
            }
        }
        // With the cells of the last call, only the agents that changed cell are out of
        // order: insertion takes about linear time (keys are distinct, so every sort gives
        // the same order).
        let budget = 4 * self.keys.len();
        if self.sorted_h != h || !insertion_sort_within(&mut self.keys, budget) {
            if parallel {
                self.keys.par_sort_unstable();
            } else {
                self.keys.sort_unstable();
            }
        }
        self.sorted_h = h;
        let keys = &self.keys;
        if !parallel {
            return search_keys(keys, q, 0..keys.len());
        }
        let runs = keys.len().div_ceil(SEARCH_CHUNK);
        (0..runs)
            .into_par_iter()
            .map(|r| {
                let end = ((r + 1) * SEARCH_CHUNK).min(keys.len());
                search_keys(keys, q, r * SEARCH_CHUNK..end)
            })
            .reduce(|| NO_PAIR, least)
    }
}

/// The closest pair of the keys in `run` (sorted `keys`) with the agents of their own and
/// the next cells, as `(distance, i, j)`, `i < j`; [`NO_PAIR`] when no distance is a
/// number.
fn search_keys(
    keys: &[(i64, i64, usize)],
    q: &[Vec2<f64>],
    run: core::ops::Range<usize>,
) -> (f64, usize, usize) {
    let mut best = NO_PAIR;
    let mut consider = |i: usize, j: usize| {
        let (a, b) = (i.min(j), i.max(j));
        best = least(best, ((q[b] - q[a]).norm(), a, b));
    };
    let next_column = |(cx, cy): (i64, i64)| (cx.saturating_add(1), cy.saturating_sub(1));
    // Start of the next column's cells (cx + 1, ≥ cy − 1) for the run's first key; it only
    // moves forward, since the keys are sorted.
    let mut next = keys.get(run.start).map_or(keys.len(), |&(cx, cy, _)| {
        let from = next_column((cx, cy));
        keys.partition_point(|&(x, y, _)| (x, y) < from)
    });
    for k in run {
        let (cx, cy, i) = keys[k];
        // Own column: this cell after agent i, and the cell above.
        for &(ox, oy, j) in &keys[k + 1..] {
            if ox != cx || oy > cy.saturating_add(1) {
                break;
            }
            consider(i, j);
        }
        // Next column: cells cy − 1 ..= cy + 1 (none when the column saturated at
        // `i64::MAX`: `nx` would be this very column, agent i included).
        let (nx, lo) = next_column((cx, cy));
        if nx == cx {
            continue;
        }
        let hi = cy.saturating_add(1);
        while next < keys.len() && (keys[next].0, keys[next].1) < (nx, lo) {
            next += 1;
        }
        for &(ox, oy, j) in &keys[next..] {
            if ox != nx || oy > hi {
                break;
            }
            consider(i, j);
        }
    }
    best
}

/// The lesser of two pairs `(distance, i, j)`: the shorter distance, an equal one to the
/// smaller `(i, j)`. A NaN distance is never the lesser of a pair with a number, so the
/// least of many pairs does not depend on the order they are compared in.
fn least(a: (f64, usize, usize), b: (f64, usize, usize)) -> (f64, usize, usize) {
    if b.0 < a.0 || (b.0 == a.0 && (b.1, b.2) < (a.1, a.2)) {
        b
    } else {
        a
    }
}

/// Sorts `v` by insertion when that takes at most `budget` moves and returns `true`;
/// otherwise stops and returns `false`, with `v` still a permutation of itself.
fn insertion_sort_within<T: Ord + Copy>(v: &mut [T], budget: usize) -> bool {
    let mut moves = 0;
    for i in 1..v.len() {
        let x = v[i];
        let mut j = i;
        while j > 0 && v[j - 1] > x {
            v[j] = v[j - 1];
            j -= 1;
        }
        v[j] = x;
        moves += i - j;
        if moves > budget {
            return false;
        }
    }
    true
}

/// The larger side of the bounding box of the finite agents (0 for none, so that the
/// search stops at once). `parallel`: on every thread (minima and maxima are exact).
fn extent(q: &[Vec2<f64>], parallel: bool) -> f64 {
    type Bounds = (Vec2<f64>, Vec2<f64>);
    let empty = || -> Bounds { (Vec2::repeat(f64::INFINITY), Vec2::repeat(f64::NEG_INFINITY)) };
    let add = |(lo, hi): Bounds, p: &Vec2<f64>| -> Bounds {
        if p.x.is_finite() && p.y.is_finite() {
            (lo.inf(p), hi.sup(p))
        } else {
            (lo, hi)
        }
    };
    let (lo, hi) = if parallel {
        q.par_iter()
            .with_min_len(SEARCH_CHUNK)
            .fold(empty, add)
            .reduce(empty, |a, b| (a.0.inf(&b.0), a.1.sup(&b.1)))
    } else {
        q.iter().fold(empty(), add)
    };
    let side = (hi - lo).max();
    if side.is_finite() {
        side
    } else {
        0.0
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn min_distance_matches_brute_force() {
        let mut q: Vec<Vec2<f64>> = (0..50)
            .map(|i| {
                let f = f64::from(i);
                Vec2::new((f * 7.3) % 11.0, (f * 3.1) % 5.0)
            })
            .collect();
        let mut md = MinDistance::new(q.len());
        for round in 0..3 {
            let mut best = f64::INFINITY;
            for i in 0..q.len() {
                for j in i + 1..q.len() {
                    best = best.min((q[i] - q[j]).norm());
                }
            }
            assert_eq!(md.compute(&q, false).0, best, "round {round}");
            assert_eq!(brute(&q), md.compute(&q, false), "round {round}");
            for p in &mut q {
                p.x += 0.3 * p.y.sin();
            }
        }
    }

    /// Small moves over many calls (the cells kept, the keys sorted by insertion), a jump
    /// (the insertion budget exceeded), and a contraction (the cells re-sized): the brute
    /// force answer every time.
    #[test]
    fn small_moves_jumps_and_contraction() {
        let mut md = MinDistance::new(0);
        let mut q: Vec<Vec2<f64>> = (0..300)
            .map(|k| Vec2::new(f64::from(k % 15) * 1.1, f64::from(k / 15)))
            .collect();
        for round in 0..40 {
            let f = f64::from(round);
            for (k, p) in q.iter_mut().enumerate() {
                let k = k as f64;
                *p += Vec2::new(0.05 * (k * 1.7 + f).sin(), 0.05 * (k * 0.9 - f).cos());
            }
            if round == 20 {
                q.reverse();
                q[17].x += 40.0;
            }
            if round >= 30 {
                q.iter_mut().for_each(|p| *p *= 0.8);
            }
            assert_eq!(md.compute(&q, false), brute(&q), "round {round}");
        }
    }

    #[test]
    fn insertion_sort_within_its_budget() {
        let mut v = [2, 1, 4, 3, 5, 7, 6, 0];
        assert!(insertion_sort_within(&mut v, 10));
        assert_eq!(v, [0, 1, 2, 3, 4, 5, 6, 7]);
        // Every permutation of five: sorted within a budget of the inversions (≤ 10).
        let mut p = [0u8, 1, 2, 3, 4];
        for k in 0..120u32 {
            let mut x = p;
            assert!(insertion_sort_within(&mut x, 10), "{p:?}");
            assert_eq!(x, [0, 1, 2, 3, 4], "{p:?}");
            p.swap(k as usize % 4, k as usize % 4 + 1);
            p.rotate_left((k % 3) as usize);
        }
        let mut w: Vec<u32> = (0..50).rev().collect();
        assert!(!insertion_sort_within(&mut w, 100));
        w.sort_unstable();
        assert_eq!(w, (0..50).collect::<Vec<_>>());
    }

    /// The closest pair by comparing every pair, ties to the smallest `(i, j)`.
    fn brute(q: &[Vec2<f64>]) -> (f64, usize, usize) {
        let mut best = (f64::INFINITY, 0, 0);
        for i in 0..q.len() {
            for j in i + 1..q.len() {
                let d = (q[j] - q[i]).norm();
                if d < best.0 {
                    best = (d, i, j);
                }
            }
        }
        best
    }

    /// A formation large enough to be searched on every thread (runs of keys, each with
    /// its own start in the next column, merged): on one, two and three threads the brute
    /// force's answer, through small moves, a closest pair on either side of a cell column
    /// (found from the next column, in a run in the middle), two closest pairs at exactly
    /// the same distance (the smaller indices win, although the search meets the other
    /// first), a lattice of ties, a coincident pair and a non-finite agent.
    #[test]
    fn a_parallel_search_gives_the_sequential_answer() {
        let n = 2 * SEARCH_CHUNK + 1500;
        let scatter = |k: usize| {
            let k = k as f64;
            Vec2::new(
                (k * 0.618_034).fract() * 90.0 - 45.0,
                (k * 0.414_214).fract() * 60.0,
            )
        };
        let mut q: Vec<Vec2<f64>> = (0..n).map(scatter).collect();
        let pools: Vec<rayon::ThreadPool> = [1, 2, 3]
            .iter()
            .map(|&t| {
                rayon::ThreadPoolBuilder::new()
                    .num_threads(t)
                    .build()
                    .expect("a pool")
            })
            .collect();
        let mut finders = vec![MinDistance::new(n); pools.len()];
        let tiny = 2f64.powi(-10);
        for round in 0..8 {
            match round {
                // Cells have an edge at x = 0 whatever their size.
                2 => {
                    q[1234] = Vec2::new(-1e-4, 7.3);
                    q[4321] = Vec2::new(1e-4, 7.3);
                }
                3 => {
                    q[1234] = scatter(1234);
                    q[4321] = scatter(4321);
                    // Exactly `tiny` apart, both; (10, 11) lies at the larger x.
                    q[10] = Vec2::new(30.0, 1.0);
                    q[11] = Vec2::new(30.0 + tiny, 1.0);
                    q[5000] = Vec2::new(-30.0, 1.0);
                    q[5001] = Vec2::new(-30.0 + tiny, 1.0);
                }
                // A lattice: every neighbour at exactly 0.5 m.
                4 => q
                    .iter_mut()
                    .enumerate()
                    .for_each(|(k, p)| *p = Vec2::new((k % 80) as f64, (k / 80) as f64) * 0.5),
                5 => q[n - 1] = q[3],
                6 => q[SEARCH_CHUNK + 7] = Vec2::new(f64::NAN, 0.0),
                _ => q.iter_mut().enumerate().for_each(|(k, p)| {
                    *p += Vec2::new(0.01 * (k as f64).sin(), 0.01 * (k as f64 * 1.3).cos());
                }),
            }
            let expected = brute(&q);
            match round {
                2 => assert_eq!(expected, (2e-4, 1234, 4321)),
                3 => assert_eq!(expected, (tiny, 10, 11)),
                _ => {}
            }
            for (pool, md) in pools.iter().zip(&mut finders) {
                let threads = pool.current_num_threads();
                assert_eq!(
                    pool.install(|| md.compute(&q, true)),
                    expected,
                    "round {round}, {threads} threads"
                );
            }
        }
    }

    /// An agent so far away that its cell column saturates at `i64::MAX` has no next
    /// column: it is never compared with itself (a distance 0 that would read as a
    /// collision).
    #[test]
    fn a_saturated_cell_is_not_its_own_neighbour() {
        let mut md = MinDistance::new(0);
        let mut q: Vec<Vec2<f64>> = (0..100)
            .map(|k| Vec2::new(f64::from(k % 10), f64::from(k / 10)))
            .collect();
        assert_eq!(md.compute(&q, false), brute(&q));
        q.iter_mut().for_each(|p| *p += Vec2::repeat(0.1));
        q[50] = Vec2::new(1e20, 3.0);
        let (d, i, j) = md.compute(&q, false);
        assert!(i < j, "({d}, {i}, {j})");
        assert_eq!((d, i, j), brute(&q));
    }

    /// A lattice (columns share one x: the case a sweep along x is slow on), pushed around
    /// over rounds so that the cell size must grow and shrink, with exact ties, a
    /// coincident pair and a non-finite agent.
    #[test]
    fn lattices_spreads_ties_and_bad_positions() {
        let mut md = MinDistance::new(0);
        let mut q: Vec<Vec2<f64>> = (0..400)
            .map(|k| Vec2::new(f64::from(k % 20), f64::from(k / 20)))
            .collect();
        assert_eq!(md.compute(&q, false), brute(&q));
        assert_eq!(md.compute(&q, false), (1.0, 0, 1));
        for p in &mut q {
            *p *= 7.0;
        }
        assert_eq!(md.compute(&q, false), brute(&q));
        q[399] = q[398] + Vec2::new(0.01, 0.0);
        assert_eq!(
            md.compute(&q, false),
            (0.01_f64.max((q[399] - q[398]).norm()), 398, 399)
        );
        q[5] = q[6];
        assert_eq!(md.compute(&q, false), (0.0, 5, 6));
        for (k, p) in q.iter_mut().enumerate() {
            *p *= 3.0 + (k as f64 * 0.37).sin();
        }
        assert_eq!(md.compute(&q, false), brute(&q));
        // Fewer agents than the last call, then all of them again.
        assert_eq!(md.compute(&q[..57], false), brute(&q[..57]));
        assert_eq!(md.compute(&q, false), brute(&q));
        q[7] = Vec2::new(f64::NAN, 1.0);
        let (d, i, j) = md.compute(&q, false);
        assert!(d.is_finite() && i != 7 && j != 7);
        assert_eq!(md.compute(&[Vec2::zeros()], false).0, f64::INFINITY);
    }
}
