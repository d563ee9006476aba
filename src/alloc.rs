//! The process's allocator: the system allocator, with large blocks aligned to
//! 2 MiB and — for the commands that opt in with [`advise_huge_pages`] — marked
//! for transparent huge pages (`madvise(MADV_HUGEPAGE)`).
//!
//! Why: a fresh block is faulted in page by page on first touch, and on the
//! virtual machines measured a 4 KiB fault costs ≈ 4 µs — 8 MB of mode shapes
//! read from the cache cost ≈ 8 ms of faults, more than the physics of the
//! demo. With huge pages the same block takes a handful of faults. Linux with
//! THP in `madvise` mode (the common default) honours the hint; elsewhere it
//! is ignored and only the alignment remains.
//!
//! Only the sound-making commands (`render`, `strike`), whose large blocks are
//! banks read once, opt in. `precompute` does not: its hundreds of MB of fresh
//! factor storage measured slower with huge pages here (30k-DOF precompute,
//! 11 alternating pairs: faster without in 10, by 0.1–0.55 s of 2.3–3.6 s, with
//! more kernel time clearing 2 MiB pages).

use std::alloc::{GlobalAlloc, Layout, System};
use std::sync::atomic::{AtomicBool, Ordering};

/// Whether large blocks are advised for huge pages (see the module docs).
static ADVISE: AtomicBool = AtomicBool::new(false);

/// Marks every large block allocated from now on for transparent huge pages.
pub fn advise_huge_pages() {
    ADVISE.store(true, Ordering::Relaxed);
}

/// Blocks at least this large are huge-page aligned and advised.
const HUGE_BLOCK_BYTES: usize = 4 << 20;
/// Huge page size on x86-64 and most aarch64 kernels.
const HUGE_PAGE_BYTES: usize = 2 << 20;

/// See the module docs.
pub struct HugePageAlloc;

impl HugePageAlloc {
    /// The layout actually requested from the system for `layout`: a pure
    /// function of size and alignment, so `dealloc` recomputes the same one.
    fn system_layout(layout: Layout) -> Layout {
        if layout.size() >= HUGE_BLOCK_BYTES && layout.align() < HUGE_PAGE_BYTES {
            Layout::from_size_align(layout.size(), HUGE_PAGE_BYTES).unwrap_or(layout)
        } else {
            layout
        }
    }

    fn advise(ptr: *mut u8, layout: Layout) {
        #[cfg(target_os = "linux")]
        if !ptr.is_null() && layout.size() >= HUGE_BLOCK_BYTES && ADVISE.load(Ordering::Relaxed) {
            // SAFETY: `ptr..ptr + size` is a block we just allocated; madvise
            // only changes how the kernel backs it (an error is harmless).
            unsafe {
                libc::madvise(ptr.cast(), layout.size(), libc::MADV_HUGEPAGE);
            }
        }
        #[cfg(not(target_os = "linux"))]
        let _ = (ptr, layout);
    }
}

// SAFETY: every method forwards to `System` with a layout of at least the
// requested size and alignment, and `dealloc` passes the same layout `alloc`
// used (`system_layout` depends only on size and alignment).
unsafe impl GlobalAlloc for HugePageAlloc {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        let layout = Self::system_layout(layout);
        // SAFETY: forwarded contract of `GlobalAlloc::alloc`.
        let ptr = unsafe { System.alloc(layout) };
        Self::advise(ptr, layout);
        ptr
    }

    unsafe fn alloc_zeroed(&self, layout: Layout) -> *mut u8 {
        if layout.size() < HUGE_BLOCK_BYTES {
            // SAFETY: forwarded contract of `GlobalAlloc::alloc_zeroed`.
            return unsafe { System.alloc_zeroed(layout) };
        }
        // Advise before the zeroing touches the block, or it is faulted in
        // small pages (the system allocator zeroes over-aligned blocks itself).
        // SAFETY: `alloc` returns a block of at least `layout.size()` bytes or null.
        unsafe {
            let ptr = self.alloc(layout);
            if !ptr.is_null() {
                std::ptr::write_bytes(ptr, 0, layout.size());
            }
            ptr
        }
    }

    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        // SAFETY: `ptr` came from `alloc`/`alloc_zeroed`/`realloc` with this layout.
        unsafe { System.dealloc(ptr, Self::system_layout(layout)) }
    }

    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        let old = Self::system_layout(layout);
        let Ok(new_layout) = Layout::from_size_align(new_size, layout.align()) else {
            return std::ptr::null_mut();
        };
        let new = Self::system_layout(new_layout);
        if old.align() == new.align() {
            // SAFETY: forwarded contract of `GlobalAlloc::realloc` (same alignment).
            let ptr = unsafe { System.realloc(ptr, old, new_size) };
            Self::advise(ptr, new);
            return ptr;
        }
        // The alignment class changes: move the block.
        // SAFETY: `new` has a non-zero size (it is at least the old size or
        // was reached by growing/shrinking a live block); copy the common prefix.
        unsafe {
            let moved = System.alloc(new);
            if !moved.is_null() {
                std::ptr::copy_nonoverlapping(ptr, moved, layout.size().min(new_size));
                System.dealloc(ptr, old);
                Self::advise(moved, new);
            }
            moved
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn large_blocks_are_aligned_zeroed_and_keep_their_bytes_across_reallocs() {
        advise_huge_pages();
        let a = HugePageAlloc;
        let big = Layout::from_size_align(HUGE_BLOCK_BYTES + 123, 8).unwrap();
        // SAFETY: every pointer comes from `a` with the layout it is freed with.
        unsafe {
            let z = a.alloc_zeroed(big);
            assert!(!z.is_null());
            assert_eq!(z as usize % HUGE_PAGE_BYTES, 0);
            assert!(std::slice::from_raw_parts(z, big.size()).iter().all(|&b| b == 0));
            for i in 0..big.size() {
                *z.add(i) = (i % 251) as u8;
            }
            // Shrink below the threshold (alignment class changes), then grow back past it.
            let small = a.realloc(z, big, 1 << 20);
            assert!((0..1 << 20).all(|i| *small.add(i) == (i % 251) as u8));
            let small_layout = Layout::from_size_align(1 << 20, 8).unwrap();
            let grown = a.realloc(small, small_layout, 2 * HUGE_BLOCK_BYTES);
            assert_eq!(grown as usize % HUGE_PAGE_BYTES, 0);
            assert!((0..1 << 20).all(|i| *grown.add(i) == (i % 251) as u8));
            // Same class (both large): still aligned, bytes kept.
            let grown_layout = Layout::from_size_align(2 * HUGE_BLOCK_BYTES, 8).unwrap();
            let again = a.realloc(grown, grown_layout, 3 * HUGE_BLOCK_BYTES);
            assert_eq!(again as usize % HUGE_PAGE_BYTES, 0);
            assert!((0..1 << 20).all(|i| *again.add(i) == (i % 251) as u8));
            a.dealloc(again, Layout::from_size_align(3 * HUGE_BLOCK_BYTES, 8).unwrap());
        }
    }
}
