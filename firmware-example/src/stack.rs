//! Peak stack use, from cortex-m-rt's `paint-stack` feature.
//!
//! At reset cortex-m-rt fills everything between `_stack_end` (the end of
//! `.bss`/`.uninit`, i.e. the lowest address the stack may reach) and
//! `_stack_start` (the initial stack pointer, end of RAM) with
//! [`cortex_m_rt::STACK_PAINT_VALUE`]. The deepest point the stack reached is
//! the lowest word that no longer holds the paint. Deterministic on QEMU; on
//! a real board it also covers interrupt handlers that ran.
//!
//! (A stack frame that reserves space without writing it is not seen; for
//! control code this underestimates by at most a few words.)

/// Stack usage figures, in bytes.
#[derive(Clone, Copy, Debug, defmt::Format)]
pub struct StackUsage {
    /// Deepest stack use since reset.
    pub peak: u32,
    /// Size of the stack region (`_stack_start - _stack_end`).
    pub size: u32,
}

extern "C" {
    static _stack_start: u32;
    static _stack_end: u32;
}

/// Scans the painted stack region and returns the peak use so far.
///
/// Call it at the end of a run, after the code of interest has executed.
#[inline(never)]
pub fn usage() -> StackUsage {
    // Only the addresses of the linker symbols are used.
    let top = core::ptr::addr_of!(_stack_start) as usize;
    let bottom = core::ptr::addr_of!(_stack_end) as usize;
    let mut p = bottom;
    while p < top {
        // SAFETY: `p` is word-aligned (cortex-m-rt asserts both bounds are)
        // and inside RAM between the end of the statics and the initial
        // stack pointer; reading it has no side effects.
        let word = unsafe { (p as *const u32).read_volatile() };
        if word != cortex_m_rt::STACK_PAINT_VALUE {
            break;
        }
        p += 4;
    }
    StackUsage {
        peak: (top - p) as u32,
        size: (top - bottom) as u32,
    }
}

/// Logs the stack usage in the line format `scripts/firmware-check.sh`
/// parses: `FWCHECK stack peak_bytes=<n> size_bytes=<n>`.
pub fn report() -> StackUsage {
    let u = usage();
    defmt::println!(
        "FWCHECK stack peak_bytes={=u32} size_bytes={=u32}",
        u.peak,
        u.size
    );
    u
}
