//! Verification cases shared by tests/ and `rotorsim verify`.
use crate::solver::{static_solve, State, StaticOptions};
use crate::structure::*;

/// Uniform section with no offsets.
#[allow(clippy::too_many_arguments)]
pub fn uniform_section(
    ea: f64,
    ga: f64,
    gj: f64,
    ei2: f64,
    ei3: f64,
    m: f64,
    i1: f64,
    i2: f64,
    i3: f64,
) -> SectionTable {
    SectionTable::uniform(SectionProps {
        s_m: 0.0,
        ea,
        ei2,
        ei3,
        gj,
        ga2: ga,
        ga3: ga,
        m,
        i1,
        i2,
        i3,
        ..Default::default()
    })
}

/// Published tip positions of the 45-degree bend (Simo & Vu-Quoc 1986, Table; Bathe &
/// Bolourchi 1979 problem): (force, [x, y, z]).
pub const BEND45_REF: [(f64, [f64; 3]); 3] = [
    (300.0, [58.84, 22.33, 40.08]),
    (450.0, [52.32, 18.62, 48.39]),
    (600.0, [47.23, 15.79, 53.37]),
];

/// (force, computed tip, reference tip).
pub type BendResult = (f64, [f64; 3], [f64; 3]);

/// 45-degree bend: returns (force, computed tip, reference tip).
pub fn bend45(n_elem: usize) -> Result<Vec<BendResult>, String> {
    let r = 100.0;
    let sec = uniform_section(1e7, 5e6, 7.05e5, 1e7 / 12.0, 1e7 / 12.0, 1.0, 1.0, 0.5, 0.5);
    let mut m = Model::new();
    let curve = move |s: f64| {
        let p = s / r;
        let (sn, cs) = p.sin_cos();
        (
            [r * sn, r * (1.0 - cs), 0.0],
            [[cs, -sn, 0.0], [sn, cs, 0.0], [0.0, 0.0, 1.0]],
        )
    };
    let ids = m
        .add_beam(
            "arc",
            n_elem,
            r * std::f64::consts::FRAC_PI_4,
            &curve,
            &sec,
            0.0,
            None,
        )
        .map_err(|e| e.to_string())?;
    m.clamp("root", ids[0]).map_err(|e| e.to_string())?;
    let tip = *ids.last().unwrap();
    let load = m
        .add_element(Element::Load(PointLoad {
            name: "F".into(),
            node: tip,
            force_n: [0.0; 3],
            moment_nm: [0.0; 3],
            follower: false,
            time: TimeTable::constant(),
        }))
        .map_err(|e| e.to_string())?;
    let mut st = State::from_model(&m);
    let mut out = vec![];
    if let Element::Load(l) = &mut m.elements[load] {
        l.force_n = [0.0, 0.0, 600.0];
    }
    let mut prev = 0.0;
    for (f, rf) in BEND45_REF {
        let opts = StaticOptions {
            load_steps: 6,
            start_factor: prev,
            end_factor: f / 600.0,
            ..Default::default()
        };
        prev = f / 600.0;
        static_solve(&mut m, &mut st, &opts, |_, _, _, _| {}).map_err(|e| e.to_string())?;
        out.push((f, st.x[tip], rf));
    }
    Ok(out)
}

/// Clamped uniform cantilever along x (flap = z, lag = y) with `n_elem` elements, tip load
/// element (force zero) and sensors `tip` (node) and `root` (joint). Returns (model, tip node,
/// load element).
pub fn cantilever(n_elem: usize, l: f64, sec: &SectionTable) -> (Model, usize, usize) {
    let mut m = Model::new();
    let ids = m
        .add_straight_beam(
            "beam",
            n_elem,
            [0.0; 3],
            [l, 0.0, 0.0],
            [0.0, 1.0, 0.0],
            sec,
            0.0,
            None,
        )
        .expect("cantilever");
    let root = m.clamp("root", ids[0]).expect("clamp");
    let tip = *ids.last().unwrap();
    let load = m
        .add_element(Element::Load(PointLoad {
            name: "tip_load".into(),
            node: tip,
            force_n: [0.0; 3],
            moment_nm: [0.0; 3],
            follower: false,
            time: TimeTable::constant(),
        }))
        .expect("load");
    m.add_sensor("tip", SensorKind::Node(tip));
    m.add_sensor("root", SensorKind::Joint(root));
    (m, tip, load)
}

/// Cantilever deflected statically by a tip force and released: returns the first flap
/// frequency [rad/s] measured from zero crossings of the tip displacement, and its analytic
/// Euler-Bernoulli value `3.5160 sqrt(EI / (m L^4))`.
pub fn cantilever_release(
    n_elem: usize,
    steps_per_period: usize,
    periods: usize,
) -> Result<(f64, f64), String> {
    use crate::solver::DynamicSolver;
    let (ei, mass, l) = (100.0, 1.0, 10.0);
    let sec = uniform_section(1e6, 1e6, 100.0, ei, ei, mass, 1e-4, 5e-5, 5e-5);
    let (mut m, tip, load) = cantilever(n_elem, l, &sec);
    let w_ref = 3.516015_f64 * (ei / (mass * l.powi(4))).sqrt();
    if let Element::Load(p) = &mut m.elements[load] {
        p.force_n = [0.0, 0.0, 0.05];
    }
    let mut st = State::from_model(&m);
    static_solve(&mut m, &mut st, &StaticOptions::default(), |_, _, _, _| {})
        .map_err(|e| e.to_string())?;
    if let Element::Load(p) = &mut m.elements[load] {
        p.force_n = [0.0; 3];
    }
    let z0 = st.x[tip][2];
    let h = 2.0 * std::f64::consts::PI / w_ref / steps_per_period as f64;
    let mut s = DynamicSolver::new(m, st, h, 1.0).map_err(|e| e.to_string())?;
    let mut crossings = vec![];
    let mut prev = z0;
    for _ in 0..steps_per_period * periods {
        s.step().map_err(|e| e.to_string())?;
        let z = s.state.x[tip][2];
        if prev > 0.0 && z <= 0.0 || prev < 0.0 && z >= 0.0 {
            // linear interpolation of the crossing time
            let t1 = s.state.t;
            crossings.push(t1 - h * z / (z - prev));
        }
        prev = z;
    }
    if crossings.len() < 3 {
        return Err("too few zero crossings".into());
    }
    let n = crossings.len() - 1;
    let period = 2.0 * (crossings[n] - crossings[0]) / n as f64;
    Ok((2.0 * std::f64::consts::PI / period, w_ref))
}

/// Non-dimensional first and second flap frequencies `omega / sqrt(EI / (m L^4))` of a uniform
/// rotating cantilever (no hub offset) vs `lambda = Omega / sqrt(EI / (m L^4))`, as tabulated by
/// Wright, Smith, Thresher & Wang (1982), J. Appl. Mech. 49, 197-202 (same values in Hodges &
/// Rutkowski 1981).
pub const WRIGHT_FLAP: [(f64, f64, f64); 13] = [
    (0.0, 3.5160, 22.0345),
    (1.0, 3.6817, 22.1810),
    (2.0, 4.1373, 22.6149),
    (3.0, 4.7973, 23.3203),
    (4.0, 5.5850, 24.2734),
    (5.0, 6.4495, 25.4461),
    (6.0, 7.3604, 26.8091),
    (7.0, 8.2996, 28.3341),
    (8.0, 9.2568, 29.9954),
    (9.0, 10.2257, 31.7705),
    (10.0, 11.2023, 33.6404),
    (11.0, 12.1843, 35.5890),
    (12.0, 13.1702, 37.6031),
];

/// One comparison of a computed quantity with its reference.
#[derive(Clone, Debug, serde::Serialize)]
pub struct Check {
    pub case: String,
    pub quantity: String,
    pub computed: f64,
    pub reference: f64,
    pub rel_error: f64,
    pub source: String,
}

impl Check {
    pub fn new(case: &str, quantity: &str, computed: f64, reference: f64, source: &str) -> Self {
        Check {
            case: case.into(),
            quantity: quantity.into(),
            computed,
            reference,
            rel_error: ((computed - reference) / reference).abs(),
            source: source.into(),
        }
    }
}

/// Rotating uniform cantilever (L = 1 m, m = 1 kg/m, EI_flap = 1, EI_lag = 4, GJ = 0.05):
/// first flap, first lag and first torsion frequency at `lambda` in `lambdas` (even, <= 12).
/// References: flap from Wright et al. (1982); lag from the flap value of a beam with EI_lag at
/// lambda/2 with `omega_lag^2 = omega_flap^2 - Omega^2`; torsion analytic
/// `omega_T^2 = (pi/2L)^2 GJ/I1 + Omega^2 (I3 - I2)/I1`.
pub fn rotating_cantilever(n_elem: usize, lambdas: &[f64]) -> Result<Vec<Check>, String> {
    use crate::solver::modal::{modes, ModalOptions, ModeKind};
    let (ei2, ei3, gj) = (1.0, 4.0, 0.05);
    let (i1, i2, i3) = (1.01e-4, 1e-6, 1e-4);
    let sec = uniform_section(1e6, 1e6, gj, ei2, ei3, 1.0, i1, i2, i3);
    let mut out = vec![];
    for &lam in lambdas {
        let (mut m, _, _) = cantilever(n_elem, 1.0, &sec);
        let mut st = State::from_model(&m);
        let omega = [0.0, 0.0, lam];
        let opts = StaticOptions {
            omega: Some(omega),
            load_steps: 1,
            ..Default::default()
        };
        static_solve(&mut m, &mut st, &opts, |_, _, _, _| {}).map_err(|e| e.to_string())?;
        let md = modes(
            &mut m,
            &st,
            &ModalOptions {
                n_modes: 12,
                omega: Some(omega),
                shift_rad_s: 0.0,
            },
        )
        .map_err(|e| e.to_string())?;
        let first = |k: ModeKind| md.iter().find(|x| x.kind == k).map(|x| x.omega_rad_s);
        let wf = first(ModeKind::Flap).ok_or("no flap mode")?;
        let wl = first(ModeKind::Lag).ok_or("no lag mode")?;
        let wt = first(ModeKind::Torsion).ok_or("no torsion mode")?;
        let tab = |l: f64| {
            WRIGHT_FLAP
                .iter()
                .find(|r| (r.0 - l).abs() < 1e-9)
                .map(|r| r.1)
        };
        let f_ref = tab(lam).ok_or("lambda not in table")?;
        let lag_nd = tab(lam / 2.0).ok_or("lambda/2 not in table")?;
        let l_ref = ((lag_nd * 2.0).powi(2) - lam * lam).sqrt();
        let t_ref =
            ((std::f64::consts::FRAC_PI_2).powi(2) * gj / i1 + lam * lam * (i3 - i2) / i1).sqrt();
        let case = format!("rotating_cantilever_lambda_{lam}");
        out.push(Check::new(&case, "flap1_nondim", wf, f_ref, "Wright, Smith, Thresher & Wang 1982, J. Appl. Mech. 49:197 (table of rotating uniform cantilever flap frequencies)"));
        out.push(Check::new(&case, "lag1_nondim", wl, l_ref, "Wright et al. 1982 flap value at lambda/2 with EI_lag = 4 EI_flap, omega_lag^2 = omega_flap^2 - Omega^2"));
        out.push(Check::new(
            &case,
            "torsion1_nondim",
            wt,
            t_ref,
            "analytic uniform beam: omega^2 = (pi/2L)^2 GJ/I1 + Omega^2 (I3 - I2)/I1",
        ));
    }
    Ok(out)
}

/// Free-flying flexible beam (in the spirit of Simo & Vu-Quoc 1988): initial rigid spin and
/// translation plus a flexural velocity field, no loads, no constraints; L = 10 m, h = 0.01 s.
/// Returns per step: total energy, linear momentum, angular momentum about the origin.
#[allow(clippy::type_complexity)]
pub fn free_flying(
    rho_inf: f64,
    steps: usize,
) -> Result<(Vec<f64>, Vec<[f64; 3]>, Vec<[f64; 3]>), String> {
    use crate::solver::dynamic::{energy, momentum};
    use crate::solver::DynamicSolver;
    let sec = uniform_section(1e4, 1e4, 500.0, 500.0, 500.0, 1.0, 10.0, 5.0, 5.0);
    let mut m = Model::new();
    m.add_straight_beam(
        "b",
        4,
        [0.0; 3],
        [10.0, 0.0, 0.0],
        [0.0, 1.0, 0.0],
        &sec,
        0.0,
        None,
    )
    .map_err(|e| e.to_string())?;
    let mut st = State::from_model(&m);
    st.set_rigid_rotation([5.0, 0.0, 0.0], [0.1, 0.3, 1.0]);
    for i in 0..st.x.len() {
        let s = st.x[i][0] / 10.0;
        st.v[i][0] += 1.0;
        st.v[i][2] += 2.0 * (std::f64::consts::PI * s).sin() - 4.0 / std::f64::consts::PI;
    }
    let mut s = DynamicSolver::new(m, st, 0.01, rho_inf).map_err(|e| e.to_string())?;
    s.init_accelerations().map_err(|e| e.to_string())?;
    let (mut e, mut p, mut l) = (vec![], vec![], vec![]);
    for k in 0..=steps {
        if k > 0 {
            s.step().map_err(|e| e.to_string())?;
        }
        let (ke, se) = energy(&s.model, &s.state);
        let (pp, ll) = momentum(&s.model, &s.state);
        e.push(ke + se);
        p.push(pp);
        l.push(ll);
    }
    Ok((e, p, l))
}

/// Observed order of accuracy from errors at meshes n, 2n, 4n, ...: log2(e_n / e_2n).
pub fn observed_orders(errors: &[f64]) -> Vec<f64> {
    errors.windows(2).map(|w| (w[0] / w[1]).log2()).collect()
}

/// Mesh convergence: (quantity, element counts, errors, observed orders).
#[allow(clippy::type_complexity)]
pub fn mesh_convergence() -> Result<Vec<(String, Vec<usize>, Vec<f64>, Vec<f64>)>, String> {
    let mut out = vec![];
    // 45-degree bend tip at F = 600 against a 32-element solution
    let tip = |n: usize| -> Result<[f64; 3], String> { Ok(bend45(n)?[2].1) };
    let fine = tip(32)?;
    let ns = vec![1, 2, 4, 8];
    let mut errs = vec![];
    for &n in &ns {
        let x = tip(n)?;
        errs.push(
            ((x[0] - fine[0]).powi(2) + (x[1] - fine[1]).powi(2) + (x[2] - fine[2]).powi(2)).sqrt()
                / 100.0,
        );
    }
    let ord = observed_orders(&errs);
    out.push((
        "bend45_tip_position_F600 (error / R vs 32 elements)".to_string(),
        ns,
        errs,
        ord,
    ));
    // first flap frequency of a non-rotating cantilever vs a 32-element solution
    let freq = |n: usize| -> Result<f64, String> {
        Ok(rotating_cantilever(n, &[0.0])?
            .into_iter()
            .find(|c| c.quantity == "flap1_nondim")
            .map(|c| c.computed)
            .unwrap_or(f64::NAN))
    };
    let fine = freq(16)?;
    let ns = vec![1, 2, 4];
    let mut errs = vec![];
    for &n in &ns {
        errs.push((freq(n)? - fine).abs() / fine);
    }
    let ord = observed_orders(&errs);
    out.push((
        "cantilever_flap1_frequency (relative error vs 16 elements)".to_string(),
        ns,
        errs,
        ord,
    ));
    Ok(out)
}
