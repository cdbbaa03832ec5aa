//! A global allocator that asks Linux to back large allocations with transparent huge
//! pages, for processes whose large tables are read at random: a broad phase of 100,000
//! bodies, most of all.
//!
//! # Why
//! A skin grid of 100,000 bodies keeps about 35 MB of records, boxes and columns, and a
//! frame reads them at scattered places: with 4 KiB pages nearly every such read also
//! misses the TLB, whose entries cover a few MiB, and waits for a page walk. With 2 MiB
//! pages the same entries cover the whole working set. Measured (`examples/broad_bench`,
//! 100,000 uniform bodies, 10 % moving, six alternating runs of 150 frames, the pages
//! switched by glibc's `glibc.malloc.hugetlb` tunable, which gives the same advice): a
//! median 4.0 → 3.15 ms a frame.
//!
//! # How
//! Every allocation (and reallocation) of at least [`HUGE_FROM`] bytes is made by the
//! system allocator as usual, then advised `MADV_HUGEPAGE` over the whole pages it spans.
//! The kernel backs the advised range with huge pages as it is first touched (and
//! `khugepaged` later collapses what it could not), when transparent huge pages are set to
//! `madvise` or `always` (`/sys/kernel/mm/transparent_hugepage/enabled`); with `never`, or
//! off Linux, this allocator is the system allocator. The advice is one system call per
//! large allocation: the hot paths allocate nothing after warm-up, so it is paid there.
//!
//! # Use
//! A library cannot choose its users' allocator; a binary opts in with
//! `#[global_allocator] static ALLOC: HugePageAlloc = HugePageAlloc;` (as `proximad` and
//! `examples/broad_bench` do).

use std::alloc::{GlobalAlloc, Layout, System};
use std::sync::atomic::{AtomicBool, Ordering};

/// Allocations of at least this many bytes are advised onto huge pages: twice a huge page
/// (2 MiB on x86-64), so that each holds at least one whole aligned huge page.
pub const HUGE_FROM: usize = 4 << 20;

/// The system allocator, with allocations of [`HUGE_FROM`] bytes or more advised onto
/// transparent huge pages (module docs) while [`advising`] is on.
#[derive(Debug, Clone, Copy, Default)]
pub struct HugePageAlloc;

/// Whether large allocations are advised; on from the start.
static ADVISING: AtomicBool = AtomicBool::new(true);

/// Turns the advice on or off for the allocations made from now on (the pages advised
/// before stay so), for a process that measures what huge pages buy, as
/// `examples/broad_bench --small-pages` does.
pub fn set_advising(on: bool) {
    ADVISING.store(on, Ordering::Relaxed);
}

/// Whether large allocations are advised now ([`set_advising`]).
#[must_use]
pub fn advising() -> bool {
    ADVISING.load(Ordering::Relaxed)
}

// SAFETY: every call is forwarded unchanged to `System`, whose contract the caller keeps;
// the advice afterwards neither moves nor changes the memory returned.
unsafe impl GlobalAlloc for HugePageAlloc {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        // SAFETY: the caller keeps `GlobalAlloc::alloc`'s contract, which is `System`'s.
        let p = unsafe { System.alloc(layout) };
        advise(p, layout.size());
        p
    }

    unsafe fn alloc_zeroed(&self, layout: Layout) -> *mut u8 {
        // SAFETY: as for `alloc`.
        let p = unsafe { System.alloc_zeroed(layout) };
        advise(p, layout.size());
        p
    }

    unsafe fn dealloc(&self, p: *mut u8, layout: Layout) {
        // SAFETY: `p` came from `System` (every allocation here does) with `layout`.
        unsafe { System.dealloc(p, layout) }
    }

    unsafe fn realloc(&self, p: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        // SAFETY: `p` came from `System` with `layout`; the caller keeps `realloc`'s
        // contract for `new_size`.
        let q = unsafe { System.realloc(p, layout, new_size) };
        advise(q, new_size);
        q
    }
}

/// Advises the whole pages of the `size` bytes at `p` (none when `p` is null, the
/// allocation is smaller than [`HUGE_FROM`] or [`advising`] is off) onto huge pages. The result is ignored: the
/// advice is a hint, and the memory is usable either way.
fn advise(p: *mut u8, size: usize) {
    if p.is_null() || size < HUGE_FROM || !advising() {
        return;
    }
    #[cfg(target_os = "linux")]
    {
        const PAGE: usize = 4096;
        let start = (p as usize).next_multiple_of(PAGE);
        let end = (p as usize + size) / PAGE * PAGE;
        if end > start {
            // SAFETY: `madvise` reads and writes no memory of ours; the range is whole pages
            // inside the allocation just made, which this process owns, and
            // `MADV_HUGEPAGE` changes how it is backed, never its contents.
            unsafe {
                libc::madvise(start as *mut libc::c_void, end - start, libc::MADV_HUGEPAGE);
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The `VmFlags` of the mapping of this process that holds `address`, from
    /// `/proc/self/smaps`.
    #[cfg(target_os = "linux")]
    fn vm_flags(address: usize) -> String {
        let smaps = std::fs::read_to_string("/proc/self/smaps").expect("smaps readable");
        let mut inside = false;
        for line in smaps.lines() {
            let range = line
                .split_whitespace()
                .next()
                .and_then(|r| r.split_once('-'));
            if let Some((low, high)) = range
                && let (Ok(low), Ok(high)) = (
                    usize::from_str_radix(low, 16),
                    usize::from_str_radix(high, 16),
                )
            {
                inside = (low..high).contains(&address);
            } else if inside && let Some(flags) = line.strip_prefix("VmFlags:") {
                return flags.to_owned();
            }
        }
        panic!("no mapping holds {address:#x}");
    }

    /// A large allocation is advised (its mapping carries the `hg` flag, `MADV_HUGEPAGE`),
    /// also after growing by reallocation; its bytes are all usable and survive the growth.
    /// (A kernel built without transparent huge pages refuses the advice: there only the
    /// bytes are checked.)
    #[cfg(target_os = "linux")]
    #[test]
    fn large_allocations_are_advised_onto_huge_pages_and_stay_usable() {
        let alloc = HugePageAlloc;
        let kernel_has_them = std::path::Path::new("/sys/kernel/mm/transparent_hugepage").exists();
        let advised = |address: usize| {
            !kernel_has_them || vm_flags(address).split_whitespace().any(|f| f == "hg")
        };
        let layout = Layout::from_size_align(HUGE_FROM, 64).expect("layout");
        // SAFETY: a valid non-zero layout; the memory is written only within it, then
        // grown and freed with the layouts it has.
        unsafe {
            let p = alloc.alloc(layout);
            assert!(!p.is_null());
            for i in 0..HUGE_FROM {
                *p.add(i) = (i % 251) as u8;
            }
            let middle = p as usize + HUGE_FROM / 2;
            assert!(advised(middle), "not advised: {}", vm_flags(middle));
            let grown = alloc.realloc(p, layout, 3 * HUGE_FROM);
            assert!(!grown.is_null());
            assert!((0..HUGE_FROM).all(|i| *grown.add(i) == (i % 251) as u8));
            let far = grown as usize + 2 * HUGE_FROM;
            assert!(advised(far), "not advised after growing: {}", vm_flags(far));
            alloc.dealloc(
                grown,
                Layout::from_size_align(3 * HUGE_FROM, 64).expect("layout"),
            );
        }
    }
}
