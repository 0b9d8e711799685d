//! Flight records: both forms of the example load identically; CSV -> MCAP -> CSV is lossless.
mod flight_support;
use flight_support::*;
use proptest::prelude::*;
use rotorsim::flight::FlightRecord;

#[test]
fn example_record_loads_identically_from_csv_and_mcap() {
    let stem = example_stem();
    let csv = FlightRecord::read(&stem).unwrap();
    let mcap = FlightRecord::read(&stem.with_extension("mcap")).unwrap();
    assert_same_bits(&csv, &mcap);
    assert!(csv.meta.synthetic, "the example is labelled synthetic");
    assert_eq!(csv.revolutions(), &[0, 1, 2, 3, 4]);
    assert_eq!(csv.azimuths_deg().len(), 256);
    assert_eq!(csv.stations_r_over_r().len(), 9);
    assert_eq!(csv.damper().len(), 5 * 256);
    // Every metadata key, known or not, survives.
    for key in [
        "number_of_blades",
        "damper_deck",
        "lag_spring_N_m_per_rad",
        "chord_m",
    ] {
        assert_eq!(csv.meta.raw.get(key), mcap.meta.raw.get(key), "{key}");
        assert!(mcap.meta.raw.contains_key(key), "{key}");
    }
    // Any one of the three CSV files names the triple.
    let via_damper = FlightRecord::read(&stem.with_file_name("c8534like.damper.csv")).unwrap();
    assert_same_bits(&csv, &via_damper);
}

#[test]
fn example_csv_to_mcap_to_csv_is_bit_for_bit() {
    let dir = tmpdir("rt");
    let a = FlightRecord::read(&example_stem()).unwrap();
    a.write_mcap(&dir.join("x.mcap")).unwrap();
    let b = FlightRecord::read(&dir.join("x.mcap")).unwrap();
    b.write_csv(&dir.join("y")).unwrap();
    let c = FlightRecord::read(&dir.join("y")).unwrap();
    assert_same_bits(&a, &b);
    assert_same_bits(&a, &c);
    // And the regenerated CSV files are byte-identical to a direct CSV write of the original.
    a.write_csv(&dir.join("z")).unwrap();
    for suf in [".airloads.csv", ".damper.csv", ".meta.json"] {
        let y = std::fs::read(dir.join(format!("y{suf}"))).unwrap();
        let z = std::fs::read(dir.join(format!("z{suf}"))).unwrap();
        assert!(y == z, "{suf} differs");
    }
    // The original text values parse to the same numbers as the regenerated file's.
    let orig = std::fs::read_to_string(example_stem().with_extension("airloads.csv")).unwrap();
    let regen = std::fs::read_to_string(dir.join("y.airloads.csv")).unwrap();
    for (lo, lr) in orig.lines().zip(regen.lines()).skip(1).step_by(97) {
        for (x, y) in lo.split(',').zip(lr.split(',')) {
            assert_eq!(
                x.parse::<f64>().unwrap().to_bits(),
                y.parse::<f64>().unwrap().to_bits()
            );
        }
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn time_helper_follows_formats() {
    let r = FlightRecord::read(&example_stem()).unwrap();
    // time = (rev * 360 + psi) / Omega[deg/s]; Omega = 27 rad/s.
    let t = r.time_s(2, 90.0);
    approx::assert_relative_eq!(
        t,
        (2.0 * 360.0 + 90.0) / 27.0_f64.to_degrees(),
        max_relative = 1e-15
    );
    approx::assert_relative_eq!(
        r.time_s(1, 0.0),
        2.0 * std::f64::consts::PI / 27.0,
        max_relative = 1e-15
    );
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 48, failure_persistence: None, .. ProptestConfig::default() })]
    /// Arbitrary finite f64 values (any bit pattern, subnormals, huge exponents) survive
    /// CSV -> MCAP -> CSV bit for bit.
    #[test]
    fn arbitrary_values_round_trip_bit_for_bit(
        vals in proptest::collection::vec(any::<u64>(), 3 * 2 * 4 * 3),
        damp in proptest::collection::vec(any::<u64>(), 2 * 4 * 2),
    ) {
        let fin = |b: u64| { let x = f64::from_bits(b); if x.is_finite() { x } else { f64::from_bits(b >> 12) } };
        let base = record(&[0, 1], 4, &[0.3, 0.6, 0.9], |_, _, _, _| 0.0);
        let n = base.normal_n_per_m().len();
        let pick = |q: usize| (0..n).map(|i| fin(vals[q * n + i])).collect::<Vec<_>>();
        let damper = base.damper().iter().enumerate().map(|(i, s)| rotorsim::flight::DamperSample {
            force_N: fin(damp[2 * i]), stroke_m: Some(fin(damp[2 * i + 1])), ..*s
        }).collect();
        let rec = FlightRecord::new(base.meta.clone(), base.stations_r_over_r().to_vec(),
            base.revolutions().to_vec(), base.azimuths_deg().to_vec(), pick(0), pick(1), pick(2), damper).unwrap();
        let dir = tmpdir("prop");
        rec.write_csv(&dir.join("a")).unwrap();
        let a = FlightRecord::read(&dir.join("a")).unwrap();
        a.write_mcap(&dir.join("a.mcap")).unwrap();
        let b = FlightRecord::read(&dir.join("a.mcap")).unwrap();
        b.write_csv(&dir.join("b")).unwrap();
        let c = FlightRecord::read(&dir.join("b")).unwrap();
        assert_same_bits(&rec, &a);
        assert_same_bits(&rec, &b);
        assert_same_bits(&rec, &c);
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
