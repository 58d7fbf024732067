//! The position packet (`ph_formation_core::wire::position`) for C: one type for the C
//! API, the Crazyflie app (`crazyflie-app/src/formation.c`) and host-sim's model of it,
//! protected with the agent's integrity mode (`crc16`, `link` or `auth`).

use ph_formation_core::wire::position::{accept_counter, PositionError, PositionPacket};

use crate::api::{check, input, status, write};
use crate::status::ph_status;
use crate::storage::{self, ph_agent};

/// Longest position packet (with `PH_INTEGRITY_AUTH`), bytes.
pub const PH_MAX_POSITION_LEN: usize = 27;
const _: () = assert!(PH_MAX_POSITION_LEN == ph_formation_core::wire::position::MAX_POSITION_LEN);

/// What a receiver keeps of one sender's position packets: the last accepted `auth`
/// counter (replays are refused). Zero it before the first packet.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct ph_position_peer {
    /// Non-zero once a counter was accepted.
    pub has_counter: u8,
    /// The last accepted counter (`epoch · 2³² + n`).
    pub counter: u64,
}

fn refused(e: PositionError) -> ph_status {
    match e {
        PositionError::Malformed => ph_status::PH_ERR_FRAME_MALFORMED,
        PositionError::ModeMismatch => ph_status::PH_ERR_FRAME_MODE_MISMATCH,
        PositionError::BadCrc => ph_status::PH_ERR_FRAME_BAD_CRC,
        PositionError::BadTag => ph_status::PH_ERR_FRAME_BAD_TAG,
        PositionError::Replayed => ph_status::PH_ERR_FRAME_REPLAYED,
        PositionError::NonFinite => ph_status::PH_ERR_FRAME_INVALID_VALUE,
        PositionError::BufferTooSmall => ph_status::PH_ERR_BUFFER_FULL,
    }
}

/// Writes this agent's position packet (its id, `position[0..2]` in m, world frame)
/// with its integrity mode into `out[0..capacity]` and its length to `*len`. `counter`
/// is used with `PH_INTEGRITY_AUTH` only: this boot's `epoch · 2³² + n`, a new `n` for
/// every packet (the receivers refuse a counter they accepted before).
/// `PH_ERR_BUFFER_FULL` when `capacity` is below the packet's length.
///
/// # Safety
/// `agent` as for `ph_stats`; `position` NULL or 2 readable floats; `out` NULL or
/// `capacity` writable bytes; `len` NULL or writable.
#[no_mangle]
pub unsafe extern "C" fn ph_position_encode(
    agent: *const ph_agent,
    position: *const f32,
    counter: u64,
    out: *mut u8,
    capacity: usize,
    len: *mut usize,
) -> ph_status {
    let r = (|| {
        // SAFETY: per this function's contract.
        let a = unsafe { storage::agent_ref(agent) }?;
        // SAFETY: as above (2 floats).
        let p = *unsafe { input(position.cast::<[f32; 2]>()) }?;
        check(out.cast_const())?;
        check(len.cast_const())?;
        let integrity = a.config().integrity;
        let mut buf = [0u8; PH_MAX_POSITION_LEN];
        let n = PositionPacket {
            sender: a.id(),
            position: p,
        }
        .encode(&integrity, counter, &mut buf)
        .map_err(refused)?;
        if capacity < n {
            return Err(ph_status::PH_ERR_BUFFER_FULL);
        }
        // SAFETY: `out` holds `capacity ≥ n` writable bytes (per the contract).
        let dst = unsafe { core::slice::from_raw_parts_mut(out, n) };
        dst.copy_from_slice(buf.get(..n).ok_or(ph_status::PH_ERR_BUFFER_FULL)?);
        // SAFETY: as above.
        unsafe { write(len, n) }
    })();
    status(r)
}

/// Reads a neighbour's position packet `bytes[0..len]` sent with this agent's
/// integrity mode: the sender to `*sender`, the position to `position[0..2]`; with
/// `PH_INTEGRITY_AUTH` checks its counter against `*peer` (the receiver's record of
/// that sender: look it up by the sender, e.g. with `ph_position_sender` first) and
/// records it. Refusals: `PH_ERR_FRAME_MALFORMED` (not a position packet of this
/// length), `PH_ERR_FRAME_MODE_MISMATCH`, `PH_ERR_FRAME_BAD_CRC`,
/// `PH_ERR_FRAME_BAD_TAG` (spoofed or corrupted), `PH_ERR_FRAME_REPLAYED`,
/// `PH_ERR_FRAME_INVALID_VALUE` (a coordinate not finite); nothing written then.
///
/// # Safety
/// `agent` as for `ph_stats`; `bytes` NULL or `len` readable bytes; `peer` NULL or a
/// `ph_position_peer`; `sender` NULL or writable; `position` NULL or 2 writable floats.
#[no_mangle]
pub unsafe extern "C" fn ph_position_decode(
    agent: *const ph_agent,
    bytes: *const u8,
    len: usize,
    peer: *mut ph_position_peer,
    sender: *mut u8,
    position: *mut f32,
) -> ph_status {
    let r = (|| {
        // SAFETY: per this function's contract.
        let a = unsafe { storage::agent_ref(agent) }?;
        // SAFETY: as above.
        let b = unsafe { crate::api::slice(bytes, len) }?;
        check(sender.cast_const())?;
        check(position.cast_const())?;
        // SAFETY: as above.
        let rec = *unsafe { input(peer.cast_const()) }?;
        let integrity = a.config().integrity;
        let (p, counter) = PositionPacket::decode(b, &integrity).map_err(refused)?;
        let mut last = (rec.has_counter != 0).then_some(rec.counter);
        if !accept_counter(&mut last, counter) {
            return Err(refused(PositionError::Replayed));
        }
        let updated = ph_position_peer {
            has_counter: u8::from(last.is_some()),
            counter: last.unwrap_or(0),
        };
        // SAFETY: as above.
        unsafe { write(peer, updated) }?;
        // SAFETY: as above.
        unsafe { write(sender, p.sender) }?;
        // SAFETY: as above (2 floats).
        unsafe { write(position.cast::<[f32; 2]>(), p.position) }
    })();
    status(r)
}

/// The sender of a position packet `bytes[0..len]` (byte 2), unchecked: to find the
/// receiver's `ph_position_peer` before `ph_position_decode`. `PH_ERR_FRAME_MALFORMED`
/// for a packet too short.
///
/// # Safety
/// `bytes` NULL or `len` readable bytes; `sender` NULL or writable.
#[no_mangle]
pub unsafe extern "C" fn ph_position_sender(
    bytes: *const u8,
    len: usize,
    sender: *mut u8,
) -> ph_status {
    let r = (|| {
        // SAFETY: per this function's contract.
        let b = unsafe { crate::api::slice(bytes, len) }?;
        let id = *b.get(2).ok_or(ph_status::PH_ERR_FRAME_MALFORMED)?;
        // SAFETY: as above.
        unsafe { write(sender, id) }
    })();
    status(r)
}
