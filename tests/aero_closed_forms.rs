//! The lifting line against the classical closed forms of rotor aerodynamics (Johnson,
//! "Helicopter Theory", 1980, ch. 2 and 5; "Rotorcraft Aeromechanics", 2013, ch. 3, 5, 6): a
//! rigid articulated blade (flap hinge on the shaft, no offset, no spring), constant chord,
//! no twist, uniform inflow, thin aerofoil (2 pi alpha, no drag), marched by the multibody
//! solver with the lifting line on its beam.
//!
//! The blade is a stiff beam (first elastic flap mode near 20/rev) of uniform mass: flap
//! inertia `I = m R^3 / 3`, Lock number `gamma = rho a c R^4 / I`. The closed forms are the
//! linear small-angle theory, so the cases keep the angles small (pitch a few degrees, inflow
//! ratio 0.02): the lifting line's nonlinear terms (inflow angle, U^2 = U_T^2 + U_P^2,
//! cos(beta)) then differ from the linear theory by a few 1e-4.
use rotorsim::aero::airfoil::{Airfoil, ClampCounts, ThinAirfoil};
use rotorsim::aero::inflow::{FlightCondition, Inflow, InflowModel};
use rotorsim::aero::lifting_line::{AeroShared, BladeAero, LiftingLine, RotorAir};
use rotorsim::aero::section::Air;
use rotorsim::periodic::{shoot, PeriodMap, ShootingOptions};
use rotorsim::rotor::hinged::{expanded_model, HingedExpand, HingedSpec};
use rotorsim::solver::statics::{static_solve, StaticOptions};
use rotorsim::solver::{DynamicSolver, SolverSnapshot, State};
use rotorsim::structure::model::Element;
use std::f64::consts::PI;
use std::path::Path;
use std::sync::{Arc, Mutex};

const OMEGA: f64 = 30.0;
const RADIUS: f64 = 5.0;
const MASS: f64 = 0.2; // kg/m: with RHO a slender chord, c/R = 0.0014 gamma (see `chord_for`)
const RHO: f64 = 1.2;
const STEPS: usize = 256;

fn flap_inertia() -> f64 {
    MASS * RADIUS.powi(3) / 3.0
}

/// Chord giving Lock number `gamma` with a = 2 pi.
fn chord_for(gamma: f64) -> f64 {
    gamma * flap_inertia() / (RHO * 2.0 * PI * RADIUS.powi(4))
}

fn deck() -> String {
    format!(
        r#"
[rotor]
omega_rad_s = {OMEGA}
radius_m = {RADIUS}
blades = 4

[[hinge]]
axis = "flap"
r_m = 0.0

[blade]
root_r_m = 0.0

[[blade.segment]]
r_end_m = {RADIUS}
elements = 4
section = {{ EA_N = 1.0e11, GA2_N = 1.0e11, GA3_N = 1.0e11, GJ_Nm2 = 1.0e8, EI2_Nm2 = 1.0e9, EI3_Nm2 = 1.0e9, m_kg_per_m = {MASS}, I1_kgm = 1.0e-5, I2_kgm = 1.0e-7, I3_kgm = 1.0e-7 }}
"#
    )
}

/// The flap angle, positive up [rad].
fn flap(s: &DynamicSolver, id: usize) -> f64 {
    match &s.solver_model().elements[id] {
        Element::Joint(j) => j.angle_prev,
        _ => f64::NAN,
    }
}

trait ModelOf {
    fn solver_model(&self) -> &rotorsim::structure::model::Model;
}
impl ModelOf for DynamicSolver {
    fn solver_model(&self) -> &rotorsim::structure::model::Model {
        &self.model
    }
}

struct Case {
    gamma: f64,
    mu: f64,
    /// Total inflow ratio (free stream through the disk plus induced), positive down.
    lambda: f64,
    th0: f64,
    th1c: f64,
    th1s: f64,
    /// Momentum inflow coupled (uniform, from the blades' thrust) instead of `lambda`.
    momentum: bool,
}

struct Run {
    solver: DynamicSolver,
    flap_id: usize,
    shared: Arc<Mutex<AeroShared>>,
    air: RotorAir,
}

fn build(c: &Case) -> Run {
    let file = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/aero_closed_forms.toml");
    let spec = HingedSpec::parse(&deck(), "aero verification blade").unwrap();
    let mut model = expanded_model(&spec, &HingedExpand::default(), &file).unwrap();
    let mut st = State::from_model(&model);
    let sopts = StaticOptions {
        load_steps: 1,
        omega: Some([0.0, 0.0, OMEGA]),
        ..Default::default()
    };
    static_solve(&mut model, &mut st, &sopts, |_, _, _, _| {}).unwrap();
    st.set_rigid_rotation([0.0; 3], [0.0, 0.0, OMEGA]);
    let vt = OMEGA * RADIUS;
    let air = RotorAir {
        air: Air {
            density_kg_m3: RHO,
            speed_of_sound_m_s: 1e9, // incompressible: the thin law has no Mach effect anyway
        },
        omega_rad_s: OMEGA,
        radius_m: RADIUS,
        freestream_m_s: if c.momentum {
            [c.mu * vt, 0.0, 0.0]
        } else {
            [c.mu * vt, 0.0, -c.lambda * vt]
        },
        center_m: [0.0; 3],
    };
    let inflow = Inflow::new(
        InflowModel::Uniform,
        FlightCondition {
            mu: c.mu,
            lambda_free: 0.0,
        },
    );
    let shared = Arc::new(Mutex::new(AeroShared {
        inflow,
        points: vec![],
    }));
    let geometry = BladeAero {
        root_r_m: 0.0,
        chord_m: vec![(0.0, chord_for(c.gamma))],
        airfoils: vec![(RADIUS, Airfoil::Thin(ThinAirfoil::default()))],
        cutout_r_m: 0.0,
        tip_loss_factor: 1.0,
        twist_rad: rotorsim::structure::kin::TimeTable { points: vec![] },
    };
    let (th0, th1c, th1s) = (c.th0, c.th1c, c.th1s);
    let law = Arc::new(move |t: f64| {
        let psi = OMEGA * t;
        th0 + th1c * psi.cos() + th1s * psi.sin()
    });
    let line = LiftingLine::new(
        &model,
        "blade_s0",
        &geometry,
        air,
        Arc::new(ClampCounts::default()),
        shared.clone(),
        0,
    )
    .unwrap()
    .with_pitch_law(law);
    model
        .add_distributed_load("blade_s0", Box::new(line))
        .unwrap();
    let flap_id = model.element_id("flap").unwrap();
    let h = 2.0 * PI / OMEGA / STEPS as f64;
    let mut solver = DynamicSolver::new(model, st, h, 0.9).unwrap();
    solver.newton.rtol = 1e-11;
    solver.init_accelerations().unwrap();
    Run {
        solver,
        flap_id,
        shared,
        air,
    }
}

impl Run {
    /// One revolution; the flap angle at the start of every step.
    fn revolution(&mut self, momentum: bool) -> Vec<f64> {
        let mut out = Vec::with_capacity(STEPS);
        for _ in 0..STEPS {
            out.push(flap(&self.solver, self.flap_id));
            self.solver.step().unwrap();
            if momentum {
                let mut sh = self.shared.lock().unwrap();
                let l = sh.rotor_airloads(&self.air, 4.0);
                sh.inflow.advance(OMEGA * self.solver.h, &l.disk);
            }
        }
        out
    }
}

/// (mean, cos, sin) harmonics of one revolution sampled at k 2 pi / n (the library's fit).
fn harmonics(x: &[f64]) -> (f64, f64, f64) {
    let n = x.len();
    let psi: Vec<f64> = (0..n).map(|k| 360.0 * k as f64 / n as f64).collect();
    let h = rotorsim::analysis::harmonics::harmonics(&psi, x, 1).unwrap();
    (h[0].cos, h[1].cos, h[1].sin)
}

/// The classical closed form (Johnson, Helicopter Theory, sec. 5.5, for nu = 1, no offset, no
/// twist, uniform inflow): harmonic balance of the mean and 1/rev flapping in
/// `beta'' + beta = gamma int_0^1 r (u_T^2 theta - u_P u_T) / 2 dr`, `u_T = r + mu sin psi`,
/// `u_P = lambda + r beta' + mu beta cos psi` (derived symbolically). With
/// `beta = beta0 + beta1c cos psi + beta1s sin psi`; Johnson's tip-path-plane tilts are
/// `a1 = -beta1c`, `b1 = -beta1s` (his eq. 5.58: b1 = 4/3 mu beta0 / (1 + mu^2/2) - theta1c).
fn closed_form(c: &Case) -> (f64, f64, f64) {
    let (g, mu, l) = (c.gamma, c.mu, c.lambda);
    let b0 = g * (c.th0 / 8.0 * (1.0 + mu * mu) + mu / 6.0 * c.th1s - l / 6.0);
    let b1c =
        -c.th1s - 8.0 / 3.0 * mu * (c.th0 + 0.75 * mu * c.th1s - 0.75 * l) / (1.0 - 0.5 * mu * mu);
    let b1s = c.th1c - 4.0 / 3.0 * mu * b0 / (1.0 + 0.5 * mu * mu);
    (b0, b1c, b1s)
}

/// The revolution map of the hover blade for the project's shooting solver (coordinates of
/// the solver's snapshot, velocities scaled by 1/Omega).
struct HoverMap {
    run: Run,
    r0: Vec<[[f64; 3]; 3]>,
    start: SolverSnapshot,
    end: SolverSnapshot,
    x: Vec<f64>,
    f: Vec<f64>,
    trial: Option<(SolverSnapshot, SolverSnapshot)>,
    periods: usize,
    change: Option<f64>,
}

impl HoverMap {
    fn new(mut run: Run) -> Self {
        let r0 = (0..run.solver.model.nodes.len())
            .map(|i| run.solver.model.node_r0(i))
            .collect();
        let start = run.solver.snapshot();
        run.revolution(false);
        let end = run.solver.snapshot();
        let mut m = HoverMap {
            run,
            r0,
            x: vec![],
            f: vec![],
            start,
            end,
            trial: None,
            periods: 1,
            change: None,
        };
        m.x = m.coords(&m.start);
        m.f = m.coords(&m.end);
        m
    }
    fn coords(&self, s: &SolverSnapshot) -> Vec<f64> {
        s.coords(&self.r0, 1.0 / OMEGA)
    }
    /// One revolution from `from` with its coordinates replaced by `x`: (start, end).
    fn from(
        &mut self,
        from: &SolverSnapshot,
        x: &[f64],
    ) -> anyhow::Result<(SolverSnapshot, SolverSnapshot)> {
        let mut s = from.clone();
        s.set_coords(&self.r0, 1.0 / OMEGA, x);
        self.run
            .solver
            .restore(&s)
            .map_err(|e| anyhow::anyhow!(e))?;
        self.run.revolution(false);
        self.periods += 1;
        Ok((s, self.run.solver.snapshot()))
    }
}

impl PeriodMap for HoverMap {
    fn accepted(&self) -> (&[f64], &[f64]) {
        (&self.x, &self.f)
    }
    fn perturbed(&mut self, x: &[f64]) -> anyhow::Result<Vec<f64>> {
        let start = self.start.clone();
        let (_, e) = self.from(&start, x)?;
        Ok(self.coords(&e))
    }
    fn trial(&mut self, x: &[f64]) -> anyhow::Result<Vec<f64>> {
        let end = self.end.clone();
        let (s, e) = self.from(&end, x)?;
        let f = self.coords(&e);
        self.trial = Some((s, e));
        Ok(f)
    }
    fn accept(&mut self) {
        if let Some((s, e)) = self.trial.take() {
            let f = self.coords(&e);
            self.change = Some(
                f.iter()
                    .zip(&self.f)
                    .map(|(a, b)| (a - b).abs())
                    .fold(0.0, f64::max),
            );
            (self.x, self.f) = (self.coords(&s), f);
            (self.start, self.end) = (s, e);
        }
    }
    fn residual(&self) -> f64 {
        self.f
            .iter()
            .zip(&self.x)
            .map(|(a, b)| (a - b).abs())
            .fold(0.0, f64::max)
    }
    fn periods(&self) -> usize {
        self.periods
    }
    fn step_change(&self) -> Option<f64> {
        self.change
    }
}

/// Hover flap mode from the Floquet multipliers of the project's shooting solver (Ritz values
/// of the revolution map about the periodic coning): hover is time-invariant, so the flap
/// multiplier is e^{sT} with s = -zeta omega_n +- i omega_d. Closed form: omega_n = Omega (no
/// offset, no spring), zeta = gamma/16, and omega_d = omega_n sqrt(1 - zeta^2) lies between
/// 1/2 and 1/rev for zeta < 0.87, which resolves the multiplier's angle (2 pi - |arg mu|).
#[test]
fn hover_flap_mode_is_one_per_rev_with_gamma_over_16_damping() {
    for (gamma, lambda) in [(0.5, 0.02), (4.0, 0.0), (4.0, 0.02), (8.0, 0.02)] {
        let case = Case {
            gamma,
            mu: 0.0,
            lambda,
            th0: 0.04,
            th1c: 0.0,
            th1s: 0.0,
            momentum: false,
        };
        let mut run = build(&case);
        let mut x = Vec::new();
        for _ in 0..2 {
            x.extend(run.revolution(false));
        }
        let (b0, _, _) = harmonics(&x[STEPS..]);
        println!(
            "coning after two revolutions {b0:.7}, closed form {:.7}",
            gamma * (case.th0 / 8.0 - lambda / 6.0)
        );
        let mut map = HoverMap::new(run);
        let o = ShootingOptions {
            tol: 1e-10,
            max_periods: 40,
            min_dirs: 4,
            ..Default::default()
        };
        let out = shoot(&mut map, &o);
        assert!(out.converged(), "shooting: {:?}", out.stop);
        // the least damped oscillating pair is the flap mode (the beam's elastic modes sit
        // near 20/rev and more, their multipliers far smaller)
        let flap = out
            .ritz
            .iter()
            .find(|p| p.multiplier.im.abs() > 1e-9)
            .expect("an oscillating multiplier");
        let (re, im) = (flap.multiplier.re, flap.multiplier.im);
        let t = 2.0 * PI / OMEGA;
        let sigma = -re.hypot(im).ln() / t;
        let wd = (2.0 * PI - im.atan2(re).abs()) / t;
        let wn = wd.hypot(sigma);
        let zeta = sigma / wn;
        println!(
            "gamma {gamma}: multiplier {re:.6} {im:+.6}i (|mu| {:.6}, {} revolutions), omega_n/Omega {:.6}, zeta {:.6} (gamma/16 {:.6})",
            re.hypot(im),
            map.periods,
            wn / OMEGA,
            zeta,
            gamma / 16.0
        );
        assert!(
            (wn / OMEGA - 1.0).abs() < 0.01,
            "omega_n/Omega {}",
            wn / OMEGA
        );
        assert!(
            (zeta / (gamma / 16.0) - 1.0).abs() < 0.01,
            "zeta {zeta} vs {}",
            gamma / 16.0
        );
    }
}

/// The exact periodic solution of the classical flap equation behind [`closed_form`]
/// (integrated over r in closed form, with its 2/rev and higher flapping):
/// `beta'' + (gamma/2)(1/4 + mu s/3) beta' + [1 + (gamma/2) mu c (1/3 + mu s/2)] beta
///  = (gamma/2) [theta (1/4 + 2 mu s/3 + mu^2 s^2/2) - lambda (1/3 + mu s/2)]`,
/// `s = sin psi`, `c = cos psi`; marched with RK4 (4096 steps per revolution) until periodic.
fn classical_periodic(k: &Case) -> (f64, f64, f64) {
    let g2 = k.gamma / 2.0;
    let mu = k.mu;
    let f = |psi: f64, y: [f64; 2]| -> [f64; 2] {
        let (s, c) = psi.sin_cos();
        let th = k.th0 + k.th1c * c + k.th1s * s;
        let rhs = g2
            * (th * (0.25 + 2.0 * mu * s / 3.0 + mu * mu * s * s / 2.0)
                - k.lambda * (1.0 / 3.0 + mu * s / 2.0));
        let damp = g2 * (0.25 + mu * s / 3.0);
        let stiff = 1.0 + g2 * mu * c * (1.0 / 3.0 + mu * s / 2.0);
        [y[1], rhs - damp * y[1] - stiff * y[0]]
    };
    let n = 4096;
    let h = 2.0 * PI / n as f64;
    let mut y = [0.0, 0.0];
    let mut rev = vec![0.0; n];
    for _ in 0..40 {
        for (j, slot) in rev.iter_mut().enumerate() {
            *slot = y[0];
            let p = j as f64 * h;
            let k1 = f(p, y);
            let k2 = f(
                p + h / 2.0,
                [y[0] + h / 2.0 * k1[0], y[1] + h / 2.0 * k1[1]],
            );
            let k3 = f(
                p + h / 2.0,
                [y[0] + h / 2.0 * k2[0], y[1] + h / 2.0 * k2[1]],
            );
            let k4 = f(p + h, [y[0] + h * k3[0], y[1] + h * k3[1]]);
            for i in 0..2 {
                y[i] += h / 6.0 * (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i]);
            }
        }
    }
    harmonics(&rev)
}

/// Periodic flapping against the closed form: coning and 1/rev in hover under cyclic pitch
/// and in forward flight up to mu = 0.3.
#[test]
fn flapping_response_matches_the_closed_form() {
    let cases = [
        // hover, cyclic: beta_1c = -theta_1s, beta_1s = theta_1c
        (0.0, 0.04, 0.02, -0.03),
        (0.1, 0.04, 0.01, -0.02),
        (0.2, 0.04, 0.01, -0.02),
        (0.3, 0.04, 0.01, -0.02),
    ];
    for (mu, th0, th1c, th1s) in cases {
        let case = Case {
            gamma: 6.0,
            mu,
            lambda: 0.005,
            th0,
            th1c,
            th1s,
            momentum: false,
        };
        let mut run = build(&case);
        let mut last = Vec::new();
        for _ in 0..6 {
            last = run.revolution(false);
        }
        let (b0, b1c, b1s) = harmonics(&last);
        let (j0, j1c, j1s) = closed_form(&case);
        let (c0, c1c, c1s) = classical_periodic(&case);
        let amp = c0.hypot(c1c).hypot(c1s);
        println!(
            "mu {mu}: beta0 {b0:.6} ({c0:.6}; two-harmonic {j0:.6}), beta1c {b1c:.6} ({c1c:.6}; {j1c:.6}), beta1s {b1s:.6} ({c1s:.6}; {j1s:.6})"
        );
        for (got, want, what) in [
            (b0, c0, "beta0"),
            (b1c, c1c, "beta1c"),
            (b1s, c1s, "beta1s"),
        ] {
            assert!(
                (got - want).abs() < 0.01 * amp,
                "mu {mu}: {what} {got} vs {want}"
            );
        }
    }
}

/// Hover thrust of the untwisted constant-chord rotor with uniform momentum inflow: the
/// lifting line coupled with the inflow against blade-element momentum theory,
/// C_T = (sigma a / 2) (theta / 3 - lambda / 2), lambda = sqrt(C_T / 2).
#[test]
fn hover_thrust_matches_blade_element_momentum_theory() {
    let gamma = 6.0;
    let th0 = 0.08;
    let case = Case {
        gamma,
        mu: 0.0,
        lambda: 0.0,
        th0,
        th1c: 0.0,
        th1s: 0.0,
        momentum: true,
    };
    let mut run = build(&case);
    for _ in 0..8 {
        run.revolution(true);
    }
    let sh = run.shared.lock().unwrap();
    let got = sh.rotor_airloads(&run.air, 4.0).disk.ct;
    let sigma = 4.0 * chord_for(gamma) / (PI * RADIUS);
    let a = 2.0 * PI;
    // C_T = k (theta/3 - sqrt(C_T/2)/2), k = sigma a / 2: a quadratic in x = sqrt(C_T)
    let k = sigma * a / 2.0;
    let b = k / (2.0 * 2f64.sqrt());
    let x = (-b + (b * b + 4.0 * k * th0 / 3.0).sqrt()) / 2.0;
    let want = x * x;
    println!(
        "hover C_T {got:.7} (BEMT {want:.7}, {:+.3}%)",
        100.0 * (got / want - 1.0)
    );
    assert!((got / want - 1.0).abs() < 0.005, "C_T {got} vs {want}");
}
