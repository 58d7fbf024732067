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
    /// More than `criteria.safe_share` of the controllers' outputs in the steady window
    /// were the safe output: the agents were not in control (neighbours never seen,
    /// bearings missing, positions stale, a neighbour silent), whatever the errors.
    NotInControl,
}

impl Outcome {
    /// Every outcome, in the order of the sweep tables' columns (`docs/sweeps.md`). A new
    /// variant goes here too: sweeps count and report whatever this lists.
    pub const ALL: &'static [Outcome] = &[
        Outcome::Converged,
        Outcome::Collision,
        Outcome::EstimateCollapse,
        Outcome::Diverged,
        Outcome::NotConverged,
        Outcome::WrongShape,
        Outcome::NotInControl,
    ];

    /// The name in `summary.json`.
    pub fn as_str(self) -> &'static str {
        match self {
            Outcome::Converged => "converged",
            Outcome::Collision => "collision",
            Outcome::EstimateCollapse => "estimate_collapse",
            Outcome::Diverged => "diverged",
            Outcome::NotConverged => "not_converged",
            Outcome::WrongShape => "wrong_shape",
            Outcome::NotInControl => "not_in_control",
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
            Outcome::NotInControl => x::NOT_IN_CONTROL,
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

#[cfg(test)]
mod tests {
    use super::Outcome;

    /// `ALL` lists each outcome once; the exhaustive match fails to compile when a variant
    /// is added, pointing here, and the count below then fails until `ALL` has it.
    #[test]
    fn all_lists_every_outcome_once() {
        fn ordinal(o: Outcome) -> usize {
            match o {
                Outcome::Converged => 0,
                Outcome::Collision => 1,
                Outcome::EstimateCollapse => 2,
                Outcome::Diverged => 3,
                Outcome::NotConverged => 4,
                Outcome::WrongShape => 5,
                Outcome::NotInControl => 6,
            }
        }
        const VARIANTS: usize = 7;
        assert_eq!(Outcome::ALL.len(), VARIANTS);
        let mut seen = [false; VARIANTS];
        for &o in Outcome::ALL {
            assert!(!seen[ordinal(o)], "{o} listed twice");
            seen[ordinal(o)] = true;
        }
    }
}
