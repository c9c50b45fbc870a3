//! A counting global allocator for the allocation tests: each test binary that includes this
//! module counts the heap allocations of each thread ([`allocations`] reads the calling
//! thread's count). Counting per thread keeps other threads (the test harness's, a pool's) out
//! of the count: a process-wide counter once saw 4 allocations in `ode_alloc` during a CI run
//! on a loaded machine that no rerun reproduced, which a deterministic step loop on the test's
//! own thread cannot produce.

use std::alloc::{GlobalAlloc, Layout, System};
use std::cell::Cell;

pub struct Counting;

thread_local! {
    // `const` initialization with a type without a destructor: reading it never allocates,
    // so the allocator may use it.
    static COUNT: Cell<usize> = const { Cell::new(0) };
}

/// Heap allocations made so far by the calling thread.
pub fn allocations() -> usize {
    COUNT.with(|c| c.get())
}

unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        // `try_with`: a thread being torn down has no counter left, and is not measured.
        let _ = COUNT.try_with(|c| c.set(c.get() + 1));
        unsafe { System.alloc(layout) }
    }
    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        unsafe { System.dealloc(ptr, layout) }
    }
}

#[global_allocator]
static GLOBAL: Counting = Counting;
