//! The replay's queries do not allocate (hot loop of the rotor run): counted with a wrapping
//! global allocator in this test binary.
mod flight_support;
use flight_support::*;
use rotorsim::flight::{AirloadReplay, FlightRecord, ReplayMode, ReplayOptions};

mod alloc_support;
use alloc_support::{allocations, assert_counting};

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
    assert_counting();
    for rp in &providers {
        let before = allocations();
        let mut acc = 0.0;
        for k in 0..2000 {
            let t = k as f64 * 7.7e-4 - 0.1;
            let r = 0.5 + (k % 80) as f64 * 0.1;
            let s = rp.section_loads(t, r);
            acc += s.normal_N_per_m + s.chord_N_per_m + s.moment_N_m_per_m;
            acc += rp.at_azimuth(k as f64 * 0.37, 0.9).normal_N_per_m;
        }
        assert!(acc.is_finite());
        assert_eq!(allocations(), before, "a query allocated");
    }
}
