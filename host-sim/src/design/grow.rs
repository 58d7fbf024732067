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
//! Before a point takes a thin triangle (smallest angle below 25°) it is *widened*: the
//! edges at its 32 nearest attached points become candidates too, and it is registered to
//! hear of later edges there. When the queue runs dry with points left (slivers on the
//! hull, points on a circle), a *fallback round* widens every point left, first to its 32
//! nearest attached points, then to its 4,096 nearest; when that finds
//! nothing, the construction is refused with the points that could not be attached.
//! Finally the worst triangles are repaired locally (`grow/repair.rs`).
//!
//! Why not simply demand a higher angle everywhere: on random points a growth with a
//! floor of 25–30° does complete, but only by taking overlapping triangles where a clear
//! thin one existed (measured: 2–17 overlaps among 298 triangles); the order above keeps
//! triangles clear wherever possible and the angle as high as that allows.
//!
//! Cost: O(N·d·log N) for N points with Delaunay degree d, plus the fallback rounds, which
//! on spread-out point sets touch only a few hull points. Measured (release build, one
//! core): 100,000 random points in a disc 1.5 s, a 100,000-point lattice 0.7 s.

use super::error::DesignError;
use super::geometry::{angles, covers, dist, interiors_overlap};
use super::neighbours::{Neighbours, PointTree};
use super::points::Point;
use rstar::primitives::{GeomWithData, Rectangle};
use rstar::{RTree, AABB};
use std::cmp::Ordering;
use std::collections::{BinaryHeap, HashSet};

mod repair;
mod search;

/// Smallest angle beyond which a triangle counts as good (rad, 35°): above it only edge
/// length and load decide.
pub(crate) const THETA_GOOD: f64 = 35.0 * std::f64::consts::PI / 180.0;
/// Weight of the edge length: a new edge twice the nearest-point distance costs as much
/// as the smallest angle falling by a factor 2^0.25 (35° → 29°).
pub(crate) const LAMBDA: f64 = 0.25;
/// Weight of the load of the edge's two agents.
pub(crate) const MU: f64 = 0.25;
/// Attached points whose edges are tried when a point is widened.
const WIDEN: usize = 32;
/// A point whose best candidate has a smallest angle below this (rad, 25°) is widened
/// before that candidate is taken.
const WIDEN_BELOW: f64 = 25.0 * std::f64::consts::PI / 180.0;
/// Attached points whose edges are tried for a point left over when widening to [`WIDEN`]
/// found nothing (bounds the cost of a refused construction).
const DEEP_WIDEN: usize = 4096;
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
    widened: Vec<bool>,
    placed_tree: RTree<GeomWithData<Point, usize>>,
    tris: Vec<[usize; 3]>,
    overlapping: Vec<bool>,
    /// Triangles taken out by the repair (indices into `tris`).
    removed: Vec<bool>,
    /// Each point's own triangle (the one it joined with; 0 for the first three).
    own: Vec<usize>,
    tri_tree: RTree<GeomWithData<Rectangle<Point>, u32>>,
    heap: BinaryHeap<Entry>,
    mark: Vec<u32>,
    epoch: u32,
}

fn min_angle(t: [Point; 3]) -> f64 {
    angles(t).into_iter().fold(f64::INFINITY, f64::min)
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
        let theta = min_angle(t);
        if theta.is_nan() || theta <= self.p.margin {
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
        self.removed.push(false);
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
            self.placed_tree.insert(GeomWithData::new(self.pts[x], x));
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

    /// Attaches `v` to edge `ab` and pushes the candidates of its two new edges.
    fn attach(&mut self, v: usize, a: usize, b: usize, overlapping: bool) {
        self.link(v, a, b, overlapping);
        self.watch[v].clear();
        self.edge_added(a, v);
        self.edge_added(b, v);
    }

    /// Attaches `v` to edge `ab` (no candidates pushed).
    fn link(&mut self, v: usize, a: usize, b: usize, overlapping: bool) {
        self.placed[v] = true;
        self.placed_tree.insert(GeomWithData::new(self.pts[v], v));
        self.n_placed += 1;
        self.adj[a].push(v as u32);
        self.adj[b].push(v as u32);
        self.adj[v] = vec![a as u32, b as u32];
        self.own[v] = self.tris.len();
        self.add_triangle([a, b, v], overlapping);
    }

    /// Whether `v` can be detached: it is not in the first triangle and no triangle is
    /// glued to one of its edges.
    fn is_leaf(&self, v: usize) -> bool {
        self.placed[v] && self.tri_count[v] == 1 && self.own[v] != 0
    }

    /// Undoes [`Self::link`] of a leaf.
    fn detach(&mut self, v: usize) {
        let k = self.own[v];
        let [a, b, _] = self.tris[k];
        let env = bbox(&self.tri(a, b, v));
        self.tri_tree.remove(&GeomWithData::new(
            Rectangle::from_corners(env.lower(), env.upper()),
            k as u32,
        ));
        self.removed[k] = true;
        for x in [a, b, v] {
            self.tri_count[x] -= 1;
        }
        self.adj[a].retain(|&w| w as usize != v);
        self.adj[b].retain(|&w| w as usize != v);
        self.adj[v].clear();
        self.placed[v] = false;
        self.n_placed -= 1;
        self.placed_tree.remove(&GeomWithData::new(self.pts[v], v));
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
        widened: vec![false; n],
        placed_tree: RTree::new(),
        tris: Vec::with_capacity(n.saturating_sub(2)),
        overlapping: Vec::with_capacity(n.saturating_sub(2)),
        removed: Vec::with_capacity(n.saturating_sub(2)),
        own: vec![0; n],
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
        if !s.widened[v] && min_angle(s.tri(a, b, v)) < WIDEN_BELOW {
            s.widen(v, WIDEN);
            s.heap.push(e);
            continue;
        }
        let clear = e.clear && !s.overlaps(&s.tri(a, b, v), [a, b, v]);
        let now = Entry { clear, score, ..e };
        if now.key() != e.key() {
            s.heap.push(now);
            continue;
        }
        s.attach(v, a, b, !clear);
    }
    s.repair();
    let keep = |k: &usize| !s.removed[*k];
    Ok(Grown {
        triangles: (0..s.tris.len()).filter(keep).map(|k| s.tris[k]).collect(),
        overlapping: (0..s.tris.len())
            .filter(keep)
            .map(|k| s.overlapping[k])
            .collect(),
    })
}
