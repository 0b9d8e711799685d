//! Rotor inflow models (src/aero/inflow.rs): Glauert momentum inflow, Drees' shape and the
//! Pitt-Peters dynamic inflow, against closed forms evaluated independently here.
//!
//! Conventions: lambda_i = l0 + ls r sin psi + lc r cos psi (positive down), psi from aft,
//! loads (ct, cs, cc) = thrust and its first moments toward the advancing side and aft.
#![allow(clippy::needless_range_loop)]
use rotorsim::aero::inflow::{
    momentum_inflow, DiskLoads, FlightCondition, Inflow, InflowModel, PITT_PETERS_M,
};
use std::f64::consts::PI;

mod alloc_support;
use alloc_support::{allocations, assert_counting};

fn cond(mu: f64, lambda_free: f64) -> FlightCondition {
    FlightCondition { mu, lambda_free }
}

fn thrust(ct: f64) -> DiskLoads {
    DiskLoads {
        ct,
        ..DiskLoads::default()
    }
}

/// Residual of Glauert's equation l0 = ct / (2 sqrt(mu^2 + (lambda_free + l0)^2)).
fn glauert_residual(l0: f64, ct: f64, c: FlightCondition) -> f64 {
    l0 - ct / (2.0 * (c.mu * c.mu + (c.lambda_free + l0).powi(2)).sqrt())
}

/// Skew angle chi = atan(mu / lambda), lambda = lambda_free + l0 > 0 here.
fn chi(c: FlightCondition, l0: f64) -> f64 {
    (c.mu / (c.lambda_free + l0)).atan()
}

/// The Pitt-Peters L in the (ct, cs, cc) first-moment convention, written out here:
/// [[1/2, 0, -15pi/64 X], [0, 4/(1+cos chi), 0], [15pi/64 X, 0, 4 cos chi/(1+cos chi)]].
fn l_matrix(chi: f64) -> [[f64; 3]; 3] {
    let x = (chi / 2.0).tan();
    let k = 15.0 * PI / 64.0;
    let c = chi.cos();
    [
        [0.5, 0.0, -k * x],
        [0.0, 4.0 / (1.0 + c), 0.0],
        [k * x, 0.0, 4.0 * c / (1.0 + c)],
    ]
}

fn rel(a: f64, b: f64) -> f64 {
    (a - b).abs() / b.abs().max(1e-300)
}

/// Hover (mu = 0, lambda_free = 0): l0 = sqrt(ct / 2) to 1e-12; a negative ct keeps its sign.
#[test]
fn hover_momentum_is_sqrt_half_ct() {
    for ct in [0.001, 0.0045, 0.008, 0.012] {
        let l0 = momentum_inflow(ct, cond(0.0, 0.0));
        assert!((l0 - (ct / 2.0f64).sqrt()).abs() < 1e-12, "ct {ct}: {l0}");
        let neg = momentum_inflow(-ct, cond(0.0, 0.0));
        assert!(
            (neg + (ct / 2.0f64).sqrt()).abs() < 1e-12,
            "ct -{ct}: {neg}"
        );
    }
    assert_eq!(momentum_inflow(0.0, cond(0.0, 0.0)), 0.0);
}

/// Forward flight, lambda_free = 0.02, ct = 0.006: the Glauert equation's residual < 1e-13 at
/// mu = 0.1, 0.2, 0.3, 0.4 (l0 about 0.024, 0.012, 0.0093, 0.0072).
#[test]
fn forward_flight_momentum_satisfies_glauert() {
    for mu in [0.1, 0.2, 0.3, 0.4] {
        let c = cond(mu, 0.02);
        let l0 = momentum_inflow(0.006, c);
        let r = glauert_residual(l0, 0.006, c);
        assert!(r.abs() < 1e-13, "mu {mu}: l0 {l0} residual {r:e}");
        assert!(l0 > 0.0 && l0 < 0.006 / (2.0 * mu));
    }
    // climb and a mild descent, and the thrust sign
    for (mu, lf, ct) in [
        (0.0, 0.05, 0.006),
        (0.15, -0.01, 0.006),
        (0.2, 0.02, -0.003),
    ] {
        let c = cond(mu, lf);
        let l0 = momentum_inflow(ct, c);
        assert!(glauert_residual(l0, ct, c).abs() < 1e-13, "{mu} {lf} {ct}");
        assert_eq!(l0.signum(), ct.signum());
    }
}

/// High-speed limit: l0 -> ct / (2 mu). With lambda_free = 0, x = l0 / mu solves
/// l0 = (ct/2mu) / sqrt(1 + x^2), so the relative difference (ct/2mu - l0) / l0 =
/// sqrt(1 + x^2) - 1 ~ ct^2 / (8 mu^4): it shrinks by ~16 per doubling of mu (to within 1% of that estimate
/// from mu = 0.2, where x^2 ~ 0.006).
#[test]
fn high_speed_limit_is_ct_over_two_mu() {
    let ct = 0.006;
    let mut last = f64::INFINITY;
    for mu in [0.2, 0.4, 0.8, 1.6, 3.2] {
        let l0 = momentum_inflow(ct, cond(mu, 0.0));
        let d = (ct / (2.0 * mu) - l0) / l0;
        let estimate = ct * ct / (8.0 * mu.powi(4));
        assert!(d > 0.0 && d < last / 15.0, "mu {mu}: {d:e} after {last:e}");
        assert!(rel(d, estimate) < 0.01, "mu {mu}: {d:e} vs {estimate:e}");
        last = d;
    }
}

/// Pitt-Peters steady state for a thrust-only loading: l0 is the momentum inflow (1e-12), no
/// lateral gradient, in hover, in climb and at mu = 0.05 ... 0.4.
#[test]
fn pitt_peters_steady_thrust_only_is_momentum() {
    for (mu, lf) in [
        (0.0, 0.0),
        (0.0, 0.03),
        (0.05, 0.01),
        (0.1, 0.02),
        (0.2, 0.02),
        (0.3, 0.02),
        (0.4, 0.02),
    ] {
        let c = cond(mu, lf);
        let s = Inflow::steady(InflowModel::PittPeters, c, &thrust(0.006));
        let l0 = momentum_inflow(0.006, c);
        assert!((s[0] - l0).abs() < 1e-12, "mu {mu}: {} vs {l0}", s[0]);
        assert!(s[1].abs() < 1e-15, "mu {mu}: ls {}", s[1]);
        // uniform and with_thrust agree
        let u = Inflow::steady(InflowModel::Uniform, c, &thrust(0.006));
        assert!((u[0] - l0).abs() < 1e-15);
        let w = Inflow::new(InflowModel::PittPeters, c).with_thrust(0.006);
        assert_eq!(w.state(), s);
    }
}

/// The classical skewed-wake result: for a thrust-only loading lc = (15 pi/32) tan(chi/2) l0
/// (from lc = L31 ct / V_T = (15pi/64) X ct / V_T and l0 = ct / (2 V_T)); positive, more
/// inflow aft. At mu = 0.3, lambda_free = 0.02: chi ~ 84 deg, lc ~ 1.33 l0.
#[test]
fn skew_result_lc_is_15pi_over_32_tan_half_chi_l0() {
    for mu in [0.05, 0.1, 0.2, 0.3, 0.4] {
        let c = cond(mu, 0.02);
        let s = Inflow::steady(InflowModel::PittPeters, c, &thrust(0.006));
        let want = 15.0 * PI / 32.0 * (chi(c, s[0]) / 2.0).tan() * s[0];
        assert!(rel(s[2], want) < 1e-12, "mu {mu}: lc {} vs {want}", s[2]);
        assert!(s[2] > 0.0);
        let mut inflow = Inflow::new(InflowModel::PittPeters, c);
        inflow.set_state(s);
        // more inflow aft (psi = 0) than forward (psi = 180 deg)
        assert!(inflow.lambda_i(1.0, 0.0) > inflow.lambda_i(1.0, PI));
        assert!((inflow.skew_angle_rad() - chi(c, s[0])).abs() < 1e-14);
        assert!((inflow.total_lambda() - (0.02 + s[0])).abs() < 1e-16);
    }
    let s = Inflow::steady(InflowModel::PittPeters, cond(0.3, 0.02), &thrust(0.006));
    assert!((s[2] / s[0] - 1.33).abs() < 0.01, "lc/l0 {}", s[2] / s[0]);
}

/// With moments: the steady state is l = L V^-1 F with V_T = sqrt(mu^2 + lambda^2),
/// V = (mu^2 + lambda (lambda + l0)) / V_T at the solution's own l0 (1e-12 relative), and the
/// moments act the right way: cs > 0 gives ls > 0 (more inflow on the advancing side), cc > 0
/// gives more lc than the thrust-only loading; in hover lc = cc / l0 (L33 / V = 2 / 2 l0).
#[test]
fn pitt_peters_steady_with_moments_is_l_v_inverse_f() {
    let loads = DiskLoads {
        ct: 0.006,
        cs: 0.0004,
        cc: 0.0003,
    };
    for (mu, lf) in [
        (0.0, 0.0),
        (0.1, 0.02),
        (0.2, 0.02),
        (0.3, 0.02),
        (0.4, 0.02),
    ] {
        let c = cond(mu, lf);
        let s = Inflow::steady(InflowModel::PittPeters, c, &loads);
        let lam = lf + s[0];
        let vt = (mu * mu + lam * lam).sqrt();
        let v = (mu * mu + lam * (lam + s[0])) / vt;
        let l = l_matrix(chi(c, s[0]));
        let f = [loads.ct / vt, loads.cs / v, loads.cc / v];
        for i in 0..3 {
            let want: f64 = (0..3).map(|j| l[i][j] * f[j]).sum();
            assert!(
                (s[i] - want).abs() < 1e-12 * want.abs().max(s[0]),
                "mu {mu}: state {i} {} vs {want}",
                s[i]
            );
        }
        assert!(s[1] > 0.0, "mu {mu}: ls {}", s[1]);
        let t = Inflow::steady(InflowModel::PittPeters, c, &thrust(0.006));
        assert!(s[2] > t[2], "mu {mu}: lc {} vs thrust-only {}", s[2], t[2]);
        if mu == 0.0 {
            assert!(rel(s[2], loads.cc / s[0]) < 1e-12);
            assert!(rel(s[1], loads.cs / s[0]) < 1e-12);
        }
    }
}

/// Hover dynamics. The l0 row in hover is (8/(3pi)) dl0/dpsi + 2 V_T l0 = ct with
/// V_T = l0, i.e. the Riccati equation dl0/dpsi = (3pi/4)(ct - 2 l0^2): closed form
/// l0 = a tanh(k a psi + atanh(l_start / a)), a = sqrt(ct/2), k = 3pi/4. Linearised about the
/// steady state: M11 d(dl)/dpsi + 4 l0 dl = 0 (d(2 l0^2)/dl0 = 4 l0, i.e. the mass flow of the
/// perturbation V = 2 V_T in hover), decay rate 4 l0 / M11 = (3pi/2) l0, time constant
/// M11 / (4 l0) ~ 3.8 rad of azimuth at ct = 0.005 (l0 = 0.05).
#[test]
fn pitt_peters_hover_time_constant() {
    let c = cond(0.0, 0.0);
    // small step 0.005 -> 0.00501: measured decay rate within 1% of (3pi/2) l0
    let mut inflow = Inflow::new(InflowModel::PittPeters, c).with_thrust(0.005);
    let ct1 = 0.00501;
    let l_end = (ct1 / 2.0f64).sqrt();
    let dpsi = 0.01;
    let (mut psi, mut d5, mut d15) = (0.0, 0.0, 0.0);
    while psi < 15.0 - 1e-9 {
        inflow.advance(dpsi, &thrust(ct1));
        psi += dpsi;
        if (psi - 5.0).abs() < 1e-9 {
            d5 = l_end - inflow.state()[0];
        }
    }
    d15 += l_end - inflow.state()[0];
    let rate = (d5 / d15).ln() / 10.0;
    let want = 1.5 * PI * l_end;
    assert!(rel(rate, want) < 0.01, "rate {rate} vs {want}");
    assert!(rel(PITT_PETERS_M[0] / (4.0 * l_end), 1.0 / want) < 1e-14);

    // large step 0.002 -> 0.006: the marched response against the Riccati closed form
    let (ct0, ct1) = (0.002, 0.006);
    let mut inflow = Inflow::new(InflowModel::PittPeters, c).with_thrust(ct0);
    let a = (ct1 / 2.0f64).sqrt();
    let start = (ct0 / 2.0f64).sqrt();
    let dpsi = 0.05;
    let mut worst = 0.0f64;
    for n in 1..=600 {
        inflow.advance(dpsi, &thrust(ct1));
        let psi = n as f64 * dpsi;
        let exact = a * (0.75 * PI * a * psi + (start / a).atanh()).tanh();
        worst = worst.max(rel(inflow.state()[0], exact));
    }
    assert!(worst < 1e-5, "worst relative error {worst:e}");
}

/// Steps of dpsi = 2 pi (and 20 pi) stay stable and converge to the steady state, from rest
/// and after a load change, in hover and at mu = 0.1, 0.3, 0.4 with moments; small steps reach
/// the same steady state.
#[test]
fn pitt_peters_big_steps_stable() {
    let loads = DiskLoads {
        ct: 0.007,
        cs: -0.0005,
        cc: 0.0004,
    };
    for (mu, lf) in [(0.0, 0.0), (0.1, 0.02), (0.3, 0.02), (0.4, 0.05)] {
        let c = cond(mu, lf);
        let want = Inflow::steady(InflowModel::PittPeters, c, &loads);
        for dpsi in [2.0 * PI, 20.0 * PI, 0.1] {
            let mut inflow = Inflow::new(InflowModel::PittPeters, c).with_thrust(0.002);
            let mut bound = 0.0f64;
            for _ in 0..(if dpsi < 1.0 { 3000 } else { 200 }) {
                inflow.advance(dpsi, &loads);
                let s = inflow.state();
                assert!(
                    s.iter().all(|v| v.is_finite()),
                    "mu {mu} dpsi {dpsi}: {s:?}"
                );
                bound = bound.max(s.iter().fold(0.0f64, |m, v| m.max(v.abs())));
            }
            let s = inflow.state();
            for i in 0..3 {
                assert!(
                    (s[i] - want[i]).abs() < 1e-10 * want[0],
                    "mu {mu} dpsi {dpsi}: state {i} {} vs {}",
                    s[i],
                    want[i]
                );
            }
            assert!(bound < 5.0 * want.iter().fold(0.0f64, |m, v| m.max(v.abs())));
            // steady is a fixed point of the step
            inflow.advance(dpsi, &loads);
            for i in 0..3 {
                assert!((inflow.state()[i] - want[i]).abs() < 1e-14);
            }
        }
    }
}

/// Drees at mu = 0.3, lambda_free = 0.02, ct = 0.006: l0 the momentum value, lc = kx l0 with
/// kx = (4/3)(1 - cos chi - 1.8 mu^2)/sin chi (~0.98 here), ls = ky l0 with ky = -2 mu.
#[test]
fn drees_shape_at_mu_03() {
    let c = cond(0.3, 0.02);
    let s = Inflow::steady(InflowModel::Drees, c, &thrust(0.006));
    let l0 = momentum_inflow(0.006, c);
    let x = chi(c, l0);
    let kx = 4.0 / 3.0 * (1.0 - x.cos() - 1.8 * 0.09) / x.sin();
    assert_eq!(s[0], l0);
    assert!(rel(s[2], kx * l0) < 1e-12, "lc {} vs {}", s[2], kx * l0);
    assert!(rel(s[1], -0.6 * l0) < 1e-14);
    assert!(kx > 0.9 && kx < 1.1, "kx {kx}");
    // the distribution it gives
    let mut inflow = Inflow::new(InflowModel::Drees, c);
    inflow.set_state(s);
    let lam = inflow.lambda_i(0.7, 0.25 * PI);
    let want = l0 * (1.0 + kx * 0.7 * (0.25 * PI).cos() - 0.6 * 0.7 * (0.25 * PI).sin());
    assert!(rel(lam, want) < 1e-13);
    // hover: no gradient
    let h = Inflow::steady(InflowModel::Drees, cond(0.0, 0.0), &thrust(0.006));
    assert_eq!((h[1], h[2]), (0.0, 0.0));
}

/// Uniform and Drees are quasi-steady: one advance of any size lands on the steady state.
#[test]
fn uniform_and_drees_reach_steady_in_one_step() {
    let loads = DiskLoads {
        ct: 0.0065,
        cs: 0.0002,
        cc: -0.0001,
    };
    for model in [InflowModel::Uniform, InflowModel::Drees] {
        for (mu, lf) in [(0.0, 0.0), (0.3, 0.02)] {
            let c = cond(mu, lf);
            let mut inflow = Inflow::new(model, c).with_thrust(0.002);
            inflow.advance(0.01, &loads);
            assert_eq!(inflow.state(), Inflow::steady(model, c, &loads));
            assert_eq!(inflow.state()[0], momentum_inflow(0.0065, c));
        }
    }
}

#[test]
fn model_names() {
    for (s, m) in [
        ("uniform", InflowModel::Uniform),
        ("drees", InflowModel::Drees),
        ("pitt-peters", InflowModel::PittPeters),
    ] {
        assert_eq!(s.parse::<InflowModel>().unwrap(), m);
        assert_eq!(m.name(), s);
    }
    assert!("pitt_peters".parse::<InflowModel>().is_err());
}

/// advance does not allocate (any model).
#[test]
fn advance_does_not_allocate() {
    assert_counting();
    let loads = DiskLoads {
        ct: 0.006,
        cs: 0.0003,
        cc: 0.0002,
    };
    for model in [
        InflowModel::Uniform,
        InflowModel::Drees,
        InflowModel::PittPeters,
    ] {
        let mut inflow = Inflow::new(model, cond(0.3, 0.02)).with_thrust(0.005);
        let before = allocations();
        for _ in 0..100 {
            inflow.advance(0.1, &loads);
        }
        assert_eq!(allocations(), before, "{}", model.name());
    }
}
