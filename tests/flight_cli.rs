//! `rotorsim convert` both ways and `rotorsim inspect` on the example record.
mod flight_support;
use flight_support::*;
use rotorsim::cli::convert::{run as convert, ConvertArgs};
use rotorsim::cli::inspect::summary;
use rotorsim::flight::FlightRecord;

#[test]
fn convert_csv_to_mcap_and_back_is_lossless() {
    let dir = tmpdir("cli");
    convert(ConvertArgs {
        input: example_stem(),
        output: dir.join("c.mcap"),
    })
    .unwrap();
    convert(ConvertArgs {
        input: dir.join("c.mcap"),
        output: dir.join("back"),
    })
    .unwrap();
    // Output named by one of the triple's files works too.
    convert(ConvertArgs {
        input: dir.join("c.mcap"),
        output: dir.join("again.meta.json"),
    })
    .unwrap();
    let orig = FlightRecord::read(&example_stem()).unwrap();
    assert_same_bits(&orig, &FlightRecord::read(&dir.join("c.mcap")).unwrap());
    assert_same_bits(&orig, &FlightRecord::read(&dir.join("back")).unwrap());
    assert_same_bits(&orig, &FlightRecord::read(&dir.join("again")).unwrap());
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn inspect_shows_what_the_record_holds_and_the_synthetic_label() {
    let rec = FlightRecord::read(&example_stem()).unwrap();
    let s = summary(&rec, "c8534like");
    for want in [
        "SYNTHETIC (not flight-test data)",
        "revolutions: 5 (0..=4)",
        "azimuths per revolution: 256",
        "step 1.40625 deg",
        "stations r/R (9)",
        "normal_force_N_per_m",
        "damper_force_N, damper_stroke_m",
        "samples: 1280 (5 revolutions x 256 azimuths)",
        "number_of_blades: 4",
        "rotor speed: 27 rad/s",
    ] {
        assert!(s.contains(want), "missing `{want}` in\n{s}");
    }
    // A measured record is labelled so, and gaps are shown.
    let mut rec = record(&[0, 2], 4, &[0.5], |_, _, _, _| 1.0);
    rec.meta.synthetic = false;
    let s = summary(&rec, "m");
    assert!(
        s.contains("measured (flight-test data)") && !s.contains("SYNTHETIC"),
        "{s}"
    );
    assert!(s.contains("GAPS: missing revolution(s) [1]"), "{s}");
}
