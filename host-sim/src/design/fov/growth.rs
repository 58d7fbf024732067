//! The growth of [`super::construct_for_camera`]: Henneberg type-1 steps that keep every
//! agent's neighbour arc within `F − 2m`, restarts, the refusal's diagnosis and the
//! headings of a finished growth (the construction is in the parent's documentation).

use super::{bearing, cover, wrap, CameraDesign, STARTS, THETA_GOOD};
use crate::design::geometry::{angles, covers, dist, interiors_overlap};
use crate::design::laman::{controlled, figures, Construction, DesignOptions, DesignTriangle};
use crate::design::neighbours::PointTree;
use crate::design::points::Point;
use rand::Rng;
use rand_chacha::ChaCha8Rng;

/// Why an attempt stopped.
pub(super) struct Stuck {
    pub(super) placed: usize,
    pub(super) reason: String,
}

pub(super) struct Growth<'a> {
    pub(super) pts: &'a [Point],
    pub(super) near: &'a [Vec<usize>],
    /// Allowed arc width `W` (rad).
    pub(super) w: f64,
    /// Angle margin (rad).
    pub(super) margin: f64,
    pub(super) disp: &'a [Point],
    /// Longest edge allowed (m).
    pub(super) range: f64,
    pub(super) clearance: f64,
    pub(super) tree: &'a PointTree,
    pub(super) mt: usize,
    pub(super) nb: usize,
}

/// The growth's state.
struct State {
    placed: Vec<bool>,
    adj: Vec<Vec<usize>>,
    tri_count: Vec<usize>,
    tris: Vec<[usize; 3]>,
}

/// Why a candidate is refused (for the refusal's message).
enum Why {
    Angle,
    Capacity,
    /// An edge beyond the range or too close to another point.
    Sight,
    Arc {
        agent: usize,
        width: f64,
    },
}

impl Growth<'_> {
    /// Agent `i`'s interval of neighbour `j` (see the module documentation): `(centre,
    /// half width)` (rad).
    pub(super) fn interval(&self, i: usize, j: usize) -> (f64, f64) {
        let (a, b) = (self.pts[i], self.pts[j]);
        let beta = bearing(a, b);
        let zero = [0.0, 0.0];
        let (di, dj) = (
            self.disp.get(i).copied().unwrap_or(zero),
            self.disp.get(j).copied().unwrap_or(zero),
        );
        let (mut lo, mut hi) = (0.0f64, 0.0f64);
        for (x, y) in [(1.0, 0.0), (0.0, 1.0), (1.0, 1.0)] {
            let e = [
                b[0] - a[0] + y * dj[0] - x * di[0],
                b[1] - a[1] + y * dj[1] - x * di[1],
            ];
            let off = wrap(e[1].atan2(e[0]) - beta);
            lo = lo.min(off);
            hi = hi.max(off);
        }
        (wrap(beta + 0.5 * (lo + hi)), 0.5 * (hi - lo))
    }

    /// The narrowest arc of agent `i` with neighbours `adj ∪ extra`: `(width, centre)`.
    fn arc(&self, i: usize, adj: &[usize], extra: &[usize]) -> (f64, f64) {
        let iv: Vec<(f64, f64)> = adj
            .iter()
            .chain(extra)
            .map(|&j| self.interval(i, j))
            .collect();
        cover(&iv)
    }

    /// Whether `x` and `y` can see each other: within range, and no other point within
    /// the clearance of the segment.
    fn sight(&self, x: usize, y: usize) -> bool {
        let (p, q) = (self.pts[x], self.pts[y]);
        let len = dist(p, q);
        if len > self.range {
            return false;
        }
        if self.clearance <= 0.0 {
            return true;
        }
        let mid = [0.5 * (p[0] + q[0]), 0.5 * (p[1] + q[1])];
        let reach = 0.5 * len + self.clearance;
        let e = [q[0] - p[0], q[1] - p[1]];
        self.tree
            .locate_within_distance(mid, reach * reach)
            .filter(|k| k.data != x && k.data != y)
            .all(|k| {
                let c = *k.geom();
                let t =
                    (((c[0] - p[0]) * e[0] + (c[1] - p[1]) * e[1]) / (len * len)).clamp(0.0, 1.0);
                dist(c, [p[0] + t * e[0], p[1] + t * e[1]]) >= self.clearance
            })
    }

    pub(super) fn min_angle(&self, t: [usize; 3]) -> f64 {
        angles(t.map(|v| self.pts[v]))
            .into_iter()
            .fold(f64::INFINITY, f64::min)
    }

    /// The score of triangle `(a, b, v)` (`v` joins edge `ab`) in state `s`, or why not.
    fn evaluate(&self, s: &State, v: usize, a: usize, b: usize) -> Result<f64, Why> {
        let theta = self.min_angle([a, b, v]);
        if theta.is_nan() || theta <= self.margin {
            return Err(Why::Angle);
        }
        let full = |x: usize| s.tri_count[x] >= self.mt || s.adj[x].len() >= self.nb;
        if full(a) || full(b) {
            return Err(Why::Capacity);
        }
        for x in [a, b] {
            if !self.sight(v, x) {
                return Err(Why::Sight);
            }
        }
        let mut slack = f64::INFINITY;
        for (x, adj, extra) in [
            (a, s.adj[a].as_slice(), [v, v]),
            (b, s.adj[b].as_slice(), [v, v]),
            (v, &[][..], [a, b]),
        ] {
            let width = self.arc(x, adj, &extra).0;
            if width > self.w {
                return Err(Why::Arc { agent: x, width });
            }
            slack = slack.min(self.w - width);
        }
        let len = dist(self.pts[v], self.pts[a]).max(dist(self.pts[v], self.pts[b]));
        let h = self.near[v]
            .first()
            .map_or(len, |&q| dist(self.pts[v], self.pts[q]))
            .min(len);
        let cover_penalty = self.near[v]
            .iter()
            .filter(|&&q| q != a && q != b)
            .any(|&q| {
                covers(
                    &[self.pts[a], self.pts[b], self.pts[v]],
                    self.pts[q],
                    1e-9 * len,
                )
            });
        Ok(
            (theta.min(THETA_GOOD) / THETA_GOOD).log2() - 0.25 * (len / h).log2() + slack / self.w
                - if cover_penalty { 1.0 } else { 0.0 },
        )
    }

    /// Start triangles `[a, b, c]` (`ab` the start edge), best first.
    pub(super) fn starts(&self, leader: Option<[usize; 2]>) -> Vec<[usize; 3]> {
        let n = self.pts.len();
        let c = self.pts.iter().fold([0.0, 0.0], |s, p| {
            [s[0] + p[0] / n as f64, s[1] + p[1] / n as f64]
        });
        let empty = State {
            placed: vec![false; n],
            adj: vec![Vec::new(); n],
            tri_count: vec![0; n],
            tris: Vec::new(),
        };
        let spacing = self
            .pts
            .iter()
            .enumerate()
            .filter_map(|(i, &p)| self.near[i].first().map(|&q| dist(p, self.pts[q])))
            .fold(f64::INFINITY, f64::min);
        let mut found: Vec<(f64, [usize; 3])> = Vec::new();
        let mut s0 = empty;
        let mut consider = |t: [usize; 3]| {
            let [a, b, v] = t;
            if a == b || b == v || a == v {
                return;
            }
            // The first triangle: `v` joins `ab`, and `a`, `b` see each other.
            if !self.sight(a, b) {
                return;
            }
            s0.adj[a].push(b);
            s0.adj[b].push(a);
            let scored = self.evaluate(&s0, v, a, b);
            s0.adj[a].clear();
            s0.adj[b].clear();
            if let Ok(score) = scored {
                let centre = [
                    (self.pts[a][0] + self.pts[b][0] + self.pts[v][0]) / 3.0,
                    (self.pts[a][1] + self.pts[b][1] + self.pts[v][1]) / 3.0,
                ];
                found.push((score - 0.05 * dist(centre, c) / spacing.max(1e-12), t));
            }
        };
        match leader {
            Some([a, b]) => {
                if a < n && b < n {
                    for v in (0..n).filter(|&v| v != a && v != b) {
                        consider([a, b, v]);
                    }
                }
            }
            None => {
                for i in 0..n {
                    for (x, &j) in self.near[i].iter().enumerate() {
                        for &k in &self.near[i][x + 1..] {
                            if i < j && i < k {
                                let mut t = [i, j, k];
                                let e = |m: usize| dist(self.pts[t[m]], self.pts[t[(m + 1) % 3]]);
                                let shortest =
                                    (0..3).min_by(|&x, &y| e(x).total_cmp(&e(y))).unwrap_or(0);
                                t.rotate_left(shortest);
                                consider(t);
                            }
                        }
                    }
                }
            }
        }
        found.sort_by(|x, y| y.0.total_cmp(&x.0).then(x.1.cmp(&y.1)));
        found.truncate(STARTS);
        found.into_iter().map(|(_, t)| t).collect()
    }

    /// One growth from `start`; scores jittered by up to ±`noise`.
    pub(super) fn attempt(
        &self,
        start: [usize; 3],
        noise: f64,
        rng: &mut ChaCha8Rng,
    ) -> Result<Vec<[usize; 3]>, Stuck> {
        let n = self.pts.len();
        let mut s = State {
            placed: vec![false; n],
            adj: vec![Vec::new(); n],
            tri_count: vec![0; n],
            tris: Vec::with_capacity(n.saturating_sub(2)),
        };
        let [a, b, c] = start;
        s.adj[a].push(b);
        s.adj[b].push(a);
        s.placed[a] = true;
        s.placed[b] = true;
        link(&mut s, c, a, b);
        let mut placed = 3;
        while placed < n {
            // Per agent left: its best candidate and how many it has.
            let mut pick: Option<(f64, [usize; 3])> = None;
            for v in (0..n).filter(|&v| !s.placed[v]) {
                let mut best: Option<(f64, [usize; 2])> = None;
                let mut count = 0usize;
                for &a in self.near[v].iter().filter(|&&a| s.placed[a]) {
                    for &b in &s.adj[a] {
                        if let Ok(score) = self.evaluate(&s, v, a, b) {
                            count += 1;
                            if best.is_none_or(|(x, _)| score > x) {
                                best = Some((score, [a, b]));
                            }
                        }
                    }
                }
                if let Some((score, [a, b])) = best {
                    // An edge with both ends near `v` counts twice: urgency is approximate.
                    let urgency = 4.0 / count as f64;
                    let jitter = noise * (2.0 * rng.random::<f64>() - 1.0);
                    let key = score + urgency + jitter;
                    if pick.is_none_or(|(x, _)| key > x) {
                        pick = Some((key, [a, b, v]));
                    }
                }
            }
            let Some((_, [a, b, v])) = pick else {
                return Err(Stuck {
                    placed,
                    reason: self.diagnose(&s),
                });
            };
            link(&mut s, v, a, b);
            placed += 1;
        }
        Ok(s.tris)
    }

    /// Why no agent left can join: the agent left nearest the formation and its best
    /// refused candidate.
    fn diagnose(&self, s: &State) -> String {
        let n = self.pts.len();
        let nearest = (0..n).filter(|&v| !s.placed[v]).min_by(|&x, &y| {
            let d = |v: usize| {
                (0..n)
                    .filter(|&q| s.placed[q])
                    .map(|q| dist(self.pts[v], self.pts[q]))
                    .fold(f64::INFINITY, f64::min)
            };
            d(x).total_cmp(&d(y))
        });
        let Some(v) = nearest else {
            return "no agent left".to_owned();
        };
        let placed = s.placed.iter().filter(|&&p| p).count();
        let (mut angle, mut capacity, mut sight) = (0usize, 0usize, 0usize);
        let mut arc: Option<(f64, usize, [usize; 2])> = None;
        for a in (0..n).filter(|&a| s.placed[a]) {
            for &b in s.adj[a].iter().filter(|&&b| b > a) {
                match self.evaluate(s, v, a, b) {
                    Err(Why::Angle) => angle += 1,
                    Err(Why::Capacity) => capacity += 1,
                    Err(Why::Sight) => sight += 1,
                    Err(Why::Arc { agent, width }) => {
                        if arc.is_none_or(|(w, _, _)| width < w) {
                            arc = Some((width, agent, [a, b]));
                        }
                    }
                    Ok(_) => {}
                }
            }
        }
        let mut msg = format!(
            "{placed} of {n} agents placed: agent {} (point {v}) cannot join: of the edges \
             there, {angle} make a triangle with an angle within the angle margin, \
             {capacity} are at an agent's capacity, {sight} need a line of sight beyond the \
             range or passing another agent",
            v + 1
        );
        if let Some((width, agent, [a, b])) = arc {
            msg.push_str(&format!(
                ", and the best of the rest, with agents {} and {}, needs agent {}'s \
                 neighbours (their bearings from start to target) to span {:.1}° > F − 2·margin = \
                 {:.1}°",
                a + 1,
                b + 1,
                agent + 1,
                width.to_degrees(),
                self.w.to_degrees()
            ));
        }
        msg
    }

    /// The construction and headings of a finished growth.
    pub(super) fn finish(
        &self,
        tris: Vec<[usize; 3]>,
        opts: &DesignOptions,
        attempt: usize,
    ) -> CameraDesign {
        let corners = |t: [usize; 3]| t.map(|v| self.pts[v]);
        let triangles: Vec<DesignTriangle> = tris
            .iter()
            .enumerate()
            .map(|(k, &t)| {
                let p = corners(t);
                let tol = 1e-9 * dist(p[0], p[1]);
                let overlapping = tris[..k]
                    .iter()
                    .any(|&u| interiors_overlap(&p, &corners(u), tol))
                    || (0..self.pts.len()).any(|q| !t.contains(&q) && covers(&p, self.pts[q], tol));
                DesignTriangle {
                    vertices: t,
                    angles: controlled(self.pts, t),
                    overlapping,
                }
            })
            .collect();
        let figures = figures(self.pts, &triangles);
        let n = self.pts.len();
        let mut adj: Vec<Vec<usize>> = vec![Vec::new(); n];
        for t in &tris {
            for &i in t {
                for &j in t {
                    if i != j && !adj[i].contains(&j) {
                        adj[i].push(j);
                    }
                }
            }
        }
        let mut widest = (0.0f64, 0usize);
        let headings = (0..n)
            .map(|i| {
                let (width, centre) = self.arc(i, &adj[i], &[]);
                if width.to_degrees() > widest.0 {
                    widest = (width.to_degrees(), i);
                }
                centre
            })
            .collect();
        CameraDesign {
            construction: Construction {
                leader: [tris[0][0], tris[0][1]],
                triangles,
                margin_deg: opts.margin_deg,
                figures,
            },
            headings,
            widest,
            attempt,
        }
    }
}

/// Joins `v` to edge `ab`.
fn link(s: &mut State, v: usize, a: usize, b: usize) {
    s.placed[v] = true;
    s.adj[a].push(v);
    s.adj[b].push(v);
    s.adj[v] = vec![a, b];
    for x in [a, b, v] {
        s.tri_count[x] += 1;
    }
    s.tris.push([a, b, v]);
}
