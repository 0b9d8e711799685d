//! The replay's queries do not allocate (hot loop of the rotor run): counted with a wrapping
//! global allocator in this test binary.
mod flight_support;
use flight_support::*;
use rotorsim::flight::{AirloadReplay, FlightRecord, ReplayMode, ReplayOptions};
use std::alloc::{GlobalAlloc, Layout, System};
use std::cell::Cell;

struct Counting;
thread_local! {
    // Per thread, so the harness's own threads cannot disturb the count.
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

#[test]
fn queries_do_not_allocate() {
    let rec = FlightRecord::read(&example_stem()).unwrap();
    let providers = [
        AirloadReplay::new(&rec, ReplayMode::Sequence, ReplayOptions::default()).unwrap(),
        AirloadReplay::new(&rec, ReplayMode::Revolution(3), ReplayOptions::default()).unwrap(),
        AirloadReplay::new(
            &rec,
            ReplayMode::Average,
            ReplayOptions {
                harmonics: Some(12),
                ..Default::default()
            },
        )
        .unwrap(),
    ];
    // The counter sees allocations of this thread.
    let b = ALLOCS.with(Cell::get);
    let v: Vec<u8> = Vec::with_capacity(8);
    std::hint::black_box(&v);
    assert!(ALLOCS.with(Cell::get) > b, "counting allocator inactive");
    for rp in &providers {
        let before = ALLOCS.with(Cell::get);
        let mut acc = 0.0;
        for k in 0..2000 {
            let t = k as f64 * 7.7e-4 - 0.1;
            let r = 0.5 + (k % 80) as f64 * 0.1;
            let s = rp.section_loads(t, r);
            acc += s.normal_N_per_m + s.chord_N_per_m + s.moment_N_m_per_m;
            acc += rp.at_azimuth(k as f64 * 0.37, 0.9).normal_N_per_m;
        }
        assert!(acc.is_finite());
        assert_eq!(ALLOCS.with(Cell::get), before, "a query allocated");
    }
}
