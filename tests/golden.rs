//! Golden outputs of the README's commands: each command of the quick start and of the "Other
//! commands" table runs as written (its `out/` folder in a temporary one) and its result folder
//! must match tests/golden/readme/<case>.txt, bit for bit or, for a case that
//! tests/golden/DIFFERENCES.md names with its reason, within 1e-9 relative
//! (tests/golden_support/mod.rs says what is compared). A case is named by its `--out` folder,
//! so a command may change how it asks for a result without losing its golden.
//! `ROTORSIM_GOLDEN_UPDATE=1 cargo test --release --test golden` writes the goldens.
//! Time: about 3 min in release on 2 cores, most of it the sensitivity study.
use std::path::{Path, PathBuf};
use std::process::Command;

mod golden_support;
mod support;
use support::{root, tmp};

/// The README's commands (`cargo run --release -- ...`), the quick start's first.
fn readme_commands() -> Vec<Vec<String>> {
    let text = std::fs::read_to_string(root().join("README.md")).unwrap();
    let prefix = "cargo run --release -- ";
    let mut out = vec![];
    for line in text.lines() {
        if let Some(rest) = line.trim().strip_prefix(prefix) {
            out.push(rest.split_whitespace().map(String::from).collect());
        }
    }
    for span in text.split('`').skip(1).step_by(2) {
        if let Some(rest) = span.strip_prefix(prefix) {
            out.push(rest.split_whitespace().map(String::from).collect());
        }
    }
    out.retain(|a: &Vec<String>| a.first().map(String::as_str) != Some("help"));
    out
}

/// A command's case: its `--out` folder below out/, or the subcommand for one that prints.
fn case_of(args: &[String]) -> String {
    args.iter()
        .position(|a| a == "--out")
        .and_then(|i| args.get(i + 1))
        .and_then(|o| o.strip_prefix("out/"))
        .map(String::from)
        .unwrap_or_else(|| args[0].clone())
}

/// Every case the goldens hold; the README's commands must be exactly these.
const CASES: [&str; 19] = [
    "run",
    "rigid",
    "orifice",
    "rotor",
    "airframe",
    "computed",
    "hybrid",
    "hybrid_periodic",
    "bench",
    "diag",
    "sweep",
    "sensitivity",
    "hammond",
    "uh60a_gr",
    "uh60a_ar",
    "tm4760",
    "decay",
    "verify",
    "inspect",
];

#[test]
fn every_readme_command_has_a_golden_case() {
    let mut found: Vec<String> = readme_commands().iter().map(|a| case_of(a)).collect();
    found.sort();
    let mut want: Vec<String> = CASES.iter().map(|s| s.to_string()).collect();
    want.sort();
    assert_eq!(found, want, "README commands against the golden cases");
}

/// Runs the README command of `case` and checks its result against the golden.
fn golden(case: &str) {
    let args = readme_commands()
        .into_iter()
        .find(|a| case_of(a) == case)
        .unwrap_or_else(|| panic!("no README command writes out/{case}"));
    let work = tmp(&format!("golden-{case}"));
    let args: Vec<String> = args
        .iter()
        .map(|a| match a.strip_prefix("out/") {
            Some(rest) => work.join(rest).display().to_string(),
            None => a.clone(),
        })
        .collect();
    let mut c = Command::new(golden_support::bin());
    c.current_dir(root()).args(&args);
    for v in [
        "SLURM_ARRAY_TASK_ID",
        "SLURM_ARRAY_TASK_COUNT",
        "SLURM_CPUS_PER_TASK",
    ] {
        c.env_remove(v);
    }
    let o = c.output().unwrap();
    assert!(
        o.status.success(),
        "rotorsim {}: {}",
        args.join(" "),
        String::from_utf8_lossy(&o.stderr)
    );
    let out: PathBuf = match args.iter().position(|a| a == "--out") {
        Some(i) => PathBuf::from(&args[i + 1]),
        None => {
            // a command that prints: its output is the result
            let d = work.join("stdout");
            std::fs::create_dir_all(&d).unwrap();
            std::fs::write(d.join("stdout.txt"), &o.stdout).unwrap();
            d
        }
    };
    let paths = golden_support::Paths::new(&out, &work);
    if let Err(e) = golden_support::check(&format!("readme/{case}"), &out, &paths) {
        panic!("{e}");
    }
    let _ = std::fs::remove_dir_all(Path::new(&work));
}

macro_rules! cases {
    ($($name:ident),*) => {
        $(#[test]
        fn $name() {
            golden(stringify!($name));
        })*
    };
}

cases!(
    run,
    rigid,
    orifice,
    rotor,
    airframe,
    computed,
    hybrid,
    hybrid_periodic,
    bench,
    diag,
    sweep,
    sensitivity,
    hammond,
    uh60a_gr,
    uh60a_ar,
    tm4760,
    decay,
    verify,
    inspect
);

/// The comparison itself: the same listing passes bit for bit, a change of 1e-12 relative is
/// within, a change of 1e-6 relative, a missing file or a changed text is an error.
#[test]
fn the_comparison_tells_bit_for_bit_within_and_changed() {
    let dir = tmp("golden-compare");
    let f = dir.join("a.csv");
    let write = |x: f64, label: &str| {
        std::fs::write(&f, format!("t_s,F_N,label\n0,{x},{label}\n1,2.5,{label}\n")).unwrap();
        golden_support::listing(&dir, &golden_support::Paths::new(&dir, &dir))
    };
    let golden = write(1234.5, "a");
    let same = golden_support::compare(&golden, &write(1234.5, "a"));
    assert!(same.within.is_empty() && same.errors.is_empty());
    let close = golden_support::compare(&golden, &write(1234.5 * (1.0 + 1e-12), "a"));
    assert_eq!(close.within, ["a.csv"]);
    assert!(close.errors.is_empty(), "{:?}", close.errors);
    let far = golden_support::compare(&golden, &write(1234.5 * (1.0 + 1e-6), "a"));
    assert!(!far.errors.is_empty());
    let text = golden_support::compare(&golden, &write(1234.5, "b"));
    assert!(!text.errors.is_empty());
    std::fs::write(dir.join("b.json"), "{\"x\": 1.0}").unwrap();
    let extra = golden_support::listing(&dir, &golden_support::Paths::new(&dir, &dir));
    std::fs::remove_file(dir.join("b.json")).unwrap();
    let missing = golden_support::compare(&extra, &write(1234.5, "a"));
    assert!(missing.errors.iter().any(|e| e.contains("b.json")));
}
