//! Who may share a triangle with whom: the Delaunay neighbours of every point (spade), and
//! the input checks that must pass first (duplicates, collinear points).
//!
//! The Delaunay triangulation maximises the smallest angle over all triangulations of the
//! points and its edges join natural neighbours, so its neighbour lists are the candidates
//! of the construction (`grow.rs`). A point's nearest neighbour is always one of its
//! Delaunay neighbours. Points on one circle (regular polygons) have many Delaunay
//! triangulations, some with a vertex of very high degree; each list is therefore cut to
//! the `cap` nearest and then made symmetric, which keeps the total size `O(N·cap)`.

use super::error::DesignError;
use super::geometry::dist;
use super::points::Point;
use rstar::primitives::GeomWithData;
use rstar::RTree;
use spade::{DelaunayTriangulation, HasPosition, Point2, Triangulation};

/// A point with its index, for spade and rstar.
#[derive(Clone, Copy, Debug)]
struct Indexed {
    p: Point,
    i: usize,
}

impl HasPosition for Indexed {
    type Scalar = f64;
    fn position(&self) -> Point2<f64> {
        Point2::new(self.p[0], self.p[1])
    }
}

/// The points in an R*-tree, each with its index.
pub(crate) type PointTree = RTree<GeomWithData<Point, usize>>;

/// Builds the R*-tree of the points.
pub(crate) fn point_tree(points: &[Point]) -> PointTree {
    RTree::bulk_load(
        points
            .iter()
            .enumerate()
            .map(|(i, &p)| GeomWithData::new(p, i))
            .collect(),
    )
}

/// Compressed neighbour lists.
#[derive(Clone, Debug, Default)]
pub(crate) struct Neighbours {
    start: Vec<usize>,
    list: Vec<u32>,
    /// Distance from each point to its nearest neighbour (m).
    pub nearest: Vec<f64>,
}

impl Neighbours {
    /// Point `i`'s neighbours, nearest first.
    pub fn of(&self, i: usize) -> &[u32] {
        &self.list[self.start[i]..self.start[i + 1]]
    }
}

/// Refuses non-finite coordinates, fewer than 3 points, coinciding points (closer than
/// `1e-9` of the extent) and points all on one line.
pub(crate) fn check_points(points: &[Point], tree: &PointTree) -> Result<(), DesignError> {
    if let Some(i) = points
        .iter()
        .position(|p| !(p[0].is_finite() && p[1].is_finite()))
    {
        return Err(DesignError::Points {
            file: "<points>".to_owned(),
            reason: format!("point {i} is not two finite numbers: {:?}", points[i]),
        });
    }
    if points.len() < 3 {
        return Err(DesignError::TooFewPoints(points.len()));
    }
    let (lo, hi) = points.iter().fold(
        ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]),
        |(lo, hi), p| {
            (
                [lo[0].min(p[0]), lo[1].min(p[1])],
                [hi[0].max(p[0]), hi[1].max(p[1])],
            )
        },
    );
    let extent = dist(lo, hi);
    let tol = 1e-9 * extent;
    let mut pairs = Vec::new();
    let mut at = Vec::new();
    for (i, &p) in points.iter().enumerate() {
        for q in tree.locate_within_distance(p, tol * tol) {
            if q.data > i {
                pairs.push([i, q.data]);
                at.push(p);
            }
        }
    }
    if !pairs.is_empty() {
        pairs.sort_unstable();
        return Err(DesignError::DuplicatePoints { pairs, at });
    }
    // The point farthest from point 0, then the largest distance from that line.
    let p0 = points[0];
    let far = points
        .iter()
        .copied()
        .max_by(|a, b| dist(p0, *a).total_cmp(&dist(p0, *b)))
        .unwrap_or(p0);
    let base = dist(p0, far);
    let height = points
        .iter()
        .map(|&p| super::geometry::cross(p0, far, p).abs() / base)
        .fold(0.0, f64::max);
    if height <= 1e-9 * base {
        return Err(DesignError::Collinear { n: points.len() });
    }
    Ok(())
}

/// The Delaunay neighbour lists, each cut to its `cap` nearest and made symmetric.
/// `points` must have passed [`check_points`].
pub(crate) fn delaunay_neighbours(points: &[Point], cap: usize) -> Result<Neighbours, DesignError> {
    let vertices: Vec<Indexed> = points
        .iter()
        .enumerate()
        .map(|(i, &p)| Indexed { p, i })
        .collect();
    let dt =
        DelaunayTriangulation::<Indexed>::bulk_load(vertices).map_err(|e| DesignError::Points {
            file: "<points>".to_owned(),
            reason: format!("cannot triangulate the points: {e:?}"),
        })?;
    let n = points.len();
    let mut adj: Vec<Vec<u32>> = vec![Vec::new(); n];
    for e in dt.undirected_edges() {
        let [a, b] = e.vertices();
        let (i, j) = (a.data().i, b.data().i);
        adj[i].push(j as u32);
        adj[j].push(i as u32);
    }
    let mut nearest = vec![f64::INFINITY; n];
    for (i, list) in adj.iter_mut().enumerate() {
        list.sort_by(|&a, &b| {
            dist(points[i], points[a as usize])
                .total_cmp(&dist(points[i], points[b as usize]))
                .then(a.cmp(&b))
        });
        list.dedup();
        if let Some(&j) = list.first() {
            nearest[i] = dist(points[i], points[j as usize]);
        }
        list.truncate(cap);
    }
    // Symmetric closure.
    let mut extra: Vec<(u32, u32)> = Vec::new();
    for (i, list) in adj.iter().enumerate() {
        for &j in list {
            if !adj[j as usize].contains(&(i as u32)) {
                extra.push((j, i as u32));
            }
        }
    }
    for (j, i) in extra {
        adj[j as usize].push(i);
    }
    let mut start = Vec::with_capacity(n + 1);
    let mut list = Vec::new();
    start.push(0);
    for (i, l) in adj.iter_mut().enumerate() {
        l.sort_by(|&a, &b| {
            dist(points[i], points[a as usize])
                .total_cmp(&dist(points[i], points[b as usize]))
                .then(a.cmp(&b))
        });
        l.dedup();
        list.extend_from_slice(l);
        start.push(list.len());
    }
    Ok(Neighbours {
        start,
        list,
        nearest,
    })
}
