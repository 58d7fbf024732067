//! The closest pair of agents, in expected linear time.

use controller_core::Vec2;

/// Exact minimum pairwise distance by sort-and-sweep on `x`: the order is kept between
/// calls (insertion sort on an almost sorted list), and the sweep stops as soon as the
/// `x` gap exceeds the best distance. Expected cost O(N) for spread-out formations;
/// worst case O(N²) when all agents share one `x`.
#[derive(Clone, Debug, Default)]
pub struct MinDistance {
    order: Vec<usize>,
}

impl MinDistance {
    /// For `n` agents.
    pub fn new(n: usize) -> Self {
        Self {
            order: (0..n).collect(),
        }
    }

    /// `(distance, i, j)` of the closest pair (`inf` with fewer than two agents).
    pub fn compute(&mut self, q: &[Vec2<f64>]) -> (f64, usize, usize) {
        let x = |i: usize| q.get(i).map_or(f64::NAN, |p| p.x);
        // Insertion sort by x (NaN sorts last through total_cmp).
        for k in 1..self.order.len() {
            let mut j = k;
            while j > 0 && x(self.order[j - 1]).total_cmp(&x(self.order[j])).is_gt() {
                self.order.swap(j - 1, j);
                j -= 1;
            }
        }
        let mut best = (f64::INFINITY, 0, 0);
        for (a, &i) in self.order.iter().enumerate() {
            for &j in self.order.iter().skip(a + 1) {
                if x(j) - x(i) >= best.0 {
                    break;
                }
                let d = (q[j] - q[i]).norm();
                if d < best.0 {
                    best = (d, i.min(j), i.max(j));
                }
            }
        }
        best
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
            for p in &mut q {
                p.x += 0.3 * p.y.sin();
            }
        }
    }
}
