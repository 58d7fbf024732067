//! Occlusion: every agent is a disc of radius `ρ`, and a disc closer than a neighbour that
//! crosses the line of sight hides it. Agent `j` is hidden from agent `i` when some other
//! agent `k` (`k ≠ i, j`) with `|q_k − q_i| < |q_j − q_i|` lies closer than `ρ` to the
//! segment `q_i q_j`.
//!
//! The candidates `k` come from an R*-tree of the agents' positions (`rstar`, already the
//! design's spatial index), bulk-loaded once per control tick (`O(N log N)`) and queried
//! with the segment's bounding box grown by `ρ` (`O(log N)` plus the agents near the
//! segment): a tick's occlusion tests cost about linear time in `N` for a formation whose
//! neighbours are near each other.

use ph_formation_core::Vec2;
use rstar::primitives::GeomWithData;
use rstar::{RTree, AABB};

/// A position with its agent's index.
type Body = GeomWithData<[f64; 2], usize>;

/// The agents' bodies at one tick.
#[derive(Debug)]
pub(crate) struct Occluders {
    /// `ρ` (m, > 0).
    radius: f64,
    tree: RTree<Body>,
}

impl Occluders {
    /// No bodies yet, of radius `radius`.
    pub(crate) fn new(radius: f64) -> Self {
        Self {
            radius,
            tree: RTree::new(),
        }
    }

    /// The bodies at positions `q`.
    pub(crate) fn rebuild(&mut self, q: &[Vec2<f64>]) {
        let bodies = q
            .iter()
            .enumerate()
            .filter(|(_, p)| p.x.is_finite() && p.y.is_finite())
            .map(|(k, p)| Body::new([p.x, p.y], k))
            .collect();
        self.tree = RTree::bulk_load(bodies);
    }

    /// Whether agent `j` is hidden from agent `i` at positions `q` (those of the last
    /// [`Self::rebuild`]); `r = |q_j − q_i|`.
    pub(crate) fn hides(&self, q: &[Vec2<f64>], i: usize, j: usize, r: f64) -> bool {
        let (a, b) = (q[i], q[j]);
        let rho = self.radius;
        let lo = [a.x.min(b.x) - rho, a.y.min(b.y) - rho];
        let hi = [a.x.max(b.x) + rho, a.y.max(b.y) + rho];
        let d = b - a;
        let r2 = r * r;
        self.tree
            .locate_in_envelope(AABB::from_corners(lo, hi))
            .any(|body| {
                let k = body.data;
                let p = Vec2::new(body.geom()[0], body.geom()[1]);
                let ap = p - a;
                if k == i || k == j || ap.norm_squared() >= r2 {
                    return false;
                }
                // The point of the segment nearest to `p`.
                let t = (ap.dot(&d) / r2).clamp(0.0, 1.0);
                (ap - d * t).norm_squared() < rho * rho
            })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn bodies(q: &[Vec2<f64>], rho: f64) -> Occluders {
        let mut o = Occluders::new(rho);
        o.rebuild(q);
        o
    }

    #[test]
    fn a_closer_body_across_the_line_hides() {
        let mut q = vec![
            Vec2::new(0.0, 0.0),
            Vec2::new(1.0, 0.05),
            Vec2::new(2.0, 0.0),
        ];
        let o = bodies(&q, 0.1);
        assert!(o.hides(&q, 0, 2, 2.0));
        // Nothing hides the middle one, and the far one hides nothing (it is farther).
        assert!(!o.hides(&q, 0, 1, q[1].norm()));
        assert!(!o.hides(&q, 1, 0, q[1].norm()));
        // Off the line by more than ρ: seen.
        q[1].y = 0.11;
        assert!(!bodies(&q, 0.1).hides(&q, 0, 2, 2.0));
        // Beyond the target, within ρ of the line's extension: not between, not closer.
        q[1] = Vec2::new(2.05, 0.0);
        assert!(!bodies(&q, 0.1).hides(&q, 0, 2, 2.0));
    }
}
