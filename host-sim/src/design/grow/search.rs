//! Where the growth starts and where it looks when the Delaunay candidates run out.

use super::{dist, Entry, Reject, State, DEEP_WIDEN, START_BATCH, WIDEN};
use crate::design::error::DesignError;

impl State<'_> {
    /// Pushes the candidates of point `v` on the edges at its `reach` nearest attached
    /// points and registers it to hear of later edges there. Returns the candidates pushed
    /// and those refused for an angle and for capacity.
    pub(super) fn widen(&mut self, v: usize, reach: usize) -> [usize; 3] {
        self.widened[v] = true;
        let near: Vec<usize> = self
            .placed_tree
            .nearest_neighbor_iter(self.pts[v])
            .take(reach)
            .map(|q| q.data)
            .collect();
        let mut counts = [0usize; 3];
        for a in near {
            if self.watched.insert((a as u32, v as u32)) {
                self.watch[a].push(v as u32);
            }
            for k in 0..self.adj[a].len() {
                let b = self.adj[a][k] as usize;
                match self.evaluate(v, a, b) {
                    Ok(score) => {
                        counts[0] += 1;
                        self.heap.push(Entry {
                            clear: true,
                            score,
                            v: v as u32,
                            a: a as u32,
                            b: b as u32,
                        });
                    }
                    Err(Reject::Angle) => counts[1] += 1,
                    Err(Reject::Capacity) => counts[2] += 1,
                }
            }
        }
        counts
    }

    /// One fallback round: every point left is widened to its [`WIDEN`] nearest attached
    /// points and, when that finds nothing and at most [`DEEP_WIDEN`] points are left, to
    /// its [`DEEP_WIDEN`] nearest (points on a circle need edges a third of the way round: no triangle of near neighbours there
    /// has an angle beyond a few degrees). `Err` when no point left can be attached.
    pub(super) fn fallback(&mut self) -> Result<(), DesignError> {
        let mut total = [0usize; 3];
        let left = self.pts.len() - self.n_placed;
        for reach in [WIDEN, DEEP_WIDEN] {
            if reach == DEEP_WIDEN && left > DEEP_WIDEN {
                break;
            }
            total = [0; 3];
            for v in 0..self.pts.len() {
                if !self.placed[v] {
                    let c = self.widen(v, reach);
                    for k in 0..3 {
                        total[k] += c[k];
                    }
                }
            }
            if total[0] > 0 {
                return Ok(());
            }
        }
        Err(DesignError::NoConstruction {
            placed: self.n_placed,
            stuck: (0..self.pts.len()).filter(|&i| !self.placed[i]).collect(),
            margin_deg: self.p.margin.to_degrees(),
            angle_rejects: total[1],
            capacity_rejects: total[2],
            max_triangles: self.p.max_triangles,
            max_neighbours: self.p.max_neighbours,
        })
    }

    /// The best first triangle `[a, b, c]` (`ab` the start edge).
    pub(super) fn first_triangle(&self) -> Result<[usize; 3], DesignError> {
        let n = self.pts.len();
        let mut best: Option<(Entry, [usize; 3])> = None;
        let consider = |t: [usize; 3], best: &mut Option<(Entry, [usize; 3])>| {
            let [a, b, c] = t;
            if let Some(score) = self.static_score(c, a, b) {
                let e = Entry {
                    clear: !self.overlaps(&self.tri(a, b, c), t),
                    score,
                    v: c as u32,
                    a: a as u32,
                    b: b as u32,
                };
                if best.as_ref().is_none_or(|(old, _)| e > *old) {
                    *best = Some((e, t));
                }
            }
        };
        if let Some([i, j]) = self.p.leader {
            let refuse = |reason: String| DesignError::LeaderEdge {
                pair: [i, j],
                reason,
            };
            if i >= n || j >= n {
                return Err(refuse(format!("there are only {n} points (0..{n})")));
            }
            if i == j {
                return Err(refuse(
                    "the two leaders must be different points".to_owned(),
                ));
            }
            // Scores first, the overlap test (a range query) only from the best down.
            let mut scored: Vec<(f64, usize)> = (0..n)
                .filter(|&k| k != i && k != j)
                .filter_map(|k| Some((self.static_score(k, i, j)?, k)))
                .collect();
            scored.sort_by(|x, y| y.0.total_cmp(&x.0).then(x.1.cmp(&y.1)));
            let clear = scored
                .iter()
                .find(|&&(_, k)| !self.overlaps(&self.tri(i, j, k), [i, j, k]));
            return clear
                .or(scored.first())
                .map(|&(_, k)| [i, j, k])
                .ok_or_else(|| {
                    refuse(format!(
                        "no third point makes a triangle with every angle above the {}° margin",
                        self.p.margin.to_degrees()
                    ))
                });
        }
        let c = self
            .pts
            .iter()
            .fold([0.0, 0.0], |s, p| [s[0] + p[0], s[1] + p[1]]);
        let centroid = [c[0] / n as f64, c[1] / n as f64];
        for (k, q) in self.all.nearest_neighbor_iter(centroid).enumerate() {
            if k % START_BATCH == 0 && best.is_some() {
                break;
            }
            let v = q.data;
            let list = self.nb.of(v);
            for (x, &a) in list.iter().enumerate() {
                for &b in &list[x + 1..] {
                    // The start edge is the triangle's shortest edge.
                    let mut t = [v, a as usize, b as usize];
                    let e = |k: usize| dist(self.pts[t[k]], self.pts[t[(k + 1) % 3]]);
                    let shortest = (0..3).min_by(|&x, &y| e(x).total_cmp(&e(y))).unwrap_or(0);
                    t.rotate_left(shortest);
                    consider(t, &mut best);
                }
            }
        }
        best.map(|(_, t)| t).ok_or(DesignError::NoConstruction {
            placed: 0,
            stuck: (0..n).collect(),
            margin_deg: self.p.margin.to_degrees(),
            angle_rejects: 0,
            capacity_rejects: 0,
            max_triangles: self.p.max_triangles,
            max_neighbours: self.p.max_neighbours,
        })
    }
}
