//! The configuration blob: one agent's [`FfiConfig`] as checked bytes, for firmware that
//! receives its configuration from a host tool (e.g. `host-sim export`) instead of
//! compiling it in.
//!
//! Layout (little-endian):
//!
//! | offset | size | field |
//! |---|---|---|
//! | 0 | 4 | magic `"PHCF"` ([`BLOB_MAGIC`]) |
//! | 4 | 1 | format version ([`BLOB_VERSION`]) |
//! | 5 | 1 | reserved, 0 |
//! | 6 | 2 | payload length `n` |
//! | 8 | `n` | payload: postcard of `AgentConfig<f32, 8>`, then of `Option<`[`BlobPolicy`]`>` |
//! | 8 + `n` | 4 | CRC-32/ISO-HDLC (zlib's `crc32`) of bytes `0 .. 8 + n` |
//!
//! The CRC-32 (rather than the frames' CRC-16) because a blob is up to ~0.6 KiB, past
//! the lengths where a 16-bit check keeps its burst-error guarantees, it is checked once
//! (speed does not matter), and every host language has zlib's `crc32` to produce one.
//!
//! The payload is the core's serde layout: a change of `AgentConfig`'s fields changes it,
//! and [`BLOB_VERSION`] must change with it (`tests/blob.rs` pins the bytes of one blob).
//! Version 3: the integrity may be `auth`, with its 128-bit key (a secret: a blob of an
//! `auth` configuration must be stored and transported like the key itself). Version 4:
//! the bearing filter (SPEC §11) after the limits. Version 5: the limits end with the
//! bearing hold (SPEC §12). Version 6: the payload ends with the vehicle's safety policies
//! and its pre-flight reference ([`BlobPolicy`], `None` when the scenario has none).

use crc::{Crc, NoTable, CRC_32_ISO_HDLC};
use serde::{Deserialize, Serialize};

use ph_formation_core::ConfigError;

use crate::{FfiAgent, FfiConfig};

/// The first four bytes of a blob.
pub const BLOB_MAGIC: [u8; 4] = *b"PHCF";
/// The blob format version this library writes and reads.
pub const BLOB_VERSION: u8 = 6;
/// Bytes before the payload.
pub const BLOB_HEADER_LEN: usize = 8;
/// Bytes of the trailing checksum.
pub const BLOB_CHECKSUM_LEN: usize = 4;
/// An upper bound of a blob's length: a configuration with every capacity used
/// (8 triangles, 8-step schedules, a leader) encodes to less (`tests/blob.rs`).
pub const PH_MAX_BLOB_LEN: usize = 1024;

const CRC32: Crc<u32, NoTable> = Crc::<u32, NoTable>::new(&CRC_32_ISO_HDLC);

/// The safety policies (the core's `policy`, C `ph_policy_config`) and the pre-flight
/// reference a blob carries: what `host-sim export` writes from the scenario's
/// `[policy]` and the agent's initial position, and `ph_blob_policy` reads.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct BlobPolicy {
    /// Lost neighbours or radio for this long (ms): land.
    pub hold_timeout_ms: u32,
    /// The flight volume's lower and upper corners (m), if there is one.
    pub fence: Option<([f32; 2], [f32; 2])>,
    /// Battery voltage to land below (V; 0: off).
    pub battery_land: f32,
    /// For this long (ms).
    pub battery_ms: u32,
    /// Minimum separation of the setpoint guard (m; 0: off).
    pub min_separation: f32,
    /// The agent's initial position in the scenario (m): the pre-flight check's
    /// reference.
    pub start: [f32; 2],
    /// How far from `start` the pre-flight check accepts the drone (m).
    pub start_tolerance: f32,
}

/// Why a blob could not be written or read.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum BlobError {
    /// The output buffer is too small (encode).
    BufferTooSmall,
    /// Not a blob: wrong magic.
    Magic,
    /// A format version (or reserved byte) this library does not read.
    Version,
    /// The length is not header + payload length + checksum.
    Length,
    /// CRC-32 mismatch.
    Checksum,
    /// The payload does not decode as a configuration, or has trailing bytes.
    Decode,
    /// The core refuses the configuration (encode checks it with `Agent::new`).
    Config(ConfigError),
}

impl core::fmt::Display for BlobError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        match self {
            Self::BufferTooSmall => write!(f, "output buffer too small for the blob"),
            Self::Magic => write!(f, "not a configuration blob (magic is not \"PHCF\")"),
            Self::Version => write!(
                f,
                "unsupported blob version (this library reads {BLOB_VERSION})"
            ),
            Self::Length => write!(f, "blob length does not match its header"),
            Self::Checksum => write!(f, "blob CRC-32 mismatch"),
            Self::Decode => write!(f, "blob payload is not an agent configuration"),
            Self::Config(e) => write!(f, "configuration refused: {e}"),
        }
    }
}

/// Writes the blob of `config` into `out`; returns its length. Refuses a configuration
/// the core would refuse (it builds the agent once to check), and an `out` too small
/// ([`PH_MAX_BLOB_LEN`] bytes are always enough).
pub fn encode_blob(config: &FfiConfig, out: &mut [u8]) -> Result<usize, BlobError> {
    encode_blob_with(config, None, out)
}

/// [`encode_blob`] with the vehicle's safety policies and pre-flight reference.
pub fn encode_blob_with(
    config: &FfiConfig,
    policy: Option<&BlobPolicy>,
    out: &mut [u8],
) -> Result<usize, BlobError> {
    FfiAgent::new(config.clone()).map_err(BlobError::Config)?;
    let (header, rest) = out
        .split_at_mut_checked(BLOB_HEADER_LEN)
        .ok_or(BlobError::BufferTooSmall)?;
    let n = postcard::to_slice(&(config, policy), rest)
        .map_err(|_| BlobError::BufferTooSmall)?
        .len();
    let len16 = u16::try_from(n).map_err(|_| BlobError::BufferTooSmall)?;
    let [l0, l1] = len16.to_le_bytes();
    let [m0, m1, m2, m3] = BLOB_MAGIC;
    header.copy_from_slice(&[m0, m1, m2, m3, BLOB_VERSION, 0, l0, l1]);
    let body = BLOB_HEADER_LEN
        .checked_add(n)
        .ok_or(BlobError::BufferTooSmall)?;
    let total = body
        .checked_add(BLOB_CHECKSUM_LEN)
        .ok_or(BlobError::BufferTooSmall)?;
    let crc = CRC32.checksum(out.get(..body).ok_or(BlobError::BufferTooSmall)?);
    out.get_mut(body..total)
        .ok_or(BlobError::BufferTooSmall)?
        .copy_from_slice(&crc.to_le_bytes());
    Ok(total)
}

/// Reads a blob: checks magic, version, length and CRC-32, then decodes the
/// configuration. (Whether the core accepts it is `Agent::new`'s call.)
pub fn decode_blob(blob: &[u8]) -> Result<FfiConfig, BlobError> {
    decode_blob_with(blob).map(|(config, _)| config)
}

/// The safety policies and pre-flight reference of a blob (`None`: it carries none),
/// after the same checks as [`decode_blob`].
pub fn decode_blob_policy(blob: &[u8]) -> Result<Option<BlobPolicy>, BlobError> {
    decode_blob_with(blob).map(|(_, policy)| policy)
}

/// The configuration and the policies of a checked blob.
fn decode_blob_with(blob: &[u8]) -> Result<(FfiConfig, Option<BlobPolicy>), BlobError> {
    let (header, rest) = blob
        .split_first_chunk::<BLOB_HEADER_LEN>()
        .ok_or(BlobError::Length)?;
    let [m0, m1, m2, m3, version, reserved, l0, l1] = *header;
    if [m0, m1, m2, m3] != BLOB_MAGIC {
        return Err(BlobError::Magic);
    }
    if version != BLOB_VERSION || reserved != 0 {
        return Err(BlobError::Version);
    }
    let n = usize::from(u16::from_le_bytes([l0, l1]));
    let (payload, check) = rest
        .split_last_chunk::<BLOB_CHECKSUM_LEN>()
        .ok_or(BlobError::Length)?;
    if payload.len() != n {
        return Err(BlobError::Length);
    }
    let body = blob
        .get(..BLOB_HEADER_LEN.saturating_add(n))
        .ok_or(BlobError::Length)?;
    if CRC32.checksum(body) != u32::from_le_bytes(*check) {
        return Err(BlobError::Checksum);
    }
    let (config, rest) =
        postcard::take_from_bytes::<FfiConfig>(payload).map_err(|_| BlobError::Decode)?;
    match postcard::take_from_bytes::<Option<BlobPolicy>>(rest) {
        Ok((policy, [])) => Ok((config, policy)),
        _ => Err(BlobError::Decode),
    }
}
