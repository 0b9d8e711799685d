//! Floquet multipliers of the UH-60A run against independent references (docs/periodic.md).
//! The settled reference: the simulation's own periodic solution at a tight Newton tolerance,
//! then exact DMD on one-revolution pairs of the whole state (`dmd_until`), grown from two
//! perturbation sets that must agree. Under measured airloads the reported flap and lag
//! multipliers must lie within 1% of it or be marked unreliable; under hybrid-periodic airloads
//! the first flap mode (it decays tenfold a revolution) within 5%. A fit of the perturbed tip
//! flap (Prony's method) brackets the first flap mode.
use nalgebra::{Complex, DMatrix, DVector};
use rotorsim::flight::FlightRecord;
use rotorsim::hydraulics::{DamperModel, IntegratorOptions};
use rotorsim::periodic::Multiplier;
use rotorsim::rotor::{ForcedResponse, RotorDeck, RunOptions, SimState};
use rotorsim::run::job::DEFAULT_REVS;
use rotorsim::run::{drive_periodic, PeriodicOptions};
mod support;
use support::root;

/// Least-squares coefficients of `a x = b` (the recurrence's rows), the roots of its
/// characteristic polynomial `z^p - sum x_j z^j` (companion matrix) and the fit's relative
/// residual.
fn recurrence_roots(a: &DMatrix<f64>, b: &DVector<f64>) -> (Vec<(f64, f64)>, f64) {
    let p = a.ncols();
    let x = a.clone().svd(true, true).solve(b, 1e-14).unwrap();
    let rel = (a * &x - b).norm() / b.norm();
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

/// Measured airloads (linear damper, 128 steps per revolution): the reported flap and lag
/// multipliers, at the run's default tolerance and at a tight one started from the first's end
/// (another subspace), within 1% of a settled reference or marked unreliable. The reference:
/// the same model at the Newton tolerance [`REFERENCE_RTOL`] driven to its own periodic
/// solution, then exact DMD ([`dmd_until`]) from two perturbation sets, A six random directions
/// by 1e-5 and B six others by 2e-5, each grown until the eigenvalues nearest the reported flap
/// and lag have residuals at most 1e-3 of |mu|; the two sets must agree within half the
/// tolerance. (On the elastomeric bearing the lag mode at 0.29/rev has neighbours at 0.31 and
/// 0.32/rev; a fit of a 40-revolution march of the perturbed state blends them, 1% low.)
#[test]
fn flap_and_lag_multipliers_match_a_settled_reference_or_are_marked() {
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
    let runs: Vec<_> = [1e-4, 1e-6]
        .iter()
        .map(|&tol| {
            let run = drive_periodic(
                sim.as_mut(),
                model,
                &PeriodicOptions::shooting(tol, DEFAULT_REVS),
                &|_, _| {},
            )
            .unwrap();
            assert!(run.converged(), "{:?}", run.periodic);
            (tol, run)
        })
        .collect();
    let reported = |run: &rotorsim::run::ModelRun, mode: &str| {
        run.periodic
            .floquet_multipliers
            .iter()
            .find(|m| m.mode == mode)
            .unwrap_or_else(|| panic!("no {mode} multiplier"))
            .clone()
    };
    let targets: Vec<Multiplier> = runs
        .iter()
        .flat_map(|(_, r)| ["flap", "lag"].map(|m| reported(r, m)))
        .collect();
    let ref_opts = RunOptions {
        newton_rtol: REFERENCE_RTOL,
        ..opts
    };
    let mut rsim = rotorsim::rotor::build(&deck, &damper, model, &rec, &ref_opts).unwrap();
    let mut po = PeriodicOptions::shooting(1e-6, DEFAULT_REVS);
    po.floquet_resolve = false;
    let rr = drive_periodic(rsim.as_mut(), model, &po, &|_, _| {}).unwrap();
    assert!(rr.converged(), "reference: {:?}", rr.periodic);
    let x0 = rr.periodic_state.clone().unwrap();
    let n = x0.coords.len();
    rsim.set_output_channels(false);
    let resolved = |eigs: &[Eig]| {
        targets
            .iter()
            .all(|m| nearest_eig(eigs, m).is_some_and(|(_, r)| r <= 1e-3))
    };
    let set_a: Vec<Vec<f64>> = (1..=6).map(|s| random_direction(n, s)).collect();
    let set_b: Vec<Vec<f64>> = (101..=106).map(|s| random_direction(n, s)).collect();
    let steps = opts.steps_per_rev;
    let (ea, na) = dmd_until(rsim.as_mut(), &x0, set_a, 1e-5, steps, &[], &resolved);
    let (eb, nb) = dmd_until(rsim.as_mut(), &x0, set_b, 2e-5, steps, &[], &resolved);
    eprintln!("reference: set A {na} pairs, set B {nb} pairs");
    for (tol, run) in &runs {
        for mode in ["flap", "lag"] {
            let m = reported(run, mode);
            let (za, ra) = nearest_eig(&ea, &m).unwrap();
            let (zb, rb) = nearest_eig(&eb, &m).unwrap();
            let (ma, mb) = (za.norm(), zb.norm());
            let dist = (m.magnitude - ma).abs() / ma;
            eprintln!(
                "tol {tol:.0e} {mode}: Floquet |mu| {:.5} at {:.4}/rev (residual {:.1e} of |mu|, reliable {}); reference A {ma:.5} at {:.4}/rev (residual {ra:.1e}), B {mb:.5} (residual {rb:.1e}): off by {dist:.2e}",
                m.magnitude,
                m.frequency_per_rev,
                m.residual / m.magnitude,
                m.reliable,
                za.im.atan2(za.re) / std::f64::consts::TAU,
            );
            assert!(
                ra <= 1e-3 && rb <= 1e-3,
                "{mode}: the reference is not resolved ({ra:.1e}, {rb:.1e})"
            );
            assert!(
                (ma - mb).abs() <= 5e-3 * ma,
                "{mode}: the reference has not settled: set A {ma:.5}, set B {mb:.5}"
            );
            assert!(
                dist <= 0.01 || !m.reliable,
                "{mode}: |mu| is {dist:.2e} from the reference yet marked reliable (residual {:.2e})",
                m.residual
            );
        }
    }
}

/// The DMD eigenvalue nearest the multiplier `m` in the complex plane (conjugates folded), and
/// its residual.
fn nearest_eig(eigs: &[Eig], m: &Multiplier) -> Option<(Complex<f64>, f64)> {
    eigs.iter()
        .min_by(|a, b| {
            let d = |z: &Complex<f64>| (z.re - m.re).hypot(z.im - m.im.abs());
            d(&a.0).total_cmp(&d(&b.0))
        })
        .map(|e| (e.0, e.1))
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

/// The blade flapped rigidly about its hinge (0.381 m): every node between it and the tip
/// raised by `delta (r - e)`.
fn rigidly_flapped(x: &SimState, delta: f64) -> SimState {
    const K: usize = 24;
    let (e, tip) = (0.381, 8.3);
    let mut xp = x.clone();
    for i in 0..xp.coords.len() / K {
        let r = xp.coords[K * i].hypot(xp.coords[K * i + 1]);
        if r > e && r < tip {
            xp.coords[K * i + 2] += delta * (r - e);
        }
    }
    xp
}

/// Roots of the per-revolution recurrence `d(t + p T) = sum_j a_j d(t + j T)` fitted by least
/// squares at every step `t >= t0` of `d` (`steps` samples per revolution `T`), and the fit's
/// relative residual. The rows start at every step, not at whole revolutions: a mode that
/// decays tenfold in a revolution is fitted from where the faster ones have died, half a
/// revolution after the perturbation if need be.
fn prony_steps(d: &[f64], p: usize, steps: usize, t0: usize) -> (Vec<(f64, f64)>, f64) {
    let rows: Vec<usize> = (t0..d.len() - p * steps).collect();
    let a = DMatrix::from_fn(rows.len(), p, |r, j| d[rows[r] + j * steps]);
    let b = DVector::from_fn(rows.len(), |r, _| d[rows[r] + p * steps]);
    recurrence_roots(&a, &b)
}

/// The hybrid-periodic case: the run (physical damper, tolerance 1e-6) and the fits of the
/// perturbed tip flap.
struct HybridCase {
    run: rotorsim::run::ModelRun,
    /// The same at every step, central difference of flaps of +-1e-4 rad.
    central: Vec<f64>,
    steps: usize,
}

/// The UH-60A deck under hybrid-periodic airloads (physical damper, the run's defaults but
/// the Newton tolerance `newton_rtol`) driven to its periodic solution by shooting (tolerance
/// 1e-6), resolving its Floquet multipliers or not.
fn hybrid_run(
    newton_rtol: f64,
    resolve: bool,
) -> (Box<dyn ForcedResponse>, rotorsim::run::ModelRun) {
    use rotorsim::rotor::aero::AirloadSource;
    let deck = RotorDeck::from_file(&root().join("rotors/uh60a.toml")).unwrap();
    let rec = FlightRecord::read(&root().join("flightdata/c8534like")).unwrap();
    let damper = deck.damper().unwrap();
    let model = DamperModel::Physical;
    let opts = RunOptions {
        airloads: AirloadSource::HybridPeriodic,
        newton_rtol,
        ..Default::default()
    };
    let mut sim = rotorsim::rotor::build(&deck, &damper, model, &rec, &opts).unwrap();
    let mut po = PeriodicOptions::shooting(1e-6, DEFAULT_REVS);
    po.floquet_resolve = resolve;
    let run = drive_periodic(sim.as_mut(), model, &po, &|_, _| {}).unwrap();
    assert!(run.converged(), "{:?}", run.periodic);
    (sim, run)
}

fn hybrid_case() -> HybridCase {
    let (mut sim, run) = hybrid_run(RunOptions::default().newton_rtol, true);
    eprintln!(
        "{} revolutions, {} of them resolving Floquet multipliers",
        run.periodic.revolutions_integrated, run.periodic.floquet_directions
    );
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
    let steps = (sim.period_s() / sim.time_step_s()).round() as usize;
    let revs = 12;
    let delta = 1e-4;
    let up = tip_flap_march(sim.as_mut(), &rigidly_flapped(&x0, delta), revs, steps);
    let down = tip_flap_march(sim.as_mut(), &rigidly_flapped(&x0, -delta), revs, steps);
    let central = up.iter().zip(&down).map(|(a, b)| (a - b) / 2.0).collect();
    HybridCase {
        run,
        central,
        steps,
    }
}

/// The aerodynamically damped first flap mode among the reported multipliers: labelled flap,
/// |mu| below 0.5 (the lifting line's damping: ~exp(-2 pi gamma/16) per revolution), at a
/// frequency within 0.1/rev of a whole multiple of 1/rev (the rotating flap frequency of an
/// articulated blade is near 1/rev; the modes of the second flap frequency, near 2.8/rev, show
/// at 0.15-0.2/rev). Exactly one, or the test fails.
fn first_flap(run: &rotorsim::run::ModelRun) -> rotorsim::periodic::Multiplier {
    let found: Vec<_> = run
        .periodic
        .floquet_multipliers
        .iter()
        .filter(|m| m.mode == "flap" && m.magnitude < 0.5 && m.frequency_per_rev < 0.1)
        .collect();
    assert!(
        found.len() == 1,
        "the first flap mode is not found (or not alone): {found:?} among {:?}",
        run.periodic.floquet_multipliers
    );
    found[0].clone()
}

/// The fitted roots of the first flap mode: for each order and window, the root nearest the
/// reported multiplier `m` (complex conjugates folded), other than the lag mode (|z| < 0.5).
fn flap_fits(c: &HybridCase, m: &rotorsim::periodic::Multiplier) -> Vec<(usize, usize, f64, f64)> {
    let mut out = vec![];
    for t0 in [c.steps, 3 * c.steps / 2] {
        for p in [4, 6] {
            let (roots, rel) = prony_steps(&c.central, p, c.steps, t0);
            let z = roots
                .iter()
                .filter(|z| z.0.hypot(z.1) < 0.5)
                .min_by(|a, b| {
                    let d = |z: &&(f64, f64)| (z.0 - m.re).hypot(z.1.abs() - m.im.abs());
                    d(a).total_cmp(&d(b))
                })
                .copied()
                .unwrap_or_else(|| panic!("order {p} from step {t0}: no fast root: {roots:?}"));
            let (mu, f) = (z.0.hypot(z.1), z.1.atan2(z.0).abs() / std::f64::consts::TAU);
            eprintln!(
                "flap fit, order {p}, rows from {:.1} revolutions: |mu| {mu:.4} at {f:.3}/rev (relative residual {rel:.1e})",
                t0 as f64 / c.steps as f64
            );
            out.push((p, t0, mu, f));
        }
    }
    out
}

/// Hybrid-periodic airloads (physical damper, the run's defaults): the first flap mode, damped
/// by the lifting line to |mu| ~ 0.1, must be reported and resolved, and a fit of the perturbed
/// march must bracket it: the periodic state with the blade flapped rigidly about its hinge
/// (+-1e-4 rad) is marched 12 revolutions, and the tip flap's central difference is fitted by a
/// linear recurrence at every step from one revolution after the perturbation (orders 4 and 6,
/// from 1 and 1.5 revolutions). Those fits do not agree to 5% among themselves: the 5% check is
/// against the settled reference of
/// `hybrid_flap_multiplier_within_5_percent_of_a_settled_reference` below.
#[test]
fn hybrid_first_flap_mode_is_resolved_within_the_decay_fits() {
    let c = hybrid_case();
    // the first flap mode: found, resolved, within the spread of the decay fits
    let flap = first_flap(&c.run);
    eprintln!(
        "first flap mode: |mu| {:.5} at {:.4}/rev, residual {:.1e} of |mu|",
        flap.magnitude,
        flap.frequency_per_rev,
        flap.residual / flap.magnitude
    );
    assert!(
        flap.reliable,
        "the first flap mode is not resolved: {flap:?}"
    );
    let fits = flap_fits(&c, &flap);
    let lo = fits.iter().map(|f| f.2).fold(f64::INFINITY, f64::min);
    let hi = fits.iter().map(|f| f.2).fold(0.0, f64::max);
    assert!(
        (lo..=hi).contains(&flap.magnitude),
        "flap |mu| {} outside the fits {lo:.4}..{hi:.4}",
        flap.magnitude
    );
}

/// Newton tolerance of the reference's marches. The run's own (1e-7 of the predictor residual)
/// leaves a noise of 2-4% in a one-revolution difference at perturbations of 1e-5 to 1e-4 (it
/// does not shrink with the perturbation: Newton stops at a tolerance, not at a solution); at
/// 1e-10 two perturbations agree within 1e-3.
const REFERENCE_RTOL: f64 = 1e-10;

/// `M v`, the monodromy matrix times `v`, by the central difference of one revolution from the
/// periodic state `x0`: `(Phi(x0 + delta v) - Phi(x0 - delta v)) / (2 delta)` (the quadratic
/// term of the map cancels).
fn monodromy_times(
    sim: &mut dyn ForcedResponse,
    x0: &SimState,
    v: &[f64],
    delta: f64,
    steps: usize,
) -> Vec<f64> {
    let mut ends = [1.0, -1.0].map(|sign: f64| {
        let mut x = x0.clone();
        for (c, vi) in x.coords.iter_mut().zip(v) {
            *c += sign * delta * vi;
        }
        sim.restore_state(&x).unwrap();
        for _ in 0..steps {
            sim.step().unwrap();
        }
        sim.save_state().unwrap().coords
    });
    let down = std::mem::take(&mut ends[1]);
    ends[0]
        .iter()
        .zip(&down)
        .map(|(a, b)| (a - b) / (2.0 * delta))
        .collect()
}

fn dot(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| x * y).sum()
}

fn unit(mut v: Vec<f64>) -> Vec<f64> {
    let n = dot(&v, &v).sqrt();
    v.iter_mut().for_each(|x| *x /= n);
    v
}

/// Eigenvalues of exact DMD on the one-revolution pairs `(q_i, w_i = M q_i)` (`q` orthonormal:
/// the least-squares map on span(q), `H = Q^T W`), each with the relative residual
/// `||W y - mu Q y|| / (|mu| ||Q y||)` of its mode and the share `|<v, p>| / ||v||` of the unit
/// direction `probe` in its mode `v` (0 for an empty probe); complex pairs once (Im >= 0).
fn dmd_pairs(q: &[Vec<f64>], w: &[Vec<f64>], probe: &[f64]) -> Vec<Eig> {
    let m = q.len();
    let h = DMatrix::from_fn(m, m, |i, j| dot(&q[i], &w[j]));
    let zero = Complex::new(0.0, 0.0);
    h.complex_eigenvalues()
        .iter()
        .filter(|z| z.im >= 0.0)
        .map(|&z| {
            // the eigenvector: the right singular vector of H - z I of the least singular value
            let b = DMatrix::from_fn(m, m, |i, j| {
                Complex::new(h[(i, j)], 0.0) - if i == j { z } else { zero }
            });
            let svd = b.svd(false, true);
            let k = (0..m)
                .min_by(|a, b| svd.singular_values[*a].total_cmp(&svd.singular_values[*b]))
                .unwrap();
            let vt = svd.v_t.unwrap();
            let (mut v, mut r) = (vec![zero; q[0].len()], vec![zero; q[0].len()]);
            for j in 0..m {
                let y = vt[(k, j)].conj();
                for (i, (qi, wi)) in q[j].iter().zip(&w[j]).enumerate() {
                    v[i] += y * qi;
                    r[i] += y * wi;
                }
            }
            let nv = v.iter().map(|c| c.norm_sqr()).sum::<f64>().sqrt();
            let res = v
                .iter()
                .zip(&r)
                .map(|(a, b)| (b - z * a).norm_sqr())
                .sum::<f64>()
                .sqrt();
            let share = v
                .iter()
                .zip(probe)
                .map(|(a, p)| a * p)
                .sum::<Complex<f64>>();
            (z, res / (nv * z.norm()), share.norm() / nv)
        })
        .collect()
}

/// The first flap mode among DMD eigenvalues (their probe the rigid flap about the hinge):
/// of those below 0.5 in `|mu|` and between 0.02 and 0.1/rev in frequency (the window of
/// [`first_flap`]) whose residual is at most 10% of `|mu|` (not a spurious value), the one
/// whose mode holds the most rigid flap, resolved or not (the blocks grow until it is). The
/// window also holds a torsion mode (0.19 at 0.056/rev on the elastomeric bearing, less damped
/// than the flap mode); the elastomers' relaxations are real, at 0/rev.
fn first_flap_of(eigs: &[Eig]) -> Option<(Complex<f64>, f64)> {
    eigs.iter()
        .filter(|(z, r, _)| {
            let f = z.im.atan2(z.re).abs() / std::f64::consts::TAU;
            z.norm() < 0.5 && (0.02..0.1).contains(&f) && *r <= 0.1
        })
        .max_by(|a, b| a.2.total_cmp(&b.2))
        .map(|e| (e.0, e.1))
}

/// A DMD eigenvalue (a multiplier), its mode's relative residual and the probe's share in it.
type Eig = (Complex<f64>, f64, f64);

/// Exact DMD on one-revolution pairs from the periodic state `x0`, the pairs a block Krylov
/// sequence: the first block is `starts`; each revolution's images (`M q`, central differences
/// of `delta`), orthogonalised against every start so far, are the next block's starts: every
/// pair starts at the full perturbation, so a mode that decays tenfold a revolution stays as
/// far above the integration's noise as the slow ones (a march would bury it within three
/// revolutions). The blocks grow until `done` holds for the eigenvalues (or 96 pairs). Returns
/// the eigenvalues with their residuals and the number of pairs.
fn dmd_until(
    sim: &mut dyn ForcedResponse,
    x0: &SimState,
    starts: Vec<Vec<f64>>,
    delta: f64,
    steps: usize,
    probe: &[f64],
    done: &dyn Fn(&[Eig]) -> bool,
) -> (Vec<Eig>, usize) {
    let (mut q, mut w): (Vec<Vec<f64>>, Vec<Vec<f64>>) = (vec![], vec![]);
    let mut block = starts;
    while q.len() < 96 && !block.is_empty() {
        let mut next = vec![];
        for mut v in block {
            let n0 = dot(&v, &v).sqrt();
            // Gram-Schmidt, twice (the images of a block are nearly parallel)
            for _ in 0..2 {
                for qi in &q {
                    let c = dot(qi, &v);
                    v.iter_mut().zip(qi).for_each(|(x, y)| *x -= c * y);
                }
            }
            if dot(&v, &v).sqrt() < 1e-10 * n0 {
                continue;
            }
            let v = unit(v);
            let img = monodromy_times(sim, x0, &v, delta, steps);
            q.push(v);
            w.push(img.clone());
            next.push(img);
        }
        block = next;
        let eigs = dmd_pairs(&q, &w, probe);
        if done(&eigs) {
            return (eigs, q.len());
        }
    }
    (dmd_pairs(&q, &w, probe), q.len())
}

/// Directions of a perturbation: uniform random (seeded) on the displacements, rotations and
/// their rates of every node (the accelerations, which follow them within a few steps, left
/// alone).
fn random_direction(n: usize, seed: u64) -> Vec<f64> {
    const K: usize = 24;
    let mut s = seed;
    let v = (0..n)
        .map(|i| {
            s = s
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            let x = ((s >> 11) as f64 / (1u64 << 53) as f64) * 2.0 - 1.0;
            if i < n / K * K && i % K < 12 {
                x
            } else {
                0.0
            }
        })
        .collect();
    unit(v)
}

/// Hybrid-periodic airloads (physical damper, the run's defaults): the reported first flap
/// multiplier, resolved, within 5% of an independent reference that has itself settled. The
/// reference uses the simulation's stepping only (`save_state`, `restore_state`, `step`): its
/// own periodic solution at the Newton tolerance [`REFERENCE_RTOL`], then exact DMD on
/// one-revolution pairs of the whole state ([`dmd_until`], until the first flap mode has a
/// residual at most 1e-3 of |mu|) from two perturbation sets: A the rigid flap about the hinge,
/// its rate and four random directions, perturbed by 1e-5; B six other random directions,
/// perturbed by 2e-5. The central differences are checked to be linear (1e-5 against 2e-5) and
/// the two sets must agree within 2.5% (half the tolerance). (The lag-labelled modes are
/// checked under measured airloads above: with the physical damper the two sets do not agree
/// on them, 0.738 against 0.797 for the mode at 0.316/rev: 2e-5 is not small for the damper.)
#[test]
fn hybrid_flap_multiplier_within_5_percent_of_a_settled_reference() {
    let (_, run) = hybrid_run(RunOptions::default().newton_rtol, true);
    let flap = first_flap(&run);
    eprintln!(
        "reported first flap mode: |mu| {:.5} at {:.4}/rev, residual {:.1e} of |mu|",
        flap.magnitude,
        flap.frequency_per_rev,
        flap.residual / flap.magnitude
    );
    assert!(
        flap.reliable,
        "the first flap mode is not resolved: {flap:?}"
    );
    let (mut sim, reference_run) = hybrid_run(REFERENCE_RTOL, false);
    let x0 = reference_run.periodic_state.clone().unwrap();
    let steps = (sim.period_s() / sim.time_step_s()).round() as usize;
    let n = x0.coords.len();
    sim.set_output_channels(false);
    // the rigid flap (1 rad) and its rate (1 rad per radian of azimuth)
    let (flap_angle, flap_rate) = {
        let up = rigidly_flapped(&x0, 1.0);
        let angle: Vec<f64> = up
            .coords
            .iter()
            .zip(&x0.coords)
            .map(|(a, b)| a - b)
            .collect();
        let mut rate = vec![0.0; n];
        for i in 0..n / 24 {
            rate[24 * i + 8] = angle[24 * i + 2];
        }
        (unit(angle), unit(rate))
    };
    // linearity: the flap's image at two perturbations
    let a = monodromy_times(sim.as_mut(), &x0, &flap_angle, 1e-5, steps);
    let b = monodromy_times(sim.as_mut(), &x0, &flap_angle, 2e-5, steps);
    let e: Vec<f64> = a.iter().zip(&b).map(|(x, y)| x - y).collect();
    let lin = (dot(&e, &e) / dot(&a, &a)).sqrt();
    eprintln!("central differences of 1e-5 and 2e-5 differ by {lin:.1e} of |M v|");
    assert!(
        lin < 1e-2,
        "the map is not linear at these perturbations: {lin:.1e}"
    );
    let probe = flap_angle.clone();
    let set_a: Vec<Vec<f64>> = [flap_angle, flap_rate]
        .into_iter()
        .chain((1..=4).map(|s| random_direction(n, s)))
        .collect();
    let set_b: Vec<Vec<f64>> = (101..=106).map(|s| random_direction(n, s)).collect();
    let resolved = |eigs: &[Eig]| first_flap_of(eigs).is_some_and(|(_, r)| r <= 1e-3);
    let (ea, na) = dmd_until(sim.as_mut(), &x0, set_a, 1e-5, steps, &probe, &resolved);
    let (eb, nb) = dmd_until(sim.as_mut(), &x0, set_b, 2e-5, steps, &probe, &resolved);
    let flap_of = |e: &[Eig], set: &str| {
        first_flap_of(e)
            .unwrap_or_else(|| panic!("set {set}: the first flap mode is not found among {e:?}"))
    };
    let ((za, ra), (zb, rb)) = (flap_of(&ea, "A"), flap_of(&eb, "B"));
    let (ma, mb) = (za.norm(), zb.norm());
    eprintln!(
        "reference: set A {ma:.5} ({na} pairs, residual {ra:.1e}), set B {mb:.5} ({nb} pairs, residual {rb:.1e}): {:.2}% apart",
        100.0 * (ma - mb).abs() / ma
    );
    assert!(
        (ma - mb).abs() <= 0.025 * ma,
        "the reference has not settled: set A {ma:.5}, set B {mb:.5}"
    );
    let dist = (flap.magnitude - ma).abs() / ma;
    eprintln!(
        "reported {:.5} against the reference {ma:.5}: {:.2}% (set B: {:.2}%)",
        flap.magnitude,
        100.0 * dist,
        100.0 * (flap.magnitude - mb).abs() / mb
    );
    assert!(
        dist <= 0.05,
        "flap |mu| {} is {:.1}% from the reference {ma:.5}",
        flap.magnitude,
        100.0 * dist
    );
}
