//! Per-blade differences of a rotor deck (docs/rotor_deck.md, "Per-blade differences"): a
//! `[blades.K...]` entry or a `--set blades.K...` reaches blade K's deck only, the base deck is
//! the deck without them, and bad input is refused on load naming the file and the key.
use rotorsim::overrides::Override;
use rotorsim::rotor::RotorDeck;
use std::path::{Path, PathBuf};
mod support;
use support::{root, tmp};

/// Writes the shipped deck with `before` prepended and `after` appended into `dir` as `name`,
/// beside a copy of its section table (the deck refers to it by a relative path).
fn deck(dir: &Path, name: &str, before: &str, after: &str) -> PathBuf {
    let data = dir.join("data");
    std::fs::create_dir_all(&data).unwrap();
    let csv = root().join("rotors/data/blade_sections_yeo.csv");
    std::fs::copy(&csv, data.join("blade_sections_yeo.csv")).unwrap();
    let base = std::fs::read_to_string(root().join("rotors/uh60a.toml")).unwrap();
    let p = dir.join(name);
    std::fs::write(&p, format!("{before}{base}\n{after}")).unwrap();
    p
}

fn sets(s: &[&str]) -> Vec<Override> {
    s.iter().map(|s| Override::parse(s).unwrap()).collect()
}

fn orifice(d: &RotorDeck) -> f64 {
    d.damper().unwrap().physical.unwrap().orifice.unwrap().area
}

fn link_ea(d: &RotorDeck) -> f64 {
    d.spec.pitch_control.link_section.ea
}

#[test]
fn a_blade_entry_reaches_that_blade_only() {
    let dir = tmp("blades-entry");
    let plain = RotorDeck::from_file(&deck(&dir, "plain.toml", "", "")).unwrap();
    let p = deck(
        &dir,
        "r.toml",
        "",
        "[blades.3.damper.physical]\nA_orf_m2 = 3.6e-6\n",
    );
    let r = RotorDeck::from_file(&p).unwrap();
    assert!(r.per_blade() && !plain.per_blade());
    // the base deck is the deck without the table
    assert_eq!(format!("{:?}", r.spec), format!("{:?}", plain.spec));
    assert_eq!(orifice(&r), 1.8e-6);
    for k in 1..=4 {
        let b = r.blade(k).unwrap();
        assert_eq!(b.path, p);
        assert!(!b.per_blade());
        assert_eq!(
            orifice(&b),
            if k == 3 { 3.6e-6 } else { 1.8e-6 },
            "blade {k}"
        );
        // the rotor reader keeps [damper] opaque: blade 3's differs
        let (mut x, mut y) = (b.spec.clone(), plain.spec.clone());
        if k == 3 {
            (x.damper, y.damper) = (None, None);
        }
        assert_eq!(format!("{x:?}"), format!("{y:?}"), "blade {k}");
        if k != 3 {
            let (x, y) = (b.damper().unwrap(), r.damper().unwrap());
            assert_eq!(x, y, "blade {k}");
        }
    }
    assert_eq!(
        r.blade_damper_overrides(3),
        sets(&["damper.physical.A_orf_m2=3.6e-6"])
    );
    assert!(r.blade_damper_overrides(2).is_empty());
    // a separate damper deck takes the blade's damper entries
    let dpath = root().join("flightdata/damper_nominal.toml");
    let d3 = r.blade_damper_deck(3, &dpath, &[]).unwrap();
    assert_eq!(d3.physical.unwrap().orifice.unwrap().area, 3.6e-6);
    let d1 = r.blade_damper_deck(1, &dpath, &[]).unwrap();
    assert_eq!(
        d1,
        rotorsim::hydraulics::DamperDeck::from_file(&dpath).unwrap()
    );
    // the blade's entry is applied after the damper deck's own --set
    let d3 = r
        .blade_damper_deck(3, &dpath, &sets(&["damper.physical.A_orf_m2=2.0e-6"]))
        .unwrap();
    assert_eq!(d3.physical.unwrap().orifice.unwrap().area, 3.6e-6);
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn a_blade_override_wins_over_the_deck_and_reaches_that_blade_only() {
    let dir = tmp("blades-set");
    let p = deck(
        &dir,
        "r.toml",
        "",
        "[blades.2.pitch_control.link_section]\nEA_N = 1.0e8\n[blades.4.bearing]\nlag_stiffness_Nm_per_rad = 30000\n",
    );
    let r = RotorDeck::from_file_with(
        &p,
        &sets(&[
            "blades.2.pitch_control.link_section.EA_N=2.0e8",
            "blades.1.damper.physical.A_orf_m2=2.0e-6",
            "bearing.flap_stiffness_Nm_per_rad=21000",
        ]),
    )
    .unwrap();
    // the base deck: the plain --set only
    assert_eq!(link_ea(&r), 9.0e5);
    assert_eq!(orifice(&r), 1.8e-6);
    assert_eq!(r.spec.bearing.flap_k, 21000.0);
    let b: Vec<RotorDeck> = (1..=4).map(|k| r.blade(k).unwrap()).collect();
    assert_eq!(
        b.iter().map(link_ea).collect::<Vec<_>>(),
        [9.0e5, 2.0e8, 9.0e5, 9.0e5]
    );
    assert_eq!(
        b.iter().map(orifice).collect::<Vec<_>>(),
        [2.0e-6, 1.8e-6, 1.8e-6, 1.8e-6]
    );
    // an integer where the deck has a number is that number
    assert_eq!(
        b.iter().map(|d| d.spec.bearing.lag_k).collect::<Vec<_>>(),
        [20400.0, 20400.0, 20400.0, 30000.0]
    );
    assert!(b.iter().all(|d| d.spec.bearing.flap_k == 21000.0));
    assert_eq!(r.differing_blades(), [1, 2, 4]);
    // the --set alone makes the deck per-blade
    let only = RotorDeck::from_file_with(&p, &sets(&[])).unwrap();
    assert!(only.per_blade());
    let plain = deck(&dir, "plain.toml", "", "");
    let s = RotorDeck::from_file_with(&plain, &sets(&["blades.4.bearing.pitch_loss_factor=0.2"]))
        .unwrap();
    assert!(s.per_blade());
    assert_eq!(
        s.blade(4).unwrap().spec.bearing.pitch_loss_factor,
        Some(0.2)
    );
    assert_eq!(
        s.blade(3).unwrap().spec.bearing.pitch_loss_factor,
        Some(0.1)
    );
    assert!(s.blade(5).is_err() && s.blade(0).is_err());
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn a_blade_section_table_is_an_input_file() {
    let dir = tmp("blades-csv");
    let p = deck(
        &dir,
        "r.toml",
        "",
        "[blades.2.blade]\nsections_csv = \"data/other.csv\"\n[blades.4.blade]\nsections_csv = \"data/other.csv\"\n",
    );
    std::fs::copy(
        dir.join("data/blade_sections_yeo.csv"),
        dir.join("data/other.csv"),
    )
    .unwrap();
    let r = RotorDeck::from_file(&p).unwrap();
    assert_eq!(
        r.input_files(),
        [
            p.clone(),
            dir.join("data/blade_sections_yeo.csv"),
            dir.join("data/other.csv")
        ]
    );
    assert_eq!(
        r.blade(2).unwrap().spec.blade.sections_csv,
        "data/other.csv"
    );
    assert_eq!(
        r.blade(3).unwrap().spec.blade.sections_csv,
        "data/blade_sections_yeo.csv"
    );
    // a blade's section table that cannot be read is refused on load
    std::fs::remove_file(dir.join("data/other.csv")).unwrap();
    let e = format!("{:#}", RotorDeck::from_file(&p).unwrap_err());
    assert!(e.contains("r.toml, blades.2.blade.sections_csv"), "{e}");
    assert!(e.contains("other.csv"), "{e}");
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn a_sweep_key_reaches_the_blade() {
    let dir = tmp("blades-sweep");
    let p = deck(&dir, "r.toml", "", "");
    let plan = format!(
        "[base]\nrotor = \"{}\"\n[vary]\n\"blades.3.damper.physical.A_orf_m2\" = [2.0e-6, 3.0e-6]\n",
        p.display()
    );
    let plan = rotorsim::sweep::Plan::parse(&plan, "plan.toml").unwrap();
    let case = &plan.cases[1];
    let job = rotorsim::sweep::runner::job_of(case, &dir.join("out"), None).unwrap();
    let (rotor, damper) = job.load_decks().unwrap();
    let rotor = rotor.unwrap();
    assert_eq!(damper.physical.unwrap().orifice.unwrap().area, 1.8e-6);
    assert_eq!(orifice(&rotor.blade(3).unwrap()), 3.0e-6);
    assert_eq!(orifice(&rotor.blade(2).unwrap()), 1.8e-6);
    let bad = format!(
        "[base]\nrotor = \"{}\"\n[[case]]\n\"blades.5.damper.physical.A_orf_m2\" = 2.0e-6\n",
        p.display()
    );
    let bad = rotorsim::sweep::Plan::parse(&bad, "plan.toml").unwrap();
    let job = rotorsim::sweep::runner::job_of(&bad.cases[0], &dir.join("out"), None).unwrap();
    let e = format!("{:#}", job.load_decks().unwrap_err());
    assert!(
        e.contains("--set blades.5.damper.physical.A_orf_m2=0.000002: rotor deck ")
            && e.contains("r.toml, blades.5: the rotor has 4 blades"),
        "{e}"
    );
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn with_a_separate_damper_deck_the_blade_damper_entries_go_to_it() {
    let dir = tmp("blades-damper-deck");
    deck(&dir, "full.toml", "", "");
    let full = std::fs::read_to_string(dir.join("full.toml")).unwrap();
    // the rotor deck without its [damper] tables
    let cut = full.find("\n[damper]\n").unwrap();
    let job = |after: &str, set: &[&str]| {
        let p = dir.join("r.toml");
        std::fs::write(&p, format!("{}\n{after}", &full[..cut])).unwrap();
        let mut job = rotorsim::run::job::RunJob::new(dir.join("out"));
        job.rotor = p;
        job.damper_deck = Some(root().join("flightdata/damper_nominal.toml"));
        job.overrides = sets(set);
        job
    };
    let good = job("[blades.3.damper.physical]\nA_orf_m2 = 3.6e-6\n", &[]);
    let (rotor, damper) = good.load_decks().unwrap();
    let rotor = rotor.unwrap();
    assert_eq!(damper.physical.unwrap().orifice.unwrap().area, 1.8e-6);
    let d3 = rotor
        .blade_damper_deck(3, good.damper_deck.as_ref().unwrap(), &[])
        .unwrap();
    assert_eq!(d3.physical.unwrap().orifice.unwrap().area, 3.6e-6);
    assert_eq!(
        rotor.blade_damper_overrides(3),
        sets(&["damper.physical.A_orf_m2=3.6e-6"])
    );
    for (after, set, want) in [
        (
            "[blades.3.damper.physical]\nA_orf_mm2 = 3.6e-6\n",
            &[][..],
            "r.toml, blades.3.damper.physical.A_orf_mm2: in damper deck ",
        ),
        (
            "",
            &["blades.2.damper.physical.Cd=-1.0"][..],
            "--set blades.2.damper.physical.Cd=-1.0: rotor deck ",
        ),
    ] {
        let e = format!("{:#}", job(after, set).load_decks().unwrap_err());
        assert!(e.contains(want) && e.contains("damper_nominal.toml"), "{e}");
    }
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn only_the_differing_blades_are_built() {
    // a blade count far beyond any rotor must not cost a deck per blade on load
    let dir = tmp("blades-many");
    let p = deck(
        &dir,
        "r.toml",
        "",
        "[blades.2.bearing]\nlag_stiffness_Nm_per_rad = 1.0\n",
    );
    let text = std::fs::read_to_string(&p).unwrap();
    std::fs::write(&p, text.replacen("blades = 4 ", "blades = 1000000000 ", 1)).unwrap();
    let t = std::time::Instant::now();
    let r = RotorDeck::from_file(&p).unwrap();
    assert_eq!(r.differing_blades(), [2]);
    assert_eq!(r.input_files().len(), 2);
    assert_eq!(r.blade(999_999_999).unwrap().spec.bearing.lag_k, 20400.0);
    assert!(t.elapsed().as_secs_f64() < 5.0, "{:?}", t.elapsed());
    let _ = std::fs::remove_dir_all(&dir);
}

/// Each bad input: text before and after the shipped deck, `--set`s, and what the message
/// must name (besides the file).
#[rustfmt::skip]
const BAD: &[(&str, &str, &[&str], &[&str])] = &[
    ("", "[blades.5.bearing]\nlag_stiffness_Nm_per_rad = 1.0\n", &[], &["r.toml, blades.5: the rotor has 4 blades (rotor.blades = 4): expected blades.1 to blades.4"]),
    ("", "[blades.0.bearing]\nlag_stiffness_Nm_per_rad = 1.0\n", &[], &["r.toml, blades.0:", "blades.1 to blades.4"]),
    ("", "[blades.two.bearing]\nlag_stiffness_Nm_per_rad = 1.0\n", &[], &["r.toml, blades.two:", "not a blade number"]),
    ("blades = 3\n", "", &[], &["r.toml, blades:", "expected per-blade tables"]),
    ("", "[blades]\n2 = 5.0\n", &[], &["r.toml, blades.2:", "expected a table"]),
    ("", "[blades.2.rotor]\nomega_rad_s = 30.0\n", &[], &["r.toml, blades.2.rotor.omega_rad_s:", "shared by all blades"]),
    ("", "[blades.2.blades.3.bearing]\nlag_stiffness_Nm_per_rad = 1.0\n", &[], &["r.toml, blades.2.blades.3.bearing.lag_stiffness_Nm_per_rad:", "do not nest"]),
    ("", "[blades.3.damper.physical]\nA_orf_mm2 = 4.0e-6\n", &[], &["r.toml, blades.3.damper.physical.A_orf_mm2: unknown key `damper.physical.A_orf_mm2`"]),
    ("", "[blades.3.damper.physical]\nA_orf_m2 = -4.0e-6\n", &[], &["r.toml, blades.3.damper.physical.A_orf_m2:", "A_orf_m2"]),
    ("", "[blades.2.bearing]\nlag_stifness_Nm_per_rad = 1.0\n", &[], &["r.toml, blades.2.bearing.lag_stifness_Nm_per_rad: unknown field `lag_stifness_Nm_per_rad`"]),
    ("", "[blades.2.bearing]\nlag_stiffness_Nm_per_rad = -1.0\n", &[], &["r.toml, blades.2.bearing.lag_stiffness_Nm_per_rad: bearing.lag_stiffness_Nm_per_rad: expected a non-negative number"]),
    ("", "[blades.2.pitch_control.link_section]\nEA_N = \"stiff\"\n", &[], &["r.toml, blades.2.pitch_control.link_section.EA_N: expected a number"]),
    ("", "[blades.2.no_such_table]\n", &[], &["r.toml, blades.2.no_such_table: unknown table"]),
    ("", "", &["blades.5.bearing.lag_stiffness_Nm_per_rad=1.0"], &["--set blades.5.bearing.lag_stiffness_Nm_per_rad=1.0: rotor deck ", "r.toml, blades.5: the rotor has 4 blades"]),
    ("", "", &["blades.3.damper.physical.A_orf_mm2=4.0e-6"], &["--set blades.3.damper.physical.A_orf_mm2=0.000004: rotor deck ", "r.toml, blades.3.damper.physical.A_orf_mm2: unknown key"]),
    ("", "", &["blades.1.rotor.blades=3"], &["--set blades.1.rotor.blades=3: rotor deck ", "r.toml, blades.1.rotor.blades:", "shared"]),
    ("", "", &["blades.2=1.0"], &["--set blades.2=1.0: rotor deck ", "r.toml, blades.2: expected blades.K.<deck key>"]),
    ("", "", &["blades.x.bearing.lag_stiffness_Nm_per_rad=1.0"], &["--set blades.x.", "r.toml, blades.x: `x` is not a blade number"]),
    ("", "", &["blades.2.bearing.lag_stiffness_Nm_per_rad=-1.0"], &["--set blades.2.bearing.lag_stiffness_Nm_per_rad=-1.0: rotor deck ", "r.toml, blades.2.bearing.lag_stiffness_Nm_per_rad: bearing.lag_stiffness_Nm_per_rad: expected a non-negative"]),
];

#[test]
fn bad_blade_input_is_refused_naming_file_and_key() {
    let dir = tmp("blades-bad");
    let mut failed = Vec::new();
    for (i, (before, after, set, want)) in BAD.iter().enumerate() {
        let p = deck(&dir, "r.toml", before, after);
        let got = RotorDeck::from_file_with(&p, &sets(set));
        let e = match got {
            Ok(_) => {
                failed.push(format!("[{i}] {after}{set:?}: accepted"));
                continue;
            }
            Err(e) => format!("{e:#}"),
        };
        for w in *want {
            if !e.contains(w) {
                failed.push(format!("[{i}] lacks `{w}`:\n    {e}"));
            }
        }
    }
    let _ = std::fs::remove_dir_all(&dir);
    assert!(failed.is_empty(), "{}", failed.join("\n"));
}
