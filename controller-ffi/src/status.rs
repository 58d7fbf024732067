//! The status codes of the C API, and the ONE place where every error of the core
//! ([`ConfigError`], [`FrameError`]) and of the blob ([`BlobError`]) becomes one.
//!
//! The matches are exhaustive: a variant added to a core error type is a compile error
//! here until it has its code.

use ph_formation_core::{ConfigError, FrameError};

use crate::blob::BlobError;

/// What an entry point did: `PH_OK` (0) or why it refused. Returned as an `int32_t`.
///
/// Codes are grouped: 1–19 arguments and storage, 20–39 configuration, 40–59 blob,
/// 60–79 received frames. A refused call changes nothing (except where its function
/// says otherwise).
#[repr(i32)]
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ph_status {
    /// Success.
    PH_OK = 0,
    /// A required pointer is NULL.
    PH_ERR_NULL = 1,
    /// The agent memory is smaller than `PH_AGENT_SIZE`.
    PH_ERR_STORAGE_SIZE = 2,
    /// The agent memory is not aligned to `PH_AGENT_ALIGN`.
    PH_ERR_STORAGE_ALIGN = 3,
    /// The agent memory does not hold an agent (`ph_agent_init*` not called, or failed).
    PH_ERR_NOT_INITIALIZED = 4,
    /// An argument is out of range: more than `PH_MAX_NEIGHBOURS` bearings, unknown
    /// bits in `ph_bearing.flags`.
    PH_ERR_ARGUMENT = 5,
    /// The output buffer is too small; what fits was written (see the function).
    PH_ERR_BUFFER_FULL = 6,
    /// Configuration: a triangle does not contain this agent.
    PH_ERR_CONFIG_NOT_IN_TRIANGLE = 20,
    /// Configuration: a triangle repeats a vertex.
    PH_ERR_CONFIG_REPEATED_VERTEX = 21,
    /// Configuration: an angle's apex is not a vertex of its triangle, or both angles
    /// share it.
    PH_ERR_CONFIG_BAD_APEX = 22,
    /// Configuration: a desired angle outside (margin, 180° − margin), or the two sum to
    /// 180° or more.
    PH_ERR_CONFIG_INFEASIBLE_ANGLES = 23,
    /// Configuration: a gain is not finite, or `c ≤ 0`, `d < 0`, `c_e ≤ 0`.
    PH_ERR_CONFIG_BAD_GAIN = 24,
    /// Configuration: more than `PH_MAX_NEIGHBOURS` distinct neighbours.
    PH_ERR_CONFIG_TOO_MANY_NEIGHBOURS = 25,
    /// Configuration: a scalar parameter (estimate, limit, friction, damping, schedule,
    /// leader gain) is not finite or out of range.
    PH_ERR_CONFIG_BAD_PARAMETER = 26,
    /// Configuration: the leader partner is the agent itself.
    PH_ERR_CONFIG_BAD_LEADER = 27,
    /// Configuration: `triangle_count > PH_MAX_TRIANGLES`.
    PH_ERR_CONFIG_TOO_MANY_TRIANGLES = 28,
    /// Configuration: a schedule's `count > PH_MAX_SCHEDULE_STEPS`.
    PH_ERR_CONFIG_SCHEDULE_TOO_LONG = 29,
    /// Configuration: `estimator` is not a `ph_estimator`, or `leader.role` not a
    /// `ph_leader_role`.
    PH_ERR_CONFIG_BAD_ENUM = 30,
    /// Configuration: a `v*` or `z*` schedule with a non-finite entry or times that do
    /// not strictly increase.
    PH_ERR_CONFIG_BAD_SCHEDULE = 31,
    /// Configuration: `comm_every` is 0 or `comm_phase ≥ comm_every`.
    PH_ERR_CONFIG_BAD_COMM_RATE = 32,
    /// Configuration: a bearing tracker setting is not finite or out of range (SPEC §11).
    PH_ERR_CONFIG_BAD_BEARING_FILTER = 33,
    /// Blob: does not start with the magic `"PHCF"`.
    PH_ERR_BLOB_MAGIC = 40,
    /// Blob: a format version (or reserved header byte) this library does not read.
    PH_ERR_BLOB_VERSION = 41,
    /// Blob: its length is not header + payload length + checksum.
    PH_ERR_BLOB_LENGTH = 42,
    /// Blob: CRC-32 mismatch.
    PH_ERR_BLOB_CHECKSUM = 43,
    /// Blob: the payload does not decode as a configuration (or has trailing bytes).
    PH_ERR_BLOB_DECODE = 44,
    /// Blob: it carries no safety policies (`ph_blob_policy`; the scenario had no
    /// `[policy]`).
    PH_ERR_BLOB_NO_POLICY = 45,
    /// Frame: shorter than a header and its check.
    PH_ERR_FRAME_TOO_SHORT = 60,
    /// Frame: longer than `PH_MAX_FRAME_LEN`.
    PH_ERR_FRAME_TOO_LONG = 61,
    /// Frame: CRC mismatch.
    PH_ERR_FRAME_BAD_CRC = 62,
    /// Frame: unknown wire version.
    PH_ERR_FRAME_UNKNOWN_VERSION = 63,
    /// Frame: the body does not decode.
    PH_ERR_FRAME_MALFORMED = 64,
    /// Frame: the sender is not a neighbour of this agent (normal on a broadcast radio).
    PH_ERR_FRAME_UNKNOWN_SENDER = 65,
    /// Frame: sent by this agent itself.
    PH_ERR_FRAME_OWN = 66,
    /// Frame: sequence number not newer than the last accepted one from this sender.
    PH_ERR_FRAME_STALE_SEQUENCE = 67,
    /// Frame: a value is NaN or infinite, `|σ| > 1`, a distance is not positive, or an
    /// estimate is below `r_min`.
    PH_ERR_FRAME_INVALID_VALUE = 68,
    /// Frame: a COBS chunk that does not decode.
    PH_ERR_FRAME_COBS = 69,
    /// Frame: its integrity or estimator mode differs from this agent's (misconfigured
    /// swarm).
    PH_ERR_FRAME_MODE_MISMATCH = 70,
    /// Frame (`auth`): the tag does not verify (forged, corrupted or another key).
    PH_ERR_FRAME_BAD_TAG = 71,
    /// Frame (`auth`): its counter is not newer than the sender's last accepted one
    /// (replayed or late).
    PH_ERR_FRAME_REPLAYED = 72,
    /// Frame (`auth`): no counter known for the sender yet and none in the frame.
    PH_ERR_FRAME_UNSYNCED = 73,
}

impl From<ConfigError> for ph_status {
    fn from(e: ConfigError) -> Self {
        match e {
            ConfigError::NotInTriangle { .. } => Self::PH_ERR_CONFIG_NOT_IN_TRIANGLE,
            ConfigError::RepeatedVertex { .. } => Self::PH_ERR_CONFIG_REPEATED_VERTEX,
            ConfigError::BadApex { .. } => Self::PH_ERR_CONFIG_BAD_APEX,
            ConfigError::InfeasibleAngles { .. } => Self::PH_ERR_CONFIG_INFEASIBLE_ANGLES,
            ConfigError::BadGain { .. } => Self::PH_ERR_CONFIG_BAD_GAIN,
            ConfigError::TooManyNeighbours => Self::PH_ERR_CONFIG_TOO_MANY_NEIGHBOURS,
            ConfigError::TooManyTriangles => Self::PH_ERR_CONFIG_TOO_MANY_TRIANGLES,
            ConfigError::BadParameter => Self::PH_ERR_CONFIG_BAD_PARAMETER,
            ConfigError::BadSchedule => Self::PH_ERR_CONFIG_BAD_SCHEDULE,
            ConfigError::BadCommRate => Self::PH_ERR_CONFIG_BAD_COMM_RATE,
            ConfigError::BadLeader => Self::PH_ERR_CONFIG_BAD_LEADER,
            ConfigError::BadBearingFilter => Self::PH_ERR_CONFIG_BAD_BEARING_FILTER,
        }
    }
}

impl From<FrameError> for ph_status {
    fn from(e: FrameError) -> Self {
        match e {
            FrameError::TooShort => Self::PH_ERR_FRAME_TOO_SHORT,
            FrameError::TooLong => Self::PH_ERR_FRAME_TOO_LONG,
            FrameError::BadCrc => Self::PH_ERR_FRAME_BAD_CRC,
            FrameError::UnknownVersion(_) => Self::PH_ERR_FRAME_UNKNOWN_VERSION,
            FrameError::ModeMismatch(_) => Self::PH_ERR_FRAME_MODE_MISMATCH,
            FrameError::Malformed => Self::PH_ERR_FRAME_MALFORMED,
            FrameError::UnknownSender(_) => Self::PH_ERR_FRAME_UNKNOWN_SENDER,
            FrameError::OwnFrame => Self::PH_ERR_FRAME_OWN,
            FrameError::StaleSequence { .. } => Self::PH_ERR_FRAME_STALE_SEQUENCE,
            FrameError::InvalidValue => Self::PH_ERR_FRAME_INVALID_VALUE,
            FrameError::Cobs => Self::PH_ERR_FRAME_COBS,
            FrameError::BadTag => Self::PH_ERR_FRAME_BAD_TAG,
            FrameError::Replayed { .. } => Self::PH_ERR_FRAME_REPLAYED,
            FrameError::Unsynced(_) => Self::PH_ERR_FRAME_UNSYNCED,
        }
    }
}

impl From<BlobError> for ph_status {
    fn from(e: BlobError) -> Self {
        match e {
            BlobError::BufferTooSmall => Self::PH_ERR_BUFFER_FULL,
            BlobError::Magic => Self::PH_ERR_BLOB_MAGIC,
            BlobError::Version => Self::PH_ERR_BLOB_VERSION,
            BlobError::Length => Self::PH_ERR_BLOB_LENGTH,
            BlobError::Checksum => Self::PH_ERR_BLOB_CHECKSUM,
            BlobError::Decode => Self::PH_ERR_BLOB_DECODE,
            BlobError::Config(c) => c.into(),
        }
    }
}

/// Every status, for the code → status lookup of `ph_status_str`. `tests/header.rs`
/// checks that it lists as many codes as the header's `ph_status` has.
pub const ALL: [ph_status; 41] = {
    use ph_status::*;
    [
        PH_OK,
        PH_ERR_NULL,
        PH_ERR_STORAGE_SIZE,
        PH_ERR_STORAGE_ALIGN,
        PH_ERR_NOT_INITIALIZED,
        PH_ERR_ARGUMENT,
        PH_ERR_BUFFER_FULL,
        PH_ERR_CONFIG_NOT_IN_TRIANGLE,
        PH_ERR_CONFIG_REPEATED_VERTEX,
        PH_ERR_CONFIG_BAD_APEX,
        PH_ERR_CONFIG_INFEASIBLE_ANGLES,
        PH_ERR_CONFIG_BAD_GAIN,
        PH_ERR_CONFIG_TOO_MANY_NEIGHBOURS,
        PH_ERR_CONFIG_BAD_PARAMETER,
        PH_ERR_CONFIG_BAD_LEADER,
        PH_ERR_CONFIG_TOO_MANY_TRIANGLES,
        PH_ERR_CONFIG_SCHEDULE_TOO_LONG,
        PH_ERR_CONFIG_BAD_ENUM,
        PH_ERR_CONFIG_BAD_SCHEDULE,
        PH_ERR_CONFIG_BAD_COMM_RATE,
        PH_ERR_CONFIG_BAD_BEARING_FILTER,
        PH_ERR_BLOB_MAGIC,
        PH_ERR_BLOB_VERSION,
        PH_ERR_BLOB_LENGTH,
        PH_ERR_BLOB_CHECKSUM,
        PH_ERR_BLOB_DECODE,
        PH_ERR_BLOB_NO_POLICY,
        PH_ERR_FRAME_TOO_SHORT,
        PH_ERR_FRAME_TOO_LONG,
        PH_ERR_FRAME_BAD_CRC,
        PH_ERR_FRAME_UNKNOWN_VERSION,
        PH_ERR_FRAME_MALFORMED,
        PH_ERR_FRAME_UNKNOWN_SENDER,
        PH_ERR_FRAME_OWN,
        PH_ERR_FRAME_STALE_SEQUENCE,
        PH_ERR_FRAME_INVALID_VALUE,
        PH_ERR_FRAME_COBS,
        PH_ERR_FRAME_MODE_MISMATCH,
        PH_ERR_FRAME_BAD_TAG,
        PH_ERR_FRAME_REPLAYED,
        PH_ERR_FRAME_UNSYNCED,
    ]
};

impl ph_status {
    /// The constant's name as a NUL-terminated string (for logs). (A new variant goes
    /// here and into [`ALL`].)
    pub fn name(self) -> &'static core::ffi::CStr {
        match self {
            Self::PH_OK => c"PH_OK",
            Self::PH_ERR_NULL => c"PH_ERR_NULL",
            Self::PH_ERR_STORAGE_SIZE => c"PH_ERR_STORAGE_SIZE",
            Self::PH_ERR_STORAGE_ALIGN => c"PH_ERR_STORAGE_ALIGN",
            Self::PH_ERR_NOT_INITIALIZED => c"PH_ERR_NOT_INITIALIZED",
            Self::PH_ERR_ARGUMENT => c"PH_ERR_ARGUMENT",
            Self::PH_ERR_BUFFER_FULL => c"PH_ERR_BUFFER_FULL",
            Self::PH_ERR_CONFIG_NOT_IN_TRIANGLE => c"PH_ERR_CONFIG_NOT_IN_TRIANGLE",
            Self::PH_ERR_CONFIG_REPEATED_VERTEX => c"PH_ERR_CONFIG_REPEATED_VERTEX",
            Self::PH_ERR_CONFIG_BAD_APEX => c"PH_ERR_CONFIG_BAD_APEX",
            Self::PH_ERR_CONFIG_INFEASIBLE_ANGLES => c"PH_ERR_CONFIG_INFEASIBLE_ANGLES",
            Self::PH_ERR_CONFIG_BAD_GAIN => c"PH_ERR_CONFIG_BAD_GAIN",
            Self::PH_ERR_CONFIG_TOO_MANY_NEIGHBOURS => c"PH_ERR_CONFIG_TOO_MANY_NEIGHBOURS",
            Self::PH_ERR_CONFIG_BAD_PARAMETER => c"PH_ERR_CONFIG_BAD_PARAMETER",
            Self::PH_ERR_CONFIG_BAD_LEADER => c"PH_ERR_CONFIG_BAD_LEADER",
            Self::PH_ERR_CONFIG_BAD_BEARING_FILTER => c"PH_ERR_CONFIG_BAD_BEARING_FILTER",
            Self::PH_ERR_CONFIG_TOO_MANY_TRIANGLES => c"PH_ERR_CONFIG_TOO_MANY_TRIANGLES",
            Self::PH_ERR_CONFIG_SCHEDULE_TOO_LONG => c"PH_ERR_CONFIG_SCHEDULE_TOO_LONG",
            Self::PH_ERR_CONFIG_BAD_ENUM => c"PH_ERR_CONFIG_BAD_ENUM",
            Self::PH_ERR_CONFIG_BAD_SCHEDULE => c"PH_ERR_CONFIG_BAD_SCHEDULE",
            Self::PH_ERR_CONFIG_BAD_COMM_RATE => c"PH_ERR_CONFIG_BAD_COMM_RATE",
            Self::PH_ERR_BLOB_MAGIC => c"PH_ERR_BLOB_MAGIC",
            Self::PH_ERR_BLOB_VERSION => c"PH_ERR_BLOB_VERSION",
            Self::PH_ERR_BLOB_LENGTH => c"PH_ERR_BLOB_LENGTH",
            Self::PH_ERR_BLOB_CHECKSUM => c"PH_ERR_BLOB_CHECKSUM",
            Self::PH_ERR_BLOB_DECODE => c"PH_ERR_BLOB_DECODE",
            Self::PH_ERR_BLOB_NO_POLICY => c"PH_ERR_BLOB_NO_POLICY",
            Self::PH_ERR_FRAME_TOO_SHORT => c"PH_ERR_FRAME_TOO_SHORT",
            Self::PH_ERR_FRAME_TOO_LONG => c"PH_ERR_FRAME_TOO_LONG",
            Self::PH_ERR_FRAME_BAD_CRC => c"PH_ERR_FRAME_BAD_CRC",
            Self::PH_ERR_FRAME_UNKNOWN_VERSION => c"PH_ERR_FRAME_UNKNOWN_VERSION",
            Self::PH_ERR_FRAME_MALFORMED => c"PH_ERR_FRAME_MALFORMED",
            Self::PH_ERR_FRAME_UNKNOWN_SENDER => c"PH_ERR_FRAME_UNKNOWN_SENDER",
            Self::PH_ERR_FRAME_OWN => c"PH_ERR_FRAME_OWN",
            Self::PH_ERR_FRAME_STALE_SEQUENCE => c"PH_ERR_FRAME_STALE_SEQUENCE",
            Self::PH_ERR_FRAME_INVALID_VALUE => c"PH_ERR_FRAME_INVALID_VALUE",
            Self::PH_ERR_FRAME_COBS => c"PH_ERR_FRAME_COBS",
            Self::PH_ERR_FRAME_MODE_MISMATCH => c"PH_ERR_FRAME_MODE_MISMATCH",
            Self::PH_ERR_FRAME_BAD_TAG => c"PH_ERR_FRAME_BAD_TAG",
            Self::PH_ERR_FRAME_REPLAYED => c"PH_ERR_FRAME_REPLAYED",
            Self::PH_ERR_FRAME_UNSYNCED => c"PH_ERR_FRAME_UNSYNCED",
        }
    }

    /// The status with this code, if any.
    pub fn from_code(code: i32) -> Option<Self> {
        ALL.iter().copied().find(|s| *s as i32 == code)
    }

    /// `PH_OK` for `Ok(())`, the error's code otherwise.
    pub fn of<E: Into<ph_status>>(r: Result<(), E>) -> Self {
        match r {
            Ok(()) => Self::PH_OK,
            Err(e) => e.into(),
        }
    }
}
