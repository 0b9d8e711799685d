//! Rotor inflow models: uniform (Glauert momentum), Drees' linear skewed-wake distribution and
//! the Pitt-Peters three-state dynamic inflow.
//!
//! Everything is dimensionless in the rotor's units: velocities / (Omega R), radius r / R, time
//! as the azimuth psi = Omega t, loads as coefficients normalised by rho pi R^2 (Omega R)^2
//! (and by R more for moments).
//!
//! # Conventions
//! Hub (non-rotating shaft) frame: z up along the shaft, the rotor turns counter-clockwise seen
//! from above, psi is measured from the downstream direction (+x, aft), so the advancing side is
//! psi = 90 deg (+y). The free stream relative to the hub is (mu, 0, -lambda_free): a positive
//! `lambda_free` is a flow down through the disk.
//!
//! The induced inflow (positive down through the disk) is
//! `lambda_i(r, psi) = l0 + ls r sin(psi) + lc r cos(psi)`.
//!
//! The loads driving it are `ct` (thrust along +z), `cs` = sum of dT r sin(psi) (first moment
//! of thrust toward the advancing side) and `cc` = sum of dT r cos(psi) (first moment toward
//! the aft/downstream side), see [`DiskLoads`].
//!
//! # Sources
//! - Glauert, H. (1926), "A general theory of the autogyro", ARC R&M 1111: momentum inflow
//!   `l0 = ct / (2 sqrt(mu^2 + (lambda_free + l0)^2))`.
//! - Drees, J. M. (1949), "A theory of airflow through rotors and its application to some
//!   helicopter problems", J. Helicopter Association of Great Britain 3(2); linear inflow
//!   `lambda_i = l0 (1 + kx r cos psi + ky r sin psi)`, kx = (4/3)(1 - cos chi - 1.8 mu^2) /
//!   sin chi, ky = -2 mu, as quoted by Johnson, *Helicopter Theory* (1980) and *Rotorcraft
//!   Aeromechanics* (2013).
//! - Pitt, D. M. and Peters, D. A. (1981), "Theoretical prediction of dynamic-inflow
//!   derivatives", Vertica 5(1), 21-34; Peters, D. A. and HaQuang, N. (1988), "Dynamic inflow
//!   for practical applications", J. American Helicopter Society 33(4), 64-68:
//!   `M dl/dpsi + V L^-1 l = (ct, cs, cc)`, M = diag(8/(3 pi), 16/(45 pi), 16/(45 pi)),
//!   V = diag(V_T, V, V), V_T = sqrt(mu^2 + lambda^2), V = (mu^2 + lambda (lambda + l0)) / V_T,
//!   lambda = lambda_free + l0, and L below (see [`pitt_peters_l`]).
//!
//! # The L matrix in these coordinates
//! With X = tan(chi / 2), chi = atan(mu / lambda) the wake skew angle, states (l0, ls, lc) and
//! loads (ct, cs, cc):
//! ```text
//!       | 1/2            0              -(15 pi/64) X    |
//!   L = | 0              4/(1+cos chi)   0               |
//!       | (15 pi/64) X   0               4 cos chi/(1+cos chi) |
//! ```
//! The published form is written against the aerodynamic roll and pitch moments (C_L, C_M),
//! with L symmetric and minus signs on the moment diagonals. Here the moment "loads" are first
//! moments of thrust: a thrust moment toward the advancing side is a negative roll moment
//! (cs = -C_L) and a thrust moment aft is a nose-down pitch moment (cc = -C_M). Substituting
//! flips the sign of the moment columns of L: the diagonal becomes positive (more thrust on a
//! side, more inflow there) and the coupling becomes antisymmetric. The (3,1) term stays
//! +(15 pi/64) X, so a thrust-only loading gives lc = (15 pi/32) tan(chi/2) l0 > 0 (more
//! inflow aft, the classical skewed-wake result); the (1,3) term is -(15 pi/64) X: thrust
//! moved forward (cc < 0) puts its wake over the disk and raises the mean inflow. The
//! determinant of the (l0, lc) block, 2 cos chi/(1+cos chi) + (15 pi/64)^2 X^2, is then
//! positive for every skew angle, so the dynamics stay stable up to edgewise flow.
//!
//! The skew angle is limited to 90 deg: a net up-flow through the disk (lambda < 0, the
//! vortex-ring and windmill-brake states) is outside these models; there chi is held at
//! 90 deg (or 0 in purely axial flow).
// Small fixed-size matrices: index loops read like the formulas.
#![allow(clippy::needless_range_loop)]
use std::f64::consts::PI;
use std::str::FromStr;

/// Which inflow model.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum InflowModel {
    /// Uniform inflow from Glauert's momentum theory (quasi-steady).
    Uniform,
    /// Glauert's mean inflow with Drees' linear skewed-wake shape (quasi-steady).
    Drees,
    /// Pitt-Peters three-state dynamic inflow.
    PittPeters,
}

impl InflowModel {
    pub fn name(self) -> &'static str {
        match self {
            InflowModel::Uniform => "uniform",
            InflowModel::Drees => "drees",
            InflowModel::PittPeters => "pitt-peters",
        }
    }
}

impl FromStr for InflowModel {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        match s {
            "uniform" => Ok(InflowModel::Uniform),
            "drees" => Ok(InflowModel::Drees),
            "pitt-peters" => Ok(InflowModel::PittPeters),
            _ => Err(format!(
                "unknown inflow model '{s}' (expected uniform, drees or pitt-peters)"
            )),
        }
    }
}

/// Rotor aerodynamic loads as coefficients: thrust `ct` = T / (rho pi R^2 (Omega R)^2) along
/// +z; `cs` = sum dT r sin(psi) / (rho pi R^2 (Omega R)^2 R) (first moment of thrust toward the
/// advancing side); `cc` the same with r cos(psi) (toward the aft/downstream side).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct DiskLoads {
    pub ct: f64,
    pub cs: f64,
    pub cc: f64,
}

/// Flight condition in the hub frame: advance ratio `mu` (free stream along +x in Omega R
/// units) and the free-stream inflow `lambda_free` (positive down through the disk).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FlightCondition {
    pub mu: f64,
    pub lambda_free: f64,
}

/// Pitt-Peters apparent-mass matrix diagonal, M = diag(8/(3 pi), 16/(45 pi), 16/(45 pi))
/// (Pitt & Peters 1981).
pub const PITT_PETERS_M: [f64; 3] = [8.0 / (3.0 * PI), 16.0 / (45.0 * PI), 16.0 / (45.0 * PI)];

/// 15 pi / 64, the skew coupling coefficient of the Pitt-Peters L matrix.
const SKEW_COUPLING: f64 = 15.0 * PI / 64.0;

/// Glauert's momentum inflow: the l0 with `l0 = ct / (2 sqrt(mu^2 + (lambda_free + l0)^2))`,
/// solved by Newton's method safeguarded by bisection on a bracket of the root (converged to
/// round-off, a relative step below 1e-15). Hover (mu = 0, lambda_free = 0) gives sqrt(ct/2).
///
/// A negative `ct` returns the root of the same equation, of the sign of `ct`
/// (`-sqrt(|ct|/2)` in hover); the windmill-brake and vortex-ring states are not modelled.
/// Where the equation has several roots (lambda_free < 0 at low mu) one of them is returned.
pub fn momentum_inflow(ct: f64, cond: FlightCondition) -> f64 {
    momentum_root(ct, 0.0, cond)
}

/// The momentum inflow of a rotor whose thrust depends on it: the l0 with
/// `l0 = ct(l0) / (2 sqrt(mu^2 + (lambda_free + l0)^2))`, `ct(l) = ct_ref + dct_dl0 (l - l0_ref)`
/// (the blades' thrust `ct_ref` at inflow `l0_ref` and its derivative with respect to a change
/// of the inflow, negative: more inflow, less lift). `dct_dl0 = 0` is [`momentum_inflow`];
/// a positive derivative is taken as 0.
pub fn momentum_inflow_coupled(
    ct_ref: f64,
    dct_dl0: f64,
    l0_ref: f64,
    cond: FlightCondition,
) -> f64 {
    let d = if dct_dl0.is_finite() {
        dct_dl0.min(0.0)
    } else {
        0.0
    };
    if d == 0.0 {
        return momentum_inflow(ct_ref, cond);
    }
    momentum_root(ct_ref - d * l0_ref, d, cond)
}

/// The root l of `2 l sqrt(mu^2 + (lambda_free + l)^2) - d l - c0` (`d <= 0`), see
/// [`momentum_inflow`] (d = 0) and [`momentum_inflow_coupled`].
fn momentum_root(c0: f64, d: f64, cond: FlightCondition) -> f64 {
    if c0 == 0.0 || !c0.is_finite() {
        return if c0.is_finite() { 0.0 } else { f64::NAN };
    }
    let ct = c0;
    let (mu, lf) = (cond.mu, cond.lambda_free);
    // g(l) = 2 l sqrt(mu^2 + (lf + l)^2) - d l - ct; g(0) = -ct, so a root lies on ct's side
    // of 0.
    let g = |l: f64| 2.0 * l * mu.hypot(lf + l) - d * l - ct;
    let sign = ct.signum();
    let hover = sign * (0.5 * ct.abs()).sqrt();
    // bracket [a, b]: sign * g(a) < 0 (a = 0), sign * g(b) >= 0 (grown from the hover value)
    let mut b = hover;
    while sign * g(b) < 0.0 {
        b *= 2.0;
        if !b.is_finite() {
            return f64::NAN;
        }
    }
    let mut a = 0.0_f64;
    // first guess: the hover value corrected for the free stream
    let mut l = ct / (2.0 * mu.hypot(lf + hover) - d);
    if !(l.is_finite() && (l - a) * (l - b) < 0.0) {
        l = 0.5 * (a + b);
    }
    for _ in 0..200 {
        let s = mu.hypot(lf + l);
        let gl = 2.0 * l * s - d * l - ct;
        if gl == 0.0 {
            break;
        }
        if sign * gl < 0.0 {
            a = l;
        } else {
            b = l;
        }
        let dg = if s > 0.0 {
            2.0 * s + 2.0 * l * (lf + l) / s - d
        } else {
            -d
        };
        let mut next = l - gl / dg;
        if !(next.is_finite() && (next - a) * (next - b) <= 0.0) {
            next = 0.5 * (a + b);
        }
        let step = next - l;
        l = next;
        if step.abs() <= 1e-15 * l.abs() {
            break;
        }
    }
    l
}

/// Wake skew angle chi = atan(mu / lambda) (radians) for the total inflow `lambda_total` =
/// lambda_free + l0, held at 90 deg when lambda_total <= 0 with mu > 0 and 0 in axial flow.
pub fn skew_angle(mu: f64, lambda_total: f64) -> f64 {
    let mu = mu.abs();
    if mu == 0.0 {
        0.0
    } else {
        mu.atan2(lambda_total.max(0.0))
    }
}

/// Drees' linear inflow shape (Drees 1949, as quoted by Johnson): returns (kx, ky) with
/// `lambda_i = l0 (1 + kx r cos psi + ky r sin psi)`, kx = (4/3)(1 - cos chi - 1.8 mu^2) /
/// sin chi, ky = -2 mu, chi = [`skew_angle`]`(mu, lambda_total)`. In axial flow (sin chi = 0,
/// mu = 0) the limit kx = 0 is returned.
pub fn drees_shape(mu: f64, lambda_total: f64) -> (f64, f64) {
    let chi = skew_angle(mu, lambda_total);
    let kx = if mu == 0.0 {
        0.0
    } else {
        // (1 - cos chi)/sin chi = tan(chi/2), which avoids the cancellation at small chi
        (4.0 / 3.0) * ((0.5 * chi).tan() - 1.8 * mu * mu / chi.sin())
    };
    (kx, -2.0 * mu)
}

/// Pitt-Peters mass-flow parameters (V_T, V) at mean inflow `l0`: V_T = sqrt(mu^2 + lambda^2)
/// for the thrust row, V = (mu^2 + lambda (lambda + l0)) / V_T for the moment rows, lambda =
/// lambda_free + l0 (Peters & HaQuang 1988). Both are 0 when V_T = 0.
pub fn mass_flow(cond: FlightCondition, l0: f64) -> (f64, f64) {
    let c = pp_coeffs(cond, l0);
    (c.d[0], c.d[1])
}

/// The Pitt-Peters L matrix for states (l0, ls, lc) and loads (ct, cs, cc) in this module's
/// conventions (see the module documentation for the signs), at skew angle
/// [`skew_angle`]`(mu, lambda_total)`.
pub fn pitt_peters_l(mu: f64, lambda_total: f64) -> [[f64; 3]; 3] {
    let chi = skew_angle(mu, lambda_total);
    let (c, x) = (chi.cos(), (0.5 * chi).tan());
    let b = SKEW_COUPLING * x;
    [
        [0.5, 0.0, -b],
        [0.0, 4.0 / (1.0 + c), 0.0],
        [b, 0.0, 4.0 * c / (1.0 + c)],
    ]
}

/// Mass flow, L^-1 and their derivatives with respect to l0 at one l0.
struct PpCoeffs {
    /// V = diag(V_T, V, V)
    d: [f64; 3],
    dd: [f64; 3],
    /// L^-1
    k: [[f64; 3]; 3],
    dk: [[f64; 3]; 3],
}

fn pp_coeffs(cond: FlightCondition, l0: f64) -> PpCoeffs {
    let mu = cond.mu.abs();
    let lam = cond.lambda_free + l0;
    let vt = mu.hypot(lam);
    let (v, dvt, dv) = if vt > 0.0 {
        let dvt = lam / vt;
        let num = mu * mu + lam * (lam + l0);
        let dnum = 3.0 * lam + l0;
        (num / vt, dvt, (dnum * vt - num * dvt) / (vt * vt))
    } else {
        (0.0, 0.0, 0.0)
    };
    // cos chi, X = tan(chi/2) and their derivatives (chi limited to [0, 90 deg])
    let (c, dc, x, dx) = if lam > 0.0 && vt > 0.0 {
        let s = vt + lam;
        (
            lam / vt,
            mu * mu / (vt * vt * vt),
            mu / s,
            -mu * (dvt + 1.0) / (s * s),
        )
    } else if mu > 0.0 {
        (0.0, 0.0, 1.0, 0.0)
    } else {
        (1.0, 0.0, 0.0, 0.0)
    };
    let b = SKEW_COUPLING * x;
    let db = SKEW_COUPLING * dx;
    let op = 1.0 + c;
    let p = 4.0 / op;
    let dp = -4.0 * dc / (op * op);
    let q = 4.0 * c / op;
    let dq = 4.0 * dc / (op * op);
    // (l0, lc) block of L: [[1/2, -b], [b, q]], det = q/2 + b^2 > 0
    let det = 0.5 * q + b * b;
    let ddet = 0.5 * dq + 2.0 * b * db;
    let inv = 1.0 / det;
    let dinv = -ddet * inv * inv;
    let k = [
        [q * inv, 0.0, b * inv],
        [0.0, 1.0 / p, 0.0],
        [-b * inv, 0.0, 0.5 * inv],
    ];
    let dk = [
        [dq * inv + q * dinv, 0.0, db * inv + b * dinv],
        [0.0, -dp / (p * p), 0.0],
        [-db * inv - b * dinv, 0.0, 0.5 * dinv],
    ];
    PpCoeffs {
        d: [vt, v, v],
        dd: [dvt, dv, dv],
        k,
        dk,
    }
}

/// G(l) = V(l0) L(l0)^-1 l and its Jacobian dG/dl.
fn pp_g(cond: FlightCondition, l: &[f64; 3]) -> ([f64; 3], [[f64; 3]; 3]) {
    let c = pp_coeffs(cond, l[0]);
    let mut g = [0.0; 3];
    let mut jac = [[0.0; 3]; 3];
    for i in 0..3 {
        let mut kl = 0.0;
        let mut dkl = 0.0;
        for m in 0..3 {
            kl += c.k[i][m] * l[m];
            dkl += c.dk[i][m] * l[m];
            jac[i][m] = c.d[i] * c.k[i][m];
        }
        g[i] = c.d[i] * kl;
        jac[i][0] += c.dd[i] * kl + c.d[i] * dkl;
    }
    (g, jac)
}

/// Solves a 3x3 system by Gaussian elimination with partial pivoting; None if singular.
fn solve3(mut a: [[f64; 3]; 3], mut b: [f64; 3]) -> Option<[f64; 3]> {
    for col in 0..3 {
        let piv = (col..3)
            .max_by(|&i, &j| a[i][col].abs().total_cmp(&a[j][col].abs()))
            .unwrap_or(col);
        if a[piv][col] == 0.0 || !a[piv][col].is_finite() {
            return None;
        }
        a.swap(col, piv);
        b.swap(col, piv);
        for row in col + 1..3 {
            let f = a[row][col] / a[col][col];
            for k in col..3 {
                a[row][k] -= f * a[col][k];
            }
            b[row] -= f * b[col];
        }
    }
    let mut x = [0.0; 3];
    for row in (0..3).rev() {
        let mut s = b[row];
        for k in row + 1..3 {
            s -= a[row][k] * x[k];
        }
        x[row] = s / a[row][row];
    }
    Some(x)
}

type Mat4 = [[f64; 4]; 4];

fn matmul4(a: &Mat4, b: &Mat4) -> Mat4 {
    let mut c = [[0.0; 4]; 4];
    for i in 0..4 {
        for k in 0..4 {
            let aik = a[i][k];
            if aik != 0.0 {
                for j in 0..4 {
                    c[i][j] += aik * b[k][j];
                }
            }
        }
    }
    c
}

/// Matrix exponential of a 4x4 matrix: scaling to a norm <= 1/2, Taylor series to degree 18
/// (truncation below 1e-21 relative), squaring back.
fn expm4(a: &Mat4) -> Mat4 {
    let norm = a
        .iter()
        .map(|row| row.iter().map(|v| v.abs()).sum::<f64>())
        .fold(0.0, f64::max);
    let squarings = if norm > 0.5 {
        (norm / 0.5).log2().ceil().min(1000.0) as i32
    } else {
        0
    };
    let scale = 0.5_f64.powi(squarings);
    let mut x = [[0.0; 4]; 4];
    for i in 0..4 {
        for j in 0..4 {
            x[i][j] = a[i][j] * scale;
        }
    }
    let mut sum = [[0.0; 4]; 4];
    let mut term = [[0.0; 4]; 4];
    for i in 0..4 {
        sum[i][i] = 1.0;
        term[i][i] = 1.0;
    }
    for n in 1..=18 {
        term = matmul4(&term, &x);
        let inv = 1.0 / f64::from(n);
        for i in 0..4 {
            for j in 0..4 {
                term[i][j] *= inv;
                sum[i][j] += term[i][j];
            }
        }
    }
    for _ in 0..squarings {
        sum = matmul4(&sum, &sum);
    }
    sum
}

/// Steady Pitt-Peters state: Newton on V(l0) L(l0)^-1 l = F from the momentum solution.
fn pitt_peters_steady(cond: FlightCondition, f: &[f64; 3]) -> [f64; 3] {
    let l0 = momentum_inflow(f[0], cond);
    let mut l = [l0, 0.0, 0.0];
    if f.iter().all(|v| *v == 0.0) {
        return [0.0; 3];
    }
    // the thrust-only part of the closed form as the start: lc = (15 pi/32) X l0
    let lam = cond.lambda_free + l0;
    let x = (0.5 * skew_angle(cond.mu, lam)).tan();
    l[2] = 2.0 * SKEW_COUPLING * x * l0;
    let resid = |l: &[f64; 3]| {
        let (g, _) = pp_g(cond, l);
        (0..3).map(|i| (g[i] - f[i]).abs()).fold(0.0, f64::max)
    };
    let mut r = resid(&l);
    for _ in 0..100 {
        let (g, jac) = pp_g(cond, &l);
        let rhs = [f[0] - g[0], f[1] - g[1], f[2] - g[2]];
        let Some(dl) = solve3(jac, rhs) else { break };
        // backtracking on the residual
        let mut t = 1.0;
        let mut next = l;
        let mut r_next = f64::INFINITY;
        for _ in 0..40 {
            for i in 0..3 {
                next[i] = l[i] + t * dl[i];
            }
            r_next = resid(&next);
            if r_next <= r {
                break;
            }
            t *= 0.5;
        }
        if r_next.is_nan() || r_next > r {
            // no descent possible: converged to round-off
            break;
        }
        let size = l.iter().map(|v| v.abs()).fold(0.0, f64::max);
        let step = (0..3).map(|i| (next[i] - l[i]).abs()).fold(0.0, f64::max);
        l = next;
        r = r_next;
        if step <= 1e-15 * size || r == 0.0 {
            break;
        }
    }
    l
}

/// Rotor inflow: model, flight condition and the three inflow states (l0, ls, lc).
#[derive(Clone, Debug)]
pub struct Inflow {
    model: InflowModel,
    cond: FlightCondition,
    /// (l0, ls, lc)
    state: [f64; 3],
}

impl Inflow {
    /// An inflow at zero thrust (state zero); see [`Inflow::with_thrust`].
    pub fn new(model: InflowModel, cond: FlightCondition) -> Self {
        Inflow {
            model,
            cond,
            state: Self::steady(model, cond, &DiskLoads::default()),
        }
    }

    /// Starts from the steady state for a thrust-only loading `ct` (the momentum value of l0).
    pub fn with_thrust(mut self, ct: f64) -> Self {
        self.state = Self::steady(
            self.model,
            self.cond,
            &DiskLoads {
                ct,
                ..DiskLoads::default()
            },
        );
        self
    }

    pub fn model(&self) -> InflowModel {
        self.model
    }

    pub fn condition(&self) -> FlightCondition {
        self.cond
    }

    /// Changes the flight condition (the states are kept).
    pub fn set_condition(&mut self, cond: FlightCondition) {
        self.cond = cond;
    }

    /// Induced inflow at (r/R, psi): lambda_i, positive down.
    pub fn lambda_i(&self, r: f64, psi_rad: f64) -> f64 {
        let (s, c) = psi_rad.sin_cos();
        self.state[0] + r * (self.state[1] * s + self.state[2] * c)
    }

    /// [`Inflow::lambda_i`] at the disk point `(x, y) / R` (x = r cos psi, y = r sin psi): the
    /// same value without the trigonometry (the hot loop's form).
    pub fn lambda_i_at(&self, x: f64, y: f64) -> f64 {
        self.state[0] + self.state[1] * y + self.state[2] * x
    }

    /// Advances by `dpsi` (= Omega dt, >= 0) under loads `l` held over the step, lagged: the
    /// loads do not respond to the new inflow ([`Inflow::advance_coupled`] with a zero
    /// derivative). A quasi-steady model fed back this way is a fixed-point iteration whose
    /// gain exceeds 1 at light loading (every-step oscillation): rotors use
    /// [`Inflow::advance_coupled`].
    pub fn advance(&mut self, dpsi: f64, l: &DiskLoads) {
        self.advance_coupled(dpsi, l, 0.0);
    }

    /// Advances by `dpsi` (= Omega dt, >= 0) under loads `l` (the blades' loads at the current
    /// inflow) which respond to a change of the mean inflow l0 as `ct + dct_dl0 (l0' - l0)`
    /// (`dct_dl0 <= 0`, the lifting line's derivative at the step).
    ///
    /// Uniform and Drees are quasi-steady: l0 solves the momentum equation together with the
    /// linearised thrust ([`momentum_inflow_coupled`], Newton), Drees' shape at that l0; at
    /// constant loads the state is the steady one for `l`. Pitt-Peters integrates
    /// `M dl/dpsi = F(l0) - V(l0) L(l0)^-1 l` with the exponential Rosenbrock-Euler scheme,
    /// `l += dpsi phi1(dpsi J) f(l)` (J the Jacobian of the right-hand side at the start of the
    /// step, thrust derivative included, phi1(z) = (e^z - 1)/z evaluated through the
    /// exponential of the 4x4 augmented matrix): exact for the linearised system, second order,
    /// its fixed points are exactly the steady solutions, and as dpsi grows it tends to a
    /// Newton step on the steady equation, so it is stable for any dpsi. Does not allocate.
    pub fn advance_coupled(&mut self, dpsi: f64, l: &DiskLoads, dct_dl0: f64) {
        let d = if dct_dl0.is_finite() {
            dct_dl0.min(0.0)
        } else {
            0.0
        };
        match self.model {
            InflowModel::Uniform => {
                let l0 = momentum_inflow_coupled(l.ct, d, self.state[0], self.cond);
                self.state = [l0, 0.0, 0.0];
            }
            InflowModel::Drees => {
                let l0 = momentum_inflow_coupled(l.ct, d, self.state[0], self.cond);
                let (kx, ky) = drees_shape(self.cond.mu, self.cond.lambda_free + l0);
                self.state = [l0, ky * l0, kx * l0];
            }
            InflowModel::PittPeters => {
                if dpsi <= 0.0 || !dpsi.is_finite() {
                    return;
                }
                let f = [l.ct, l.cs, l.cc];
                let (g, jac) = pp_g(self.cond, &self.state);
                let mut aug = [[0.0; 4]; 4];
                for i in 0..3 {
                    let minv = dpsi / PITT_PETERS_M[i];
                    for j in 0..3 {
                        aug[i][j] = -minv * jac[i][j];
                    }
                    aug[i][3] = minv * (f[i] - g[i]);
                }
                aug[0][0] += dpsi / PITT_PETERS_M[0] * d;
                let e = expm4(&aug);
                for i in 0..3 {
                    self.state[i] += e[i][3];
                }
            }
        }
    }

    /// The states (l0, ls, lc).
    pub fn state(&self) -> [f64; 3] {
        self.state
    }

    pub fn set_state(&mut self, s: [f64; 3]) {
        self.state = s;
    }

    /// Steady solution for loads `l` (what [`Inflow::advance`] converges to under constant
    /// loads). Uniform: (momentum l0, 0, 0); Drees: momentum l0 with Drees' shape; Pitt-Peters:
    /// `l = L V^-1 F` solved by Newton with V and L at the solution's l0 (for a thrust-only
    /// loading l0 is Glauert's momentum inflow).
    pub fn steady(model: InflowModel, cond: FlightCondition, l: &DiskLoads) -> [f64; 3] {
        match model {
            InflowModel::Uniform => [momentum_inflow(l.ct, cond), 0.0, 0.0],
            InflowModel::Drees => {
                let l0 = momentum_inflow(l.ct, cond);
                let (kx, ky) = drees_shape(cond.mu, cond.lambda_free + l0);
                [l0, ky * l0, kx * l0]
            }
            InflowModel::PittPeters => pitt_peters_steady(cond, &[l.ct, l.cs, l.cc]),
        }
    }

    /// Wake skew angle chi = atan(mu / lambda) at the current total inflow (radians).
    pub fn skew_angle_rad(&self) -> f64 {
        skew_angle(self.cond.mu, self.total_lambda())
    }

    /// lambda_free + l0.
    pub fn total_lambda(&self) -> f64 {
        self.cond.lambda_free + self.state[0]
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn cond(mu: f64, lf: f64) -> FlightCondition {
        FlightCondition {
            mu,
            lambda_free: lf,
        }
    }

    #[test]
    fn names_round_trip() {
        for m in [
            InflowModel::Uniform,
            InflowModel::Drees,
            InflowModel::PittPeters,
        ] {
            assert_eq!(m.name().parse::<InflowModel>().unwrap(), m);
        }
        assert!("peters".parse::<InflowModel>().is_err());
    }

    /// L^-1 as built against the L of `pitt_peters_l`, in hover and forward flight.
    #[test]
    fn l_inverse_is_the_inverse() {
        for (mu, lf) in [(0.0, 0.0), (0.1, 0.01), (0.3, 0.02), (0.3, -0.05)] {
            let c = cond(mu, lf);
            let l0 = 0.03;
            let lmat = pitt_peters_l(mu, lf + l0);
            let k = pp_coeffs(c, l0).k;
            for i in 0..3 {
                for j in 0..3 {
                    let p: f64 = (0..3).map(|m| lmat[i][m] * k[m][j]).sum();
                    let want = if i == j { 1.0 } else { 0.0 };
                    assert!((p - want).abs() < 1e-14, "mu {mu}: ({i},{j}) {p}");
                }
            }
        }
    }

    /// The closed-form Jacobian of V L^-1 l against central differences.
    #[test]
    fn jacobian_against_differences() {
        for (mu, lf) in [(0.0, 0.0), (0.05, 0.01), (0.2, 0.02), (0.4, 0.03)] {
            let c = cond(mu, lf);
            let l = [0.04, 0.01, -0.015];
            let (_, jac) = pp_g(c, &l);
            for j in 0..3 {
                let h = 1e-6;
                let (mut lp, mut lm) = (l, l);
                lp[j] += h;
                lm[j] -= h;
                let (gp, _) = pp_g(c, &lp);
                let (gm, _) = pp_g(c, &lm);
                for i in 0..3 {
                    let fd = (gp[i] - gm[i]) / (2.0 * h);
                    assert!(
                        (fd - jac[i][j]).abs() < 1e-7 * (1.0 + jac[i][j].abs()),
                        "mu {mu}: d{i}/d{j} fd {fd} closed {}",
                        jac[i][j]
                    );
                }
            }
        }
    }

    /// expm of a diagonal and of a nilpotent (phi1 column) matrix.
    #[test]
    fn expm4_known_cases() {
        let mut a = [[0.0; 4]; 4];
        a[0][0] = -3.0;
        a[1][1] = 0.5;
        a[2][2] = -40.0;
        a[0][3] = 2.0; // phi1 column: 2 (e^-3 - 1)/(-3)
        let e = expm4(&a);
        // scaling by 2^-7 and squaring back: round-off grows to ~2^7 eps relative
        let rel = |x: f64, y: f64| (x - y).abs() / y.abs();
        assert!(rel(e[0][0], (-3.0f64).exp()) < 1e-13);
        assert!(rel(e[1][1], 0.5f64.exp()) < 1e-13);
        assert!(rel(e[2][2], (-40.0f64).exp()) < 1e-12);
        let want = 2.0 * ((-3.0f64).exp() - 1.0) / -3.0;
        assert!(rel(e[0][3], want) < 1e-13, "{} vs {want}", e[0][3]);
        assert_eq!(e[3][3], 1.0);
    }

    /// The coupled momentum inflow solves its equation, is the momentum inflow of its own
    /// thrust, and the momentum inflow without a derivative.
    #[test]
    fn coupled_momentum_inflow_solves_with_the_linearised_thrust() {
        for (mu, lf) in [(0.0, 0.0), (0.05, 0.0), (0.3, 0.01)] {
            let c = cond(mu, lf);
            let (ct, d, l_ref) = (0.004, -0.1, 0.02);
            let l = momentum_inflow_coupled(ct, d, l_ref, c);
            let ct_l = ct + d * (l - l_ref);
            assert!((2.0 * l * mu.hypot(lf + l) - ct_l).abs() < 1e-15, "mu {mu}");
            assert!((l - momentum_inflow(ct_l, c)).abs() < 1e-15);
            assert_eq!(
                momentum_inflow_coupled(ct, 0.0, l_ref, c),
                momentum_inflow(ct, c)
            );
            // a positive derivative is taken as none
            assert_eq!(
                momentum_inflow_coupled(ct, 0.1, l_ref, c),
                momentum_inflow(ct, c)
            );
        }
    }

    /// A thrust falling with the inflow (CT = c0 - G l0) in hover, fed back step after step:
    /// lagged, the gain G / (4 l0) above 1 flips the inflow every step; coupled, the first step
    /// lands on the consistent inflow.
    #[test]
    fn coupled_update_has_no_every_step_oscillation() {
        let c = cond(0.0, 0.0);
        let (c0, g) = (0.004, 0.3);
        let consistent = momentum_inflow_coupled(c0, -g, 0.0, c);
        assert!(g / (4.0 * consistent) > 1.0);
        let mut lagged = Inflow::new(InflowModel::Uniform, c);
        let mut coupled = lagged.clone();
        let mut lag = vec![];
        for _ in 0..20 {
            let l = lagged.state()[0];
            lagged.advance(
                0.01,
                &DiskLoads {
                    ct: c0 - g * l,
                    ..Default::default()
                },
            );
            lag.push(lagged.state()[0]);
            let l = coupled.state()[0];
            coupled.advance_coupled(
                0.01,
                &DiskLoads {
                    ct: c0 - g * l,
                    ..Default::default()
                },
                -g,
            );
            assert!((coupled.state()[0] - consistent).abs() < 1e-14);
        }
        let flips = lag
            .windows(2)
            .filter(|w| (w[1] - w[0]).abs() > 0.1 * consistent)
            .count();
        assert!(flips > 10, "{lag:?}");
    }

    #[test]
    fn solve3_solves() {
        let a = [[2.0, 1.0, 0.0], [0.0, 0.0, 3.0], [1.0, 4.0, 1.0]];
        let x = solve3(a, [1.0, 2.0, 3.0]).unwrap();
        for i in 0..3 {
            let s: f64 = (0..3).map(|j| a[i][j] * x[j]).sum();
            assert!((s - [1.0, 2.0, 3.0][i]).abs() < 1e-14);
        }
        assert!(solve3([[0.0; 3]; 3], [1.0; 3]).is_none());
    }
}
