//! User elements with internal state (StepElement) and external distributed loads.
use rotorsim::solver::fdcheck::check_model;
use rotorsim::solver::verification::{cantilever, uniform_section};
use rotorsim::solver::{static_solve, DynamicSolver, NewtonError, State, StaticOptions};
use rotorsim::structure::*;

/// Linear spring-dashpot between two nodes with a committed-state counter; errors when the
/// stretch exceeds a limit.
struct SpringDamper {
    nodes: [usize; 2],
    k: f64,
    c: f64,
    commits: usize,
    evaluations: usize,
    limit_m: f64,
    force_last: f64,
    /// Multiplies the tangent: anything but 1 makes it lie.
    tangent_scale: f64,
}

impl StepElement for SpringDamper {
    fn name(&self) -> &str {
        "damper"
    }
    fn nodes(&self) -> [usize; 2] {
        self.nodes
    }
    fn evaluate(
        &mut self,
        _t: f64,
        dt: f64,
        x_i: [[f64; 3]; 2],
        x_f: [[f64; 3]; 2],
        out: &mut ElementOutput,
    ) -> Result<(), ElementError> {
        self.evaluations += 1;
        // force on node 0 = k (x1 - x0) + c (v1 - v0), velocities by backward difference
        let mut f = [0.0; 3];
        for i in 0..3 {
            let d = x_f[1][i] - x_f[0][i];
            if d.abs() > self.limit_m {
                return Err(ElementError {
                    element: "damper".into(),
                    msg: format!("stroke {d} m exceeds limit"),
                });
            }
            let rate = if dt > 0.0 {
                (d - (x_i[1][i] - x_i[0][i])) / dt
            } else {
                0.0
            };
            f[i] = self.k * d + self.c * rate;
        }
        let kk = (self.k + if dt > 0.0 { self.c / dt } else { 0.0 }) * self.tangent_scale;
        out.force = [f, [-f[0], -f[1], -f[2]]];
        out.jac = [[[[0.0; 3]; 3]; 2]; 2];
        for i in 0..3 {
            out.jac[0][0][i][i] = -kk;
            out.jac[0][1][i][i] = kk;
            out.jac[1][0][i][i] = kk;
            out.jac[1][1][i][i] = -kk;
        }
        self.force_last = f[2];
        Ok(())
    }
    fn commit(&mut self) {
        self.commits += 1;
    }
    fn sensors(&self) -> Vec<(String, f64)> {
        vec![
            ("force_z_N".into(), self.force_last),
            ("commits".into(), self.commits as f64),
        ]
    }
}

fn model_with_spring(k: f64, c: f64, limit: f64) -> (Model, usize) {
    model_with_spring_tangent(k, c, limit, 1.0)
}

fn model_with_spring_tangent(k: f64, c: f64, limit: f64, tangent_scale: f64) -> (Model, usize) {
    let (ei, l) = (100.0, 10.0);
    let sec = uniform_section(1e6, 1e6, 100.0, ei, ei, 1.0, 1e-4, 5e-5, 5e-5);
    let (mut m, tip, load) = cantilever(8, l, &sec);
    if let Element::Load(p) = &mut m.elements[load] {
        p.force_n = [0.0, 0.0, 0.05];
    }
    let anchor = m
        .add_node(
            "anchor",
            [l, 0.0, 0.0],
            rotorsim::structure::rotation::ident(),
        )
        .unwrap();
    m.clamp("anchor_clamp", anchor).unwrap();
    m.add_step_element(Box::new(SpringDamper {
        nodes: [anchor, tip],
        k,
        c,
        commits: 0,
        evaluations: 0,
        limit_m: limit,
        force_last: 0.0,
        tangent_scale,
    }))
    .unwrap();
    (m, tip)
}

#[test]
fn step_element_spring_in_static_analysis() {
    let (k, ei, l) = (0.2, 100.0, 10.0_f64);
    let (mut m, tip) = model_with_spring(k, 0.0, 1.0);
    let mut st = State::from_model(&m);
    static_solve(&mut m, &mut st, &StaticOptions::default(), |_, _, _, _| {}).unwrap();
    let expect = 0.05 / (k + 3.0 * ei / l.powi(3));
    let got = st.x[tip][2];
    println!("tip with spring: {got:.6e} m, linear theory {expect:.6e} m");
    assert!((got - expect).abs() / expect < 2e-3);
}

#[test]
fn step_element_damper_is_committed_once_per_converged_step_and_can_abort() {
    let (m, _) = model_with_spring(0.0, 0.5, 1.0);
    let mut st = State::from_model(&m);
    let mut m = m;
    static_solve(&mut m, &mut st, &StaticOptions::default(), |_, _, _, _| {}).unwrap();
    if let Some(Element::Load(p)) = m.elements.iter_mut().find(|e| e.name() == "tip_load") {
        p.force_n = [0.0; 3];
    }
    let mut s = DynamicSolver::new(m, st, 0.5, 0.9).unwrap();
    let mut amp = vec![];
    for _ in 0..40 {
        s.step().unwrap();
        amp.push(s.sensor_values());
    }
    // with the exact step-element tangent the iteration count is that of the undamped case
    // (169 for 40 steps of 0.5 s, measured)
    println!("Newton iterations over 40 steps: {}", s.total_iterations);
    assert!(s.total_iterations <= 175, "{}", s.total_iterations);
    let hdr = s.sensor_header();
    let ic = hdr.iter().position(|h| h == "damper.commits").unwrap();
    let iz = hdr.iter().position(|h| h == "tip.z_m").unwrap();
    // one commit from the static solution + one per converged step
    assert_eq!(amp.last().unwrap()[ic] as usize, 41);
    // the dashpot removes energy: tip amplitude decays
    let first = amp[..10].iter().map(|r| r[iz].abs()).fold(0.0, f64::max);
    let last = amp[30..].iter().map(|r| r[iz].abs()).fold(0.0, f64::max);
    println!("tip amplitude first 5 s {first:.3e}, last 5 s {last:.3e}");
    assert!(last < 0.5 * first);

    // element error aborts the step and leaves the state at the last converged step
    let (mut m, _) = model_with_spring(0.0, 0.5, 0.01);
    let mut st = State::from_model(&m);
    let r = static_solve(&mut m, &mut st, &StaticOptions::default(), |_, _, _, _| {});
    match r {
        Err(e @ NewtonError::Element { .. }) => {
            // the message says where: time, Newton iteration and the last residual norm
            let msg = e.to_string();
            let NewtonError::Element {
                iteration,
                residual,
                ref source,
                ..
            } = e
            else {
                unreachable!()
            };
            assert!(source.msg.contains("exceeds limit"), "{msg}");
            assert!(iteration >= 1 && residual.is_finite(), "{msg}");
            assert!(
                msg.contains("at t = ")
                    && msg.contains(&format!("Newton iteration {iteration}, residual norm")),
                "{msg}"
            );
        }
        other => panic!("expected element error, got {other:?}"),
    }
}

#[test]
fn a_tiny_correction_with_a_large_residual_is_not_convergence() {
    // A tangent 1e16 times too stiff makes every correction ~1e-18 m, below the increment
    // tolerance, while the residual stays at the 0.05 N of the tip load: the static and the
    // dynamic Newton loops must both refuse to call that converged.
    let (mut m, _) = model_with_spring_tangent(0.2, 0.0, 1.0, 1e16);
    let mut st = State::from_model(&m);
    match static_solve(&mut m, &mut st, &StaticOptions::default(), |_, _, _, _| {}) {
        Err(NewtonError::StaticDiverged { residual, .. }) => {
            assert!(residual > 1e-3, "{residual}")
        }
        other => panic!("expected the static solve to fail, got {other:?}"),
    }
    let (m, _) = model_with_spring_tangent(0.2, 0.0, 1.0, 1e16);
    let st = State::from_model(&m);
    let mut s = DynamicSolver::new(m, st, 0.01, 0.9).unwrap();
    match s.step() {
        Err(e @ NewtonError::Diverged { .. }) => {
            let msg = e.to_string();
            assert!(
                msg.contains("at t = 0.01 s") && msg.contains("residual norm"),
                "{msg}"
            )
        }
        other => panic!("expected the dynamic step to fail, got {other:?}"),
    }
    // the true tangent converges in a few iterations
    let (mut m, _) = model_with_spring_tangent(0.2, 0.0, 1.0, 1.0);
    let mut st = State::from_model(&m);
    let rep = static_solve(&mut m, &mut st, &StaticOptions::default(), |_, _, _, _| {}).unwrap();
    assert!(
        rep.iterations.iter().all(|&i| i <= 6),
        "{:?}",
        rep.iterations
    );
}

/// Uniform distributed force per unit length, global or follower.
struct Uniform {
    f: [f64; 3],
    follower: bool,
    calls: usize,
}

impl DistributedLoad for Uniform {
    fn eval(&mut self, p: &LoadPoint) -> SectionLoad {
        self.calls += 1;
        assert!(p.s_m >= 0.0 && p.s_m <= 10.0);
        SectionLoad {
            force: self.f,
            moment: [0.0; 3],
            follower: self.follower,
        }
    }
}

#[test]
fn distributed_load_provider_reaction_and_tangent() {
    let sec = uniform_section(1e6, 1e6, 100.0, 100.0, 100.0, 1.0, 1e-4, 5e-5, 5e-5);
    let (mut m, tip, _) = cantilever(4, 10.0, &sec);
    m.add_distributed_load(
        "beam",
        Box::new(Uniform {
            f: [0.0, 0.0, 0.01],
            follower: false,
            calls: 0,
        }),
    )
    .unwrap();
    let mut st = State::from_model(&m);
    static_solve(&mut m, &mut st, &StaticOptions::default(), |_, _, _, _| {}).unwrap();
    // Euler-Bernoulli tip deflection q L^4 / 8 EI (+ shear q L^2 / 2 GA)
    let expect = 0.01 * 1e4 / (8.0 * 100.0) + 0.01 * 100.0 / (2.0 * 1e6);
    println!(
        "uniform load tip {:.6e}, theory {:.6e}",
        st.x[tip][2], expect
    );
    assert!((st.x[tip][2] - expect).abs() / expect < 2e-3);
    // force of the root joint on the beam = -q L
    let off = rotorsim::solver::state::lambda_offsets(&m);
    let v = rotorsim::solver::state::sensor_values(&m, &st, &off);
    let h = rotorsim::solver::state::sensor_header(&m);
    let fz = v[h.iter().position(|x| x == "root.fz_N").unwrap()];
    assert!((fz + 0.1).abs() < 1e-9, "{fz}");
    // follower external loads: tangent includes the load stiffness
    let mut m2 = Model::new();
    m2.add_straight_beam(
        "b",
        1,
        [0.0; 3],
        [1.0, 0.2, 0.1],
        [0.0, 1.0, 0.0],
        &sec,
        0.0,
        None,
    )
    .unwrap();
    m2.add_distributed_load(
        "b",
        Box::new(Uniform {
            f: [0.3, -0.2, 1.0],
            follower: true,
            calls: 0,
        }),
    )
    .unwrap();
    let mut st = State::from_model(&m2);
    for i in 0..4 {
        st.q[i] =
            rotorsim::structure::rotation::update_left(&st.q[i], [0.1 * i as f64, -0.2, 0.05]);
    }
    let mut kin = vec![];
    st.kin(&mut kin);
    m2.update_distributed_loads(0.0, &kin);
    let r = check_model(&m2, &kin, &[], &EvalCtx::default());
    assert!(r[0].rel_error < 1e-6, "{r:?}");
}
