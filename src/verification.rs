//! Verification cases shared by tests/ and `rotorsim verify` (issue #3).
use crate::solver::{static_solve, State, StaticOptions};
use crate::structure::*;

/// Uniform section with no offsets.
#[allow(clippy::too_many_arguments)]
pub fn uniform_section(ea: f64, ga: f64, gj: f64, ei2: f64, ei3: f64, m: f64, i1: f64, i2: f64, i3: f64) -> SectionTable {
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
        cm2: 0.0,
        cm3: 0.0,
        sc2: 0.0,
        sc3: 0.0,
        ca2: 0.0,
        ca3: 0.0,
    })
}

/// Published tip positions of the 45-degree bend (Simo & Vu-Quoc 1986, Table; Bathe &
/// Bolourchi 1979 problem): (force, [x, y, z]).
pub const BEND45_REF: [(f64, [f64; 3]); 3] = [
    (300.0, [58.84, 22.33, 40.08]),
    (450.0, [52.32, 18.62, 48.39]),
    (600.0, [47.23, 15.79, 53.37]),
];

/// 45-degree bend: returns (force, computed tip, reference tip).
pub fn bend45(n_elem: usize) -> Result<Vec<(f64, [f64; 3], [f64; 3])>, String> {
    let r = 100.0;
    let sec = uniform_section(1e7, 5e6, 7.05e5, 1e7 / 12.0, 1e7 / 12.0, 1.0, 1.0, 0.5, 0.5);
    let mut m = Model::new();
    let curve = move |s: f64| {
        let p = s / r;
        let (sn, cs) = p.sin_cos();
        ([r * sn, r * (1.0 - cs), 0.0], [[cs, -sn, 0.0], [sn, cs, 0.0], [0.0, 0.0, 1.0]])
    };
    let ids = m
        .add_beam("arc", n_elem, r * std::f64::consts::FRAC_PI_4, &curve, &sec, 0.0, None)
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
        static_solve(&mut m, &mut st, &opts, |s, n, it, r| { if std::env::var("DBG").is_ok() { eprintln!("step {s}/{n} it {it} r {r:.3e}") } }).map_err(|e| e.to_string())?;
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
        .add_straight_beam("beam", n_elem, [0.0; 3], [l, 0.0, 0.0], [0.0, 1.0, 0.0], sec, 0.0, None)
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
pub fn cantilever_release(n_elem: usize, steps_per_period: usize, periods: usize) -> Result<(f64, f64), String> {
    use crate::solver::DynamicSolver;
    let (ei, mass, l) = (100.0, 1.0, 10.0);
    let sec = uniform_section(1e6, 1e6, 100.0, ei, ei, mass, 1e-4, 5e-5, 5e-5);
    let (mut m, tip, load) = cantilever(n_elem, l, &sec);
    let w_ref = 3.516015_f64 * (ei / (mass * l.powi(4))).sqrt();
    if let Element::Load(p) = &mut m.elements[load] {
        p.force_n = [0.0, 0.0, 0.05];
    }
    let mut st = State::from_model(&m);
    static_solve(&mut m, &mut st, &StaticOptions::default(), |_, _, _, _| {}).map_err(|e| e.to_string())?;
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
