//! An INDEPENDENT truth model of the physical damper (flightdata/damper_nominal.toml), written
//! from the reference paper's equations (Bauchau & Liu, Eqs. 1-8) and the deck description of
//! docs/formats.md, with its own regularizations and its own integrator (Dormand-Prince 5(4) with
//! error control). It shares no code with `rotorsim::hydraulics`: only the deck's numbers.
//!
//! Regularizations chosen here (the paper leaves them open):
//! - orifice, relief and check flows: `Q = Cd A sqrt(2/rho) dp / (dp^2 + dp_l^2)^(1/4)`, which
//!   is Eq. (4) for |dp| >> dp_l and laminar (linear in dp) below;
//! - relief poppets: Eq. (5) with a stiff, critically damped seat (penalty contact, 1e8 N/m)
//!   instead of a held constraint; the flow area of Eq. (7) is zero for x <= 0;
//! - check valves: the same flow law from p_s, zero for p >= p_s (no cracking pressure);
//! - cavitation: a vapour-cavity compliance `exp(-p/p_v)/p_v` (p_v = 5 kPa) added to the
//!   oil's, so a chamber's pressure cannot fall much below zero and recovers as the cavity
//!   collapses (the cavity volume is the integral of that compliance);
//! - entrained air: isothermal free air whose volume fraction is given at p_s, pressure floored
//!   at 20 kPa in the air law;
//! - pressures are absolute; the force is Eq. (8), `F = p0 A0 - p1 A1`.
//!
//! Effects are physical parts of the hardware: LuGre seal friction (bristle state, Stribeck),
//! free play or an elastic mount as a link with a moving mass (rod, rod end, piston) between the
//! bench actuator and the piston, with light contact damping; annular piston leakage
//! (Poiseuille plus Couette drag); laminar bleed of each chamber to the accumulator.
#![allow(dead_code)]

use std::f64::consts::PI;
use std::path::Path;

/// Relief valve (Eqs. 5-7).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Valve {
    pub m: f64,
    pub c: f64,
    pub k: f64,
    pub f_p: f64,
    pub a_front: f64,
    pub a_back: f64,
    pub a: f64,
    pub b: f64,
}

/// The damper's data sheet (SI).
#[derive(Debug, Clone, PartialEq)]
pub struct Sheet {
    pub area: [f64; 2],
    pub volume: [f64; 2],
    pub rho: f64,
    pub alpha: f64,
    pub beta: f64,
    pub a_orf: f64,
    pub cd: f64,
    pub p_s: f64,
    pub dp_l: f64,
    pub a_check: f64,
    pub relief: [Valve; 2],
}

fn num(t: &toml::Table, key: &str, file: &str) -> Result<f64, String> {
    match t.get(key) {
        Some(toml::Value::Float(x)) => Ok(*x),
        Some(toml::Value::Integer(i)) => Ok(*i as f64),
        _ => Err(format!("{file}: missing or non-numeric key `{key}`")),
    }
}

fn table<'a>(t: &'a toml::Table, key: &str, file: &str) -> Result<&'a toml::Table, String> {
    t.get(key)
        .and_then(|v| v.as_table())
        .ok_or_else(|| format!("{file}: missing table `{key}`"))
}

impl Sheet {
    /// Reads `[damper.physical]` of a damper deck (docs/formats.md) with the `toml` crate.
    pub fn from_file(path: &Path) -> Result<Self, String> {
        let file = path.display().to_string();
        let text = std::fs::read_to_string(path).map_err(|e| format!("{file}: {e}"))?;
        let root: toml::Table = text.parse().map_err(|e| format!("{file}: {e}"))?;
        let p = table(table(&root, "damper", &file)?, "physical", &file)?;
        let valve = |name: &str| -> Result<Valve, String> {
            let v = table(p, name, &file)?;
            Ok(Valve {
                m: num(v, "m_kg", &file)?,
                c: num(v, "c_N_s_per_m", &file)?,
                k: num(v, "k_N_per_m", &file)?,
                f_p: num(v, "F_p_N", &file)?,
                a_front: num(v, "A_front_m2", &file)?,
                a_back: num(v, "A_back_m2", &file)?,
                a: num(v, "a_m", &file)?,
                b: num(v, "b", &file)?,
            })
        };
        Ok(Self {
            area: [num(p, "A0_m2", &file)?, num(p, "A1_m2", &file)?],
            volume: [num(p, "V0_m3", &file)?, num(p, "V1_m3", &file)?],
            rho: num(p, "rho_kg_m3", &file)?,
            alpha: num(p, "bulk_alpha_per_Pa", &file)?,
            beta: num(p, "bulk_beta_per_Pa2", &file)?,
            a_orf: num(p, "A_orf_m2", &file)?,
            cd: num(p, "Cd", &file)?,
            p_s: num(p, "p_s_Pa", &file)?,
            dp_l: num(p, "dp_laminar_Pa", &file)?,
            a_check: num(p, "check_valve_area_m2", &file)?,
            relief: [valve("relief_valve_0")?, valve("relief_valve_1")?],
        })
    }

    /// flightdata/damper_nominal.toml.
    pub fn nominal() -> Self {
        Self::from_file(Path::new(concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/flightdata/damper_nominal.toml"
        )))
        .expect("nominal damper deck")
    }
}

/// LuGre seal friction on the piston (bristle deflection z).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Friction {
    /// Coulomb level [N].
    pub f_c: f64,
    /// Static (breakaway) level [N].
    pub f_s: f64,
    /// Stribeck velocity [m/s].
    pub v_s: f64,
    /// Bristle stiffness [N/m].
    pub sigma0: f64,
}

impl Friction {
    /// A seal: breakaway 25% above Coulomb, Stribeck velocity 5 mm/s, presliding 20 um.
    pub fn seal(f_c: f64) -> Self {
        Self {
            f_c,
            f_s: 1.25 * f_c,
            v_s: 0.005,
            sigma0: 1.25 * f_c / 2.0e-5,
        }
    }
}

/// The link between the bench actuator and the piston: a gap (total `gap`, 0 for a mount) in
/// series with a contact stiffness and light damping, and the moving mass between.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Link {
    pub gap: f64,
    pub k: f64,
    pub c: f64,
    pub mass: f64,
}

/// Moving mass of piston, rod and rod end [kg].
pub const LINK_MASS_KG: f64 = 1.5;
/// Damping ratio of the contact (or mount) against the moving mass.
pub const LINK_DAMPING_RATIO: f64 = 0.05;
/// Contact stiffness of a "rigid" free play (steel on steel, a bearing) [N/m].
pub const RIGID_CONTACT_N_PER_M: f64 = 5.0e9;

impl Link {
    pub fn new(gap: f64, k: f64) -> Self {
        Self {
            gap,
            k,
            c: 2.0 * LINK_DAMPING_RATIO * (k * LINK_MASS_KG).sqrt(),
            mass: LINK_MASS_KG,
        }
    }
}

/// Annular piston leakage: Poiseuille conductance `k` with the Couette drag of the piston
/// (clearance h from k for a 25 mm long seal land in oil of 0.03 Pa s).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Leak {
    pub k: f64,
    /// Couette flow per unit piston velocity [m^2] (flow 0 -> 1 = couette * w).
    pub couette: f64,
}

/// The oil's temperature: the data sheet holds at 20 C; density and bulk modulus fall linearly
/// with it (a mineral oil's expansion 7.5e-4/K; its modulus 0.45%/K).
pub const OIL_REFERENCE_K: f64 = 293.15;
pub const OIL_DENSITY_PER_K: f64 = 7.5e-4;
pub const OIL_BULK_PER_K: f64 = 4.5e-3;

impl Sheet {
    /// The sheet with its oil at `t_k`: `rho (1 - a dT)`, and alpha, beta of Eq. (3) over
    /// `(1 - b dT)` and its square, so the modulus is `(1 - b dT)` times the sheet's at the
    /// correspondingly scaled pressure.
    pub fn at_oil_temperature(&self, t_k: f64) -> Self {
        let dt = t_k - OIL_REFERENCE_K;
        let f = 1.0 - OIL_BULK_PER_K * dt;
        Self {
            rho: self.rho * (1.0 - OIL_DENSITY_PER_K * dt),
            alpha: self.alpha / f,
            beta: self.beta / (f * f),
            ..self.clone()
        }
    }
}

/// Oil viscosity [Pa s] and seal land length [m] of the annular leakage.
pub const LEAK_VISCOSITY_PA_S: f64 = 0.03;
pub const LEAK_LAND_M: f64 = 0.025;

impl Leak {
    pub fn annular(k: f64, piston_area: f64) -> Self {
        let (mu, len) = (LEAK_VISCOSITY_PA_S, LEAK_LAND_M);
        let d = 2.0 * (piston_area / PI).sqrt();
        let h = (12.0 * mu * len * k / (PI * d)).cbrt();
        Self {
            k,
            couette: 0.5 * PI * d * h,
        }
    }
}

/// The truth damper: data sheet plus hardware effects.
#[derive(Debug, Clone, PartialEq)]
pub struct Truth {
    pub sheet: Sheet,
    pub friction: Option<Friction>,
    pub link: Option<Link>,
    /// Free-air volume fraction at p_s, per chamber.
    pub air: [f64; 2],
    pub leak: Option<Leak>,
    /// Bleed of each chamber to the accumulator at p_s [m^3/(s Pa)].
    pub bleed: f64,
}

impl Truth {
    pub fn new(sheet: Sheet) -> Self {
        Self {
            sheet,
            friction: None,
            link: None,
            air: [0.0; 2],
            leak: None,
            bleed: 0.0,
        }
    }
}

/// Imposed stroke `mean + sum a_j sin(n_j omega t + phi_j)`.
#[derive(Debug, Clone, PartialEq)]
pub struct Stroke {
    pub mean: f64,
    pub omega: f64,
    /// (harmonic number, amplitude [m], phase [rad]).
    pub terms: Vec<(f64, f64, f64)>,
}

impl Stroke {
    pub fn harmonic(omega: f64, amplitude: f64) -> Self {
        Self {
            mean: 0.0,
            omega,
            terms: vec![(1.0, amplitude, 0.0)],
        }
    }
    pub fn at(&self, t: f64) -> (f64, f64) {
        let mut d = self.mean;
        let mut v = 0.0;
        for &(n, a, ph) in &self.terms {
            let w = n * self.omega;
            d += a * (w * t + ph).sin();
            v += a * w * (w * t + ph).cos();
        }
        (d, v)
    }
    /// Period of the fundamental [s].
    pub fn period(&self) -> f64 {
        2.0 * PI / self.omega
    }
}

/// State: p0, p1, x0, u0 (poppet 0), x1, u1 (poppet 1), s, w (piston position and velocity,
/// used with a link), z (bristle deflection).
pub const N: usize = 9;
pub type State = [f64; N];

const SEAT_K: f64 = 1.0e8;
const P_VAPOUR: f64 = 5.0e3;
const P_AIR_FLOOR: f64 = 2.0e4;

/// Regularized orifice law (see the module doc).
#[inline]
fn flow(cd_a: f64, rho: f64, dp: f64, dp_l: f64) -> f64 {
    cd_a * (2.0 / rho).sqrt() * dp / (dp * dp + dp_l * dp_l).sqrt().sqrt()
}

/// Every flow and force of a state (for the right-hand side and the diagnostics).
#[derive(Debug, Clone, Copy, Default)]
pub struct Flows {
    pub q_orifice: f64,
    pub q_relief: [f64; 2],
    pub q_check: [f64; 2],
    pub q_leak: f64,
    pub q_bleed: [f64; 2],
    /// Hydraulic force on the piston, Eq. (8).
    pub f_hyd: f64,
    pub f_fric: f64,
    /// Force of the link on the piston mass.
    pub f_link: f64,
    /// Force the damper exerts on the bench actuator (the load cell), Eq. (8) convention.
    pub f_meas: f64,
}

impl Truth {
    /// Compliance `-(1/V) dV/dp` of chamber k's mixture at pressure p [1/Pa].
    pub fn compliance(&self, k: usize, p: f64) -> f64 {
        let s = &self.sheet;
        let c = |p: f64| 1.0 + s.alpha * p + s.beta * p * p;
        let liquid = (s.alpha + 2.0 * s.beta * p) / c(p);
        let x0 = self.air[k];
        let mut comp = liquid;
        if x0 > 0.0 {
            let pa = p.max(P_AIR_FLOOR);
            let vl = (1.0 - x0) * c(s.p_s) / c(p);
            let va = x0 * s.p_s / pa;
            let x = va / (va + vl);
            comp = (1.0 - x) * liquid + x / pa;
        }
        comp + (-(p / P_VAPOUR).clamp(-50.0, 50.0)).exp() / P_VAPOUR
    }

    /// Piston position and velocity (the imposed stroke without a link).
    fn piston(&self, y: &State, d: f64, v: f64) -> (f64, f64) {
        if self.link.is_some() {
            (y[6], y[7])
        } else {
            (d, v)
        }
    }

    pub fn flows(&self, y: &State, d: f64, v: f64) -> Flows {
        let s = &self.sheet;
        let (p0, p1) = (y[0], y[1]);
        let (_, w) = self.piston(y, d, v);
        let dp = p0 - p1;
        let mut f = Flows {
            q_orifice: flow(s.cd * s.a_orf, s.rho, dp, s.dp_l),
            ..Default::default()
        };
        for k in 0..2 {
            let x = y[2 + 2 * k];
            let r = &s.relief[k];
            let area = if x > 0.0 { r.a * x + r.b * x * x } else { 0.0 };
            // valve 0 relieves chamber 0 (flow 0 -> 1), valve 1 chamber 1 (flow 1 -> 0)
            let sgn = if k == 0 { 1.0 } else { -1.0 };
            f.q_relief[k] = flow(s.cd * area, s.rho, sgn * dp, s.dp_l);
            let p = y[k];
            f.q_check[k] = if p < s.p_s {
                flow(s.cd * s.a_check, s.rho, s.p_s - p, s.dp_l)
            } else {
                0.0
            };
            f.q_bleed[k] = self.bleed * (p - s.p_s);
        }
        if let Some(l) = &self.leak {
            f.q_leak = l.k * dp + l.couette * w;
        }
        f.f_hyd = p0 * s.area[0] - p1 * s.area[1];
        if let Some(fr) = &self.friction {
            f.f_fric = -fr.sigma0 * y[8];
        }
        match &self.link {
            None => {
                f.f_link = -(f.f_hyd + f.f_fric);
            }
            Some(l) => {
                let rel = d - y[6];
                let rel_v = v - y[7];
                let h = 0.5 * l.gap;
                let e = rel - rel.clamp(-h, h);
                let fl = l.k * e + l.c * rel_v;
                f.f_link = if l.gap == 0.0 {
                    fl
                } else if e > 0.0 {
                    fl.max(0.0)
                } else if e < 0.0 {
                    fl.min(0.0)
                } else {
                    0.0
                };
            }
        }
        f.f_meas = -f.f_link;
        f
    }

    /// Right-hand side at time t.
    pub fn rhs(&self, stroke: &Stroke, t: f64, y: &State, dy: &mut State) {
        let s = &self.sheet;
        let (d, v) = stroke.at(t);
        let f = self.flows(y, d, v);
        let (sp, w) = self.piston(y, d, v);
        // Net inflow of each chamber (Eq. 1), lambda = +1 (chamber 0), -1 (chamber 1).
        let q0 =
            -f.q_orifice - f.q_relief[0] + f.q_relief[1] + f.q_check[0] - f.q_bleed[0] - f.q_leak;
        let q1 =
            f.q_orifice + f.q_relief[0] - f.q_relief[1] + f.q_check[1] - f.q_bleed[1] + f.q_leak;
        let vol0 = s.volume[0] + s.area[0] * sp;
        let vol1 = s.volume[1] - s.area[1] * sp;
        dy[0] = (q0 - s.area[0] * w) / (vol0 * self.compliance(0, y[0]));
        dy[1] = (q1 + s.area[1] * w) / (vol1 * self.compliance(1, y[1]));
        for k in 0..2 {
            let r = &s.relief[k];
            let (x, u) = (y[2 + 2 * k], y[3 + 2 * k]);
            let (pf, pb) = if k == 0 { (y[0], y[1]) } else { (y[1], y[0]) };
            let seat = if x < 0.0 {
                (-SEAT_K * x - 2.0 * (SEAT_K * r.m).sqrt() * u).max(0.0)
            } else {
                0.0
            };
            // Eq. (5)
            let acc = (pf * r.a_front - pb * r.a_back - r.f_p - r.c * u - r.k * x + seat) / r.m;
            dy[2 + 2 * k] = u;
            dy[3 + 2 * k] = acc;
        }
        if let Some(l) = &self.link {
            dy[6] = y[7];
            dy[7] = (f.f_hyd + f.f_fric + f.f_link) / l.mass;
        } else {
            dy[6] = 0.0;
            dy[7] = 0.0;
        }
        dy[8] = match &self.friction {
            Some(fr) => {
                let g = fr.f_c + (fr.f_s - fr.f_c) * (-(w / fr.v_s).powi(2)).exp();
                w - fr.sigma0 * w.abs() * y[8] / g
            }
            None => 0.0,
        };
    }

    /// Initial state: both chambers at p_s, poppets seated under their preload, piston at the
    /// stroke, bristles relaxed.
    pub fn initial(&self, stroke: &Stroke) -> State {
        let s = &self.sheet;
        let (d, v) = stroke.at(0.0);
        let mut y = [0.0; N];
        y[0] = s.p_s;
        y[1] = s.p_s;
        for k in 0..2 {
            let r = &s.relief[k];
            let net = s.p_s * (r.a_front - r.a_back) - r.f_p;
            y[2 + 2 * k] = if net < 0.0 { net / (SEAT_K + r.k) } else { 0.0 };
        }
        y[6] = d;
        y[7] = v;
        y
    }
}

/// Integration tolerances and statistics.
#[derive(Debug, Clone, Copy)]
pub struct Tolerance {
    pub rtol: f64,
    /// Absolute tolerance of a pressure [Pa]; the other states scale from it.
    pub atol_pa: f64,
}

impl Default for Tolerance {
    fn default() -> Self {
        Self {
            rtol: 1e-7,
            atol_pa: 10.0,
        }
    }
}

#[derive(Debug, Clone, Copy, Default)]
pub struct Stats {
    pub accepted: usize,
    pub rejected: usize,
}

// Dormand-Prince 5(4) tableau.
const C: [f64; 7] = [0.0, 0.2, 0.3, 0.8, 8.0 / 9.0, 1.0, 1.0];
const A: [[f64; 6]; 7] = [
    [0.0; 6],
    [0.2, 0.0, 0.0, 0.0, 0.0, 0.0],
    [3.0 / 40.0, 9.0 / 40.0, 0.0, 0.0, 0.0, 0.0],
    [44.0 / 45.0, -56.0 / 15.0, 32.0 / 9.0, 0.0, 0.0, 0.0],
    [
        19372.0 / 6561.0,
        -25360.0 / 2187.0,
        64448.0 / 6561.0,
        -212.0 / 729.0,
        0.0,
        0.0,
    ],
    [
        9017.0 / 3168.0,
        -355.0 / 33.0,
        46732.0 / 5247.0,
        49.0 / 176.0,
        -5103.0 / 18656.0,
        0.0,
    ],
    [
        35.0 / 384.0,
        0.0,
        500.0 / 1113.0,
        125.0 / 192.0,
        -2187.0 / 6784.0,
        11.0 / 84.0,
    ],
];
/// 5th-order weights (= the last row of A, FSAL).
const B5: [f64; 7] = [
    35.0 / 384.0,
    0.0,
    500.0 / 1113.0,
    125.0 / 192.0,
    -2187.0 / 6784.0,
    11.0 / 84.0,
    0.0,
];
/// 4th-order embedded weights.
const B4: [f64; 7] = [
    5179.0 / 57600.0,
    0.0,
    7571.0 / 16695.0,
    393.0 / 640.0,
    -92097.0 / 339200.0,
    187.0 / 2100.0,
    1.0 / 40.0,
];

/// Adaptive Dormand-Prince integration of the truth model with the stroke imposed.
pub struct Integrator<'a> {
    pub model: &'a Truth,
    pub stroke: &'a Stroke,
    pub tol: Tolerance,
    pub t: f64,
    pub y: State,
    h: f64,
    k1: State,
    scale: State,
    pub stats: Stats,
}

impl<'a> Integrator<'a> {
    pub fn new(model: &'a Truth, stroke: &'a Stroke, tol: Tolerance) -> Self {
        let y = model.initial(stroke);
        let mut k1 = [0.0; N];
        model.rhs(stroke, 0.0, &y, &mut k1);
        let p = tol.atol_pa;
        // Absolute tolerances per state: 10 Pa ~ 1e-10 m of poppet or piston travel.
        let scale = [
            p,
            p,
            p * 1e-11,
            p * 1e-7,
            p * 1e-11,
            p * 1e-7,
            p * 1e-11,
            p * 1e-8,
            p * 1e-11,
        ];
        Self {
            model,
            stroke,
            tol,
            t: 0.0,
            y,
            h: 1e-6,
            k1,
            scale,
            stats: Stats::default(),
        }
    }

    /// Advances to `t_end` exactly (steps chosen by the error estimate).
    pub fn advance(&mut self, t_end: f64) -> Result<(), String> {
        let mut k = [[0.0; N]; 7];
        let mut ytmp = [0.0; N];
        let mut ynew = [0.0; N];
        while self.t < t_end - 1e-15 {
            let last = self.t + self.h >= t_end;
            let h = if last { t_end - self.t } else { self.h };
            k[0] = self.k1;
            for st in 1..7 {
                for i in 0..N {
                    let mut acc = 0.0;
                    for (j, kj) in k.iter().enumerate().take(st) {
                        acc += A[st][j] * kj[i];
                    }
                    ytmp[i] = self.y[i] + h * acc;
                }
                let (before, after) = k.split_at_mut(st);
                let _ = before;
                self.model
                    .rhs(self.stroke, self.t + C[st] * h, &ytmp, &mut after[0]);
                if st == 6 {
                    ynew = ytmp;
                }
            }
            // Error of the embedded 4th-order solution.
            let mut err = 0.0;
            for i in 0..N {
                let mut e = 0.0;
                for s in 0..7 {
                    e += (B5[s] - B4[s]) * k[s][i];
                }
                e *= h;
                let sc = self.scale[i] + self.tol.rtol * self.y[i].abs().max(ynew[i].abs());
                err += (e / sc).powi(2);
            }
            let err = (err / N as f64).sqrt();
            if !err.is_finite() {
                self.h *= 0.1;
                self.stats.rejected += 1;
                if self.h < 1e-14 {
                    return Err(format!("step size underflow at t = {}", self.t));
                }
                continue;
            }
            let fac = if err == 0.0 {
                5.0
            } else {
                (0.9 * err.powf(-0.2)).clamp(0.2, 5.0)
            };
            if err <= 1.0 {
                self.t += h;
                self.y = ynew;
                self.k1 = k[6];
                self.stats.accepted += 1;
                if !last {
                    self.h = (h * fac).min(1e-3);
                } else {
                    // keep the controller's step across sample boundaries
                    self.h = self.h.max(h * fac).min(1e-3);
                }
            } else {
                self.h = h * fac.min(1.0);
                self.stats.rejected += 1;
                if self.h < 1e-14 {
                    return Err(format!("step size underflow at t = {}", self.t));
                }
            }
        }
        Ok(())
    }

    pub fn flows(&self) -> Flows {
        let (d, v) = self.stroke.at(self.t);
        self.model.flows(&self.y, d, v)
    }
}

/// Measured force (load cell) of `model` under `stroke` at the sample times `t`.
pub fn force_at(
    model: &Truth,
    stroke: &Stroke,
    t: &[f64],
    tol: Tolerance,
) -> Result<Vec<f64>, String> {
    let mut it = Integrator::new(model, stroke, tol);
    let mut out = Vec::with_capacity(t.len());
    for &ti in t {
        it.advance(ti)?;
        out.push(it.flows().f_meas);
    }
    Ok(out)
}
