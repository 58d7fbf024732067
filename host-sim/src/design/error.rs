//! Why a design request is refused: each message says which input, which points (by
//! zero-based index and by the agent id `index + 1` they get) and why.

use super::points::Point;
use thiserror::Error;

/// A refused design request.
#[derive(Clone, Debug, PartialEq, Error)]
pub enum DesignError {
    /// A points file or list cannot be read.
    #[error("{file}: {reason}")]
    Points {
        /// The file (or `<inline>`).
        file: String,
        /// Which line or entry, and why.
        reason: String,
    },
    /// An option is out of range.
    #[error("option `{option}`: {reason}")]
    Option {
        /// The option's name.
        option: String,
        /// Why it is refused.
        reason: String,
    },
    /// Fewer than three points.
    #[error("a formation needs at least 3 points, got {0}")]
    TooFewPoints(usize),
    /// Two or more points coincide.
    #[error("{}", duplicate_message(.pairs, .at))]
    DuplicatePoints {
        /// Coinciding pairs of point indices (the first few).
        pairs: Vec<[usize; 2]>,
        /// Where each pair is.
        at: Vec<Point>,
    },
    /// Every point lies on one line.
    #[error(
        "all {n} points lie on one line: every triangle has angles of 0° and 180°, so no \
         triangulated formation has its angles away from 0 and 180°"
    )]
    Collinear {
        /// Number of points.
        n: usize,
    },
    /// The chosen leader edge cannot start a construction.
    #[error("leader edge ({}, {}) (agents {} and {}): {reason}", .pair[0], .pair[1], .pair[0] + 1, .pair[1] + 1)]
    LeaderEdge {
        /// The two point indices.
        pair: [usize; 2],
        /// Why.
        reason: String,
    },
    /// The construction could not attach every point.
    #[error("{}", stuck_message(*.placed, .stuck, *.margin_deg, *.angle_rejects, *.capacity_rejects, *.max_triangles, *.max_neighbours))]
    NoConstruction {
        /// Points attached before the construction stopped.
        placed: usize,
        /// Points that could not be attached (all of them; the message names the first few).
        stuck: Vec<usize>,
        /// The angle margin (degrees).
        margin_deg: f64,
        /// Candidate triangles refused for an angle within the margin.
        angle_rejects: usize,
        /// Candidate triangles refused for the capacity of an agent.
        capacity_rejects: usize,
        /// Triangles per agent allowed.
        max_triangles: usize,
        /// Neighbours per agent allowed.
        max_neighbours: usize,
    },
    /// The scenario template cannot be used.
    #[error("template {file}: {reason}")]
    Template {
        /// The template's label (file path or built-in name).
        file: String,
        /// Why.
        reason: String,
    },
    /// The initial positions cannot be made valid.
    #[error("initial positions: {0}")]
    Initial(String),
    /// No design keeps every neighbour in a camera's view (`--fov-deg`).
    #[error("camera (--fov-deg): {0}")]
    Camera(String),
}

/// Why [`super::verify`] finds a construction wrong: the first problem found, by triangle
/// (its index in the construction) and point (zero-based index).
#[derive(Clone, Debug, PartialEq, Error)]
pub enum VerifyError {
    /// Not `N − 2` triangles.
    #[error("{points} points need {} triangles, got {triangles}", .points.saturating_sub(2))]
    TriangleCount {
        /// Points.
        points: usize,
        /// Triangles in the construction.
        triangles: usize,
    },
    /// A triangle's vertices are out of range or repeated.
    #[error("triangle {k} {vertices:?} is not three distinct points")]
    NotDistinct {
        /// The triangle.
        k: usize,
        /// Its vertices.
        vertices: [usize; 3],
    },
    /// A later triangle is not glued to an existing edge.
    #[error("triangle {k} {vertices:?}: ({}, {}) is not an edge yet", .vertices[0], .vertices[1])]
    NotOnAnEdge {
        /// The triangle.
        k: usize,
        /// Its vertices (base edge first).
        vertices: [usize; 3],
    },
    /// A triangle's new point was placed before.
    #[error("triangle {k} {vertices:?}: point {} is already placed", .vertices[2])]
    AlreadyPlaced {
        /// The triangle.
        k: usize,
        /// Its vertices (new point last).
        vertices: [usize; 3],
    },
    /// An interior angle within the margin.
    #[error("triangle {k} {vertices:?} has an angle of {angle_deg}° (margin {margin_deg}°)")]
    AngleWithinMargin {
        /// The triangle.
        k: usize,
        /// Its vertices.
        vertices: [usize; 3],
        /// The angle (degrees).
        angle_deg: f64,
        /// The margin (degrees).
        margin_deg: f64,
    },
    /// The controlled angles are not at two distinct vertices.
    #[error("triangle {k}: apexes {first} and {second} are not two of its vertices")]
    Apexes {
        /// The triangle.
        k: usize,
        /// The first apex.
        first: usize,
        /// The second apex.
        second: usize,
    },
    /// A desired angle the points do not realise, or within the margin.
    #[error(
        "triangle {k}: angle at {apex} is {actual_deg}° in the points, desired {desired_deg}°"
    )]
    DesiredAngle {
        /// The triangle.
        k: usize,
        /// The apex.
        apex: usize,
        /// The angle in the points (degrees).
        actual_deg: f64,
        /// The desired angle (degrees).
        desired_deg: f64,
    },
    /// The two controlled angles leave no room for the third.
    #[error("triangle {k}: controlled angles leave no third angle beyond the margin")]
    NoThirdAngle {
        /// The triangle.
        k: usize,
    },
    /// A point in no triangle.
    #[error("point {0} is in no triangle")]
    Unplaced(usize),
    /// A point over the capacity.
    #[error("point {point} has {triangles} triangles and {neighbours} neighbours (capacity {max_triangles} and {max_neighbours})")]
    Capacity {
        /// The point.
        point: usize,
        /// Its triangles.
        triangles: usize,
        /// Its neighbours.
        neighbours: usize,
        /// Triangles allowed.
        max_triangles: usize,
        /// Neighbours allowed.
        max_neighbours: usize,
    },
    /// The leader pair is not an edge.
    #[error("leader edge {0:?} is not an edge")]
    LeaderNotAnEdge([usize; 2]),
}

/// `"3 and 17 (agents 4 and 18)"`-style list of pairs.
fn duplicate_message(pairs: &[[usize; 2]], at: &[Point]) -> String {
    let shown: Vec<String> = pairs
        .iter()
        .zip(at)
        .take(10)
        .map(|([i, j], p)| {
            format!(
                "points {i} and {j} (agents {} and {}) at ({}, {})",
                i + 1,
                j + 1,
                p[0],
                p[1]
            )
        })
        .collect();
    let more = if pairs.len() > 10 {
        format!(" and {} more pairs", pairs.len() - 10)
    } else {
        String::new()
    };
    format!(
        "duplicate points: {}{more}; two agents cannot share a target position",
        shown.join("; ")
    )
}

/// Names the first stuck points and the reasons their triangles were refused.
fn stuck_message(
    placed: usize,
    stuck: &[usize],
    margin_deg: f64,
    angle_rejects: usize,
    capacity_rejects: usize,
    max_triangles: usize,
    max_neighbours: usize,
) -> String {
    let shown: Vec<String> = stuck
        .iter()
        .take(10)
        .map(|i| format!("{i} (agent {})", i + 1))
        .collect();
    let more = if stuck.len() > 10 {
        format!(" and {} more", stuck.len() - 10)
    } else {
        String::new()
    };
    format!(
        "found no triangulated Laman graph: after attaching {placed} points, {} cannot be \
         attached (points {}{more}): every triangle that joins one of them to an edge of the \
         formation built so far has an angle within {margin_deg}° of 0 or 180° ({angle_rejects} \
         candidates) or would give an agent more than {max_triangles} triangles or \
         {max_neighbours} neighbours ({capacity_rejects} candidates). Spread the points more \
         evenly, lower the angle margin or raise the capacity.",
        stuck.len(),
        shown.join(", "),
    )
}
