//! Floquet multipliers of the UH-60A run against a fit of the perturbed periodic march
//! (docs/periodic.md): the periodic state is perturbed, both it and the unperturbed state are
//! marched, and the per-revolution deviation `d_k` (every perturbable coordinate) is fitted by
//! a linear recurrence `d_{k+p} = sum_j a_j d_{k+j}` (Prony's method: the roots of
//! `z^p - sum a_j z^j` are the multipliers of the modes left in the deviation). The reported
//! flap and lag multipliers must lie within 1% of the fitted ones or be marked unreliable.
use nalgebra::{DMatrix, DVector};
use rotorsim::flight::FlightRecord;
use rotorsim::hydraulics::{DamperModel, IntegratorOptions};
use rotorsim::rotor::{ForcedResponse, RotorDeck, RunOptions, SimState};
use rotorsim::run::{drive_periodic, PeriodicOptions};
mod support;
use support::root;

/// Revolutions marched after the perturbation, and the first one fitted (the fast modes,
/// |mu| < 0.5, have decayed below 1e-3 of their start by then).
const REVS: usize = 40;
const FIRST: usize = 10;
/// Size of the perturbation in the map's coordinates (that of shooting's finite differences).
const PERTURBATION: f64 = 1e-4;

fn march(sim: &mut dyn ForcedResponse, from: &SimState, steps: usize) -> Vec<Vec<f64>> {
    sim.restore_state(from).unwrap();
    let mut out = vec![from.coords.clone()];
    for _ in 0..REVS {
        for _ in 0..steps {
            sim.step().unwrap();
        }
        out.push(sim.save_state().unwrap().coords);
    }
    out
}

/// Roots of the order-`p` recurrence fitted by least squares to every coordinate of `d`
/// from revolution `FIRST`, and the fit's relative residual.
fn prony(d: &[Vec<f64>], p: usize) -> (Vec<(f64, f64)>, f64) {
    prony_from(d, p, FIRST)
}

/// [`prony`] from revolution `first`.
fn prony_from(d: &[Vec<f64>], p: usize, first: usize) -> (Vec<(f64, f64)>, f64) {
    let n = d[0].len();
    let rows: Vec<(usize, usize)> = (first..d.len() - p)
        .flat_map(|k| (0..n).map(move |c| (k, c)))
        .collect();
    let a = DMatrix::from_fn(rows.len(), p, |r, j| d[rows[r].0 + j][rows[r].1]);
    let b = DVector::from_fn(rows.len(), |r, _| d[rows[r].0 + p][rows[r].1]);
    let x = a.clone().svd(true, true).solve(&b, 1e-14).unwrap();
    let rel = (&a * &x - &b).norm() / b.norm();
    // companion matrix of z^p - sum x_j z^j
    let mut cm = DMatrix::<f64>::zeros(p, p);
    for j in 0..p {
        cm[(0, j)] = x[p - 1 - j];
        if j + 1 < p {
            cm[(j + 1, j)] = 1.0;
        }
    }
    let roots = cm
        .complex_eigenvalues()
        .iter()
        .map(|z| (z.re, z.im))
        .collect();
    (roots, rel)
}

/// Multiplier of the fitted roots nearest in frequency (mod 1/rev) to `f`, among the slow ones.
fn nearest(roots: &[(f64, f64)], f: f64) -> (f64, f64) {
    let freq = |z: &(f64, f64)| z.1.atan2(z.0).abs() / (2.0 * std::f64::consts::PI);
    *roots
        .iter()
        .filter(|z| z.1 >= 0.0 && z.0.hypot(z.1) > 0.5)
        .min_by(|a, b| (freq(a) - f).abs().total_cmp(&(freq(b) - f).abs()))
        .unwrap()
}

#[test]
fn flap_and_lag_multipliers_match_a_fit_of_the_perturbed_march_or_are_marked() {
    let deck = RotorDeck::from_file(&root().join("rotors/uh60a.toml")).unwrap();
    let rec = FlightRecord::read(&root().join("flightdata/c8534like")).unwrap();
    let damper = deck.damper().unwrap();
    let model = DamperModel::Linear;
    let opts = RunOptions {
        steps_per_rev: 128,
        hydraulics: IntegratorOptions {
            substeps: 50,
            ..Default::default()
        },
        perturbation_damping: false,
        ..Default::default()
    };
    let mut sim = rotorsim::rotor::build(&deck, &damper, model, &rec, &opts).unwrap();
    // the run's default tolerance, then a tight one started from the first's end (another
    // subspace: on it the lag multiplier is 1.6% off and its residual 24% of |mu|)
    let runs: Vec<_> = [1e-4, 1e-6]
        .iter()
        .map(|&tol| {
            let run = drive_periodic(
                sim.as_mut(),
                model,
                &PeriodicOptions::shooting(tol, 75),
                &|_, _| {},
            )
            .unwrap();
            assert!(run.converged(), "{:?}", run.periodic);
            (tol, run)
        })
        .collect();
    let x0 = runs[1].1.periodic_state.clone().unwrap();
    let mut xp = x0.clone();
    let v: Vec<f64> = (0..xp.coords.len())
        .map(|i| (1.3 * i as f64 + 0.7).sin())
        .collect();
    let nv = v.iter().map(|x| x * x).sum::<f64>().sqrt();
    for (c, vi) in xp.coords.iter_mut().zip(&v) {
        *c += PERTURBATION * vi / nv;
    }
    let steps = opts.steps_per_rev;
    let base = march(sim.as_mut(), &x0, steps);
    let pert = march(sim.as_mut(), &xp, steps);
    let d: Vec<Vec<f64>> = base
        .iter()
        .zip(&pert)
        .map(|(b, p)| p.iter().zip(b).map(|(x, y)| x - y).collect())
        .collect();
    // the deviation holds about six slow modes (lag, flap, their second modes, torsion):
    // order 12; order 10 tells how well the fit has settled
    let (roots, rel) = prony(&d, 12);
    let (roots10, _) = prony(&d, 10);
    eprintln!("fit of order 12: relative residual {rel:.2e}");
    assert!(rel < 2e-2, "the order-12 recurrence leaves {rel:.2e}");
    for (tol, run) in &runs {
        for m in &run.periodic.floquet_multipliers {
            eprintln!(
                "tol {tol:.0e}: Floquet {:>8}: {:.6} {:+.6}i |mu| {:.5} f {:.4}/rev residual {:.2e} reliable {}",
                m.mode, m.re, m.im, m.magnitude, m.frequency_per_rev, m.residual, m.reliable
            );
        }
        for mode in ["flap", "lag"] {
            // the least damped multiplier of that label
            let m = run
                .periodic
                .floquet_multipliers
                .iter()
                .find(|m| m.mode == mode)
                .unwrap_or_else(|| panic!("no {mode} multiplier"));
            let (fr, fi) = nearest(&roots, m.frequency_per_rev);
            let (gr, gi) = nearest(&roots10, m.frequency_per_rev);
            let fit = fr.hypot(fi);
            // the reference has settled: the decays per revolution of orders 10 and 12 agree
            // within half the tolerance (the lag's frequency settles only to ~0.002/rev)
            assert!(
                (fit - gr.hypot(gi)).abs() < 5e-3 * fit,
                "{mode}: fits of order 10 and 12 differ: {fit} vs {}",
                gr.hypot(gi)
            );
            let dist = (m.magnitude - fit).abs() / fit;
            let cdist = (m.re - fr).hypot(m.im.abs() - fi) / fit;
            let decay = m.magnitude.ln() / fit.ln();
            eprintln!(
                "tol {tol:.0e} {mode}: Floquet |mu| {:.5}, fit {fit:.5} (order 10: {:.5}): |mu| off by {dist:.2e}, complex distance {cdist:.2e}, decay rate x{decay:.3}; residual {:.2e} of |mu|, reliable {}",
                m.magnitude,
                gr.hypot(gi),
                m.residual / m.magnitude,
                m.reliable
            );
            assert!(
                dist <= 0.01 || !m.reliable,
                "{mode}: |mu| is {dist:.2e} from the fit yet marked reliable (residual {:.2e})",
                m.residual
            );
        }
    }
}

/// Marches `revs` revolutions from `from`, the tip flap channel at every step.
fn tip_flap_march(
    sim: &mut dyn ForcedResponse,
    from: &SimState,
    revs: usize,
    steps: usize,
) -> Vec<f64> {
    sim.restore_state(from).unwrap();
    sim.set_output_channels(true);
    let names = sim.channel_names();
    let k = names.iter().position(|c| c == "tip_flap_m").unwrap();
    let mut buf = vec![0.0; names.len()];
    let mut out = Vec::with_capacity(revs * steps);
    for _ in 0..revs * steps {
        sim.step().unwrap();
        sim.channels(&mut buf);
        out.push(buf[k]);
    }
    out
}

/// Hybrid-periodic airloads (physical damper, the run's defaults): the periodic state with
/// the blade flapped rigidly about its hinge (1e-4 rad) is marched 12 revolutions beside the
/// unperturbed one; the tip flap channel's deviation, revolution by revolution (every sample
/// a row), is fitted by a linear recurrence (Prony, as above). The least damped root, the lag
/// mode, must match the reported lag multiplier within 1%, and the reported multiplier must be
/// resolved. The flap transient's decay (RMS of the deviation, revolution to revolution) is
/// printed beside the flap-labelled multipliers: it falls by about 0.09 then 0.12 in the first
/// two revolutions, faster than any resolved flap-labelled multiplier (0.38, 0.36 at
/// 0.16/rev, 0.14 at 0.19/rev): the aerodynamically damped first flap mode is not among the
/// reported multipliers (|mu| below the 0.1 the run resolves), and no comparison is asserted.
#[test]
fn hybrid_lag_multiplier_matches_a_fit_of_the_perturbed_tip_flap() {
    use rotorsim::rotor::aero::AirloadSource;
    let deck = RotorDeck::from_file(&root().join("rotors/uh60a.toml")).unwrap();
    let rec = FlightRecord::read(&root().join("flightdata/c8534like")).unwrap();
    let damper = deck.damper().unwrap();
    let model = DamperModel::Physical;
    let opts = RunOptions {
        airloads: AirloadSource::HybridPeriodic,
        ..Default::default()
    };
    let mut sim = rotorsim::rotor::build(&deck, &damper, model, &rec, &opts).unwrap();
    let run = drive_periodic(
        sim.as_mut(),
        model,
        &PeriodicOptions::shooting(1e-6, 75),
        &|_, _| {},
    )
    .unwrap();
    assert!(run.converged(), "{:?}", run.periodic);
    for m in &run.periodic.floquet_multipliers {
        eprintln!(
            "Floquet {:>8}: |mu| {:.5} f {:.4}/rev residual {:.2e} of |mu|",
            m.mode,
            m.magnitude,
            m.frequency_per_rev,
            m.residual / m.magnitude
        );
    }
    let x0 = run.periodic_state.clone().unwrap();
    // a rigid flap about the hinge: every blade node beyond it raised by delta (r - e)
    const K: usize = 24;
    let (e, delta, tip) = (0.381, 1e-4, 8.3);
    let mut xp = x0.clone();
    for i in 0..xp.coords.len() / K {
        let r = xp.coords[K * i].hypot(xp.coords[K * i + 1]);
        if r > e && r < tip {
            xp.coords[K * i + 2] += delta * (r - e);
        }
    }
    let steps = (sim.period_s() / sim.time_step_s()).round() as usize;
    let revs = 12;
    let base = tip_flap_march(sim.as_mut(), &x0, revs, steps);
    let pert = tip_flap_march(sim.as_mut(), &xp, revs, steps);
    let d: Vec<Vec<f64>> = (0..revs)
        .map(|k| {
            (k * steps..(k + 1) * steps)
                .map(|i| pert[i] - base[i])
                .collect()
        })
        .collect();
    let rms: Vec<f64> = d
        .iter()
        .map(|v| (v.iter().map(|x| x * x).sum::<f64>() / v.len() as f64).sqrt())
        .collect();
    for k in 1..4 {
        eprintln!(
            "tip flap deviation, revolution {k}: RMS {:.3e}, {:.4} of the revolution before",
            rms[k],
            rms[k] / rms[k - 1]
        );
    }
    let lag = run
        .periodic
        .floquet_multipliers
        .iter()
        .find(|m| m.mode == "lag")
        .expect("no lag multiplier");
    let least_damped = |p: usize| {
        let (roots, rel) = prony_from(&d, p, 1);
        let z = roots
            .iter()
            .copied()
            .max_by(|a, b| a.0.hypot(a.1).total_cmp(&b.0.hypot(b.1)))
            .unwrap();
        eprintln!(
            "fit of order {p}: least damped {:.5} at {:.4}/rev, relative residual {rel:.1e}",
            z.0.hypot(z.1),
            z.1.atan2(z.0).abs() / std::f64::consts::TAU
        );
        z
    };
    let (z6, z8) = (least_damped(6), least_damped(8));
    let fit = z6.0.hypot(z6.1);
    assert!(
        (fit - z8.0.hypot(z8.1)).abs() < 5e-3 * fit,
        "the fit has not settled"
    );
    assert!(lag.reliable, "lag not resolved: {lag:?}");
    let dist = (lag.magnitude - fit).abs() / fit;
    assert!(dist < 0.01, "lag |mu| {} vs fit {fit}", lag.magnitude);
    let fdist = (lag.frequency_per_rev - z6.1.atan2(z6.0).abs() / std::f64::consts::TAU).abs();
    assert!(fdist < 0.005, "lag frequency off by {fdist}/rev");
}
