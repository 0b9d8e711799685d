//! The command line an engineer reads: every `--help` says what the command writes and the
//! exit status; one name per concept (old spellings still accepted); plain progress lines
//! when stderr is not a terminal.
use std::process::Command;

mod support;
use support::{root, tmp};

fn rotorsim(args: &[&str]) -> std::process::Output {
    Command::new(env!("CARGO_BIN_EXE_rotorsim"))
        .args(args)
        .current_dir(root())
        .output()
        .unwrap()
}

#[test]
fn every_help_says_what_the_command_writes_and_the_exit_status() {
    for cmd in [
        "run",
        "bench",
        "diagnose",
        "static",
        "dynamic",
        "modes",
        "verify",
        "convert",
        "inspect",
        "expand",
        "sweep",
        "sensitivity",
    ] {
        let o = rotorsim(&[cmd, "--help"]);
        assert!(o.status.success(), "{cmd}");
        let h = String::from_utf8_lossy(&o.stdout);
        assert!(h.contains("Writes"), "{cmd} --help: no outputs\n{h}");
        assert!(
            h.contains("Exit status: 0"),
            "{cmd} --help: no exit status\n{h}"
        );
    }
    let top = String::from_utf8_lossy(&rotorsim(&["--help"]).stdout).to_string();
    assert!(top.contains("Exit status: 0"), "{top}");
    // a command line that cannot be parsed exits 2, a refused input 1
    assert_eq!(
        rotorsim(&["run", "--no-such-option"]).status.code(),
        Some(2)
    );
    assert_eq!(
        rotorsim(&["run", "--damper", "magic", "--out", "/nonexistent/x"])
            .status
            .code(),
        Some(1)
    );
}

#[test]
fn bench_help_lists_its_files_and_options() {
    let o = rotorsim(&["bench", "--help"]);
    let h = String::from_utf8_lossy(&o.stdout);
    for want in [
        "bench.html",
        "bench_summary.csv",
        "history_v<v>m_s.csv",
        "peaks.csv",
        "replay_summary.csv",
        "--output-rate <HZ>",
        "--skip-cycles <N>",
    ] {
        assert!(h.contains(want), "bench --help lacks {want}\n{h}");
    }
}

#[test]
fn one_name_per_concept_with_the_old_spellings_kept() {
    // --damper-deck, --scheme and --model mean the same in run, bench and diagnose; the old
    // spellings (--deck, --integrator, --rotor-model) parse to the same options: each call
    // below gets past the parser (exit 1 with the option's own message, not clap's 2).
    let out = tmp("cli-names");
    let o = out.to_str().unwrap();
    let deck = "flightdata/damper_nominal.toml";
    for (args, want) in [
        (
            vec![
                "bench",
                "--damper-deck",
                deck,
                "--scheme",
                "euler",
                "--out",
                o,
            ],
            "euler",
        ),
        (
            vec!["bench", "--deck", deck, "--integrator", "euler", "--out", o],
            "euler",
        ),
        (
            vec![
                "diagnose",
                "--rotor",
                "rotors/uh60a.toml",
                "--flight",
                "flightdata/c8534like",
                "--model",
                "elastic",
                "--out",
                o,
            ],
            "--model: unknown rotor model 'elastic'",
        ),
        (
            vec![
                "diagnose",
                "--rotor",
                "rotors/uh60a.toml",
                "--flight",
                "flightdata/c8534like",
                "--rotor-model",
                "elastic",
                "--out",
                o,
            ],
            "--model: unknown rotor model 'elastic'",
        ),
        (
            vec!["diagnose", "--damper-deck", deck, "--out", o],
            "nothing to diagnose",
        ),
        (
            vec!["diagnose", "--deck", deck, "--out", o],
            "nothing to diagnose",
        ),
    ] {
        let r = rotorsim(&args);
        let e = String::from_utf8_lossy(&r.stderr);
        assert_eq!(r.status.code(), Some(1), "{args:?}: {e}");
        assert!(e.contains(want), "{args:?}: {e}");
    }
    let _ = std::fs::remove_dir_all(&out);
}

#[test]
fn progress_is_plain_lines_when_stderr_is_not_a_terminal() {
    let out = tmp("cli-plain-progress");
    let r = rotorsim(&[
        "run",
        "--model",
        "rigid",
        "--damper",
        "linear",
        "--out",
        out.to_str().unwrap(),
    ]);
    assert!(r.status.success());
    let e = String::from_utf8_lossy(&r.stderr);
    // the first revolution is reported at once, the end always; no terminal control codes
    assert!(
        e.contains("linear: revolution 1 of at most 100, periodicity"),
        "{e}"
    );
    assert!(e.contains("linear: done after"), "{e}");
    assert!(!e.contains('\u{1b}'), "{e}");
    let s = String::from_utf8_lossy(&r.stdout);
    assert!(s.contains("verdict: ") || s.contains("open: "), "{s}");
    assert!(s.contains("report.html"), "{s}");
    let _ = std::fs::remove_dir_all(&out);
}
