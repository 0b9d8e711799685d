//! The command line's defaults are the library jobs' own: a job's `new` (what library callers
//! start from) and its settings type's defaults (the command line, sweep plans, Python) must
//! ask for the same job, or the two would drift apart.
use clap::Parser;
use rotorsim::cli::{Cli, Command};

fn parse(args: &[&str]) -> Command {
    Cli::try_parse_from(std::iter::once("rotorsim").chain(args.iter().copied()))
        .unwrap()
        .command
}

#[test]
fn bench_defaults_are_the_jobs() {
    let Command::Bench(a) = parse(&["bench", "--damper-deck", "d.toml", "--out", "o"]) else {
        panic!("not a bench command");
    };
    let job = rotorsim::checks::bench::BenchJob::new("d.toml", "o");
    assert_eq!(
        format!("{:?}", a.settings.job(&a.out).unwrap()),
        format!("{job:?}")
    );
}

#[test]
fn stability_defaults_are_the_jobs() {
    let Command::Stability(a) = parse(&[
        "stability",
        "--rotor",
        "r.toml",
        "--speeds",
        "1:2:1",
        "--out",
        "o",
    ]) else {
        panic!("not a stability command");
    };
    let job = rotorsim::resonance::StabilityJob::new("r.toml", "1:2:1", "o");
    assert_eq!(
        format!("{:?}", a.settings.job(&a.out).unwrap()),
        format!("{job:?}")
    );
}

#[test]
fn modes_defaults_are_the_jobs() {
    let Command::Modes(a) = parse(&["modes", "--rotor", "r.toml", "--out", "o"]) else {
        panic!("not a modes command");
    };
    let job = rotorsim::checks::modes::ModesJob {
        rotor: Some("r.toml".into()),
        ..rotorsim::checks::modes::ModesJob::new("o")
    };
    assert_eq!(
        format!("{:?}", a.settings.job(&a.out).unwrap()),
        format!("{job:?}")
    );
}

#[test]
fn diagnose_defaults_are_the_jobs() {
    let Command::Diagnose(a) = parse(&["diagnose", "--out", "o"]) else {
        panic!("not a diagnose command");
    };
    let cfg = rotorsim::diagnose::pipeline::Config::new("o");
    assert_eq!(format!("{:?}", a.job()), format!("{cfg:?}"));
}
