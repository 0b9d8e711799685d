//! `rotorsim diagnose` (issue #7): find what the damper model gets wrong in measured data, name
//! the cause, extend the model and measure the gain on held-out data.
use crate::diagnose::data::periodic_derivative;
use crate::diagnose::{self, DiagnoseOptions, Measurement};
use crate::flight::FlightRecord;
use crate::hydraulics::bench::read_bench_csv;
use crate::hydraulics::DamperDeck;
use crate::io::{write_atomic, OutDir};
use anyhow::{bail, Context};
use clap::Args;
use std::path::{Path, PathBuf};

#[derive(Args, Debug)]
pub struct DiagnoseArgs {
    /// Damper deck of the baseline model (any TOML file with a [damper] table).
    #[arg(long)]
    pub deck: Option<PathBuf>,
    /// Measured bench test(s) (bench CSV of FORMATS.md, with force).
    #[arg(long)]
    pub measured: Vec<PathBuf>,
    /// Rotor deck (flight-record diagnosis; its [damper] table is the baseline unless --deck).
    #[arg(long)]
    pub rotor: Option<PathBuf>,
    /// Flight record (MCAP file or CSV stem, e.g. flightdata/c8534like).
    #[arg(long)]
    pub flight: Option<PathBuf>,
    /// Output directory (diagnosis.json, diagnosis.html).
    #[arg(long)]
    pub out: PathBuf,
    /// Write the extended model as a damper deck.
    #[arg(long)]
    pub write_deck: Option<PathBuf>,
    /// Cycles simulated per fit test (the first settles the model).
    #[arg(long, default_value_t = 3)]
    pub fit_cycles: usize,
    /// Largest RK4 sub-step of the hydraulic model [s].
    #[arg(long, default_value_t = 3.0e-5)]
    pub max_substep: f64,
}

fn flight_measurement(rec: &FlightRecord, path: &Path) -> anyhow::Result<Measurement> {
    if !rec.has_stroke() {
        bail!(
            "{}: the record has no damper stroke; diagnosing the damper through the full rotor run is not available yet (the rotor run, issue #6, does not exist): give a record with damper_stroke_m",
            path.display()
        );
    }
    let omega_deg = rec.meta.rotor_speed_deg_s();
    let s = rec.damper();
    let mut t = Vec::with_capacity(s.len());
    let mut d = Vec::with_capacity(s.len());
    let mut f = Vec::with_capacity(s.len());
    for x in s {
        t.push((x.revolution as f64 * 360.0 + x.azimuth_deg) / omega_deg);
        d.push(x.stroke_m.unwrap_or(f64::NAN));
        f.push(x.force_N);
    }
    if d.iter().any(|v| !v.is_finite()) {
        bail!("{}: some damper samples lack a stroke", path.display());
    }
    if let Some(i) = t.windows(2).position(|w| w[1] <= w[0]) {
        bail!(
            "{}: damper samples not in time order at sample {}",
            path.display(),
            i + 1
        );
    }
    let revs = rec.damper_revolutions();
    if revs.windows(2).any(|w| w[1] != w[0] + 1) {
        bail!(
            "{}: damper revolutions have gaps ({revs:?}); the stroke-driven replay needs a continuous record",
            path.display()
        );
    }
    let dt = (t[t.len() - 1] - t[0]) / (t.len() - 1) as f64;
    // The record is periodic over whole revolutions: periodic derivative of the stroke.
    let v = periodic_derivative(&d, dt);
    Ok(Measurement {
        name: path
            .file_name()
            .map_or("flight".into(), |s| s.to_string_lossy().into_owned()),
        time_s: t,
        stroke_m: d,
        force_n: f,
        velocity_m_s: v,
        period_s: 360.0 / omega_deg,
    })
}

pub fn run(args: DiagnoseArgs) -> anyhow::Result<()> {
    if args.fit_cycles < 2 {
        bail!("--fit-cycles must be >= 2 (one settles the model, the rest are compared)");
    }
    if !(args.max_substep > 0.0 && args.max_substep.is_finite()) {
        bail!("--max-substep must be a positive number of seconds");
    }
    let (deck, data, source) = match (&args.flight, args.measured.is_empty()) {
        (Some(fl), true) => {
            let deck_path = args
                .deck
                .clone()
                .or(args.rotor.clone())
                .context("--flight needs --rotor ROTOR (or --deck DECK) for the baseline damper")?;
            let deck = DamperDeck::from_file(&deck_path)?;
            let rec = FlightRecord::read(fl)?;
            let m = flight_measurement(&rec, fl)?;
            let synth = if rec.meta.synthetic { " SYNTHETIC record (labelled synthetic in its metadata)." } else { "" };
            let src = format!(
                "Flight record {} (stroke-driven replay of the damper, Omega = {} rad/s), baseline deck {}.{synth}",
                fl.display(),
                rec.meta.rotor_speed_rad_s,
                deck_path.display()
            );
            (deck, vec![m], src)
        }
        (None, false) => {
            let deck_path = args.deck.clone().context("--measured needs --deck DECK")?;
            let deck = DamperDeck::from_file(&deck_path)?;
            let data = args
                .measured
                .iter()
                .map(|p| {
                    let t = read_bench_csv(p)?;
                    Measurement::from_bench(&t)
                        .with_context(|| format!("bench file {}", p.display()))
                })
                .collect::<anyhow::Result<Vec<_>>>()?;
            let src = format!(
                "Bench tests {} (stroke-driven replay), baseline deck {}.",
                args.measured
                    .iter()
                    .map(|p| p.display().to_string())
                    .collect::<Vec<_>>()
                    .join(", "),
                deck_path.display()
            );
            (deck, data, src)
        }
        (Some(_), false) => bail!("give either --flight or --measured, not both"),
        (None, true) => bail!(
            "nothing to diagnose: give --deck DECK --measured TEST.csv [...] or --rotor ROTOR --flight RECORD"
        ),
    };
    let opts = DiagnoseOptions {
        fit_cycles: args.fit_cycles,
        max_substep_s: args.max_substep,
        ..Default::default()
    };
    let outcome = diagnose::diagnose(&deck, &data, &opts)?;
    let d = &outcome.diagnosis;
    let out = OutDir::create(&args.out)?;
    out.write(
        "diagnosis.json",
        serde_json::to_string_pretty(d)?.as_bytes(),
    )?;
    let html = diagnose::report::html(d, &outcome.curves, &source)?;
    out.write("diagnosis.html", html.as_bytes())?;
    let deck_text = format!(
        "# Extended damper deck written by `rotorsim diagnose` (cause: {}), from {}\n{}",
        d.cause,
        deck.source,
        outcome.extended.to_toml()
    );
    out.write("extended_deck.toml", deck_text.as_bytes())?;
    if let Some(p) = &args.write_deck {
        write_atomic(p, deck_text.as_bytes())?;
    }
    out.finish()?;
    println!("cause: {}", d.cause);
    for (k, v) in &d.parameters {
        println!("  {k} = {v:.6e}");
    }
    println!(
        "RMS error: baseline {:.1} N, extended {:.1} N; held-out ({}): baseline {:.1} N, extended {:.1} N, gain {:.3}",
        d.baseline_rms_N,
        d.extended_rms_N,
        d.validation.method,
        d.validation.baseline_rms_N,
        d.validation.extended_rms_N,
        d.gain
    );
    println!(
        "{:<18} {:>3} {:>14} {:>12} {:>14}",
        "candidate", "k", "BIC", "RMS [N]", "held-out [N]"
    );
    for c in &d.candidates {
        println!(
            "{:<18} {:>3} {:>14.1} {:>12.1} {:>14.1}",
            c.cause, c.k, c.bic, c.rms_N, c.held_out_rms_N
        );
    }
    for l in &d.limitations {
        println!("limitation: {l}");
    }
    println!(
        "wrote {}/diagnosis.json and diagnosis.html",
        args.out.display()
    );
    if let Some(p) = &args.write_deck {
        println!("wrote extended deck {}", p.display());
    }
    Ok(())
}
