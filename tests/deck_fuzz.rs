//! Random mutations of the shipped decks and of a bench CSV (byte flips, truncation, line
//! deletion and duplication, a number replaced by NaN, infinity, -1, 0, a huge value or a
//! string): the readers return a value or an error that names the file, never a panic.
use proptest::prelude::*;
use rotorsim::hydraulics::bench::parse_bench_csv;
use rotorsim::hydraulics::deck::DamperDeck;
use rotorsim::rotor::deck::RotorSpec;
use rotorsim::structure::deck::parse_deck;

mod support;
use support::root;

const REPLACEMENTS: [&str; 12] = [
    "nan", "inf", "-inf", "-1", "0", "0.0", "1e308", "-1e308", "1e-320", "\"x\"", "[]", "true",
];

#[derive(Debug, Clone)]
enum Mutation {
    /// XOR a byte at a relative position.
    Flip(f64, u8),
    /// Keep a leading fraction of the text.
    Truncate(f64),
    DeleteLine(f64),
    DuplicateLine(f64),
    /// Replace the k-th number (relative position among the numbers) by a replacement.
    Replace(f64, usize),
}

fn mutation() -> impl Strategy<Value = Mutation> {
    prop_oneof![
        (0.0f64..1.0, 1u8..=255).prop_map(|(p, b)| Mutation::Flip(p, b)),
        (0.0f64..1.0).prop_map(Mutation::Truncate),
        (0.0f64..1.0).prop_map(Mutation::DeleteLine),
        (0.0f64..1.0).prop_map(Mutation::DuplicateLine),
        (0.0f64..1.0, 0..REPLACEMENTS.len()).prop_map(|(p, k)| Mutation::Replace(p, k)),
        (0.0f64..1.0, 0..REPLACEMENTS.len()).prop_map(|(p, k)| Mutation::Replace(p, k)),
    ]
}

fn at(p: f64, n: usize) -> usize {
    ((p * n as f64) as usize).min(n.saturating_sub(1))
}

/// Byte ranges of the numbers of the text (a digit run with signs, dots and exponents, not
/// part of a name).
fn numbers(t: &[u8]) -> Vec<(usize, usize)> {
    let mut v = Vec::new();
    let mut i = 0;
    while i < t.len() {
        let starts = (t[i].is_ascii_digit() || t[i] == b'-' || t[i] == b'.')
            && (i == 0 || !(t[i - 1].is_ascii_alphanumeric() || t[i - 1] == b'_'));
        if starts {
            let mut j = i;
            while j < t.len() && (t[j].is_ascii_digit() || b"+-.eE".contains(&t[j])) {
                j += 1;
            }
            if t[i..j].iter().any(u8::is_ascii_digit) {
                v.push((i, j));
            }
            i = j.max(i + 1);
        } else {
            i += 1;
        }
    }
    v
}

fn mutate(text: &str, ms: &[Mutation]) -> String {
    let mut b = text.as_bytes().to_vec();
    for m in ms {
        if b.is_empty() {
            break;
        }
        match *m {
            Mutation::Flip(p, x) => {
                let i = at(p, b.len());
                b[i] ^= x;
            }
            Mutation::Truncate(p) => b.truncate(at(p, b.len())),
            Mutation::DeleteLine(p) | Mutation::DuplicateLine(p) => {
                let s = String::from_utf8_lossy(&b).into_owned();
                let mut lines: Vec<&str> = s.split_inclusive('\n').collect();
                let i = at(p, lines.len());
                if matches!(m, Mutation::DeleteLine(_)) {
                    lines.remove(i);
                } else {
                    lines.insert(i, lines[i]);
                }
                b = lines.concat().into_bytes();
            }
            Mutation::Replace(p, k) => {
                let nums = numbers(&b);
                if nums.is_empty() {
                    continue;
                }
                let (i, j) = nums[at(p, nums.len())];
                b.splice(i..j, REPLACEMENTS[k].bytes());
            }
        }
    }
    String::from_utf8_lossy(&b).into_owned()
}

fn shipped(p: &str) -> String {
    std::fs::read_to_string(root().join(p)).unwrap()
}

/// Copies refer to the shipped files they reference by absolute path.
fn absolute(text: String) -> String {
    text.replace(
        "sections_csv = \"data/",
        &format!("sections_csv = \"{}/", root().join("rotors/data").display()),
    )
    .replace(
        "deck = \"../../rotors/",
        &format!("deck = \"{}/", root().join("rotors").display()),
    )
}

fn bench_text() -> String {
    let mut s = String::from("time_s,stroke_m,velocity_m_s,force_N\n");
    for i in 0..40 {
        let t = i as f64 * 1e-3;
        let w = 2.0 * std::f64::consts::PI * 25.0;
        s += &format!(
            "{t},{},{},{}\n",
            1e-3 * (w * t).sin(),
            1e-3 * w * (w * t).cos(),
            68000.0 * 1e-3 * w * (w * t).cos()
        );
    }
    s
}

fn mutations() -> impl Strategy<Value = Vec<Mutation>> {
    proptest::collection::vec(mutation(), 1..4)
}

fn config() -> ProptestConfig {
    ProptestConfig {
        cases: 1000,
        failure_persistence: None,
        ..ProptestConfig::default()
    }
}

proptest! {
    #![proptest_config(config())]

    #[test]
    fn mutated_rotor_deck_never_panics(ms in mutations()) {
        let text = mutate(&absolute(shipped("rotors/uh60a.toml")), &ms);
        if let Err(e) = RotorSpec::parse(&text, "fuzz/uh60a.toml") {
            let e = format!("{e:#}");
            prop_assert!(e.contains("fuzz/uh60a.toml"), "{e}");
        }
    }

    #[test]
    fn mutated_damper_deck_never_panics(ms in mutations()) {
        let text = mutate(&shipped("flightdata/damper_nominal.toml"), &ms);
        if let Err(e) = DamperDeck::from_toml_str(&text, "fuzz/damper.toml") {
            let e = e.to_string();
            prop_assert!(e.contains("fuzz/damper.toml"), "{e}");
        }
    }

    #[test]
    fn mutated_rotor_damper_table_never_panics(ms in mutations()) {
        let base = shipped("rotors/uh60a.toml");
        let k = base.find("[damper]").unwrap();
        let text = format!("{}{}", &base[..k], mutate(&base[k..], &ms));
        if let Err(e) = DamperDeck::from_toml_str(&text, "fuzz/rotor.toml") {
            let e = e.to_string();
            prop_assert!(e.contains("fuzz/rotor.toml"), "{e}");
        }
    }

    #[test]
    fn mutated_model_deck_never_panics(ms in mutations(), which in 0usize..2) {
        let deck = ["docs/examples/cantilever.toml", "docs/examples/actuator_pitch_beam.toml"][which];
        let text = mutate(&absolute(shipped(deck)), &ms);
        let base = root().join("docs/examples");
        if let Err(e) = parse_deck(&text, "fuzz/model.toml", &base) {
            let e = e.to_string();
            prop_assert!(e.contains("fuzz/model.toml"), "{e}");
        }
    }

    #[test]
    fn mutated_bench_csv_never_panics(ms in mutations()) {
        let text = mutate(&bench_text(), &ms);
        if let Err(e) = parse_bench_csv(&text, "fuzz/bench.csv", "bench") {
            let e = e.to_string();
            prop_assert!(e.contains("fuzz/bench.csv"), "{e}");
        }
    }
}

#[test]
fn shipped_files_are_read_unmutated() {
    RotorSpec::parse(&absolute(shipped("rotors/uh60a.toml")), "uh60a.toml").unwrap();
    DamperDeck::from_toml_str(&shipped("flightdata/damper_nominal.toml"), "d.toml").unwrap();
    for d in [
        "docs/examples/cantilever.toml",
        "docs/examples/actuator_pitch_beam.toml",
    ] {
        parse_deck(&absolute(shipped(d)), d, &root().join("docs/examples")).unwrap();
    }
    parse_bench_csv(&bench_text(), "b.csv", "b").unwrap();
}

/// A bench CSV written to a file and read back: errors name the path.
#[test]
fn bench_file_errors_name_the_path() {
    let dir = support::tmp("fuzz_bench");
    let p = dir.join("cut.csv");
    std::fs::write(&p, "time_s,stroke_m\n0,0\n0.001,x\n").unwrap();
    let e = rotorsim::hydraulics::bench::read_bench_csv(&p)
        .unwrap_err()
        .to_string();
    assert!(
        e.contains(&p.display().to_string()) && e.contains("line 3"),
        "{e}"
    );
    let _ = std::fs::remove_dir_all(&dir);
}
