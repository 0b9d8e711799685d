//! Seed sweep of the hidden-effect diagnosis: prints one row per seed and the hit rate.
//! `cargo run --release --example diagnose_hit_rate -- [SEEDS] [CYCLES] [RATE_HZ] [FIRST_SEED] [-v]`
#[path = "../tests/diagnose_support/mod.rs"]
mod support;
use rotorsim::diagnose::{diagnose, DiagnoseOptions};

fn main() {
    let a: Vec<String> = std::env::args().collect();
    let seeds: u64 = a.get(1).and_then(|s| s.parse().ok()).unwrap_or(20);
    let cycles: usize = a.get(2).and_then(|s| s.parse().ok()).unwrap_or(4);
    let rate: f64 = a.get(3).and_then(|s| s.parse().ok()).unwrap_or(2000.0);
    let first: u64 = a.get(4).and_then(|s| s.parse().ok()).unwrap_or(0);
    let verbose = a.iter().any(|s| s == "-v");
    let base = support::nominal_deck();
    let (mut named, mut recovered, mut positive, mut covered) = (0, 0, 0, 0);
    println!("seed,true_cause,true_value,named,fitted_value,rel_error,gain,interval_lo,interval_hi,covered,hit");
    for seed in first..first + seeds {
        let h = support::draw(seed);
        let data = support::standard(&h.deck, cycles, rate, seed);
        let o = diagnose(&base, &data, &DiagnoseOptions::default()).expect("diagnosis");
        let d = &o.diagnosis;
        if verbose {
            for c in &d.candidates {
                eprintln!(
                    "  {} bic {:.1} rms {:.1} held-out {:.1} {:?}",
                    c.cause, c.bic, c.rms_N, c.held_out_rms_N, c.parameters
                );
            }
        }
        let fitted = d.parameters.get(h.param).copied().unwrap_or(f64::NAN);
        let rel = (fitted - h.value).abs() / h.value;
        let ok_name = d.cause == h.cause.name();
        let ok_par = ok_name && rel <= h.tolerance;
        named += ok_name as u32;
        recovered += ok_par as u32;
        positive += (ok_name && d.gain > 0.0) as u32;
        // The 95% interval of the recovered parameter covers the truth.
        let [lo, hi] = d
            .parameter_intervals
            .get(h.param)
            .copied()
            .unwrap_or([f64::NAN, f64::NAN]);
        let cov = ok_name && lo <= h.value && h.value <= hi;
        covered += cov as u32;
        println!(
            "{seed},{},{:.4e},{},{:.4e},{:.3},{:.3},{:.4e},{:.4e},{},{}",
            h.cause.name(),
            h.value,
            d.cause,
            fitted,
            rel,
            d.gain,
            lo,
            hi,
            cov,
            ok_par && d.gain > 0.0
        );
    }
    println!(
        "seeds {seeds}: cause named {named}/{seeds}, parameter within tolerance {recovered}/{seeds}, named with positive held-out gain {positive}/{seeds}, 95% interval covers the truth {covered}/{seeds}"
    );
}
