//! Flight records: bad input gives a clear error (file, channel or line, what was expected) and
//! never a panic.
mod flight_support;
use flight_support::*;
use proptest::prelude::*;
use rotorsim::flight::{FlightError, FlightRecord};
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

fn small() -> FlightRecord {
    record(&[0, 1, 2], 8, &[0.3, 0.6, 0.9], |q, r, p, s| {
        (q as f64 + 1.0) * (100.0 * s + (p.to_radians()).sin() + r as f64)
    })
}

/// Writes the small record as CSV and returns its stem.
fn csv_stem(name: &str) -> PathBuf {
    let dir = tmpdir(name);
    let stem = dir.join("rec");
    small().write_csv(&stem).unwrap();
    stem
}

fn edit(path: &Path, f: impl Fn(String) -> String) {
    let s = std::fs::read_to_string(path).unwrap();
    std::fs::write(path, f(s)).unwrap();
}

fn err_of(path: &Path) -> String {
    match FlightRecord::read(path) {
        Ok(_) => panic!("{} was accepted", path.display()),
        Err(e) => e.to_string(),
    }
}

fn air(stem: &Path) -> PathBuf {
    PathBuf::from(format!("{}.airloads.csv", stem.display()))
}

#[test]
fn unknown_unit_names_column_and_accepted_units() {
    let stem = csv_stem("unit");
    edit(&air(&stem), |s| {
        s.replacen("normal_force_N_per_m", "normal_force_kN_per_m", 1)
    });
    let e = err_of(&stem);
    assert!(
        e.contains("airloads.csv") && e.contains("normal_force_kN_per_m"),
        "{e}"
    );
    assert!(
        e.contains("kN_per_m") && e.contains("normal_force_lb_per_in"),
        "{e}"
    );
    assert!(matches!(
        FlightRecord::read(&stem),
        Err(FlightError::UnknownUnit { .. })
    ));
}

#[test]
fn missing_and_unexpected_columns() {
    let stem = csv_stem("cols");
    edit(&air(&stem), |s| {
        s.replacen(",pitching_moment_N_m_per_m", ",foo", 1)
    });
    let e = err_of(&stem);
    assert!(e.contains("line 1") && e.contains("`foo`"), "{e}");
    let stem = csv_stem("cols2");
    let d = PathBuf::from(format!("{}.damper.csv", stem.display()));
    edit(&d, |s| {
        s.lines()
            .map(|l| {
                l.rsplit_once(',')
                    .unwrap()
                    .0
                    .rsplit_once(',')
                    .unwrap()
                    .0
                    .to_string()
                    + "\n"
            })
            .collect()
    });
    let e = err_of(&stem);
    assert!(
        e.contains("damper.csv") && e.contains("missing column `damper_force_N`"),
        "{e}"
    );
}

#[test]
fn nan_and_garbage_values_name_the_line() {
    let stem = csv_stem("nan");
    edit(&air(&stem), |s| {
        let mut l: Vec<String> = s.lines().map(String::from).collect();
        let f: Vec<&str> = l[5].split(',').collect();
        l[5] = format!("{},{},{},NaN,{},{}", f[0], f[1], f[2], f[4], f[5]);
        l.join("\n") + "\n"
    });
    let e = err_of(&stem);
    assert!(
        e.contains("line 6") && e.contains("normal_force_N_per_m") && e.contains("finite"),
        "{e}"
    );
    let stem = csv_stem("garbage");
    edit(&air(&stem), |s| s.replacen("\n0,45,", "\n0,4x5,", 1));
    let e = err_of(&stem);
    assert!(
        e.contains("azimuth_deg") && e.contains("4x5") && e.contains("line"),
        "{e}"
    );
    let stem = csv_stem("short");
    edit(&air(&stem), |s| s.replacen("\n1,0,0.3,", "\n1,0,", 1));
    let e = err_of(&stem);
    assert!(e.contains("fields, expected 6"), "{e}");
}

#[test]
fn duplicate_and_missing_azimuths() {
    let stem = csv_stem("dup");
    edit(&air(&stem), |s| {
        let mut l: Vec<String> = s.lines().map(String::from).collect();
        l.insert(10, l[9].clone());
        l.join("\n") + "\n"
    });
    let e = err_of(&stem);
    assert!(
        e.contains("duplicate") && e.contains("line 10") && e.contains("line 11"),
        "{e}"
    );

    let stem = csv_stem("gap");
    // Drop azimuth 90 deg of revolution 2.
    edit(&air(&stem), |s| {
        s.lines()
            .filter(|l| !l.starts_with("2,90,"))
            .map(|l| l.to_string() + "\n")
            .collect()
    });
    let e = err_of(&stem);
    assert!(
        e.contains("revolution 2") && e.contains("azimuth 90 deg missing"),
        "{e}"
    );

    let stem = csv_stem("outside");
    edit(&air(&stem), |s| s.replacen("\n0,45,", "\n0,360,", 1));
    let e = err_of(&stem);
    assert!(e.contains("outside [0, 360)"), "{e}");

    let stem = csv_stem("dgap");
    let d = PathBuf::from(format!("{}.damper.csv", stem.display()));
    edit(&d, |s| {
        s.lines()
            .filter(|l| !l.starts_with("1,135,"))
            .map(|l| l.to_string() + "\n")
            .collect()
    });
    let e = err_of(&stem);
    assert!(
        e.contains("damper.csv") && e.contains("damper revolution 1") && e.contains("135"),
        "{e}"
    );
}

#[test]
fn metadata_errors_name_the_key() {
    let stem = csv_stem("meta");
    let m = PathBuf::from(format!("{}.meta.json", stem.display()));
    edit(&m, |s| {
        let mut v: serde_json::Value = serde_json::from_str(&s).unwrap();
        v.as_object_mut().unwrap().remove("synthetic");
        v.to_string()
    });
    let e = err_of(&stem);
    assert!(e.contains("meta.json") && e.contains("`synthetic`"), "{e}");
    let stem = csv_stem("meta2");
    let m = PathBuf::from(format!("{}.meta.json", stem.display()));
    edit(&m, |s| {
        s.replace(
            "\"rotor_speed_rad_s\": 27.0",
            "\"rotor_speed_rad_s\": \"fast\"",
        )
    });
    let e = err_of(&stem);
    assert!(
        e.contains("`rotor_speed_rad_s`") && e.contains("expected a number"),
        "{e}"
    );
}

#[test]
fn alternate_units_convert_at_the_edge() {
    let rec = small();
    let stem = csv_stem("alt");
    let lbf = 4.4482216152605;
    let inch = 0.0254;
    // Rewrite the airloads in lb/in, in-lb/in and the damper in lb, in.
    let a = air(&stem);
    edit(&a, |s| {
        let mut out = String::new();
        for (i, l) in s.lines().enumerate() {
            if i == 0 {
                out += "revolution,azimuth_deg,r_over_R,normal_force_lb_per_in,chord_force_lb_per_in,pitching_moment_in_lb_per_in\n";
                continue;
            }
            let f: Vec<f64> = l.split(',').map(|x| x.parse().unwrap()).collect();
            out += &format!(
                "{},{},{},{},{},{}\n",
                f[0],
                f[1],
                f[2],
                f[3] / (lbf / inch),
                f[4] / (lbf / inch),
                f[5] / lbf
            );
        }
        out
    });
    let d = PathBuf::from(format!("{}.damper.csv", stem.display()));
    edit(&d, |s| {
        let mut out = String::from("revolution,azimuth_deg,damper_force_lb,damper_stroke_in\n");
        for l in s.lines().skip(1) {
            let f: Vec<f64> = l.split(',').map(|x| x.parse().unwrap()).collect();
            out += &format!("{},{},{},{}\n", f[0], f[1], f[2] / lbf, f[3] / inch);
        }
        out
    });
    let back = FlightRecord::read(&stem).unwrap();
    for (x, y) in rec.normal_n_per_m().iter().zip(back.normal_n_per_m()) {
        approx::assert_relative_eq!(x, y, max_relative = 1e-15);
    }
    for (x, y) in rec.moment_n_m_per_m().iter().zip(back.moment_n_m_per_m()) {
        approx::assert_relative_eq!(x, y, max_relative = 1e-15);
    }
    for (x, y) in rec.damper().iter().zip(back.damper()) {
        approx::assert_relative_eq!(x.force_N, y.force_N, max_relative = 1e-15);
        approx::assert_relative_eq!(
            x.stroke_m.unwrap(),
            y.stroke_m.unwrap(),
            max_relative = 1e-15,
            epsilon = 1e-18
        );
    }
}

#[test]
fn mach_squared_coefficients_use_metadata() {
    let rec = small();
    let stem = csv_stem("m2c");
    let (rho, a, c) = (1.0, 336.0, 0.527);
    let q = 0.5 * rho * a * a * c;
    edit(&air(&stem), |s| {
        let mut out = String::from("revolution,azimuth_deg,r_over_R,M2Cn,M2Cc,M2Cm\n");
        for l in s.lines().skip(1) {
            let f: Vec<f64> = l.split(',').map(|x| x.parse().unwrap()).collect();
            out += &format!(
                "{},{},{},{},{},{}\n",
                f[0],
                f[1],
                f[2],
                f[3] / q,
                f[4] / q,
                f[5] / (q * c)
            );
        }
        out
    });
    let back = FlightRecord::read(&stem).unwrap();
    for (x, y) in rec.chord_n_per_m().iter().zip(back.chord_n_per_m()) {
        approx::assert_relative_eq!(x, y, max_relative = 1e-14);
    }
    for (x, y) in rec.moment_n_m_per_m().iter().zip(back.moment_n_m_per_m()) {
        approx::assert_relative_eq!(x, y, max_relative = 1e-14);
    }
    // Without the chord the conversion is refused, naming the key.
    let m = PathBuf::from(format!("{}.meta.json", stem.display()));
    edit(&m, |s| s.replace("\"chord_m\": 0.527,", ""));
    let e = err_of(&stem);
    assert!(e.contains("`chord_m`") && e.contains("M^2 C"), "{e}");
}

// ---- MCAP ----

fn mcap_bytes() -> Vec<u8> {
    rotorsim::flight::mcap::mcap_bytes(&small(), Path::new("mem.mcap")).unwrap()
}

fn read_bytes(b: &[u8]) -> Result<FlightRecord, FlightError> {
    rotorsim::flight::mcap::read_mcap_from(&mut &b[..], b.len() as u64, Path::new("mem.mcap"))
}

/// An MCAP with our channels, except as `tweak` says: (topic, schema name) pairs to write.
fn custom_mcap(channels: &[(&str, &str)]) -> Vec<u8> {
    let rec = small();
    let good = mcap_bytes();
    // Re-emit the good file's messages onto the requested channel set.
    let stream = mcap::MessageStream::new(&good).unwrap();
    let mut buf = std::io::Cursor::new(Vec::new());
    {
        let mut w = mcap::Writer::new(&mut buf).unwrap();
        let mut ids = BTreeMap::new();
        for (topic, schema) in channels {
            let json = match *topic {
                "/rotor/meta" => rotorsim::flight::mcap::META_SCHEMA_JSON,
                "/rotor/airloads" => rotorsim::flight::mcap::AIRLOADS_SCHEMA_JSON,
                _ => rotorsim::flight::mcap::DAMPER_SCHEMA_JSON,
            };
            let s = w.add_schema(schema, "jsonschema", json.as_bytes()).unwrap();
            let c = w.add_channel(s, topic, "json", &BTreeMap::new()).unwrap();
            ids.insert(topic.to_string(), c);
        }
        for m in stream {
            let m = m.unwrap();
            if let Some(&id) = ids.get(&m.channel.topic) {
                w.write_to_known_channel(
                    &mcap::records::MessageHeader {
                        channel_id: id,
                        sequence: m.sequence,
                        log_time: m.log_time,
                        publish_time: m.publish_time,
                    },
                    &m.data,
                )
                .unwrap();
            }
        }
        w.finish().unwrap();
    }
    let _ = rec;
    buf.into_inner()
}

/// The small record as an uncompressed MCAP without chunk or data CRCs.
fn unchecked_mcap() -> Vec<u8> {
    let good = mcap_bytes();
    let mut buf = std::io::Cursor::new(Vec::new());
    {
        let mut w = mcap::WriteOptions::new()
            .compression(None)
            .calculate_chunk_crcs(false)
            .calculate_data_section_crc(false)
            .calculate_summary_section_crc(false)
            .create(&mut buf)
            .unwrap();
        for m in mcap::MessageStream::new(&good).unwrap() {
            w.write(&m.unwrap()).unwrap();
        }
        w.finish().unwrap();
    }
    buf.into_inner()
}

#[test]
fn unchecked_mcap_reads_back() {
    assert_same_bits(&small(), &read_bytes(&unchecked_mcap()).unwrap());
}

#[test]
fn mcap_reads_back_in_memory() {
    let r = read_bytes(&mcap_bytes()).unwrap();
    assert_same_bits(&small(), &r);
}

#[test]
fn truncated_mcap_is_a_clear_error() {
    let b = mcap_bytes();
    for cut in [0, 4, 8, 100, b.len() / 2, b.len() - 9, b.len() - 1] {
        let e = read_bytes(&b[..cut]).unwrap_err().to_string();
        assert!(
            e.contains("mem.mcap") && (e.contains("truncated or corrupt") || e.contains("missing")),
            "cut {cut}: {e}"
        );
    }
    let dir = tmpdir("trunc");
    let p = dir.join("t.mcap");
    std::fs::write(&p, &b[..b.len() / 2]).unwrap();
    let e = err_of(&p);
    assert!(
        e.contains("t.mcap") && e.contains("truncated or corrupt MCAP"),
        "{e}"
    );
}

#[test]
fn missing_channel_is_named() {
    let b = custom_mcap(&[
        ("/rotor/meta", "rotorsim.FlightMeta"),
        ("/rotor/airloads", "rotorsim.AirloadsAzimuth"),
    ]);
    let e = read_bytes(&b).unwrap_err().to_string();
    assert!(
        e.contains("channel /rotor/damper") && e.contains("missing"),
        "{e}"
    );
}

#[test]
fn wrong_schema_is_named() {
    let b = custom_mcap(&[
        ("/rotor/meta", "rotorsim.FlightMeta"),
        ("/rotor/airloads", "foo.Bar"),
        ("/rotor/damper", "rotorsim.DamperSample"),
    ]);
    let e = read_bytes(&b).unwrap_err().to_string();
    assert!(
        e.contains("/rotor/airloads")
            && e.contains("foo.Bar")
            && e.contains("rotorsim.AirloadsAzimuth"),
        "{e}"
    );
}

#[test]
fn messages_that_do_not_match_the_schema_are_named() {
    let good = mcap_bytes();
    let stream = mcap::MessageStream::new(&good).unwrap();
    let mut buf = std::io::Cursor::new(Vec::new());
    {
        let mut w = mcap::Writer::new(&mut buf).unwrap();
        for (k, m) in stream.enumerate() {
            let m = m.unwrap();
            let mut data = m.data.to_vec();
            if m.channel.topic == "/rotor/airloads" && k == 5 {
                data = br#"{"revolution":0,"azimuth_deg":"east"}"#.to_vec();
            }
            w.write(&mcap::Message {
                data: data.into(),
                ..m
            })
            .unwrap();
        }
        w.finish().unwrap();
    }
    let e = read_bytes(&buf.into_inner()).unwrap_err().to_string();
    assert!(
        e.contains("channel /rotor/airloads, message") && e.contains("rotorsim.AirloadsAzimuth"),
        "{e}"
    );
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 256, failure_persistence: None, .. ProptestConfig::default() })]
    /// Truncations and byte flips of a valid MCAP: an error or a record, never a panic.
    #[test]
    fn mangled_mcap_never_panics(cut in 0.0f64..1.0, flips in proptest::collection::vec((0.0f64..1.0, any::<u8>()), 0..6)) {
        let mut b = mcap_bytes();
        for (pos, byte) in flips {
            let i = ((pos * b.len() as f64) as usize).min(b.len() - 1);
            b[i] ^= byte.max(1);
        }
        let n = if cut > 0.9 { b.len() } else { (cut / 0.9 * b.len() as f64) as usize };
        let _ = read_bytes(&b[..n]);
    }

    /// The same on an uncompressed MCAP without CRCs, so flipped bytes reach the JSON messages
    /// and the record assembly instead of being caught by a checksum.
    #[test]
    fn mangled_unchecked_mcap_never_panics(flips in proptest::collection::vec((0.0f64..1.0, any::<u8>()), 1..4)) {
        let mut b = unchecked_mcap();
        for (pos, byte) in flips {
            let i = ((pos * b.len() as f64) as usize).min(b.len() - 1);
            b[i] ^= byte.max(1);
        }
        let _ = read_bytes(&b);
    }

    /// Mangled CSV lines (random text in place of a line, or a line cut short): never a panic.
    #[test]
    fn mangled_csv_never_panics(line in 0usize..80, junk in "[ -~]{0,40}", which in 0usize..3) {
        let stem = csv_stem(&format!("pcsv{which}"));
        let suffix = [".airloads.csv", ".damper.csv", ".meta.json"][which];
        let p = PathBuf::from(format!("{}{suffix}", stem.display()));
        edit(&p, |s| {
            let mut l: Vec<String> = s.lines().map(String::from).collect();
            let i = line % l.len();
            l[i] = junk.clone();
            l.join("\n")
        });
        let _ = FlightRecord::read(&stem);
    }
}

#[test]
fn rows_in_any_order_load_the_same_record() {
    let stem = csv_stem("shuffle");
    let a = air(&stem);
    edit(&a, |s| {
        let mut l: Vec<&str> = s.lines().collect();
        let header = l.remove(0);
        // A deterministic shuffle: reverse, then interleave halves.
        l.reverse();
        let (x, y) = l.split_at(l.len() / 2);
        let mut out = vec![header];
        for k in 0..x.len().max(y.len()) {
            out.extend(y.get(k));
            out.extend(x.get(k));
        }
        out.join("\n") + "\n"
    });
    assert_same_bits(&small(), &FlightRecord::read(&stem).unwrap());
}

#[test]
fn record_ending_inside_a_revolution_is_an_error() {
    let stem = csv_stem("endgap");
    // Drop the last azimuth (315 deg) of the last revolution (2): rows stay in canonical order.
    edit(&air(&stem), |s| {
        s.lines()
            .filter(|l| !l.starts_with("2,315,"))
            .map(|l| l.to_string() + "\n")
            .collect()
    });
    let e = err_of(&stem);
    assert!(
        e.contains("revolution 2") && e.contains("315") && e.contains("missing"),
        "{e}"
    );
    let stem = csv_stem("endgap2");
    // Drop only the last station of the last row.
    edit(&air(&stem), |s| {
        let mut l: Vec<&str> = s.lines().collect();
        l.pop();
        l.join("\n") + "\n"
    });
    let e = err_of(&stem);
    assert!(
        e.contains("revolution 2") && e.contains("r/R 0.9") && e.contains("missing"),
        "{e}"
    );
}

#[test]
fn byte_order_mark_and_crlf_are_accepted() {
    let stem = csv_stem("bom");
    edit(&air(&stem), |s| {
        format!("\u{feff}{}", s.replace('\n', "\r\n"))
    });
    assert_same_bits(&small(), &FlightRecord::read(&stem).unwrap());
}
