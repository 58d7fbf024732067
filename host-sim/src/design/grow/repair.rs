//! Local repair of the worst triangles after the growth.
//!
//! A point attached late may find itself in a pocket: every edge around it was taken by
//! neighbours placed before it, and only a thin triangle is left. For each triangle whose
//! smallest angle is below [`REPAIR_BELOW`] (worst first) whose new point `v` is a *leaf*
//! (nothing is glued to its edges), `v` and the leaves among its Delaunay neighbours are
//! detached and attached again *most constrained first*: each round, every pending point
//! finds its best candidate, and the point whose best is worst is attached with it. The
//! new triangles are kept when they overlap no more and their smallest angle is larger;
//! otherwise the old ones are put back. Leaves carry nothing, so taking them out and
//! appending them at the end of the construction order keeps it valid.

use super::{min_angle, Entry, State, WIDEN};

/// Triangles with a smallest angle below this (rad, 25°) are repaired.
const REPAIR_BELOW: f64 = 25.0 * std::f64::consts::PI / 180.0;
/// Most points detached in one repair.
const MAX_SET: usize = 8;

/// (overlapping triangles, smallest angle) of a set of triangles: fewer overlaps first,
/// then the larger smallest angle.
type Quality = (usize, f64);

fn better(new: Quality, old: Quality) -> bool {
    new.0 < old.0 || (new.0 == old.0 && new.1 > old.1 * (1.0 + 1e-12))
}

impl State<'_> {
    fn own_min_angle(&self, v: usize) -> f64 {
        let [a, b, c] = self.tris[self.own[v]];
        min_angle(self.tri(a, b, c))
    }

    fn quality(&self, set: &[usize]) -> Quality {
        set.iter().fold((0, f64::INFINITY), |(n, th), &v| {
            (
                n + usize::from(self.overlapping[self.own[v]]),
                th.min(self.own_min_angle(v)),
            )
        })
    }

    /// Best candidate of pending point `v` on the edges at its nearest attached points:
    /// the best clear one, else the best overlapping one.
    fn best_for(&self, v: usize) -> Option<Entry> {
        let mut cands: Vec<Entry> = Vec::new();
        for q in self
            .placed_tree
            .nearest_neighbor_iter(self.pts[v])
            .take(WIDEN)
        {
            let a = q.data;
            for &b in &self.adj[a] {
                let b = b as usize;
                if let Ok(score) = self.evaluate(v, a, b) {
                    cands.push(Entry {
                        clear: true,
                        score,
                        v: v as u32,
                        a: a as u32,
                        b: b as u32,
                    });
                }
            }
        }
        cands.sort_unstable_by(|x, y| y.cmp(x));
        let clear = cands.iter().find(|e| {
            !self.overlaps(
                &self.tri(e.a as usize, e.b as usize, v),
                [e.a as usize, e.b as usize, v],
            )
        });
        match (clear, cands.first()) {
            (Some(e), _) => Some(*e),
            (None, Some(e)) => Some(Entry { clear: false, ..*e }),
            (None, None) => None,
        }
    }

    /// Attaches `set` most constrained first; `false` (with whatever was attached left in
    /// place) when a point finds no candidate.
    fn reattach(&mut self, set: &[usize]) -> bool {
        let mut pending: Vec<usize> = set.to_vec();
        while !pending.is_empty() {
            let mut pick: Option<(Entry, usize)> = None;
            for (i, &u) in pending.iter().enumerate() {
                let Some(e) = self.best_for(u) else {
                    return false;
                };
                if pick.as_ref().is_none_or(|(p, _)| e < *p) {
                    pick = Some((e, i));
                }
            }
            let Some((e, i)) = pick else {
                return false;
            };
            pending.remove(i);
            self.link(e.v as usize, e.a as usize, e.b as usize, !e.clear);
        }
        true
    }

    /// Repairs the worst triangles (see the module documentation).
    pub(super) fn repair(&mut self) {
        let mut bad: Vec<(f64, usize)> = (0..self.pts.len())
            .filter(|&v| self.is_leaf(v))
            .map(|v| (self.own_min_angle(v), v))
            .filter(|&(th, _)| th < REPAIR_BELOW)
            .collect();
        bad.sort_by(|x, y| x.0.total_cmp(&y.0).then(x.1.cmp(&y.1)));
        for (_, v) in bad {
            if !self.is_leaf(v) || self.own_min_angle(v) >= REPAIR_BELOW {
                continue;
            }
            let mut set = vec![v];
            for &u in self.nb.of(v) {
                if set.len() < MAX_SET && self.is_leaf(u as usize) {
                    set.push(u as usize);
                }
            }
            let old_quality = self.quality(&set);
            let old: Vec<([usize; 3], bool)> = set
                .iter()
                .map(|&u| (self.tris[self.own[u]], self.overlapping[self.own[u]]))
                .collect();
            for &u in &set {
                self.detach(u);
            }
            let done = self.reattach(&set);
            if done && better(self.quality(&set), old_quality) {
                continue;
            }
            for &u in &set {
                if self.placed[u] {
                    self.detach(u);
                }
            }
            for ([a, b, u], overlapping) in old {
                self.link(u, a, b, overlapping);
            }
        }
    }
}
