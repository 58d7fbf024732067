//! Scenario errors (file, field, reason) and the process exit codes.

use std::fmt;

/// Exit codes of the `host-sim` binary (documented in `docs/outputs.md`).
pub mod exit_code {
    /// The run converged (or `validate`, `list`, `plot` succeeded).
    pub const CONVERGED: u8 = 0;
    /// Output could not be written, or another runtime error.
    pub const IO: u8 = 1;
    /// Bad command line (clap's usage errors).
    pub const USAGE: u8 = 2;
    /// The run ended without converging.
    pub const NOT_CONVERGED: u8 = 10;
    /// Two agents came closer than the collision distance.
    pub const COLLISION: u8 = 11;
    /// An estimate was held at `r_min`.
    pub const ESTIMATE_COLLAPSE: u8 = 12;
    /// The state became non-finite, too fast, or `V` grew without bound.
    pub const DIVERGED: u8 = 13;
    /// Host-in-the-loop: `qemu-system-arm` not found.
    pub const HIL_NO_QEMU: u8 = 30;
    /// Host-in-the-loop: the firmware ELF not found.
    pub const HIL_NO_FIRMWARE: u8 = 31;
    /// Host-in-the-loop: QEMU did not start or connect, exited, or closed the link.
    pub const HIL_TARGET_FAILED: u8 = 32;
    /// Host-in-the-loop: the firmware did not answer within the timeout.
    pub const HIL_TIMEOUT: u8 = 33;
    /// Host-in-the-loop: a corrupt link frame or a message out of protocol.
    pub const HIL_CORRUPT: u8 = 34;
    /// Host-in-the-loop: the agent's configuration does not fit the firmware, or the
    /// firmware refused it.
    pub const HIL_REFUSED: u8 = 35;
}

/// Why a run stopped without a result.
#[derive(Clone, Debug, PartialEq)]
pub enum RunError {
    /// Setup or output failure (exit code [`exit_code::IO`]).
    Failed(String),
    /// A host-in-the-loop failure (its own exit code).
    Hil(crate::engine::hil::HilError),
}

impl RunError {
    /// The process exit code.
    pub fn exit_code(&self) -> u8 {
        match self {
            Self::Failed(_) => exit_code::IO,
            Self::Hil(e) => e.exit_code(),
        }
    }
}

impl fmt::Display for RunError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::Failed(s) => f.write_str(s),
            Self::Hil(e) => write!(f, "host-in-the-loop: {e}"),
        }
    }
}

impl std::error::Error for RunError {}

impl From<String> for RunError {
    fn from(s: String) -> Self {
        Self::Failed(s)
    }
}

impl From<crate::engine::hil::HilError> for RunError {
    fn from(e: crate::engine::hil::HilError) -> Self {
        Self::Hil(e)
    }
}

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
