//! From target points to a triangulated Laman graph (SPEC §3) with two controlled angles
//! per triangle and their desired values.
//!
//! # What is maximised, and why
//!
//! A triangle's shape (up to similarity) follows from any two of its angles, and its
//! sensitivity to angle errors is governed by all three: with the sine rule
//! `∂ log(a/b)/∂A = cot A`, so a small angle *anywhere* in the triangle, controlled or
//! not, makes the shape ill-conditioned (the new agent sits where two nearly parallel
//! rays cross). In a triangle with angles `a ≤ b ≤ c` the margins `min(α, π − α)` are
//! `a`, `b` and `min(c, a + b)`, and `a` is the smallest of them. So the construction
//!
//! * maximises the **smallest interior angle** of every triangle (bottleneck-greedy,
//!   `grow.rs`), which is also what the loader needs: every desired angle, the third
//!   angle and every initial interior angle must be beyond the angle margin;
//! * controls in each triangle the **two angles with the largest margins** (it leaves the
//!   smallest angle uncontrolled). The controller acts on `cos α` (S4), whose slope
//!   `sin α` vanishes at 0 and π; dropping the smallest angle maximises the smallest
//!   controlled margin, which is then the triangle's middle angle (≥ its smallest angle).
//!
//! Ties go to short edges (radio range) and lightly loaded agents (capacity MT, NB); new
//! triangles lie on the far side of the edge they are glued to and cover no other point
//! whenever such a triangle exists.

use super::error::{DesignError, VerifyError};
use super::geometry::{angle_at, angles, dist, margin};
use super::grow::{grow, Params};
use super::neighbours::{check_points, delaunay_neighbours, point_tree};
use super::points::Point;
use std::collections::HashSet;
use std::f64::consts::PI;

/// Default angle margin (degrees), as the loader's `controller.angle_margin_deg`.
pub const DEFAULT_MARGIN_DEG: f64 = 5.0;
/// Default triangles per agent: the controller-core capacity `MT`.
pub const DEFAULT_MAX_TRIANGLES: usize = crate::model::MT;
/// Default neighbours per agent: the controller-core capacity `NB`.
pub const DEFAULT_MAX_NEIGHBOURS: usize = crate::model::NB;
/// A construction whose smallest controlled angle is below this (degrees) is grown again
/// with the margin raised in steps of [`RAISE_STEP_DEG`] up to [`RAISE_MAX_DEG`], keeping
/// the last that succeeds. The controller acts on `cos α` (S4), whose slope `sin α` is
/// 0.13 at 7.5°: points on a circle (a ring of agents) grown with the default 5° margin
/// get angles of 180°/N between near neighbours and never converge (measured: 50-gons,
/// docs/design.md), while a margin of 20–30° forces triangles across the ring that do.
pub const RAISE_BELOW_DEG: f64 = 15.0;
/// Step of the margin raise (degrees).
pub const RAISE_STEP_DEG: f64 = 5.0;
/// Highest margin tried by the raise (degrees).
pub const RAISE_MAX_DEG: f64 = 30.0;
/// Delaunay neighbours kept per point (nearest first; see `neighbours.rs`).
const NEIGHBOUR_CAP: usize = 16;

/// Options of [`construct`].
#[derive(Clone, Debug, PartialEq)]
pub struct DesignOptions {
    /// Every interior angle of every triangle must exceed this (degrees, in (0, 60)).
    pub margin_deg: f64,
    /// Triangles per agent at most (firmware capacity MT).
    pub max_triangles: usize,
    /// Neighbours per agent at most (firmware capacity NB).
    pub max_neighbours: usize,
    /// Leader edge as two point indices; the construction starts from it. `None`: the best
    /// triangle near the centroid starts it and its shortest edge is the leader edge.
    pub leader: Option<[usize; 2]>,
}

impl Default for DesignOptions {
    fn default() -> Self {
        Self {
            margin_deg: DEFAULT_MARGIN_DEG,
            max_triangles: DEFAULT_MAX_TRIANGLES,
            max_neighbours: DEFAULT_MAX_NEIGHBOURS,
            leader: None,
        }
    }
}

/// One controlled angle (S4): apex point index and desired value.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ControlledAngle {
    /// Point index of the apex.
    pub apex: usize,
    /// α* (rad): the angle the target positions make at the apex.
    pub desired: f64,
}

/// One triangle of the construction.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DesignTriangle {
    /// `[a, b, new]`: `ab` is an edge of the triangles before, `new` joins here (the first
    /// triangle: `ab` is the start edge).
    pub vertices: [usize; 3],
    /// The two controlled angles.
    pub angles: [ControlledAngle; 2],
    /// Whether no triangle on the far side of its edge (and covering no point) was left,
    /// so it overlaps a triangle before it or covers a point.
    pub overlapping: bool,
}

/// Figures of merit of a construction.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Figures {
    /// Agents N.
    pub agents: usize,
    /// Triangles M = N − 2.
    pub triangles: usize,
    /// Smallest margin `min(α*, 180° − α*)` of a controlled angle (degrees).
    pub min_controlled_deg: f64,
    /// Smallest interior angle of a triangle (degrees).
    pub min_angle_deg: f64,
    /// Largest number of triangles of one agent.
    pub max_triangles_per_agent: usize,
    /// Largest number of neighbours of one agent.
    pub max_neighbours_per_agent: usize,
    /// Longest edge (m).
    pub longest_edge: f64,
    /// Mean edge length (m).
    pub mean_edge: f64,
    /// Triangles that overlap a triangle before them or cover a point.
    pub overlapping: usize,
}

/// A triangulated Laman graph over the points.
#[derive(Clone, Debug, PartialEq)]
pub struct Construction {
    /// Triangles in construction order.
    pub triangles: Vec<DesignTriangle>,
    /// Leader edge (point indices): an edge of the first triangle.
    pub leader: [usize; 2],
    /// The angle margin the growth ran with (degrees): the option's, or a higher one when
    /// the option's gave thin angles ([`RAISE_BELOW_DEG`]).
    pub margin_deg: f64,
    /// Figures of merit.
    pub figures: Figures,
}

impl DesignOptions {
    fn check(&self) -> Result<(), DesignError> {
        let bad = |option: &str, reason: String| {
            Err(DesignError::Option {
                option: option.to_owned(),
                reason,
            })
        };
        if !(self.margin_deg.is_finite() && self.margin_deg > 0.0 && self.margin_deg < 60.0) {
            return bad(
                "margin",
                format!(
                    "must be in (0, 60) degrees (no triangle has every angle above 60°), got {}",
                    self.margin_deg
                ),
            );
        }
        if self.max_triangles < 1 {
            return bad("max-triangles", "must be at least 1".to_owned());
        }
        if self.max_neighbours < 2 {
            return bad("max-neighbours", "must be at least 2".to_owned());
        }
        Ok(())
    }
}

/// Builds a triangulated Laman graph over `points` (see the module documentation):
/// `N − 2` triangles, each with two controlled angles, every interior angle beyond the
/// margin and every agent within capacity, or a [`DesignError`] naming the points that
/// could not be attached and why. O(N log N).
pub fn construct(points: &[Point], opts: &DesignOptions) -> Result<Construction, DesignError> {
    opts.check()?;
    let tree = point_tree(points);
    check_points(points, &tree)?;
    let nb = delaunay_neighbours(points, NEIGHBOUR_CAP)?;
    let attempt = |margin_deg: f64| -> Result<Construction, DesignError> {
        let grown = grow(
            points,
            &nb,
            &tree,
            Params {
                margin: margin_deg.to_radians(),
                max_triangles: opts.max_triangles,
                max_neighbours: opts.max_neighbours,
                leader: opts.leader,
            },
        )?;
        let triangles: Vec<DesignTriangle> = grown
            .triangles
            .iter()
            .zip(&grown.overlapping)
            .map(|(&t, &overlapping)| DesignTriangle {
                vertices: t,
                angles: controlled(points, t),
                overlapping,
            })
            .collect();
        let leader = [grown.triangles[0][0], grown.triangles[0][1]];
        let figures = figures(points, &triangles);
        Ok(Construction {
            triangles,
            leader,
            margin_deg,
            figures,
        })
    };
    let mut best = attempt(opts.margin_deg)?;
    if best.figures.min_controlled_deg < RAISE_BELOW_DEG {
        let mut m = (opts.margin_deg / RAISE_STEP_DEG).floor() * RAISE_STEP_DEG + RAISE_STEP_DEG;
        while m <= RAISE_MAX_DEG {
            match attempt(m) {
                Ok(c) if c.figures.min_controlled_deg > best.figures.min_controlled_deg => best = c,
                Ok(_) => {}
                Err(_) => break,
            }
            m += RAISE_STEP_DEG;
        }
    }
    Ok(best)
}

/// The two angles of triangle `t` with the largest margins; ties prefer the new agent,
/// then `a`, then `b`.
pub(super) fn controlled(points: &[Point], t: [usize; 3]) -> [ControlledAngle; 2] {
    let a = angles(t.map(|v| points[v]));
    let mut order = [2usize, 0, 1];
    order.sort_by(|&x, &y| margin(a[y]).total_cmp(&margin(a[x])));
    [order[0], order[1]].map(|k| ControlledAngle {
        apex: t[k],
        desired: a[k],
    })
}

/// The figures of a list of triangles in construction order.
pub(super) fn figures(points: &[Point], triangles: &[DesignTriangle]) -> Figures {
    let n = triangles.len() + 2;
    let mut tri_count = vec![0usize; n.max(points.len())];
    let mut nbrs = vec![0usize; n.max(points.len())];
    let mut edges = Vec::with_capacity(2 * n);
    let mut min_controlled = f64::INFINITY;
    let mut min_angle = f64::INFINITY;
    for (k, t) in triangles.iter().enumerate() {
        let [a, b, c] = t.vertices;
        for v in t.vertices {
            tri_count[v] += 1;
        }
        let new_edges: &[[usize; 2]] = if k == 0 {
            &[[a, b], [a, c], [b, c]]
        } else {
            &[[a, c], [b, c]]
        };
        for &[x, y] in new_edges {
            nbrs[x] += 1;
            nbrs[y] += 1;
            edges.push(dist(points[x], points[y]));
        }
        for ang in angles(t.vertices.map(|v| points[v])) {
            min_angle = min_angle.min(ang);
        }
        for ca in t.angles {
            min_controlled = min_controlled.min(margin(ca.desired));
        }
    }
    Figures {
        agents: n,
        triangles: triangles.len(),
        min_controlled_deg: min_controlled.to_degrees(),
        min_angle_deg: min_angle.to_degrees(),
        max_triangles_per_agent: tri_count.iter().copied().max().unwrap_or(0),
        max_neighbours_per_agent: nbrs.iter().copied().max().unwrap_or(0),
        longest_edge: edges.iter().copied().fold(0.0, f64::max),
        mean_edge: edges.iter().sum::<f64>() / edges.len().max(1) as f64,
        overlapping: triangles.iter().filter(|t| t.overlapping).count(),
    }
}

/// Checks a construction independently of how it was built: a triangulated Laman graph
/// on all points in the listed order (M = N − 2, each triangle after the first joins its
/// new agent to an existing edge), two controlled angles per triangle at distinct apexes
/// with the desired values the points realise, every interior angle beyond the margin,
/// capacities, and a leader edge that is an edge. Returns the first problem found.
pub fn verify(points: &[Point], c: &Construction, opts: &DesignOptions) -> Result<(), VerifyError> {
    let n = points.len();
    if c.triangles.len() + 2 != n {
        return Err(VerifyError::TriangleCount {
            points: n,
            triangles: c.triangles.len(),
        });
    }
    let key = |x: usize, y: usize| (x.min(y), x.max(y));
    let mut placed = vec![false; n];
    let mut edges: HashSet<(usize, usize)> = HashSet::new();
    let mut tri_count = vec![0usize; n];
    let margin_rad = opts.margin_deg.to_radians();
    for (k, t) in c.triangles.iter().enumerate() {
        let [a, b, v] = t.vertices;
        let vertices = t.vertices;
        if t.vertices.iter().any(|&x| x >= n) || a == b || b == v || a == v {
            return Err(VerifyError::NotDistinct { k, vertices });
        }
        if k == 0 {
            placed[a] = true;
            placed[b] = true;
            edges.insert(key(a, b));
        } else if !(placed[a] && placed[b] && edges.contains(&key(a, b))) {
            return Err(VerifyError::NotOnAnEdge { k, vertices });
        }
        if placed[v] {
            return Err(VerifyError::AlreadyPlaced { k, vertices });
        }
        placed[v] = true;
        edges.insert(key(a, v));
        edges.insert(key(b, v));
        for x in t.vertices {
            tri_count[x] += 1;
        }
        let p = t.vertices.map(|x| points[x]);
        if let Some(th) = angles(p)
            .into_iter()
            .find(|&th| th.is_nan() || th <= margin_rad)
        {
            return Err(VerifyError::AngleWithinMargin {
                k,
                vertices,
                angle_deg: th.to_degrees(),
                margin_deg: opts.margin_deg,
            });
        }
        let [x, y] = t.angles;
        if x.apex == y.apex || !t.vertices.contains(&x.apex) || !t.vertices.contains(&y.apex) {
            return Err(VerifyError::Apexes {
                k,
                first: x.apex,
                second: y.apex,
            });
        }
        for ca in t.angles {
            let far: Vec<Point> = t
                .vertices
                .iter()
                .filter(|&&q| q != ca.apex)
                .map(|&q| points[q])
                .collect();
            let actual = angle_at(points[ca.apex], far[0], far[1]);
            if (actual - ca.desired).abs() > 1e-9
                || margin(ca.desired).is_nan()
                || margin(ca.desired) <= margin_rad
            {
                return Err(VerifyError::DesiredAngle {
                    k,
                    apex: ca.apex,
                    actual_deg: actual.to_degrees(),
                    desired_deg: ca.desired.to_degrees(),
                });
            }
        }
        if PI - x.desired - y.desired <= margin_rad {
            return Err(VerifyError::NoThirdAngle { k });
        }
    }
    if let Some(i) = placed.iter().position(|p| !p) {
        return Err(VerifyError::Unplaced(i));
    }
    let mut nbrs = vec![0usize; n];
    for &(x, y) in &edges {
        nbrs[x] += 1;
        nbrs[y] += 1;
    }
    if let Some(i) =
        (0..n).find(|&i| tri_count[i] > opts.max_triangles || nbrs[i] > opts.max_neighbours)
    {
        return Err(VerifyError::Capacity {
            point: i,
            triangles: tri_count[i],
            neighbours: nbrs[i],
            max_triangles: opts.max_triangles,
            max_neighbours: opts.max_neighbours,
        });
    }
    if !edges.contains(&key(c.leader[0], c.leader[1])) {
        return Err(VerifyError::LeaderNotAnEdge(c.leader));
    }
    Ok(())
}
