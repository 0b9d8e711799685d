//! The implicit scheme's analytic Jacobian of the circuit right-hand side against central
//! finite differences, at states covering every element branch.
use rotorsim::hydraulics::circuit::{State, IIMP, IP0, IP1, IV0, IV1, IX0, IX1, NS};
use rotorsim::hydraulics::{ActuatorParams, DamperDeck, PiecewiseLinear};
use std::path::Path;

fn check(
    params: &rotorsim::hydraulics::CircuitParams,
    t: f64,
    d: f64,
    d_dot: f64,
    y: &State,
    label: &str,
) {
    let (_, j, _) = params.evaluate::<true>(t, d, d_dot, y, None).unwrap();
    for c in 0..NS {
        // A seated poppet (x = 0) sits on the kinks of Eq. (7) and of the seat contact: the
        // analytic Jacobian takes the closed side there, so only smooth directions are checked.
        let seated = |ix: usize| y[ix] <= 0.0;
        if (c == IX0 || c == IV0) && seated(IX0) || (c == IX1 || c == IV1) && seated(IX1) {
            continue;
        }
        let h = match c {
            IP0 | IP1 => 1e-3 * (1.0 + y[c].abs() * 1e-6),
            IX0 | IX1 => 1e-10,
            IV0 | IV1 => 1e-8,
            _ => 1e-3,
        };
        let mut yp = *y;
        let mut ym = *y;
        yp[c] += h;
        ym[c] -= h;
        let fp = params.evaluate::<false>(t, d, d_dot, &yp, None).unwrap().0;
        let fm = params.evaluate::<false>(t, d, d_dot, &ym, None).unwrap().0;
        for r in 0..NS {
            let fd = (fp[r] - fm[r]) / (2.0 * h);
            let an = j[(r, c)];
            let scale = an.abs().max(fd.abs()).max(1e-12);
            assert!(
                (fd - an).abs() <= 1e-5 * scale + 1e-9,
                "{label}: J[{r},{c}] analytic {an:e} vs FD {fd:e}"
            );
        }
    }
}

fn damper() -> rotorsim::hydraulics::CircuitParams {
    DamperDeck::from_file(Path::new(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/rotors/uh60a.toml"
    )))
    .unwrap()
    .physical
    .unwrap()
}

#[test]
fn damper_jacobian_matches_finite_differences() {
    let p = damper();
    let mk = |p0: f64, p1: f64, x0: f64, v0: f64, x1: f64, v1: f64| {
        let mut y = State::zeros();
        y[IP0] = p0;
        y[IP1] = p1;
        y[IX0] = x0;
        y[IV0] = v0;
        y[IX1] = x1;
        y[IV1] = v1;
        y[IIMP] = 3.0;
        y
    };
    // Closed valves, turbulent orifice.
    check(
        &p,
        0.1,
        1e-3,
        0.05,
        &mk(2.0e6, 6.0e5, 0.0, 0.0, 0.0, 0.0),
        "closed",
    );
    // Laminar orifice, check valve in its progressive band and fully open.
    check(
        &p,
        0.1,
        1e-3,
        0.05,
        &mk(4.996e5, 4.9985e5, 0.0, 0.0, 0.0, 0.0),
        "laminar",
    );
    check(
        &p,
        0.1,
        1e-3,
        0.05,
        &mk(3.0e5, 4.9995e5, 0.0, 0.0, 0.0, 0.0),
        "check valve",
    );
    // Valve 0 open and moving, valve 1 open.
    check(
        &p,
        0.1,
        -2e-3,
        -0.2,
        &mk(1.0e7, 6.0e5, 1.5e-4, 0.01, 0.0, 0.0),
        "valve 0 open",
    );
    check(
        &p,
        0.1,
        2e-3,
        0.2,
        &mk(6.0e5, 1.0e7, 0.0, 0.0, 2.0e-4, -0.02),
        "valve 1 open",
    );
    // Low pressure: cavitation factor active.
    check(
        &p,
        0.1,
        2e-3,
        0.2,
        &mk(2.0e4, 1.0e7, 0.0, 0.0, 2.0e-4, -0.02),
        "cavitation",
    );
}

#[test]
fn actuator_jacobian_matches_finite_differences() {
    let mut p = ActuatorParams::paper_table1().to_circuit();
    p.entrance.as_mut().unwrap().area_schedule = Some(PiecewiseLinear::ramp_up_down(0.5, 1.0));
    let mut y = State::zeros();
    y[IP0] = 1.1e6;
    y[IP1] = 0.9e6;
    check(&p, 0.3, 1e-3, 0.01, &y, "actuator");
}
