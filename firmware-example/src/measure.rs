//! Instruction-count markers for on-target measurements.
//!
//! A measured region is delimited by two 32-bit stores into the marker table
//! [`PH_INSN_MARKERS`] (a `#[no_mangle]` static, so its address can be read
//! from the ELF):
//!
//! * begin of region `id`: a store to `PH_INSN_MARKERS + 8 * id`,
//! * end of region `id`: a store to `PH_INSN_MARKERS + 8 * id + 4`.
//!
//! The QEMU TCG plugin in `tools/qemu-insn/` watches stores to that table and
//! prints how many guest instructions executed between the begin and the end
//! store of each region. The count includes a small fixed overhead (the end
//! store and the [`black_box`] spills of [`measured`], 6 instructions today):
//! the `overhead` row that `scripts/firmware-check.sh` prints is an empty
//! region measured the same way. The stored value is the region id,
//! which also makes the markers visible to a debugger on a real board, where
//! they are ordinary RAM stores and cost a few cycles.
//!
//! Use [`measured`] around one step:
//!
//! ```ignore
//! let force = measure::measured(id, &inputs, |inp| controller_step(inp));
//! ```
//!
//! Region ids are `0..MAX_REGIONS`; the `measure` binary uses 0 for the empty
//! calibration region and `i + 1` for `STEP_CONFIGS[i]`.

use core::cell::UnsafeCell;
use core::hint::black_box;
use core::mem::MaybeUninit;

/// Number of distinct region ids (`0..MAX_REGIONS`).
pub const MAX_REGIONS: usize = 64;

/// Marker table watched by the instruction-counting plugin.
///
/// It lives in `.uninit` (not zeroed at reset), so that the start-up code
/// does not write it and produce spurious markers; the program only ever
/// writes it.
#[repr(transparent)]
pub struct Markers(UnsafeCell<MaybeUninit<[u32; 2 * MAX_REGIONS]>>);

// SAFETY: the table is only ever written with volatile stores of plain
// integers and never read by the program; concurrent writes cannot break any
// invariant.
unsafe impl Sync for Markers {}

/// The marker table; its symbol name is what the measurement scripts look up
/// in the ELF (`llvm-nm`). Do not rename without updating
/// `scripts/firmware-check.sh`.
#[no_mangle]
#[cfg_attr(target_os = "none", link_section = ".uninit.PH_INSN_MARKERS")]
pub static PH_INSN_MARKERS: Markers = Markers(UnsafeCell::new(MaybeUninit::uninit()));

/// Address of the begin (`end == false`) or end marker word of region `id`
/// (taken modulo [`MAX_REGIONS`]).
#[inline(always)]
fn slot(id: u8, end: bool) -> *mut u32 {
    let index = 2 * (usize::from(id) % MAX_REGIONS) + usize::from(end);
    // In bounds: `index < 2 * MAX_REGIONS`.
    PH_INSN_MARKERS.0.get().cast::<u32>().wrapping_add(index)
}

#[inline(always)]
fn mark(word: *mut u32, id: u8) {
    // SAFETY: `word` comes from `slot`, so it points into the static marker
    // table, which is valid for writes of `u32` for the whole program.
    unsafe { word.write_volatile(u32::from(id)) };
}

/// Marks the beginning of measured region `id` (taken modulo
/// [`MAX_REGIONS`]).
#[inline(always)]
pub fn begin(id: u8) {
    mark(slot(id, false), id);
}

/// Marks the end of measured region `id` (taken modulo [`MAX_REGIONS`]).
#[inline(always)]
pub fn end(id: u8) {
    mark(slot(id, true), id);
}

/// Runs `step(input)` as measured region `id` and returns its result.
///
/// `input` and the result pass through [`black_box`], so the compiler can
/// neither start the computation before the begin marker nor finish it after
/// the end marker (nor drop it). Put everything that belongs to one control
/// step inside `step`, and prepare its inputs before the call.
///
/// For counts that are comparable between call sites, call this from one
/// `#[inline(never)]` function (as the `measure` binary does): the compiler
/// may schedule a few unrelated instructions of the caller between the two
/// markers, and a single call site keeps that overhead the same everywhere.
#[inline(always)]
pub fn measured<T, R>(id: u8, input: T, step: impl FnOnce(T) -> R) -> R {
    let (first, last) = (slot(id, false), slot(id, true));
    mark(first, id);
    let out = black_box(step(black_box(input)));
    mark(last, id);
    out
}
