//! The air-resonance rotor (rigid flapping and lagging blades on a hub that translates and
//! rotates, quasi-steady aerodynamics in hover) against references it does not share code
//! with: the flap and lag roots of a uniform blade written in closed form here, the
//! ground-resonance model of Coleman & Feingold (`LagRotor`, derived by hand) with the air
//! switched off, and its own Floquet integration against its Coleman eigenvalues.
use rotorsim::aero::airfoil::{Airfoil, ThinAirfoil};
use rotorsim::aero::section::Air;
use rotorsim::stability::{
    AirBlade, AirRotor, AirframeAxis, BodyAxis, BodyDof, LagBlade, LagRotor, Mode, ModeLabel, Strip,
};
use std::f64::consts::PI;

const RADIUS: f64 = 8.0;
const HINGE: f64 = 0.4;
const CHORD: f64 = 0.53;
const MASS_PER_M: f64 = 12.0;
const STRIPS: usize = 400;

fn air(density: f64) -> Air {
    Air {
        density_kg_m3: density,
        speed_of_sound_m_s: 340.3,
    }
}

/// A uniform blade from the hinge to the tip in equal strips (midpoints), pitch `pitch_rad`.
fn blade(pitch_rad: f64, lag_k: f64, lag_c: f64, flap_k: f64) -> AirBlade {
    let l = RADIUS - HINGE;
    let d = l / STRIPS as f64;
    AirBlade {
        hinge_offset_m: HINGE,
        strips: (0..STRIPS)
            .map(|j| Strip {
                rho_m: (j as f64 + 0.5) * d,
                mass_kg: MASS_PER_M * d,
                width_m: d,
                chord_m: CHORD,
                pitch_rad,
                lift_factor: 1.0,
                airfoil: 0,
            })
            .collect(),
        lag_stiffness_nm_per_rad: lag_k,
        lag_damping_nms_per_rad: lag_c,
        flap_stiffness_nm_per_rad: flap_k,
        flap_damping_nms_per_rad: 0.0,
    }
}

fn thin(cd0: f64) -> Vec<Airfoil> {
    vec![Airfoil::Thin(ThinAirfoil {
        lift_slope_per_rad: 2.0 * PI,
        cd0,
        cm0: 0.0,
    })]
}

fn rotor(blades: Vec<AirBlade>, body: Vec<BodyDof>, density: f64, cd0: f64) -> AirRotor {
    AirRotor {
        blades,
        body,
        air: air(density),
        airfoils: thin(cd0),
        radius_m: RADIUS,
    }
}

fn find(modes: &[Mode], label: ModeLabel) -> &Mode {
    modes
        .iter()
        .find(|m| m.label == label)
        .unwrap_or_else(|| panic!("no {label} mode in {modes:?}"))
}

/// Roots of `a s^2 + b s + c` with `Im >= 0`.
fn root(a: f64, b: f64, c: f64) -> (f64, f64) {
    let disc = b * b - 4.0 * a * c;
    assert!(disc < 0.0);
    (-b / (2.0 * a), (-disc).sqrt() / (2.0 * a))
}

/// Uniform blade, zero pitch, no drag: no lift at rest, so no coning, no inflow, and the flap
/// and lag equations decouple. Collective flap: `I s^2 + c_beta s + (I + e S) Omega^2 = 0`
/// with the aerodynamic flap damping `c_beta = 1/2 rho a c Omega (L^4/4 + e L^3/3)` (the lift
/// of `U_P = rho beta'` at `U_T = Omega (e + rho)`, moment about the hinge); collective lag:
/// `I s^2 + e S Omega^2 = 0`. Integrals in closed form: the midpoint strips are within
/// `O(1/STRIPS^2)` (2e-6 here) of them.
#[test]
fn uniform_blade_flap_and_lag_roots_in_closed_form() {
    let omega = 27.0;
    let r = rotor(vec![blade(0.0, 0.0, 0.0, 0.0); 4], vec![], 1.225, 0.0);
    let (h, modes) = r.coleman_eigenvalues(omega).unwrap();
    assert!(h.thrust_n.abs() < 1e-6, "thrust {}", h.thrust_n);
    assert!(h.flap_rad[0].abs() < 1e-12 && h.lag_rad[0].abs() < 1e-12);
    let l = RADIUS - HINGE;
    let i_b = MASS_PER_M * l.powi(3) / 3.0;
    let s_b = MASS_PER_M * l * l / 2.0;
    let c_beta =
        0.5 * 1.225 * 2.0 * PI * CHORD * omega * (l.powi(4) / 4.0 + HINGE * l.powi(3) / 3.0);
    let (re, im) = root(i_b, c_beta, (i_b + HINGE * s_b) * omega * omega);
    let flap = find(&modes, ModeLabel::CollectiveFlap);
    let tol = 1e-5;
    assert!(
        (flap.eigenvalue.re - re).abs() < tol * im && (flap.eigenvalue.im - im).abs() < tol * im,
        "collective flap {} vs closed form {re} + {im} i",
        flap.eigenvalue
    );
    let lag = find(&modes, ModeLabel::CollectiveLag);
    let wl = (HINGE * s_b / i_b).sqrt() * omega;
    assert!(lag.eigenvalue.re.abs() < 1e-9 * wl, "{}", lag.eigenvalue);
    assert!(
        (lag.eigenvalue.im - wl).abs() < tol * wl,
        "{} vs {wl}",
        lag.eigenvalue
    );
    // the differential roots are the same rotating-frame roots (no hub coupling)
    let dflap = find(&modes, ModeLabel::DifferentialFlap);
    assert!((dflap.eigenvalue - flap.eigenvalue).norm() < 1e-9 * im);
    // the Lock number's classical form with e = 0 would be gamma/8 Omega; here the strips'
    // own sums (not the code's) give the damping within 1e-9
    let d = l / STRIPS as f64;
    let (mut i_s, mut c_s) = (0.0, 0.0);
    for j in 0..STRIPS {
        let rho = (j as f64 + 0.5) * d;
        i_s += MASS_PER_M * d * rho * rho;
        c_s += 0.5 * 1.225 * 2.0 * PI * CHORD * omega * (HINGE + rho) * rho * rho * d;
    }
    assert!(
        (-2.0 * i_s * flap.eigenvalue.re - c_s).abs() < 1e-9 * c_s,
        "flap damping {} vs strip sum {c_s}",
        -2.0 * i_s * flap.eigenvalue.re
    );
}

/// With the air off and the hub moving only in the plane, the lag and hub modes are the
/// ground-resonance model's (derived by hand in `LagRotor`), and the flap modes decouple.
#[test]
fn without_air_the_in_plane_modes_are_coleman_and_feingold() {
    let omega = 22.0;
    let (lag_k, lag_c) = (20_000.0, 3_000.0);
    let ax = |m: f64, k: f64, c: f64| AirframeAxis {
        mass_kg: m,
        stiffness_n_per_m: k,
        damping_ns_per_m: c,
    };
    let body = vec![
        BodyDof {
            axis: BodyAxis::X,
            mass: 8026.6,
            stiffness: 1.24e6,
            damping: 20_000.0,
            center_z_m: 0.0,
        },
        BodyDof {
            axis: BodyAxis::Y,
            mass: 3283.6,
            stiffness: 0.9e6,
            damping: 8_000.0,
            center_z_m: 0.0,
        },
    ];
    let b = blade(0.1, lag_k, lag_c, 5_000.0);
    let r = rotor(vec![b.clone(); 4], body, 0.0, 0.0);
    let (_, modes) = r.coleman_eigenvalues(omega).unwrap();
    let lag = LagRotor {
        blades: vec![
            LagBlade {
                mass_kg: b.mass_kg(),
                first_moment_kg_m: b.first_moment_kg_m(),
                inertia_kg_m2: b.inertia_kg_m2(),
                hinge_offset_m: HINGE,
                stiffness_nm_per_rad: lag_k,
                damping_nms_per_rad: lag_c,
            };
            4
        ],
        x: Some(ax(8026.6, 1.24e6, 20_000.0)),
        y: Some(ax(3283.6, 0.9e6, 8_000.0)),
    };
    let reference = lag.coleman_eigenvalues(omega).unwrap();
    for m in &reference {
        let near = modes
            .iter()
            .filter(|a| a.label == m.label)
            .min_by(|a, b| {
                (a.eigenvalue - m.eigenvalue)
                    .norm()
                    .total_cmp(&(b.eigenvalue - m.eigenvalue).norm())
            })
            .unwrap();
        // the same physics derived twice; apart by the linearisation's differences (~1e-10)
        let err = (near.eigenvalue - m.eigenvalue).norm() / m.eigenvalue.norm();
        assert!(
            err < 1e-9,
            "{} {}: {} vs {} ({err:.2e})",
            m.label,
            m.frequency_hz,
            near.eigenvalue,
            m.eigenvalue
        );
        assert_eq!(near.label, m.label, "{near:?} vs {m:?}");
    }
    // the flap roots: rotating frame `I s^2 + (k + (I + e S) Omega^2) = 0`, no damping
    let i_b = b.inertia_kg_m2();
    let wf = ((5_000.0 + (i_b + HINGE * b.first_moment_kg_m()) * omega * omega) / i_b).sqrt();
    let cf = find(&modes, ModeLabel::CollectiveFlap);
    assert!((cf.eigenvalue.im - wf).abs() < 1e-8 * wf && cf.eigenvalue.re.abs() < 1e-8 * wf);
    for label in [ModeLabel::RegressingFlap, ModeLabel::ProgressiveFlap] {
        let f = find(&modes, label);
        let expected = if label == ModeLabel::RegressingFlap {
            wf - omega
        } else {
            wf + omega
        };
        assert!(
            (f.eigenvalue.im - expected).abs() < 1e-8 * wf,
            "{label}: {} vs {expected}",
            f.eigenvalue
        );
    }
}

/// A hovering rotor on an airframe that rolls and pitches about centres below the hub:
/// the multi-blade equations are constant in time, the Fourier series of a blade's matrices
/// equals its direct linearisation at any azimuth, and Floquet over one revolution gives
/// the Coleman eigenvalues.
fn hovering() -> AirRotor {
    let body = vec![
        BodyDof {
            axis: BodyAxis::Roll,
            mass: 7_600.0,
            stiffness: 2.0e5,
            damping: 1.0e3,
            center_z_m: -1.8,
        },
        BodyDof {
            axis: BodyAxis::Pitch,
            mass: 40_000.0,
            stiffness: 6.0e5,
            damping: 4.0e3,
            center_z_m: -1.8,
        },
        BodyDof {
            axis: BodyAxis::X,
            mass: 3_000.0,
            stiffness: 2.0e7,
            damping: 1.0e4,
            center_z_m: 0.0,
        },
    ];
    rotor(
        vec![blade(8f64.to_radians(), 20_400.0, 2_000.0, 20_400.0); 4],
        body,
        1.225,
        0.01,
    )
}

#[test]
fn hover_equations_are_periodic_as_claimed() {
    let r = hovering();
    let h = r.hover(27.0).unwrap();
    assert!(
        h.thrust_n > 1e4 && h.flap_rad[0] > 0.0 && h.lag_rad[0] < 0.0,
        "{h:?}"
    );
    // momentum theory closes
    let vi = (h.thrust_n / (2.0 * 1.225 * PI * RADIUS * RADIUS)).sqrt();
    assert!((h.inflow_m_s - vi).abs() < 1e-9 * vi);
    // The entries are fourth-order differences whose truncation and roundoff sit near 1e-10
    // of the residual's scale (the strips' summed forces); 1e-8 of each matrix's largest
    // entry leaves room for the sums over blades and the transformation.
    let tol = |m: &[f64]| 1e-8 * m.iter().fold(0.0f64, |a, v| a.max(v.abs()));
    let series = r.blade_series(0, &h);
    for psi in [0.3, 1.234, 4.0] {
        let direct = r.linearise_blade(0, &h, psi);
        let fourier = series.at(psi);
        for (d, f) in direct.iter().zip(&fourier) {
            let noise = tol(d);
            for (a, b) in d.iter().zip(f) {
                assert!((a - b).abs() < noise, "{a} vs {b} (tolerance {noise:.1e})");
            }
        }
    }
    let t = 0.37 * 2.0 * PI / 27.0;
    let a = r.coleman_matrices(&h, 0.0).unwrap();
    let b = r.coleman_matrices(&h, t).unwrap();
    for (ma, mb) in a.iter().zip(&b) {
        let entries: Vec<f64> = (0..ma.nrows())
            .flat_map(|i| (0..ma.ncols()).map(move |j| ma[(i, j)]))
            .collect();
        let noise = tol(&entries);
        for i in 0..ma.nrows() {
            for j in 0..ma.ncols() {
                assert!(
                    (ma[(i, j)] - mb[(i, j)]).abs() < noise,
                    "({i},{j}): {} vs {} (tolerance {noise:.1e})",
                    ma[(i, j)],
                    mb[(i, j)]
                );
            }
        }
    }
}

#[test]
fn floquet_of_the_isotropic_hovering_rotor_is_coleman() {
    let r = hovering();
    let omega = 27.0;
    let (_, coleman) = r.coleman_eigenvalues(omega).unwrap();
    let (_, floquet) = r.floquet(omega, 512).unwrap();
    assert_eq!(coleman.len(), floquet.len());
    for c in &coleman {
        let f = floquet
            .iter()
            .find(|f| f.label == c.label && (f.eigenvalue - c.eigenvalue).norm() < 1e-3 * omega)
            .unwrap_or_else(|| panic!("no Floquet match for {c:?}"));
        assert!(
            (f.eigenvalue - c.eigenvalue).norm() < 1e-6 * omega,
            "{}: {} vs {}",
            c.label,
            f.eigenvalue,
            c.eigenvalue
        );
    }
    for label in [
        ModeLabel::RegressingLag,
        ModeLabel::RegressingFlap,
        ModeLabel::AirframeRoll,
        ModeLabel::AirframePitch,
    ] {
        find(&coleman, label);
    }
}

/// One lag damper inoperative, air off, hub in the plane: the Floquet exponents of the
/// air-resonance rotor (its blade equations from positions, RK4 on its Fourier series) are
/// those of the ground-resonance rotor's own Floquet analysis (equations by hand).
#[test]
fn one_damper_out_floquet_matches_the_ground_resonance_model() {
    let omega = 24.0;
    let ax = |m: f64, k: f64, c: f64| AirframeAxis {
        mass_kg: m,
        stiffness_n_per_m: k,
        damping_ns_per_m: c,
    };
    let dof = |axis, m, k, c| BodyDof {
        axis,
        mass: m,
        stiffness: k,
        damping: c,
        center_z_m: 0.0,
    };
    let good = blade(0.1, 20_000.0, 3_000.0, 5_000.0);
    let mut out = good.clone();
    out.lag_damping_nms_per_rad = 0.0;
    let mut blades = vec![good.clone(); 4];
    blades[0] = out;
    let r = rotor(
        blades,
        vec![
            dof(BodyAxis::X, 8026.6, 1.24e6, 20_000.0),
            dof(BodyAxis::Y, 3283.6, 0.9e6, 8_000.0),
        ],
        0.0,
        0.0,
    );
    let (_, modes) = r.floquet(omega, 512).unwrap();
    let lb = |c: f64| LagBlade {
        mass_kg: good.mass_kg(),
        first_moment_kg_m: good.first_moment_kg_m(),
        inertia_kg_m2: good.inertia_kg_m2(),
        hinge_offset_m: HINGE,
        stiffness_nm_per_rad: 20_000.0,
        damping_nms_per_rad: c,
    };
    let lag = LagRotor {
        blades: vec![lb(0.0), lb(3_000.0), lb(3_000.0), lb(3_000.0)],
        x: Some(ax(8026.6, 1.24e6, 20_000.0)),
        y: Some(ax(3283.6, 0.9e6, 8_000.0)),
    };
    let reference = lag.floquet(omega, 512).unwrap();
    for m in &reference {
        let near = modes
            .iter()
            .min_by(|a, b| {
                (a.eigenvalue - m.eigenvalue)
                    .norm()
                    .total_cmp(&(b.eigenvalue - m.eigenvalue).norm())
            })
            .unwrap();
        // both RK4 at 512 steps per revolution (truncation in other coordinates) and the
        // linearisation's differences: about 1e-10 of Omega apart here
        assert!(
            (near.eigenvalue - m.eigenvalue).norm() < 1e-8 * omega,
            "{}: {} vs {}",
            m.label,
            near.eigenvalue,
            m.eigenvalue
        );
        assert!(
            (near.growth_rate_per_s - m.growth_rate_per_s).abs() < 1e-8 * omega,
            "{} growth {} vs {}",
            m.label,
            near.growth_rate_per_s,
            m.growth_rate_per_s
        );
    }
}
