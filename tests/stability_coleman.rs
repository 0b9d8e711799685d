//! Coleman eigenvalues against the constant-coefficient equations written again here (other
//! lag sign, other coordinate order and scaling, nalgebra's eigen solver), Floquet of the
//! isotropic rotor against Coleman, and every error variant once.
use nalgebra::{Complex, DMatrix};
use rotorsim::stability::{AirframeAxis, LagBlade, LagRotor, Mode, StabilityError};

fn blade(damping: f64) -> LagBlade {
    LagBlade {
        mass_kg: 94.9,
        first_moment_kg_m: 289.1,
        inertia_kg_m2: 1084.7,
        hinge_offset_m: 0.3048,
        stiffness_nm_per_rad: 20_000.0,
        damping_nms_per_rad: damping,
    }
}

fn rotor(n: usize, x: bool, y: bool) -> LagRotor {
    LagRotor {
        blades: vec![blade(3000.0); n],
        x: x.then_some(AirframeAxis {
            mass_kg: 8026.6,
            stiffness_n_per_m: 1.24e6,
            damping_ns_per_m: 20_000.0,
        }),
        y: y.then_some(AirframeAxis {
            mass_kg: 3283.6,
            stiffness_n_per_m: 0.9e6,
            damping_ns_per_m: 8_000.0,
        }),
    }
}

/// All fixed-frame eigenvalues, from the equations with the lag angle positive AGAINST the
/// rotation (Johnson's sign), coordinates `[x, y, b_c, b_s]` with the rotor centre-of-mass
/// offsets `b = N/2 S zeta_1` as unknowns, velocity-first companion matrix; the reactionless
/// modes from the rotating-frame roots shifted by `n Omega`.
fn independent(r: &LagRotor, omega: f64) -> Vec<Complex<f64>> {
    let nb = r.blades.len();
    let b = &r.blades[0];
    let nf = nb as f64;
    let (ib, sb, cb) = (b.inertia_kg_m2, b.first_moment_kg_m, b.damping_nms_per_rad);
    let kb = b.stiffness_nm_per_rad + b.hinge_offset_m * sb * omega * omega;
    let hs = nf / 2.0 * sb;
    // Blade rows of the cyclic equations, divided by hs so that the unknown is b = hs zeta.
    let (ib2, cb2, kb2) = (ib / hs, cb / hs, kb / hs);
    let mut axes = vec![];
    if let Some(a) = &r.x {
        axes.push((0usize, a));
    }
    if let Some(a) = &r.y {
        axes.push((1usize, a));
    }
    let nh = axes.len();
    let n = nh + 2;
    let (ic, is) = (nh, nh + 1);
    let mut m = DMatrix::<f64>::zeros(n, n);
    let mut c = DMatrix::<f64>::zeros(n, n);
    let mut k = DMatrix::<f64>::zeros(n, n);
    m[(ic, ic)] = ib2;
    m[(is, is)] = ib2;
    c[(ic, ic)] = cb2;
    c[(is, is)] = cb2;
    c[(ic, is)] = 2.0 * omega * ib2;
    c[(is, ic)] = -2.0 * omega * ib2;
    k[(ic, ic)] = kb2 - omega * omega * ib2;
    k[(is, is)] = kb2 - omega * omega * ib2;
    k[(ic, is)] = cb2 * omega;
    k[(is, ic)] = -cb2 * omega;
    for (j, (axis, a)) in axes.iter().enumerate() {
        m[(j, j)] = a.mass_kg + nf * b.mass_kg;
        c[(j, j)] = a.damping_ns_per_m;
        k[(j, j)] = a.stiffness_n_per_m;
        // Lag against rotation: every coupling sign flips.
        if *axis == 0 {
            m[(j, is)] = 1.0;
            m[(is, j)] = sb;
        } else {
            m[(j, ic)] = -1.0;
            m[(ic, j)] = -sb;
        }
    }
    let mi = m.try_inverse().expect("mass matrix");
    let mut a = DMatrix::<f64>::zeros(2 * n, 2 * n);
    let mic = -&mi * &c;
    let mik = -&mi * &k;
    for i in 0..n {
        for j in 0..n {
            a[(i, j)] = mic[(i, j)];
            a[(i, n + j)] = mik[(i, j)];
        }
        a[(n + i, i)] = 1.0;
    }
    let mut out: Vec<Complex<f64>> = a.complex_eigenvalues().iter().copied().collect();
    // I s^2 + c s + K = 0 in the rotating frame.
    let disc = Complex::new(cb * cb - 4.0 * ib * kb, 0.0).sqrt();
    let roots = [
        (Complex::new(-cb, 0.0) + disc) / (2.0 * ib),
        (Complex::new(-cb, 0.0) - disc) / (2.0 * ib),
    ];
    out.extend(roots); // collective
    if nb.is_multiple_of(2) {
        out.extend(roots); // differential
    }
    for h in 2..=(nb - 1) / 2 {
        for rt in roots {
            for sign in [-1.0, 1.0] {
                out.push(rt + Complex::new(0.0, sign * h as f64 * omega));
            }
        }
    }
    assert_eq!(out.len(), 2 * r.coordinate_count());
    out
}

fn rel(a: Complex<f64>, b: Complex<f64>) -> f64 {
    (a - b).norm() / b.norm()
}

fn lib_c(m: &Mode) -> Complex<f64> {
    Complex::new(m.eigenvalue.re, m.eigenvalue.im)
}

/// Both ways: each library mode is in the reference set, each reference eigenvalue with
/// `Im > 0` is among the library modes.
fn max_set_error(lib: &[Complex<f64>], reference: &[Complex<f64>]) -> f64 {
    let nearest = |z: Complex<f64>, set: &[Complex<f64>]| {
        set.iter().map(|w| rel(z, *w)).fold(f64::MAX, f64::min)
    };
    let mut worst: f64 = 0.0;
    for z in lib {
        worst = worst.max(nearest(*z, reference));
    }
    for z in reference.iter().filter(|z| z.im > 1e-9 * z.norm()) {
        worst = worst.max(nearest(*z, lib));
    }
    worst
}

const SPEEDS_RAD_S: [f64; 5] = [6.0, 12.0, 17.0, 24.0, 33.0];

#[test]
fn coleman_matches_independent_equations() {
    let mut worst: f64 = 0.0;
    for (nb, x, y) in [
        (3, true, true),
        (4, true, true),
        (5, true, true),
        (4, true, false),
        (4, false, true),
    ] {
        let r = rotor(nb, x, y);
        for omega in SPEEDS_RAD_S {
            let modes = r.coleman_eigenvalues(omega).unwrap();
            assert_eq!(
                modes.len(),
                r.coordinate_count(),
                "one mode per conjugate pair"
            );
            let lib: Vec<_> = modes.iter().map(lib_c).collect();
            let e = max_set_error(&lib, &independent(&r, omega));
            assert!(e < 1e-6, "N = {nb}, x {x}, y {y}, Omega {omega}: {e:e}");
            worst = worst.max(e);
        }
    }
    println!("Coleman vs independent equations: max relative error {worst:.2e}");
    // Labels of the uncoupled-looking cases: frequencies of the regressing lag below Omega.
    let modes = rotor(4, true, true).coleman_eigenvalues(33.0).unwrap();
    for m in &modes {
        println!(
            "  Omega 33: {:>16} {:8.4} Hz  zeta {:+.4}",
            m.label.as_str(),
            m.frequency_hz,
            m.damping_ratio
        );
    }
    let f_omega = 33.0 / (2.0 * std::f64::consts::PI);
    let reg: Vec<_> = modes
        .iter()
        .filter(|m| m.label.as_str() == "regressing lag")
        .collect();
    let prog: Vec<_> = modes
        .iter()
        .filter(|m| m.label.as_str() == "progressive lag")
        .collect();
    assert_eq!((reg.len(), prog.len()), (1, 1));
    assert!(reg[0].frequency_hz < f_omega && prog[0].frequency_hz > f_omega);
    for label in [
        "collective lag",
        "differential lag",
        "airframe x",
        "airframe y",
    ] {
        assert_eq!(
            modes.iter().filter(|m| m.label.as_str() == label).count(),
            1,
            "{label}"
        );
    }
}

#[test]
fn floquet_of_isotropic_rotor_equals_coleman() {
    let (mut worst_growth, mut worst_freq, mut worst_abs): (f64, f64, f64) = (0.0, 0.0, 0.0);
    for (nb, x, y) in [
        (3, true, true),
        (4, true, true),
        (5, true, true),
        (4, false, true),
    ] {
        let r = rotor(nb, x, y);
        for omega in SPEEDS_RAD_S {
            let coleman = r.coleman_eigenvalues(omega).unwrap();
            let floquet = r.floquet(omega, 1000).unwrap();
            assert_eq!(coleman.len(), floquet.len());
            for f in &floquet {
                let c = coleman
                    .iter()
                    .min_by(|a, b| rel(lib_c(a), lib_c(f)).total_cmp(&rel(lib_c(b), lib_c(f))))
                    .unwrap();
                // Collective and differential lag share a root: either label fits.
                let same_root: Vec<_> = coleman
                    .iter()
                    .filter(|o| rel(lib_c(o), lib_c(c)) < 1e-9)
                    .collect();
                assert!(
                    same_root.iter().any(|o| o.label == f.label),
                    "N {nb} Omega {omega}: {}",
                    f.label
                );
                let eg =
                    (f.growth_rate_per_s - c.growth_rate_per_s).abs() / c.growth_rate_per_s.abs();
                let ef = (f.frequency_hz - c.frequency_hz).abs() / c.frequency_hz.max(1e-12);
                assert!(
                    eg < 1e-6 && ef < 1e-6,
                    "N {nb} Omega {omega} {}: growth {eg:e} frequency {ef:e}",
                    c.label
                );
                worst_growth = worst_growth.max(eg);
                worst_freq = worst_freq.max(ef);
                worst_abs = worst_abs.max(rel(lib_c(f), lib_c(c)));
            }
        }
    }
    println!(
        "Floquet (isotropic) vs Coleman: growth rate {worst_growth:.2e}, frequency {worst_freq:.2e}, eigenvalue {worst_abs:.2e} (max relative)"
    );
}

#[test]
fn each_error_variant_once() {
    let msg = |e: StabilityError| e.to_string();

    let mut r = rotor(4, true, true);
    r.blades[1].mass_kg = f64::NAN;
    let e = r.coleman_eigenvalues(20.0).unwrap_err();
    assert!(matches!(e, StabilityError::NotFinite { .. }));
    assert_eq!(msg(e), "blades[1].mass_kg = NaN is not finite");

    let mut r = rotor(4, true, true);
    r.blades[2].mass_kg = -1.0;
    let e = r.floquet(20.0, 100).unwrap_err();
    assert!(matches!(e, StabilityError::OutOfRange { .. }));
    assert_eq!(
        msg(e),
        "blades[2].mass_kg = -1 is out of range: expected > 0"
    );

    let e = rotor(2, true, true).coleman_eigenvalues(20.0).unwrap_err();
    assert!(matches!(e, StabilityError::TooFewBlades { .. }));
    assert_eq!(
        msg(e),
        "the Coleman transformation needs at least 3 blades; the rotor has 2"
    );

    let mut r = rotor(4, true, true);
    r.blades[3].damping_nms_per_rad = 0.0;
    let e = r.coleman_eigenvalues(20.0).unwrap_err();
    assert!(matches!(e, StabilityError::NotIsotropic { .. }));
    assert_eq!(
        msg(e),
        "the Coleman transformation needs identical blades: blade 4 differs from blade 1 in \
         damping_nms_per_rad (use floquet for a dissimilar rotor)"
    );

    let r = rotor(3, true, false);
    let e = r.time_response(20.0, &[0.0; 3], 1.0, 0.01).unwrap_err();
    assert!(matches!(e, StabilityError::StateLength { .. }));
    assert_eq!(
        msg(e),
        "initial state has 3 entries; expected 8 (zeta_1 [rad], zeta_2 [rad], zeta_3 [rad], x [m], then their rates)"
    );

    // A step far beyond RK4's stability limit overflows.
    let mut init = vec![0.0; r.state_len()];
    init[3] = 0.1;
    let e = r.time_response(20.0, &init, 10_000.0, 10.0).unwrap_err();
    assert!(matches!(e, StabilityError::Numerical(_)));
    assert!(msg(e).starts_with("numerical failure: time response is not finite at t = "));
}

/// Coleman & Feingold's classical result: without damping, an isotropic rotor on an isotropic
/// support is unstable where the regressing lag frequency `(1 - nu) Omega` meets the support
/// frequency `omega_b`, and neutrally stable well away from it.
#[test]
fn undamped_instability_at_the_regressing_lag_coincidence() {
    let mut r = rotor(4, true, true);
    for b in &mut r.blades {
        b.damping_nms_per_rad = 0.0;
        b.stiffness_nm_per_rad = 0.0;
    }
    let axis = AirframeAxis {
        mass_kg: 5000.0,
        stiffness_n_per_m: 1.0e6,
        damping_ns_per_m: 0.0,
    };
    r.x = Some(axis.clone());
    r.y = Some(axis);
    let b = &r.blades[0];
    let nu = (b.hinge_offset_m * b.first_moment_kg_m / b.inertia_kg_m2).sqrt();
    let omega_b = (1.0e6 / (5000.0 + 4.0 * b.mass_kg)).sqrt();
    let growth = |w: f64| {
        let modes = r.coleman_eigenvalues(w).unwrap();
        let scale = modes
            .iter()
            .map(|m| m.eigenvalue.norm())
            .fold(0.0, f64::max);
        let g = modes
            .iter()
            .map(|m| m.growth_rate_per_s)
            .fold(f64::MIN, f64::max);
        g / scale
    };
    let coincidence = omega_b / (1.0 - nu);
    println!(
        "undamped: nu {nu:.4}, coincidence {coincidence:.3} rad/s, growth/|lambda| there {:.3e}",
        growth(coincidence)
    );
    assert!(growth(coincidence) > 1e-3);
    for w in [0.4 * coincidence, 2.5 * coincidence] {
        assert!(growth(w).abs() < 1e-9, "{w}: {}", growth(w));
    }
}
