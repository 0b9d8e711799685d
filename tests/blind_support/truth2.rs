//! A SECOND independent truth model of the physical damper (flightdata/damper_nominal.toml),
//! written from the reference paper's equations (Bauchau & Liu, Eqs. 1-8), docs/hydraulics.md
//! and docs/formats.md, and sharing no code with `rotorsim::hydraulics` nor with the first truth
//! model (truth.rs): only the deck's numbers, read here with the `toml` crate. It exists to
//! measure the diagnosis against data whose CONVENTIONS differ from the replay's (docs/diagnosis.md
//! "Blind suite", "Second truth model").
//!
//! Equations. Chamber k (lambda_0 = +1, lambda_1 = -1), Eqs. (1)-(2):
//! `p_k' = (Q_k - lambda_k A_k s') / (V_k C_k(p_k))`, `V_k = V_k0 + lambda_k A_k s`,
//! s the piston's stroke, C_k the compliance `-(1/V) dV/dp` of the chamber's mixture: the oil of
//! Eq. (3), whose sealed volume goes as `1/c(p)`, `c(p) = 1 + alpha p + beta p^2` (the integral of
//! `dV/V = -dp/B`), and free gas (entrained air, isothermal, fraction x_k at p_s) moving with the
//! oil as a homogeneous mixture: per unit volume at p_s, oil `(1 - x) c(p_s)/c(p)` and gas
//! `x p_s / p`. Orifice Eq. (4), relief valves Eqs. (5)-(7) (valve k relieves chamber k: its
//! poppet is opened by `p_k A_front - p_other A_back - F_p`, its flow goes from chamber k to the
//! other), check valves from the accumulator at p_s, force Eq. (8) `F = p0 A0 - p1 A1`.
//!
//! Regularisations chosen here where the paper leaves a detail open (deliberately unlike the
//! first truth's and the library's):
//! - every flow law: `Q = C_d A sqrt(2/rho) sign(dp) sqrt|dp| tanh(sqrt(|dp|/dp_l))`, dp_l the
//!   deck's `dp_laminar_Pa`: a discharge coefficient that rises with the flow number as a tanh
//!   (laminar, linear in dp, for |dp| << dp_l; Eq. (4) within 1% above 7 dp_l);
//! - relief poppets: Eq. (5) on a Hertzian seat with Hunt-Crossley dissipation, seat force
//!   `k_s delta^(3/2) (1 + chi_s delta')` (delta the poppet's penetration into the seat, never
//!   pulling), k_s = 2e11 N/m^1.5, chi_s = 10 s/m; flow area of Eq. (7) zero for x <= 0;
//! - check valves: the flow law from p_s through an opening area
//!   `A_check (1 - exp(-(p_s - p)/2 kPa))` for p < p_s, shut above;
//! - cavitation: gaseous, by a nucleus content of free gas (1e-7 of the volume at p_s, the
//!   same isothermal law as entrained air) that expands without limit as p -> 0, so a chamber's
//!   pressure stays positive and its cavity collapses as oil returns; below 1 Pa the gas volume
//!   is continued linearly (C1), a guard for Newton iterates only;
//! - pressures are absolute.
//!
//! Effects are hardware: seal friction by the elasto-plastic law (Dupont et al.: pure elastic
//! presliding below a breakaway deflection, a smooth transition to sliding, Stribeck peak
//! `F_s = 1.15 F_c` decaying as `exp(-|v|/v_s)`, v_s = 8 mm/s, presliding `F_c/sigma0` = 35 um);
//! a link (free play or mount) with the moving mass of rod, rod end and piston (0.9 kg) between
//! the bench actuator and the piston: a gap behind a contact with Hunt-Crossley dissipation
//! `k delta (1 + chi delta')` (chi = 5 s/m, pushing only), steel 3e9 N/m, or a mount as a
//! Kelvin-Voigt spring-dashpot at 8% of critical; annular piston leakage (Poiseuille plus the
//! piston's Couette drag, clearance from the conductance, oil 0.021 Pa s, land 17 mm); laminar
//! bleed of each chamber to the accumulator.
//!
//! Integrator: 3-stage Radau IIA (order 5, stiffly accurate) with simplified Newton iterations
//! on a finite-difference Jacobian and step control by the embedded order-3 estimate filtered by
//! `(I - h gamma0 J)^-1` (Hairer & Wanner, IV.8), stepping exactly onto every output time.
//!
//! Acquisition (the conventions this model exists for): the FORCE is the average over each
//! sample interval (an integrating ADC: the value at t_k is `(1/h) int_{t_k-h}^{t_k} F dt`, the
//! integral an extra ODE state reset at every sample: group delay h/2), and the STROKE comes
//! from a position sensor, a 2nd-order Butterworth low-pass of the true stroke integrated as two
//! ODE states (group delay `2 zeta/omega_c` = `sqrt(2)/omega_c` at low frequency), then noise and
//! quantisation (the campaign's, suite2.rs). The bench actuator starts from rest with the
//! amplitude ramped in over the first period (raised cosine), so the damper rests at p_s before
//! t = 0.
use std::f64::consts::PI;
use std::path::Path;

/// One relief valve of the data sheet (Eqs. 5-7).
#[derive(Debug, Clone, PartialEq)]
pub struct Poppet {
    pub mass: f64,
    pub damping: f64,
    pub spring: f64,
    pub preload: f64,
    pub area_front: f64,
    pub area_back: f64,
    pub a: f64,
    pub b: f64,
}

/// The damper's data sheet (the `[damper.physical]` table).
#[derive(Debug, Clone, PartialEq)]
pub struct DataSheet {
    pub piston_area: [f64; 2],
    pub chamber_volume: [f64; 2],
    pub density: f64,
    pub alpha: f64,
    pub beta: f64,
    pub orifice_area: f64,
    pub discharge: f64,
    pub supply: f64,
    pub laminar: f64,
    pub check_area: f64,
    pub poppet: [Poppet; 2],
}

impl DataSheet {
    /// Reads `[damper.physical]` of a damper deck.
    pub fn read(path: &Path) -> Result<Self, String> {
        let where_ = path.display().to_string();
        let text = std::fs::read_to_string(path).map_err(|e| format!("{where_}: {e}"))?;
        let root: toml::Table = text.parse().map_err(|e| format!("{where_}: {e}"))?;
        let phys = root
            .get("damper")
            .and_then(|d| d.get("physical"))
            .ok_or_else(|| format!("{where_}: no [damper.physical]"))?;
        let num = |t: &toml::Value, key: &str| -> Result<f64, String> {
            t.get(key)
                .and_then(|v| v.as_float().or_else(|| v.as_integer().map(|i| i as f64)))
                .ok_or_else(|| format!("{where_}: no number {key}"))
        };
        let poppet = |name: &str| -> Result<Poppet, String> {
            let t = phys
                .get(name)
                .ok_or_else(|| format!("{where_}: no [damper.physical.{name}]"))?;
            Ok(Poppet {
                mass: num(t, "m_kg")?,
                damping: num(t, "c_N_s_per_m")?,
                spring: num(t, "k_N_per_m")?,
                preload: num(t, "F_p_N")?,
                area_front: num(t, "A_front_m2")?,
                area_back: num(t, "A_back_m2")?,
                a: num(t, "a_m")?,
                b: num(t, "b")?,
            })
        };
        Ok(Self {
            piston_area: [num(phys, "A0_m2")?, num(phys, "A1_m2")?],
            chamber_volume: [num(phys, "V0_m3")?, num(phys, "V1_m3")?],
            density: num(phys, "rho_kg_m3")?,
            alpha: num(phys, "bulk_alpha_per_Pa")?,
            beta: num(phys, "bulk_beta_per_Pa2")?,
            orifice_area: num(phys, "A_orf_m2")?,
            discharge: num(phys, "Cd")?,
            supply: num(phys, "p_s_Pa")?,
            laminar: num(phys, "dp_laminar_Pa")?,
            check_area: num(phys, "check_valve_area_m2")?,
            poppet: [poppet("relief_valve_0")?, poppet("relief_valve_1")?],
        })
    }

    /// flightdata/damper_nominal.toml.
    pub fn nominal() -> Self {
        Self::read(Path::new(concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/flightdata/damper_nominal.toml"
        )))
        .expect("nominal damper deck")
    }
}

/// Free gas content that makes the cavitation law (fraction of the volume at p_s).
pub const NUCLEI: f64 = 1.0e-7;
/// Below this pressure [Pa] the gas volume is continued linearly (a guard for Newton iterates).
pub const GAS_FLOOR_PA: f64 = 1.0;
/// Hertzian seat of the relief poppets [N/m^1.5] and its Hunt-Crossley coefficient [s/m].
pub const SEAT_STIFFNESS: f64 = 2.0e11;
pub const SEAT_DISSIPATION_S_PER_M: f64 = 10.0;
/// Pressure deficit [Pa] over which a check valve opens (`1 - exp(-dp/this)`).
pub const CHECK_OPENING_PA: f64 = 2.0e3;
/// Moving mass between a link and the oil (rod, rod end, piston) [kg].
pub const MOVING_MASS_KG: f64 = 0.9;
/// Steel contact behind a rigid gap [N/m].
pub const STEEL_CONTACT_N_PER_M: f64 = 3.0e9;
/// Hunt-Crossley coefficient of a gap's contact [s/m].
pub const CONTACT_DISSIPATION_S_PER_M: f64 = 5.0;
/// Damping of an elastic mount, fraction of critical against the moving mass.
pub const MOUNT_DAMPING_RATIO: f64 = 0.08;
/// Oil viscosity [Pa s] and the seal land's length [m] of the annular leakage.
pub const LEAK_VISCOSITY_PA_S: f64 = 0.021;
pub const LEAK_LAND_M: f64 = 0.017;
/// Elasto-plastic seal: static over Coulomb level, Stribeck velocity [m/s], presliding
/// deflection at the Coulomb level [m], breakaway deflection over it.
pub const SEAL_STATIC_RATIO: f64 = 1.15;
pub const SEAL_STRIBECK_M_S: f64 = 8.0e-3;
pub const SEAL_PRESLIDING_M: f64 = 35.0e-6;
pub const SEAL_BREAKAWAY: f64 = 0.6;

/// Elasto-plastic seal friction (Dupont, Hayward, Armstrong, Altpeter 2002).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Seal {
    pub f_c: f64,
    pub f_s: f64,
    pub v_s: f64,
    pub sigma0: f64,
    pub breakaway: f64,
}

impl Seal {
    pub fn new(f_c: f64) -> Self {
        Self {
            f_c,
            f_s: SEAL_STATIC_RATIO * f_c,
            v_s: SEAL_STRIBECK_M_S,
            sigma0: f_c / SEAL_PRESLIDING_M,
            breakaway: SEAL_BREAKAWAY,
        }
    }
    /// Rate of the deflection z at sliding velocity v.
    pub fn rate(&self, z: f64, v: f64) -> f64 {
        let g = self.f_c + (self.f_s - self.f_c) * (-v.abs() / self.v_s).exp();
        let z_ss = g / self.sigma0;
        let z_ba = self.breakaway * self.f_c / self.sigma0;
        let a = z.abs();
        let alpha = if z * v <= 0.0 || a <= z_ba {
            0.0
        } else if a >= z_ss {
            1.0
        } else {
            0.5 + 0.5 * (PI * (a - 0.5 * (z_ss + z_ba)) / (z_ss - z_ba)).sin()
        };
        v - alpha * v.abs() * z / z_ss
    }
}

/// The contact of a link between the bench actuator and the piston.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Contact {
    /// Total gap [m] (+-gap/2) behind a stiffness [N/m] with Hunt-Crossley dissipation [s/m].
    Gap {
        gap: f64,
        stiffness: f64,
        dissipation: f64,
    },
    /// Kelvin-Voigt mount: stiffness [N/m], dashpot [N s/m].
    Mount { stiffness: f64, damping: f64 },
}

/// A link with the moving mass [kg] between it and the oil.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Link {
    pub contact: Contact,
    pub mass: f64,
}

impl Link {
    pub fn gap(gap: f64, stiffness: f64) -> Self {
        Self {
            contact: Contact::Gap {
                gap,
                stiffness,
                dissipation: CONTACT_DISSIPATION_S_PER_M,
            },
            mass: MOVING_MASS_KG,
        }
    }
    pub fn mount(stiffness: f64) -> Self {
        Self {
            contact: Contact::Mount {
                stiffness,
                damping: 2.0 * MOUNT_DAMPING_RATIO * (stiffness * MOVING_MASS_KG).sqrt(),
            },
            mass: MOVING_MASS_KG,
        }
    }
    /// Force of the link on the piston (towards the actuator's end) at deflection
    /// `e = end - piston` and its rate.
    pub fn force(&self, e: f64, e_dot: f64) -> f64 {
        match self.contact {
            Contact::Mount { stiffness, damping } => stiffness * e + damping * e_dot,
            Contact::Gap {
                gap,
                stiffness,
                dissipation,
            } => {
                let half = 0.5 * gap;
                if e > half {
                    (stiffness * (e - half) * (1.0 + dissipation * e_dot)).max(0.0)
                } else if e < -half {
                    -(stiffness * (-e - half) * (1.0 - dissipation * e_dot)).max(0.0)
                } else {
                    0.0
                }
            }
        }
    }
}

/// Annular piston leakage: Poiseuille conductance k [m^3/(s Pa)] and the Couette drag area
/// `pi D h / 2` [m^2] (the flow the moving piston drags toward the chamber it shrinks).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Annulus {
    pub k: f64,
    pub drag: f64,
}

impl Annulus {
    /// Clearance from the conductance of an annulus of the piston's bore (from its area),
    /// `k = pi D h^3 / (12 mu L)`, with this model's oil and land.
    pub fn from_conductance(k: f64, piston_area: f64) -> Self {
        let d = (4.0 * piston_area / PI).sqrt();
        let h = (12.0 * LEAK_VISCOSITY_PA_S * LEAK_LAND_M * k / (PI * d)).cbrt();
        Self {
            k,
            drag: 0.5 * PI * d * h,
        }
    }
}

/// The truth model: data sheet plus hardware effects.
#[derive(Debug, Clone, PartialEq)]
pub struct Model {
    pub sheet: DataSheet,
    /// Entrained air, volume fraction at p_s, per chamber.
    pub gas: [f64; 2],
    /// Cavitation nuclei (free gas always present), fraction at p_s.
    pub nuclei: f64,
    pub seal: Option<Seal>,
    pub link: Option<Link>,
    pub annulus: Option<Annulus>,
    /// Bleed conductance of each chamber to the accumulator [m^3/(s Pa)].
    pub bleed: f64,
}

impl Model {
    pub fn new(sheet: DataSheet) -> Self {
        Self {
            sheet,
            gas: [0.0; 2],
            nuclei: NUCLEI,
            seal: None,
            link: None,
            annulus: None,
            bleed: 0.0,
        }
    }

    /// Volume per unit volume at p_s of chamber k's mixture at p, and its derivative in p.
    pub fn mixture(&self, k: usize, p: f64) -> (f64, f64) {
        let s = &self.sheet;
        let x = self.gas[k] + self.nuclei;
        let c = |p: f64| 1.0 + s.alpha * p + s.beta * p * p;
        let (cs, cp) = (c(s.supply), c(p));
        let oil = (1.0 - x) * cs / cp;
        let d_oil = -(1.0 - x) * cs * (s.alpha + 2.0 * s.beta * p) / (cp * cp);
        let (gas, d_gas) = if p >= GAS_FLOOR_PA {
            (x * s.supply / p, -x * s.supply / (p * p))
        } else {
            let slope = -x * s.supply / (GAS_FLOOR_PA * GAS_FLOOR_PA);
            (
                x * s.supply / GAS_FLOOR_PA + slope * (p - GAS_FLOOR_PA),
                slope,
            )
        };
        (oil + gas, d_oil + d_gas)
    }

    /// Compliance `-(1/V) dV/dp` of chamber k's mixture at p [1/Pa].
    pub fn compliance(&self, k: usize, p: f64) -> f64 {
        let (v, dv) = self.mixture(k, p);
        -dv / v
    }

    /// Flow law per unit `C_d A` [m^3/s per m^2]: `sqrt(2/rho) sign(dp) sqrt|dp| tanh(sqrt(|dp|/dp_l))`.
    pub fn flow_law(&self, dp: f64) -> f64 {
        let a = dp.abs();
        let r = a.sqrt();
        (2.0 / self.sheet.density).sqrt() * dp.signum() * r * (r / self.sheet.laminar.sqrt()).tanh()
    }

    /// Flow area of relief valve k at opening x (Eq. 7).
    fn relief_area(&self, k: usize, x: f64) -> f64 {
        let v = &self.sheet.poppet[k];
        if x > 0.0 {
            v.a * x + v.b * x * x
        } else {
            0.0
        }
    }

    /// Check valve flow into a chamber at pressure p.
    fn check_flow(&self, p: f64) -> f64 {
        let s = &self.sheet;
        let dp = s.supply - p;
        if dp <= 0.0 {
            0.0
        } else {
            s.discharge * s.check_area * (1.0 - (-dp / CHECK_OPENING_PA).exp()) * self.flow_law(dp)
        }
    }

    /// Seat force on a poppet at opening x, velocity u (pushes it off the seat; zero off it).
    fn seat_force(x: f64, u: f64) -> f64 {
        if x >= 0.0 {
            return 0.0;
        }
        let delta = -x;
        (SEAT_STIFFNESS * delta * delta.sqrt() * (1.0 - SEAT_DISSIPATION_S_PER_M * u)).max(0.0)
    }

    /// Static seated penetration of poppet k with both chambers at p_s (solves
    /// `k_s delta^1.5 + k delta = F_p - p_s (A_front - A_back)`).
    fn seated_penetration(&self, k: usize) -> f64 {
        let v = &self.sheet.poppet[k];
        let load = v.preload - self.sheet.supply * (v.area_front - v.area_back);
        if load <= 0.0 {
            return 0.0;
        }
        let (mut lo, mut hi) = (0.0f64, 1.0f64);
        for _ in 0..200 {
            let m = 0.5 * (lo + hi);
            if SEAT_STIFFNESS * m * m.sqrt() + v.spring * m > load {
                hi = m
            } else {
                lo = m
            }
        }
        0.5 * (lo + hi)
    }
}

/// Imposed end stroke `mean + r(t) sum a_j sin(n_j omega t + phi_j)`, r the raised-cosine ramp
/// `(1 - cos(pi t/ramp))/2` over `ramp` seconds (0: none), at rest for t < 0.
#[derive(Debug, Clone, PartialEq)]
pub struct Motion {
    pub mean: f64,
    pub omega: f64,
    /// (harmonic number, amplitude [m], phase [rad]).
    pub terms: Vec<(f64, f64, f64)>,
    pub ramp: f64,
}

impl Motion {
    pub fn harmonic(omega: f64, amplitude: f64) -> Self {
        Self {
            mean: 0.0,
            omega,
            terms: vec![(1.0, amplitude, 0.0)],
            ramp: 0.0,
        }
    }
    /// Stroke and its rate at t.
    pub fn at(&self, t: f64) -> (f64, f64) {
        if t < 0.0 && self.ramp > 0.0 {
            return (self.mean, 0.0);
        }
        let (mut x, mut v) = (0.0, 0.0);
        for &(n, a, ph) in &self.terms {
            let w = n * self.omega;
            x += a * (w * t + ph).sin();
            v += a * w * (w * t + ph).cos();
        }
        if self.ramp > 0.0 && t < self.ramp {
            let u = PI * t / self.ramp;
            let (r, dr) = (0.5 * (1.0 - u.cos()), 0.5 * PI / self.ramp * u.sin());
            return (self.mean + r * x, r * v + dr * x);
        }
        (self.mean + x, v)
    }
    /// Period of the fundamental [s].
    pub fn period(&self) -> f64 {
        2.0 * PI / self.omega
    }
}

/// The stroke sensor: 2nd-order low-pass of cutoff `omega_c` [rad/s] and damping ratio zeta.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Sensor {
    pub omega_c: f64,
    pub zeta: f64,
}

impl Sensor {
    /// Butterworth (zeta = 1/sqrt 2) of cutoff `hz`.
    pub fn butterworth(hz: f64) -> Self {
        Self {
            omega_c: 2.0 * PI * hz,
            zeta: std::f64::consts::FRAC_1_SQRT_2,
        }
    }
    /// Group delay at low frequency, `2 zeta/omega_c` [s].
    pub fn delay(&self) -> f64 {
        2.0 * self.zeta / self.omega_c
    }
}

/// State: p0, p1, x0, u0 (poppet 0), x1, u1, force integral since the last force sample,
/// sensor output and its rate, piston stroke and velocity (with a link), seal deflection.
pub const N: usize = 12;
pub type State = [f64; N];
pub const P0: usize = 0;
pub const P1: usize = 1;
pub const X0: usize = 2;
pub const U0: usize = 3;
pub const X1: usize = 4;
pub const U1: usize = 5;
pub const IMPULSE: usize = 6;
pub const SENSOR: usize = 7;
pub const SENSOR_RATE: usize = 8;
pub const PISTON: usize = 9;
pub const PISTON_RATE: usize = 10;
pub const SEAL: usize = 11;

/// Typical magnitude of each state (absolute tolerances scale from it).
pub const MAGNITUDE: State = [
    1e6, 1e6, 1e-4, 1e-1, 1e-4, 1e-1, 1.0, 1e-2, 1e-1, 1e-2, 1e-1, 1e-5,
];

/// Every flow and force of a state.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Flows {
    pub orifice: f64,
    pub relief: [f64; 2],
    pub check: [f64; 2],
    pub leak: f64,
    pub bleed: [f64; 2],
    /// Eq. (8) on the piston.
    pub hydraulic: f64,
    pub seal: f64,
    /// The link's force on the piston (0 without a link).
    pub link: f64,
    /// The force at the load cell (Eq. 8 convention: positive pushes the ends apart).
    pub measured: f64,
}

/// The damper on the bench: model, imposed motion, stroke sensor.
pub struct Bench<'a> {
    pub model: &'a Model,
    pub motion: &'a Motion,
    pub sensor: Sensor,
}

impl Bench<'_> {
    /// Piston stroke and velocity (the end's without a link).
    fn piston(&self, t: f64, y: &State) -> (f64, f64, f64, f64) {
        let (d, dd) = self.motion.at(t);
        if self.model.link.is_some() {
            (d, dd, y[PISTON], y[PISTON_RATE])
        } else {
            (d, dd, d, dd)
        }
    }

    pub fn flows(&self, t: f64, y: &State) -> Flows {
        let m = self.model;
        let s = &m.sheet;
        let (d, dd, _, v) = self.piston(t, y);
        let (p0, p1) = (y[P0], y[P1]);
        let dp = p0 - p1;
        let orifice = s.discharge * s.orifice_area * m.flow_law(dp);
        let relief = [
            s.discharge * m.relief_area(0, y[X0]) * m.flow_law(dp),
            s.discharge * m.relief_area(1, y[X1]) * m.flow_law(-dp),
        ];
        let check = [m.check_flow(p0), m.check_flow(p1)];
        let leak = m.annulus.map_or(0.0, |a| a.k * dp + a.drag * v);
        let bleed = [m.bleed * (p0 - s.supply), m.bleed * (p1 - s.supply)];
        let hydraulic = p0 * s.piston_area[0] - p1 * s.piston_area[1];
        let seal = m.seal.map_or(0.0, |f| -f.sigma0 * y[SEAL]);
        let (link, measured) = match &m.link {
            Some(l) => {
                let f = l.force(d - y[PISTON], dd - y[PISTON_RATE]);
                (f, -f)
            }
            None => (0.0, hydraulic + seal),
        };
        Flows {
            orifice,
            relief,
            check,
            leak,
            bleed,
            hydraulic,
            seal,
            link,
            measured,
        }
    }

    /// The load cell's force at state y.
    pub fn force(&self, t: f64, y: &State) -> f64 {
        self.flows(t, y).measured
    }

    pub fn rhs(&self, t: f64, y: &State, dy: &mut State) {
        let m = self.model;
        let s = &m.sheet;
        let (d, _, x, v) = self.piston(t, y);
        let f = self.flows(t, y);
        let vol = [
            (s.chamber_volume[0] + s.piston_area[0] * x).max(1e-12),
            (s.chamber_volume[1] - s.piston_area[1] * x).max(1e-12),
        ];
        let q0 = -f.orifice - f.relief[0] + f.relief[1] + f.check[0] - f.leak - f.bleed[0];
        let q1 = f.orifice + f.relief[0] - f.relief[1] + f.check[1] + f.leak - f.bleed[1];
        dy[P0] = (q0 - s.piston_area[0] * v) / (vol[0] * m.compliance(0, y[P0]));
        dy[P1] = (q1 + s.piston_area[1] * v) / (vol[1] * m.compliance(1, y[P1]));
        for (k, (xi, ui)) in [(X0, U0), (X1, U1)].into_iter().enumerate() {
            let pv = &s.poppet[k];
            let (front, back) = if k == 0 {
                (y[P0], y[P1])
            } else {
                (y[P1], y[P0])
            };
            let net = front * pv.area_front
                - back * pv.area_back
                - pv.preload
                - pv.spring * y[xi]
                - pv.damping * y[ui]
                + Model::seat_force(y[xi], y[ui]);
            dy[xi] = y[ui];
            dy[ui] = net / pv.mass;
        }
        dy[IMPULSE] = f.measured;
        dy[SENSOR] = y[SENSOR_RATE];
        let sn = self.sensor;
        dy[SENSOR_RATE] =
            sn.omega_c * sn.omega_c * (d - y[SENSOR]) - 2.0 * sn.zeta * sn.omega_c * y[SENSOR_RATE];
        match &m.link {
            Some(l) => {
                dy[PISTON] = y[PISTON_RATE];
                dy[PISTON_RATE] = (f.hydraulic + f.seal + f.link) / l.mass;
            }
            None => {
                dy[PISTON] = 0.0;
                dy[PISTON_RATE] = 0.0;
            }
        }
        dy[SEAL] = m.seal.map_or(0.0, |sl| sl.rate(y[SEAL], v));
    }

    /// The damper at rest at t = 0: both chambers at p_s, poppets seated under their preload,
    /// the piston at static equilibrium behind its link, the sensor settled, the seal relaxed.
    pub fn initial(&self) -> State {
        let m = self.model;
        let s = &m.sheet;
        let mut y = [0.0; N];
        y[P0] = s.supply;
        y[P1] = s.supply;
        y[X0] = -m.seated_penetration(0);
        y[X1] = -m.seated_penetration(1);
        let (d, dd) = self.motion.at(0.0);
        y[SENSOR] = d;
        y[SENSOR_RATE] = dd;
        if let Some(l) = &m.link {
            let f_h = s.supply * (s.piston_area[0] - s.piston_area[1]);
            // deflection e with l.force(e, 0) = -f_h
            let e = match l.contact {
                Contact::Mount { stiffness, .. } => -f_h / stiffness,
                Contact::Gap { gap, stiffness, .. } => {
                    if f_h == 0.0 {
                        0.0
                    } else {
                        -f_h.signum() * (0.5 * gap + f_h.abs() / stiffness)
                    }
                }
            };
            y[PISTON] = d - e;
            y[PISTON_RATE] = dd;
        }
        y
    }
}

/// Integration tolerances: relative, and the absolute as this fraction of each state's
/// [`MAGNITUDE`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Tolerance {
    pub rtol: f64,
    pub atol: f64,
}

impl Default for Tolerance {
    fn default() -> Self {
        Self {
            rtol: 1e-8,
            atol: 1e-8,
        }
    }
}

#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct Stats {
    pub accepted: usize,
    pub rejected: usize,
    pub newton_failures: usize,
    pub rhs: usize,
}

/// Coefficients of the 3-stage Radau IIA method and of its embedded order-3 error estimate.
#[derive(Debug, Clone, Copy)]
pub struct RadauTableau {
    pub a: [[f64; 3]; 3],
    pub c: [f64; 3],
    /// A^-1.
    pub w: [[f64; 3]; 3],
    /// Real eigenvalue of A.
    pub gamma0: f64,
    /// `y_hat - y1 = gamma0 h f(t0, y0) + sum_j e_j z_j`.
    pub e: [f64; 3],
}

fn inv3(m: &[[f64; 3]; 3]) -> [[f64; 3]; 3] {
    let det = m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1])
        - m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0])
        + m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0]);
    let mut r = [[0.0; 3]; 3];
    for (i, row) in r.iter_mut().enumerate() {
        for (j, v) in row.iter_mut().enumerate() {
            // cofactor of (j, i)
            let (a0, a1) = ((j + 1) % 3, (j + 2) % 3);
            let (b0, b1) = ((i + 1) % 3, (i + 2) % 3);
            *v = (m[a0][b0] * m[a1][b1] - m[a0][b1] * m[a1][b0]) / det;
        }
    }
    r
}

impl RadauTableau {
    pub fn new() -> Self {
        let s6 = 6.0f64.sqrt();
        let a = [
            [
                (88.0 - 7.0 * s6) / 360.0,
                (296.0 - 169.0 * s6) / 1800.0,
                (-2.0 + 3.0 * s6) / 225.0,
            ],
            [
                (296.0 + 169.0 * s6) / 1800.0,
                (88.0 + 7.0 * s6) / 360.0,
                (-2.0 - 3.0 * s6) / 225.0,
            ],
            [(16.0 - s6) / 36.0, (16.0 + s6) / 36.0, 1.0 / 9.0],
        ];
        let c = [(4.0 - s6) / 10.0, (4.0 + s6) / 10.0, 1.0];
        let w = inv3(&a);
        // The real eigenvalue of A^-1 is 3 + 3^(2/3) - 3^(1/3).
        let gamma0 = 1.0 / (3.0 + 3.0f64.powf(2.0 / 3.0) - 3.0f64.cbrt());
        // Embedded order-3 weights with the extra node c = 0 weighted gamma0:
        // gamma0 + sum bh = 1, sum bh c = 1/2, sum bh c^2 = 1/3.
        let m = [
            [1.0, 1.0, 1.0],
            [c[0], c[1], c[2]],
            [c[0] * c[0], c[1] * c[1], c[2] * c[2]],
        ];
        let mi = inv3(&m);
        let rhs = [1.0 - gamma0, 0.5, 1.0 / 3.0];
        let mut bh = [0.0; 3];
        for (i, b) in bh.iter_mut().enumerate() {
            *b = (0..3).map(|j| mi[i][j] * rhs[j]).sum();
        }
        let b = a[2];
        let mut e = [0.0; 3];
        for (j, ej) in e.iter_mut().enumerate() {
            *ej = (0..3).map(|i| (bh[i] - b[i]) * w[i][j]).sum();
        }
        Self { a, c, w, gamma0, e }
    }
}

impl Default for RadauTableau {
    fn default() -> Self {
        Self::new()
    }
}

/// LU factorisation with partial pivoting of the n x n row-major matrix `a`, in place.
fn lu(a: &mut [f64], n: usize, piv: &mut [usize]) -> Result<(), String> {
    for k in 0..n {
        let mut p = k;
        for i in k + 1..n {
            if a[i * n + k].abs() > a[p * n + k].abs() {
                p = i;
            }
        }
        if a[p * n + k] == 0.0 || !a[p * n + k].is_finite() {
            return Err("singular Newton matrix".into());
        }
        piv[k] = p;
        if p != k {
            for j in 0..n {
                a.swap(k * n + j, p * n + j);
            }
        }
        let inv = 1.0 / a[k * n + k];
        for i in k + 1..n {
            let l = a[i * n + k] * inv;
            a[i * n + k] = l;
            if l != 0.0 {
                for j in k + 1..n {
                    a[i * n + j] -= l * a[k * n + j];
                }
            }
        }
    }
    Ok(())
}

fn lu_solve(a: &[f64], n: usize, piv: &[usize], b: &mut [f64]) {
    for (k, &p) in piv.iter().enumerate().take(n) {
        b.swap(k, p);
    }
    for i in 1..n {
        let s: f64 = (0..i).map(|j| a[i * n + j] * b[j]).sum();
        b[i] -= s;
    }
    for i in (0..n).rev() {
        let s: f64 = (i + 1..n).map(|j| a[i * n + j] * b[j]).sum();
        b[i] = (b[i] - s) / a[i * n + i];
    }
}

/// Adaptive Radau IIA integration of the bench.
pub struct Integrator<'a> {
    pub bench: Bench<'a>,
    pub tol: Tolerance,
    pub t: f64,
    pub y: State,
    h: f64,
    tab: RadauTableau,
    first: bool,
    pub stats: Stats,
}

const NEWTON_MAX: usize = 10;
const NEWTON_KAPPA: f64 = 0.01;

impl<'a> Integrator<'a> {
    pub fn new(bench: Bench<'a>, tol: Tolerance) -> Self {
        let y = bench.initial();
        Self {
            bench,
            tol,
            t: 0.0,
            y,
            h: 1e-6,
            tab: RadauTableau::new(),
            first: true,
            stats: Stats::default(),
        }
    }

    fn f(&mut self, t: f64, y: &State) -> State {
        let mut dy = [0.0; N];
        self.bench.rhs(t, y, &mut dy);
        self.stats.rhs += 1;
        dy
    }

    fn scale(&self, y0: &State, y1: &State) -> State {
        let mut s = [0.0; N];
        for k in 0..N {
            s[k] = self.tol.atol * MAGNITUDE[k] + self.tol.rtol * y0[k].abs().max(y1[k].abs());
        }
        s
    }

    /// Finite-difference Jacobian (row-major N x N) at (t, y) with f0 = f(t, y).
    fn jacobian(&mut self, t: f64, y: &State, f0: &State) -> Vec<f64> {
        let mut j = vec![0.0; N * N];
        for k in 0..N {
            let dk = 1.5e-8 * y[k].abs().max(1e-3 * MAGNITUDE[k]);
            let mut yp = *y;
            yp[k] += dk;
            let fp = self.f(t, &yp);
            for i in 0..N {
                j[i * N + k] = (fp[i] - f0[i]) / dk;
            }
        }
        j
    }

    /// One Radau IIA step of size h from (t, y): the new state and the scaled error norm, or
    /// None when the Newton iterations do not converge.
    fn try_step(
        &mut self,
        h: f64,
        f0: &State,
        jac: &[f64],
        retry: bool,
    ) -> Result<Option<(State, f64)>, String> {
        let tab = self.tab;
        let (t, y0) = (self.t, self.y);
        let n3 = 3 * N;
        let mut m = vec![0.0; n3 * n3];
        for bi in 0..3 {
            for bj in 0..3 {
                let hij = h * tab.a[bi][bj];
                for i in 0..N {
                    for k in 0..N {
                        let mut v = -hij * jac[i * N + k];
                        if bi == bj && i == k {
                            v += 1.0;
                        }
                        m[(bi * N + i) * n3 + bj * N + k] = v;
                    }
                }
            }
        }
        let mut piv = vec![0usize; n3];
        if lu(&mut m, n3, &mut piv).is_err() {
            return Ok(None);
        }
        let sc = self.scale(&y0, &y0);
        let mut z = vec![0.0; n3];
        let mut prev = f64::NAN;
        let mut converged = false;
        for it in 0..NEWTON_MAX {
            let mut fz = [[0.0; N]; 3];
            for (i, fi) in fz.iter_mut().enumerate() {
                let mut yi = y0;
                for k in 0..N {
                    yi[k] += z[i * N + k];
                }
                *fi = self.f(t + tab.c[i] * h, &yi);
            }
            let mut g = vec![0.0; n3];
            for i in 0..3 {
                for k in 0..N {
                    let af: f64 = (0..3).map(|j| tab.a[i][j] * fz[j][k]).sum();
                    g[i * N + k] = -(z[i * N + k] - h * af);
                }
            }
            lu_solve(&m, n3, &piv, &mut g);
            let mut norm = 0.0;
            for i in 0..3 {
                for k in 0..N {
                    z[i * N + k] += g[i * N + k];
                    norm += (g[i * N + k] / sc[k]).powi(2);
                }
            }
            let norm = (norm / n3 as f64).sqrt();
            if !norm.is_finite() {
                return Ok(None);
            }
            if it == 0 {
                if norm <= 1e-2 * NEWTON_KAPPA {
                    converged = true;
                    break;
                }
            } else {
                let theta = norm / prev;
                if theta >= 0.99 {
                    return Ok(None);
                }
                if theta / (1.0 - theta) * norm <= NEWTON_KAPPA || norm <= 1e-2 * NEWTON_KAPPA {
                    converged = true;
                    break;
                }
            }
            prev = norm;
        }
        if !converged {
            return Ok(None);
        }
        let mut y1 = y0;
        for k in 0..N {
            y1[k] += z[2 * N + k];
        }
        // error estimate
        let mut e1 = vec![0.0; N * N];
        for i in 0..N {
            for k in 0..N {
                e1[i * N + k] = -h * tab.gamma0 * jac[i * N + k] + if i == k { 1.0 } else { 0.0 };
            }
        }
        let mut piv1 = vec![0usize; N];
        if lu(&mut e1, N, &mut piv1).is_err() {
            return Ok(None);
        }
        let zsum: Vec<f64> = (0..N)
            .map(|k| (0..3).map(|j| tab.e[j] * z[j * N + k]).sum())
            .collect();
        let mut err: Vec<f64> = (0..N).map(|k| tab.gamma0 * h * f0[k] + zsum[k]).collect();
        lu_solve(&e1, N, &piv1, &mut err);
        let sc = self.scale(&y0, &y1);
        let norm =
            |err: &[f64]| ((0..N).map(|k| (err[k] / sc[k]).powi(2)).sum::<f64>() / N as f64).sqrt();
        let mut en = norm(&err);
        if en > 1.0 && (self.first || retry) {
            let mut yp = y0;
            for k in 0..N {
                yp[k] += err[k];
            }
            let fp = self.f(t, &yp);
            let mut err2: Vec<f64> = (0..N).map(|k| tab.gamma0 * h * fp[k] + zsum[k]).collect();
            lu_solve(&e1, N, &piv1, &mut err2);
            en = norm(&err2);
        }
        if !y1.iter().all(|v| v.is_finite()) {
            return Ok(None);
        }
        Ok(Some((y1, en)))
    }

    /// Advances to `t_end` exactly (steps chosen by the error estimate).
    pub fn advance(&mut self, t_end: f64) -> Result<(), String> {
        while self.t < t_end {
            let rem = t_end - self.t;
            if rem <= 1e-13 * t_end.abs().max(1.0) {
                // output times that differ in their last bits (a lag of whole samples)
                self.t = t_end;
                break;
            }
            let (mut h, truncated) = if self.h >= rem * 0.999 {
                (rem, true)
            } else {
                (self.h, false)
            };
            let f0 = self.f(self.t, &self.y.clone());
            let jac = self.jacobian(self.t, &self.y.clone(), &f0);
            let mut rejected = false;
            loop {
                if h < 1e-14 * self.t.abs().max(1e-3) {
                    return Err(format!("step size underflow at t = {}", self.t));
                }
                match self.try_step(h, &f0, &jac, rejected)? {
                    None => {
                        self.stats.newton_failures += 1;
                        h *= 0.3;
                        rejected = true;
                    }
                    Some((y1, err)) if err <= 1.0 => {
                        self.stats.accepted += 1;
                        let grow = if rejected { 1.0 } else { 5.0 };
                        let h_new = h * (0.9 * err.max(1e-10).powf(-0.25)).clamp(0.2, grow);
                        self.h = if truncated && !rejected {
                            self.h.max(h_new)
                        } else {
                            h_new
                        };
                        self.t = if h == rem { t_end } else { self.t + h };
                        self.y = y1;
                        self.first = false;
                        break;
                    }
                    Some((_, err)) => {
                        self.stats.rejected += 1;
                        h *= (0.9 * err.powf(-0.25)).clamp(0.1, 0.5);
                        rejected = true;
                    }
                }
            }
        }
        Ok(())
    }
}

/// What the bench records at the sample times `t` (ascending, from 0), samples every
/// `interval` seconds: the force averaged over `[t_k - lag - interval, t_k - lag]` (the force
/// channel delayed by `lag` >= 0, an acquisition fault; 0 for the convention alone) and the
/// sensor's stroke at t_k (before noise and quantisation). The damper rests at its initial
/// state before t = 0 (the motion ramps in from rest; without a ramp the rest force is taken
/// before 0 too).
pub fn record(
    model: &Model,
    motion: &Motion,
    sensor: Sensor,
    t: &[f64],
    interval: f64,
    lag: f64,
    tol: Tolerance,
) -> Result<(Vec<f64>, Vec<f64>), String> {
    let bench = Bench {
        model,
        motion,
        sensor,
    };
    let mut it = Integrator::new(bench, tol);
    let rest = it.bench.force(0.0, &it.y);
    let n = t.len();
    let (mut force, mut stroke) = (vec![f64::NAN; n], vec![f64::NAN; n]);
    // events: (time, 0 = stroke sample k, 1 = end of force window k)
    let mut ev: Vec<(f64, u8, usize)> = Vec::with_capacity(2 * n);
    for (k, &tk) in t.iter().enumerate() {
        ev.push((tk, 0, k));
        let tau = tk - lag;
        if tau > 0.0 {
            ev.push((tau, 1, k));
        } else {
            force[k] = rest;
        }
    }
    ev.sort_by(|a, b| a.0.total_cmp(&b.0).then(b.1.cmp(&a.1)));
    for (te, kind, k) in ev {
        if te > it.t {
            it.advance(te)?;
        }
        if kind == 0 {
            stroke[k] = it.y[SENSOR];
        } else {
            let before_zero = (interval - te).max(0.0);
            force[k] = (it.y[IMPULSE] + rest * before_zero) / interval;
            it.y[IMPULSE] = 0.0;
        }
    }
    Ok((force, stroke))
}

/// The instantaneous load-cell force at the times `t` (ascending, from 0), for the checks
/// against analytic limits and against the library (no averaging, no sensor).
pub fn force_at(
    model: &Model,
    motion: &Motion,
    t: &[f64],
    tol: Tolerance,
) -> Result<Vec<f64>, String> {
    let bench = Bench {
        model,
        motion,
        sensor: Sensor::butterworth(1e3),
    };
    let mut it = Integrator::new(bench, tol);
    let mut out = Vec::with_capacity(t.len());
    for &tk in t {
        if tk > it.t {
            it.advance(tk)?;
        }
        out.push(it.bench.force(it.t, &it.y));
    }
    Ok(out)
}
