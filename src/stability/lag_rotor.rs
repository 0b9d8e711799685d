//! Rigid lag-hinged blades on a hub moving in the plane: the ground-resonance model of
//! Coleman & Feingold (NACA TR-1351, 1958), in individual blade coordinates (time-periodic,
//! any rotor) and in multi-blade coordinates (constant coefficients, isotropic rotor).
//!
//! # Equations (Lagrange, small lag angles)
//!
//! Hub displacement `h = (x, y)` in the fixed frame; blade `k` at azimuth
//! `psi_k = Omega t + 2 pi (k-1)/N`, lag angle `zeta_k` about a hinge at `e_k` from the shaft,
//! positive in the direction of rotation (a lead; the sign does not change the eigenvalues).
//! With `u(a) = (cos a, sin a)`, `w(a) = (-sin a, cos a)`, a blade element at `r` from the
//! hinge is at `p = h + e u(psi) + r u(psi + zeta)`, so
//! `T_k = 1/2 m |h'|^2 + 1/2 I (Omega + zeta')^2 + m e Omega h'.w(psi)
//!        + S (Omega + zeta') h'.w(psi + zeta) + S e Omega (Omega + zeta') cos zeta + const`
//! with `m, S, I` the blade's mass, first and second moments about the hinge. Lagrange's
//! equation for `zeta_k` (hinge spring `k_lag`, damper `c_lag`), linearised:
//!
//! `I zeta'' + c_lag zeta' + (k_lag + e S Omega^2) zeta + S (-x'' sin psi + y'' cos psi) = 0`
//!
//! (the centrifugal stiffening `e S Omega^2` is the `sin zeta` term). For the hub,
//! `d/dt dT/dh'` linearised about `zeta = 0`, with the airframe axes' mass `M`, spring `K`
//! and damper `C`:
//!
//! `(M_x + sum m) x'' + C_x x' + K_x x - sum S d2/dt2(zeta sin psi) = 0`
//! `(M_y + sum m) y'' + C_y y' + K_y y + sum S d2/dt2(zeta cos psi) = 0`
//!
//! The zeroth-order terms `-(m e + S) Omega^2 u(psi_k)` cancel over identical blades; for
//! dissimilar blade masses they are a 1/rev forcing (rotor imbalance), not part of the
//! homogeneous perturbation equations, and are dropped. The form (rotating lag frequency
//! `nu^2 = (k_lag + e S Omega^2) / I`, coupling through `S` in the blade equations and
//! `N/2 S` in the hub equations) is the classical one of Coleman & Feingold and of Johnson,
//! "Rotorcraft Aeromechanics" (2013) ch. 13 (ground resonance); the derivation above is this
//! module's own, checked against those forms (not against their printed equation numbers) and
//! against Coleman's undamped result that the instability sits where the regressing lag
//! frequency `(1 - nu) Omega` meets the airframe frequency (tests/stability_coleman.rs).
//!
//! # Multi-blade coordinates (isotropic rotor, N >= 3)
//!
//! `zeta_0 = 1/N sum zeta_k`, `zeta_nc = 2/N sum zeta_k cos n psi_k`,
//! `zeta_ns = 2/N sum zeta_k sin n psi_k` (`1 <= n <= (N-1)/2`), `zeta_d = 1/N sum zeta_k (-1)^k`
//! (N even). Substituting `zeta_k = zeta_nc cos n psi_k + zeta_ns sin n psi_k` gives, with
//! `K = k_lag + e S Omega^2`:
//!
//! `I (zeta_nc'' + 2 n Omega zeta_ns' - n^2 Omega^2 zeta_nc) + c (zeta_nc' + n Omega zeta_ns)
//!  + K zeta_nc + [n = 1] S y'' = 0`
//! `I (zeta_ns'' - 2 n Omega zeta_nc' - n^2 Omega^2 zeta_ns) + c (zeta_ns' - n Omega zeta_nc)
//!  + K zeta_ns - [n = 1] S x'' = 0`
//! `(M_x + N m) x'' + C_x x' + K_x x - N/2 S zeta_1s'' = 0`
//! `(M_y + N m) y'' + C_y y' + K_y y + N/2 S zeta_1c'' = 0`
//!
//! and `I zeta'' + c zeta' + K zeta = 0` for the collective and differential coordinates,
//! which do not couple to the hub.
//!
//! # Floquet
//!
//! In individual blade coordinates the coefficients are periodic with `T = 2 pi / Omega`.
//! The monodromy matrix (RK4 over one revolution, `steps_per_rev` steps) has multipliers `mu`;
//! the characteristic exponent `ln(mu) / T` has an exact real part (the growth rate) and an
//! imaginary part known modulo `Omega`. For an isotropic rotor the multi-blade transformation
//! is `T`-periodic, so the multipliers are exactly `exp(lambda T)` of the Coleman eigenvalues
//! `lambda`. The rule used here: each multiplier is matched to the Coleman eigenvalue of the
//! isotropic rotor with the blades' mean properties (nearest `lambda T` in the log plane,
//! imaginary part taken modulo `2 pi`), and the integer multiple of `Omega` is the one that
//! puts the frequency nearest that Coleman frequency; for a non-isotropic rotor this matching
//! is continued from the mean rotor to the actual one in [`CONTINUATION_STAGES`] equal steps
//! of the blade properties, each stage matched to the previous one. The label is carried over.
use super::labels::{self, Family};
use crate::solver::ode::{self, NotFinite, OdeRhs, Rk4};
use faer::{c64, Mat};
use std::f64::consts::PI;
use std::fmt;
use thiserror::Error;

/// Stages of the continuation from the mean isotropic rotor to a dissimilar one (Floquet
/// frequency resolution); enough to keep each stage's multipliers near the previous ones for
/// a fully inoperative damper.
pub const CONTINUATION_STAGES: usize = 8;

/// Bad input to the stability model: the field and the range it should be in.
#[derive(Debug, Error, Clone, PartialEq)]
pub enum StabilityError {
    #[error("{field} = {value} is not finite")]
    NotFinite { field: String, value: f64 },
    #[error("{field} = {value} is out of range: expected {expected}")]
    OutOfRange {
        field: String,
        value: f64,
        expected: &'static str,
    },
    #[error("{what} needs at least {min} blades; the rotor has {count}")]
    TooFewBlades {
        what: &'static str,
        count: usize,
        min: usize,
    },
    #[error(
        "the Coleman transformation needs identical blades: blade {blade} differs from blade 1 \
         in {field} (use floquet for a dissimilar rotor)"
    )]
    NotIsotropic { blade: usize, field: &'static str },
    #[error("initial state has {got} entries; expected {expected} ({layout})")]
    StateLength {
        got: usize,
        expected: usize,
        layout: String,
    },
    #[error("numerical failure: {0}")]
    Numerical(String),
}

pub type Result<T> = std::result::Result<T, StabilityError>;

impl From<NotFinite> for StabilityError {
    fn from(_: NotFinite) -> Self {
        StabilityError::Numerical("monodromy matrix is not finite".into())
    }
}

/// One rigid blade on a lag hinge.
#[derive(Clone, Debug, PartialEq)]
pub struct LagBlade {
    pub mass_kg: f64,
    /// First moment of mass about the lag hinge.
    pub first_moment_kg_m: f64,
    /// Second moment of mass about the lag hinge.
    pub inertia_kg_m2: f64,
    /// Lag hinge distance from the shaft.
    pub hinge_offset_m: f64,
    pub stiffness_nm_per_rad: f64,
    pub damping_nms_per_rad: f64,
}

/// One in-plane direction of the airframe at the hub: effective mass (without the blades),
/// spring and viscous damper to ground.
#[derive(Clone, Debug, PartialEq)]
pub struct AirframeAxis {
    pub mass_kg: f64,
    pub stiffness_n_per_m: f64,
    pub damping_ns_per_m: f64,
}

/// Blades on a hub; `None` for an axis holds the hub rigidly in that direction.
#[derive(Clone, Debug, PartialEq)]
pub struct LagRotor {
    pub blades: Vec<LagBlade>,
    pub x: Option<AirframeAxis>,
    pub y: Option<AirframeAxis>,
}

/// What a mode is, from its eigenvector (Coleman) or from the Coleman mode it continues
/// (Floquet).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ModeLabel {
    RegressingLag,
    ProgressiveLag,
    AirframeX,
    AirframeY,
    CollectiveLag,
    DifferentialLag,
    /// Air resonance (flap and the airframe's rotations, [`super::air_rotor`]).
    RegressingFlap,
    ProgressiveFlap,
    CollectiveFlap,
    DifferentialFlap,
    AirframeRoll,
    AirframePitch,
    /// Floquet mode of a rotor with fewer than 3 blades: no Coleman reference, frequency is
    /// the principal value in `[0, Omega/2]`.
    Unresolved,
}

impl ModeLabel {
    pub fn as_str(self) -> &'static str {
        match self {
            ModeLabel::RegressingLag => "regressing lag",
            ModeLabel::ProgressiveLag => "progressive lag",
            ModeLabel::AirframeX => "airframe x",
            ModeLabel::AirframeY => "airframe y",
            ModeLabel::CollectiveLag => "collective lag",
            ModeLabel::DifferentialLag => "differential lag",
            ModeLabel::RegressingFlap => "regressing flap",
            ModeLabel::ProgressiveFlap => "progressive flap",
            ModeLabel::CollectiveFlap => "collective flap",
            ModeLabel::DifferentialFlap => "differential flap",
            ModeLabel::AirframeRoll => "airframe roll",
            ModeLabel::AirframePitch => "airframe pitch",
            ModeLabel::Unresolved => "unresolved",
        }
    }
}

impl ModeLabel {
    /// The families labelled together ([`LagRotor::coleman_eigenvalues`]): the modes that
    /// couple to the airframe (0), the collective (1), the differential and higher cyclic (2)
    /// and the unresolved (3). A mode keeps its block when a value moves; within the coupled
    /// block the labels may trade places where two modes coalesce.
    pub fn block(self) -> u8 {
        match self {
            ModeLabel::CollectiveLag | ModeLabel::CollectiveFlap => 1,
            ModeLabel::DifferentialLag | ModeLabel::DifferentialFlap => 2,
            ModeLabel::Unresolved => 3,
            _ => 0,
        }
    }
}

impl fmt::Display for ModeLabel {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.as_str())
    }
}

/// One eigenvalue (one per complex-conjugate pair, `Im >= 0`) in the fixed frame.
#[derive(Clone, Debug, PartialEq)]
pub struct Mode {
    /// The mode's family.
    pub label: ModeLabel,
    /// 0 when the mode is its family's only one at this speed; else its number within the
    /// family, 1, 2, ... by decreasing growth rate (an overdamped pair split into two real
    /// roots: root 1 the slower to decay). See [`Mode::name`].
    pub root: usize,
    /// `|Im lambda| / 2 pi`, fixed frame.
    pub frequency_hz: f64,
    /// `-Re lambda / |lambda|` (negative when unstable).
    pub damping_ratio: f64,
    /// `Re lambda`.
    pub growth_rate_per_s: f64,
    pub eigenvalue: c64,
}

impl Mode {
    pub(super) fn new(label: ModeLabel, eigenvalue: c64) -> Self {
        let norm = eigenvalue.re.hypot(eigenvalue.im);
        Mode {
            label,
            root: 0,
            frequency_hz: eigenvalue.im.abs() / (2.0 * PI),
            damping_ratio: if norm > 0.0 {
                -eigenvalue.re / norm
            } else {
                0.0
            },
            growth_rate_per_s: eigenvalue.re,
            eigenvalue,
        }
    }
}

impl Mode {
    /// The name of the mode, unique at its speed: the family ("airframe y"), and when the
    /// family has more than one mode at this speed, which: "airframe y (real root 1)" for a
    /// real root, "differential lag (2)" for an oscillating one.
    pub fn name(&self) -> String {
        match self.root {
            0 => self.label.as_str().to_string(),
            k if self.eigenvalue.im == 0.0 => format!("{} (real root {k})", self.label),
            k => format!("{} ({k})", self.label),
        }
    }
}

/// States of [`LagRotor::time_response`]: `states[i * state_len..][..state_len]` at
/// `time_s[i]`, ordered as [`LagRotor::state_layout`].
#[derive(Clone, Debug)]
pub struct TimeResponse {
    pub time_s: Vec<f64>,
    pub states: Vec<f64>,
    pub state_len: usize,
}

impl TimeResponse {
    pub fn state(&self, i: usize) -> &[f64] {
        &self.states[i * self.state_len..(i + 1) * self.state_len]
    }

    /// The history of one state entry.
    pub fn series(&self, index: usize) -> Vec<f64> {
        self.states
            .chunks_exact(self.state_len)
            .map(|s| s[index])
            .collect()
    }
}

fn finite(field: impl Into<String>, value: f64) -> Result<()> {
    if value.is_finite() {
        Ok(())
    } else {
        Err(StabilityError::NotFinite {
            field: field.into(),
            value,
        })
    }
}

pub(super) fn range(
    field: impl Into<String>,
    value: f64,
    ok: bool,
    expected: &'static str,
) -> Result<()> {
    let field = field.into();
    finite(field.clone(), value)?;
    if ok {
        Ok(())
    } else {
        Err(out_of_range(field, value, expected))
    }
}

pub(super) fn out_of_range(field: String, value: f64, expected: &'static str) -> StabilityError {
    StabilityError::OutOfRange {
        field,
        value,
        expected,
    }
}

pub(super) fn check_omega(omega_rad_s: f64) -> Result<()> {
    range(
        "omega_rad_s",
        omega_rad_s,
        omega_rad_s > 0.0,
        "> 0 (rotor speed)",
    )
}

impl LagBlade {
    fn validate(&self, k: usize) -> Result<()> {
        let f = |name: &str| format!("blades[{k}].{name}");
        range(f("mass_kg"), self.mass_kg, self.mass_kg > 0.0, "> 0")?;
        range(
            f("inertia_kg_m2"),
            self.inertia_kg_m2,
            self.inertia_kg_m2 > 0.0,
            "> 0",
        )?;
        let s = self.first_moment_kg_m;
        // Cauchy-Schwarz: S^2 <= m I for any mass distribution; it keeps the mass matrix
        // positive definite.
        range(
            f("first_moment_kg_m"),
            s,
            s >= 0.0 && s * s <= self.mass_kg * self.inertia_kg_m2 * (1.0 + 1e-12),
            "0 <= S <= sqrt(mass_kg * inertia_kg_m2)",
        )?;
        range(
            f("hinge_offset_m"),
            self.hinge_offset_m,
            self.hinge_offset_m >= 0.0,
            ">= 0",
        )?;
        range(
            f("stiffness_nm_per_rad"),
            self.stiffness_nm_per_rad,
            self.stiffness_nm_per_rad >= 0.0,
            ">= 0",
        )?;
        range(
            f("damping_nms_per_rad"),
            self.damping_nms_per_rad,
            self.damping_nms_per_rad >= 0.0,
            ">= 0",
        )
    }
}

impl AirframeAxis {
    fn validate(&self, axis: &str) -> Result<()> {
        let f = |name: &str| format!("{axis}.{name}");
        range(f("mass_kg"), self.mass_kg, self.mass_kg > 0.0, "> 0")?;
        range(
            f("stiffness_n_per_m"),
            self.stiffness_n_per_m,
            self.stiffness_n_per_m >= 0.0,
            ">= 0",
        )?;
        range(
            f("damping_ns_per_m"),
            self.damping_ns_per_m,
            self.damping_ns_per_m >= 0.0,
            ">= 0",
        )
    }
}

/// Hub coordinate: which axis, total mass (airframe + blades), spring, damper.
#[derive(Clone, Copy, Debug)]
struct Hub {
    is_y: bool,
    mass_kg: f64,
    stiffness: f64,
    damping: f64,
}

impl LagRotor {
    pub fn validate(&self) -> Result<()> {
        need_blades("the lag rotor", self.blades.len(), 1)?;
        for (k, b) in self.blades.iter().enumerate() {
            b.validate(k)?;
        }
        if let Some(a) = &self.x {
            a.validate("x")?;
        }
        if let Some(a) = &self.y {
            a.validate("y")?;
        }
        Ok(())
    }

    /// Blades, then the present airframe axes (x before y).
    pub fn coordinate_count(&self) -> usize {
        self.blades.len() + usize::from(self.x.is_some()) + usize::from(self.y.is_some())
    }

    /// Coordinates then their velocities.
    pub fn state_len(&self) -> usize {
        2 * self.coordinate_count()
    }

    pub fn x_index(&self) -> Option<usize> {
        self.x.as_ref().map(|_| self.blades.len())
    }

    pub fn y_index(&self) -> Option<usize> {
        self.y
            .as_ref()
            .map(|_| self.blades.len() + usize::from(self.x.is_some()))
    }

    /// The state ordering in words (for messages).
    pub fn state_layout(&self) -> String {
        let mut q: Vec<String> = (1..=self.blades.len())
            .map(|k| format!("zeta_{k} [rad]"))
            .collect();
        if self.x.is_some() {
            q.push("x [m]".into());
        }
        if self.y.is_some() {
            q.push("y [m]".into());
        }
        format!("{}, then their rates", q.join(", "))
    }

    /// All blades equal (bit for bit: a deck's copies of one blade).
    pub fn is_isotropic(&self) -> bool {
        self.first_dissimilar().is_none()
    }

    fn first_dissimilar(&self) -> Option<(usize, &'static str)> {
        let b0 = self.blades.first()?;
        for (k, b) in self.blades.iter().enumerate().skip(1) {
            let fields = [
                ("mass_kg", b.mass_kg, b0.mass_kg),
                (
                    "first_moment_kg_m",
                    b.first_moment_kg_m,
                    b0.first_moment_kg_m,
                ),
                ("inertia_kg_m2", b.inertia_kg_m2, b0.inertia_kg_m2),
                ("hinge_offset_m", b.hinge_offset_m, b0.hinge_offset_m),
                (
                    "stiffness_nm_per_rad",
                    b.stiffness_nm_per_rad,
                    b0.stiffness_nm_per_rad,
                ),
                (
                    "damping_nms_per_rad",
                    b.damping_nms_per_rad,
                    b0.damping_nms_per_rad,
                ),
            ];
            if let Some((name, _, _)) = fields.iter().find(|(_, a, b)| a != b) {
                return Some((k + 1, name));
            }
        }
        None
    }

    /// The isotropic rotor with each blade property averaged over the blades.
    pub fn mean_rotor(&self) -> LagRotor {
        self.blend_to_mean(0.0)
    }

    /// Blades `mean + s (actual - mean)`: `s = 0` the mean rotor, `s = 1` this one.
    fn blend_to_mean(&self, s: f64) -> LagRotor {
        let n = self.blades.len() as f64;
        let mean = |f: fn(&LagBlade) -> f64| self.blades.iter().map(f).sum::<f64>() / n;
        let m = LagBlade {
            mass_kg: mean(|b| b.mass_kg),
            first_moment_kg_m: mean(|b| b.first_moment_kg_m),
            inertia_kg_m2: mean(|b| b.inertia_kg_m2),
            hinge_offset_m: mean(|b| b.hinge_offset_m),
            stiffness_nm_per_rad: mean(|b| b.stiffness_nm_per_rad),
            damping_nms_per_rad: mean(|b| b.damping_nms_per_rad),
        };
        let mix = |a: f64, b: f64| a + s * (b - a);
        LagRotor {
            blades: self
                .blades
                .iter()
                .map(|b| LagBlade {
                    mass_kg: mix(m.mass_kg, b.mass_kg),
                    first_moment_kg_m: mix(m.first_moment_kg_m, b.first_moment_kg_m),
                    inertia_kg_m2: mix(m.inertia_kg_m2, b.inertia_kg_m2),
                    hinge_offset_m: mix(m.hinge_offset_m, b.hinge_offset_m),
                    stiffness_nm_per_rad: mix(m.stiffness_nm_per_rad, b.stiffness_nm_per_rad),
                    damping_nms_per_rad: mix(m.damping_nms_per_rad, b.damping_nms_per_rad),
                })
                .collect(),
            x: self.x.clone(),
            y: self.y.clone(),
        }
    }

    fn hubs(&self) -> Vec<Hub> {
        let blade_mass: f64 = self.blades.iter().map(|b| b.mass_kg).sum();
        let mut out = Vec::new();
        for (axis, is_y) in [(&self.x, false), (&self.y, true)] {
            if let Some(a) = axis {
                out.push(Hub {
                    is_y,
                    mass_kg: a.mass_kg + blade_mass,
                    stiffness: a.stiffness_n_per_m,
                    damping: a.damping_ns_per_m,
                });
            }
        }
        out
    }

    /// Constant-coefficient eigenvalues in multi-blade coordinates (isotropic rotor, N >= 3),
    /// one per complex-conjugate pair, sorted by frequency.
    ///
    /// Labels: the collective, differential and higher cyclic (reactionless, "differential
    /// lag") coordinates do not couple to the hub and are solved as separate blocks, labelled
    /// by block. In the coupled block (cyclic n = 1 with the hub) the labels are solved jointly
    /// ([`super::labels`]): each mode offers each family its share of the eigenvector's kinetic
    /// energy, cyclic lag `N/2 I (|zeta_1c|^2 + |zeta_1s|^2)`, `M_x |x|^2`, `M_y |y|^2` (total
    /// masses), and the assignment with the largest total share gives each family (regressing
    /// lag, progressive lag, airframe x, airframe y) to one conjugate pair, or to one pair of
    /// real roots when the family is overdamped. The cyclic share is split between progressive
    /// and regressing by the whirl: a cyclic-lag mode is "progressive" when its whirl turns
    /// forward in the rotating frame, i.e. forward whirl in the fixed frame (`|zeta_1c + i
    /// zeta_1s|` larger than `|zeta_1c - i zeta_1s|`) at a fixed-frame frequency above
    /// `Omega`; otherwise it is "regressing" (below `Omega`, or backward whirl in the fixed
    /// frame). The forward part of the whirl above `Omega` counts as progressive, the rest as
    /// regressing. A family with two modes at one speed numbers them ([`Mode::name`]).
    pub fn coleman_eigenvalues(&self, omega_rad_s: f64) -> Result<Vec<Mode>> {
        Ok(upper_modes(self.coleman_all(omega_rad_s)?))
    }

    /// All `2 n` Coleman eigenvalues (conjugates included) with their labels.
    fn coleman_all(&self, omega: f64) -> Result<Vec<(c64, ModeLabel)>> {
        self.validate()?;
        check_omega(omega)?;
        let nb = self.blades.len();
        need_blades("the Coleman transformation", nb, 3)?;
        if let Some((blade, field)) = self.first_dissimilar() {
            return Err(StabilityError::NotIsotropic { blade, field });
        }
        let b = &self.blades[0];
        let (i_b, s_b, c_b) = (b.inertia_kg_m2, b.first_moment_kg_m, b.damping_nms_per_rad);
        let k_b = b.stiffness_nm_per_rad + b.hinge_offset_m * s_b * omega * omega;
        let hubs = self.hubs();
        let mut out = Vec::with_capacity(2 * self.coordinate_count());
        // Reactionless blocks do not couple to the hub; solved apart so that their labels do
        // not depend on how a solver splits the collective/differential double root.
        let single = |c: f64, k: f64| {
            let m1 = Mat::<f64>::from_fn(1, 1, |_, _| i_b);
            let c1 = Mat::<f64>::from_fn(1, 1, |_, _| c);
            let k1 = Mat::<f64>::from_fn(1, 1, |_, _| k);
            eigen_pairs(&m1, &c1, &k1)
        };
        let (roots, _) = single(c_b, k_b)?;
        out.extend(roots.iter().map(|&l| (l, ModeLabel::CollectiveLag)));
        if nb.is_multiple_of(2) {
            out.extend(roots.iter().map(|&l| (l, ModeLabel::DifferentialLag)));
        }
        // Cyclic n >= 2 (N >= 5), reactionless: the cyclic equations without the hub terms.
        for h in 2..=(nb - 1) / 2 {
            let hw = h as f64 * omega;
            let m2 = Mat::<f64>::from_fn(2, 2, |i, j| if i == j { i_b } else { 0.0 });
            let c2 = Mat::<f64>::from_fn(2, 2, |i, j| match (i, j) {
                (0, 1) => 2.0 * hw * i_b,
                (1, 0) => -2.0 * hw * i_b,
                _ => c_b,
            });
            let k2 = Mat::<f64>::from_fn(2, 2, |i, j| match (i, j) {
                (0, 1) => c_b * hw,
                (1, 0) => -c_b * hw,
                _ => k_b - hw * hw * i_b,
            });
            let (l2, _) = eigen_pairs(&m2, &c2, &k2)?;
            out.extend(l2.iter().map(|&l| (l, ModeLabel::DifferentialLag)));
        }
        // Cyclic n = 1 coupled to the hub: coordinates zeta_1c, zeta_1s, hubs.
        let (mm, cm, km, weight) = self.cyclic_block(omega);
        let (lams, u) = eigen_pairs(&mm, &cm, &km)?;
        let mut families = vec![
            Family {
                label: ModeLabel::RegressingLag,
                slots: 1,
            },
            Family {
                label: ModeLabel::ProgressiveLag,
                slots: 1,
            },
        ];
        families.extend(hubs.iter().map(|hub| Family {
            label: if hub.is_y {
                ModeLabel::AirframeY
            } else {
                ModeLabel::AirframeX
            },
            slots: 1,
        }));
        let weights: Vec<Vec<f64>> = lams
            .iter()
            .enumerate()
            .map(|(j, &l)| {
                let energy = |i: usize| weight[i] * u[(i, j)].norm() * u[(i, j)].norm();
                // Whirl of (zeta_1c, zeta_1s) for the Im >= 0 member of the pair.
                let (zc, zs) = if l.im >= 0.0 {
                    (u[(0, j)], u[(1, j)])
                } else {
                    (u[(0, j)].conj(), u[(1, j)].conj())
                };
                let (reg, pro) = labels::whirl_split(l, zc, zs, omega, energy(0) + energy(1));
                let mut e = vec![reg, pro];
                e.extend((0..hubs.len()).map(|jh| energy(2 + jh)));
                labels::shares(&e)
            })
            .collect();
        let labels = labels::assign(&lams, &weights, &families);
        out.extend(lams.iter().copied().zip(labels));
        Ok(out)
    }

    /// The cyclic n = 1 equations coupled to the hub (isotropic rotor): mass, damping and
    /// stiffness on `zeta_1c, zeta_1s`, then the hubs, and each coordinate's kinetic-energy
    /// weight.
    fn cyclic_block(&self, omega: f64) -> (Mat<f64>, Mat<f64>, Mat<f64>, Vec<f64>) {
        let nb = self.blades.len();
        let b = &self.blades[0];
        let (i_b, s_b, c_b) = (b.inertia_kg_m2, b.first_moment_kg_m, b.damping_nms_per_rad);
        let k_b = b.stiffness_nm_per_rad + b.hinge_offset_m * s_b * omega * omega;
        let hubs = self.hubs();
        let n = 2 + hubs.len();
        let mut mm = Mat::<f64>::zeros(n, n);
        let mut cm = Mat::<f64>::zeros(n, n);
        let mut km = Mat::<f64>::zeros(n, n);
        let mut weight = vec![nb as f64 / 2.0 * i_b; n];
        for i in 0..2 {
            mm[(i, i)] = i_b;
            cm[(i, i)] = c_b;
            km[(i, i)] = k_b - omega * omega * i_b;
        }
        cm[(0, 1)] = 2.0 * omega * i_b;
        cm[(1, 0)] = -2.0 * omega * i_b;
        km[(0, 1)] = c_b * omega;
        km[(1, 0)] = -c_b * omega;
        let half_n_s = nb as f64 / 2.0 * s_b;
        for (j, hub) in hubs.iter().enumerate() {
            let ih = 2 + j;
            mm[(ih, ih)] = hub.mass_kg;
            cm[(ih, ih)] = hub.damping;
            km[(ih, ih)] = hub.stiffness;
            weight[ih] = hub.mass_kg;
            if hub.is_y {
                mm[(0, ih)] = s_b;
                mm[(ih, 0)] = half_n_s;
            } else {
                mm[(1, ih)] = -s_b;
                mm[(ih, 1)] = -half_n_s;
            }
        }
        (mm, cm, km, weight)
    }

    /// A state (ordered as [`LagRotor::state_layout`], blade 1 at zero azimuth) on the least
    /// damped Coleman mode labelled `label` of this isotropic rotor, scaled to a cyclic lag
    /// amplitude of 1 rad ([`cyclic_amplitude`]): the start of a free response that holds
    /// that mode alone. Only the coupled modes (regressing and progressive lag, airframe).
    pub fn mode_state(&self, omega_rad_s: f64, label: ModeLabel) -> Result<Vec<f64>> {
        let modes = self.coleman_eigenvalues(omega_rad_s)?;
        let target = modes
            .iter()
            .filter(|m| m.label == label)
            .max_by(|a, b| a.growth_rate_per_s.total_cmp(&b.growth_rate_per_s))
            .ok_or_else(|| StabilityError::Numerical(format!("no {label} mode")))?;
        let (mm, cm, km, _) = self.cyclic_block(omega_rad_s);
        let (lams, u) = eigen_pairs(&mm, &cm, &km)?;
        let j = nearest(&lams, target.eigenvalue)
            .ok_or_else(|| StabilityError::Numerical("empty Coleman block".into()))?;
        let (lam, nh) = (lams[j], self.hubs().len());
        let q = |i: usize| u[(i, j)].re;
        let v = |i: usize| (lam * u[(i, j)]).re;
        let nb = self.blades.len();
        let n = nb + nh;
        let mut z = vec![0.0; 2 * n];
        for k in 0..nb {
            let (sn, cs) = (2.0 * PI * k as f64 / nb as f64).sin_cos();
            z[k] = q(0) * cs + q(1) * sn;
            z[n + k] = v(0) * cs - omega_rad_s * q(0) * sn + v(1) * sn + omega_rad_s * q(1) * cs;
        }
        for h in 0..nh {
            z[nb + h] = q(2 + h);
            z[n + nb + h] = v(2 + h);
        }
        unit_cyclic(z, nb, omega_rad_s, lam.im.abs(), label)
    }

    /// Floquet characteristic exponents of the periodic equations in individual blade
    /// coordinates (any rotor), one per conjugate pair of the reference Coleman modes,
    /// sorted by frequency; the frequency is resolved as in the module documentation.
    pub fn floquet(&self, omega_rad_s: f64, steps_per_rev: usize) -> Result<Vec<Mode>> {
        self.validate()?;
        check_omega(omega_rad_s)?;
        range(
            "steps_per_rev",
            steps_per_rev as f64,
            (16..=10_000_000).contains(&steps_per_rev),
            "16 ..= 10^7 (RK4 steps per revolution)",
        )?;
        let period = 2.0 * PI / omega_rad_s;
        if self.blades.len() < 3 {
            let mu = self.multipliers(omega_rad_s, steps_per_rev)?;
            let mut modes: Vec<Mode> = mu
                .into_iter()
                .filter(|m| m.im >= 0.0)
                .map(|m| Mode::new(ModeLabel::Unresolved, m.ln() / period))
                .collect();
            modes.sort_by(|a, b| a.frequency_hz.total_cmp(&b.frequency_hz));
            return Ok(modes);
        }
        let coleman = self.mean_rotor().coleman_all(omega_rad_s)?;
        continued_modes(
            coleman,
            period,
            omega_rad_s,
            self.is_isotropic(),
            |blend| match blend {
                None => self.multipliers(omega_rad_s, steps_per_rev),
                Some(s) => self
                    .blend_to_mean(s)
                    .multipliers(omega_rad_s, steps_per_rev),
            },
        )
    }

    /// Eigenvalues of the monodromy matrix over one revolution.
    fn multipliers(&self, omega: f64, steps_per_rev: usize) -> Result<Vec<c64>> {
        let phi = self.monodromy(omega, steps_per_rev)?;
        floquet_multipliers(&phi, self.state_len())
    }

    /// The monodromy matrix, column-major (`state_len^2`), by RK4 on all columns at once.
    pub fn monodromy(&self, omega_rad_s: f64, steps_per_rev: usize) -> Result<Vec<f64>> {
        self.validate()?;
        check_omega(omega_rad_s)?;
        let mut sys = PeriodicSystem::new(self, omega_rad_s);
        ode::monodromy(
            &mut sys,
            self.state_len(),
            2.0 * PI / omega_rad_s,
            steps_per_rev,
        )
    }

    /// The uniform steps of a free response from `initial` to `t_end_s` of at most `dt_s`
    /// (`t_end_s / ceil(t_end_s / dt_s)`, landing on `t_end_s`): their count and length, the
    /// state and sizes checked.
    pub(super) fn response_steps(
        &self,
        initial: &[f64],
        t_end_s: f64,
        dt_s: f64,
    ) -> Result<(usize, f64)> {
        let m = self.state_len();
        if initial.len() != m {
            return Err(StabilityError::StateLength {
                got: initial.len(),
                expected: m,
                layout: self.state_layout(),
            });
        }
        for (i, v) in initial.iter().enumerate() {
            finite(format!("initial[{i}]"), *v)?;
        }
        range("dt_s", dt_s, dt_s > 0.0, "> 0")?;
        range("t_end_s", t_end_s, t_end_s >= 0.0, ">= 0")?;
        let steps_f = (t_end_s / dt_s).ceil();
        range(
            "t_end_s / dt_s",
            steps_f,
            steps_f <= 1e7,
            "<= 10^7 steps (the history is kept in memory)",
        )?;
        let steps = steps_f as usize;
        let h = if steps > 0 {
            t_end_s / steps as f64
        } else {
            0.0
        };
        Ok((steps, h))
    }

    /// Free response of the periodic equations from `initial` (ordered as
    /// [`LagRotor::state_layout`]) at `t = 0` (blade 1 at zero azimuth) to `t_end_s`, RK4 with
    /// the uniform step `t_end_s / ceil(t_end_s / dt_s)` (<= `dt_s`, landing on `t_end_s`).
    pub fn time_response(
        &self,
        omega_rad_s: f64,
        initial: &[f64],
        t_end_s: f64,
        dt_s: f64,
    ) -> Result<TimeResponse> {
        self.validate()?;
        check_omega(omega_rad_s)?;
        let m = self.state_len();
        let (steps, h) = self.response_steps(initial, t_end_s, dt_s)?;
        let mut sys = PeriodicSystem::new(self, omega_rad_s);
        let mut ws = Rk4::new(m);
        let mut time_s = Vec::with_capacity(steps + 1);
        let mut states = Vec::with_capacity((steps + 1) * m);
        let mut y = initial.to_vec();
        time_s.push(0.0);
        states.extend_from_slice(&y);
        for step in 0..steps {
            let t = step as f64 * h;
            ws.step(&mut sys, t, h, &mut y)?;
            if y.iter().any(|v| !v.is_finite()) {
                return Err(StabilityError::Numerical(format!(
                    "time response is not finite at t = {:.6} s (unstable, or dt_s too large for RK4)",
                    t + h
                )));
            }
            time_s.push(t + h);
            states.extend_from_slice(&y);
        }
        Ok(TimeResponse {
            time_s,
            states,
            state_len: m,
        })
    }
}

/// Eigenvalues and eigenvectors (displacement rows first) of
/// `A = [[0, I], [-M^-1 K, -M^-1 C]]`.
pub(super) fn eigen_pairs(
    mm: &Mat<f64>,
    cm: &Mat<f64>,
    km: &Mat<f64>,
) -> Result<(Vec<c64>, Mat<c64>)> {
    use faer::linalg::solvers::Solve;
    let n = mm.nrows();
    let lu = mm.partial_piv_lu();
    let mik = lu.solve(km);
    let mic = lu.solve(cm);
    let bad = |m: &Mat<f64>| (0..n).any(|i| (0..n).any(|j| !m[(i, j)].is_finite()));
    if bad(&mik) || bad(&mic) {
        return Err(StabilityError::Numerical("singular mass matrix".into()));
    }
    let a = Mat::from_fn(2 * n, 2 * n, |i, j| match (i < n, j < n) {
        (true, true) => 0.0,
        (true, false) => f64::from(u8::from(j - n == i)),
        (false, true) => -mik[(i - n, j)],
        (false, false) => -mic[(i - n, j - n)],
    });
    let eig = a
        .eigen()
        .map_err(|e| StabilityError::Numerical(format!("Coleman eigenvalues: {e:?}")))?;
    let lams = (0..2 * n).map(|j| eig.S().column_vector()[j]).collect();
    Ok((lams, eig.U().to_owned()))
}

/// At least `min` blades for `what`.
pub(super) fn need_blades(what: &'static str, count: usize, min: usize) -> Result<()> {
    if count < min {
        return Err(StabilityError::TooFewBlades { what, count, min });
    }
    Ok(())
}

/// The index of the eigenvalue in `lams` nearest `target`.
pub(super) fn nearest(lams: &[c64], target: c64) -> Option<usize> {
    (0..lams.len()).min_by(|&a, &b| {
        (lams[a] - target)
            .norm()
            .total_cmp(&(lams[b] - target).norm())
    })
}

/// The mode state `z` (blade 1 at zero azimuth, whirl frequency `w`) scaled to a cyclic lag
/// amplitude of 1 rad ([`cyclic_amplitude`]).
pub(super) fn unit_cyclic(
    mut z: Vec<f64>,
    blades: usize,
    omega: f64,
    w: f64,
    label: ModeLabel,
) -> Result<Vec<f64>> {
    let a = cyclic_amplitude(&z, blades, omega, 0.0, w);
    if !(a > 0.0 && a.is_finite()) {
        return Err(StabilityError::Numerical(format!(
            "the {label} mode has no cyclic lag motion"
        )));
    }
    z.iter_mut().for_each(|x| *x /= a);
    Ok(z)
}

/// One mode per conjugate pair (`Im >= 0`) of `all`, sorted by frequency.
pub(super) fn upper_modes(all: Vec<(c64, ModeLabel)>) -> Vec<Mode> {
    modes_by_frequency(all.into_iter().filter(|(l, _)| l.im >= 0.0))
}

fn modes_by_frequency(all: impl Iterator<Item = (c64, ModeLabel)>) -> Vec<Mode> {
    let mut modes: Vec<Mode> = all.map(|(l, label)| Mode::new(label, l)).collect();
    modes.sort_by(|a, b| a.frequency_hz.total_cmp(&b.frequency_hz));
    let key: Vec<(ModeLabel, c64)> = modes.iter().map(|m| (m.label, m.eigenvalue)).collect();
    for (m, root) in modes.iter_mut().zip(labels::roots_within_family(&key)) {
        m.root = root;
    }
    modes
}

/// Floquet multipliers of the column-major `m x m` monodromy matrix `phi`.
pub(super) fn floquet_multipliers(phi: &[f64], m: usize) -> Result<Vec<c64>> {
    ode::multipliers(phi, m)
        .map_err(|e| StabilityError::Numerical(format!("Floquet multipliers: {e}")))
}

/// The Floquet modes of a rotor from the Coleman modes `coleman` (all, conjugates included)
/// of its mean isotropic rotor, continued as in the module documentation: `multipliers(None)`
/// of the rotor itself when it is isotropic, else `multipliers(Some(s))` of the blend
/// `mean + s (actual - mean)` for `s = k / CONTINUATION_STAGES`, `k = 1..=CONTINUATION_STAGES`.
/// One mode per conjugate pair, sorted by frequency.
pub(super) fn continued_modes(
    coleman: Vec<(c64, ModeLabel)>,
    period: f64,
    omega: f64,
    isotropic: bool,
    mut multipliers: impl FnMut(Option<f64>) -> Result<Vec<c64>>,
) -> Result<Vec<Mode>> {
    let stages = if isotropic { 1 } else { CONTINUATION_STAGES };
    let out = ode::continue_exponents(coleman, stages, period, omega, |k| {
        multipliers((!isotropic).then(|| (k + 1) as f64 / CONTINUATION_STAGES as f64))
    })?;
    // One mode per conjugate pair of the continued exponents (as of the Coleman ones): a pair
    // of the mean rotor's real roots may continue to a conjugate pair, and a conjugate pair to
    // two real roots.
    Ok(upper_modes(out))
}

/// The periodic equations in individual blade coordinates, evaluated in place.
pub(super) struct PeriodicSystem {
    omega: f64,
    inertia: Vec<f64>,
    first_moment: Vec<f64>,
    damping: Vec<f64>,
    /// `k_lag + e S Omega^2`.
    stiffness: Vec<f64>,
    phase: Vec<f64>,
    hubs: Vec<Hub>,
    sin: Vec<f64>,
    cos: Vec<f64>,
    force: Vec<f64>,
    /// External lag moment on each blade [N m], linear in time over a step: `m0 + (t - t0)
    /// slope` (a damper outside the linear equations, [`super::dampers`]); zero otherwise.
    moment: Vec<f64>,
    moment_start: Vec<f64>,
    moment_slope: Vec<f64>,
    moment_t0: f64,
}

impl PeriodicSystem {
    pub(super) fn new(rotor: &LagRotor, omega: f64) -> Self {
        let nb = rotor.blades.len();
        let b = &rotor.blades;
        PeriodicSystem {
            omega,
            inertia: b.iter().map(|b| b.inertia_kg_m2).collect(),
            first_moment: b.iter().map(|b| b.first_moment_kg_m).collect(),
            damping: b.iter().map(|b| b.damping_nms_per_rad).collect(),
            stiffness: b
                .iter()
                .map(|b| {
                    b.stiffness_nm_per_rad + b.hinge_offset_m * b.first_moment_kg_m * omega * omega
                })
                .collect(),
            phase: (0..nb).map(|k| 2.0 * PI * k as f64 / nb as f64).collect(),
            hubs: rotor.hubs(),
            sin: vec![0.0; nb],
            cos: vec![0.0; nb],
            force: vec![0.0; nb],
            moment: vec![0.0; nb],
            moment_start: vec![0.0; nb],
            moment_slope: vec![0.0; nb],
            moment_t0: 0.0,
        }
    }

    /// The external lag moments from `start` at `t0` to `end` at `t0 + h`.
    pub(super) fn set_moments(&mut self, t0: f64, h: f64, start: &[f64], end: &[f64]) {
        self.moment_t0 = t0;
        for k in 0..self.moment.len() {
            self.moment_start[k] = start[k];
            self.moment_slope[k] = (end[k] - start[k]) / h;
        }
    }

    /// Mass coupling of blade `k` to hub coordinate `hub`, and the hub row's damping and
    /// stiffness coupling: `-S d2/dt2(zeta sin psi)` for x, `+S d2/dt2(zeta cos psi)` for y.
    #[inline]
    fn coupling(&self, hub: &Hub, k: usize) -> (f64, f64, f64) {
        let (s, w) = (self.first_moment[k], self.omega);
        let (sn, cs) = (self.sin[k], self.cos[k]);
        if hub.is_y {
            (s * cs, -2.0 * w * s * sn, -w * w * s * cs)
        } else {
            (-s * sn, -2.0 * w * s * cs, w * w * s * sn)
        }
    }

    /// `dz = f(t, z)` at the time of the last `set_time`; `z = [q, q']`. Inlined into the
    /// loop over the monodromy's columns.
    #[inline(always)]
    fn eval(&mut self, z: &[f64], dz: &mut [f64]) {
        let nb = self.inertia.len();
        let n = nb + self.hubs.len();
        let (q, v) = z.split_at(n);
        dz[..n].copy_from_slice(v);
        for k in 0..nb {
            self.force[k] = self.moment[k] - (self.damping[k] * v[k] + self.stiffness[k] * q[k]);
        }
        // Hub forces and the Schur complement of the (diagonal) blade inertia block:
        // (H - B^T D^-1 B) a_h = f_h - B^T D^-1 f_b.
        let mut g = [0.0; 2];
        let mut h = [[0.0; 2]; 2];
        for (j, hub) in self.hubs.iter().enumerate() {
            let mut f = -(hub.damping * v[nb + j] + hub.stiffness * q[nb + j]);
            h[j][j] = hub.mass_kg;
            for k in 0..nb {
                let (b, c, kk) = self.coupling(hub, k);
                f -= c * v[k] + kk * q[k];
                let inv_i = 1.0 / self.inertia[k];
                f -= b * self.force[k] * inv_i;
                for (l, other) in self.hubs.iter().enumerate() {
                    let (b2, _, _) = self.coupling(other, k);
                    h[j][l] -= b * b2 * inv_i;
                }
            }
            g[j] = f;
        }
        let mut a = [0.0; 2];
        match self.hubs.len() {
            1 => a[0] = g[0] / h[0][0],
            2 => {
                let det = h[0][0] * h[1][1] - h[0][1] * h[1][0];
                a[0] = (g[0] * h[1][1] - h[0][1] * g[1]) / det;
                a[1] = (h[0][0] * g[1] - h[1][0] * g[0]) / det;
            }
            _ => {}
        }
        for k in 0..nb {
            let mut f = self.force[k];
            for (j, hub) in self.hubs.iter().enumerate() {
                f -= self.coupling(hub, k).0 * a[j];
            }
            dz[n + k] = f / self.inertia[k];
        }
        for j in 0..self.hubs.len() {
            dz[n + nb + j] = a[j];
        }
    }
}

impl OdeRhs for PeriodicSystem {
    type Error = StabilityError;

    #[inline]
    fn set_time(&mut self, t: f64) -> Result<()> {
        for k in 0..self.phase.len() {
            let (s, c) = (self.omega * t + self.phase[k]).sin_cos();
            self.sin[k] = s;
            self.cos[k] = c;
            self.moment[k] = self.moment_start[k] + (t - self.moment_t0) * self.moment_slope[k];
        }
        Ok(())
    }

    #[inline]
    fn rhs(&mut self, z: &[f64], dz: &mut [f64]) {
        self.eval(z, dz);
    }

    fn rhs_columns(&mut self, z: &[f64], dz: &mut [f64], m: usize) {
        for (zc, dc) in z.chunks_exact(m).zip(dz.chunks_exact_mut(m)) {
            self.eval(zc, dc);
        }
    }
}

/// Cyclic lag amplitude of state `z` at time `t` [rad]: `sqrt((z_1c^2 + z_1s^2 + (z_1c'^2 +
/// z_1s'^2) / w^2) / 2)` with the multi-blade coordinates `z_1c = 2/N sum zeta_k cos psi_k`,
/// `z_1s = 2/N sum zeta_k sin psi_k` (`psi_k = Omega t + 2 pi k / N`) and `w` the whirl's
/// fixed-frame frequency. Constant over the cycle for a whirl of one frequency (circular or
/// elliptic), so its logarithm grows at the mode's growth rate without the cycle's ripple;
/// each blade's lag amplitude for a circular whirl.
pub fn cyclic_amplitude(z: &[f64], blades: usize, omega: f64, t: f64, w: f64) -> f64 {
    let n = z.len() / 2;
    let (mut c, mut s, mut dc, mut ds) = (0.0, 0.0, 0.0, 0.0);
    for k in 0..blades {
        let (sn, cs) = (omega * t + 2.0 * PI * k as f64 / blades as f64).sin_cos();
        let (q, v) = (z[k], z[n + k]);
        c += q * cs;
        s += q * sn;
        dc += v * cs - omega * q * sn;
        ds += v * sn + omega * q * cs;
    }
    let f = 2.0 / blades as f64;
    let (c, s, dc, ds) = (f * c, f * s, f * dc, f * ds);
    (0.5 * (c * c + s * s + (dc * dc + ds * ds) / (w * w))).sqrt()
}
