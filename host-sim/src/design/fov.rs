//! Designing for a camera (`host-sim design --fov-deg F`, docs/design.md "Designing for a
//! camera"): the triangles *and* every agent's heading, so that every triangle neighbour
//! an agent senses stays inside its field of view, with a margin, at the target, at the
//! initial positions and on the way between.
//!
//! Agent `i` sees neighbour `j` when `j`'s bearing is within `F/2` of `i`'s heading (the
//! camera's boresight, `engine/sensors/camera.rs`). In the paper's law every corner of a
//! triangle needs bearings to both other corners (SPEC §12), so every graph neighbour must
//! be seen. Two things move a neighbour's bearing in the camera's frame during a run:
//!
//! * **the agents' motion** from the initial positions to the target: agent `i` starts
//!   at `p_i + s_i d_i` (`d_i` its drawn displacement, `s_i ∈ (0, 1]` what is left of it
//!   after the loader's shortening), so while both move straight to their targets at any
//!   speeds the vector to the neighbour stays in the parallelogram `p_j − p_i + a d_j −
//!   b d_i`, `a, b ∈ [0, 1]`, and its bearing between those of the four corners: the
//!   *neighbour interval* of `j` at `i`;
//! * **the formation's rotation and the headings' own errors**, the same for every
//!   neighbour of an agent: the *heading margin* `m` (docs/design.md argues its default,
//!   the heading error plus the spread plus the drift over the run).
//!
//! So agent `i`'s neighbour intervals must fit in one arc of width `W = F − 2m`, and its
//! heading is the centre of the narrowest such arc: then every neighbour stays at least
//! `m` inside the view at the target, at the initial positions and on straight paths
//! between ([`view_check`] checks the first two on the written positions).
//!
//! The graph is grown by Henneberg type-1 steps (a new agent joined to both ends of an
//! edge: a triangulated Laman graph, SPEC §3) and a step is taken only when the three
//! agents' arcs stay within `W`, every interior angle beyond the angle margin and every
//! agent within capacity. Overlapping triangles are allowed. Each step takes the best
//! candidate by the smallest angle, the edge length, the arcs' slack and the agent's
//! urgency (an agent with one or two candidates left goes first); when the growth gets
//! stuck it starts again from another start triangle with randomised scores, up to
//! [`attempts`] times (deterministic for a seed), and then refuses, naming the agent that
//! could not join and why.

use super::error::DesignError;
use super::geometry::{angles, covers, dist, interiors_overlap};
use super::laman::{controlled, figures, Construction, DesignOptions, DesignTriangle};
use super::neighbours::{check_points, point_tree};
use super::points::Point;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use std::f64::consts::{PI, TAU};

/// Points whose edges a new agent may join (its nearest, placed or not).
const NEAR: usize = 12;
/// Start triangles kept, best first.
const STARTS: usize = 64;
/// Smallest angle beyond which a triangle counts as good (rad, 35°), as in `grow.rs`.
const THETA_GOOD: f64 = 35.0 * PI / 180.0;

/// What the camera design needs besides [`DesignOptions`].
#[derive(Clone, Debug, PartialEq)]
pub struct CameraOptions {
    /// Field of view `F` (degrees, in (0, 360)).
    pub fov_deg: f64,
    /// Heading margin `m` (degrees, ≥ 0): every neighbour stays this far inside the view.
    pub heading_margin_deg: f64,
    /// Every agent's displacement `d_i` from its target as drawn
    /// ([`super::initial::displacements`]); the initial position is the target plus
    /// `s_i d_i`, `0 < s_i ≤ 1`. Empty: the agents start at the target.
    pub displacement: Vec<Point>,
    /// Camera range (m): every edge plus twice the largest displacement must be within it.
    pub range: f64,
    /// Line-of-sight clearance (m): no other point may lie this close to an edge at the
    /// target (the bodies' occlusion radius plus room for the motion).
    pub clearance: f64,
    /// Seed of the restarts' randomised scores.
    pub seed: u64,
}

/// A construction and the headings that keep every neighbour in view.
#[derive(Clone, Debug, PartialEq)]
pub struct CameraDesign {
    /// The triangles.
    pub construction: Construction,
    /// Every agent's heading (rad, in (−π, π]): the centre of its narrowest arc.
    pub headings: Vec<f64>,
    /// The widest arc an agent needs (degrees) and that agent (point index).
    pub widest: (f64, usize),
    /// The attempt that succeeded (1-based).
    pub attempt: usize,
}

/// Attempts before refusing: 1,000 up to 30 agents, fewer beyond (a failed attempt costs
/// O(N²)): the smallest fields of view of docs/design.md were found with these.
pub fn attempts(n: usize) -> usize {
    (30_000 / n.max(1)).clamp(16, 1000)
}

/// The narrowest arc covering angular intervals `(centre, half width)`: `(width, centre)`
/// (rad); `(2π, 0)` when none but the whole circle does.
pub fn cover(intervals: &[(f64, f64)]) -> (f64, f64) {
    let mut best = (TAU, 0.0);
    for &(ck, hk) in intervals {
        let lo = ck - hk;
        let mut width = 0.0f64;
        let mut ok = true;
        for &(cj, hj) in intervals {
            let s = (cj - hj - lo).rem_euclid(TAU);
            let e = (cj + hj - lo).rem_euclid(TAU);
            if s > e + 1e-12 {
                ok = false;
                break;
            }
            width = width.max(e);
        }
        if ok && width < best.0 {
            best = (width, wrap(lo + 0.5 * width));
        }
    }
    if intervals.is_empty() {
        (0.0, 0.0)
    } else {
        best
    }
}

/// An angle in (−π, π].
fn wrap(x: f64) -> f64 {
    let y = x.rem_euclid(TAU);
    if y > PI {
        y - TAU
    } else {
        y
    }
}

/// The bearing of `b` seen from `a` (rad).
fn bearing(a: Point, b: Point) -> f64 {
    (b[1] - a[1]).atan2(b[0] - a[0])
}

/// Checks, independently of the design, that at `positions` every triangle neighbour of
/// every agent is at least `margin` (rad) inside its field of view `fov` (rad) about its
/// heading (to 1e-9 rad). Returns the smallest slack (rad), or the first agent, neighbour
/// and how far off its boresight the neighbour is (rad).
pub fn view_check(
    positions: &[Point],
    triangles: &[[usize; 3]],
    headings: &[f64],
    fov: f64,
    margin: f64,
) -> Result<f64, (usize, usize, f64)> {
    let mut slack = f64::INFINITY;
    for t in triangles {
        for &i in t {
            for &j in t.iter().filter(|&&j| j != i) {
                let off = wrap(bearing(positions[i], positions[j]) - headings[i]).abs();
                let s = 0.5 * fov - margin - off;
                // 1e-9 rad: rounding of a neighbour exactly at the edge of the arc.
                if s < -1e-9 {
                    return Err((i, j, off));
                }
                slack = slack.min(s);
            }
        }
    }
    Ok(slack)
}

/// Designs the triangles and headings (see the module documentation), or refuses.
pub fn construct_for_camera(
    points: &[Point],
    opts: &DesignOptions,
    cam: &CameraOptions,
) -> Result<CameraDesign, DesignError> {
    let refuse = |reason: String| Err(DesignError::Camera(reason));
    if !(cam.fov_deg.is_finite() && cam.fov_deg > 0.0 && cam.fov_deg < 360.0) {
        return refuse(format!(
            "the field of view must be in (0, 360) degrees here, got {}",
            cam.fov_deg
        ));
    }
    if !(cam.heading_margin_deg.is_finite() && cam.heading_margin_deg >= 0.0) {
        return refuse(format!(
            "the heading margin must be a finite angle ≥ 0 degrees, got {}",
            cam.heading_margin_deg
        ));
    }
    let w_deg = cam.fov_deg - 2.0 * cam.heading_margin_deg;
    if w_deg <= 60.0 {
        return refuse(format!(
            "F − 2·margin = {}° − 2·{}° = {w_deg}° ≤ 60°: every triangle has an angle of at \
             least 60°, and that corner must see both others within F − 2·margin, so no \
             triangle fits (widen the field of view or lower --heading-margin-deg)",
            cam.fov_deg, cam.heading_margin_deg
        ));
    }
    let tree = point_tree(points);
    check_points(points, &tree)?;
    let n = points.len();
    let near: Vec<Vec<usize>> = points
        .iter()
        .enumerate()
        .map(|(i, &p)| {
            tree.nearest_neighbor_iter(p)
                .filter(|q| q.data != i)
                .take(NEAR)
                .map(|q| q.data)
                .collect()
        })
        .collect();
    let g = Growth {
        pts: points,
        near: &near,
        w: w_deg.to_radians(),
        margin: opts.margin_deg.to_radians(),
        disp: &cam.displacement,
        range: cam.range
            - 2.0
                * cam
                    .displacement
                    .iter()
                    .map(|d| d[0].hypot(d[1]))
                    .fold(0.0, f64::max),
        clearance: cam.clearance,
        tree: &tree,
        mt: opts.max_triangles,
        nb: opts.max_neighbours,
    };
    let starts = g.starts(opts.leader);
    if starts.is_empty() {
        return refuse(format!(
            "no triangle{} has every angle above the {}° margin and each corner's two \
             neighbours within F − 2·margin = {w_deg}°",
            opts.leader.map_or_else(String::new, |[a, b]| format!(
                " on the leader edge ({}, {})",
                a + 1,
                b + 1
            )),
            opts.margin_deg
        ));
    }
    let total = attempts(n);
    let mut worst: Option<Stuck> = None;
    for k in 0..total {
        let start = starts[k % starts.len()];
        let noise = if k == 0 {
            0.0
        } else {
            0.25 + 1.5 * (k % 8) as f64 / 8.0
        };
        let mut rng = ChaCha8Rng::seed_from_u64(cam.seed ^ (k as u64).wrapping_mul(0x9E37));
        match g.attempt(start, noise, &mut rng) {
            Ok(tris) => return Ok(g.finish(tris, opts, k + 1)),
            Err(s) => {
                if worst.as_ref().is_none_or(|w| s.placed > w.placed) {
                    worst = Some(s);
                }
            }
        }
    }
    let s = worst.map_or_else(String::new, |s| s.reason);
    refuse(format!(
        "no design with F = {}° and heading margin {}° (neighbour arcs of at most {w_deg}°) \
         after {total} attempts; the furthest got stuck at {s}",
        cam.fov_deg, cam.heading_margin_deg
    ))
}

/// Why an attempt stopped.
struct Stuck {
    placed: usize,
    reason: String,
}

struct Growth<'a> {
    pts: &'a [Point],
    near: &'a [Vec<usize>],
    /// Allowed arc width `W` (rad).
    w: f64,
    /// Angle margin (rad).
    margin: f64,
    disp: &'a [Point],
    /// Longest edge allowed (m).
    range: f64,
    clearance: f64,
    tree: &'a super::neighbours::PointTree,
    mt: usize,
    nb: usize,
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
    fn interval(&self, i: usize, j: usize) -> (f64, f64) {
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

    fn min_angle(&self, t: [usize; 3]) -> f64 {
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
    fn starts(&self, leader: Option<[usize; 2]>) -> Vec<[usize; 3]> {
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
    fn attempt(
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
    fn finish(&self, tris: Vec<[usize; 3]>, opts: &DesignOptions, attempt: usize) -> CameraDesign {
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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn cover_finds_the_narrowest_arc_across_the_cut() {
        let d = |x: f64| x.to_radians();
        let (w, c) = cover(&[(d(170.0), 0.0), (d(-170.0), 0.0)]);
        assert!((w - d(20.0)).abs() < 1e-12 && (c.abs() - PI).abs() < 1e-12);
        let (w, c) = cover(&[(d(10.0), d(5.0)), (d(80.0), d(5.0))]);
        assert!((w - d(80.0)).abs() < 1e-12 && (c - d(45.0)).abs() < 1e-12);
        // Three directions 120° apart need 240°.
        let (w, _) = cover(&[(0.0, 0.0), (d(120.0), 0.0), (d(240.0), 0.0)]);
        assert!((w - d(240.0)).abs() < 1e-9);
    }

    /// The neighbour interval holds the bearing for every shortening of the two
    /// displacements and every point of straight paths to the target; a negative control:
    /// an interval of the target bearing alone does not.
    #[test]
    fn the_neighbour_interval_holds_every_bearing_on_the_way() {
        let pts = [[0.0, 0.0], [1.0, 0.0], [0.5, 0.8]];
        let disp = [[0.08, -0.05], [-0.03, 0.09], [0.0, 0.0]];
        let tree = point_tree(&pts);
        let near = vec![vec![1, 2], vec![0, 2], vec![0, 1]];
        let g = Growth {
            pts: &pts,
            near: &near,
            w: PI,
            margin: 0.1,
            disp: &disp,
            range: 10.0,
            clearance: 0.0,
            tree: &tree,
            mt: 8,
            nb: 12,
        };
        let (c, h) = g.interval(0, 1);
        let mut missed_by_target_only = false;
        for k in 0..=20 {
            for l in 0..=20 {
                let (a, b) = (k as f64 / 20.0, l as f64 / 20.0);
                let e = [
                    pts[1][0] - pts[0][0] + b * disp[1][0] - a * disp[0][0],
                    pts[1][1] - pts[0][1] + b * disp[1][1] - a * disp[0][1],
                ];
                let off = wrap(e[1].atan2(e[0]) - c).abs();
                assert!(off <= h + 1e-12, "{a} {b}: {off} > {h}");
                missed_by_target_only |= e[1].atan2(e[0]).abs() > 1e-3;
            }
        }
        assert!(h > 0.05 && missed_by_target_only);
    }
}
