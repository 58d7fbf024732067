//! Scenario errors: each names the file, the field and the reason; each kind has its
//! own exit code (20–28, `docs/scenarios.md`).

use std::fmt;

/// What is wrong with a scenario; each kind has its own exit code.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ErrorKind {
    /// The file cannot be read, or the name is neither a file nor a built-in.
    Io,
    /// TOML syntax, unknown field, wrong type, missing field, bad `--set`.
    Syntax,
    /// The triangles do not form a triangulated Laman graph.
    NotLaman,
    /// A desired angle outside `(margin, π − margin)`, or a triangle's angles infeasible.
    InfeasibleAngles,
    /// Two agents with the same id.
    DuplicateId,
    /// An id that names no agent (or an apex outside its triangle).
    UnknownId,
    /// A triangle (nearly) collinear in the initial positions.
    CollinearTriangle,
    /// A gain that must be positive (or non-negative) is not.
    NonPositiveGain,
    /// Any other out-of-range value (mass, time step, probability, capacity, …).
    InvalidValue,
}

impl ErrorKind {
    /// The process exit code of this kind.
    pub fn exit_code(self) -> u8 {
        match self {
            ErrorKind::Io => 20,
            ErrorKind::Syntax => 21,
            ErrorKind::NotLaman => 22,
            ErrorKind::InfeasibleAngles => 23,
            ErrorKind::DuplicateId => 24,
            ErrorKind::UnknownId => 25,
            ErrorKind::CollinearTriangle => 26,
            ErrorKind::NonPositiveGain => 27,
            ErrorKind::InvalidValue => 28,
        }
    }

    /// Short name, used in messages and tests.
    pub fn name(self) -> &'static str {
        match self {
            ErrorKind::Io => "unreadable scenario",
            ErrorKind::Syntax => "schema error",
            ErrorKind::NotLaman => "not a triangulated Laman graph",
            ErrorKind::InfeasibleAngles => "infeasible angles",
            ErrorKind::DuplicateId => "duplicate id",
            ErrorKind::UnknownId => "unknown id",
            ErrorKind::CollinearTriangle => "collinear initial triangle",
            ErrorKind::NonPositiveGain => "non-positive gain",
            ErrorKind::InvalidValue => "invalid value",
        }
    }
}

/// One problem in a scenario: which file, which field, and why.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct ScenarioError {
    /// What is wrong.
    pub kind: ErrorKind,
    /// The file path (or `builtin:<name>`).
    pub file: String,
    /// The dotted field (`triangles[1].angles[0].desired_deg`), or empty.
    pub field: String,
    /// A human sentence.
    pub reason: String,
}

impl ScenarioError {
    /// Builds an error.
    pub fn new(kind: ErrorKind, file: &str, field: &str, reason: impl Into<String>) -> Self {
        Self {
            kind,
            file: file.to_owned(),
            field: field.to_owned(),
            reason: reason.into(),
        }
    }
}

impl fmt::Display for ScenarioError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        if self.field.is_empty() {
            write!(f, "{}: {}: {}", self.file, self.kind.name(), self.reason)
        } else {
            write!(
                f,
                "{}: field `{}`: {}: {}",
                self.file,
                self.field,
                self.kind.name(),
                self.reason
            )
        }
    }
}

impl std::error::Error for ScenarioError {}

/// All problems found in one scenario (at least one).
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct ScenarioErrors(pub Vec<ScenarioError>);

impl ScenarioErrors {
    /// The exit code: the first error's.
    pub fn exit_code(&self) -> u8 {
        self.0
            .first()
            .map_or(ErrorKind::InvalidValue.exit_code(), |e| e.kind.exit_code())
    }

    /// Whether any error is of `kind`.
    pub fn has(&self, kind: ErrorKind) -> bool {
        self.0.iter().any(|e| e.kind == kind)
    }
}

impl From<ScenarioError> for ScenarioErrors {
    fn from(e: ScenarioError) -> Self {
        Self(vec![e])
    }
}

impl fmt::Display for ScenarioErrors {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        for (i, e) in self.0.iter().enumerate() {
            if i > 0 {
                writeln!(f)?;
            }
            write!(f, "error: {e}")?;
        }
        Ok(())
    }
}

impl std::error::Error for ScenarioErrors {}
