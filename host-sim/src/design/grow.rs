//! The greedy growth of a triangulated Laman graph (SPEC §3) over the target points.
//!
//! A *candidate* is a triangle `(a, b, v)`: `ab` is an edge of the graph built so far and
//! `v` a point not yet attached. Candidates are kept in one priority queue ordered by
//!
//! 1. **clear**: the triangle contains no other point and its interior meets no placed
//!    triangle (so a triangle glued to an edge lies on the far side of it), then
//! 2. **score** = `log₂(min(θ, θ_good)/θ_good) − λ·log₂(ℓ/h) − μ·load`, with θ the
//!    triangle's smallest interior angle, ℓ its longest new edge, h the distance from `v`
//!    to its nearest point, and load the mean fill of `a` and `b` (triangles / MT and
//!    neighbours / NB, whichever is larger),
//!
//! and the best one is attached, like Prim's algorithm for a bottleneck spanning tree.
//! Every candidate's priority can only fall (loads grow, placed triangles appear), so the
//! queue is lazy: a popped candidate is re-evaluated and put back when its key dropped.
//! Triangles with an angle within the margin, or that would put an agent over capacity,
//! are never candidates.
//!
//! Candidates come from the Delaunay neighbours of the new edge's ends (`neighbours.rs`).
//! When the queue runs dry with points left (slivers on the hull, points on a circle), a
//! *fallback round* tries, for every point left, the edges at its 32 nearest attached
//! points, and registers it to hear of later edges there. When that finds nothing, the
//! construction is refused with the points that could not be attached.
//!
//! Cost: O(N·d·log N) for N points with Delaunay degree d (plus the fallback rounds, which
//! on spread-out point sets touch only a few hull points).

use super::error::DesignError;
use super::geometry::{angles, covers, dist, interiors_overlap};
use super::neighbours::{Neighbours, PointTree};
use super::points::Point;
use rstar::primitives::{GeomWithData, Rectangle};
use rstar::{RTree, AABB};
use std::cmp::Ordering;
use std::collections::{BinaryHeap, HashSet};

/// Smallest angle beyond which a triangle counts as good (rad, 35°): above it only edge
/// length and load decide.
pub(crate) const THETA_GOOD: f64 = 35.0 * std::f64::consts::PI / 180.0;
/// Weight of the edge length: a new edge twice the nearest-point distance costs as much
/// as the smallest angle falling by a factor 2^0.25 (35° → 29°).
pub(crate) const LAMBDA: f64 = 0.25;
/// Weight of the load of the edge's two agents.
pub(crate) const MU: f64 = 0.25;
/// Attached points tried per left-over point in a fallback round.
const FALLBACK: usize = 32;
/// Start vertices (nearest the centroid) examined before taking the best start triangle.
const START_BATCH: usize = 32;

/// What the growth needs.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Params {
    /// Every interior angle must exceed this (rad).
    pub margin: f64,
    /// Triangles per agent (MT).
    pub max_triangles: usize,
    /// Neighbours per agent (NB).
    pub max_neighbours: usize,
    /// Start edge.
    pub leader: Option<[usize; 2]>,
}

/// The grown graph.
pub(crate) struct Grown {
    /// Triangles in construction order: `[a, b, new]` (the first: `[a, b, c]` with `ab`
    /// the start edge).
    pub triangles: Vec<[usize; 3]>,
    /// Whether each triangle overlaps a placed triangle or covers another point.
    pub overlapping: Vec<bool>,
}

#[derive(Clone, Copy, Debug)]
struct Entry {
    clear: bool,
    score: f64,
    v: u32,
    a: u32,
    b: u32,
}

impl Entry {
    fn key(&self) -> (bool, f64) {
        (self.clear, self.score)
    }
}

impl Ord for Entry {
    fn cmp(&self, o: &Self) -> Ordering {
        self.clear
            .cmp(&o.clear)
            .then(self.score.total_cmp(&o.score))
            .then(o.v.cmp(&self.v))
            .then(o.a.cmp(&self.a))
            .then(o.b.cmp(&self.b))
    }
}
impl PartialOrd for Entry {
    fn partial_cmp(&self, o: &Self) -> Option<Ordering> {
        Some(self.cmp(o))
    }
}
impl PartialEq for Entry {
    fn eq(&self, o: &Self) -> bool {
        self.cmp(o) == Ordering::Equal
    }
}
impl Eq for Entry {}

/// Why a candidate is refused.
enum Reject {
    Angle,
    Capacity,
}

struct State<'a> {
    pts: &'a [Point],
    nb: &'a Neighbours,
    all: &'a PointTree,
    p: Params,
    tol: f64,
    placed: Vec<bool>,
    n_placed: usize,
    tri_count: Vec<u32>,
    adj: Vec<Vec<u32>>,
    watch: Vec<Vec<u32>>,
    watched: HashSet<(u32, u32)>,
    tris: Vec<[usize; 3]>,
    overlapping: Vec<bool>,
    tri_tree: RTree<GeomWithData<Rectangle<Point>, u32>>,
    heap: BinaryHeap<Entry>,
    mark: Vec<u32>,
    epoch: u32,
}

fn bbox(t: &[Point; 3]) -> AABB<Point> {
    AABB::from_points(t.iter())
}

impl State<'_> {
    fn tri(&self, a: usize, b: usize, v: usize) -> [Point; 3] {
        [self.pts[a], self.pts[b], self.pts[v]]
    }

    /// Angle and length part of the score, or `None` when an angle is within the margin.
    fn static_score(&self, v: usize, a: usize, b: usize) -> Option<f64> {
        let t = self.tri(a, b, v);
        let theta = angles(t).into_iter().fold(f64::INFINITY, f64::min);
        if !(theta > self.p.margin) {
            return None;
        }
        let len = dist(t[2], t[0]).max(dist(t[2], t[1]));
        let h = self.nb.nearest[v].min(len);
        Some((theta.min(THETA_GOOD) / THETA_GOOD).log2() - LAMBDA * (len / h).log2())
    }

    fn load(&self, x: usize) -> f64 {
        (self.tri_count[x] as f64 / self.p.max_triangles as f64)
            .max(self.adj[x].len() as f64 / self.p.max_neighbours as f64)
    }

    fn evaluate(&self, v: usize, a: usize, b: usize) -> Result<f64, Reject> {
        let s = self.static_score(v, a, b).ok_or(Reject::Angle)?;
        let full = |x: usize| {
            self.tri_count[x] as usize >= self.p.max_triangles
                || self.adj[x].len() >= self.p.max_neighbours
        };
        if full(a) || full(b) {
            return Err(Reject::Capacity);
        }
        Ok(s - MU * 0.5 * (self.load(a) + self.load(b)))
    }

    /// Whether the triangle covers another point or meets a placed triangle's interior.
    fn overlaps(&self, t: &[Point; 3], own: [usize; 3]) -> bool {
        let env = bbox(t);
        let covers_point = self
            .all
            .locate_in_envelope(env)
            .any(|q| !own.contains(&q.data) && covers(t, *q.geom(), self.tol));
        covers_point
            || self
                .tri_tree
                .locate_in_envelope_intersecting(env)
                .any(|r| interiors_overlap(t, &self.tri_of(r.data as usize), self.tol))
    }

    fn tri_of(&self, k: usize) -> [Point; 3] {
        let [a, b, c] = self.tris[k];
        self.tri(a, b, c)
    }

    fn add_triangle(&mut self, t: [usize; 3], overlapping: bool) {
        let pts = self.tri(t[0], t[1], t[2]);
        let env = bbox(&pts);
        self.tri_tree.insert(GeomWithData::new(
            Rectangle::from_corners(env.lower(), env.upper()),
            self.tris.len() as u32,
        ));
        self.tris.push(t);
        self.overlapping.push(overlapping);
        for &x in &t {
            self.tri_count[x] += 1;
        }
    }

    /// Pushes the candidates of a new edge `xy`.
    fn edge_added(&mut self, x: usize, y: usize) {
        self.epoch = self.epoch.wrapping_add(1);
        let mut found: Vec<u32> = Vec::new();
        for src in [self.nb.of(x), self.nb.of(y), &self.watch[x], &self.watch[y]] {
            for &w in src {
                let wi = w as usize;
                if !self.placed[wi] && self.mark[wi] != self.epoch {
                    self.mark[wi] = self.epoch;
                    found.push(w);
                }
            }
        }
        for w in found {
            if let Ok(score) = self.evaluate(w as usize, x, y) {
                self.heap.push(Entry {
                    clear: true,
                    score,
                    v: w,
                    a: x as u32,
                    b: y as u32,
                });
            }
        }
    }

    fn start(&mut self, t: [usize; 3]) {
        for &x in &t {
            self.placed[x] = true;
        }
        self.n_placed = 3;
        let [a, b, c] = t;
        self.adj[a] = vec![b as u32, c as u32];
        self.adj[b] = vec![a as u32, c as u32];
        self.adj[c] = vec![a as u32, b as u32];
        self.add_triangle(t, false);
        self.edge_added(a, b);
        self.edge_added(a, c);
        self.edge_added(b, c);
    }

    fn attach(&mut self, v: usize, a: usize, b: usize, overlapping: bool) {
        self.placed[v] = true;
        self.n_placed += 1;
        self.adj[a].push(v as u32);
        self.adj[b].push(v as u32);
        self.adj[v] = vec![a as u32, b as u32];
        self.add_triangle([a, b, v], overlapping);
        self.watch[v].clear();
        self.edge_added(a, v);
        self.edge_added(b, v);
    }

    /// One fallback round; `Err` when no point left can be attached.
    fn fallback(&mut self) -> Result<(), DesignError> {
        let placed_tree: RTree<GeomWithData<Point, usize>> = RTree::bulk_load(
            (0..self.pts.len())
                .filter(|&i| self.placed[i])
                .map(|i| GeomWithData::new(self.pts[i], i))
                .collect(),
        );
        let (mut pushed, mut angle, mut capacity) = (0usize, 0usize, 0usize);
        for v in 0..self.pts.len() {
            if self.placed[v] {
                continue;
            }
            let near: Vec<usize> = placed_tree
                .nearest_neighbor_iter(self.pts[v])
                .take(FALLBACK)
                .map(|q| q.data)
                .collect();
            for a in near {
                if self.watched.insert((a as u32, v as u32)) {
                    self.watch[a].push(v as u32);
                }
                for k in 0..self.adj[a].len() {
                    let b = self.adj[a][k] as usize;
                    match self.evaluate(v, a, b) {
                        Ok(score) => {
                            pushed += 1;
                            self.heap.push(Entry {
                                clear: true,
                                score,
                                v: v as u32,
                                a: a as u32,
                                b: b as u32,
                            });
                        }
                        Err(Reject::Angle) => angle += 1,
                        Err(Reject::Capacity) => capacity += 1,
                    }
                }
            }
        }
        if pushed > 0 {
            return Ok(());
        }
        Err(DesignError::NoConstruction {
            placed: self.n_placed,
            stuck: (0..self.pts.len()).filter(|&i| !self.placed[i]).collect(),
            margin_deg: self.p.margin.to_degrees(),
            angle_rejects: angle,
            capacity_rejects: capacity,
            max_triangles: self.p.max_triangles,
            max_neighbours: self.p.max_neighbours,
        })
    }

    /// The best first triangle `[a, b, c]` (`ab` the start edge).
    fn first_triangle(&self) -> Result<[usize; 3], DesignError> {
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
                return Err(refuse("the two leaders must be different points".to_owned()));
            }
            for k in (0..n).filter(|&k| k != i && k != j) {
                consider([i, j, k], &mut best);
            }
            return best.map(|(_, t)| t).ok_or_else(|| {
                refuse(format!(
                    "no third point makes a triangle with every angle above the {}° margin",
                    self.p.margin.to_degrees()
                ))
            });
        }
        let c = self.pts.iter().fold([0.0, 0.0], |s, p| [s[0] + p[0], s[1] + p[1]]);
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

/// Grows the graph (see the module documentation). `points` must have passed
/// `check_points`; `nb` and `all` are their neighbour lists and R*-tree.
pub(crate) fn grow(
    points: &[Point],
    nb: &Neighbours,
    all: &PointTree,
    p: Params,
) -> Result<Grown, DesignError> {
    let n = points.len();
    let extent = all.root().envelope();
    let tol = 1e-9 * dist(extent.lower(), extent.upper());
    let mut s = State {
        pts: points,
        nb,
        all,
        p,
        tol,
        placed: vec![false; n],
        n_placed: 0,
        tri_count: vec![0; n],
        adj: vec![Vec::new(); n],
        watch: vec![Vec::new(); n],
        watched: HashSet::new(),
        tris: Vec::with_capacity(n.saturating_sub(2)),
        overlapping: Vec::with_capacity(n.saturating_sub(2)),
        tri_tree: RTree::new(),
        heap: BinaryHeap::new(),
        mark: vec![0; n],
        epoch: 0,
    };
    let first = s.first_triangle()?;
    s.start(first);
    while s.n_placed < n {
        let Some(e) = s.heap.pop() else {
            s.fallback()?;
            continue;
        };
        let (v, a, b) = (e.v as usize, e.a as usize, e.b as usize);
        if s.placed[v] {
            continue;
        }
        let Ok(score) = s.evaluate(v, a, b) else {
            continue;
        };
        let clear = e.clear && !s.overlaps(&s.tri(a, b, v), [a, b, v]);
        let now = Entry { clear, score, ..e };
        if now.key() != e.key() {
            s.heap.push(now);
            continue;
        }
        s.attach(v, a, b, !clear);
    }
    Ok(Grown {
        triangles: s.tris,
        overlapping: s.overlapping,
    })
}
