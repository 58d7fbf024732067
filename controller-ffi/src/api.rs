//! The `extern "C"` entry points (`ph_*`). Each checks its pointers, converts through
//! `config`, `tick` or `blob`, calls the core, and returns a [`ph_status`].
//!
//! Per control tick: `ph_receive` every frame heard since the last tick, `ph_step` with
//! the own measurements, then `ph_frames` (into a buffer) or `ph_frames_cb` (through a
//! callback) to broadcast. None of them allocates, blocks or keeps a pointer it was
//! given; the agent is not thread-safe (call them from one task, or lock).

use core::ffi::{c_char, c_void};

use crate::blob::decode_blob;
use crate::config::{default_config, ph_config, to_core};
use crate::status::ph_status;
use crate::storage::{self, ph_agent};
use crate::tick::{
    bearing_to_core, estimate_from_core, output_from_core, ph_bearing, ph_estimate, ph_frame_stats,
    ph_measurements, ph_output, stats_from_core, NO_OUTPUT,
};
use crate::{PH_ABI_VERSION, PH_AGENT_ALIGN, PH_AGENT_SIZE, PH_MAX_FRAME_LEN, PH_MAX_NEIGHBOURS};
use ph_formation_core::{BearingMeasurement, Measurements, Vec2};

/// Called by `ph_frames_cb` with each frame: `bytes[0..len]`, `len ≤ PH_MAX_FRAME_LEN`,
/// valid only during the call.
pub type ph_send_fn = Option<unsafe extern "C" fn(ctx: *mut c_void, bytes: *const u8, len: usize)>;

/// `PH_ERR_NULL` for NULL, `PH_ERR_ARGUMENT` for a misaligned pointer.
pub(crate) fn check<T>(ptr: *const T) -> Result<(), ph_status> {
    if ptr.is_null() {
        Err(ph_status::PH_ERR_NULL)
    } else if !ptr.is_aligned() {
        Err(ph_status::PH_ERR_ARGUMENT)
    } else {
        Ok(())
    }
}

/// `&*ptr` if `ptr` is non-null and aligned.
///
/// # Safety
/// A non-null `ptr` points to a valid `T` for `'a`.
pub(crate) unsafe fn input<'a, T>(ptr: *const T) -> Result<&'a T, ph_status> {
    check(ptr)?;
    // SAFETY: non-null and aligned; valid per the caller.
    Ok(unsafe { &*ptr })
}

/// Writes `value` to `*ptr` if `ptr` is non-null and aligned (a raw write: the memory
/// may hold anything before).
///
/// # Safety
/// A non-null `ptr` is valid for writes of a `T`.
pub(crate) unsafe fn write<T>(ptr: *mut T, value: T) -> Result<(), ph_status> {
    check(ptr)?;
    // SAFETY: non-null and aligned; valid for writes per the caller.
    unsafe { ptr.write(value) };
    Ok(())
}

/// `ptr[0..len]` (empty for `len == 0`, whatever `ptr`).
///
/// # Safety
/// For `len > 0`, a non-null `ptr` points to `len` valid `T`s for `'a`.
pub(crate) unsafe fn slice<'a, T>(ptr: *const T, len: usize) -> Result<&'a [T], ph_status> {
    if len == 0 {
        return Ok(&[]);
    }
    check(ptr)?;
    // SAFETY: non-null and aligned (checked); `len` elements per the caller.
    Ok(unsafe { core::slice::from_raw_parts(ptr, len) })
}

/// `ptr[0..len]` for writing. Only for element types without invalid bit patterns
/// (integers, floats and structs of them): the memory may hold anything before.
///
/// # Safety
/// For `len > 0`, a non-null `ptr` is valid for reads and writes of `len` `T`s for
/// `'a`.
unsafe fn slice_mut<'a, T: Plain>(ptr: *mut T, len: usize) -> Result<&'a mut [T], ph_status> {
    if len == 0 {
        return Ok(&mut []);
    }
    check(ptr)?;
    // SAFETY: non-null and aligned (checked); `len` elements per the caller;
    // any bit pattern is a valid `T` (`Plain`).
    Ok(unsafe { core::slice::from_raw_parts_mut(ptr, len) })
}

/// Types for which every bit pattern is a valid value.
trait Plain {}
impl Plain for u8 {}
impl Plain for [u8; PH_MAX_FRAME_LEN] {}
impl Plain for ph_estimate {}

/// Writes `value` to an optional out-parameter (NULL: nothing is written).
///
/// # Safety
/// As [`write`].
unsafe fn set_optional<T>(ptr: *mut T, value: T) {
    // SAFETY: per the caller. A NULL (or misaligned) pointer is not written.
    let _ = unsafe { write(ptr, value) };
}

pub(crate) fn status(r: Result<(), ph_status>) -> ph_status {
    match r {
        Ok(()) => ph_status::PH_OK,
        Err(e) => e,
    }
}

/// The ABI version of this library (`PH_ABI_VERSION` of the header it was built with).
#[no_mangle]
pub extern "C" fn ph_abi_version() -> u32 {
    PH_ABI_VERSION
}

/// `PH_AGENT_SIZE` of this library (for a check against the header's).
#[no_mangle]
pub extern "C" fn ph_agent_size() -> usize {
    PH_AGENT_SIZE
}

/// `PH_AGENT_ALIGN` of this library.
#[no_mangle]
pub extern "C" fn ph_agent_align() -> usize {
    PH_AGENT_ALIGN
}

/// The name of a status code (`"PH_OK"`, `"PH_ERR_NULL"`, …; `"unknown status"` for a
/// value that is none): a static NUL-terminated string.
#[no_mangle]
pub extern "C" fn ph_status_str(status: i32) -> *const c_char {
    ph_status::from_code(status).map_or(c"unknown status".as_ptr(), |s| s.name().as_ptr())
}

/// Fills `*config` with the defaults of agent `id`: no triangles, no leader, shared
/// estimators, `r̂(0) = 1`, `r_min = 0.1`, zero friction and damping, `v* = 0`, the
/// core's default limits.
///
/// # Safety
/// `config` is NULL or valid for writes of a `ph_config`.
#[no_mangle]
pub unsafe extern "C" fn ph_config_default(config: *mut ph_config, id: u8) -> ph_status {
    // SAFETY: per this function's contract.
    status(unsafe { write(config, default_config(id)) })
}

/// Builds the agent of `*config` in `agent` (`size` bytes of caller memory, at least
/// `PH_AGENT_SIZE`, aligned to `PH_AGENT_ALIGN`). On any error the memory holds no agent
/// (later calls give `PH_ERR_NOT_INITIALIZED`). Needs a few KiB of stack
/// (docs/c-api.md); call it again to restart the agent.
///
/// # Safety
/// `agent` is NULL or valid for writes of `size` bytes and used by nothing else;
/// `config` is NULL or points to a `ph_config`.
#[no_mangle]
pub unsafe extern "C" fn ph_agent_init(
    agent: *mut ph_agent,
    size: usize,
    config: *const ph_config,
) -> ph_status {
    // SAFETY: per this function's contract.
    let config = || unsafe { input(config) }.and_then(to_core);
    // SAFETY: per this function's contract.
    unsafe { storage::init(agent, size, config) }
}

/// `ph_agent_init` with the configuration in a blob (`blob[0..len]`, written by the
/// Rust `ph_formation_ffi::encode_blob`, e.g. `host-sim export`). A blob with a wrong
/// magic, version, length or CRC-32, or one that does not decode, gives its own
/// `PH_ERR_BLOB_*` status; a configuration the core refuses, its `PH_ERR_CONFIG_*`.
///
/// # Safety
/// As `ph_agent_init`; `blob` is NULL or points to `len` readable bytes.
#[no_mangle]
pub unsafe extern "C" fn ph_agent_init_blob(
    agent: *mut ph_agent,
    size: usize,
    blob: *const u8,
    len: usize,
) -> ph_status {
    let config = || {
        // SAFETY: per this function's contract.
        let bytes = unsafe { slice(blob, len) }?;
        if bytes.is_empty() {
            return Err(ph_status::PH_ERR_NULL);
        }
        decode_blob(bytes).map_err(ph_status::from)
    };
    // SAFETY: per this function's contract.
    unsafe { storage::init(agent, size, config) }
}

/// Takes one received frame (`bytes[0..len]`, e.g. a P2P packet's payload). `PH_OK` if
/// accepted; a rejected frame changes nothing but the counters (`ph_stats`) and gives
/// its `PH_ERR_FRAME_*` status. Frames from robots that are not neighbours are
/// rejected with `PH_ERR_FRAME_UNKNOWN_SENDER`: normal on a broadcast radio.
///
/// # Safety
/// `agent` as for `ph_step`; `bytes` is NULL or points to `len` readable bytes.
#[no_mangle]
pub unsafe extern "C" fn ph_receive(
    agent: *mut ph_agent,
    bytes: *const u8,
    len: usize,
) -> ph_status {
    // SAFETY: per this function's contract.
    let r = unsafe { storage::agent_mut(agent) }.and_then(|a| {
        // SAFETY: per this function's contract.
        let bytes = unsafe { slice(bytes, len) }?;
        a.receive(bytes).map_err(ph_status::from)
    });
    status(r)
}

/// One control step with this tick's measurements → `*out` (force, status, fault).
/// Faults in the measurements or in what was heard are not errors: the output is then
/// the safe one (`PH_OUTPUT_SAFE`, `fault` says why) and the call returns `PH_OK`.
/// Refused arguments (NULL, more than `PH_MAX_NEIGHBOURS` bearings, unknown flag bits,
/// no agent) return their status without stepping, and `*out` (if not NULL) is a zero
/// force with `PH_OUTPUT_SAFE` and `PH_FAULT_NONE`.
///
/// # Safety
/// `agent` is NULL or memory passed to `ph_agent_init*`, not used concurrently;
/// `measurements` is NULL or points to a `ph_measurements` whose `bearings` point to
/// `bearing_count` readable `ph_bearing`s; `out` is NULL or writable.
#[no_mangle]
pub unsafe extern "C" fn ph_step(
    agent: *mut ph_agent,
    measurements: *const ph_measurements,
    out: *mut ph_output,
) -> ph_status {
    // Check `out` before stepping: a step whose output is lost would still advance the
    // agent.
    if let Err(e) = check(out) {
        return e;
    }
    // SAFETY: per this function's contract.
    let (o, r) = match unsafe { step(agent, measurements) } {
        Ok(o) => (o, ph_status::PH_OK),
        Err(e) => (NO_OUTPUT, e),
    };
    // SAFETY: per this function's contract.
    match unsafe { write(out, o) } {
        Ok(()) => r,
        Err(e) => e,
    }
}

/// # Safety
/// As [`ph_step`].
unsafe fn step(
    agent: *mut ph_agent,
    measurements: *const ph_measurements,
) -> Result<ph_output, ph_status> {
    // SAFETY: per the caller.
    let agent = unsafe { storage::agent_mut(agent) }?;
    // SAFETY: per the caller.
    let ph_measurements {
        time,
        dt,
        velocity,
        bearings,
        bearing_count,
        has_partner_offset,
        partner_offset,
    } = *unsafe { input(measurements) }?;
    // SAFETY: per the caller.
    let given: &[ph_bearing] = unsafe { slice(bearings, bearing_count) }?;
    let mut buf = [BearingMeasurement {
        neighbour: 0,
        bearing: Vec2::zeros(),
        rate: None,
        range: None,
    }; PH_MAX_NEIGHBOURS];
    let used = buf
        .get_mut(..given.len())
        .ok_or(ph_status::PH_ERR_ARGUMENT)?;
    for (dst, b) in used.iter_mut().zip(given) {
        *dst = bearing_to_core(b)?;
    }
    let [vx, vy] = velocity;
    let [px, py] = partner_offset;
    let o = agent.step(&Measurements {
        time,
        dt,
        velocity: Vec2::new(vx, vy),
        bearings: used,
        partner_offset: (has_partner_offset != 0).then(|| Vec2::new(px, py)),
    });
    Ok(output_from_core(&o))
}

/// This tick's broadcast into a caller buffer: frame `k` is `frames[k][0..lens[k]]`,
/// for `k < *count`. With `max_frames ≥ PH_MAX_FRAMES_PER_TICK` everything fits;
/// otherwise the frames that do not fit are lost (their sequence numbers are used) and
/// the call returns `PH_ERR_BUFFER_FULL` with what fit. Call once per tick, after
/// `ph_step`.
///
/// # Safety
/// `agent` as for `ph_step`; `frames` and `lens` are NULL or writable for `max_frames`
/// entries; `count` is NULL or writable.
#[no_mangle]
pub unsafe extern "C" fn ph_frames(
    agent: *mut ph_agent,
    frames: *mut [u8; PH_MAX_FRAME_LEN],
    lens: *mut u8,
    max_frames: usize,
    count: *mut usize,
) -> ph_status {
    // SAFETY: per this function's contract.
    unsafe { set_optional(count, 0) };
    let r = (|| {
        // SAFETY: per this function's contract.
        let agent = unsafe { storage::agent_mut(agent) }?;
        // SAFETY: per this function's contract.
        let frames = unsafe { slice_mut(frames, max_frames) }?;
        // SAFETY: per this function's contract.
        let lens = unsafe { slice_mut(lens, max_frames) }?;
        let mut slots = frames.iter_mut().zip(lens.iter_mut());
        let (mut written, mut lost) = (0usize, false);
        agent.frames(|bytes| match (slots.next(), u8::try_from(bytes.len())) {
            (Some((frame, len)), Ok(n)) => {
                if let Some(dst) = frame.get_mut(..bytes.len()) {
                    dst.copy_from_slice(bytes);
                    *len = n;
                    written = written.saturating_add(1);
                } else {
                    lost = true;
                }
            }
            _ => lost = true,
        });
        // SAFETY: per this function's contract.
        unsafe { set_optional(count, written) };
        if lost {
            Err(ph_status::PH_ERR_BUFFER_FULL)
        } else {
            Ok(())
        }
    })();
    status(r)
}

/// This tick's broadcast through `send(ctx, bytes, len)`, once per frame (e.g. straight
/// into `radiolinkSendP2PPacketBroadcast`); `*count` (if not NULL) is the number of
/// frames. Call once per tick, after `ph_step`.
///
/// # Safety
/// `agent` as for `ph_step`; `send` is NULL or a function safe to call with `ctx`;
/// `count` is NULL or writable.
#[no_mangle]
pub unsafe extern "C" fn ph_frames_cb(
    agent: *mut ph_agent,
    send: ph_send_fn,
    ctx: *mut c_void,
    count: *mut usize,
) -> ph_status {
    // SAFETY: per this function's contract.
    unsafe { set_optional(count, 0) };
    let Some(send) = send else {
        return ph_status::PH_ERR_NULL;
    };
    // SAFETY: per this function's contract.
    let r = unsafe { storage::agent_mut(agent) }.map(|a| {
        // SAFETY: `send` is safe to call with `ctx` (contract); the bytes are valid
        // during the call.
        a.frames(|bytes| unsafe { send(ctx, bytes.as_ptr(), bytes.len()) })
    });
    match r {
        Ok(n) => {
            // SAFETY: per this function's contract.
            unsafe { set_optional(count, n) };
            ph_status::PH_OK
        }
        Err(e) => e,
    }
}

/// `PH_INTEGRITY_AUTH`: sets this boot's epoch; the next frame's counter is
/// `epoch · 2³²`. Call it once after `ph_agent_init*` and before the first `ph_frames`,
/// with a value larger than at any earlier boot of this robot (keep it in non-volatile
/// memory and increment it at every boot): receivers reject every counter not larger
/// than the last one they accepted. Harmless with the other integrity modes.
///
/// # Safety
/// `agent` as for `ph_step`.
#[no_mangle]
pub unsafe extern "C" fn ph_agent_set_boot_epoch(agent: *mut ph_agent, epoch: u32) -> ph_status {
    // SAFETY: per this function's contract.
    let r = unsafe { storage::agent_mut(agent) }.map(|a| a.set_boot_epoch(epoch));
    status(r)
}

/// The counters of received frames, and the bearing trackers' reset counters.
///
/// # Safety
/// `agent` as for `ph_step` (read only); `out` is NULL or writable.
#[no_mangle]
pub unsafe extern "C" fn ph_stats(agent: *const ph_agent, out: *mut ph_frame_stats) -> ph_status {
    // SAFETY: per this function's contract.
    let r = unsafe { storage::agent_ref(agent) }
        // SAFETY: per this function's contract.
        .and_then(|a| unsafe {
            write(
                out,
                stats_from_core(a.stats(), a.track_resets().map(|(_, r)| r)),
            )
        });
    status(r)
}

/// The distance estimates this agent owns: `out[0..*count]`. `PH_MAX_OWNED_ESTIMATES`
/// entries always suffice; with fewer, the first `capacity` are written and the call
/// returns `PH_ERR_BUFFER_FULL`.
///
/// # Safety
/// `agent` as for `ph_stats`; `out` is NULL or writable for `capacity` entries; `count`
/// is NULL or writable.
#[no_mangle]
pub unsafe extern "C" fn ph_owned_estimates(
    agent: *const ph_agent,
    out: *mut ph_estimate,
    capacity: usize,
    count: *mut usize,
) -> ph_status {
    // SAFETY: per this function's contract.
    unsafe {
        copy_out(agent, out, capacity, count, |a, put| {
            a.owned_estimates().all(|e| put(estimate_from_core(&e)))
        })
    }
}

/// The ids of this agent's neighbours (triangle neighbours, then the leader partner):
/// `out[0..*count]`. Bearings are only taken to these. `PH_MAX_NEIGHBOURS` entries
/// always suffice; with fewer, the call returns `PH_ERR_BUFFER_FULL`.
///
/// # Safety
/// As `ph_owned_estimates`.
#[no_mangle]
pub unsafe extern "C" fn ph_neighbours(
    agent: *const ph_agent,
    out: *mut u8,
    capacity: usize,
    count: *mut usize,
) -> ph_status {
    // SAFETY: per this function's contract.
    unsafe {
        copy_out(agent, out, capacity, count, |a, put| {
            a.neighbours().all(put)
        })
    }
}

/// The leader partner of this agent: `*is_leader` = 1 and `*partner` its id for the
/// two leaders (SPEC S11), else `*is_leader` = 0 (and `*partner` untouched).
///
/// # Safety
/// `agent` as for `ph_stats`; `partner` and `is_leader` are NULL or writable.
#[no_mangle]
pub unsafe extern "C" fn ph_leader_partner(
    agent: *const ph_agent,
    partner: *mut u8,
    is_leader: *mut u8,
) -> ph_status {
    // SAFETY: per this function's contract.
    let r = unsafe { storage::agent_ref(agent) }.and_then(|a| {
        check(partner.cast_const())?;
        check(is_leader.cast_const())?;
        match &a.config().leader {
            Some(l) => {
                // SAFETY: per this function's contract.
                unsafe { write(partner, l.partner) }?;
                // SAFETY: as above.
                unsafe { write(is_leader, 1) }
            }
            // SAFETY: as above.
            None => unsafe { write(is_leader, 0) },
        }
    });
    status(r)
}

/// Fills `out[0..capacity]` with what `each` passes to `put` (which returns `false`
/// once full); sets `*count` to the number written.
///
/// # Safety
/// As `ph_owned_estimates`.
unsafe fn copy_out<T: Plain>(
    agent: *const ph_agent,
    out: *mut T,
    capacity: usize,
    count: *mut usize,
    each: impl FnOnce(&crate::FfiAgent, &mut dyn FnMut(T) -> bool) -> bool,
) -> ph_status {
    // SAFETY: per the caller.
    unsafe { set_optional(count, 0) };
    let r = (|| {
        // SAFETY: per the caller.
        let agent = unsafe { storage::agent_ref(agent) }?;
        // SAFETY: per the caller.
        let out = unsafe { slice_mut(out, capacity) }?;
        let mut slots = out.iter_mut();
        let mut written = 0usize;
        let all = each(agent, &mut |v| match slots.next() {
            Some(s) => {
                *s = v;
                written = written.saturating_add(1);
                true
            }
            None => false,
        });
        // SAFETY: per the caller.
        unsafe { set_optional(count, written) };
        if all {
            Ok(())
        } else {
            Err(ph_status::PH_ERR_BUFFER_FULL)
        }
    })();
    status(r)
}
