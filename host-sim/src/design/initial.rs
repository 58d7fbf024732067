//! Initial positions: the target, optionally rotated about its centroid, plus a seeded
//! random displacement per agent, kept valid for the loader.

use super::error::DesignError;
use super::geometry::{angles, cross, dist};
use super::laman::Construction;
use super::neighbours::point_tree;
use super::points::Point;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use std::f64::consts::PI;

/// What [`Perturbation::fraction`] is a fraction of.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Scale {
    /// The formation's size (its RMS distance from the centroid), the same for every
    /// agent: a global measure, as a basin-of-attraction sweep wants.
    #[default]
    Size,
    /// The formation's spacing: the median over the points of the distance to the nearest
    /// other point. A local measure that means the same at any N and for any shape (10 %
    /// moves an agent of a 1 m-spaced ring 0.1 m, whatever the ring's diameter or the
    /// length of its graph's diagonals; a lone centre point moves no further than the
    /// others).
    Spacing,
}

/// How the initial positions leave the target.
#[derive(Clone, Debug, PartialEq)]
pub struct Perturbation {
    /// Largest displacement as a fraction of [`Perturbation::scale`], in `[0, 1]`. Each
    /// agent's displacement is uniform in that disc.
    pub fraction: f64,
    /// What the fraction is of.
    pub scale: Scale,
    /// Rotate the whole formation by a random angle about its centroid.
    pub rotate: bool,
    /// Seed (the same seed gives the same positions on every machine).
    pub seed: u64,
}

impl Default for Perturbation {
    fn default() -> Self {
        Self {
            fraction: 0.05,
            scale: Scale::Size,
            rotate: false,
            seed: 1,
        }
    }
}

/// Initial positions and what was done to make them.
#[derive(Clone, Debug, PartialEq)]
pub struct Initial {
    /// `q(0)` of every agent, in point order.
    pub positions: Vec<Point>,
    /// Rotation applied about the centroid (rad).
    pub rotation: f64,
    /// Largest displacement allowed, over all agents (m).
    pub max_displacement: f64,
    /// Agents whose displacement was shortened (see [`initial_positions`]).
    pub shortened: usize,
}

/// RMS distance of the points from their centroid (m).
pub fn formation_size(points: &[Point]) -> f64 {
    let n = points.len().max(1) as f64;
    let c = points
        .iter()
        .fold([0.0, 0.0], |s, p| [s[0] + p[0] / n, s[1] + p[1] / n]);
    (points.iter().map(|p| dist(*p, c).powi(2)).sum::<f64>() / n).sqrt()
}

/// Target + rotation + displacement. Every triangle must start with each interior angle
/// beyond `margin_deg` (the loader refuses nearly collinear initial triangles) and with
/// the orientation it has in the target (a triangle that starts mirrored can converge
/// mirrored: the angles cannot tell), and no two agents may start closer than
/// `collision_distance` (m). Agents of a triangle or pair that breaks a rule have their
/// displacement halved, repeatedly (deterministic), until none does.
pub fn initial_positions(
    points: &[Point],
    c: &Construction,
    p: &Perturbation,
    margin_deg: f64,
    collision_distance: f64,
) -> Result<Initial, DesignError> {
    if !(p.fraction.is_finite() && (0.0..=1.0).contains(&p.fraction)) {
        return Err(DesignError::Option {
            option: "perturbation".to_owned(),
            reason: format!("must be a fraction in [0, 1], got {}", p.fraction),
        });
    }
    let margin = margin_deg.to_radians();
    if c.figures.min_angle_deg <= margin_deg {
        return Err(DesignError::Initial(format!(
            "the construction's smallest angle {:.3}° is within the scenario's angle margin \
             {margin_deg}°: construct with a margin of at least {margin_deg}°",
            c.figures.min_angle_deg
        )));
    }
    let close = close_pairs(points, collision_distance);
    if let Some(&[i, j]) = close.first() {
        return Err(DesignError::Initial(format!(
            "target points {i} and {j} (agents {} and {}) are {} m apart, closer than the \
             collision distance {collision_distance} m: the run would end in a collision",
            i + 1,
            j + 1,
            dist(points[i], points[j])
        )));
    }
    let Draws {
        rotation,
        base,
        mut disp,
        max_displacement,
    } = draws(points, p);
    let mut shortened = vec![false; points.len()];
    for _ in 0..64 {
        let q: Vec<Point> = base
            .iter()
            .zip(&disp)
            .map(|(b, d)| [b[0] + d[0], b[1] + d[1]])
            .collect();
        let mut bad: Vec<usize> = Vec::new();
        for t in &c.triangles {
            let now = t.vertices.map(|v| q[v]);
            let target = t.vertices.map(|v| points[v]);
            let flat = angles(now).iter().any(|&a| a.is_nan() || a <= margin);
            let flipped = cross(now[0], now[1], now[2]).signum()
                != cross(target[0], target[1], target[2]).signum();
            if flat || flipped {
                bad.extend(t.vertices);
            }
        }
        bad.extend(close_pairs(&q, collision_distance).into_iter().flatten());
        if bad.is_empty() {
            return Ok(Initial {
                positions: q,
                rotation,
                max_displacement,
                shortened: shortened.iter().filter(|&&x| x).count(),
            });
        }
        bad.sort_unstable();
        bad.dedup();
        for v in bad {
            disp[v] = [disp[v][0] * 0.5, disp[v][1] * 0.5];
            shortened[v] = true;
        }
    }
    Err(DesignError::Initial(
        "no valid initial positions after shortening the displacements 64 times".to_owned(),
    ))
}

/// Every agent's displacement from its target as drawn for `p`, before any is shortened
/// (m): [`initial_positions`] moves agent `i` by `s_i` times it, `0 < s_i ≤ 1` (and turns
/// the formation first when `p.rotate`). `host-sim design --fov-deg` bounds the
/// neighbours' bearings with it.
pub fn displacements(points: &[Point], p: &Perturbation) -> Vec<Point> {
    draws(points, p).disp
}

/// The random draws of [`initial_positions`].
struct Draws {
    rotation: f64,
    base: Vec<Point>,
    disp: Vec<Point>,
    max_displacement: f64,
}

fn draws(points: &[Point], p: &Perturbation) -> Draws {
    let n = points.len() as f64;
    let centre = points
        .iter()
        .fold([0.0, 0.0], |s, q| [s[0] + q[0] / n, s[1] + q[1] / n]);
    let reach: Vec<f64> = match p.scale {
        Scale::Size => vec![p.fraction * formation_size(points); points.len()],
        Scale::Spacing => vec![p.fraction * spacing(points); points.len()],
    };
    let max_displacement = reach.iter().copied().fold(0.0, f64::max);
    let mut rng = ChaCha8Rng::seed_from_u64(p.seed);
    let turn = rng.random::<f64>() * 2.0 * PI;
    let rotation = if p.rotate { turn } else { 0.0 };
    let (s, co) = rotation.sin_cos();
    let base: Vec<Point> = points
        .iter()
        .map(|q| {
            let d = [q[0] - centre[0], q[1] - centre[1]];
            [
                centre[0] + co * d[0] - s * d[1],
                centre[1] + s * d[0] + co * d[1],
            ]
        })
        .collect();
    let disp: Vec<Point> = reach
        .iter()
        .map(|&reach| {
            let r = reach * rng.random::<f64>().sqrt();
            let a = rng.random::<f64>() * 2.0 * PI;
            [r * a.cos(), r * a.sin()]
        })
        .collect();
    Draws {
        rotation,
        base,
        disp,
        max_displacement,
    }
}

/// The median over the points of the distance to the nearest other point (0 for fewer
/// than two points).
pub fn spacing(points: &[Point]) -> f64 {
    let tree = point_tree(points);
    let mut d: Vec<f64> = points
        .iter()
        .enumerate()
        .filter_map(|(i, &p)| {
            tree.nearest_neighbor_iter(p)
                .find(|q| q.data != i)
                .map(|q| dist(p, *q.geom()))
        })
        .collect();
    if d.is_empty() {
        return 0.0;
    }
    let mid = d.len() / 2;
    *d.select_nth_unstable_by(mid, f64::total_cmp).1
}

/// Pairs of points closer than `d` (each pair once, `i < j`, sorted).
fn close_pairs(points: &[Point], d: f64) -> Vec<[usize; 2]> {
    if d <= 0.0 {
        return Vec::new();
    }
    let tree = point_tree(points);
    let mut out = Vec::new();
    for (i, &p) in points.iter().enumerate() {
        for q in tree.locate_within_distance(p, d * d) {
            if q.data > i && dist(p, points[q.data]) < d {
                out.push([i, q.data]);
            }
        }
    }
    out.sort_unstable();
    out
}
