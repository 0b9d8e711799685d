//! A counting global allocator for the tests that check a hot loop does not allocate: counts
//! per thread, so the harness's own threads cannot disturb the count.
use std::alloc::{GlobalAlloc, Layout, System};
use std::cell::Cell;

struct Counting;
thread_local! {
    static ALLOCS: Cell<usize> = const { Cell::new(0) };
}

unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        let _ = ALLOCS.try_with(|c| c.set(c.get() + 1));
        unsafe { System.alloc(layout) }
    }
    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        unsafe { System.dealloc(ptr, layout) }
    }
}

#[global_allocator]
static GLOBAL: Counting = Counting;

/// Allocations made by this thread so far.
pub fn allocations() -> usize {
    ALLOCS.with(Cell::get)
}

/// Panics unless the counter sees an allocation of this thread.
pub fn assert_counting() {
    let b = allocations();
    std::hint::black_box(Vec::<u8>::with_capacity(8));
    assert!(allocations() > b, "counting allocator inactive");
}
