//! Error of the sub-step integrators vs the number of sub-steps N, on the bench sweep of the
//! shipped UH-60A-like damper (docs/integrators.md). Run:
//! `cargo run --release --example hydraulics_error_vs_n`
//! Reference: SDIRK3 with N = 2048. Errors over the last cycle, relative to the peak force:
//! `peak` = max over amplitudes of |peak_N - peak_ref| / |peak_ref|,
//! `history` = max over amplitudes of max_t |F_N(t) - F_ref(t)| / |peak_ref|.
use rotorsim::hydraulics::bench::{harmonic_run, IN_TO_M};
use rotorsim::hydraulics::*;
use std::path::Path;
use std::time::Instant;

fn main() {
    let deck = DamperDeck::from_file(Path::new(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/rotors/uh60a.toml"
    )))
    .unwrap();
    let amps: Vec<f64> = [0.5, 1.0, 2.0, 3.0, 4.0, 6.0, 8.0, 10.0]
        .iter()
        .map(|v| v * IN_TO_M)
        .collect();
    let run = |scheme, n| {
        let dev = deck
            .build(
                DamperModel::Physical,
                IntegratorOptions {
                    scheme,
                    substeps: n,
                },
            )
            .unwrap();
        let t0 = Instant::now();
        let r: Vec<_> = amps
            .iter()
            .map(|&v| harmonic_run(dev.as_ref(), 27.02, v, 10, 256, true))
            .collect();
        (r, t0.elapsed().as_secs_f64())
    };
    let (reference, _) = run(Scheme::Implicit, 2048);
    let reference: Vec<_> = reference.into_iter().map(|r| r.unwrap()).collect();
    println!("| scheme | N | peak error | history error | sweep time [s] |");
    println!("|---|---|---|---|---|");
    for scheme in [Scheme::Rk4, Scheme::Implicit] {
        for n in [1, 2, 4, 8, 12, 16, 25, 50, 100] {
            let (runs, secs) = run(scheme, n);
            let (mut pe, mut he) = (0.0f64, 0.0f64);
            let mut failed = None;
            for (r, rf) in runs.iter().zip(&reference) {
                match r {
                    Err(e) => failed = Some(e.to_string()),
                    Ok(r) => {
                        let pk = rf.peak_force_pos_n;
                        pe = pe.max((r.peak_force_pos_n - pk).abs() / pk);
                        pe = pe.max((r.peak_force_neg_n - rf.peak_force_neg_n).abs() / pk);
                        let m = rf.history.force_n.len();
                        for i in m - 257..m {
                            let e = (r.history.force_n[i] - rf.history.force_n[i]).abs() / pk;
                            he = he.max(if e.is_nan() { f64::INFINITY } else { e });
                        }
                    }
                }
            }
            match failed {
                Some(e) => println!("| {scheme:?} | {n} | failed: {e} | | {secs:.3} |"),
                None => println!("| {scheme:?} | {n} | {pe:.2e} | {he:.2e} | {secs:.3} |"),
            }
        }
    }
}
