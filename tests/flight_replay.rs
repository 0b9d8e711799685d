//! Airload replay: exact at stations and azimuths, periodic across 360 deg, root/tip taper,
//! harmonic truncation, modes.
#![allow(clippy::needless_range_loop)] // three load components indexed alike
mod flight_support;
use flight_support::*;
use rotorsim::flight::replay::UH60A_ROOT_CUTOUT_R_OVER_R;
use rotorsim::flight::{AirloadReplay, FlightRecord, ReplayMode, ReplayOptions, SectionLoads};

fn loads(s: SectionLoads) -> [f64; 3] {
    [s.normal_N_per_m, s.chord_N_per_m, s.moment_N_m_per_m]
}

fn example() -> FlightRecord {
    FlightRecord::read(&example_stem()).unwrap()
}

fn recorded(rec: &FlightRecord, i_rev: usize, i_az: usize, i_st: usize) -> [f64; 3] {
    let i = rec.index(i_rev, i_az, i_st);
    [
        rec.normal_n_per_m()[i],
        rec.chord_n_per_m()[i],
        rec.moment_n_m_per_m()[i],
    ]
}

#[test]
fn exact_at_every_station_and_azimuth() {
    let rec = example();
    let opts = ReplayOptions::default();
    let seq = AirloadReplay::new(&rec, ReplayMode::Sequence, opts).unwrap();
    for (ir, &rev) in rec.revolutions().iter().enumerate() {
        let one = AirloadReplay::new(&rec, ReplayMode::Revolution(rev), opts).unwrap();
        for (ia, &psi) in rec.azimuths_deg().iter().enumerate() {
            for (is, &r) in rec.stations_r_over_r().iter().enumerate() {
                let want = recorded(&rec, ir, ia, is);
                assert_eq!(
                    loads(one.at_azimuth(psi, r)),
                    want,
                    "rev {rev} psi {psi} r {r}"
                );
                // Same azimuth one revolution later: periodic forcing.
                assert_eq!(loads(one.at_azimuth(psi + 360.0 * 7.0, r)), want);
                assert_eq!(loads(seq.at_azimuth(rev as f64 * 360.0 + psi, r)), want);
            }
        }
    }
}

#[test]
fn average_mode_is_the_mean_of_revolutions() {
    let rec = example();
    let avg = AirloadReplay::new(&rec, ReplayMode::Average, ReplayOptions::default()).unwrap();
    let n = rec.revolutions().len();
    for (ia, &psi) in rec.azimuths_deg().iter().enumerate().step_by(17) {
        for (is, &r) in rec.stations_r_over_r().iter().enumerate() {
            let mut m = [0.0; 3];
            for ir in 0..n {
                let v = recorded(&rec, ir, ia, is);
                (0..3).for_each(|q| m[q] += v[q] / n as f64);
            }
            let got = loads(avg.at_azimuth(psi, r));
            for q in 0..3 {
                approx::assert_relative_eq!(got[q], m[q], max_relative = 1e-12, epsilon = 1e-9);
            }
        }
    }
}

#[test]
fn periodic_and_continuous_across_360() {
    let rec = example();
    let rp = AirloadReplay::new(&rec, ReplayMode::Revolution(2), ReplayOptions::default()).unwrap();
    let az = rec.azimuths_deg();
    let last = az[az.len() - 1];
    let r = 0.775;
    let is = rec
        .stations_r_over_r()
        .iter()
        .position(|&s| s == r)
        .unwrap();
    let (a, b) = (
        recorded(&rec, 2, az.len() - 1, is),
        recorded(&rec, 2, 0, is),
    );
    // Midway between the last azimuth and 360 (= azimuth 0): the mean of the two samples.
    let mid = loads(rp.at_azimuth(0.5 * (last + 360.0), r));
    for q in 0..3 {
        approx::assert_relative_eq!(mid[q], 0.5 * (a[q] + b[q]), max_relative = 1e-12);
    }
    // Continuity at 360: approaching from below tends to the value at 0.
    let below = loads(rp.at_azimuth(360.0 - 1e-9, r));
    for q in 0..3 {
        assert!(
            (below[q] - b[q]).abs() <= 1e-6 * (1.0 + b[q].abs()),
            "{below:?} {b:?}"
        );
    }
    // Negative azimuths and times wrap too.
    assert_eq!(
        loads(rp.at_azimuth(-360.0 + az[3], r)),
        recorded(&rec, 2, 3, is)
    );
    // Sequence: the whole record repeats after its last revolution.
    let seq = AirloadReplay::new(&rec, ReplayMode::Sequence, ReplayOptions::default()).unwrap();
    assert_eq!(
        loads(seq.at_azimuth(5.0 * 360.0 + az[9], r)),
        recorded(&rec, 0, 9, is)
    );
    approx::assert_relative_eq!(
        seq.period_s(),
        5.0 * 2.0 * std::f64::consts::PI / 27.0,
        max_relative = 1e-14
    );
}

#[test]
fn time_queries_follow_the_record_clock() {
    let rec = example();
    let seq = AirloadReplay::new(&rec, ReplayMode::Sequence, ReplayOptions::default()).unwrap();
    let radius = rec.meta.radius_m;
    for (ir, &rev) in rec.revolutions().iter().enumerate() {
        for ia in [0, 31, 200] {
            let psi = rec.azimuths_deg()[ia];
            let t = rec.time_s(rev, psi);
            let got = loads(seq.section_loads(t, 0.55 * radius));
            let want = recorded(&rec, ir, ia, 2);
            for q in 0..3 {
                // t * Omega recovers psi to rounding, which moves the value by less than this.
                assert!(
                    (got[q] - want[q]).abs() <= 1e-9 * (1.0 + want[q].abs()),
                    "{got:?} {want:?}"
                );
            }
        }
    }
}

#[test]
fn spanwise_linear_between_stations_and_taper_at_root_and_tip() {
    let rec = example();
    let rp = AirloadReplay::new(&rec, ReplayMode::Revolution(0), ReplayOptions::default()).unwrap();
    let st = rec.stations_r_over_r();
    let psi = rec.azimuths_deg()[40];
    let v = |is: usize| recorded(&rec, 0, 40, is);
    // Between stations: linear.
    let x = 0.25 * st[3] + 0.75 * st[4];
    let got = loads(rp.at_azimuth(psi, x));
    for q in 0..3 {
        approx::assert_relative_eq!(
            got[q],
            0.25 * v(3)[q] + 0.75 * v(4)[q],
            max_relative = 1e-12
        );
    }
    // Root: zero at the cut-out, half the first station's value midway, zero inboard.
    let rc = UH60A_ROOT_CUTOUT_R_OVER_R;
    assert_eq!(loads(rp.at_azimuth(psi, rc)), [0.0; 3]);
    assert_eq!(loads(rp.at_azimuth(psi, 0.5 * rc)), [0.0; 3]);
    let mid = loads(rp.at_azimuth(psi, 0.5 * (rc + st[0])));
    for q in 0..3 {
        approx::assert_relative_eq!(mid[q], 0.5 * v(0)[q], max_relative = 1e-12);
    }
    // Tip: zero at r/R = 1 and beyond, half the last station's value midway.
    assert_eq!(loads(rp.at_azimuth(psi, 1.0)), [0.0; 3]);
    assert_eq!(loads(rp.at_azimuth(psi, 1.2)), [0.0; 3]);
    let mid = loads(rp.at_azimuth(psi, 0.5 * (st[8] + 1.0)));
    for q in 0..3 {
        approx::assert_relative_eq!(mid[q], 0.5 * v(8)[q], max_relative = 1e-12);
    }
    // A chosen cut-out is honoured.
    let rp2 = AirloadReplay::new(
        &rec,
        ReplayMode::Revolution(0),
        ReplayOptions {
            root_cutout_r_over_r: Some(0.2),
            ..Default::default()
        },
    )
    .unwrap();
    assert_eq!(rp2.nodes_r_over_r()[0], 0.2);
    assert_eq!(loads(rp2.at_azimuth(psi, 0.2)), [0.0; 3]);
}

#[test]
fn harmonic_truncation_is_exact_for_band_limited_loads_and_filters_the_rest() {
    // Loads with harmonics 0..3 plus a 6/rev component, 32 azimuths.
    let f = |q: usize, p: f64, s: f64, with6: bool| {
        let p = p.to_radians();
        (q as f64 + 1.0)
            * s
            * (100.0 + 30.0 * p.cos() - 20.0 * (2.0 * p).sin() + 5.0 * (3.0 * p).cos())
            + if with6 { 7.0 * (6.0 * p).sin() } else { 0.0 }
    };
    let rec = record(&[0, 1], 32, &[0.3, 0.7], |q, _, p, s| f(q, p, s, true));
    let h3 = AirloadReplay::new(
        &rec,
        ReplayMode::Average,
        ReplayOptions {
            harmonics: Some(3),
            ..Default::default()
        },
    )
    .unwrap();
    let h8 = AirloadReplay::new(
        &rec,
        ReplayMode::Average,
        ReplayOptions {
            harmonics: Some(8),
            ..Default::default()
        },
    )
    .unwrap();
    for k in 0..50 {
        let psi = k as f64 * 7.3 - 20.0;
        for s in [0.3, 0.7] {
            let a = loads(h3.at_azimuth(psi, s));
            let b = loads(h8.at_azimuth(psi, s));
            for q in 0..3 {
                approx::assert_relative_eq!(
                    a[q],
                    f(q, psi, s, false),
                    max_relative = 1e-12,
                    epsilon = 1e-9
                );
                approx::assert_relative_eq!(
                    b[q],
                    f(q, psi, s, true),
                    max_relative = 1e-12,
                    epsilon = 1e-9
                );
            }
        }
    }
    // Too many harmonics for the grid, or a sequence: refused with the reason.
    let e = AirloadReplay::new(
        &rec,
        ReplayMode::Average,
        ReplayOptions {
            harmonics: Some(16),
            ..Default::default()
        },
    )
    .unwrap_err()
    .to_string();
    assert!(e.contains("more than 32 azimuths"), "{e}");
    let e = AirloadReplay::new(
        &rec,
        ReplayMode::Sequence,
        ReplayOptions {
            harmonics: Some(2),
            ..Default::default()
        },
    )
    .unwrap_err()
    .to_string();
    assert!(e.contains("periodic modes"), "{e}");
}

#[test]
fn modes_report_missing_revolutions() {
    let rec = record(&[0, 1, 3], 8, &[0.5], |_, r, p, _| r as f64 + p);
    assert_eq!(rec.missing_revolutions(), vec![2]);
    let e = AirloadReplay::new(&rec, ReplayMode::Sequence, ReplayOptions::default())
        .unwrap_err()
        .to_string();
    assert!(e.contains("missing revolution(s) 2"), "{e}");
    let e = AirloadReplay::new(&rec, ReplayMode::Revolution(2), ReplayOptions::default())
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("revolution 2 is not in the record") && e.contains("0, 1, 3"),
        "{e}"
    );
    assert!(AirloadReplay::new(&rec, ReplayMode::Revolution(3), ReplayOptions::default()).is_ok());
}

#[test]
fn provider_is_shareable_across_threads() {
    fn send_sync<T: Send + Sync>() {}
    send_sync::<AirloadReplay>();
    let rec = example();
    let rp = std::sync::Arc::new(
        AirloadReplay::new(&rec, ReplayMode::Average, ReplayOptions::default()).unwrap(),
    );
    let h: Vec<_> = (0..2)
        .map(|k| {
            let rp = rp.clone();
            std::thread::spawn(move || rp.section_loads(0.01 * k as f64, 6.0).normal_N_per_m)
        })
        .collect();
    for t in h {
        assert!(t.join().unwrap().is_finite());
    }
}

#[test]
fn damper_channel_revolution_and_average() {
    let rec = example();
    let r1 = rec.damper_revolution(1).unwrap();
    assert_eq!(r1.azimuth_deg.len(), 256);
    assert_eq!(r1.force_N[0], rec.damper()[256].force_N);
    let avg = rec.damper_average().unwrap();
    let mean0: f64 = (0..5).map(|k| rec.damper()[256 * k].force_N).sum::<f64>() / 5.0;
    approx::assert_relative_eq!(avg.force_N[0], mean0, max_relative = 1e-14);
    assert!(avg.stroke_m.is_some());
    assert!(rec.damper_revolution(9).is_err());
}

#[test]
fn non_uniform_azimuth_grid_is_exact_at_samples_and_linear_between() {
    let az = vec![0.0, 10.0, 50.0, 200.0, 300.0];
    let st = vec![0.4, 0.8];
    let f = |p: f64, s: f64| 1000.0 * s + p * p * 0.01;
    let mut v = Vec::new();
    for rev in 0..2 {
        for &p in &az {
            for &s in &st {
                v.push(f(p, s) + rev as f64);
            }
        }
    }
    let base = record(&[0, 1], 5, &st, |_, _, _, _| 0.0);
    let rec = FlightRecord::new(
        base.meta.clone(),
        st.clone(),
        vec![0, 1],
        az.clone(),
        v.clone(),
        v.clone(),
        v,
        base.damper().to_vec(),
    )
    .unwrap();
    let rp = AirloadReplay::new(&rec, ReplayMode::Revolution(1), ReplayOptions::default()).unwrap();
    for &p in &az {
        for &s in &st {
            assert_eq!(rp.at_azimuth(p, s).normal_N_per_m, f(p, s) + 1.0);
        }
    }
    // Between 300 and 360 (= 0): linear in the wrapped interval.
    let got = rp.at_azimuth(330.0, 0.4).chord_N_per_m;
    approx::assert_relative_eq!(
        got,
        0.5 * (f(300.0, 0.4) + f(0.0, 0.4)) + 1.0,
        max_relative = 1e-14
    );
    let got = rp.at_azimuth(125.0, 0.8).moment_N_m_per_m;
    approx::assert_relative_eq!(
        got,
        0.5 * (f(50.0, 0.8) + f(200.0, 0.8)) + 1.0,
        max_relative = 1e-14
    );
    let e = AirloadReplay::new(
        &rec,
        ReplayMode::Average,
        ReplayOptions {
            harmonics: Some(1),
            ..Default::default()
        },
    )
    .unwrap_err()
    .to_string();
    assert!(e.contains("uniform azimuth grid"), "{e}");
}
