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
