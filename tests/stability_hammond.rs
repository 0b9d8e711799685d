//! Hammond 1974 (data/stability/hammond1974.md): the unstable speed range with all lag
//! dampers working (Coleman sweep, checked by Floquet of the same rotor: the paper's figure
//! is not available), and with blade 4's damper inoperative (Floquet growth rates against a
//! log-decrement fit of the periodic system's time response).
use rotorsim::stability::{LagRotor, Mode};
use std::f64::consts::PI;

mod support;
use std::time::Instant;

/// data/stability/hammond1974.md (MBDyn tests/Hammond/GR_MBDyn/GR_rotor.mbd).
fn hammond(out: Option<usize>) -> LagRotor {
    support::hammond_rotor(out)
}

/// No rotor speed range in the MBDyn folder: 1-40 rad/s brackets both regressing-lag /
/// airframe coincidences (about 17 and 26 rad/s).
const SWEEP_RAD_S: (f64, f64, f64) = (1.0, 40.0, 0.05);
const STEPS_PER_REV: usize = 600;

fn max_growth(modes: &[Mode]) -> &Mode {
    modes
        .iter()
        .max_by(|a, b| a.growth_rate_per_s.total_cmp(&b.growth_rate_per_s))
        .unwrap()
}

/// Speeds where `g` changes sign on the sweep grid, refined by bisection.
fn crossings(g: impl Fn(f64) -> f64, step: f64) -> Vec<(f64, bool)> {
    let (lo, hi, _) = SWEEP_RAD_S;
    let n = ((hi - lo) / step).round() as usize;
    let mut out = vec![];
    let mut prev = (lo, g(lo));
    for i in 1..=n {
        let w = lo + i as f64 * step;
        let gw = g(w);
        if (prev.1 > 0.0) != (gw > 0.0) {
            let (mut a, mut b) = (prev.0, w);
            let ga = prev.1;
            while b - a > 1e-9 {
                let m = 0.5 * (a + b);
                if (g(m) > 0.0) == (ga > 0.0) {
                    a = m;
                } else {
                    b = m;
                }
            }
            out.push((0.5 * (a + b), gw > 0.0));
        }
        prev = (w, gw);
    }
    out
}

fn ranges(cross: &[(f64, bool)], starts_unstable: bool) -> Vec<(f64, f64)> {
    let mut out = vec![];
    let mut open = starts_unstable.then_some(SWEEP_RAD_S.0);
    for &(w, to_unstable) in cross {
        if to_unstable {
            open = Some(w);
        } else if let Some(a) = open.take() {
            out.push((a, w));
        }
    }
    if let Some(a) = open {
        out.push((a, SWEEP_RAD_S.1));
    }
    out
}

#[test]
fn all_dampers_working_coleman_range_checked_by_floquet() {
    let t0 = Instant::now();
    let r = hammond(None);
    let g = |w: f64| max_growth(&r.coleman_eigenvalues(w).unwrap()).growth_rate_per_s;
    let cross = crossings(g, SWEEP_RAD_S.2);
    let rs = ranges(&cross, g(SWEEP_RAD_S.0) > 0.0);
    println!("Hammond, all dampers: unstable ranges (Coleman) {rs:?} rad/s");
    let (lo, hi, step) = SWEEP_RAD_S;
    let worst = (0..=((hi - lo) / step).round() as usize)
        .map(|i| lo + i as f64 * step)
        .map(|w| (w, r.coleman_eigenvalues(w).unwrap()))
        .max_by(|a, b| {
            max_growth(&a.1)
                .growth_rate_per_s
                .total_cmp(&max_growth(&b.1).growth_rate_per_s)
        })
        .unwrap();
    let m = max_growth(&worst.1);
    println!(
        "  least stable on the sweep: {} at {:.2} rad/s, growth {:+.5} 1/s, damping ratio {:+.5}",
        m.label, worst.0, m.growth_rate_per_s, m.damping_ratio
    );
    // The ground-resonance candidate: the least damped regressing-lag mode near the airframe
    // coincidences (10-40 rad/s).
    let reg = (0..=600)
        .map(|i| 10.0 + 0.05 * i as f64)
        .filter_map(|w| {
            let modes = r.coleman_eigenvalues(w).unwrap();
            let m = modes
                .into_iter()
                .filter(|m| m.label.as_str() == "regressing lag")
                .min_by(|a, b| a.damping_ratio.total_cmp(&b.damping_ratio))?;
            Some((w, m))
        })
        .min_by(|a, b| a.1.damping_ratio.total_cmp(&b.1.damping_ratio))
        .unwrap();
    println!(
        "  least damped regressing lag (10-40 rad/s): {:.2} rad/s, {:.4} Hz, damping ratio {:+.5}",
        reg.0, reg.1.frequency_hz, reg.1.damping_ratio
    );
    // Independent check: the Floquet analysis of the same rotor in individual blade
    // coordinates. At each crossing its largest growth rate is zero, and it has the Coleman
    // sign either side; with no crossing, it agrees in sign on a 1 rad/s grid.
    let gf = |w: f64| max_growth(&r.floquet(w, STEPS_PER_REV).unwrap()).growth_rate_per_s;
    for &(w, to_unstable) in &cross {
        let scale = r
            .coleman_eigenvalues(w)
            .unwrap()
            .iter()
            .map(|m| m.eigenvalue.norm())
            .fold(0.0, f64::max);
        assert!(
            gf(w).abs() < 1e-6 * scale,
            "Floquet growth at the crossing {w}: {}",
            gf(w)
        );
        assert_eq!(gf(w + 1e-3) > 0.0, to_unstable);
        assert_eq!(gf(w - 1e-3) > 0.0, !to_unstable);
    }
    for i in 0..=39 {
        let w = 1.0 + i as f64;
        assert_eq!(gf(w) > 0.0, g(w) > 0.0, "sign at {w} rad/s");
        assert!(
            (gf(w) - g(w)).abs() < 1e-6 * g(w).abs().max(1e-3),
            "{w}: {} vs {}",
            gf(w),
            g(w)
        );
    }
    println!("  ({:.2} s)", t0.elapsed().as_secs_f64());
}

/// Growth rate from the peaks of `|x|`: the largest `|x|` in each window of `window_s`, a
/// least-squares line through their logarithms against time.
fn log_decrement_fit(t: &[f64], x: &[f64], from_s: f64, window_s: f64) -> f64 {
    let mut pts: Vec<(f64, f64)> = vec![];
    let mut i = t.iter().position(|&ti| ti >= from_s).unwrap();
    while i < t.len() {
        let end = t[i] + window_s;
        let mut best = (t[i], 0.0f64);
        while i < t.len() && t[i] < end {
            if x[i].abs() > best.1 {
                best = (t[i], x[i].abs());
            }
            i += 1;
        }
        if i < t.len() {
            pts.push((best.0, best.1.ln()));
        }
    }
    let n = pts.len() as f64;
    let (st, sy) = pts.iter().fold((0.0, 0.0), |a, p| (a.0 + p.0, a.1 + p.1));
    let (mt, my) = (st / n, sy / n);
    let (num, den) = pts.iter().fold((0.0, 0.0), |a, p| {
        (a.0 + (p.0 - mt) * (p.1 - my), a.1 + (p.0 - mt) * (p.0 - mt))
    });
    num / den
}

#[test]
fn one_damper_inoperative_floquet_vs_time_response() {
    let t0 = Instant::now();
    let r = hammond(Some(3));
    let g = |w: f64| max_growth(&r.floquet(w, STEPS_PER_REV).unwrap()).growth_rate_per_s;
    // Coarser grid than the Coleman sweep: each Floquet point is a continuation in 8 stages.
    let cross = crossings(g, 0.25);
    let rs = ranges(&cross, g(SWEEP_RAD_S.0) > 0.0);
    println!("  ({:.2} s)", t0.elapsed().as_secs_f64());
    println!("Hammond, blade 4 damper inoperative: unstable ranges (Floquet) {rs:?} rad/s");
    assert!(
        !rs.is_empty(),
        "an inoperative damper should open an unstable zone"
    );
    let (a, b) = rs
        .iter()
        .copied()
        .max_by(|p, q| (p.1 - p.0).total_cmp(&(q.1 - q.0)))
        .unwrap();
    // Convergence of the monodromy integration: 600 against 4800 RK4 steps per revolution.
    let mid = 0.5 * (a + b);
    let (coarse, fine) = (
        r.floquet(mid, STEPS_PER_REV).unwrap(),
        r.floquet(mid, 8 * STEPS_PER_REV).unwrap(),
    );
    let conv = coarse
        .iter()
        .zip(&fine)
        .map(|(c, f)| (c.eigenvalue - f.eigenvalue).norm() / f.eigenvalue.norm())
        .fold(0.0, f64::max);
    println!("  Floquet at {mid:.3} rad/s, {STEPS_PER_REV} vs {} steps/rev: max relative change {conv:.1e}", 8 * STEPS_PER_REV);
    assert!(conv < 1e-8);
    let mut worst: f64 = 0.0;
    for i in 0..10 {
        let w = a + (b - a) * (0.1 + 0.8 * i as f64 / 9.0);
        let modes = r.floquet(w, STEPS_PER_REV).unwrap();
        let m = max_growth(&modes);
        let second = modes
            .iter()
            .map(|o| o.growth_rate_per_s)
            .filter(|&s| s < m.growth_rate_per_s - 1e-9)
            .fold(f64::MIN, f64::max);
        let sigma = m.growth_rate_per_s;
        let period = 2.0 * PI / w;
        // Long enough for the other modes to fade (e^-12) and the fit to span e^30 of growth.
        let settle = 12.0 / (sigma - second);
        let fit = 30.0 / sigma;
        let mut init = vec![0.0; r.state_len()];
        init[r.x_index().unwrap()] = 0.1; // x0 of the MBDyn deck
        let resp = r
            .time_response(w, &init, settle + fit, period / 128.0)
            .unwrap();
        let x = resp.series(r.x_index().unwrap());
        let window = 3.0
            * period
                .max(2.0 * PI / m.eigenvalue.im.abs().max(1e-9))
                .min(10.0 * period);
        let fitted = log_decrement_fit(&resp.time_s, &x, settle, window);
        let err = (fitted - sigma).abs() / sigma;
        println!(
            "  {w:7.3} rad/s  {:>15} {:7.4} Hz  Floquet {sigma:+.6} 1/s  time response {fitted:+.6} 1/s  ({:.3}%)",
            m.label,
            m.frequency_hz,
            100.0 * err
        );
        assert!(err < 0.02, "{w} rad/s: Floquet {sigma}, fit {fitted}");
        worst = worst.max(err);
    }
    println!(
        "  max difference {:.3}%  ({:.2} s)",
        100.0 * worst,
        t0.elapsed().as_secs_f64()
    );
}
