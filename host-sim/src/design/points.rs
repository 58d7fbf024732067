//! Target point sets: read from a CSV or TOML file, or made by a built-in generator.
//!
//! Every generator takes the number of points `n` and a `spacing` (m): the side of the
//! polygon, the lattice step, the strip's edge, or the smallest distance between two random
//! points. Point `i` becomes agent `i + 1`.

use super::error::DesignError;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use std::f64::consts::PI;
use std::path::Path;

/// A position `[x, y]` (m).
pub type Point = [f64; 2];

/// Largest `n` a generator accepts (memory stays below a few hundred MB).
pub const MAX_GENERATED: usize = 2_000_000;

/// A built-in shape.
#[derive(Clone, Debug, PartialEq)]
pub enum Generator {
    /// A regular polygon with side `spacing`; with `centre`, `n − 1` corners and a point at
    /// the centre (the last point).
    Polygon {
        /// Number of points (corners, plus the centre).
        n: usize,
        /// Side length (m).
        spacing: f64,
        /// Add the centre.
        centre: bool,
    },
    /// A square lattice filled row by row, `⌈√n⌉` points wide (the last row may be short).
    RectangularLattice {
        /// Number of points.
        n: usize,
        /// Lattice step (m).
        spacing: f64,
    },
    /// A triangular lattice (rows shifted by half a step, `spacing·√3/2` apart) filled row
    /// by row, `⌈√n⌉` points wide.
    TriangularLattice {
        /// Number of points.
        n: usize,
        /// Lattice step (m).
        spacing: f64,
    },
    /// A zig-zag strip of equilateral triangles: point `i` at
    /// `(i·spacing/2, (i mod 2)·spacing·√3/2)`.
    Strip {
        /// Number of points.
        n: usize,
        /// Edge length (m).
        spacing: f64,
    },
    /// Random points in a disc of area `2.5·n·spacing²`, no two closer than `spacing`
    /// (dart throwing, seeded: the same seed gives the same points on every machine).
    RandomDisc {
        /// Number of points.
        n: usize,
        /// Smallest distance between two points (m).
        spacing: f64,
        /// Seed.
        seed: u64,
    },
}

impl Generator {
    /// One generator of each shape, with `n` points and the given spacing (and seed for the
    /// random disc): every shape at once, for surveys, examples and tests.
    pub fn every_shape(n: usize, spacing: f64, seed: u64) -> [Self; 6] {
        [
            Self::Polygon {
                n,
                spacing,
                centre: false,
            },
            Self::Polygon {
                n,
                spacing,
                centre: true,
            },
            Self::RectangularLattice { n, spacing },
            Self::TriangularLattice { n, spacing },
            Self::Strip { n, spacing },
            Self::RandomDisc { n, spacing, seed },
        ]
    }

    /// One line for the scenario header, e.g. `triangular lattice, n = 50, spacing 1 m`.
    pub fn describe(&self) -> String {
        match *self {
            Self::Polygon { n, spacing, centre } => format!(
                "regular polygon {} centre, n = {n}, side {spacing} m",
                if centre { "with" } else { "without" }
            ),
            Self::RectangularLattice { n, spacing } => {
                format!("rectangular lattice, n = {n}, spacing {spacing} m")
            }
            Self::TriangularLattice { n, spacing } => {
                format!("triangular lattice, n = {n}, spacing {spacing} m")
            }
            Self::Strip { n, spacing } => format!("zig-zag strip, n = {n}, edge {spacing} m"),
            Self::RandomDisc { n, spacing, seed } => format!(
                "random points in a disc, n = {n}, minimum separation {spacing} m, seed {seed}"
            ),
        }
    }

    /// The points.
    pub fn points(&self) -> Result<Vec<Point>, DesignError> {
        let (n, spacing) = match *self {
            Self::Polygon { n, spacing, .. }
            | Self::RectangularLattice { n, spacing }
            | Self::TriangularLattice { n, spacing }
            | Self::Strip { n, spacing }
            | Self::RandomDisc { n, spacing, .. } => (n, spacing),
        };
        let min_n = if matches!(self, Self::Polygon { centre: true, .. }) {
            4
        } else {
            3
        };
        if !(min_n..=MAX_GENERATED).contains(&n) {
            return Err(option(
                "n",
                format!("must be in {min_n}..={MAX_GENERATED}, got {n}"),
            ));
        }
        if !(spacing.is_finite() && spacing > 0.0) {
            return Err(option(
                "spacing",
                format!("must be a finite length > 0, got {spacing}"),
            ));
        }
        let h = 3f64.sqrt() / 2.0;
        let width = (n as f64).sqrt().ceil() as usize;
        Ok(match *self {
            Self::Polygon { centre, .. } => {
                let m = n - usize::from(centre);
                let radius = spacing / (2.0 * (PI / m as f64).sin());
                let mut p: Vec<Point> = (0..m)
                    .map(|k| {
                        let a = 2.0 * PI * k as f64 / m as f64;
                        [radius * a.cos(), radius * a.sin()]
                    })
                    .collect();
                if centre {
                    p.push([0.0, 0.0]);
                }
                p
            }
            Self::RectangularLattice { .. } => (0..n)
                .map(|k| [(k % width) as f64 * spacing, (k / width) as f64 * spacing])
                .collect(),
            Self::TriangularLattice { .. } => (0..n)
                .map(|k| {
                    let row = k / width;
                    let shift = 0.5 * (row % 2) as f64;
                    [
                        ((k % width) as f64 + shift) * spacing,
                        row as f64 * h * spacing,
                    ]
                })
                .collect(),
            Self::Strip { .. } => (0..n)
                .map(|k| [0.5 * k as f64 * spacing, (k % 2) as f64 * h * spacing])
                .collect(),
            Self::RandomDisc { seed, .. } => random_disc(n, spacing, seed)?,
        })
    }
}

fn option(name: &str, reason: String) -> DesignError {
    DesignError::Option {
        option: name.to_owned(),
        reason,
    }
}

/// Dart throwing in a disc of area `2.5·n·d²` with a background grid of cell `d/√2` (at
/// most one point per cell). The area is about 1.7 times the random-packing limit, so
/// darts keep landing; the attempt budget only guards against a bug.
fn random_disc(n: usize, d: f64, seed: u64) -> Result<Vec<Point>, DesignError> {
    let radius = d * (2.5 * n as f64 / PI).sqrt();
    let cell = d / 2f64.sqrt();
    let cells = (2.0 * radius / cell).ceil() as usize + 1;
    let mut grid: Vec<u32> = vec![u32::MAX; cells * cells];
    let index = |p: Point| {
        let cx = ((p[0] + radius) / cell) as usize;
        let cy = ((p[1] + radius) / cell) as usize;
        (cx.min(cells - 1), cy.min(cells - 1))
    };
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let mut out: Vec<Point> = Vec::with_capacity(n);
    let budget = 1000 * n as u64 + 10_000;
    let mut tries = 0u64;
    while out.len() < n {
        tries += 1;
        if tries > budget {
            return Err(option(
                "n",
                format!(
                    "placed only {} of {n} random points {d} m apart after {budget} tries",
                    out.len()
                ),
            ));
        }
        let r = radius * rng.random::<f64>().sqrt();
        let a = 2.0 * PI * rng.random::<f64>();
        let p = [r * a.cos(), r * a.sin()];
        let (cx, cy) = index(p);
        let mut free = true;
        'scan: for gx in cx.saturating_sub(2)..=(cx + 2).min(cells - 1) {
            for gy in cy.saturating_sub(2)..=(cy + 2).min(cells - 1) {
                let k = grid[gy * cells + gx];
                if k != u32::MAX {
                    let q = out[k as usize];
                    if (p[0] - q[0]).hypot(p[1] - q[1]) < d {
                        free = false;
                        break 'scan;
                    }
                }
            }
        }
        if free {
            grid[cy * cells + cx] = out.len() as u32;
            out.push(p);
        }
    }
    Ok(out)
}

/// Reads points from a `.csv` file ([`parse_csv`]) or a `.toml` file ([`parse_toml`]).
pub fn read_points(path: &Path) -> Result<Vec<Point>, DesignError> {
    let label = path.display().to_string();
    let text = std::fs::read_to_string(path).map_err(|e| DesignError::Points {
        file: label.clone(),
        reason: format!("cannot read: {e}"),
    })?;
    match path.extension().and_then(|e| e.to_str()) {
        Some(e) if e.eq_ignore_ascii_case("csv") => parse_csv(&text, &label),
        Some(e) if e.eq_ignore_ascii_case("toml") => parse_toml(&text, &label),
        _ => Err(DesignError::Points {
            file: label,
            reason:
                "unknown kind of file: give a .csv (columns x, y) or a .toml (points = [[x, y], …])"
                    .to_owned(),
        }),
    }
}

/// Parses CSV points: one point per row, `x,y`. A first row that is not two numbers is a
/// header naming the columns; columns named `x` and `y` are used (others are ignored),
/// without a header the first two columns. `#` starts a comment line.
pub fn parse_csv(text: &str, file: &str) -> Result<Vec<Point>, DesignError> {
    let err = |reason: String| DesignError::Points {
        file: file.to_owned(),
        reason,
    };
    let mut reader = csv::ReaderBuilder::new()
        .has_headers(false)
        .flexible(true)
        .trim(csv::Trim::All)
        .comment(Some(b'#'))
        .from_reader(text.as_bytes());
    let mut columns: Option<[usize; 2]> = None;
    let mut out = Vec::new();
    for (k, record) in reader.records().enumerate() {
        let record = record.map_err(|e| err(format!("not CSV: {e}")))?;
        let line = record.position().map_or(k as u64 + 1, |p| p.line());
        if columns.is_none() {
            let numbers = record.len() >= 2
                && record.get(0).is_some_and(|s| s.parse::<f64>().is_ok())
                && record.get(1).is_some_and(|s| s.parse::<f64>().is_ok());
            if numbers {
                columns = Some([0, 1]);
            } else {
                let find = |name: &str| {
                    record
                        .iter()
                        .position(|h| h.eq_ignore_ascii_case(name))
                        .ok_or_else(|| {
                            err(format!(
                                "line {line}: the header has no column `{name}` (columns: {})",
                                record.iter().collect::<Vec<_>>().join(", ")
                            ))
                        })
                };
                columns = Some([find("x")?, find("y")?]);
                continue;
            }
        }
        let [cx, cy] = columns.unwrap_or([0, 1]);
        let mut p = [0.0; 2];
        for (slot, (c, name)) in p.iter_mut().zip([(cx, "x"), (cy, "y")]) {
            let raw = record
                .get(c)
                .ok_or_else(|| err(format!("line {line}: no column `{name}`")))?;
            *slot = raw
                .parse::<f64>()
                .ok()
                .filter(|v| v.is_finite())
                .ok_or_else(|| {
                    err(format!(
                        "line {line}: `{name}` = `{raw}` is not a finite number"
                    ))
                })?;
        }
        out.push(p);
    }
    if out.is_empty() {
        return Err(err("no points".to_owned()));
    }
    Ok(out)
}

/// Parses TOML points: `points = [[x, y], …]`, or a `[target]` table with
/// `positions = [[x, y], …]` (so a generated scenario can be read back as a shape).
pub fn parse_toml(text: &str, file: &str) -> Result<Vec<Point>, DesignError> {
    let err = |reason: String| DesignError::Points {
        file: file.to_owned(),
        reason,
    };
    let table: toml::Table =
        toml::from_str(text).map_err(|e| err(format!("not TOML: {}", e.message())))?;
    let (field, list) = if let Some(v) = table.get("points") {
        ("points", v)
    } else if let Some(v) = table
        .get("target")
        .and_then(|t| t.as_table())
        .and_then(|t| t.get("positions"))
    {
        ("target.positions", v)
    } else {
        return Err(err(
            "no `points = [[x, y], …]` and no `[target]` with `positions`".to_owned(),
        ));
    };
    let list = list
        .as_array()
        .ok_or_else(|| err(format!("`{field}` must be an array of [x, y] pairs")))?;
    let mut out = Vec::with_capacity(list.len());
    for (i, entry) in list.iter().enumerate() {
        let pair = entry.as_array().filter(|a| a.len() == 2);
        let num = |v: &toml::Value| {
            v.as_float()
                .or_else(|| v.as_integer().map(|i| i as f64))
                .filter(|x| x.is_finite())
        };
        match pair.and_then(|a| Some([num(&a[0])?, num(&a[1])?])) {
            Some(p) => out.push(p),
            None => {
                return Err(err(format!(
                    "`{field}[{i}]` must be [x, y] with two finite numbers, got {entry}"
                )))
            }
        }
    }
    if out.is_empty() {
        return Err(err(format!("`{field}` is empty")));
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn generators_give_n_points_with_the_spacing() {
        for n in [10, 50, 200] {
            let gens = Generator::every_shape(n, 1.0, 3);
            for g in gens {
                let p = g.points().unwrap();
                assert_eq!(p.len(), n, "{}", g.describe());
                let mut nearest = f64::INFINITY;
                for i in 0..n {
                    for j in 0..i {
                        nearest = nearest.min((p[i][0] - p[j][0]).hypot(p[i][1] - p[j][1]));
                    }
                }
                assert!(nearest >= 1.0 - 1e-9, "{}: {nearest}", g.describe());
                if !matches!(
                    g,
                    Generator::RandomDisc { .. } | Generator::Polygon { centre: true, .. }
                ) {
                    assert!((nearest - 1.0).abs() < 1e-9, "{}: {nearest}", g.describe());
                }
            }
        }
    }

    #[test]
    fn random_disc_is_reproducible() {
        let g = |seed| {
            Generator::RandomDisc {
                n: 100,
                spacing: 0.5,
                seed,
            }
            .points()
            .unwrap()
        };
        assert_eq!(g(7), g(7));
        assert_ne!(g(7), g(8));
    }

    #[test]
    fn bad_generator_options() {
        let e = Generator::Strip { n: 2, spacing: 1.0 }
            .points()
            .unwrap_err();
        assert!(e.to_string().contains("option `n`"), "{e}");
        let e = Generator::Strip {
            n: 5,
            spacing: -1.0,
        }
        .points()
        .unwrap_err();
        assert!(e.to_string().contains("option `spacing`"), "{e}");
    }

    #[test]
    fn csv_with_and_without_header() {
        let p = parse_csv("# shape\nid,x,y\n1, 0.5, 1\n2,2,3\n", "a.csv").unwrap();
        assert_eq!(p, vec![[0.5, 1.0], [2.0, 3.0]]);
        let p = parse_csv("0,0\n1,0\n0,1\n", "b.csv").unwrap();
        assert_eq!(p.len(), 3);
        let e = parse_csv("x,y\n1,2\n3,abc\n", "c.csv")
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("c.csv") && e.contains("line 3") && e.contains("`y` = `abc`"),
            "{e}"
        );
        let e = parse_csv("a,b\n1,2\n", "d.csv").unwrap_err().to_string();
        assert!(e.contains("no column `x`"), "{e}");
    }

    #[test]
    fn toml_points_and_target() {
        let p = parse_toml("points = [[0, 0], [1.5, 0], [0, 2]]", "a.toml").unwrap();
        assert_eq!(p[1], [1.5, 0.0]);
        let p = parse_toml(
            "name = \"x\"\n[target]\npositions = [[1, 2], [3, 4]]\n",
            "b.toml",
        )
        .unwrap();
        assert_eq!(p, vec![[1.0, 2.0], [3.0, 4.0]]);
        let e = parse_toml("points = [[0, 0], [1]]", "c.toml")
            .unwrap_err()
            .to_string();
        assert!(e.contains("c.toml") && e.contains("`points[1]`"), "{e}");
    }
}
