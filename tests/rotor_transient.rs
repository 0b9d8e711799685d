//! Perturbation damping (src/rotor/transient.rs) on a small model: a cantilever under a
//! T-periodic follower load, with stiffness-proportional structural damping, marched to the
//! periodic solution with g = 0 and g > 0.
use rotorsim::rotor::transient::{Damped, DampingParams, PerturbationDamping};
use rotorsim::solver::verification::uniform_section;
use rotorsim::solver::{DynamicSolver, State};
use rotorsim::structure::beam::SectionLoad;
use rotorsim::structure::model::{DistributedLoad, LoadPoint, Model};
use std::f64::consts::PI;

const L: f64 = 10.0;
const EI: f64 = 100.0;
const M: f64 = 1.0;
/// Steps per forcing period.
const N: usize = 64;

/// First bending frequency of the cantilever (Euler-Bernoulli) [rad/s].
fn w1() -> f64 {
    3.516015 * (EI / (M * L.powi(4))).sqrt()
}

/// Forcing period with the first mode at `nu` per period.
fn period(nu: f64) -> f64 {
    2.0 * PI * nu / w1()
}

struct Periodic {
    period: f64,
}

impl DistributedLoad for Periodic {
    fn eval(&mut self, p: &LoadPoint) -> SectionLoad {
        let ph = 2.0 * PI * p.t / self.period;
        SectionLoad {
            force: [0.0, 0.0, 0.01 * (ph.sin() + 0.5 * (2.0 * ph).cos())],
            moment: [0.0; 3],
            follower: true,
        }
    }
}

/// Damping coefficient per unit length [N s/m^2] (uniform: root_r_m = 1, c_n = c r / r).
const C: f64 = 0.04;

/// Tip deflection at every step of `revs` periods; mode 1 at `nu` per period with structural
/// damping ratio `zeta` (stiffness proportional, mu w1 / 2).
fn run(gain: f64, revs: usize, nu: f64, zeta: f64) -> Vec<f64> {
    run_delay(gain, 1, revs, nu, zeta)
}

/// As [`run`] with a delay of `delay_revs` periods.
fn run_delay(gain: f64, delay_revs: usize, revs: usize, nu: f64, zeta: f64) -> Vec<f64> {
    let sec = uniform_section(1e6, 1e6, 100.0, EI, EI, M, 1e-4, 5e-5, 5e-5);
    let mut m = Model::new();
    let mu = 2.0 * zeta / w1();
    let ids = m
        .add_straight_beam(
            "b",
            4,
            [0.0; 3],
            [L, 0.0, 0.0],
            [0.0, 1.0, 0.0],
            &sec,
            mu,
            None,
        )
        .unwrap();
    m.clamp("root", ids[0]).unwrap();
    let tip = *ids.last().unwrap();
    let t = period(nu);
    let h = t / N as f64;
    // c_n(r) = cn_per_r r with r = root_r_m + s_m: a huge root radius makes it uniform
    let r0 = 1e9;
    let damping = PerturbationDamping::new(
        &m,
        "b",
        DampingParams {
            gain,
            cn_per_r_n_s_per_m3: C / r0,
            root_r_m: r0,
            center_m: [0.0; 3],
            omega_rad_s: [0.0; 3],
            h_s: h,
            steps_per_rev: N,
            delay_revs,
        },
    )
    .unwrap();
    m.add_distributed_load(
        "b",
        Box::new(Damped {
            inner: Periodic { period: t },
            damping,
        }),
    )
    .unwrap();
    let st = State::from_model(&m);
    let mut s = DynamicSolver::new(m, st, h, 0.9).unwrap();
    s.newton.rtol = 1e-10;
    s.init_accelerations().unwrap();
    let mut z = Vec::with_capacity(revs * N);
    for _ in 0..revs * N {
        s.step().unwrap();
        z.push(s.state.x[tip][2]);
    }
    z
}

/// Largest change of the tip deflection from the previous period, per period (from the
/// second on), relative to the range of the last period.
fn periodicity(z: &[f64]) -> Vec<f64> {
    let last = &z[z.len() - N..];
    let range = last.iter().cloned().fold(f64::MIN, f64::max)
        - last.iter().cloned().fold(f64::MAX, f64::min);
    (1..z.len() / N)
        .map(|k| {
            (0..N)
                .map(|j| (z[k * N + j] - z[(k - 1) * N + j]).abs())
                .fold(0.0, f64::max)
                / range
        })
        .collect()
}

/// Root of `s^2 + 2 zeta w s + w^2 + G s (1 - e^{-sT}) = 0` near the undamped mode
/// (continuation in G, complex Newton).
fn delay_root(w: f64, zeta: f64, g_c_over_m: f64, t: f64) -> (f64, f64) {
    let (mut re, mut im) = (-zeta * w, w * (1.0 - zeta * zeta).sqrt());
    let cm = |a: (f64, f64), b: (f64, f64)| (a.0 * b.0 - a.1 * b.1, a.0 * b.1 + a.1 * b.0);
    for j in 1..=100 {
        let g = g_c_over_m * j as f64 / 100.0;
        for _ in 0..50 {
            let s = (re, im);
            let mag = (-re * t).exp();
            let e = (mag * (im * t).cos(), -mag * (im * t).sin());
            let one_m_e = (1.0 - e.0, -e.1);
            let s2 = cm(s, s);
            let d = cm(s, one_m_e);
            let f = (
                s2.0 + 2.0 * zeta * w * re + w * w + g * d.0,
                s2.1 + 2.0 * zeta * w * im + g * d.1,
            );
            let ste = cm(cm(s, (t, 0.0)), e);
            let df = (
                2.0 * re + 2.0 * zeta * w + g * (one_m_e.0 + ste.0),
                2.0 * im + g * (one_m_e.1 + ste.1),
            );
            let den = df.0 * df.0 + df.1 * df.1;
            let q = (
                (f.0 * df.0 + f.1 * df.1) / den,
                (f.1 * df.0 - f.0 * df.1) / den,
            );
            re -= q.0;
            im -= q.1;
        }
    }
    (re, im)
}

/// Decay per period of the rev-to-rev change between periods a+1 and b+1.
fn rate(p: &[f64], a: usize, b: usize) -> f64 {
    ((p[b] / p[a]).ln() / (b - a) as f64).exp()
}

/// Mode 1 at 1.5 per period, where 1 - cos(wT) = 2 (largest damping, no stiffness shift).
#[test]
fn periodic_solution_unchanged_and_transient_decays_at_the_predicted_rate() {
    let (revs, nu, zeta) = (60, 1.5, 0.04);
    let z0 = run(0.0, revs, nu, zeta);
    let z1 = run(1.0, revs, nu, zeta);
    let p0 = periodicity(&z0);
    let p1 = periodicity(&z1);
    for k in [1, 5, 10, 20, 30, revs - 2] {
        println!(
            "period {:2}: rev-to-rev change g=0 {:.2e}, g=1 {:.2e}",
            k + 1,
            p0[k],
            p1[k]
        );
    }
    // same periodic solution: last period of g = 0 and g = 1 agree
    let a = &z0[z0.len() - N..];
    let b = &z1[z1.len() - N..];
    let range =
        a.iter().cloned().fold(f64::MIN, f64::max) - a.iter().cloned().fold(f64::MAX, f64::min);
    let diff = a
        .iter()
        .zip(b)
        .map(|(x, y)| (x - y).abs())
        .fold(0.0, f64::max)
        / range;
    println!("last period: max |z(g=1) - z(g=0)| / range = {diff:.2e}");
    assert!(p0[revs - 2] < 1e-8 && p1[revs - 2] < 1e-8);
    assert!(diff < 1e-8, "{diff:e}");
    // decay per period of the rev-to-rev change (mode 1) vs the delay equation
    let t = period(nu);
    let expect = |g: f64| (delay_root(w1(), zeta, g * C / M, t).0 * t).exp();
    let (r0, r1) = (rate(&p0, 4, 14), rate(&p1, 4, 14));
    println!(
        "decay per period: g=0 {r0:.4} (predicted {:.4}), g=1 {r1:.4} (predicted {:.4})",
        expect(0.0),
        expect(1.0)
    );
    assert!((r0 - expect(0.0)).abs() < 0.02, "{r0} vs {}", expect(0.0));
    assert!((r1 - expect(1.0)).abs() < 0.02, "{r1} vs {}", expect(1.0));
    assert!(r1 < r0 * 0.8);
    let first = |p: &[f64]| p.iter().position(|&x| x < 1e-4).unwrap_or(usize::MAX);
    println!(
        "first period below 1e-4: g=0 {}, g=1 {}",
        first(&p0) + 2,
        first(&p1) + 2
    );
    assert!(first(&p1) * 2 < first(&p0));
}

/// Mode 1 at 1.035 per period (the UH-60A flap mode): the delayed term pulls the mode toward
/// 1 per period, where it sees no damping, and a decaying mode's previous period is larger than
/// its present one, so the decay becomes slower, as the delay equation predicts.
#[test]
fn near_integer_mode_decays_slower_as_the_delay_equation_predicts() {
    let (revs, nu, zeta, gain) = (32, 1.035, 0.02, 2.5);
    let p0 = periodicity(&run(0.0, revs, nu, zeta));
    let p1 = periodicity(&run(gain, revs, nu, zeta));
    let t = period(nu);
    let root = |g: f64| delay_root(w1(), zeta, g * C / M, t);
    let (r0, r1) = (rate(&p0, 8, 28), rate(&p1, 8, 28));
    let (e0, e1) = (root(0.0), root(gain));
    println!(
        "nu 1.035: decay per period g=0 {r0:.4} (predicted {:.4}), g={gain} {r1:.4} (predicted {:.4}, mode at {:.4}/period)",
        (e0.0 * t).exp(),
        (e1.0 * t).exp(),
        e1.1 * t / (2.0 * PI)
    );
    assert!((r0 - (e0.0 * t).exp()).abs() < 0.01);
    assert!((r1 - (e1.0 * t).exp()).abs() < 0.01);
    assert!(r1 > r0);
}

/// Mode 1 at 1.035 per period: a delay of 10 periods (1 - cos(2 pi 0.035 x 10) = 0.94 instead of
/// 0.024) damps it. Scalar delay-equation simulation (docs/rotor_model.md): the envelope falls
/// 0.026x from period 20 to 60 with g = 0.05 against 0.075x without.
#[test]
fn ten_period_delay_damps_the_near_integer_mode() {
    let (revs, nu, zeta) = (60, 1.035, 0.01);
    let p0 = periodicity(&run(0.0, revs, nu, zeta));
    let z10 = run_delay(0.05, 10, revs, nu, zeta);
    let p10 = periodicity(&z10);
    let (d0, d10) = (p0[58] / p0[18], p10[58] / p10[18]);
    println!("nu 1.035, periods 20 -> 60: rev-to-rev change falls {d0:.3}x (g = 0), {d10:.3}x (g = 0.05, delay 10)");
    assert!(d10 < 0.6 * d0, "{d10} vs {d0}");
    // untouched until t = 10 T (the first step that has v_n(t - 10 T) ends at t = 10 T)
    let z0 = run(0.0, 10, nu, zeta);
    let n = 10 * N - 1;
    assert!(z0[..n] == z10[..n] && z0[n] != z10[n]);
}
