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
//! huge page policy unless that is `never`). Only ranges densely filled with the values
//! given are collapsed (clusters whose gaps are under [`JOIN_GAP`]): allocations from
//! different allocator arenas never make one range over whatever lies between them
//! (other threads' stacks, libraries). Like a prefetch, it is a hint: it never
//! changes a value, and where the kernel refuses it or on other systems nothing happens,
//! so results never depend on it.

/// The memory of many values, collapsed cluster by cluster ([`Regions::collapse`]).
#[derive(Clone, Debug, Default)]
pub struct Regions {
    /// `(start, end)` of every value added.
    ranges: Vec<(usize, usize)>,
}

impl Regions {
    /// No memory yet.
    pub fn new() -> Self {
        Self::default()
    }

    /// Adds the memory of `value` (its dynamic size for a trait object or a slice).
    pub fn add<T: ?Sized>(&mut self, value: &T) {
        let addr = (value as *const T).cast::<u8>() as usize;
        self.cover(addr, std::mem::size_of_val(value));
    }

    /// Adds the whole allocated buffer of `v` (its capacity, not only its length).
    pub fn add_buffer<T>(&mut self, v: &Vec<T>) {
        let len = v.capacity().saturating_mul(std::mem::size_of::<T>());
        self.cover(v.as_ptr() as usize, len);
    }

    /// Adds `len` bytes at `addr` (nothing if `len` is 0).
    fn cover(&mut self, addr: usize, len: usize) {
        if len > 0 {
            self.ranges.push((addr, addr.saturating_add(len)));
        }
    }

    /// The whole huge pages inside each cluster of the values added (values less than
    /// [`JOIN_GAP`] apart join one cluster), `(start, length)` in address order; clusters
    /// with fewer than [`MIN_HUGE_PAGES`] are left out.
    pub fn huge_pages(&mut self) -> Vec<(usize, usize)> {
        self.ranges.sort_unstable();
        let mut clusters: Vec<(usize, usize)> = Vec::new();
        for &(lo, hi) in &self.ranges {
            match clusters.last_mut() {
                Some(last) if lo < last.1.saturating_add(JOIN_GAP) => last.1 = last.1.max(hi),
                _ => clusters.push((lo, hi)),
            }
        }
        clusters
            .into_iter()
            .filter_map(|(lo, hi)| {
                let start = lo.checked_next_multiple_of(HUGE_PAGE)?;
                let end = hi - hi % HUGE_PAGE;
                (end >= start + MIN_HUGE_PAGES * HUGE_PAGE).then(|| (start, end - start))
            })
            .collect()
    }

    /// Asks the kernel to back the whole huge pages of every cluster
    /// ([`Self::huge_pages`]) with huge pages.
    pub fn collapse(&mut self) {
        for (start, len) in self.huge_pages() {
            collapse(start, len);
        }
    }
}

/// The huge page size of x86-64 and AArch64 Linux (2 MiB).
pub const HUGE_PAGE: usize = 2 << 20;

/// Values closer than this join one cluster (8 huge pages): the allocator's own data
/// between a simulator's values (the model's, the tick's other buffers) is collapsed
/// with them, while separately mapped regions (other arenas, thread stacks, libraries)
/// lie farther apart.
pub const JOIN_GAP: usize = 8 * HUGE_PAGE;

/// Clusters of fewer huge pages are left alone: their translations fit the TLB anyway,
/// and small simulations (a sweep builds thousands) save the system call.
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
    fn clusters_cover_what_was_added_rounded_inward_to_huge_pages() {
        let mut r = Regions::new();
        assert!(r.huge_pages().is_empty());
        let big = vec![0u8; 5 * HUGE_PAGE];
        r.add(big.as_slice());
        let pages = r.huge_pages();
        assert_eq!(pages.len(), 1, "{pages:?}");
        let (start, len) = pages[0];
        let lo = big.as_ptr() as usize;
        assert!(start >= lo && start % HUGE_PAGE == 0);
        assert!(start + len <= lo + big.len() && len % HUGE_PAGE == 0);
        assert!(len >= 4 * HUGE_PAGE);
        // Small values, and nothing at all, give no huge page.
        let mut t = Regions::new();
        t.add(&[0u8; 100]);
        t.add(&[0u8; 0][..]);
        assert!(t.huge_pages().is_empty());
    }

    #[test]
    fn values_far_apart_are_separate_clusters() {
        let p = HUGE_PAGE;
        let mut r = Regions::new();
        // Two dense runs of 1 KiB values 100 huge pages apart, added out of order; a
        // lone value far beyond them.
        for k in (0..10 * 1024).rev() {
            r.cover(1000 * p + k * 1024, 1024);
            r.cover(1100 * p + k * 1024, 1024);
        }
        r.cover(5000 * p, 64);
        assert_eq!(r.huge_pages(), vec![(1000 * p, 5 * p), (1100 * p, 5 * p)]);
        // Gaps under JOIN_GAP join, wider ones do not.
        let mut j = Regions::new();
        j.cover(10 * p, 3 * p);
        j.cover(13 * p + JOIN_GAP - p / 2, 3 * p);
        j.cover(30 * p + 2 * JOIN_GAP, 4 * p);
        let joined = (10 * p, 6 * p + JOIN_GAP - p);
        assert_eq!(j.huge_pages(), vec![joined, (30 * p + 2 * JOIN_GAP, 4 * p)]);
    }

    #[test]
    fn collapsing_never_changes_a_value() {
        let mut data: Vec<u64> = (0..(5 * HUGE_PAGE / 8) as u64).collect();
        let mut r = Regions::new();
        r.add(data.as_slice());
        r.collapse();
        data[0] += 1;
        assert!(data
            .iter()
            .enumerate()
            .all(|(i, &x)| x == i as u64 + u64::from(i == 0)));
    }
}
