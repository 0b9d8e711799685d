//! A closed or full standard output or error never panics a command: `rotorsim ... | head -0`
//! (the reader goes away: not an error) and `rotorsim ... > /dev/full` (the printed output is
//! lost: a plain error, exit 1), for every command that prints. Structurally, src/cli prints
//! only through its never-panicking macros (checked on the sources).
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};

mod support;
use support::tmp;

fn repo(p: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join(p)
}

/// Quick invocations of every command that prints (long ones shortened); `out` for results.
fn commands(out: &Path) -> Vec<Vec<String>> {
    let s = |v: &[&str]| v.iter().map(|x| x.to_string()).collect::<Vec<_>>();
    let o = |name: &str| out.join(name).display().to_string();
    let deck = repo("docs/examples/cantilever.toml").display().to_string();
    let rotor = repo("rotors/uh60a.toml").display().to_string();
    let rec = repo("flightdata/c8534like").display().to_string();
    vec![
        s(&["inspect", &rec]),
        s(&["expand", "--rotor", &rotor]),
        s(&["static", &deck, "--out", &o("static")]),
        s(&["dynamic", &deck, "--out", &o("dynamic")]),
        s(&["modes", &deck, "--out", &o("modes")]),
        s(&["convert", &rec, &o("rec.mcap")]),
        s(&[
            "bench",
            "--deck",
            &rotor,
            "--damper",
            "linear",
            "--peak-velocity",
            "1",
            "--cycles",
            "2",
            "--out",
            &o("bench"),
        ]),
        s(&[
            "run",
            "--model",
            "sdof",
            "--rotor",
            &rotor,
            "--flight",
            &rec,
            "--revs",
            "3",
            "--periodic",
            "march",
            "--damper",
            "linear",
            "--out",
            &o("run"),
        ]),
        // an error goes to standard error
        s(&["inspect", &o("no_such_record")]),
    ]
}

fn no_panic(what: &str, o: &std::process::Output) {
    let e = String::from_utf8_lossy(&o.stderr);
    assert!(
        o.status.code().is_some() && o.status.code() != Some(101) && !e.contains("panicked"),
        "{what}: {:?}\n{e}",
        o.status
    );
}

#[test]
fn a_closed_standard_output_or_error_never_panics() {
    let out = tmp("streams_closed");
    for args in commands(&out) {
        // the reader of standard output goes away at once (as `| head -0`)
        let mut child = Command::new(env!("CARGO_BIN_EXE_rotorsim"))
            .args(&args)
            .stdout(Stdio::piped())
            .stderr(Stdio::piped())
            .spawn()
            .unwrap();
        drop(child.stdout.take());
        let o = child.wait_with_output().unwrap();
        no_panic(&format!("{args:?} | head -0"), &o);
        let fails = args[0] == "inspect" && args[1].contains("no_such");
        assert_eq!(o.status.success(), !fails, "{args:?}: {:?}", o.status);
        // and the reader of standard error
        let mut child = Command::new(env!("CARGO_BIN_EXE_rotorsim"))
            .args(&args)
            .stdout(Stdio::null())
            .stderr(Stdio::piped())
            .spawn()
            .unwrap();
        drop(child.stderr.take());
        let status = child.wait().unwrap();
        assert!(
            status.code().is_some() && status.code() != Some(101),
            "{args:?} 2>closed: {status:?}"
        );
    }
    let _ = std::fs::remove_dir_all(&out);
}

#[test]
fn a_full_standard_output_fails_plainly_and_a_full_standard_error_never_panics() {
    if !Path::new("/dev/full").exists() {
        return;
    }
    let out = tmp("streams_full");
    for args in commands(&out) {
        let full = || {
            std::fs::OpenOptions::new()
                .write(true)
                .open("/dev/full")
                .unwrap()
        };
        let o = Command::new(env!("CARGO_BIN_EXE_rotorsim"))
            .args(&args)
            .stdout(full())
            .stderr(Stdio::piped())
            .output()
            .unwrap();
        no_panic(&format!("{args:?} > /dev/full"), &o);
        let e = String::from_utf8_lossy(&o.stderr);
        // every one of these commands prints something: what it printed is lost
        assert!(!o.status.success(), "{args:?} > /dev/full: {:?}", o.status);
        if !(args[0] == "inspect" && args[1].contains("no_such")) {
            assert!(e.contains("cannot write standard output"), "{args:?}: {e}");
        }
        let o = Command::new(env!("CARGO_BIN_EXE_rotorsim"))
            .args(&args)
            .stdout(Stdio::null())
            .stderr(full())
            .output()
            .unwrap();
        no_panic(&format!("{args:?} 2> /dev/full"), &o);
    }
    let _ = std::fs::remove_dir_all(&out);
}

#[test]
fn the_command_line_prints_only_through_the_never_panicking_macros() {
    for entry in std::fs::read_dir(repo("src/cli")).unwrap() {
        let p = entry.unwrap().path();
        let text = std::fs::read_to_string(&p).unwrap();
        for (i, line) in text.lines().enumerate() {
            let code = line.split("//").next().unwrap_or("");
            for m in [
                "println!(",
                "eprintln!(",
                " print!(",
                " eprint!(",
                "(print!(",
                "dbg!(",
            ] {
                assert!(
                    !code.contains(m),
                    "{}:{}: `{m}` panics on a closed or full stream; use outln!/errln!",
                    p.display(),
                    i + 1
                );
            }
        }
    }
}
