//! An elastomer about a revolute joint in the multibody solver: a rigid body on an elastomeric
//! hinge (model deck `elastomer = {...}`) released with an angular velocity follows the exact
//! solution of the continuous system (body and Maxwell branches as a linear ODE, by the matrix
//! exponential: an independent reference for the joint, the solver's step and the commits).
//! Also: a snapshot restores the branch history, and bad elastomer keys are refused with the
//! key.
use nalgebra::{DMatrix, DVector};
use rotorsim::solver::{DynamicSolver, State};
use rotorsim::structure::deck::parse_deck;
use rotorsim::structure::elastomer::MaxwellChain;
use rotorsim::structure::model::Element;
use std::path::Path;

const INERTIA: f64 = 1.0;
const K: f64 = 400.0;
const ETA: f64 = 0.1;
/// Undamped frequency sqrt(K / I) [rad/s], the chain's reference frequency.
const W: f64 = 20.0;

fn deck(elastomer: &str) -> String {
    format!(
        r#"
[[node]]
name = "body"
position_m = [0.0, 0.0, 0.0]

[[rigid_body]]
name = "disk"
node = "body"
mass_kg = 1.0
inertia_kgm2 = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, {INERTIA}]]

[[joint]]
name = "hinge"
type = "revolute"
node_b = "body"
axis = [0.0, 0.0, 1.0]
stiffness_Nm_per_rad = {K}
{elastomer}

[[sensor]]
name = "hinge"
joint = "hinge"
"#
    )
}

fn good() -> String {
    deck(&format!(
        "elastomer = {{ loss_factor = {ETA}, band_rad_s = [{}, {}], reference_rad_s = {W} }}",
        0.3 * W,
        4.0 * W
    ))
}

/// The exact free decay of the continuous system: state `[psi, psi', m_1..m_n]` with
/// `I psi'' = -(K_inf psi + sum m_i)` and `m_i' = k_i psi' - m_i / tau_i`, stepped by the
/// matrix exponential of its (constant) system matrix.
fn exact_decay(c: &MaxwellChain, h: f64, steps: usize, rate0: f64) -> Vec<f64> {
    let nb = c.k.len();
    let n = 2 + nb;
    let mut a = DMatrix::<f64>::zeros(n, n);
    a[(0, 1)] = 1.0;
    a[(1, 0)] = -c.k_inf / INERTIA;
    for i in 0..nb {
        a[(1, 2 + i)] = -1.0 / INERTIA;
        a[(2 + i, 1)] = c.k[i];
        a[(2 + i, 2 + i)] = -1.0 / c.tau_s[i];
    }
    let step = (a * h).exp();
    let mut x = DVector::<f64>::zeros(n);
    x[1] = rate0;
    let mut out = vec![0.0];
    for _ in 0..steps {
        x = &step * &x;
        out.push(x[0]);
    }
    out
}

/// Angle history of the free decay: `steps_per_period` steps per undamped period, `periods`
/// periods, released at zero angle with angular velocity 0.1 rad/s.
fn decay(steps_per_period: usize, periods: usize) -> (Vec<f64>, Vec<f64>, MaxwellChain) {
    let (_, model) = parse_deck(&good(), "elastomer.toml", Path::new(".")).unwrap();
    let chain = model
        .elements
        .iter()
        .find_map(|e| match e {
            Element::Joint(j) => j.elastomer.map(|e| e.chain),
            _ => None,
        })
        .expect("the hinge has an elastomer");
    let mut st = State::from_model(&model);
    st.w[0] = [0.0, 0.0, 0.1];
    let h = 2.0 * std::f64::consts::PI / W / steps_per_period as f64;
    let mut s = DynamicSolver::new(model, st, h, 1.0).unwrap();
    s.init_accelerations().unwrap();
    let col = s
        .sensor_header()
        .iter()
        .position(|c| c == "hinge.angle_rad")
        .unwrap();
    let (mut t, mut a) = (vec![0.0], vec![0.0]);
    for _ in 0..steps_per_period * periods {
        s.step().unwrap();
        t.push(s.state.t);
        a.push(s.sensor_values()[col]);
    }
    (t, a, chain)
}

#[test]
fn free_decay_on_an_elastomeric_hinge_matches_the_exact_solution() {
    // 14 undamped periods: the oscillation decays to ~1% and the branches' relaxation modes
    // (real roots near -1/tau_i) are in it from the start. The solver (generalized alpha,
    // rho_inf 1, and the chain stepped exactly for an angle linear in each step) errs at
    // second order in the step, mostly in phase: w t (w h)^2 / 12 times the amplitude
    // exp(-sigma t), largest near t = 1/sigma (sigma ~ 1/s here): 3.8e-5 of the peak at 800
    // steps per period.
    let periods = 14;
    let mut errs = vec![];
    for n in [400, 800] {
        let (t, a, chain) = decay(n, periods);
        let h = t[1] - t[0];
        let exact = exact_decay(&chain, h, n * periods, 0.1);
        let peak = exact.iter().fold(0.0f64, |m, x| m.max(x.abs()));
        let err = a
            .iter()
            .zip(&exact)
            .fold(0.0f64, |m, (x, y)| m.max((x - y).abs()))
            / peak;
        println!("{n} steps per period: max |psi - exact| / max |exact| = {err:.2e}");
        errs.push(err);
    }
    assert!(errs[1] < 1e-4, "{errs:?}");
    let order = (errs[0] / errs[1]).log2();
    assert!(
        (order - 2.0).abs() < 0.3,
        "convergence order {order:.2} ({errs:?})"
    );
}

#[test]
fn the_loss_factor_holds_over_the_band_in_the_deck_built_chain() {
    let (_, _, c) = decay(4, 1);
    for j in 0..=100 {
        let w = 0.3 * W * (4.0f64 / 0.3).powf(j as f64 / 100.0);
        let e = c.loss_factor(w);
        assert!((e / ETA - 1.0).abs() < 0.1, "loss factor {e} at {w} rad/s");
    }
    assert!((c.complex(W).0 / K - 1.0).abs() < 1e-12);
}

#[test]
fn bad_elastomer_keys_are_refused_with_the_key() {
    let cases = [
        (
            "elastomer = { loss_factor = -0.1, band_rad_s = [6.0, 80.0], reference_rad_s = 20.0 }",
            "hinge`.elastomer",
        ),
        (
            "elastomer = { loss_factor = 0.1, band_rad_s = [80.0, 6.0], reference_rad_s = 20.0 }",
            "band",
        ),
        (
            "elastomer = { loss_factor = 0.1, band_rad_s = [6.0, 80.0], reference_rad_s = 200.0 }",
            "reference frequency",
        ),
        (
            "elastomer = { loss_factor = 0.1, band_rad_s = [6.0, 80.0] }",
            "reference_rad_s",
        ),
    ];
    for (line, want) in cases {
        let err = parse_deck(&deck(line), "e.toml", Path::new("."))
            .err()
            .unwrap_or_else(|| panic!("accepted: {line}"))
            .to_string();
        assert!(err.contains(want), "{line}: {err}");
        assert!(err.contains("e.toml"), "{line}: {err}");
    }
    // a storage stiffness is needed
    let no_k = good().replace(&format!("stiffness_Nm_per_rad = {K}"), "");
    let err = parse_deck(&no_k, "e.toml", Path::new("."))
        .err()
        .unwrap()
        .to_string();
    assert!(err.contains("stiffness_Nm_per_rad"), "{err}");
}

/// The body on its elastomeric hinge released with 0.1 rad/s and stepped `steps` times (200
/// steps per undamped period, rho_inf 0.8).
fn released_for(steps: usize) -> DynamicSolver {
    let (_, model) = parse_deck(&good(), "e.toml", Path::new(".")).unwrap();
    let mut st = State::from_model(&model);
    st.w[0] = [0.0, 0.0, 0.1];
    let h = 2.0 * std::f64::consts::PI / W / 200.0;
    let mut s = DynamicSolver::new(model, st, h, 0.8).unwrap();
    for _ in 0..steps {
        s.step().unwrap();
    }
    s
}

#[test]
fn a_snapshot_restores_the_elastomer_history() {
    let mut s = released_for(137);
    let snap = s.snapshot();
    assert!(snap
        .joint_elastomers_nm
        .iter()
        .any(|v| v.iter().any(|&x| x != 0.0)));
    let mut after = vec![];
    for _ in 0..50 {
        s.step().unwrap();
        after.push(s.sensor_values());
    }
    // a replay from the snapshot equals the first pass to round-off (the stored factorization
    // is the later one, so not bit for bit); without the branch history it would not
    let replay = |s: &mut DynamicSolver| {
        let mut worst = 0.0f64;
        for row in &after {
            s.step().unwrap();
            for (x, y) in s.sensor_values().iter().zip(row) {
                worst = worst.max((x - y).abs() / y.abs().max(1e-3));
            }
        }
        worst
    };
    s.restore(&snap).unwrap();
    let with = replay(&mut s);
    assert!(with < 1e-12, "replay differs by {with:.2e}");
    // an older file without the elastomer entries loads, the elastomer keeping its state
    let mut old = snap.clone();
    old.joint_elastomers_nm.clear();
    s.restore(&old).unwrap();
    let without = replay(&mut s);
    println!("replay: {with:.1e} with the branch history, {without:.1e} without");
    assert!(
        without > 1e-6,
        "the branch history made no difference ({without:.2e})"
    );
}

/// A state is at the angle of its own configuration: restoring the configuration of one
/// instant with the joint angles recorded at another (shooting moves a state's coordinates and
/// keeps the rest of the snapshot it came from) marches exactly as restoring the instant
/// itself. The record only picks the turn; read as the angle, the difference would be a strain
/// of the elastomer within one step, `k_i` times it in every branch.
#[test]
fn a_restored_state_is_at_the_angle_of_its_configuration() {
    let mut s = released_for(137);
    let earlier = s.snapshot();
    for _ in 0..50 {
        s.step().unwrap();
    }
    let now = s.snapshot();
    let moved = |a: &rotorsim::solver::snapshot::SolverSnapshot| {
        a.joint_angles_rad.iter().flatten().copied().next().unwrap()
    };
    let apart = (moved(&now) - moved(&earlier)).abs();
    assert!(apart > 1e-3, "the two records are {apart:.1e} rad apart");
    let mut mixed = now.clone();
    mixed.joint_angles_rad.clone_from(&earlier.joint_angles_rad);
    let march = |s: &mut DynamicSolver, from: &rotorsim::solver::snapshot::SolverSnapshot| {
        s.restore(from).unwrap();
        (0..50)
            .map(|_| {
                s.step().unwrap();
                s.sensor_values()
            })
            .collect::<Vec<_>>()
    };
    let a = march(&mut s, &now);
    let b = march(&mut s, &mixed);
    let scale = a.iter().flatten().fold(0.0f64, |m, x| m.max(x.abs()));
    let worst = a
        .iter()
        .flatten()
        .zip(b.iter().flatten())
        .fold(0.0f64, |m, (x, y)| m.max((x - y).abs()));
    println!("records {apart:.2e} rad apart: the marches differ by {worst:.1e} of {scale:.2e}");
    assert!(
        worst <= 1e-14 * scale,
        "the record's angle changed the march by {worst:.2e} (of {scale:.2e})"
    );
}
