//! A formation compared with its target shape up to translation, rotation, uniform scale
//! and a mirror image of the whole formation (angles cannot see any of these), and which
//! triangles are folded.
//!
//! The best similarity is the closed-form least-squares fit (Umeyama 1991; in 2-D with
//! points as complex numbers): with `z_i`, `w_i` the formation's and the target's points
//! minus their centroids, the map `z ↦ a·z` minimising `Σ|a·z_i − w_i|²` is
//! `a = Σ conj(z_i)·w_i / Σ|z_i|²` (scale `|a|`, rotation `arg a`), and the mirrored map
//! `z ↦ a·conj(z)` has `a = Σ z_i·w_i / Σ|z_i|²`; the one with the smaller residual
//! `Σ|w|² − |Σ…|² / Σ|z|²` wins.

use super::geometry::cross;
use thiserror::Error;

/// A position `[x, y]` (m).
pub type Point = [f64; 2];

/// Why two point sets cannot be compared.
#[derive(Clone, Debug, PartialEq, Error)]
pub enum ShapeError {
    /// Different numbers of points.
    #[error("the formation has {formation} agents but the target {target} points")]
    LengthMismatch {
        /// Formation points.
        formation: usize,
        /// Target points.
        target: usize,
    },
    /// Fewer than two points.
    #[error("a shape comparison needs at least 2 points, got {0}")]
    TooFew(usize),
    /// A coordinate is NaN or infinite.
    #[error("{which} point {index} is not finite")]
    NotFinite {
        /// `formation` or `target`.
        which: &'static str,
        /// Its index.
        index: usize,
    },
    /// All target points coincide: no size to compare against.
    #[error("the target points all coincide")]
    DegenerateTarget,
    /// A triangle names a point that does not exist.
    #[error("triangle {index} names a point outside 0..{n}")]
    BadTriangle {
        /// The triangle's index.
        index: usize,
        /// Number of points.
        n: usize,
    },
}

/// The best similarity from formation to target and what is left.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SimilarityFit {
    /// Uniform scale (target units per formation unit).
    pub scale: f64,
    /// Rotation (rad), applied after the mirror.
    pub rotation: f64,
    /// The formation is mirrored (`(x, y) ↦ (x, −y)` first).
    pub reflected: bool,
    /// Translation: target ≈ `scale·R(rotation)·M·q + translation`, `M` the mirror or `I`.
    pub translation: Point,
    /// RMS distance between fitted formation and target (target units).
    pub rms: f64,
    /// Largest distance between a fitted agent and its target point.
    pub max: f64,
    /// `rms` over the target's size (its RMS distance from its centroid).
    pub rms_rel: f64,
    /// `max` over the target's size.
    pub max_rel: f64,
}

impl SimilarityFit {
    /// Where the fit sends formation point `q`.
    pub fn apply(&self, q: Point) -> Point {
        let y = if self.reflected { -q[1] } else { q[1] };
        let (s, c) = self.rotation.sin_cos();
        [
            self.scale * (c * q[0] - s * y) + self.translation[0],
            self.scale * (s * q[0] + c * y) + self.translation[1],
        ]
    }
}

/// A comparison: the fit and the folded triangles.
#[derive(Clone, Debug, PartialEq)]
pub struct ShapeComparison {
    /// The best similarity.
    pub fit: SimilarityFit,
    /// Indices of the triangles whose orientation differs from the target's once the
    /// global mirror of the fit is taken out (a zero-area formation triangle counts as
    /// folded; a zero-area target triangle is never reported).
    pub folded: Vec<usize>,
}

fn check(formation: &[Point], target: &[Point]) -> Result<(), ShapeError> {
    if formation.len() != target.len() {
        return Err(ShapeError::LengthMismatch {
            formation: formation.len(),
            target: target.len(),
        });
    }
    if target.len() < 2 {
        return Err(ShapeError::TooFew(target.len()));
    }
    for (which, set) in [("formation", formation), ("target", target)] {
        if let Some(index) = set
            .iter()
            .position(|p| !(p[0].is_finite() && p[1].is_finite()))
        {
            return Err(ShapeError::NotFinite { which, index });
        }
    }
    Ok(())
}

fn centroid(p: &[Point]) -> Point {
    let n = p.len() as f64;
    p.iter()
        .fold([0.0, 0.0], |s, q| [s[0] + q[0] / n, s[1] + q[1] / n])
}

/// The best similarity (with optional mirror) from `formation` to `target`.
pub fn fit_similarity(formation: &[Point], target: &[Point]) -> Result<SimilarityFit, ShapeError> {
    check(formation, target)?;
    let (cz, cw) = (centroid(formation), centroid(target));
    let mut zz = 0.0;
    let mut ww = 0.0;
    // Σ conj(z)·w and Σ z·w, as (re, im).
    let mut proper = [0.0, 0.0];
    let mut mirror = [0.0, 0.0];
    for (p, q) in formation.iter().zip(target) {
        let z = [p[0] - cz[0], p[1] - cz[1]];
        let w = [q[0] - cw[0], q[1] - cw[1]];
        zz += z[0] * z[0] + z[1] * z[1];
        ww += w[0] * w[0] + w[1] * w[1];
        proper[0] += z[0] * w[0] + z[1] * w[1];
        proper[1] += z[0] * w[1] - z[1] * w[0];
        mirror[0] += z[0] * w[0] - z[1] * w[1];
        mirror[1] += z[0] * w[1] + z[1] * w[0];
    }
    if ww == 0.0 {
        return Err(ShapeError::DegenerateTarget);
    }
    let norm = |a: [f64; 2]| a[0].hypot(a[1]);
    let reflected = norm(mirror) > norm(proper) * (1.0 + 1e-12);
    let a = if reflected { mirror } else { proper };
    let (scale, rotation) = if zz > 0.0 {
        (norm(a) / zz, a[1].atan2(a[0]))
    } else {
        (0.0, 0.0)
    };
    let mut fit = SimilarityFit {
        scale,
        rotation,
        reflected,
        translation: [0.0, 0.0],
        rms: 0.0,
        max: 0.0,
        rms_rel: 0.0,
        max_rel: 0.0,
    };
    let moved = fit.apply(cz);
    fit.translation = [cw[0] - moved[0], cw[1] - moved[1]];
    let mut sum = 0.0;
    for (p, q) in formation.iter().zip(target) {
        let f = fit.apply(*p);
        let d = (f[0] - q[0]).hypot(f[1] - q[1]);
        sum += d * d;
        fit.max = fit.max.max(d);
    }
    let n = target.len() as f64;
    let size = (ww / n).sqrt();
    fit.rms = (sum / n).sqrt();
    fit.rms_rel = fit.rms / size;
    fit.max_rel = fit.max / size;
    Ok(fit)
}

/// Triangles of `triangles` whose orientation in `formation` (mirrored when `reflected`)
/// differs from their orientation in `target`.
pub fn folded_triangles(
    formation: &[Point],
    target: &[Point],
    triangles: &[[usize; 3]],
    reflected: bool,
) -> Result<Vec<usize>, ShapeError> {
    check(formation, target)?;
    let n = target.len();
    let flip = if reflected { -1.0 } else { 1.0 };
    let mut out = Vec::new();
    for (index, t) in triangles.iter().enumerate() {
        if t.iter().any(|&v| v >= n) {
            return Err(ShapeError::BadTriangle { index, n });
        }
        let [a, b, c] = *t;
        let want = cross(target[a], target[b], target[c]).signum();
        let got = flip * cross(formation[a], formation[b], formation[c]);
        if cross(target[a], target[b], target[c]) != 0.0
            && (got * want).partial_cmp(&0.0) != Some(std::cmp::Ordering::Greater)
        {
            out.push(index);
        }
    }
    Ok(out)
}

/// [`fit_similarity`] and [`folded_triangles`] together.
pub fn compare(
    formation: &[Point],
    target: &[Point],
    triangles: &[[usize; 3]],
) -> Result<ShapeComparison, ShapeError> {
    let fit = fit_similarity(formation, target)?;
    let folded = folded_triangles(formation, target, triangles, fit.reflected)?;
    Ok(ShapeComparison { fit, folded })
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{Rng, SeedableRng};
    use rand_chacha::ChaCha8Rng;

    fn strip(n: usize) -> (Vec<Point>, Vec<[usize; 3]>) {
        let h = 3f64.sqrt() / 2.0;
        let p = (0..n)
            .map(|i| [0.5 * i as f64, h * (i % 2) as f64])
            .collect();
        (p, (0..n - 2).map(|i| [i, i + 1, i + 2]).collect())
    }

    #[test]
    fn similarity_and_mirror_leave_no_residual() {
        let mut rng = ChaCha8Rng::seed_from_u64(5);
        let (target, tris) = strip(30);
        for k in 0..20 {
            let s = rng.random_range(0.1..10.0);
            let th = rng.random_range(-3.0..3.0f64);
            let t = [rng.random_range(-50.0..50.0), rng.random_range(-50.0..50.0)];
            let mirror = k % 2 == 1;
            let (sn, cs) = th.sin_cos();
            let formation: Vec<Point> = target
                .iter()
                .map(|p| {
                    let y = if mirror { -p[1] } else { p[1] };
                    [
                        s * (cs * p[0] - sn * y) + t[0],
                        s * (sn * p[0] + cs * y) + t[1],
                    ]
                })
                .collect();
            let c = compare(&formation, &target, &tris).unwrap();
            assert!(
                c.fit.rms_rel < 1e-12 && c.fit.max_rel < 1e-12,
                "{:?}",
                c.fit
            );
            assert_eq!(c.fit.reflected, mirror);
            assert!((c.fit.scale * s - 1.0).abs() < 1e-12, "{:?}", c.fit);
            assert!(c.folded.is_empty(), "{:?}", c.folded);
            for (p, q) in formation.iter().zip(&target) {
                let f = c.fit.apply(*p);
                assert!((f[0] - q[0]).abs() < 1e-9 && (f[1] - q[1]).abs() < 1e-9);
            }
        }
    }

    #[test]
    fn a_triangle_mirrored_across_its_base_is_folded() {
        let (target, tris) = strip(8);
        for mirror_all in [false, true] {
            let mut formation = target.clone();
            // Mirror the last point across the line through points 5 and 6.
            let (a, b, p) = (target[5], target[6], target[7]);
            let d = [b[0] - a[0], b[1] - a[1]];
            let t = ((p[0] - a[0]) * d[0] + (p[1] - a[1]) * d[1]) / (d[0] * d[0] + d[1] * d[1]);
            let foot = [a[0] + t * d[0], a[1] + t * d[1]];
            formation[7] = [2.0 * foot[0] - p[0], 2.0 * foot[1] - p[1]];
            if mirror_all {
                for q in &mut formation {
                    q[0] = -q[0];
                }
            }
            let c = compare(&formation, &target, &tris).unwrap();
            assert_eq!(c.folded, vec![5], "mirror_all {mirror_all}");
            assert_eq!(c.fit.reflected, mirror_all);
            assert!(c.fit.max_rel > 0.1, "{:?}", c.fit);
        }
    }

    #[test]
    fn refusals() {
        let p = [[0.0, 0.0], [1.0, 0.0]];
        assert_eq!(
            fit_similarity(&p, &p[..1]),
            Err(ShapeError::LengthMismatch {
                formation: 2,
                target: 1
            })
        );
        assert_eq!(
            fit_similarity(&p, &[[1.0, 1.0]; 2]),
            Err(ShapeError::DegenerateTarget)
        );
        let e = compare(&p, &p, &[[0, 1, 2]]).unwrap_err();
        assert_eq!(e, ShapeError::BadTriangle { index: 0, n: 2 });
        // A formation collapsed to one point: scale 0, residual = the target's size.
        let f = fit_similarity(&[[3.0, 3.0]; 2], &p).unwrap();
        assert_eq!(f.scale, 0.0);
        assert!((f.rms_rel - 1.0).abs() < 1e-12);
    }
}
