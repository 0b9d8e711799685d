//! The optional measured blade motion of a flight record (STEM.motion.csv, MCAP `/rotor/motion`):
//! reading the shipped example, the Fourier series of `BladeMotion::periodic`, bad motion files
//! (each error names the file, the line and the column), records without motion, round trips.
mod flight_support;
use flight_support::*;
use rotorsim::flight::{BladeMotion, FlightError, FlightRecord};
use std::f64::consts::PI;
use std::path::{Path, PathBuf};

mod alloc_support;
use alloc_support::{allocations, assert_counting};

/// (revolution, azimuth_deg, flap_deg, lag_deg, pitch_deg) rows parsed from the CSV text here,
/// independently of the reader.
fn motion_rows(text: &str) -> Vec<[f64; 5]> {
    let mut lines = text.lines();
    assert_eq!(
        lines.next().unwrap().trim(),
        "revolution,azimuth_deg,flap_deg,lag_deg,pitch_deg"
    );
    lines
        .filter(|l| !l.trim().is_empty())
        .map(|l| {
            let v: Vec<f64> = l.split(',').map(|x| x.trim().parse().unwrap()).collect();
            [v[0], v[1], v[2], v[3], v[4]]
        })
        .collect()
}

#[test]
fn example_record_motion_matches_the_csv_text() {
    let stem = example_stem();
    let rec = FlightRecord::read(&stem).unwrap();
    let mo = rec
        .motion
        .as_ref()
        .expect("the example has STEM.motion.csv");
    assert_eq!(mo.revolutions(), rec.revolutions());
    assert_eq!(mo.azimuths_deg(), rec.azimuths_deg());

    // Mean and 1/rev amplitude of flap straight from the text: over all rows (every revolution
    // has the same uniform grid, so this is the DFT of the revolution average).
    let text = std::fs::read_to_string(stem.with_extension("motion.csv")).unwrap();
    let rows = motion_rows(&text);
    assert_eq!(rows.len(), 5 * 256);
    let n = rows.len() as f64;
    let p = rec.meta.rotor_speed_rad_s;
    let per = mo.periodic(1, p).unwrap();
    for (ch, col) in [(0usize, 2usize), (1, 3), (2, 4)] {
        let mean = rows.iter().map(|r| r[col]).sum::<f64>() / n;
        let a1 = 2.0 / n
            * rows
                .iter()
                .map(|r| r[col] * r[1].to_radians().cos())
                .sum::<f64>();
        let b1 = 2.0 / n
            * rows
                .iter()
                .map(|r| r[col] * r[1].to_radians().sin())
                .sum::<f64>();
        let amp = a1.hypot(b1);
        let got_mean = per.mean_rad()[ch].to_degrees();
        let got_amp = per.amplitude_rad(1).unwrap()[ch].to_degrees();
        assert!(
            (got_mean - mean).abs() < 1e-9,
            "channel {ch}: mean {got_mean} vs {mean}"
        );
        assert!(
            (got_amp - amp).abs() < 1e-9,
            "channel {ch}: 1/rev {got_amp} vs {amp}"
        );
    }
    // The flap of the example: a coning of a few degrees and a small but real 1/rev.
    let flap_mean = per.mean_rad()[0].to_degrees();
    let flap_1 = per.amplitude_rad(1).unwrap()[0].to_degrees();
    assert!((1.0..5.0).contains(&flap_mean), "{flap_mean}");
    assert!((0.05..1.0).contains(&flap_1), "{flap_1}");
    // First sample as written.
    let i = mo.index(0, 1);
    assert_eq!(mo.flap_deg()[i], rows[1][2]);
    assert_eq!(mo.lag_deg()[i], rows[1][3]);
    assert_eq!(mo.pitch_deg()[i], rows[1][4]);

    // The files of the stem include the motion, and the motion file names the stem.
    let files = FlightRecord::files(&stem).unwrap();
    assert!(
        files.iter().any(|f| f.ends_with("c8534like.motion.csv")),
        "{files:?}"
    );
    assert_eq!(files.len(), 4);
    let via = FlightRecord::read(&stem.with_extension("motion.csv")).unwrap();
    assert_eq!(via, rec);
    // And the shipped MCAP carries the same motion, bit for bit.
    let mcap = FlightRecord::read(&stem.with_extension("mcap")).unwrap();
    assert_same_bits(&rec, &mcap);
}

#[test]
fn inspect_lists_the_motion_channels() {
    let rec = FlightRecord::read(&example_stem()).unwrap();
    let s = rotorsim::cli::inspect::summary(&rec, "c8534like");
    let line = s
        .lines()
        .find(|l| l.contains("motion (blade 1)"))
        .unwrap_or_else(|| panic!("no motion line in\n{s}"));
    for w in [
        "5 revolutions",
        "256 azimuths",
        "flap",
        "lag",
        "pitch",
        "mean",
        "1/rev",
    ] {
        assert!(line.contains(w), "{w} not in {line}");
    }
    let flap_mean = rec
        .motion
        .as_ref()
        .unwrap()
        .periodic(1, 27.0)
        .unwrap()
        .mean_rad()[0];
    assert!(
        line.contains(&format!("flap {:.4} deg mean", flap_mean.to_degrees())),
        "{line}"
    );
    assert!(s.contains("SYNTHETIC"), "{s}");
    // A record without motion prints no motion line.
    let plain = record(&[0, 1], 8, &[0.5, 0.9], |_, _, _, _| 1.0);
    assert!(!rotorsim::cli::inspect::summary(&plain, "x").contains("motion"));
}

/// A band-limited motion with every harmonic up to `h` (deg), its derivative d/dpsi (deg/rad).
fn band_limited(h: usize, ch: usize, psi: f64) -> (f64, f64) {
    let mut x = 1.5 + ch as f64;
    let mut d = 0.0;
    for k in 1..=h {
        let kf = k as f64;
        let (a, b) = (
            0.7 / kf + 0.1 * ch as f64,
            -0.4 / (kf * kf) + 0.05 * kf - 0.2 * ch as f64,
        );
        x += a * (kf * psi).cos() + b * (kf * psi).sin();
        d += kf * (-a * (kf * psi).sin() + b * (kf * psi).cos());
    }
    (x, d)
}

fn synthetic_motion(n_az: usize, h: usize, revs: &[u32]) -> BladeMotion {
    let az: Vec<f64> = (0..n_az).map(|j| j as f64 * 360.0 / n_az as f64).collect();
    let mut v = [Vec::new(), Vec::new(), Vec::new()];
    for _ in revs {
        for &p in &az {
            for (ch, vc) in v.iter_mut().enumerate() {
                vc.push(band_limited(h, ch, p.to_radians()).0);
            }
        }
    }
    let [f, l, p] = v;
    BladeMotion::new(revs.to_vec(), az, f, l, p).unwrap()
}

#[test]
fn fourier_series_is_exact_on_band_limited_motion() {
    let omega = 27.0;
    for n_az in [16usize, 17, 64] {
        let h = n_az / 2 - 1;
        let mo = synthetic_motion(n_az, h, &[0, 1, 2]);
        assert_eq!(mo.max_harmonics(), h);
        let per = mo.periodic(h, omega).unwrap();
        assert_eq!(per.harmonics(), h);
        let mut worst = (0.0f64, 0.0f64);
        for &p in mo.azimuths_deg() {
            let psi = p.to_radians();
            let s = per.at(psi);
            // The series is the band-limited function itself: exact at the samples and between.
            for q in [psi, psi + 0.37 * 2.0 * PI / n_az as f64, psi - 4.0 * PI] {
                let s2 = per.at(q);
                let got = [
                    (s2.flap_rad, s2.flap_rate_rad_s),
                    (s2.lag_rad, s2.lag_rate_rad_s),
                    (s2.pitch_rad, s2.pitch_rate_rad_s),
                ];
                for (ch, (x, xd)) in got.into_iter().enumerate() {
                    let (e, ed) = band_limited(h, ch, q);
                    worst.0 = worst.0.max((x - e.to_radians()).abs());
                    worst.1 = worst.1.max((xd - omega * ed.to_radians()).abs());
                }
            }
            assert_eq!(s, per.at(psi));
        }
        assert!(
            worst.0 < 1e-12 && worst.1 < 1e-12,
            "n_az {n_az}: worst value error {:e} rad, rate error {:e} rad/s",
            worst.0,
            worst.1
        );
    }
    // Truncated: the mean and the kept harmonics are those of the full series.
    let mo = synthetic_motion(32, 15, &[0]);
    let full = mo.periodic(15, omega).unwrap();
    let cut = mo.periodic(2, omega).unwrap();
    assert_eq!(cut.harmonics(), 2);
    assert_eq!(cut.mean_rad(), full.mean_rad());
    assert_eq!(cut.coefficients_rad(2), full.coefficients_rad(2));
    assert_eq!(cut.coefficients_rad(3), None);
    let (a1, b1) = cut.coefficients_rad(1).unwrap();
    assert!((a1[0] - 0.7f64.to_radians()).abs() < 1e-14, "{a1:?}");
    assert!(
        (b1[0] - (-0.4f64 + 0.05).to_radians()).abs() < 1e-14,
        "{b1:?}"
    );
    // Harmonics 0: the mean, rates zero.
    let s = mo.periodic(0, omega).unwrap().at(1.0);
    assert_eq!(s.flap_rad, full.mean_rad()[0]);
    assert_eq!(s.flap_rate_rad_s, 0.0);
}

#[test]
fn periodic_refuses_non_uniform_grids_and_too_many_harmonics() {
    let mo = synthetic_motion(16, 7, &[0]);
    let e = mo.periodic(8, 27.0).unwrap_err().to_string();
    assert!(e.contains("8 harmonics") && e.contains("at most 7"), "{e}");
    let mut az = mo.azimuths_deg().to_vec();
    az[3] += 1.0;
    let skew = BladeMotion::new(
        vec![0],
        az,
        mo.flap_deg().to_vec(),
        mo.lag_deg().to_vec(),
        mo.pitch_deg().to_vec(),
    )
    .unwrap();
    let e = skew.periodic(2, 27.0).unwrap_err().to_string();
    assert!(e.contains("uniform"), "{e}");
}

#[test]
fn periodic_at_does_not_allocate() {
    let rec = FlightRecord::read(&example_stem()).unwrap();
    let per = rec.motion.as_ref().unwrap().periodic(12, 27.0).unwrap();
    assert_counting();
    let before = allocations();
    let mut acc = 0.0;
    for k in 0..5000 {
        let s = per.at(k as f64 * 0.01);
        acc += s.flap_rad + s.lag_rate_rad_s + s.pitch_rad;
    }
    assert_eq!(allocations(), before, "PeriodicMotion::at allocated");
    assert!(acc.is_finite());
}

#[test]
fn record_without_motion_reads_as_before() {
    let dir = tmpdir("motion-none");
    for suf in [".meta.json", ".airloads.csv", ".damper.csv"] {
        std::fs::copy(
            example_stem().with_extension(&suf[1..]),
            dir.join(format!("r{suf}")),
        )
        .unwrap();
    }
    let rec = FlightRecord::read(&dir.join("r")).unwrap();
    assert!(rec.motion.is_none());
    assert_eq!(FlightRecord::files(&dir.join("r")).unwrap().len(), 3);
    // Everything else is the example's.
    let full = FlightRecord::read(&example_stem()).unwrap();
    assert_same_bits(&rec, &full.clone().with_motion(None).unwrap());
    // Written back: three files, no motion; MCAP without a motion channel.
    rec.write_csv(&dir.join("w")).unwrap();
    assert!(!dir.join("w.motion.csv").exists());
    rec.write_mcap(&dir.join("w.mcap")).unwrap();
    let m = FlightRecord::read(&dir.join("w.mcap")).unwrap();
    assert!(m.motion.is_none());
    let bytes = std::fs::read(dir.join("w.mcap")).unwrap();
    assert!(!bytes.windows(13).any(|w| w == b"/rotor/motion"));
    // Writing a record without motion over a stem that had one removes the stale file.
    full.write_csv(&dir.join("w")).unwrap();
    assert!(dir.join("w.motion.csv").exists());
    rec.write_csv(&dir.join("w")).unwrap();
    assert!(FlightRecord::read(&dir.join("w")).unwrap().motion.is_none());
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn motion_round_trips_csv_mcap_csv_bit_for_bit() {
    let dir = tmpdir("motion-rt");
    let a = FlightRecord::read(&example_stem()).unwrap();
    a.write_mcap(&dir.join("x.mcap")).unwrap();
    let b = FlightRecord::read(&dir.join("x.mcap")).unwrap();
    b.write_csv(&dir.join("y")).unwrap();
    let c = FlightRecord::read(&dir.join("y")).unwrap();
    assert_same_bits(&a, &b);
    assert_same_bits(&a, &c);
    assert_eq!(a, c);
    // A synthetic motion with awkward values, on a small record.
    let rec = record(&[0, 1, 3], 8, &[0.5, 0.9], |q, r, p, s| {
        q as f64 + r as f64 * p * s
    });
    let mo = synthetic_motion(8, 3, &[1, 3]);
    let bits = |k: usize| f64::from_bits(0x3ff0_0000_0000_0001 + k as u64) * 1e-7;
    let flap: Vec<f64> = (0..mo.flap_deg().len()).map(bits).collect();
    let mo = BladeMotion::new(
        mo.revolutions().to_vec(),
        mo.azimuths_deg().to_vec(),
        flap,
        mo.lag_deg().to_vec(),
        mo.pitch_deg().to_vec(),
    )
    .unwrap();
    let rec = rec.with_motion(Some(mo)).unwrap();
    rec.write_csv(&dir.join("s")).unwrap();
    let s = FlightRecord::read(&dir.join("s")).unwrap();
    s.write_mcap(&dir.join("s.mcap")).unwrap();
    let t = FlightRecord::read(&dir.join("s.mcap")).unwrap();
    assert_same_bits(&rec, &s);
    assert_same_bits(&rec, &t);
    // with_motion refuses a motion on another grid.
    let other = synthetic_motion(16, 3, &[0]);
    let e = rec
        .clone()
        .with_motion(Some(other))
        .unwrap_err()
        .to_string();
    assert!(e.contains("azimuth grid"), "{e}");
    std::fs::remove_dir_all(&dir).unwrap();
}

/// Copies the example triple to `dir/NAME` and writes `motion` as `dir/NAME.motion.csv`.
fn stem_with_motion(dir: &Path, name: &str, motion: &str) -> PathBuf {
    for suf in [".meta.json", ".airloads.csv", ".damper.csv"] {
        std::fs::copy(
            example_stem().with_extension(&suf[1..]),
            dir.join(format!("{name}{suf}")),
        )
        .unwrap();
    }
    std::fs::write(dir.join(format!("{name}.motion.csv")), motion).unwrap();
    dir.join(name)
}

#[test]
fn bad_motion_files_name_file_line_and_column() {
    let dir = tmpdir("motion-bad");
    let good = std::fs::read_to_string(example_stem().with_extension("motion.csv")).unwrap();
    let lines: Vec<&str> = good.lines().collect();
    let join = |v: &[&str]| v.join("\n") + "\n";
    let edit_line = |k: usize, to: &str| {
        let mut v = lines.clone();
        v[k - 1] = to;
        join(&v)
    };
    let delete_line = |k: usize| {
        let mut v = lines.clone();
        v.remove(k - 1);
        join(&v)
    };
    // Line 3 is "0,1.406250,2.335330,4.243541,13.070834"; line 257 the last of revolution 0.
    assert_eq!(lines[2], "0,1.406250,2.335330,4.243541,13.070834");
    assert!(lines[256].starts_with("0,358.593750,"));
    let dup3 = {
        let mut v = lines.clone();
        v.insert(3, lines[2]);
        join(&v)
    };
    let swap = {
        let mut v = lines.clone();
        v.swap(2, 3);
        join(&v)
    };
    let last_line = format!("line {}", lines.len() - 1);
    let cut_expect = [
        last_line.as_str(),
        "`revolution`",
        "revolution 4 has 255 of the 256",
        "at the end",
    ];
    let cases: Vec<(&str, String, &[&str])> = vec![
        (
            "not a number",
            edit_line(3, "0,1.406250,x2.3,4.243541,13.070834"),
            &["line 3", "`flap_deg`", "expected a number", "x2.3"],
        ),
        (
            "not finite",
            edit_line(3, "0,1.406250,2.335330,NaN,13.070834"),
            &["line 3", "`lag_deg`", "finite"],
        ),
        (
            "wrong header (unit)",
            edit_line(1, "revolution,azimuth_deg,flap_deg,lag_deg,pitch_rad"),
            &[
                "line 1",
                "`pitch_rad`",
                "revolution,azimuth_deg,flap_deg,lag_deg,pitch_deg",
            ],
        ),
        (
            "header lacks a column",
            edit_line(1, "revolution,azimuth_deg,flap_deg,lag_deg"),
            &["line 1", "`pitch_deg`", "missing"],
        ),
        (
            "row lacks a column",
            edit_line(3, "0,1.406250,2.335330,4.243541"),
            &["line 3", "4 fields, expected 5", "`pitch_deg` missing"],
        ),
        (
            "row has a column too many",
            edit_line(3, "0,1.406250,2.335330,4.243541,13.070834,1"),
            &["line 3", "6 fields, expected 5"],
        ),
        (
            "revolution not a whole number",
            edit_line(3, "0.5,1.406250,2.335330,4.243541,13.070834"),
            &["line 3", "`revolution`", "whole number"],
        ),
        (
            "azimuth off the airloads' grid",
            edit_line(3, "0,1.5,2.335330,4.243541,13.070834"),
            &[
                "line 3",
                "`azimuth_deg`",
                "1.5 deg is not on the airloads' azimuth grid",
                "256 azimuths",
            ],
        ),
        (
            "azimuth out of range",
            edit_line(3, "0,361,2.335330,4.243541,13.070834"),
            &["line 3", "`azimuth_deg`", "[0, 360)"],
        ),
        (
            "azimuth repeated (not increasing)",
            dup3,
            &[
                "line 4",
                "`azimuth_deg`",
                "does not increase within revolution 0",
            ],
        ),
        (
            "azimuths swapped (not increasing)",
            swap,
            &["line 3", "`azimuth_deg`", "azimuth 1.40625 deg missing"],
        ),
        (
            "revolution missing an azimuth (middle)",
            delete_line(10),
            &[
                "line 10",
                "`azimuth_deg`",
                "revolution 0: azimuth 11.25 deg missing",
            ],
        ),
        (
            "revolution missing its last azimuth",
            delete_line(257),
            &[
                "line 257",
                "`revolution`",
                "revolution 0 has 255 of the 256 azimuths",
                "358.59375 deg",
            ],
        ),
        (
            "last revolution cut short",
            delete_line(lines.len()),
            &cut_expect,
        ),
        (
            "revolutions out of order",
            {
                let mut v = lines.clone();
                let r1: Vec<&str> = v.drain(257..513).collect();
                v.splice(1..1, r1);
                join(&v)
            },
            &[
                "line 258",
                "`revolution`",
                "revolution 0 after revolution 1",
            ],
        ),
        (
            "no rows",
            edit_line(1, "revolution,azimuth_deg,flap_deg,lag_deg,pitch_deg")
                .lines()
                .next()
                .unwrap()
                .to_string()
                + "\n",
            &["line 1", "no motion rows"],
        ),
    ];
    let mut failures = Vec::new();
    for (k, (name, text, expect)) in cases.iter().enumerate() {
        let stem = stem_with_motion(&dir, &format!("c{k}"), text);
        let file = format!("c{k}.motion.csv");
        let msg = match FlightRecord::read(&stem) {
            Ok(_) => {
                failures.push(format!("{name}: read without error"));
                continue;
            }
            Err(e @ FlightError::Line { .. }) => e.to_string(),
            Err(e) => {
                failures.push(format!("{name}: not a line error: {e}"));
                continue;
            }
        };
        for w in std::iter::once(&file.as_str()).chain(expect.iter()) {
            if !msg.contains(w) {
                failures.push(format!("{name}: `{w}` not in: {msg}"));
            }
        }
    }
    // MCAP: a motion message off the grid names the channel and message index.
    let rec = FlightRecord::read(&example_stem()).unwrap();
    let mut bad = rec.clone();
    let mo = rec.motion.as_ref().unwrap();
    let mut az = mo.azimuths_deg().to_vec();
    az[5] += 0.5;
    bad.motion = Some(
        BladeMotion::new(
            mo.revolutions().to_vec(),
            az,
            mo.flap_deg().to_vec(),
            mo.lag_deg().to_vec(),
            mo.pitch_deg().to_vec(),
        )
        .unwrap(),
    );
    bad.write_mcap(&dir.join("bad.mcap")).unwrap();
    let e = FlightRecord::read(&dir.join("bad.mcap"))
        .unwrap_err()
        .to_string();
    for w in [
        "bad.mcap",
        "/rotor/motion",
        "message 5",
        "azimuth_deg",
        "not on the airloads' azimuth grid",
    ] {
        if !e.contains(w) {
            failures.push(format!("mcap: `{w}` not in: {e}"));
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
    std::fs::remove_dir_all(&dir).unwrap();
}
