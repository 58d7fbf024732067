//! The closest pair of agents, in expected linear time.

use controller_core::Vec2;

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
    /// or when no distance is a number).
    pub fn compute(&mut self, q: &[Vec2<f64>]) -> (f64, usize, usize) {
        let none = (f64::INFINITY, 0, 0);
        if q.len() < 2 {
            return none;
        }
        let side = extent(q);
        let mut h = self.h;
        if !(h.is_finite() && h >= MIN_CELL) {
            h = (side / (q.len() as f64).sqrt()).max(MIN_CELL);
        }
        loop {
            let best = self.search(q, h);
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
    fn search(&mut self, q: &[Vec2<f64>], h: f64) -> (f64, usize, usize) {
        // `as` saturates (NaN → 0): such agents only give NaN distances, never the best.
        let cell = |p: &Vec2<f64>| ((p.x / h).floor() as i64, (p.y / h).floor() as i64);
        if self.keys.len() == q.len() {
            // The agents in the order of the last call, with their new cells.
            for k in &mut self.keys {
                (k.0, k.1) = cell(&q[k.2]);
            }
        } else {
            self.keys.clear();
            self.keys.extend(q.iter().enumerate().map(|(i, p)| {
                let (cx, cy) = cell(p);
                (cx, cy, i)
            }));
        }
        // With the cells of the last call, only the agents that changed cell are out of
        // order: insertion takes about linear time (keys are distinct, so every sort gives
        // the same order).
        let budget = 4 * self.keys.len();
        if self.sorted_h != h || !insertion_sort_within(&mut self.keys, budget) {
            self.keys.sort_unstable();
        }
        self.sorted_h = h;
        let keys = &self.keys;
        let mut best = (f64::INFINITY, 0, 0);
        let mut consider = |i: usize, j: usize| {
            let (a, b) = (i.min(j), i.max(j));
            let d = (q[b] - q[a]).norm();
            if d < best.0 || (d == best.0 && (a, b) < (best.1, best.2)) {
                best = (d, a, b);
            }
        };
        // Start of the next column's cells (cx + 1, ≥ cy − 1): only moves forward.
        let mut next = 0;
        for (k, &(cx, cy, i)) in keys.iter().enumerate() {
            // Own column: this cell after agent i, and the cell above.
            for &(ox, oy, j) in &keys[k + 1..] {
                if ox != cx || oy > cy.saturating_add(1) {
                    break;
                }
                consider(i, j);
            }
            // Next column: cells cy − 1 ..= cy + 1.
            let (nx, lo, hi) = (
                cx.saturating_add(1),
                cy.saturating_sub(1),
                cy.saturating_add(1),
            );
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
/// search stops at once).
fn extent(q: &[Vec2<f64>]) -> f64 {
    let (mut lo, mut hi) = (Vec2::repeat(f64::INFINITY), Vec2::repeat(f64::NEG_INFINITY));
    for p in q.iter().filter(|p| p.x.is_finite() && p.y.is_finite()) {
        lo = lo.inf(p);
        hi = hi.sup(p);
    }
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
            assert_eq!(md.compute(&q).0, best, "round {round}");
            assert_eq!(brute(&q), md.compute(&q), "round {round}");
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
            assert_eq!(md.compute(&q), brute(&q), "round {round}");
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

    /// A lattice (columns share one x: the case a sweep along x is slow on), pushed around
    /// over rounds so that the cell size must grow and shrink, with exact ties, a
    /// coincident pair and a non-finite agent.
    #[test]
    fn lattices_spreads_ties_and_bad_positions() {
        let mut md = MinDistance::new(0);
        let mut q: Vec<Vec2<f64>> = (0..400)
            .map(|k| Vec2::new(f64::from(k % 20), f64::from(k / 20)))
            .collect();
        assert_eq!(md.compute(&q), brute(&q));
        assert_eq!(md.compute(&q), (1.0, 0, 1));
        for p in &mut q {
            *p *= 7.0;
        }
        assert_eq!(md.compute(&q), brute(&q));
        q[399] = q[398] + Vec2::new(0.01, 0.0);
        assert_eq!(
            md.compute(&q),
            (0.01_f64.max((q[399] - q[398]).norm()), 398, 399)
        );
        q[5] = q[6];
        assert_eq!(md.compute(&q), (0.0, 5, 6));
        for (k, p) in q.iter_mut().enumerate() {
            *p *= 3.0 + (k as f64 * 0.37).sin();
        }
        assert_eq!(md.compute(&q), brute(&q));
        // Fewer agents than the last call, then all of them again.
        assert_eq!(md.compute(&q[..57]), brute(&q[..57]));
        assert_eq!(md.compute(&q), brute(&q));
        q[7] = Vec2::new(f64::NAN, 1.0);
        let (d, i, j) = md.compute(&q);
        assert!(d.is_finite() && i != 7 && j != 7);
        assert_eq!(md.compute(&[Vec2::zeros()]).0, f64::INFINITY);
    }
}
