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
//! could not join and why. After the first design it tries [`MORE_ATTEMPTS`] more and
//! writes the one whose thinnest triangle is widest.

use super::error::DesignError;
use super::laman::{Construction, DesignOptions};
use super::neighbours::{check_points, point_tree};
use super::points::Point;
use growth::{Growth, Stuck};
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use std::f64::consts::{PI, TAU};

mod growth;

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

/// Attempts after the first that found a design, the best of which is written.
pub const MORE_ATTEMPTS: usize = 32;

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
    // After the first design, [`MORE_ATTEMPTS`] more, and the one whose thinnest triangle
    // is widest wins (the thinner the triangles, the more the angles' errors move the
    // agents): `(smallest interior angle, triangles, attempt)`.
    let mut best: Option<(f64, Vec<[usize; 3]>, usize)> = None;
    let mut first_ok = None;
    for k in 0..total {
        if first_ok.is_some_and(|f: usize| k > f + MORE_ATTEMPTS) {
            break;
        }
        let start = starts[k % starts.len()];
        let noise = if k == 0 {
            0.0
        } else {
            0.25 + 1.5 * (k % 8) as f64 / 8.0
        };
        let mut rng = ChaCha8Rng::seed_from_u64(cam.seed ^ (k as u64).wrapping_mul(0x9E37));
        match g.attempt(start, noise, &mut rng) {
            Ok(tris) => {
                first_ok.get_or_insert(k);
                let thinnest = tris
                    .iter()
                    .map(|&t| g.min_angle(t))
                    .fold(f64::INFINITY, f64::min);
                if best.as_ref().is_none_or(|(q, ..)| thinnest > *q) {
                    best = Some((thinnest, tris, k + 1));
                }
            }
            Err(s) => {
                if worst.as_ref().is_none_or(|w| s.placed > w.placed) {
                    worst = Some(s);
                }
            }
        }
    }
    if let Some((_, tris, attempt)) = best {
        return Ok(g.finish(tris, opts, attempt));
    }
    let s = worst.map_or_else(String::new, |s| s.reason);
    refuse(format!(
        "no design with F = {}° and heading margin {}° (neighbour arcs of at most {w_deg}°) \
         after {total} attempts; the furthest got stuck at {s}",
        cam.fov_deg, cam.heading_margin_deg
    ))
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
