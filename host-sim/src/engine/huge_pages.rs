//! Huge pages for a large run's per-agent memory.
//!
//! A 100,000-agent run keeps about 400 MB of per-agent state (controllers, frame
//! buffers) in 4 KiB pages: each agent's tick touches a few pages no other recent tick
//! touched, so most ticks miss the address-translation cache (the TLB covers a few MB
//! with 4 KiB pages) and wait for page-table walks on top of the data itself. Backing the
//! same memory with 2 MiB pages removes most of those walks: 2.76 → 2.98–3.06 M
//! agent-steps/s at 100,000 agents on one thread (`docs/performance.md`), with no change
//! at 1,000 (whose state fits a few huge pages' worth of TLB entries anyway).
//!
//! The memory is already allocated and filled when the simulator is built (the
//! allocator's heap, in no particular order), so it is collapsed in place
//! (`madvise(MADV_COLLAPSE)`, Linux ≥ 6.1; independent of the system's transparent
//! huge page policy unless that is `never`). Like a prefetch, it is a hint: it never
//! changes a value, and where the kernel refuses it or on other systems nothing happens,
//! so results never depend on it.

/// A range of addresses that grows to cover every value added to it.
#[derive(Clone, Copy, Debug)]
pub struct Span {
    lo: usize,
    hi: usize,
}

impl Default for Span {
    fn default() -> Self {
        Self::new()
    }
}

impl Span {
    /// An empty span.
    pub fn new() -> Self {
        Self {
            lo: usize::MAX,
            hi: 0,
        }
    }

    /// Extends the span over the memory of `value` (its dynamic size for a trait object
    /// or a slice).
    pub fn add<T: ?Sized>(&mut self, value: &T) {
        let addr = (value as *const T).cast::<u8>() as usize;
        self.cover(addr, std::mem::size_of_val(value));
    }

    /// Extends the span over the whole allocated buffer of `v` (its capacity, not only
    /// its length).
    pub fn add_buffer<T>(&mut self, v: &Vec<T>) {
        let len = v.capacity().saturating_mul(std::mem::size_of::<T>());
        self.cover(v.as_ptr() as usize, len);
    }

    /// Extends the span over `len` bytes at `addr` (nothing if `len` is 0).
    fn cover(&mut self, addr: usize, len: usize) {
        if len > 0 {
            self.lo = self.lo.min(addr);
            self.hi = self.hi.max(addr.saturating_add(len));
        }
    }

    /// The whole huge pages inside the span: `(start, length)`, or `None` if there is
    /// not one.
    pub fn huge_pages(&self) -> Option<(usize, usize)> {
        let start = self.lo.checked_next_multiple_of(HUGE_PAGE)?;
        let end = self.hi - self.hi % HUGE_PAGE;
        (end > start).then(|| (start, end - start))
    }

    /// Asks the kernel to back the whole huge pages inside the span with huge pages
    /// (nothing if there are fewer than [`MIN_HUGE_PAGES`]).
    pub fn collapse(&self) {
        if let Some((start, len)) = self.huge_pages() {
            if len >= MIN_HUGE_PAGES * HUGE_PAGE {
                collapse(start, len);
            }
        }
    }
}

/// The huge page size of x86-64 and AArch64 Linux (2 MiB).
pub const HUGE_PAGE: usize = 2 << 20;

/// Spans of fewer huge pages are left alone: their translations fit the TLB anyway, and
/// small simulations (a sweep builds thousands) save the system call.
pub const MIN_HUGE_PAGES: usize = 4;

#[cfg(all(target_os = "linux", target_env = "gnu"))]
fn collapse(start: usize, len: usize) {
    // SAFETY: `madvise` with `MADV_COLLAPSE` only changes which physical pages back the
    // range, never its contents or its mapping; on memory the process does not own (or
    // an unmapped part) it fails with an error code, which is ignored (a hint).
    unsafe {
        libc::madvise(start as *mut libc::c_void, len, libc::MADV_COLLAPSE);
    }
}

#[cfg(not(all(target_os = "linux", target_env = "gnu")))]
fn collapse(_start: usize, _len: usize) {}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_span_covers_what_was_added_and_rounds_inward_to_huge_pages() {
        let mut s = Span::new();
        assert_eq!(s.huge_pages(), None);
        let big = vec![0u8; 5 * HUGE_PAGE];
        s.add(big.as_slice());
        let (start, len) = s
            .huge_pages()
            .expect("a 10 MiB buffer holds whole huge pages");
        let lo = big.as_ptr() as usize;
        assert!(start >= lo && start % HUGE_PAGE == 0);
        assert!(start + len <= lo + big.len() && len % HUGE_PAGE == 0);
        assert!(len >= 4 * HUGE_PAGE);
        let small = [0u8; 100];
        let mut t = Span::new();
        t.add(&small);
        t.add(&[0u8; 0][..]);
        assert_eq!(t.huge_pages(), None);
        // Collapsing never changes a value.
        let mut data: Vec<u64> = (0..(5 * HUGE_PAGE / 8) as u64).collect();
        let mut d = Span::new();
        d.add(data.as_slice());
        d.collapse();
        data[0] += 1;
        assert!(data
            .iter()
            .enumerate()
            .all(|(i, &x)| x == i as u64 + u64::from(i == 0)));
    }
}
