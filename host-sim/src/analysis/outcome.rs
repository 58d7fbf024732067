//! How a run ended, and the failures detected on the way.

use std::fmt;

/// How a run ended (`summary.json` field `outcome`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Outcome {
    /// Angles, displacement and velocity errors within tolerance at the end.
    Converged,
    /// Two agents closer than the collision distance.
    Collision,
    /// An estimate held at `r_min`.
    EstimateCollapse,
    /// Non-finite state, excessive speed, or unbounded `V`.
    Diverged,
    /// None of the above, but not within tolerance at the end.
    NotConverged,
    /// Every controlled angle, the leader edge and the velocity are within tolerance, but
    /// the formation is not the target shape (a triangle folded across an edge: the angles
    /// cannot tell a triangle from its mirror image).
    WrongShape,
}

impl Outcome {
    /// The name in `summary.json`.
    pub fn as_str(self) -> &'static str {
        match self {
            Outcome::Converged => "converged",
            Outcome::Collision => "collision",
            Outcome::EstimateCollapse => "estimate_collapse",
            Outcome::Diverged => "diverged",
            Outcome::NotConverged => "not_converged",
            Outcome::WrongShape => "wrong_shape",
        }
    }

    /// The process exit code.
    pub fn exit_code(self) -> u8 {
        use crate::exit_code as x;
        match self {
            Outcome::Converged => x::CONVERGED,
            Outcome::Collision => x::COLLISION,
            Outcome::EstimateCollapse => x::ESTIMATE_COLLAPSE,
            Outcome::Diverged => x::DIVERGED,
            Outcome::NotConverged => x::NOT_CONVERGED,
            Outcome::WrongShape => x::WRONG_SHAPE,
        }
    }
}

impl fmt::Display for Outcome {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.as_str())
    }
}

/// A detected failure.
#[derive(Clone, Debug, PartialEq)]
pub struct Event {
    /// When (s).
    pub t: f64,
    /// Which failure.
    pub kind: Outcome,
    /// A human sentence.
    pub message: String,
}
