//! The naming rule on SYNTHETIC campaigns of the nominal damper itself (no physical effect):
//! a force recorded a fifth of a millisecond late, or averaged over each sample interval (half a
//! sample late), is a sampling convention the diagnosis cannot know, not a fault of the
//! acquisition: `force_lag` fits it and passes the BIC and held-out tests, but its interval lies
//! within the timing uncertainty, so it is listed as considered, not supported, and not named.
//! A lag of 1.3 ms is a fault and is named.
//! Nor is a physical cause that tilts the loop as a lag does (a mount of ~1e9 N/m) named in its
//! place: a cause must beat the baseline aligned by the best lag within the timing band.
//! The lags are fitted 13 us above the lag put in (data made on a grid ten times finer, or
//! with the stroke shifted), within the tolerance.
mod diagnose_support;
use diagnose_support as support;
use rotorsim::diagnose::acquisition::Fault;
use rotorsim::diagnose::fit::simulate;
use rotorsim::diagnose::{diagnose, Cause, DiagnoseOptions, Diagnosis, Measurement};
use rotorsim::hydraulics::bench::IN_TO_M;

const RATE_HZ: f64 = 2000.0;
/// Fine samples per recorded sample (the force averaged over the sample interval).
const FINE: usize = 10;

/// How the force sample at `t_k` is taken from the damper's force.
#[derive(Clone, Copy)]
enum Sampling {
    /// At `t_k - lag`.
    Late(f64),
    /// Averaged over `[t_k - h, t_k]` (trapezoid on a grid ten times finer).
    Averaged,
}

/// Three harmonic tests (2, 4, 8 in/s, 4 cycles, 2 kHz) of the nominal damper, the force
/// sampled as `how`, plus Gaussian noise of 0.5% of the campaign's peak force.
fn campaign(how: Sampling, seed: u64) -> Vec<Measurement> {
    let deck = support::nominal_deck();
    let w = support::OMEGA;
    let period = 2.0 * std::f64::consts::PI / w;
    let n = (4.0 * period * RATE_HZ).round() as usize + 1;
    let h = 1.0 / RATE_HZ;
    let harmonic = |name: String, a: f64, t: Vec<f64>, lag: f64| Measurement {
        name,
        stroke_m: t.iter().map(|t| a * (w * (t - lag)).sin()).collect(),
        velocity_m_s: t.iter().map(|t| a * w * (w * (t - lag)).cos()).collect(),
        time_s: t,
        force_n: vec![],
        period_s: period,
        oil_temperature_k: None,
    };
    let mut tests: Vec<Measurement> = [2.0, 4.0, 8.0]
        .iter()
        .map(|&v| {
            let a = v * IN_TO_M / w;
            let name = format!("synthetic_{v}in_s");
            let t: Vec<f64> = (0..n).map(|k| k as f64 * h).collect();
            let force = match how {
                Sampling::Late(lag) => {
                    let m = harmonic(name.clone(), a, t.clone(), lag);
                    let mut f = Vec::new();
                    simulate(&deck, &m, n, 1e-5, &mut f).unwrap();
                    f
                }
                Sampling::Averaged => {
                    let nf = (n - 1) * FINE + 1;
                    let tf = (0..nf).map(|j| j as f64 * h / FINE as f64).collect();
                    let m = harmonic(name.clone(), a, tf, 0.0);
                    let mut f = Vec::new();
                    simulate(&deck, &m, nf, 1e-5, &mut f).unwrap();
                    (0..n)
                        .map(|k| {
                            if k == 0 {
                                return f[0];
                            }
                            let s = &f[(k - 1) * FINE..=k * FINE];
                            (s.iter().sum::<f64>() - 0.5 * (s[0] + s[FINE])) / FINE as f64
                        })
                        .collect()
                }
            };
            Measurement {
                force_n: force,
                ..harmonic(name, a, t, 0.0)
            }
        })
        .collect();
    let peak = tests
        .iter()
        .flat_map(|m| m.force_n.iter())
        .fold(0.0f64, |a, f| a.max(f.abs()));
    let mut rng = support::Rng::new(seed);
    for m in &mut tests {
        for f in &mut m.force_n {
            *f += 0.005 * peak * rng.normal();
        }
    }
    tests
}

/// The faults and the two physical causes that tilt the force-stroke loop as a lag does.
fn options() -> DiagnoseOptions {
    DiagnoseOptions {
        candidates: vec![Cause::EntrainedAir, Cause::MountCompliance],
        ..DiagnoseOptions::default()
    }
}

fn run(how: Sampling) -> Diagnosis {
    let o = diagnose(&support::nominal_deck(), &campaign(how, 11), &options()).unwrap();
    let html = rotorsim::diagnose::report::html(&o.diagnosis, &o.curves, "SYNTHETIC").unwrap();
    assert_eq!(
        html.contains("Considered, not supported"),
        !o.diagnosis.considered_not_supported.is_empty()
    );
    let d = o.diagnosis;
    let lag = d
        .candidates
        .iter()
        .find(|c| c.cause == "force_lag")
        .unwrap();
    eprintln!(
        "cause {} {:?}; force_lag {:?} {:?} bic {:.1} held {:.1} (baseline {:.1}, {:.1}); {}",
        d.cause,
        d.parameters,
        lag.parameters,
        lag.intervals,
        lag.bic,
        lag.held_out_rms_N,
        d.baseline_bic,
        d.validation.baseline_rms_N,
        d.criterion_naming
    );
    eprintln!(
        "considered, not supported: {:#?}",
        d.considered_not_supported
    );
    // Whatever is named, the data support it.
    for p in d.named_parameters_supported() {
        assert!(
            p.supported,
            "{} named without support: {}",
            p.name, p.reason
        );
    }
    d
}

/// The lag is within the timing uncertainty: fitted, passing the old tests, not named.
fn lag_by_convention_is_not_named(d: &Diagnosis, expected_s: f64) {
    assert!(
        !d.cause.split('+').any(|c| c == Fault::Lag.name()),
        "{}: {:#?}",
        d.cause,
        d.considered_not_supported
    );
    let lag = d
        .candidates
        .iter()
        .find(|c| c.cause == "force_lag")
        .unwrap();
    let (x, iv) = (lag.parameters["lag_s"], lag.intervals["lag_s"]);
    assert!(
        (x - expected_s).abs() < 0.05e-3,
        "lag {x} against {expected_s}"
    );
    // Zero is outside its interval: without the timing uncertainty it would be a fault.
    assert!(iv[0] > 0.0, "{iv:?}");
    // Nothing is named: not the lag, nor a physical cause that only mimics it (a very stiff
    // mount): the reference every cause must beat is the baseline aligned within the band.
    assert_eq!(d.cause, "none", "{:#?}", d.candidates);
    assert!(d.criterion.contains("aligned"), "{}", d.criterion);
    // Where the lag passes the tests against the unaligned baseline it is listed as such.
    if let Some(ns) = d
        .considered_not_supported
        .iter()
        .find(|n| n.name == "force_lag")
    {
        assert_eq!(ns.role, "cause");
        assert_eq!(ns.parts_not_supported, ["force_lag"]);
        assert!(ns.reason.contains("timing uncertainty"), "{}", ns.reason);
        assert!(
            matches!(ns.no_effect["lag_s"], rotorsim::diagnose::NoEffect::Band { lo, hi } if hi > 0.25e-3 && lo == -hi)
        );
        let j = serde_json::to_value(d).unwrap();
        assert_eq!(
            j["considered_not_supported"][0]["no_effect"]["lag_s"]["kind"],
            "band"
        );
    }
}

#[test]
fn a_fifth_of_a_millisecond_is_a_sampling_convention_not_a_fault() {
    let d = run(Sampling::Late(0.2e-3));
    lag_by_convention_is_not_named(&d, 0.2e-3);
}

#[test]
fn a_force_averaged_over_the_sample_interval_is_not_a_lag() {
    let d = run(Sampling::Averaged);
    lag_by_convention_is_not_named(&d, 0.5 / RATE_HZ);
}

#[test]
fn a_lag_of_1_3_ms_is_named() {
    let d = run(Sampling::Late(1.3e-3));
    assert_eq!(d.cause, "force_lag", "{:#?}", d.candidates);
    let x = d.parameters["lag_s"];
    assert!((x - 1.3e-3).abs() < 0.05e-3, "{x}");
    let p = d.named_parameters_supported();
    assert_eq!(p.len(), 1);
    assert!(p[0].supported && p[0].reason.contains("excludes"), "{p:?}");
    assert!(
        !d.considered_not_supported
            .iter()
            .any(|n| n.name == "force_lag"),
        "{:#?}",
        d.considered_not_supported
    );
}
