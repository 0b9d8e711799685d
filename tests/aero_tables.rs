//! Aerofoil coefficient tables (src/aero/c81.rs, src/aero/airfoil.rs): the shipped C81 tables
//! parse to what their text says, interpolation is exact at grid points and bilinear between,
//! queries outside a table clamp to its edge and are counted, bad tables are refused with the
//! file, line and columns named, and the thin-aerofoil fallback is 2 pi alpha.
use rotorsim::aero::airfoil::{Airfoil, ClampCounts, Coefficients, ThinAirfoil};
use rotorsim::aero::c81::{C81Error, C81Table};
use std::f64::consts::PI;
use std::path::PathBuf;
use std::sync::Arc;

mod alloc_support;
use alloc_support::{allocations, assert_counting};

fn repo(p: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join(p)
}

fn read(p: &str) -> String {
    std::fs::read_to_string(repo(p)).unwrap()
}

/// Columns `a..=b` (1-based) of a line, parsed as a number.
fn cols(line: &str, a: usize, b: usize) -> f64 {
    line[a - 1..b.min(line.len())].trim().parse().unwrap()
}

// ---------------------------------------------------------------- shipped tables

#[test]
fn naca0012_counts_and_values_match_the_file_text() {
    let path = repo("data/airfoils/naca0012.c81");
    let t = C81Table::from_file(&path).unwrap();
    assert_eq!(t.name, "PROFILO NACA 0012");
    assert_eq!(t.source, path.display().to_string());
    // Header "PROFILO NACA 0012             11391165 947": ML NL MD ND MM NM.
    assert_eq!((t.cl.mach.len(), t.cl.alpha_deg.len()), (11, 39));
    assert_eq!((t.cd.mach.len(), t.cd.alpha_deg.len()), (11, 65));
    assert_eq!((t.cm.mach.len(), t.cm.alpha_deg.len()), (9, 47));
    let m11 = [0.0, 0.2, 0.3, 0.4, 0.5, 0.6, 0.7, 0.75, 0.8, 0.9, 1.0];
    assert_eq!(t.cl.mach, m11);
    assert_eq!(t.cd.mach, m11);
    // The moment table's Mach row holds 0. in its ignored first 7 columns.
    assert_eq!(t.cm.mach, m11[1..10]);

    // Independently: each row's alpha in columns 1-7, the first coefficient in columns 8-14,
    // the last (Mach 1 for lift and drag) as the line's last whitespace-separated token.
    let text = read("data/airfoils/naca0012.c81");
    let lines: Vec<&str> = text.lines().collect();
    assert_eq!(lines.len(), 1 + 40 + 66 + 48);
    for (tab, first_row, n) in [(&t.cl, 2, 39), (&t.cd, 42, 65), (&t.cm, 108, 47)] {
        for i in 0..n {
            let l = lines[first_row + i];
            assert_eq!(
                tab.alpha_deg[i],
                cols(l, 1, 7),
                "line {}",
                first_row + i + 1
            );
            assert_eq!(tab.at(i, 0), cols(l, 8, 14), "line {}", first_row + i + 1);
            let last: f64 = l.split_whitespace().last().unwrap().parse().unwrap();
            assert_eq!(
                tab.at(i, tab.mach.len() - 1),
                last,
                "line {}",
                first_row + i + 1
            );
        }
    }
    // A row whose fields touch: line 16 is "-11.    -1.161-1.161 -1.19 ...".
    assert!(lines[15].starts_with("-11.    -1.161-1.161"));
    assert_eq!(t.cl.alpha_deg[13], -11.0);
    assert_eq!(
        (t.cl.at(13, 0), t.cl.at(13, 1), t.cl.at(13, 2)),
        (-1.161, -1.161, -1.19)
    );
    assert_eq!(t.cl.alpha_deg[0], -180.0);
    assert_eq!(t.cl.alpha_deg[38], 180.0);
}

#[test]
fn naca0012_through_the_airfoil() {
    let t = Arc::new(C81Table::from_file(&repo("data/airfoils/naca0012.c81")).unwrap());
    let af = Airfoil::Table(t.clone());
    assert_eq!(af.name(), "PROFILO NACA 0012");
    let clamps = ClampCounts::default();
    // Grid point: alpha 10 deg, Mach 0.5 (lift row "10.    1.055  1.055  1.1    1.082  .985").
    let c = af.coefficients(10f64.to_radians(), 0.5, &clamps);
    assert!((c.cl - 0.985).abs() < 1e-12, "{c:?}");
    assert_eq!(clamps.total(), 0);
    // Symmetric section: cl odd, cd even in alpha at Mach 0.3.
    for a in [1.0f64, 3.7, 8.0, 12.5] {
        let p = af.coefficients(a.to_radians(), 0.3, &clamps);
        let m = af.coefficients((-a).to_radians(), 0.3, &clamps);
        assert!((p.cl + m.cl).abs() < 1e-9, "{a}: {p:?} {m:?}");
        assert!((p.cd - m.cd).abs() < 1e-9, "{a}: {p:?} {m:?}");
    }
    assert_eq!(clamps.total(), 0);
    // Mach 0.1 is below the moment table's Mach row (0.2 to 0.9): one query, one count.
    let c = af.coefficients(0.05, 0.1, &clamps);
    assert_eq!((clamps.mach_low(), clamps.total()), (1, 1));
    let (cm, _) = t.cm.eval(0.05f64.to_degrees(), 0.2);
    assert_eq!(c.cm, cm);
    // Mach 0.95 is above the moment table's range, inside the lift table's.
    af.coefficients(0.05, 0.95, &clamps);
    assert_eq!(clamps.mach_high(), 1);
    assert_eq!(
        af.clamp_summary(&clamps),
        "1 query below the table's Mach range (Mach 0.2), \
         1 query above the table's Mach range (Mach 0.9)"
    );
    // Any angle of attack wraps into the table's -180..180 deg: no alpha clamps.
    for a in [-10.0, -4.0, 3.5, 7.0, 100.0] {
        af.coefficients(a, 0.5, &clamps);
    }
    assert_eq!(clamps.alpha_low() + clamps.alpha_high(), 0);
    let a = af.coefficients(0.1, 0.5, &clamps);
    let b = af.coefficients(0.1 + 4.0 * PI, 0.5, &clamps);
    assert!((a.cl - b.cl).abs() < 1e-9);
}

#[test]
fn thin_airfoil2_free_format_matches_the_file_text() {
    let t = C81Table::from_file(&repo("data/airfoils/ThinAirfoil2.c81")).unwrap();
    assert_eq!(t.name, "flotor airfoil");
    assert_eq!((t.cl.mach.len(), t.cl.alpha_deg.len()), (2, 68));
    assert_eq!((t.cd.mach.len(), t.cd.alpha_deg.len()), (2, 83));
    assert_eq!((t.cm.mach.len(), t.cm.alpha_deg.len()), (2, 67));
    assert_eq!(t.cl.mach, [-0.000002, 1.0]);
    let text = read("data/airfoils/ThinAirfoil2.c81");
    let lines: Vec<&str> = text.lines().collect();
    for (tab, first_row, n) in [(&t.cl, 2, 68), (&t.cd, 71, 83), (&t.cm, 155, 67)] {
        for i in 0..n {
            let v: Vec<f64> = lines[first_row + i]
                .split_whitespace()
                .map(|s| s.parse().unwrap())
                .collect();
            assert_eq!(
                (tab.alpha_deg[i], tab.at(i, 0), tab.at(i, 1)),
                (v[0], v[1], v[2])
            );
        }
    }
    // "10.000000 1.096623 1.096623": the 2 pi alpha lift slope of the table (per degree).
    let i = t.cl.alpha_deg.iter().position(|&a| a == 10.0).unwrap();
    assert_eq!(t.cl.at(i, 0), 1.096623);
    assert!((1.096623 - 2.0 * PI * 10f64.to_radians()).abs() < 1e-6);
}

// ---------------------------------------------------------------- a small table

/// A fixed-layout C81 text from fields (each padded to 7 columns); the header's counts are
/// given as text so that tests can break them.
fn fixed(counts: &str, tables: &[(&[&str], &[&[&str]]); 3]) -> String {
    let f7 = |s: &str| format!("{s:<7}");
    let mut out = format!("{:<30}{counts}\n", "SMALL TEST TABLE");
    for (mach, rows) in tables {
        out += &f7("");
        for m in *mach {
            out += &f7(m);
        }
        out += "\n";
        for r in *rows {
            for v in *r {
                out += &f7(v);
            }
            out += "\n";
        }
    }
    out
}

const MACH: &[&str] = &["0.3", "0.6"];
const CL: &[&[&str]] = &[
    &["-10.", "-1.0", "-1.2"],
    &["0.", "0.0", "0.1"],
    &["10.", "1.0", "1.4"],
];
const CD: &[&[&str]] = &[
    &["-10.", "0.02", "0.03"],
    &["0.", "0.01", "0.012"],
    &["10.", "0.02", "0.04"],
];
const CM: &[&[&str]] = &[
    &["-10.", "0.01", "0.02"],
    &["0.", "0.0", "0.0"],
    &["10.", "-0.01", "-0.02"],
];

fn small_text() -> String {
    fixed(" 2 3 2 3 2 3", &[(MACH, CL), (MACH, CD), (MACH, CM)])
}

fn small() -> C81Table {
    C81Table::parse(&small_text(), "small.c81").unwrap()
}

#[test]
fn small_table_layout() {
    let text = small_text();
    assert!(text.starts_with("SMALL TEST TABLE               2 3 2 3 2 3\n       0.3    0.6"));
    let t = small();
    assert_eq!(t.name, "SMALL TEST TABLE");
    assert_eq!(t.cl.mach, [0.3, 0.6]);
    assert_eq!(t.cl.alpha_deg, [-10.0, 0.0, 10.0]);
    assert_eq!(t.cl.values, [-1.0, -1.2, 0.0, 0.1, 1.0, 1.4]);
    assert_eq!(t.cd.values, [0.02, 0.03, 0.01, 0.012, 0.02, 0.04]);
    assert_eq!(t.cm.values, [0.01, 0.02, 0.0, 0.0, -0.01, -0.02]);
}

#[test]
fn interpolation_exact_at_grid_points() {
    let t = small();
    for tab in [&t.cl, &t.cd, &t.cm] {
        for (i, &a) in tab.alpha_deg.iter().enumerate() {
            for (j, &m) in tab.mach.iter().enumerate() {
                let (v, c) = tab.eval(a, m);
                assert_eq!(v, tab.at(i, j));
                assert!(!c.any());
            }
        }
    }
}

#[test]
fn interpolation_bilinear_between_grid_points() {
    let t = small();
    // alpha 5 deg: halfway from row 0 deg to row 10 deg; Mach 0.4: a third from 0.3 to 0.6.
    // cl: row 0 deg: 0 + (0.1 - 0)/3 = 1/30; row 10 deg: 1 + 0.4/3 = 17/15;
    // halfway: (1/30 + 34/30)/2 = 35/60 = 7/12.
    let (cl, c) = t.cl.eval(5.0, 0.4);
    assert!((cl - 7.0 / 12.0).abs() < 1e-14, "{cl}");
    assert!(!c.any());
    // cd at (-2.5 deg, 0.55): rows -10 and 0 with weights 1/4 and 3/4; Mach weights 1/6, 5/6.
    // row -10: 0.02/6 + 0.03*5/6 = 0.17/6; row 0: 0.01/6 + 0.012*5/6 = 0.07/6;
    // 0.25*0.17/6 + 0.75*0.07/6 = (0.0425 + 0.0525)/6 = 0.095/6.
    let (cd, _) = t.cd.eval(-2.5, 0.55);
    assert!((cd - 0.095 / 6.0).abs() < 1e-14, "{cd}");
    // Through the Airfoil in radians.
    let af = Airfoil::Table(Arc::new(t));
    let clamps = ClampCounts::default();
    let c = af.coefficients(5f64.to_radians(), 0.4, &clamps);
    assert!((c.cl - 7.0 / 12.0).abs() < 1e-12, "{c:?}");
    assert!((c.cd - (0.5 * (0.01 + 0.002 / 3.0) + 0.5 * (0.02 + 0.02 / 3.0))).abs() < 1e-12);
    assert!((c.cm - 0.5 * (-0.01 - 0.01 / 3.0)).abs() < 1e-12);
    assert_eq!(clamps.total(), 0);
}

#[test]
fn clamping_uses_the_edge_and_counts_it() {
    let t = Arc::new(small());
    let af = Airfoil::Table(t.clone());
    let clamps = ClampCounts::default();
    let edge = |a: f64, m: f64| af.coefficients(a.to_radians(), m, &ClampCounts::default());
    // Alpha below: the -10 deg row.
    let c = af.coefficients((-30f64).to_radians(), 0.3, &clamps);
    assert_eq!(c, edge(-10.0, 0.3));
    assert_eq!((c.cl, c.cd, c.cm), (-1.0, 0.02, 0.01));
    assert_eq!((clamps.alpha_low(), clamps.total()), (1, 1));
    // Alpha above: the 10 deg row, interpolated in Mach.
    let c = af.coefficients(20f64.to_radians(), 0.45, &clamps);
    assert!((c.cl - 1.2).abs() < 1e-14);
    assert_eq!((clamps.alpha_high(), clamps.total()), (1, 2));
    // Mach below and above.
    let c = af.coefficients(0.0, 0.1, &clamps);
    assert_eq!((c.cl, c.cd), (0.0, 0.01));
    assert_eq!((clamps.mach_low(), clamps.total()), (1, 3));
    let c = af.coefficients(0.0, 0.9, &clamps);
    assert_eq!((c.cl, c.cd), (0.1, 0.012));
    assert_eq!((clamps.mach_high(), clamps.total()), (1, 4));
    // Both at once: the corner, and both counters.
    let c = af.coefficients(1.0, 2.0, &clamps);
    assert_eq!((c.cl, c.cd, c.cm), (1.4, 0.04, -0.02));
    assert_eq!(
        (clamps.alpha_high(), clamps.mach_high(), clamps.total()),
        (2, 2, 6)
    );
    // Never extrapolated: far beyond equals the edge.
    assert_eq!(t.cl.eval(1e6, 50.0).0, 1.4);
    assert_eq!(
        clamps.summary(),
        "1 query below the table's angle of attack range, \
         2 queries above the table's angle of attack range, \
         1 query below the table's Mach range, 2 queries above the table's Mach range"
    );
    assert_eq!(
        af.clamp_summary(&clamps),
        "1 query below the table's angle of attack range (-10 deg), \
         2 queries above the table's angle of attack range (10 deg), \
         1 query below the table's Mach range (Mach 0.3), \
         2 queries above the table's Mach range (Mach 0.6)"
    );
}

#[test]
fn clamp_counts_are_shared_between_threads() {
    let af = Airfoil::Table(Arc::new(small()));
    let clamps = Arc::new(ClampCounts::default());
    std::thread::scope(|s| {
        for _ in 0..4 {
            let (af, clamps) = (af.clone(), clamps.clone());
            s.spawn(move || {
                for _ in 0..1000 {
                    af.coefficients(0.0, 0.1, &clamps);
                }
            });
        }
    });
    assert_eq!(clamps.mach_low(), 4000);
    assert_eq!(clamps.total(), 4000);
}

#[test]
fn thin_fallback_never_clamps() {
    let af = Airfoil::Thin(ThinAirfoil::default());
    let clamps = ClampCounts::default();
    for a in [-100.0, -3.0, -1.0, 0.0, 0.5, 3.0, 1e3] {
        for m in [0.0, 0.5, 3.0, 10.0] {
            af.coefficients(a, m, &clamps);
        }
    }
    assert_eq!(clamps.total(), 0);
    assert_eq!(clamps.summary(), "");
}

#[test]
fn thin_fallback_is_two_pi_alpha() {
    let d = ThinAirfoil::default();
    assert_eq!(d.lift_slope_per_rad, 2.0 * PI);
    assert_eq!((d.cd0, d.cm0), (0.0, 0.0));
    let af = Airfoil::Thin(d);
    assert_eq!(af.name(), "thin aerofoil (2 pi alpha)");
    let clamps = ClampCounts::default();
    for a in [-1.5, -1.0, -0.1, 0.0, 0.05, 0.3, 1.5] {
        let c = af.coefficients(a, 0.7, &clamps);
        assert_eq!(
            c,
            Coefficients {
                cl: 2.0 * PI * a,
                cd: 0.0,
                cm: 0.0
            }
        );
    }
    // Wrapped to [-pi, pi) first.
    let c = af.coefficients(0.2 + 2.0 * PI, 0.0, &clamps);
    assert!((c.cl - 2.0 * PI * 0.2).abs() < 1e-12);
    // Reversed flow: the flat plate seen from its trailing edge, alpha -+ pi.
    for a in [3.1, -3.0, PI - 0.2, -PI + 0.1] {
        let c = af.coefficients(a, 0.0, &clamps);
        let want = 2.0 * PI * (a - PI * a.signum());
        assert!((c.cl - want).abs() < 1e-12, "{a}: {} vs {want}", c.cl);
    }
    let custom = Airfoil::Thin(ThinAirfoil {
        lift_slope_per_rad: 5.7,
        cd0: 0.008,
        cm0: -0.01,
    });
    let c = custom.coefficients(0.1, 0.0, &clamps);
    assert!((c.cl - 0.57).abs() < 1e-15);
    assert_eq!((c.cd, c.cm), (0.008, -0.01));
}

#[test]
fn queries_do_not_allocate() {
    let naca = Airfoil::Table(Arc::new(
        C81Table::from_file(&repo("data/airfoils/naca0012.c81")).unwrap(),
    ));
    let thin = Airfoil::Thin(ThinAirfoil::default());
    let clamps = ClampCounts::default();
    assert_counting();
    let before = allocations();
    let mut sum = 0.0;
    for k in 0..10_000 {
        let a = -7.0 + 14.0 * (k as f64) / 10_000.0;
        let m = 1.2 * (k % 97) as f64 / 96.0;
        sum += naca.coefficients(a, m, &clamps).cl + thin.coefficients(a, m, &clamps).cl;
    }
    assert_eq!(allocations(), before, "queries allocated");
    assert!(sum.is_finite());
    assert!(clamps.total() > 0);
}

// ---------------------------------------------------------------- continuation lines

#[test]
fn continuation_lines_and_rows_joined_after_column_70_agree() {
    // 11 Mach numbers: 9 on the Mach row, 2 on its continuation line; likewise each row.
    let mach: Vec<String> = (0..11).map(|j| format!("{:.2}", 0.1 * j as f64)).collect();
    let f7 = |s: &str| format!("{s:<7}");
    let row = |a: f64, k: f64| -> Vec<String> {
        (0..11)
            .map(|j| format!("{:.3}", k * a * (1.0 + 0.01 * j as f64)))
            .collect()
    };
    let alphas = [-20.0, 0.0, 20.0];
    let mut std_layout = format!("{:<30}{}\n", "CONT", "11 311 311 3");
    let mut joined = std_layout.clone();
    for k in [0.1, 0.01, -0.001] {
        std_layout += &format!(
            "{}{}\n",
            f7(""),
            mach[..9].iter().map(|s| f7(s)).collect::<String>()
        );
        std_layout += &format!(
            "{}{}\n",
            f7(""),
            mach[9..].iter().map(|s| f7(s)).collect::<String>()
        );
        joined += &format!(
            "{}{}   {}\n",
            f7(""),
            mach[..9].iter().map(|s| f7(s)).collect::<String>(),
            mach[9..].join("  ")
        );
        for a in alphas {
            let v = row(a, k);
            let head = format!(
                "{}{}",
                f7(&format!("{a:.1}")),
                v[..9].iter().map(|s| f7(s)).collect::<String>()
            );
            std_layout += &format!(
                "{head}\n{}{}\n",
                f7(""),
                v[9..].iter().map(|s| f7(s)).collect::<String>()
            );
            joined += &format!("{head}        {}\n", v[9..].join(" "));
        }
    }
    let a = C81Table::parse(&std_layout, "std.c81").unwrap();
    let b = C81Table::parse(&joined, "joined.c81").unwrap();
    assert_eq!(a.cl.mach.len(), 11);
    assert_eq!(a.cl.mach[10], 1.0);
    assert_eq!(a.cl.at(2, 10), 2.2);
    assert_eq!(
        (a.cl.clone(), a.cd.clone(), a.cm.clone()),
        (b.cl, b.cd, b.cm)
    );
}

// ---------------------------------------------------------------- bad input

fn err(text: &str) -> String {
    C81Table::parse(text, "bad.c81").unwrap_err().to_string()
}

#[test]
fn bad_non_number_in_a_field() {
    let cl: &[&[&str]] = &[
        &["-10.", "-1.0", "-1.2"],
        &["0.", "0.0", "0.1x3"],
        &["10.", "1.0", "1.4"],
    ];
    let text = fixed(" 2 3 2 3 2 3", &[(MACH, cl), (MACH, CD), (MACH, CM)]);
    assert_eq!(
        err(&text),
        "bad.c81 line 4, columns 15-21: expected a number (coefficient 2 of 2), found `0.1x3`"
    );
    // In a Mach row.
    let text = fixed(
        " 2 3 2 3 2 3",
        &[(MACH, CL), (&["0.3", "M.6"], CD), (MACH, CM)],
    );
    assert_eq!(
        err(&text),
        "bad.c81 line 6, columns 15-21: expected a number (Mach number 2 of 2), found `M.6`"
    );
    // In the free layout: field and columns on the line.
    let text = "free; 1 1 1 1 1 1\n0.3\n0. 0.1\n0.3\n0. 0.0x1\n0.3\n0. 0.0\n";
    assert_eq!(
        err(text),
        "bad.c81 line 5, field 2 (columns 4-8): expected a number \
         (the drag table's row 1 of 1, coefficient 1 of 1), found `0.0x1`"
    );
}

#[test]
fn bad_table_shorter_than_its_header() {
    // The moment table's last row is missing.
    let text = small_text();
    let short: String = text.lines().take(12).map(|l| format!("{l}\n")).collect();
    assert_eq!(
        err(&short),
        "bad.c81 line 13: expected moment table's row 3 of 3, found the end of the file"
    );
    // A row with a value missing: a blank field.
    let cd: &[&[&str]] = &[
        &["-10.", "0.02", "0.03"],
        &["0.", "0.01"],
        &["10.", "0.02", "0.04"],
    ];
    let text = fixed(" 2 3 2 3 2 3", &[(MACH, CL), (MACH, cd), (MACH, CM)]);
    assert_eq!(
        err(&text),
        "bad.c81 line 8, columns 15-21: expected a number (coefficient 2 of 2), found a blank field"
    );
    // The header says 4 lift rows where there are 3: the drag Mach row is read as a row.
    let text = fixed(" 2 4 2 3 2 3", &[(MACH, CL), (MACH, CD), (MACH, CM)]);
    assert_eq!(
        err(&text),
        "bad.c81 line 6, columns 1-7: expected a number (the angle of attack), found a blank field"
    );
    // Free layout.
    let text = "free; 1 1 1 1 1 2\n0.3\n0. 0.1\n0.3\n0. 0.0\n0.3\n0. 0.0\n";
    assert_eq!(
        err(text),
        "bad.c81 line 8: expected a number (the moment table's angle of attack of row 2 of 2), \
         found the end of the file"
    );
}

#[test]
fn bad_table_longer_than_its_header() {
    let text = fixed(" 2 3 2 3 2 2", &[(MACH, CL), (MACH, CD), (MACH, CM)]);
    assert_eq!(
        err(&text),
        "bad.c81 line 13, column 1: expected the end of the file after the moment table, found `10.`"
    );
    let text = fixed(" 1 3 2 3 2 3", &[(MACH, CL), (MACH, CD), (MACH, CM)]);
    assert_eq!(
        err(&text),
        "bad.c81 line 2, column 15: expected the end of the lift table's Mach row after its 1 \
         values, found `0.6`"
    );
}

#[test]
fn bad_header_counts() {
    let text = fixed(" 2 x 2 3 2 3", &[(MACH, CL), (MACH, CD), (MACH, CM)]);
    assert_eq!(
        err(&text),
        "bad.c81 line 1, columns 33-34: expected the count NL (angles of attack of the lift \
         table), a whole number of at least 1, found `x`"
    );
    let text = fixed(" 2 3 2 3 2", &[(MACH, CL), (MACH, CD), (MACH, CM)]);
    assert_eq!(
        err(&text),
        "bad.c81 line 1, columns 41-42: expected the count NM (angles of attack of the moment \
         table), a whole number of at least 1, found a blank field"
    );
    let text = fixed(" 2 3 0 3 2 3", &[(MACH, CL), (MACH, CD), (MACH, CM)]);
    assert!(err(&text).starts_with("bad.c81 line 1, columns 35-36: expected the count MD"));
    assert_eq!(
        err("free; 1 1 1.5 1 1 1\n"),
        "bad.c81 line 1, columns 11-13: expected the count MD (Mach numbers of the drag table), \
         a whole number of at least 1, found `1.5`"
    );
}

#[test]
fn bad_missing_file() {
    let e = C81Table::from_file(&PathBuf::from("/nonexistent/foo.c81")).unwrap_err();
    assert!(matches!(e, C81Error::Read { .. }));
    assert_eq!(
        e.to_string(),
        "aerofoil table /nonexistent/foo.c81: cannot read: No such file or directory"
    );
}

#[test]
fn bad_alpha_not_increasing() {
    let cd: &[&[&str]] = &[
        &["-10.", "0.02", "0.03"],
        &["10.", "0.02", "0.04"],
        &["0.", "0.01", "0.012"],
    ];
    let text = fixed(" 2 3 2 3 2 3", &[(MACH, CL), (MACH, cd), (MACH, CM)]);
    assert_eq!(
        err(&text),
        "bad.c81 line 9, columns 1-7: expected a drag table angle of attack above the previous \
         one, 10. deg (line 8), as they must increase, found `0.`"
    );
    // Equal angles are refused too.
    let cl: &[&[&str]] = &[
        &["-10.", "-1.0", "-1.2"],
        &["0.", "0.0", "0.1"],
        &["0.", "1.0", "1.4"],
    ];
    let text = fixed(" 2 3 2 3 2 3", &[(MACH, cl), (MACH, CD), (MACH, CM)]);
    assert!(err(&text).starts_with("bad.c81 line 5, columns 1-7: expected a lift table angle"));
}

#[test]
fn bad_mach_not_increasing() {
    let text = fixed(
        " 2 3 2 3 2 3",
        &[(MACH, CL), (MACH, CD), (&["0.6", "0.3"], CM)],
    );
    assert_eq!(
        err(&text),
        "bad.c81 line 10, columns 15-21: expected a moment table Mach number above the previous \
         one, 0.6 (line 10), as they must increase, found `0.3`"
    );
    let text = "free; 2 1 1 1 1 1\n0.5 0.5\n0. 0.1 0.2\n0.3\n0. 0.0\n0.3\n0. 0.0\n";
    assert_eq!(
        err(text),
        "bad.c81 line 2, field 2 (columns 5-7): expected a lift table Mach number above the \
         previous one, 0.5 (line 2), as they must increase, found `0.5`"
    );
}
