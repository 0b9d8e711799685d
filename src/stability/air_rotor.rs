//! Air resonance: rigid blades on coincident lag and flap hinges (lag inboard of flap, the
//! elastomeric bearing's order) on a hub that moves with the airframe in x, y, roll and
//! pitch, with quasi-steady blade-element aerodynamics in hover.
//!
//! # Equations
//!
//! The equations are not written out by hand: the positions of the blade's mass and air
//! points are, and the rest follows from them. A point at `rho` from the hinge of blade `k`
//! (azimuth `psi = Omega t + 2 pi (k-1)/N`, lag `zeta` positive in the direction of rotation,
//! flap `beta` positive up) is, in the shaft frame,
//!
//! `r = e u(psi) + rho cos(beta) u(psi + zeta) + rho sin(beta) e_z`,
//! `u(a) = (cos a, sin a, 0)`,
//!
//! and in the fixed frame `p = p_h + R r` with the shaft's orientation `R = R_x(phi) R_y(theta)`
//! (roll `phi` about x, pitch `theta` about y, the rotor driven at constant `Omega` relative to
//! the airframe) and the hub at `p_h = x e_x + y e_y + (c_r - R_x c_r) + (c_p - R_y c_p)`
//! (each rotation about its centre `c = (0, 0, center_z)`). Velocities and accelerations are
//! the exact time derivatives of these (written out below); d'Alembert's principle gives the
//! generalized forces `sum_j J_j^T (m_j a_j - F_j)` with `J_j = dp_j/dq`, to which the hinge
//! springs and dampers and the airframe's masses, springs and dampers are added. The air
//! force `F_j` of a strip is [`blade_element`] of the air's velocity relative to the strip
//! (a uniform induced inflow `v_i` down, from momentum theory at the hover equilibrium and
//! then frozen: no dynamic inflow) in the section frame `R R_z(psi + zeta) R_y(-beta)
//! R_x(theta_j)`, `theta_j` the strip's pitch (collective and twist; no pitch-flap coupling).
//! Gravity and the sections' own rotary inertia are left out.
//!
//! The hover equilibrium (coning and lag angle of each blade, the hub at rest) is solved by
//! Newton; the equations are linearised about it by central differences. Each blade's
//! linearised matrices are trigonometric polynomials of degree 2 in its azimuth (its motion
//! seen from the hub is first harmonic, and so is the hub's seen from the blade); they are
//! sampled at [`AZIMUTH_SAMPLES`] azimuths and kept as Fourier series, which the Coleman
//! transformation and the Floquet integration evaluate at any time.
//!
//! Isotropic rotors (N >= 3): the multi-blade transformation of the periodic equations at
//! `t = 0` (constant coefficients in hover), eigenvalues in the fixed frame. Others: Floquet
//! multipliers over one revolution (RK4), matched to the mean isotropic rotor's Coleman
//! eigenvalues by the continuation of [`super::lag_rotor`].
use super::dampers::{coupled_step, BladeDamper, DeviceResponse, StepForces};
use super::labels::{self, Family};
use super::lag_rotor::{
    continued_modes, eigen_pairs, floquet_multipliers, nearest, need_blades, out_of_range,
    unit_cyclic, upper_modes, Mode, ModeLabel, Result, StabilityError,
};
use crate::aero::airfoil::{Airfoil, ClampCounts};
use crate::aero::section::{blade_element, Air};
use crate::solver::ode::{self, OdeRhs, Rk4};
use faer::{c64, Mat};
use std::f64::consts::PI;

/// Azimuth samples of a blade's linearised matrices (harmonics 0 to 3 kept; the matrices are
/// of degree 2, tests/stability_air.rs checks the series against a direct linearisation).
pub const AZIMUTH_SAMPLES: usize = 8;

/// Continuation stages of the Floquet labels from the mean rotor to a dissimilar one (the
/// lag rotor's).
pub use super::lag_rotor::CONTINUATION_STAGES;

/// Step of the linearisation's differences [rad, m, and per s, per s^2]: the fourth-order
/// stencil's truncation (step^4 against the trigonometric and aerodynamic scales, 0.1 rad
/// and 10 m/s at least) and roundoff (1e-16 / step of the residual) both below 1e-10.
const FD_STEP: f64 = 1e-4;

/// A spanwise strip of a blade: a point mass on the blade's axis and a blade element there.
#[derive(Clone, Debug, PartialEq)]
pub struct Strip {
    /// Distance from the hinge [m].
    pub rho_m: f64,
    pub mass_kg: f64,
    /// Span the element covers [m] (0: no air load).
    pub width_m: f64,
    pub chord_m: f64,
    /// Pitch of the section (collective and built-in twist) [rad].
    pub pitch_rad: f64,
    /// Tip loss: the lift's factor (0 outboard of B R).
    pub lift_factor: f64,
    /// Index into [`AirRotor::airfoils`].
    pub airfoil: usize,
}

/// One rigid blade on coincident lag and flap hinges.
#[derive(Clone, Debug, PartialEq)]
pub struct AirBlade {
    /// Hinge distance from the shaft [m].
    pub hinge_offset_m: f64,
    pub strips: Vec<Strip>,
    pub lag_stiffness_nm_per_rad: f64,
    pub lag_damping_nms_per_rad: f64,
    pub flap_stiffness_nm_per_rad: f64,
    pub flap_damping_nms_per_rad: f64,
}

impl AirBlade {
    /// Second moment of mass about the hinge [kg m^2] (flap and lag alike).
    pub fn inertia_kg_m2(&self) -> f64 {
        self.strips
            .iter()
            .map(|s| s.mass_kg * s.rho_m * s.rho_m)
            .sum()
    }
    /// First moment of mass about the hinge [kg m].
    pub fn first_moment_kg_m(&self) -> f64 {
        self.strips.iter().map(|s| s.mass_kg * s.rho_m).sum()
    }
    pub fn mass_kg(&self) -> f64 {
        self.strips.iter().map(|s| s.mass_kg).sum()
    }

    fn blend(&self, other: &AirBlade, s: f64) -> AirBlade {
        let mix = |a: f64, b: f64| a + s * (b - a);
        AirBlade {
            hinge_offset_m: mix(self.hinge_offset_m, other.hinge_offset_m),
            strips: self
                .strips
                .iter()
                .zip(&other.strips)
                .map(|(a, b)| Strip {
                    rho_m: mix(a.rho_m, b.rho_m),
                    mass_kg: mix(a.mass_kg, b.mass_kg),
                    width_m: mix(a.width_m, b.width_m),
                    chord_m: mix(a.chord_m, b.chord_m),
                    pitch_rad: mix(a.pitch_rad, b.pitch_rad),
                    lift_factor: mix(a.lift_factor, b.lift_factor),
                    airfoil: a.airfoil,
                })
                .collect(),
            lag_stiffness_nm_per_rad: mix(
                self.lag_stiffness_nm_per_rad,
                other.lag_stiffness_nm_per_rad,
            ),
            lag_damping_nms_per_rad: mix(
                self.lag_damping_nms_per_rad,
                other.lag_damping_nms_per_rad,
            ),
            flap_stiffness_nm_per_rad: mix(
                self.flap_stiffness_nm_per_rad,
                other.flap_stiffness_nm_per_rad,
            ),
            flap_damping_nms_per_rad: mix(
                self.flap_damping_nms_per_rad,
                other.flap_damping_nms_per_rad,
            ),
        }
    }
}

/// Which way an airframe coordinate moves the hub.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum BodyAxis {
    X,
    Y,
    /// About x, through a centre `center_z_m` above the hub.
    Roll,
    /// About y.
    Pitch,
}

/// One airframe coordinate at the hub: mass [kg] or inertia [kg m^2] (without the rotor),
/// spring and damper to ground.
#[derive(Clone, Debug, PartialEq)]
pub struct BodyDof {
    pub axis: BodyAxis,
    pub mass: f64,
    pub stiffness: f64,
    pub damping: f64,
    /// Rotations: height of the centre above the hub [m].
    pub center_z_m: f64,
}

/// Blades on a moving hub in hover.
#[derive(Clone, Debug)]
pub struct AirRotor {
    pub blades: Vec<AirBlade>,
    pub body: Vec<BodyDof>,
    pub air: Air,
    pub airfoils: Vec<Airfoil>,
    /// Rotor radius [m] (the momentum theory's disk).
    pub radius_m: f64,
}

/// The hover equilibrium at one rotor speed.
#[derive(Clone, Debug, PartialEq)]
pub struct Hover {
    pub omega_rad_s: f64,
    /// Each blade's lag and flap (coning) angle [rad].
    pub lag_rad: Vec<f64>,
    pub flap_rad: Vec<f64>,
    /// Rotor thrust [N] and the uniform induced velocity [m/s] (down).
    pub thrust_n: f64,
    pub inflow_m_s: f64,
}

/// A blade's linearised equations (its lag and flap, then its share of the airframe's) as
/// Fourier series in its azimuth: `[harmonic][cos, sin]` matrices, row-major `n x n`.
#[derive(Clone, Debug)]
pub struct BladeSeries {
    n: usize,
    /// `m, c, k` each `[h][0 = cos, 1 = sin][i * n + j]`.
    coef: [Vec<[Vec<f64>; 2]>; 3],
}

impl BladeSeries {
    /// Mass, damping and stiffness at azimuth `psi`, added into `out` (row-major `n x n`).
    fn eval_into(&self, psi: f64, out: [&mut [f64]; 3]) {
        for (mat, o) in out.into_iter().enumerate() {
            for (h, cs) in self.coef[mat].iter().enumerate() {
                let (s, c) = (h as f64 * psi).sin_cos();
                for i in 0..self.n * self.n {
                    o[i] += c * cs[0][i] + s * cs[1][i];
                }
            }
        }
    }
    /// The matrices at `psi`.
    pub fn at(&self, psi: f64) -> [Vec<f64>; 3] {
        let mut m = vec![0.0; self.n * self.n];
        let mut c = m.clone();
        let mut k = m.clone();
        self.eval_into(psi, [&mut m, &mut c, &mut k]);
        [m, c, k]
    }
}

fn u(a: f64) -> [f64; 3] {
    [a.cos(), a.sin(), 0.0]
}
fn w(a: f64) -> [f64; 3] {
    [-a.sin(), a.cos(), 0.0]
}
type M3 = [[f64; 3]; 3];
fn mv(m: &M3, v: [f64; 3]) -> [f64; 3] {
    [
        m[0][0] * v[0] + m[0][1] * v[1] + m[0][2] * v[2],
        m[1][0] * v[0] + m[1][1] * v[1] + m[1][2] * v[2],
        m[2][0] * v[0] + m[2][1] * v[1] + m[2][2] * v[2],
    ]
}
fn mtv(m: &M3, v: [f64; 3]) -> [f64; 3] {
    [
        m[0][0] * v[0] + m[1][0] * v[1] + m[2][0] * v[2],
        m[0][1] * v[0] + m[1][1] * v[1] + m[2][1] * v[2],
        m[0][2] * v[0] + m[1][2] * v[1] + m[2][2] * v[2],
    ]
}
fn mm(a: &M3, b: &M3) -> M3 {
    let mut r = [[0.0; 3]; 3];
    for i in 0..3 {
        for j in 0..3 {
            r[i][j] = a[i][0] * b[0][j] + a[i][1] * b[1][j] + a[i][2] * b[2][j];
        }
    }
    r
}
fn add(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[0] + b[0], a[1] + b[1], a[2] + b[2]]
}
fn scale(s: f64, a: [f64; 3]) -> [f64; 3] {
    [s * a[0], s * a[1], s * a[2]]
}
fn dot(a: [f64; 3], b: [f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}
fn madd(a: &M3, b: &M3, s: f64) -> M3 {
    let mut r = *a;
    for i in 0..3 {
        for j in 0..3 {
            r[i][j] += s * b[i][j];
        }
    }
    r
}
/// `R_x(a)` and its first and second derivatives in `a`.
fn rx(a: f64) -> [M3; 3] {
    let (s, c) = a.sin_cos();
    [
        [[1.0, 0.0, 0.0], [0.0, c, -s], [0.0, s, c]],
        [[0.0, 0.0, 0.0], [0.0, -s, -c], [0.0, c, -s]],
        [[0.0, 0.0, 0.0], [0.0, -c, s], [0.0, -s, -c]],
    ]
}
/// `R_y(a)` and its first and second derivatives in `a`.
fn ry(a: f64) -> [M3; 3] {
    let (s, c) = a.sin_cos();
    [
        [[c, 0.0, s], [0.0, 1.0, 0.0], [-s, 0.0, c]],
        [[-s, 0.0, c], [0.0, 0.0, 0.0], [-c, 0.0, -s]],
        [[-c, 0.0, -s], [0.0, 0.0, 0.0], [s, 0.0, -c]],
    ]
}
fn rz(a: f64) -> M3 {
    let (s, c) = a.sin_cos();
    [[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]]
}

impl AirRotor {
    /// Coordinates of one blade's local equations: lag, flap, then the airframe's.
    fn local_len(&self) -> usize {
        2 + self.body.len()
    }

    /// Coordinates of the whole rotor: `[zeta_1, ..., zeta_N, beta_1, ..., beta_N, airframe...]`.
    pub fn coordinate_count(&self) -> usize {
        2 * self.blades.len() + self.body.len()
    }

    pub fn validate(&self) -> Result<()> {
        let bad = |field: String, value: f64, ok: bool, expected: &'static str| {
            if ok && value.is_finite() {
                Ok(())
            } else {
                Err(out_of_range(field, value, expected))
            }
        };
        need_blades("the air-resonance rotor", self.blades.len(), 1)?;
        for (k, b) in self.blades.iter().enumerate() {
            let f = |n: &str| format!("blades[{k}].{n}");
            bad(
                f("hinge_offset_m"),
                b.hinge_offset_m,
                b.hinge_offset_m >= 0.0,
                ">= 0",
            )?;
            for (n, v) in [
                ("lag_stiffness_nm_per_rad", b.lag_stiffness_nm_per_rad),
                ("lag_damping_nms_per_rad", b.lag_damping_nms_per_rad),
                ("flap_stiffness_nm_per_rad", b.flap_stiffness_nm_per_rad),
                ("flap_damping_nms_per_rad", b.flap_damping_nms_per_rad),
            ] {
                bad(f(n), v, v >= 0.0, ">= 0")?;
            }
            bad(
                f("inertia_kg_m2"),
                b.inertia_kg_m2(),
                b.inertia_kg_m2() > 0.0,
                "> 0",
            )?;
            if b.strips.len() != self.blades[0].strips.len() {
                return Err(StabilityError::OutOfRange {
                    field: f("strips"),
                    value: b.strips.len() as f64,
                    expected: "as many strips as blade 1",
                });
            }
            for (j, s) in b.strips.iter().enumerate() {
                let g = |n: &str| format!("blades[{k}].strips[{j}].{n}");
                bad(g("rho_m"), s.rho_m, s.rho_m >= 0.0, ">= 0")?;
                bad(g("mass_kg"), s.mass_kg, s.mass_kg >= 0.0, ">= 0")?;
                bad(g("width_m"), s.width_m, s.width_m >= 0.0, ">= 0")?;
                bad(g("chord_m"), s.chord_m, s.chord_m >= 0.0, ">= 0")?;
                bad(g("pitch_rad"), s.pitch_rad, true, "finite")?;
                bad(
                    g("lift_factor"),
                    s.lift_factor,
                    s.lift_factor >= 0.0,
                    ">= 0",
                )?;
                if s.airfoil >= self.airfoils.len() && s.width_m > 0.0 {
                    return Err(StabilityError::OutOfRange {
                        field: g("airfoil"),
                        value: s.airfoil as f64,
                        expected: "an index into airfoils",
                    });
                }
            }
        }
        for (i, d) in self.body.iter().enumerate() {
            let f = |n: &str| format!("body[{i}].{n}");
            bad(f("mass"), d.mass, d.mass > 0.0, "> 0")?;
            bad(f("stiffness"), d.stiffness, d.stiffness >= 0.0, ">= 0")?;
            bad(f("damping"), d.damping, d.damping >= 0.0, ">= 0")?;
            bad(f("center_z_m"), d.center_z_m, true, "finite")?;
        }
        bad(
            "air.density_kg_m3".into(),
            self.air.density_kg_m3,
            self.air.density_kg_m3 >= 0.0,
            ">= 0",
        )?;
        bad("radius_m".into(), self.radius_m, self.radius_m > 0.0, "> 0")
    }

    /// One blade's local residual (lag, flap, and its generalized forces on the airframe
    /// coordinates, airframe springs excluded) at azimuth `psi`, induced velocity `vi` down,
    /// coordinates `z` (total angles), rates `zd` and accelerations `zdd`. Also returns the
    /// blade's vertical air force [N].
    #[allow(clippy::too_many_arguments)]
    fn residual(
        &self,
        b: &AirBlade,
        omega: f64,
        psi: f64,
        vi: f64,
        z: &[f64],
        zd: &[f64],
        zdd: &[f64],
        out: &mut [f64],
        clamps: &ClampCounts,
    ) -> f64 {
        let nl = self.local_len();
        out[..nl].iter_mut().for_each(|v| *v = 0.0);
        let (mut xd, mut yd, mut xdd, mut ydd) = (0.0, 0.0, 0.0, 0.0);
        let (mut ph, mut phd, mut phdd, mut th, mut thd, mut thdd) = (0.0, 0.0, 0.0, 0.0, 0.0, 0.0);
        let (mut cr, mut cp) = ([0.0; 3], [0.0; 3]);
        for (i, d) in self.body.iter().enumerate() {
            let (q, qd, qdd) = (z[2 + i], zd[2 + i], zdd[2 + i]);
            match d.axis {
                BodyAxis::X => (xd, xdd) = (qd, qdd),
                BodyAxis::Y => (yd, ydd) = (qd, qdd),
                BodyAxis::Roll => {
                    (ph, phd, phdd) = (q, qd, qdd);
                    cr = [0.0, 0.0, d.center_z_m];
                }
                BodyAxis::Pitch => {
                    (th, thd, thdd) = (q, qd, qdd);
                    cp = [0.0, 0.0, d.center_z_m];
                }
            }
        }
        let [rx0, rx1, rx2] = rx(ph);
        let [ry0, ry1, ry2] = ry(th);
        let r = mm(&rx0, &ry0);
        let rd = madd(
            &mm(&rx1, &ry0).map(|v| v.map(|e| e * phd)),
            &mm(&rx0, &ry1),
            thd,
        );
        let mut rdd = mm(&rx2, &ry0).map(|v| v.map(|e| e * phd * phd));
        rdd = madd(&rdd, &mm(&rx1, &ry0), phdd);
        rdd = madd(&rdd, &mm(&rx1, &ry1), 2.0 * phd * thd);
        rdd = madd(&rdd, &mm(&rx0, &ry2), thd * thd);
        rdd = madd(&rdd, &mm(&rx0, &ry1), thdd);
        let neg = |v: [f64; 3]| scale(-1.0, v);
        // the hub's position itself does not enter (no gravity): its rates do
        let pd_h = add(
            [xd, yd, 0.0],
            add(neg(scale(phd, mv(&rx1, cr))), neg(scale(thd, mv(&ry1, cp)))),
        );
        let pdd_h = add(
            [xdd, ydd, 0.0],
            add(
                neg(add(
                    scale(phd * phd, mv(&rx2, cr)),
                    scale(phdd, mv(&rx1, cr)),
                )),
                neg(add(
                    scale(thd * thd, mv(&ry2, cp)),
                    scale(thdd, mv(&ry1, cp)),
                )),
            ),
        );
        let (zeta, zetad, zetadd) = (z[0], zd[0], zdd[0]);
        let (beta, betad, betadd) = (z[1], zd[1], zdd[1]);
        let e = b.hinge_offset_m;
        let a1 = psi + zeta;
        let (a1d, a1dd) = (omega + zetad, zetadd);
        let (sb, cb) = beta.sin_cos();
        let (ua, wa) = (u(a1), w(a1));
        let ez = [0.0, 0.0, 1.0];
        let jz_b = wa; // times rho cos(beta)
        let jb_b = add(scale(-sb, ua), scale(cb, ez)); // times rho
        let rxp_ry = mm(&rx1, &ry0);
        let rx_ryp = mm(&rx0, &ry1);
        // the section frame without the strip's pitch
        let frame = mm(&mm(&r, &rz(a1)), &ry(-beta)[0]);
        let v_air = [0.0, 0.0, -vi];
        let mut vertical = 0.0;
        for s in &b.strips {
            let rho = s.rho_m;
            let rb = add(
                add(scale(e, u(psi)), scale(rho * cb, ua)),
                scale(rho * sb, ez),
            );
            let rbd = add(
                scale(e * omega, w(psi)),
                scale(
                    rho,
                    add(
                        add(scale(-sb * betad, ua), scale(cb * a1d, wa)),
                        scale(cb * betad, ez),
                    ),
                ),
            );
            let rbdd = add(
                scale(-e * omega * omega, u(psi)),
                scale(
                    rho,
                    add(
                        add(
                            scale(-cb * betad * betad - sb * betadd - cb * a1d * a1d, ua),
                            scale(-2.0 * sb * betad * a1d + cb * a1dd, wa),
                        ),
                        scale(-sb * betad * betad + cb * betadd, ez),
                    ),
                ),
            );
            let v = add(add(pd_h, mv(&rd, rb)), mv(&r, rbd));
            let a = add(
                add(pdd_h, mv(&rdd, rb)),
                add(scale(2.0, mv(&rd, rbd)), mv(&r, rbdd)),
            );
            let mut f = scale(s.mass_kg, a);
            if s.width_m > 0.0 && s.chord_m > 0.0 && self.air.density_kg_m3 > 0.0 {
                let sec = mm(&frame, &rx(s.pitch_rad)[0]);
                let rel = mtv(&sec, add(v_air, neg(v)));
                let el = blade_element(
                    rel,
                    s.chord_m,
                    &self.air,
                    &self.airfoils[s.airfoil],
                    clamps,
                    s.lift_factor,
                );
                let fa = scale(s.width_m, mv(&sec, el.force_n_per_m));
                vertical += fa[2];
                f = add(f, neg(fa));
            }
            out[0] += dot(mv(&r, scale(rho * cb, jz_b)), f);
            out[1] += dot(mv(&r, scale(rho, jb_b)), f);
            for (i, d) in self.body.iter().enumerate() {
                let j = match d.axis {
                    BodyAxis::X => [1.0, 0.0, 0.0],
                    BodyAxis::Y => [0.0, 1.0, 0.0],
                    BodyAxis::Roll => add(mv(&rxp_ry, rb), neg(mv(&rx1, cr))),
                    BodyAxis::Pitch => add(mv(&rx_ryp, rb), neg(mv(&ry1, cp))),
                };
                out[2 + i] += dot(j, f);
            }
        }
        out[0] += b.lag_stiffness_nm_per_rad * zeta + b.lag_damping_nms_per_rad * zetad;
        out[1] += b.flap_stiffness_nm_per_rad * beta + b.flap_damping_nms_per_rad * betad;
        vertical
    }

    /// Lag and flap of blade `b` in hover with the hub at rest (Newton, central-difference
    /// Jacobian) and its vertical air force.
    fn blade_equilibrium(&self, b: &AirBlade, omega: f64, vi: f64) -> Result<(f64, f64, f64)> {
        let nl = self.local_len();
        let clamps = ClampCounts::default();
        let zero = vec![0.0; nl];
        let mut z = vec![0.0; nl];
        let mut r = vec![0.0; nl];
        let mut rp = vec![0.0; nl];
        let mut rm = vec![0.0; nl];
        let scale_m = b.inertia_kg_m2() * omega * omega;
        for _ in 0..60 {
            self.residual(b, omega, 0.0, vi, &z, &zero, &zero, &mut r, &clamps);
            let mut jac = [[0.0; 2]; 2];
            for c in 0..2 {
                let mut zp = z.clone();
                zp[c] += FD_STEP;
                self.residual(b, omega, 0.0, vi, &zp, &zero, &zero, &mut rp, &clamps);
                zp[c] -= 2.0 * FD_STEP;
                self.residual(b, omega, 0.0, vi, &zp, &zero, &zero, &mut rm, &clamps);
                for row in 0..2 {
                    jac[row][c] = (rp[row] - rm[row]) / (2.0 * FD_STEP);
                }
            }
            let det = jac[0][0] * jac[1][1] - jac[0][1] * jac[1][0];
            if det == 0.0 || !det.is_finite() {
                return Err(StabilityError::Numerical(format!(
                    "hover equilibrium at {omega} rad/s: singular Jacobian"
                )));
            }
            let d0 = (jac[1][1] * r[0] - jac[0][1] * r[1]) / det;
            let d1 = (-jac[1][0] * r[0] + jac[0][0] * r[1]) / det;
            z[0] -= d0;
            z[1] -= d1;
            if d0.abs().max(d1.abs()) < 1e-13 && r[0].abs().max(r[1].abs()) < 1e-9 * scale_m {
                let t = self.residual(b, omega, 0.0, vi, &z, &zero, &zero, &mut r, &clamps);
                return Ok((z[0], z[1], t));
            }
        }
        Err(StabilityError::Numerical(format!(
            "hover equilibrium at {omega} rad/s: Newton did not converge in 60 iterations (residual {:.3e}, {:.3e} N m)",
            r[0], r[1]
        )))
    }

    /// The hover equilibrium at `omega`: each blade's lag and coning, the thrust, and the
    /// uniform induced velocity of momentum theory `v_i = sqrt(T / (2 rho pi R^2))` (secant
    /// iteration between the two, to 1e-12 relative).
    pub fn hover(&self, omega_rad_s: f64) -> Result<Hover> {
        self.validate()?;
        super::lag_rotor::check_omega(omega_rad_s)?;
        let area = PI * self.radius_m * self.radius_m;
        let rho = self.air.density_kg_m3;
        // the blades' equilibrium at induced velocity vi, and momentum theory's vi for its thrust
        let eval = |vi: f64| -> Result<(Hover, f64)> {
            let mut lag = Vec::with_capacity(self.blades.len());
            let mut flap = Vec::with_capacity(self.blades.len());
            let mut thrust = 0.0;
            for b in &self.blades {
                let (z, bt, t) = self.blade_equilibrium(b, omega_rad_s, vi)?;
                lag.push(z);
                flap.push(bt);
                thrust += t;
            }
            let next = if rho > 0.0 && thrust > 0.0 {
                (thrust / (2.0 * rho * area)).sqrt()
            } else {
                0.0
            };
            let h = Hover {
                omega_rad_s,
                lag_rad: lag,
                flap_rad: flap,
                thrust_n: thrust,
                inflow_m_s: vi,
            };
            Ok((h, next))
        };
        // secant on g(vi) = momentum(vi) - vi, from the fixed point's first step
        let (mut h0, n0) = eval(0.0)?;
        let (mut v0, mut g0) = (0.0, n0);
        let mut v1 = n0;
        for _ in 0..60 {
            let (h1, n1) = eval(v1)?;
            let g1 = n1 - v1;
            if g1.abs() <= 1e-12 * (1.0 + n1) {
                return Ok(h1);
            }
            let slope = (g1 - g0) / (v1 - v0);
            let step = if slope.is_finite() && slope != 0.0 {
                -g1 / slope
            } else {
                g1
            };
            (v0, g0, h0) = (v1, g1, h1);
            v1 = (v1 + step).max(0.0);
        }
        Err(StabilityError::Numerical(format!(
            "hover inflow at {omega_rad_s} rad/s: momentum theory did not converge in 60 secant steps (thrust {:.1} N, induced velocity {:.4} m/s, momentum's {:.4} m/s)",
            h0.thrust_n,
            v0,
            v0 + g0
        )))
    }

    /// Blade `k`'s linearised equations about the hover `h` at azimuth `psi`: mass, damping,
    /// stiffness (row-major, [`Self::local_len`] square), by central differences.
    pub fn linearise_blade(&self, k: usize, h: &Hover, psi: f64) -> [Vec<f64>; 3] {
        let b = &self.blades[k];
        let nl = self.local_len();
        let clamps = ClampCounts::default();
        let mut z0 = vec![0.0; nl];
        z0[0] = h.lag_rad[k];
        z0[1] = h.flap_rad[k];
        let zero = vec![0.0; nl];
        let mut out = [vec![0.0; nl * nl], vec![0.0; nl * nl], vec![0.0; nl * nl]];
        let mut r = vec![0.0; nl];
        for which in 0..3 {
            for c in 0..nl {
                // fourth-order central differences: the residual sums hundreds of strips'
                // forces of size I Omega^2, whose roundoff a second-order step would amplify
                for (shift, wgt) in [(2.0, -1.0), (1.0, 8.0), (-1.0, -8.0), (-2.0, 1.0)] {
                    let mut vals = [z0.clone(), zero.clone(), zero.clone()];
                    vals[which][c] += shift * FD_STEP;
                    self.residual(
                        b,
                        h.omega_rad_s,
                        psi,
                        h.inflow_m_s,
                        &vals[0],
                        &vals[1],
                        &vals[2],
                        &mut r,
                        &clamps,
                    );
                    for row in 0..nl {
                        out[2 - which][row * nl + c] += wgt * r[row] / (12.0 * FD_STEP);
                    }
                }
            }
        }
        out
    }

    /// Blade `k`'s linearised equations as Fourier series in its azimuth.
    pub fn blade_series(&self, k: usize, h: &Hover) -> BladeSeries {
        let nl = self.local_len();
        let ns = AZIMUTH_SAMPLES;
        let hmax = ns / 2 - 1;
        let samples: Vec<[Vec<f64>; 3]> = (0..ns)
            .map(|s| self.linearise_blade(k, h, 2.0 * PI * s as f64 / ns as f64))
            .collect();
        let coef = std::array::from_fn(|mat| {
            (0..=hmax)
                .map(|hh| {
                    let mut cs = [vec![0.0; nl * nl], vec![0.0; nl * nl]];
                    let f = if hh == 0 { 1.0 } else { 2.0 } / ns as f64;
                    for (s, smp) in samples.iter().enumerate() {
                        let a = hh as f64 * 2.0 * PI * s as f64 / ns as f64;
                        for i in 0..nl * nl {
                            cs[0][i] += f * a.cos() * smp[mat][i];
                            cs[1][i] += f * a.sin() * smp[mat][i];
                        }
                    }
                    cs
                })
                .collect()
        });
        BladeSeries { n: nl, coef }
    }

    /// The whole rotor's linearised periodic equations at time `t` (blade 1 at azimuth
    /// `Omega t`): mass, damping, stiffness as `n x n` matrices.
    pub fn matrices_at(&self, series: &[BladeSeries], omega: f64, t: f64) -> [Mat<f64>; 3] {
        let n = self.coordinate_count();
        let nb = self.blades.len();
        let nl = self.local_len();
        let mut out = [Mat::<f64>::zeros(n, n), Mat::zeros(n, n), Mat::zeros(n, n)];
        let map = |k: usize, i: usize| if i < 2 { i * nb + k } else { 2 * nb + i - 2 };
        let mut buf = [vec![0.0; nl * nl], vec![0.0; nl * nl], vec![0.0; nl * nl]];
        for (k, s) in series.iter().enumerate() {
            buf.iter_mut()
                .for_each(|b| b.iter_mut().for_each(|v| *v = 0.0));
            let psi = omega * t + 2.0 * PI * k as f64 / nb as f64;
            let [b0, b1, b2] = &mut buf;
            s.eval_into(psi, [b0, b1, b2]);
            for (mat, b) in buf.iter().enumerate() {
                for i in 0..nl {
                    for j in 0..nl {
                        out[mat][(map(k, i), map(k, j))] += b[i * nl + j];
                    }
                }
            }
        }
        for (i, d) in self.body.iter().enumerate() {
            let ii = 2 * nb + i;
            out[0][(ii, ii)] += d.mass;
            out[1][(ii, ii)] += d.damping;
            out[2][(ii, ii)] += d.stiffness;
        }
        out
    }

    /// Whether every blade is the same (the Coleman transformation applies).
    pub fn is_isotropic(&self) -> bool {
        self.blades.iter().all(|b| *b == self.blades[0])
    }

    /// Each blade's series about the hover `h`.
    fn all_series(&self, h: &Hover) -> Vec<BladeSeries> {
        if self.is_isotropic() {
            let s = self.blade_series(0, h);
            vec![s; self.blades.len()]
        } else {
            (0..self.blades.len())
                .map(|k| self.blade_series(k, h))
                .collect()
        }
    }

    /// The multi-blade transformation `q = T(t) m` and its time derivatives, for blade
    /// coordinates `[zeta_1..N, beta_1..N]` and multi-blade ones `[zeta_0, zeta_1c, zeta_1s, ...,
    /// zeta_d, beta_0, ...]` (the airframe's unchanged).
    fn mbc(&self, omega: f64, t: f64) -> [Mat<f64>; 3] {
        let nb = self.blades.len();
        let n = self.coordinate_count();
        let mut out = [Mat::<f64>::zeros(n, n), Mat::zeros(n, n), Mat::zeros(n, n)];
        for k in 0..nb {
            let psi = omega * t + 2.0 * PI * k as f64 / nb as f64;
            for d in 0..2 {
                let row = d * nb + k;
                for c in 0..nb {
                    let col = d * nb + c;
                    let (v, vd, vdd) = if c == 0 {
                        (1.0, 0.0, 0.0)
                    } else if nb.is_multiple_of(2) && c == nb - 1 {
                        (if k % 2 == 0 { 1.0 } else { -1.0 }, 0.0, 0.0)
                    } else {
                        let h = c.div_ceil(2) as f64;
                        let (s, co) = (h * psi).sin_cos();
                        let hw = h * omega;
                        if c % 2 == 1 {
                            (co, -hw * s, -hw * hw * co)
                        } else {
                            (s, hw * co, -hw * hw * s)
                        }
                    };
                    out[0][(row, col)] = v;
                    out[1][(row, col)] = vd;
                    out[2][(row, col)] = vdd;
                }
            }
        }
        for i in 2 * nb..n {
            out[0][(i, i)] = 1.0;
        }
        out
    }

    /// The constant-coefficient equations in multi-blade coordinates (isotropic rotor,
    /// N >= 3) at time `t`: mass, damping, stiffness.
    pub fn coleman_matrices(&self, h: &Hover, t: f64) -> Result<[Mat<f64>; 3]> {
        use faer::linalg::solvers::Solve;
        let series = self.all_series(h);
        let [m, c, k] = self.matrices_at(&series, h.omega_rad_s, t);
        let [tt, td, tdd] = self.mbc(h.omega_rad_s, t);
        let lu = tt.partial_piv_lu();
        let mm = lu.solve(&m * &tt);
        let cm = lu.solve(&m * &td * 2.0 + &c * &tt);
        let km = lu.solve(&m * &tdd + &c * &td + &k * &tt);
        Ok([mm, cm, km])
    }

    /// Kinetic-energy weights of the multi-blade coordinates (cyclic `N/2 I`, collective and
    /// differential `N I`, the airframe's its diagonal mass).
    fn weights(&self, mm: &Mat<f64>) -> Vec<f64> {
        let nb = self.blades.len();
        let i_b = self.blades[0].inertia_kg_m2();
        (0..self.coordinate_count())
            .map(|i| {
                if i < 2 * nb {
                    let c = i % nb;
                    let cyclic = c != 0 && !(nb.is_multiple_of(2) && c == nb - 1);
                    if cyclic {
                        nb as f64 / 2.0 * i_b
                    } else {
                        nb as f64 * i_b
                    }
                } else {
                    mm[(i, i)]
                }
            })
            .collect()
    }

    /// The families of the multi-blade coordinates `group` (solved together), each with as
    /// many slots as coordinates it stands for: collective, cyclic (one regressing and one
    /// progressive per cyclic pair), differential and higher cyclic ("differential"), lag then
    /// flap, and the airframe's degrees of freedom.
    fn families(&self, group: &[usize]) -> Vec<Family> {
        let nb = self.blades.len();
        let mut out: Vec<Family> = vec![];
        let mut add = |label: ModeLabel, n: usize| {
            if n == 0 {
                return;
            }
            match out.iter_mut().find(|f| f.label == label) {
                Some(f) => f.slots += n,
                None => out.push(Family { label, slots: n }),
            }
        };
        for d in 0..2 {
            let has = |c: usize| group.contains(&(d * nb + c));
            let [collective, regressing, progressive, reactionless] = Self::blade_families(d);
            add(collective, usize::from(has(0)));
            let cyclic = usize::from(has(1)) + usize::from(has(2));
            add(regressing, cyclic / 2);
            add(progressive, cyclic / 2);
            add(reactionless, (3..nb).filter(|&c| has(c)).count());
        }
        for (i, dof) in self.body.iter().enumerate() {
            add(
                Self::body_family(dof.axis),
                usize::from(group.contains(&(2 * nb + i))),
            );
        }
        out
    }

    /// (collective, regressing, progressive, differential) of the lag (`d = 0`) or the flap.
    fn blade_families(d: usize) -> [ModeLabel; 4] {
        if d == 0 {
            [
                ModeLabel::CollectiveLag,
                ModeLabel::RegressingLag,
                ModeLabel::ProgressiveLag,
                ModeLabel::DifferentialLag,
            ]
        } else {
            [
                ModeLabel::CollectiveFlap,
                ModeLabel::RegressingFlap,
                ModeLabel::ProgressiveFlap,
                ModeLabel::DifferentialFlap,
            ]
        }
    }

    fn body_family(axis: BodyAxis) -> ModeLabel {
        match axis {
            BodyAxis::X => ModeLabel::AirframeX,
            BodyAxis::Y => ModeLabel::AirframeY,
            BodyAxis::Roll => ModeLabel::AirframeRoll,
            BodyAxis::Pitch => ModeLabel::AirframePitch,
        }
    }

    /// The share of the eigenvector `v` (multi-blade coordinates, eigenvalue `lam`) in each of
    /// `families`, from the kinetic energy of its groups (cyclic lag and flap split into
    /// regressing and progressive by the whirl rule of
    /// [`super::LagRotor::coleman_eigenvalues`]).
    fn shares(
        &self,
        lam: c64,
        v: &[c64],
        weight: &[f64],
        omega: f64,
        families: &[Family],
    ) -> Vec<f64> {
        let nb = self.blades.len();
        let e = |i: usize| weight[i] * v[i].norm() * v[i].norm();
        let mut energy = vec![0.0; families.len()];
        let mut offer = |label: ModeLabel, x: f64| {
            if let Some(f) = families.iter().position(|f| f.label == label) {
                energy[f] += x;
            }
        };
        for d in 0..2 {
            let base = d * nb;
            let [collective, regressing, progressive, reactionless] = Self::blade_families(d);
            offer(collective, e(base));
            let (zc, zs) = if lam.im >= 0.0 {
                (v[base + 1], v[base + 2])
            } else {
                (v[base + 1].conj(), v[base + 2].conj())
            };
            let (reg, pro) = labels::whirl_split(lam, zc, zs, omega, e(base + 1) + e(base + 2));
            offer(regressing, reg);
            offer(progressive, pro);
            offer(reactionless, (3..nb).map(|c| e(base + c)).sum());
        }
        for (i, dof) in self.body.iter().enumerate() {
            offer(Self::body_family(dof.axis), e(2 * nb + i));
        }
        labels::shares(&energy)
    }

    /// All Coleman eigenvalues (conjugates included) with their labels, about the hover `h`.
    fn coleman_all(&self, h: &Hover) -> Result<Vec<(c64, ModeLabel)>> {
        let nb = self.blades.len();
        need_blades("the Coleman transformation", nb, 3)?;
        if !self.is_isotropic() {
            return Err(StabilityError::Numerical(
                "the Coleman transformation needs identical blades (use Floquet)".into(),
            ));
        }
        let [mm, cm, km] = self.coleman_matrices(h, 0.0)?;
        let weight = self.weights(&mm);
        let n = self.coordinate_count();
        // Groups that do not couple in hover: the collective coordinates, the differential
        // ones (N even), each higher cyclic pair, and the first cyclic with the airframe.
        // Solved apart so that a double root (collective and differential) keeps its labels.
        let mut groups: Vec<Vec<usize>> = vec![vec![0, nb]];
        if nb.is_multiple_of(2) {
            groups.push(vec![nb - 1, 2 * nb - 1]);
        }
        for hh in 2..=(nb - 1) / 2 {
            let (c, s) = (2 * hh - 1, 2 * hh);
            groups.push(vec![c, s, nb + c, nb + s]);
        }
        let mut coupled = vec![1, 2, nb + 1, nb + 2];
        coupled.extend(2 * nb..n);
        groups.push(coupled);
        let group_of = |i: usize| groups.iter().position(|g| g.contains(&i)).unwrap();
        let big = [&mm, &cm, &km].map(|m| {
            (0..n)
                .flat_map(|i| (0..n).map(move |j| (i, j)))
                .fold(0.0f64, |a, (i, j)| a.max(m[(i, j)].abs()))
        });
        let separable = [&mm, &cm, &km].iter().zip(big).all(|(m, b)| {
            (0..n)
                .all(|i| (0..n).all(|j| group_of(i) == group_of(j) || m[(i, j)].abs() <= 1e-9 * b))
        });
        if !separable {
            groups = vec![(0..n).collect()];
        }
        let mut out = Vec::with_capacity(2 * n);
        for g in &groups {
            let sub = |m: &Mat<f64>| Mat::<f64>::from_fn(g.len(), g.len(), |i, j| m[(g[i], g[j])]);
            let (lams, vecs) = eigen_pairs(&sub(&mm), &sub(&cm), &sub(&km))?;
            let families = self.families(g);
            let shares: Vec<Vec<f64>> = lams
                .iter()
                .enumerate()
                .map(|(j, &l)| {
                    let mut v = vec![c64::new(0.0, 0.0); n];
                    for (i, &gi) in g.iter().enumerate() {
                        v[gi] = vecs[(i, j)];
                    }
                    self.shares(l, &v, &weight, h.omega_rad_s, &families)
                })
                .collect();
            let labels = labels::assign(&lams, &shares, &families);
            out.extend(lams.iter().copied().zip(labels));
        }
        Ok(out)
    }

    /// Constant-coefficient eigenvalues in multi-blade coordinates about the hover at
    /// `omega_rad_s` (isotropic rotor, N >= 3), one per conjugate pair, by frequency.
    pub fn coleman_eigenvalues(&self, omega_rad_s: f64) -> Result<(Hover, Vec<Mode>)> {
        let h = self.hover(omega_rad_s)?;
        let modes = upper_modes(self.coleman_all(&h)?);
        Ok((h, modes))
    }

    /// A state `[q, q']` (blade 1 at zero azimuth) on the least damped Coleman mode labelled
    /// `label` of this isotropic rotor about the hover `h`, scaled to a cyclic lag amplitude of
    /// 1 rad ([`super::cyclic_amplitude`]).
    pub fn mode_state(&self, h: &Hover, label: ModeLabel) -> Result<Vec<f64>> {
        let all = self.coleman_all(h)?;
        let target = all
            .iter()
            .filter(|(l, lb)| *lb == label && l.im >= 0.0)
            .max_by(|a, b| a.0.re.total_cmp(&b.0.re))
            .ok_or_else(|| StabilityError::Numerical(format!("no {label} mode")))?
            .0;
        let [mm, cm, km] = self.coleman_matrices(h, 0.0)?;
        let (lams, u) = eigen_pairs(&mm, &cm, &km)?;
        let j = nearest(&lams, target)
            .ok_or_else(|| StabilityError::Numerical("no Coleman eigenvalue".into()))?;
        let lam = lams[j];
        let n = self.coordinate_count();
        let [tt, td, _] = self.mbc(h.omega_rad_s, 0.0);
        let m: Vec<f64> = (0..n).map(|i| u[(i, j)].re).collect();
        let md: Vec<f64> = (0..n).map(|i| (lam * u[(i, j)]).re).collect();
        let mut z = vec![0.0; 2 * n];
        for i in 0..n {
            for c in 0..n {
                z[i] += tt[(i, c)] * m[c];
                z[n + i] += td[(i, c)] * m[c] + tt[(i, c)] * md[c];
            }
        }
        unit_cyclic(z, self.blades.len(), h.omega_rad_s, lam.im.abs(), label)
    }

    /// Free response of the linearised equations about the hover `h` with `dampers[k]` on
    /// blade `k` (its lag spring and damper in `self` without the damper), from `initial`
    /// (`[q, q']`, blade 1 at zero azimuth), RK4 at `steps_per_rev` steps per revolution
    /// until `t_end_s` is reached (the last step ends at or just after it). The damper sees the
    /// lag perturbation's stroke `arm * zeta`; over a step its moment is its time-averaged
    /// force held constant, solved by the fixed point of [`super::free_response_with_dampers`].
    /// `stop_lag_rad`: the response ends once a blade's lag perturbation exceeds it. The
    /// equations' operators at the revolution's half steps are computed once, so the steps do
    /// not allocate (beyond the history they return).
    #[allow(clippy::too_many_arguments)]
    pub fn response_with_dampers(
        &self,
        h: &Hover,
        dampers: &mut [BladeDamper],
        initial: &[f64],
        t_end_s: f64,
        steps_per_rev: usize,
        stop_lag_rad: f64,
    ) -> Result<DeviceResponse> {
        use faer::linalg::solvers::Solve;
        let nb = self.blades.len();
        let n = self.coordinate_count();
        let m2 = 2 * n;
        if dampers.len() != nb || initial.len() != m2 {
            return Err(StabilityError::Numerical(format!(
                "{} dampers and {} states for {nb} blades and {m2} states",
                dampers.len(),
                initial.len()
            )));
        }
        let omega = h.omega_rad_s;
        let hh = 2.0 * PI / omega / steps_per_rev.max(1) as f64;
        let steps_f = (t_end_s / hh).ceil();
        if !((16..=1_000_000).contains(&steps_per_rev) && t_end_s >= 0.0 && steps_f <= 1e7) {
            return Err(StabilityError::OutOfRange {
                field: "t_end_s, steps_per_rev".into(),
                value: steps_f,
                expected: "16 ..= 10^6 steps per revolution, at most 10^7 steps",
            });
        }
        let steps = steps_f as usize;
        let series = self.all_series(h);
        // at the revolution's half steps: -M^-1 K, -M^-1 C and M^-1 on the lag coordinates
        let e = Mat::<f64>::from_fn(n, nb, |i, j| f64::from(u8::from(i == j)));
        let mut table = Vec::with_capacity(2 * steps_per_rev);
        for i in 0..2 * steps_per_rev {
            let t = 0.5 * hh * i as f64;
            let [m, c, k] = self.matrices_at(&series, omega, t);
            let lu = m.partial_piv_lu();
            let (a, b, g) = (lu.solve(&k), lu.solve(&c), lu.solve(&e));
            if (0..n).any(|i| (0..n).any(|j| !a[(i, j)].is_finite() || !b[(i, j)].is_finite())) {
                return Err(StabilityError::Numerical(format!(
                    "singular mass matrix at t = {t} s"
                )));
            }
            table.push((a, b, g));
        }
        let mut sys = Tabulated {
            table: &table,
            half_step: 0.5 * hh,
            at: 0,
            n,
            moment: vec![0.0; nb],
        };
        let mut rk = Rk4::new(m2);
        let mut y = initial.to_vec();
        let mut trial = vec![0.0; m2];
        let mut forces = StepForces::new(dampers);
        let mut time_s = Vec::with_capacity(steps + 1);
        let mut states = Vec::with_capacity((steps + 1) * m2);
        time_s.push(0.0);
        states.extend_from_slice(&y);
        let mut force_n = Vec::with_capacity(steps * nb);
        let mut max_iterations = 0;
        for step in 0..steps {
            let t = step as f64 * hh;
            let it = coupled_step(
                dampers,
                &mut forces,
                step == 0,
                t,
                hh,
                &y,
                &mut trial,
                |moment, trial| {
                    sys.moment.copy_from_slice(moment);
                    trial.copy_from_slice(&y);
                    rk.step(&mut sys, t, hh, trial)
                },
            )?;
            max_iterations = max_iterations.max(it);
            y.copy_from_slice(&trial);
            force_n.extend_from_slice(&forces.mean);
            time_s.push(t + hh);
            states.extend_from_slice(&y);
            if y[..nb].iter().any(|z| z.abs() > stop_lag_rad) {
                break;
            }
        }
        Ok(DeviceResponse {
            response: super::TimeResponse {
                time_s,
                states,
                state_len: m2,
            },
            force_n,
            max_iterations,
        })
    }

    /// The monodromy matrix over one revolution about the hover `h` (RK4, column-major
    /// `2n x 2n`, state `[q, q']`).
    pub fn monodromy(&self, h: &Hover, steps_per_rev: usize) -> Result<Vec<f64>> {
        let series = self.all_series(h);
        let omega = h.omega_rad_s;
        let n = self.coordinate_count();
        let mut sys = StateMatrix {
            rotor: self,
            series: &series,
            omega,
            a: Mat::zeros(2 * n, 2 * n),
        };
        ode::monodromy(&mut sys, 2 * n, 2.0 * PI / omega, steps_per_rev)
    }

    fn multipliers(&self, h: &Hover, steps_per_rev: usize) -> Result<Vec<c64>> {
        let phi = self.monodromy(h, steps_per_rev)?;
        floquet_multipliers(&phi, 2 * self.coordinate_count())
    }

    /// The isotropic rotor with each blade the mean of the blades, and the blend `mean + s
    /// (actual - mean)`.
    pub fn blend_to_mean(&self, s: f64) -> AirRotor {
        let nb = self.blades.len() as f64;
        let b0 = &self.blades[0];
        let mut mean = b0.clone();
        let sum = |f: &dyn Fn(&AirBlade) -> f64| self.blades.iter().map(f).sum::<f64>() / nb;
        mean.hinge_offset_m = sum(&|b| b.hinge_offset_m);
        mean.lag_stiffness_nm_per_rad = sum(&|b| b.lag_stiffness_nm_per_rad);
        mean.lag_damping_nms_per_rad = sum(&|b| b.lag_damping_nms_per_rad);
        mean.flap_stiffness_nm_per_rad = sum(&|b| b.flap_stiffness_nm_per_rad);
        mean.flap_damping_nms_per_rad = sum(&|b| b.flap_damping_nms_per_rad);
        for (j, st) in mean.strips.iter_mut().enumerate() {
            st.rho_m = sum(&|b| b.strips[j].rho_m);
            st.mass_kg = sum(&|b| b.strips[j].mass_kg);
            st.width_m = sum(&|b| b.strips[j].width_m);
            st.chord_m = sum(&|b| b.strips[j].chord_m);
            st.pitch_rad = sum(&|b| b.strips[j].pitch_rad);
            st.lift_factor = sum(&|b| b.strips[j].lift_factor);
        }
        let mut r = self.clone();
        r.blades = self.blades.iter().map(|b| mean.blend(b, s)).collect();
        r
    }

    /// Floquet modes about the hover at `omega_rad_s` (any rotor with N >= 3): multipliers
    /// of the monodromy matrix, each matched to the mean rotor's Coleman mode by continuation
    /// in [`CONTINUATION_STAGES`] stages; the frequency is the one nearest the matched
    /// Coleman frequency among those the multiplier allows (multiples of `Omega` apart).
    pub fn floquet(&self, omega_rad_s: f64, steps_per_rev: usize) -> Result<(Hover, Vec<Mode>)> {
        self.validate()?;
        super::lag_rotor::check_omega(omega_rad_s)?;
        if !(16..=1_000_000).contains(&steps_per_rev) {
            return Err(StabilityError::OutOfRange {
                field: "steps_per_rev".into(),
                value: steps_per_rev as f64,
                expected: "16 ..= 10^6 (RK4 steps per revolution)",
            });
        }
        let period = 2.0 * PI / omega_rad_s;
        let mean = self.blend_to_mean(0.0);
        let hm = mean.hover(omega_rad_s)?;
        let coleman = mean.coleman_all(&hm)?;
        let mut hover = hm;
        let modes = continued_modes(coleman, period, omega_rad_s, self.is_isotropic(), |blend| {
            let stage;
            let rotor = match blend {
                None => self,
                Some(s) => {
                    stage = self.blend_to_mean(s);
                    &stage
                }
            };
            hover = rotor.hover(omega_rad_s)?;
            rotor.multipliers(&hover, steps_per_rev)
        })?;
        Ok((hover, modes))
    }
}

/// The linearised equations `y' = A(t) y` about a hover, `A = [[0, I], [-M^-1 K, -M^-1 C]]`
/// formed at each stage time.
struct StateMatrix<'a> {
    rotor: &'a AirRotor,
    series: &'a [BladeSeries],
    omega: f64,
    a: Mat<f64>,
}

impl OdeRhs for StateMatrix<'_> {
    type Error = StabilityError;

    fn set_time(&mut self, t: f64) -> Result<()> {
        use faer::linalg::solvers::Solve;
        let n = self.rotor.coordinate_count();
        let [m, c, k] = self.rotor.matrices_at(self.series, self.omega, t);
        let lu = m.partial_piv_lu();
        let mik = lu.solve(&k);
        let mic = lu.solve(&c);
        if (0..n).any(|i| (0..n).any(|j| !mik[(i, j)].is_finite() || !mic[(i, j)].is_finite())) {
            return Err(StabilityError::Numerical(format!(
                "singular mass matrix at t = {t} s"
            )));
        }
        self.a = Mat::from_fn(2 * n, 2 * n, |i, j| match (i < n, j < n) {
            (true, true) => 0.0,
            (true, false) => f64::from(u8::from(j - n == i)),
            (false, true) => -mik[(i - n, j)],
            (false, false) => -mic[(i - n, j - n)],
        });
        Ok(())
    }

    fn rhs(&mut self, y: &[f64], dy: &mut [f64]) {
        self.rhs_columns(y, dy, y.len());
    }

    /// `dY = A Y` by one matrix product over all columns.
    fn rhs_columns(&mut self, y: &[f64], dy: &mut [f64], m: usize) {
        let cols = y.len() / m;
        faer::linalg::matmul::matmul(
            faer::MatMut::from_column_major_slice_mut(dy, m, cols),
            faer::Accum::Replace,
            self.a.as_ref(),
            faer::MatRef::from_column_major_slice(y, m, cols),
            1.0,
            faer::get_global_parallelism(),
        );
    }
}

/// The linearised equations with the operators `(M^-1 K, M^-1 C, M^-1 on the lag coordinates)`
/// tabulated at the revolution's half steps, and the lag moments held over a step.
struct Tabulated<'a> {
    table: &'a [(Mat<f64>, Mat<f64>, Mat<f64>)],
    half_step: f64,
    /// The table entry of the last `set_time`.
    at: usize,
    n: usize,
    moment: Vec<f64>,
}

impl OdeRhs for Tabulated<'_> {
    type Error = StabilityError;

    fn set_time(&mut self, t: f64) -> Result<()> {
        // stage times are whole half steps
        self.at = (t / self.half_step).round() as usize % self.table.len();
        Ok(())
    }

    #[inline]
    fn rhs(&mut self, y: &[f64], out: &mut [f64]) {
        let (n, o) = (self.n, &self.table[self.at]);
        for i in 0..n {
            out[i] = y[n + i];
            let mut acc = 0.0;
            for j in 0..n {
                acc -= o.0[(i, j)] * y[j] + o.1[(i, j)] * y[n + j];
            }
            for (j, fj) in self.moment.iter().enumerate() {
                acc += o.2[(i, j)] * fj;
            }
            out[n + i] = acc;
        }
    }
}
