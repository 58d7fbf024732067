//! Software prefetch of what the next agents' ticks will read.
//!
//! A large run walks every agent's core (2.6 KB for a strip agent) and its neighbours'
//! frames once per tick; beyond about 5,000 agents that no longer fits the last-level
//! cache, and each agent's tick stalled on a dozen scattered misses (the neighbour table,
//! the angle states, the frames): 0.9 M agent-steps/s at 10,000 and 100,000 agents against
//! 2.6 M at 1,000. Asking for agent `i + AHEAD`'s memory while agent `i` ticks turns those
//! misses into one overlapped stream: 2.0–2.2 M at 10,000 and 100,000
//! (`docs/performance.md`, where the hint and distance were measured).
//!
//! A prefetch is a hint: it never faults, never changes a value, and is a no-op on
//! targets other than x86-64, so results do not depend on it.

/// How many agents ahead to prefetch: 2, 4, 8 and 16 measured the same within noise.
pub const AHEAD: usize = 4;

/// Where a value lies in memory, kept to prefetch it later without borrowing it (a
/// controller behind a `Box` never moves).
#[derive(Clone, Copy, Debug)]
pub struct Footprint {
    addr: usize,
    len: usize,
}

impl Footprint {
    /// The memory of `value` (its dynamic size for a trait object).
    pub fn of<T: ?Sized>(value: &T) -> Self {
        Self {
            addr: (value as *const T).cast::<u8>() as usize,
            len: std::mem::size_of_val(value),
        }
    }

    /// Asks for every cache line of the footprint.
    #[inline]
    pub fn prefetch(self) {
        for offset in (0..self.len).step_by(64) {
            line(self.addr.wrapping_add(offset));
        }
    }
}

/// Asks for every cache line of `value`.
#[inline]
pub fn prefetch<T: ?Sized>(value: &T) {
    Footprint::of(value).prefetch();
}

/// Asks for the cache line at `addr` into the mid-level cache (`T1`: in this simulator's
/// walk, 2.05 M agent-steps/s at 100,000 agents against 1.25 M with `T0`, whose requests
/// crowded the first-level cache's miss buffers).
#[inline(always)]
fn line(addr: usize) {
    #[cfg(target_arch = "x86_64")]
    // SAFETY: `_mm_prefetch` only needs SSE, which every x86-64 processor has; a prefetch
    // of any address (even an unmapped one) never faults and never reads into the program.
    unsafe {
        use std::arch::x86_64::{_mm_prefetch, _MM_HINT_T1};
        _mm_prefetch::<_MM_HINT_T1>(addr as *const i8);
    }
    #[cfg(not(target_arch = "x86_64"))]
    let _ = addr;
}
