//! The coupled inflow against an independent blade-element momentum theory (BEMT), and the
//! absence of an every-step oscillation of the quasi-steady inflow (docs/aerodynamics.md,
//! "Inflow").
//!
//! The runs: `rotorsim run --airloads computed` on the shipped UH-60A-like deck, stiffened in
//! pitch (see [`stiff_overrides`]), with a copy of
//! the shipped record whose controls are a collective alone (3, 6, 9 and 12 deg, no cyclic),
//! shaft untilted, in hover and at advance ratio 0.05, uniform inflow (`aero.inflow =
//! "uniform"`). Drees' inflow is uniform in hover; in forward flight its first-harmonic shape
//! moves the thrust by a second-order amount that a uniform BEMT does not have, so the 2%
//! criterion is checked with uniform inflow, and Drees and Pitt-Peters are checked for the
//! every-step oscillation at the lightest loading.
//!
//! The BEMT, written here: the deck's chord, built-in twist, root cut-out and tip loss (no lift
//! outboard of B R), the shipped NACA 0012 C81 table through the public aerofoil API (lift and
//! drag at the section's angle of attack and Mach number), the record's air; the blade rigid
//! and unconed. Thrust is integrated over radius (and azimuth at mu > 0, in-plane velocity
//! `Omega r + mu Omega R sin psi`) at a uniform inflow ratio lambda, which solves Glauert's
//! momentum equation `lambda_i = CT / (2 sqrt(mu^2 + lambda^2))`, `lambda = lambda_i + mu
//! tan(alpha_s)` (alpha_s = 0 here: the free stream in the disk plane). The annulus-wise
//! BEMT (momentum per annulus, `dCT = 4 lambda_i sqrt(mu^2 + lambda^2) r dr`) is printed
//! beside it.
//!
//! What the BEMT's rigid, unconed blade does not have and the run keeps: the flow curvature a
//! coned or bent blade's three-quarter-chord point sees (a pitch rate `Omega` times the local
//! flap slope about the span). At 3 deg in hover the blade droops outboard (slope -1 deg
//! there, +0.7 deg at the root) and it moves the run's CT/sigma by -0.8%; at 6 to 12 deg,
//! coned up, by +1.2% to +2.1% (measured by dropping the three-quarter-chord arm).
mod support;

use rotorsim::aero::airfoil::{Airfoil, ClampCounts};
use rotorsim::aero::c81::C81Table;
use rotorsim::hydraulics::DamperModel;
use rotorsim::overrides::Override;
use rotorsim::rotor::aero::AirloadSource;
use rotorsim::rotor::RotorDeck;
use rotorsim::run::job::{DamperChoice, RunJob};
use rotorsim::run::periodic::PeriodicMethod;
use rotorsim::run::Silent;
use std::f64::consts::PI;
use std::path::{Path, PathBuf};
use std::sync::Arc;

/// Revolutions marched and steps per revolution of the runs (coarse steps: the check is the
/// mean thrust and the inflow's step-to-step behaviour; the start, the record's flight state,
/// leaves a lag and flap transient that moves the thrust by several percent for some
/// revolutions).
const REVS: usize = 12;
const STEPS: usize = 128;

/// The shipped deck stiffened in pitch: the blade's torsion (GJ x 100, a copy of its section
/// table) and the control system (the pitch link's EA x 1000). The BEMT's blade is rigid in
/// pitch; the shipped elastic blade and controls give about 0.2 deg of nose-down pitch in hover
/// (CT/sigma 5.6% lower at 6 deg of collective, 8% at 3 deg).
fn stiff_overrides(dir: &Path) -> Vec<Override> {
    let src = support::root().join("rotors/data/blade_sections_yeo.csv");
    let text = std::fs::read_to_string(src).unwrap();
    let mut lines = text.lines();
    let header = lines.next().unwrap();
    let gj = header.split(',').position(|c| c == "GJ_Nm2").unwrap();
    let mut out = format!("{header}\n");
    for l in lines {
        let row: Vec<String> = l
            .split(',')
            .enumerate()
            .map(|(i, v)| {
                if i == gj {
                    format!("{:e}", v.parse::<f64>().unwrap() * 100.0)
                } else {
                    v.to_string()
                }
            })
            .collect();
        out.push_str(&row.join(","));
        out.push('\n');
    }
    let csv = dir.join("stiff_sections.csv");
    std::fs::write(&csv, out).unwrap();
    vec![
        Override::parse("pitch_control.link_section.EA_N=9.0e8").unwrap(),
        Override::parse(&format!("blade.sections_csv=\"{}\"", csv.display())).unwrap(),
    ]
}

/// The shipped record with the controls a collective alone, at advance ratio `mu`.
fn record(dir: &Path, name: &str, mu: f64, collective_deg: f64) -> PathBuf {
    let root = support::root();
    let src = root.join("flightdata/c8534like");
    let mut meta = support::read_json(&PathBuf::from(format!("{}.meta.json", src.display())));
    meta["advance_ratio"] = mu.into();
    meta["forward_speed_kt"] = (mu * 27.0 * 8.178 / 0.514444).into();
    meta["shaft_tilt_deg"] = 0.0.into();
    meta["controls_deg"] = serde_json::json!({
        "collective": collective_deg,
        "lateral_cyclic": 0.0,
        "longitudinal_cyclic": 0.0,
    });
    let stem = dir.join(name);
    std::fs::write(
        format!("{}.meta.json", stem.display()),
        serde_json::to_string_pretty(&meta).unwrap(),
    )
    .unwrap();
    for suf in [".airloads.csv", ".damper.csv"] {
        std::fs::copy(
            format!("{}{suf}", src.display()),
            format!("{}{suf}", stem.display()),
        )
        .unwrap();
    }
    stem
}

/// The columns of last_rev.csv.
fn columns(path: &Path) -> (Vec<String>, Vec<Vec<f64>>) {
    let text = std::fs::read_to_string(path).unwrap();
    let mut lines = text.lines();
    let names: Vec<String> = lines
        .next()
        .unwrap()
        .split(',')
        .map(|s| s.to_string())
        .collect();
    let mut cols = vec![vec![]; names.len()];
    for l in lines {
        for (c, v) in l.split(',').enumerate() {
            cols[c].push(v.parse::<f64>().unwrap_or(f64::NAN));
        }
    }
    (names, cols)
}

struct RunOut {
    ct_over_sigma: f64,
    inflow: Vec<f64>,
}

fn run(dir: &Path, name: &str, mu: f64, collective_deg: f64, inflow: &str) -> RunOut {
    let rec = record(dir, name, mu, collective_deg);
    let out = dir.join(format!("{name}_out"));
    let job = RunJob {
        rotor: support::root().join("rotors/uh60a.toml"),
        flight: rec,
        damper: DamperChoice::One(DamperModel::Linear),
        periodic: PeriodicMethod::March,
        revs: REVS,
        steps_per_rev: STEPS,
        airloads: AirloadSource::Computed,
        overrides: {
            let mut o = stiff_overrides(dir);
            o.push(Override::parse(&format!("aero.inflow=\"{inflow}\"")).unwrap());
            o
        },
        ..RunJob::new(&out)
    };
    job.execute(&Silent).unwrap();
    let (names, cols) = columns(&out.join("linear/last_rev.csv"));
    let col = |n: &str| {
        let i = names.iter().position(|c| c == n).unwrap();
        cols[i].clone()
    };
    let ct = col("rotor_CT_over_sigma");
    RunOut {
        ct_over_sigma: ct.iter().sum::<f64>() / ct.len() as f64,
        inflow: col("inflow_ratio_mean"),
    }
}

/// The blade and air the BEMT integrates.
struct Blade {
    radius: f64,
    omega: f64,
    blades: f64,
    chord: f64,
    cutout: f64,
    tip_loss: f64,
    twist_deg: Vec<[f64; 2]>,
    airfoil: Airfoil,
    rho: f64,
    sound: f64,
}

impl Blade {
    fn shipped() -> Self {
        let root = support::root();
        let deck = RotorDeck::from_file(&root.join("rotors/uh60a.toml")).unwrap();
        let spec = &deck.spec;
        let aero = spec.aero.as_ref().unwrap();
        let table = C81Table::from_file(&root.join("data/airfoils/naca0012.c81")).unwrap();
        let meta = support::read_json(&root.join("flightdata/c8534like.meta.json"));
        Blade {
            radius: spec.rotor.radius_m,
            omega: spec.rotor.omega_rad_s,
            blades: spec.rotor.blades as f64,
            chord: aero.chord_m,
            cutout: aero.cutout_r_m,
            tip_loss: aero.tip_loss_factor,
            twist_deg: spec.blade.twist_deg.clone(),
            airfoil: Airfoil::Table(Arc::new(table)),
            rho: meta["density_kg_m3"].as_f64().unwrap(),
            sound: meta["speed_of_sound_m_s"].as_f64().unwrap(),
        }
    }

    fn solidity(&self) -> f64 {
        self.blades * self.chord / (PI * self.radius)
    }

    /// Built-in twist at radius r [rad]: linear in the table, constant outside it.
    fn twist(&self, r: f64) -> f64 {
        let t = &self.twist_deg;
        if r <= t[0][0] {
            return t[0][1].to_radians();
        }
        for w in t.windows(2) {
            if r <= w[1][0] {
                let f = (r - w[0][0]) / (w[1][0] - w[0][0]);
                return (w[0][1] + f * (w[1][1] - w[0][1])).to_radians();
            }
        }
        t[t.len() - 1][1].to_radians()
    }

    /// Thrust per unit radius of the rotor [N/m] at radius r, mean over azimuth, at inflow
    /// ratio `lambda` (positive down) and collective `th0` [rad].
    fn dthrust(&self, r: f64, lambda: f64, mu: f64, th0: f64) -> f64 {
        let vt = self.omega * self.radius;
        let naz = if mu == 0.0 { 1 } else { 72 };
        let clamps = ClampCounts::default();
        let lift = if r <= self.tip_loss * self.radius {
            1.0
        } else {
            0.0
        };
        let mut f = 0.0;
        for k in 0..naz {
            let psi = 2.0 * PI * k as f64 / naz as f64;
            let ut = self.omega * r + mu * vt * psi.sin();
            let up = lambda * vt;
            let phi = up.atan2(ut);
            let alpha = th0 + self.twist(r) - phi;
            let u2 = ut * ut + up * up;
            let c = self
                .airfoil
                .coefficients(alpha, u2.sqrt() / self.sound, &clamps);
            let q = 0.5 * self.rho * u2 * self.chord;
            f += q * (lift * c.cl * phi.cos() - c.cd * phi.sin());
        }
        self.blades * f / naz as f64
    }

    fn scale(&self) -> f64 {
        let vt = self.omega * self.radius;
        self.rho * PI * self.radius.powi(2) * vt * vt
    }

    /// Radial midpoints from the cut-out to the tip.
    fn stations(&self) -> Vec<(f64, f64)> {
        let n = 400;
        let dr = (self.radius - self.cutout) / n as f64;
        (0..n)
            .map(|i| (self.cutout + (i as f64 + 0.5) * dr, dr))
            .collect()
    }

    /// CT at a uniform inflow ratio `lambda`.
    fn ct(&self, lambda: f64, mu: f64, th0: f64) -> f64 {
        self.stations()
            .iter()
            .map(|(r, dr)| self.dthrust(*r, lambda, mu, th0) * dr)
            .sum::<f64>()
            / self.scale()
    }

    /// Uniform-inflow BEMT: lambda with `CT(lambda) = 2 lambda sqrt(mu^2 + lambda^2)` (no free
    /// stream through the disk), by bisection; returns CT.
    fn ct_uniform(&self, mu: f64, th0: f64) -> f64 {
        let resid = |l: f64| self.ct(l, mu, th0) - 2.0 * l * mu.hypot(l);
        assert!(resid(0.0) > 0.0 && resid(0.3) < 0.0);
        self.ct(bisect(resid, 0.0, 0.3), mu, th0)
    }

    /// Annulus BEMT: per annulus, lambda(r) with `dT = rho 4 pi r V_T lambda_i Omega R dr`
    /// (`V_T = sqrt(mu^2 + lambda^2) Omega R`); returns CT.
    fn ct_annulus(&self, mu: f64, th0: f64) -> f64 {
        let vt = self.omega * self.radius;
        let mut t = 0.0;
        for (r, dr) in self.stations() {
            let resid = |l: f64| {
                self.dthrust(r, l, mu, th0) - self.rho * 4.0 * PI * r * mu.hypot(l) * vt * l * vt
            };
            if resid(0.0) <= 0.0 {
                continue;
            }
            t += self.dthrust(r, bisect(resid, 0.0, 0.5), mu, th0) * dr;
        }
        t / self.scale()
    }
}

/// The root of `f` in `[a, b]` (`f(a) > 0`) by 60 bisections.
fn bisect(f: impl Fn(f64) -> f64, mut a: f64, mut b: f64) -> f64 {
    for _ in 0..60 {
        let m = 0.5 * (a + b);
        if f(m) > 0.0 {
            a = m;
        } else {
            b = m;
        }
    }
    0.5 * (a + b)
}

/// Largest step-to-step change of the inflow over the last revolution relative to its mean.
fn every_step_change(inflow: &[f64]) -> f64 {
    let mean = inflow.iter().sum::<f64>() / inflow.len() as f64;
    let d = inflow
        .windows(2)
        .map(|w| (w[1] - w[0]).abs())
        .fold(0.0, f64::max);
    d / mean.abs()
}

/// The cases checked to 2% (advance ratio, collective [deg]).
const CASES: [(f64, f64); 8] = [
    (0.0, 3.0),
    (0.0, 6.0),
    (0.0, 9.0),
    (0.0, 12.0),
    (0.05, 3.0),
    (0.05, 6.0),
    (0.05, 9.0),
    (0.05, 12.0),
];

#[test]
fn coupled_inflow_matches_blade_element_momentum_theory() {
    let dir = support::tmp("inflow_consistency");
    let mut failures = check_cases(&dir, &CASES);
    // the other models at the lightest loading, where the lagged quasi-steady inflow flipped
    for (mu, inflow) in [(0.05, "drees"), (0.0, "pitt-peters")] {
        let name = format!("mu{mu}_{inflow}");
        let r = run(&dir, &name, mu, 3.0, inflow);
        let step = every_step_change(&r.inflow);
        println!("{inflow}, mu {mu}, collective 3 deg: largest inflow step change {step:.2e} of its mean, CT/sigma {:.5}", r.ct_over_sigma);
        if step.is_nan() || step >= 0.01 {
            failures.push(format!("{name}: inflow step change {step:.2e} of its mean"));
        }
    }
    let _ = std::fs::remove_dir_all(&dir);
    assert!(failures.is_empty(), "{failures:#?}");
}

/// Runs each case with uniform inflow and checks CT/sigma against the BEMT to 2% and the
/// inflow's step-to-step change; returns the failures.
fn check_cases(dir: &Path, cases: &[(f64, f64)]) -> Vec<String> {
    let blade = Blade::shipped();
    let sigma = blade.solidity();
    let mut failures = vec![];
    for &(mu, th) in cases {
        let name = format!("mu{mu}_th{th}");
        let r = run(dir, &name, mu, th, "uniform");
        let want = blade.ct_uniform(mu, th.to_radians()) / sigma;
        let annulus = blade.ct_annulus(mu, th.to_radians()) / sigma;
        let err = r.ct_over_sigma / want - 1.0;
        let step = every_step_change(&r.inflow);
        let mean = r.inflow.iter().sum::<f64>() / r.inflow.len() as f64;
        println!(
                "mu {mu} collective {th} deg: CT/sigma run {:.5}, BEMT (uniform) {want:.5} ({:+.2}%), BEMT (annulus) {annulus:.5}; inflow ratio {mean:.5}, largest step change {:.2e} of it",
                r.ct_over_sigma,
                100.0 * err,
                step
            );
        if err.abs() > 0.02 {
            failures.push(format!("{name}: CT/sigma {:+.2}% from BEMT", 100.0 * err));
        }
        if step.is_nan() || step >= 0.01 {
            failures.push(format!("{name}: inflow step change {step:.2e} of its mean"));
        }
    }
    failures
}

/// The periodicity monitor's step-rate measure: an every-step alternation about a mean is 1/2
/// of its peak-to-peak, a smooth periodic signal has none.
#[test]
fn step_rate_content_sees_the_alternation_only() {
    use rotorsim::run::periodic::step_rate_content;
    let n = 256;
    let flip: Vec<f64> = (0..n)
        .map(|j| 1000.0 + if j % 2 == 0 { 50.0 } else { -30.0 })
        .collect();
    assert!((step_rate_content(&flip, 10.0) - 0.5).abs() < 1e-12);
    let smooth: Vec<f64> = (0..n)
        .map(|j| 1000.0 + 40.0 * (4.0 * 2.0 * PI * j as f64 / n as f64).sin())
        .collect();
    assert!(step_rate_content(&smooth, 10.0) < 1e-12);
    assert_eq!(step_rate_content(&[5.0; 8], 10.0), 0.0);
}
