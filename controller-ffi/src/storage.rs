//! The agent in memory the caller provides: `PH_AGENT_SIZE` bytes aligned to
//! `PH_AGENT_ALIGN`, typically a static buffer of the firmware.
//!
//! The memory holds a [`Slot`]: a marker word and the agent. `ph_agent_init*` writes
//! the agent and then the marker; every other entry point checks pointer, alignment and
//! marker before it touches the agent, so a zeroed (never initialised) buffer or a
//! failed initialisation gives `PH_ERR_NOT_INITIALIZED` instead of undefined behaviour.
//! (The marker cannot tell a random buffer from an agent with certainty: initialise
//! before use.)
//!
//! The sizes are literal constants because the header needs literals; the assertions
//! below fail to compile when they are wrong, and the error message names the right
//! value ("expected an array with a size of X, found one with a size of Y": X is the
//! constant, Y the real size).

use core::mem::{align_of, size_of};
use core::ptr::{addr_of, addr_of_mut};

use crate::status::ph_status;
use crate::{FfiAgent, FfiConfig};

/// Opaque handle: a pointer to the caller's agent memory (`PH_AGENT_SIZE` bytes,
/// aligned to `PH_AGENT_ALIGN`). (Not `repr(C)`: the header declares it incomplete.)
pub struct ph_agent {
    _private: [u8; 0],
}

/// Bytes of agent memory (`sizeof` the agent, for 32-bit targets such as Cortex-M).
#[cfg(target_pointer_width = "32")]
pub const PH_AGENT_SIZE: usize = 3860;
/// Alignment of the agent memory, in bytes.
#[cfg(target_pointer_width = "32")]
pub const PH_AGENT_ALIGN: usize = 4;
/// Bytes of agent memory (`sizeof` the agent, for 64-bit hosts).
#[cfg(target_pointer_width = "64")]
pub const PH_AGENT_SIZE: usize = 4200;
/// Alignment of the agent memory, in bytes.
#[cfg(target_pointer_width = "64")]
pub const PH_AGENT_ALIGN: usize = 8;

/// "PHAG": the memory holds an initialised agent.
const MARKER: u32 = 0x4741_4850;

/// What the caller's memory holds.
#[repr(C)]
pub struct Slot {
    marker: u32,
    agent: FfiAgent,
}

const _: [(); PH_AGENT_SIZE] = [(); size_of::<Slot>()];
const _: [(); PH_AGENT_ALIGN] = [(); align_of::<Slot>()];

/// Checks the memory for initialisation and returns it as a `Slot` pointer.
fn slot_ptr(memory: *mut ph_agent, size: usize) -> Result<*mut Slot, ph_status> {
    if memory.is_null() {
        return Err(ph_status::PH_ERR_NULL);
    }
    if size < size_of::<Slot>() {
        return Err(ph_status::PH_ERR_STORAGE_SIZE);
    }
    let slot = memory.cast::<Slot>();
    if !slot.is_aligned() {
        return Err(ph_status::PH_ERR_STORAGE_ALIGN);
    }
    Ok(slot)
}

/// Builds the agent of the configuration `config()` returns in `memory` (`size` bytes).
/// On any error the memory no longer holds an agent. (`config` runs inside, so that
/// the configuration is built in the same out-of-line frame as the agent.)
///
/// # Safety
/// `memory` is NULL or valid for writes of `size` bytes, and not used by anything else
/// while the agent lives there.
pub unsafe fn init(
    memory: *mut ph_agent,
    size: usize,
    config: impl FnOnce() -> Result<FfiConfig, ph_status>,
) -> ph_status {
    let slot = match slot_ptr(memory, size) {
        Ok(s) => s,
        Err(e) => return e,
    };
    // SAFETY: `slot` is non-null, aligned and has room for a `Slot` (checked above);
    // the caller guarantees it is valid for writes. Raw writes: the memory may hold
    // anything (no reference to a `Slot` is made before it holds one).
    unsafe { addr_of_mut!((*slot).marker).write(0) };
    // SAFETY: as above.
    if let Err(e) = unsafe { build(config, addr_of_mut!((*slot).agent)) } {
        return e;
    }
    // SAFETY: as above; the marker is written last, so an agent is only ever seen
    // complete.
    unsafe { addr_of_mut!((*slot).marker).write(MARKER) };
    ph_status::PH_OK
}

/// `Agent::new(config)` written to `dst`, copied straight out of the `Result` (moving
/// it out would put a second copy of the agent on the stack: init's stack is in
/// docs/c-api.md). Out of line, so that no caller's frame holds one either.
///
/// # Safety
/// `dst` is valid for writes of an agent.
#[inline(never)]
unsafe fn build(
    config: impl FnOnce() -> Result<FfiConfig, ph_status>,
    dst: *mut FfiAgent,
) -> Result<(), ph_status> {
    let built = FfiAgent::new(configure(config)?);
    match &built {
        Ok(agent) => {
            // SAFETY: `dst` is valid for writes (caller); this is a bitwise move of
            // `agent`, whose original is forgotten right after (never used or dropped).
            unsafe { core::ptr::copy_nonoverlapping(agent, dst, 1) };
            core::mem::forget(built);
            Ok(())
        }
        Err(e) => Err((*e).into()),
    }
}

/// `config()` out of line: its conversion's temporaries (a blob's decoder, the C
/// struct's mapping) live in a frame of their own that is gone before `Agent::new`
/// runs, instead of in `build`'s frame underneath it.
#[inline(never)]
fn configure(
    config: impl FnOnce() -> Result<FfiConfig, ph_status>,
) -> Result<FfiConfig, ph_status> {
    config()
}

/// The agent in `memory`, if it holds one.
///
/// # Safety
/// `memory` is NULL, or was passed to `init` (or is valid for reads of
/// `PH_AGENT_SIZE` bytes), and no other reference to the agent exists during `'a`.
pub unsafe fn agent_mut<'a>(memory: *mut ph_agent) -> Result<&'a mut FfiAgent, ph_status> {
    let slot = slot_ptr(memory, size_of::<Slot>())?;
    // SAFETY: `slot` is non-null and aligned; the caller guarantees it is readable.
    if unsafe { addr_of!((*slot).marker).read() } != MARKER {
        return Err(ph_status::PH_ERR_NOT_INITIALIZED);
    }
    // SAFETY: the marker says `init` wrote a complete agent there; the caller
    // guarantees exclusive access.
    Ok(unsafe { &mut *addr_of_mut!((*slot).agent) })
}

/// [`agent_mut`] for reading.
///
/// # Safety
/// As [`agent_mut`], but other shared references may exist.
pub unsafe fn agent_ref<'a>(memory: *const ph_agent) -> Result<&'a FfiAgent, ph_status> {
    let slot = slot_ptr(memory.cast_mut(), size_of::<Slot>())?;
    // SAFETY: as in `agent_mut`.
    if unsafe { addr_of!((*slot).marker).read() } != MARKER {
        return Err(ph_status::PH_ERR_NOT_INITIALIZED);
    }
    // SAFETY: as in `agent_mut`, shared.
    Ok(unsafe { &*addr_of!((*slot).agent) })
}
