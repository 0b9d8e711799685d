//! Sub-step integrators for the hydraulic states. Schemes are data: an explicit Butcher
//! tableau (classical RK4, the paper's scheme, Ref. 12) and a singly diagonally implicit tableau
//! (Alexander's 3-stage SDIRK, order 3, L-stable, stiffly accurate) solved by Newton on the
//! small state with the system's analytic Jacobian. Everything lives on the stack.
// Tableau sums read best as index loops over (i, j).
#![allow(clippy::needless_range_loop)]
use super::HydraulicError;
use nalgebra::{SMatrix, SVector};

/// Which sub-step scheme integrates the hydraulic states.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Scheme {
    /// Classical 4th-order Runge-Kutta, fixed sub-steps (the paper's scheme).
    #[default]
    Rk4,
    /// 3-stage L-stable SDIRK (order 3) with Newton iterations on the small state.
    Implicit,
}

impl std::str::FromStr for Scheme {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        match s {
            "rk4" => Ok(Self::Rk4),
            "implicit" | "sdirk3" => Ok(Self::Implicit),
            _ => Err(format!(
                "unknown integrator '{s}' (expected rk4 or implicit)"
            )),
        }
    }
}

/// Integrator selection: scheme and number of sub-steps per structural step.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct IntegratorOptions {
    pub scheme: Scheme,
    pub substeps: usize,
}

impl Default for IntegratorOptions {
    /// RK4 with N = 25 sub-steps, as in the paper's rotor simulation.
    fn default() -> Self {
        Self {
            scheme: Scheme::Rk4,
            substeps: 25,
        }
    }
}

/// An ODE `y' = f(t, y)` on a small fixed-size state, with constraints applied by projection
/// after every sub-step (e.g. a relief valve poppet cannot go through its seat).
pub trait OdeSystem<const N: usize> {
    /// f(t, y).
    fn rhs(&self, t: f64, y: &SVector<f64, N>) -> Result<SVector<f64, N>, HydraulicError>;
    /// df/dy at (t, y), consistent with `rhs` (same contact branch).
    fn jacobian(&self, t: f64, y: &SVector<f64, N>) -> Result<SMatrix<f64, N, N>, HydraulicError>;
    /// Error weight of each component for Newton convergence: atol_i + rtol |y_i|.
    fn weights(&self, y: &SVector<f64, N>) -> SVector<f64, N>;
    /// Project onto the admissible set (default: nothing).
    fn project(&self, _y: &mut SVector<f64, N>) {}
    /// Called at the start of every sub-step of an implicit scheme with its initial state, e.g.
    /// to freeze contact conditions over the sub-step (default: nothing).
    fn begin_implicit_substep(&mut self, _t: f64, _y: &SVector<f64, N>) {}
    /// Called with the (projected) state at the end of every sub-step, e.g. to record what
    /// moves faster than the step (default: nothing). Must not allocate.
    fn end_substep(&mut self, _t: f64, _y: &SVector<f64, N>) {}
}

/// Explicit Runge-Kutta tableau (strictly lower triangular `a`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ExplicitTableau<const S: usize> {
    pub a: [[f64; S]; S],
    pub b: [f64; S],
    pub c: [f64; S],
}

/// Classical RK4.
pub const RK4: ExplicitTableau<4> = ExplicitTableau {
    a: [
        [0.0, 0.0, 0.0, 0.0],
        [0.5, 0.0, 0.0, 0.0],
        [0.0, 0.5, 0.0, 0.0],
        [0.0, 0.0, 1.0, 0.0],
    ],
    b: [1.0 / 6.0, 1.0 / 3.0, 1.0 / 3.0, 1.0 / 6.0],
    c: [0.0, 0.5, 0.5, 1.0],
};

/// Singly diagonally implicit tableau (lower triangular `a`, constant diagonal gamma).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SdirkTableau<const S: usize> {
    pub a: [[f64; S]; S],
    pub b: [f64; S],
    pub c: [f64; S],
    pub gamma: f64,
}

const G: f64 = 0.435_866_521_508_459;
const T2: f64 = (1.0 + G) / 2.0;
const B1: f64 = -(6.0 * G * G - 16.0 * G + 1.0) / 4.0;
const B2: f64 = (6.0 * G * G - 20.0 * G + 5.0) / 4.0;

/// Alexander (1977) 3-stage SDIRK: order 3, L-stable, stiffly accurate (last row of `a` = `b`).
pub const SDIRK3: SdirkTableau<3> = SdirkTableau {
    a: [[G, 0.0, 0.0], [T2 - G, G, 0.0], [B1, B2, G]],
    b: [B1, B2, G],
    c: [G, T2, 1.0],
    gamma: G,
};

/// One explicit RK step of size h from (t, y).
#[inline(always)]
pub fn explicit_step<const N: usize, const S: usize>(
    tab: &ExplicitTableau<S>,
    sys: &impl OdeSystem<N>,
    t: f64,
    y: &SVector<f64, N>,
    h: f64,
) -> Result<SVector<f64, N>, HydraulicError> {
    let mut k = [SVector::<f64, N>::zeros(); S];
    for i in 0..S {
        let mut yi = *y;
        for j in 0..i {
            if tab.a[i][j] != 0.0 {
                yi += k[j] * (h * tab.a[i][j]);
            }
        }
        k[i] = sys.rhs(t + tab.c[i] * h, &yi)?;
    }
    let mut out = *y;
    for i in 0..S {
        out += k[i] * (h * tab.b[i]);
    }
    Ok(out)
}

/// [`explicit_step`] with [`RK4`], its stages written out: the same operations in the same
/// order (bit-identical), but the stages' rates stay in registers instead of an indexed array.
#[inline(always)]
pub fn rk4_step<const N: usize>(
    sys: &impl OdeSystem<N>,
    t: f64,
    y: &SVector<f64, N>,
    h: f64,
) -> Result<SVector<f64, N>, HydraulicError> {
    let (a, b, c) = (&RK4.a, &RK4.b, &RK4.c);
    let k1 = sys.rhs(t + c[0] * h, y)?;
    let k2 = sys.rhs(t + c[1] * h, &(y + k1 * (h * a[1][0])))?;
    let k3 = sys.rhs(t + c[2] * h, &(y + k2 * (h * a[2][1])))?;
    let k4 = sys.rhs(t + c[3] * h, &(y + k3 * (h * a[3][2])))?;
    let mut out = *y;
    out += k1 * (h * b[0]);
    out += k2 * (h * b[1]);
    out += k3 * (h * b[2]);
    out += k4 * (h * b[3]);
    Ok(out)
}

/// Newton settings of the implicit scheme.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct NewtonOptions {
    /// Maximum Newton iterations per stage.
    pub max_iter: usize,
    /// Convergence when the weighted RMS norm of the Newton update is below this.
    pub tol: f64,
    /// Reuse the factorized iteration matrix across iterations and stages of a sub-step
    /// (refreshed when convergence slows); `false` (default) = full Newton. Measured on the bench
    /// sweep: no faster than full Newton (more iterations offset the saved Jacobians), see
    /// docs/integrators.md.
    pub simplified: bool,
}

impl Default for NewtonOptions {
    fn default() -> Self {
        Self {
            max_iter: 30,
            tol: 1.0,
            simplified: false,
        }
    }
}

/// LU factorization with partial pivoting of a small fixed-size matrix, on the stack.
#[derive(Debug, Clone, Copy)]
pub struct DenseLu<const N: usize> {
    lu: SMatrix<f64, N, N>,
    piv: [usize; N],
}

impl<const N: usize> DenseLu<N> {
    /// Factorizes `m`; `None` when it is singular or not finite.
    pub fn factor(mut m: SMatrix<f64, N, N>) -> Option<Self> {
        let mut piv = [0; N];
        for c in 0..N {
            let (mut p, mut best) = (c, m[(c, c)].abs());
            for r in c + 1..N {
                if m[(r, c)].abs() > best {
                    p = r;
                    best = m[(r, c)].abs();
                }
            }
            if !(best > 0.0 && best.is_finite()) {
                return None;
            }
            piv[c] = p;
            if p != c {
                m.swap_rows(p, c);
            }
            let d = m[(c, c)];
            for r in c + 1..N {
                let f = m[(r, c)] / d;
                m[(r, c)] = f;
                if f != 0.0 {
                    for k in c + 1..N {
                        m[(r, k)] -= f * m[(c, k)];
                    }
                }
            }
        }
        Some(Self { lu: m, piv })
    }

    /// Solves `m x = b`.
    pub fn solve(&self, mut b: SVector<f64, N>) -> SVector<f64, N> {
        // Whole rows (multipliers included) were swapped while factorizing, so P m = L U:
        // permute b first, then substitute.
        for c in 0..N {
            if self.piv[c] != c {
                b.swap_rows(self.piv[c], c);
            }
        }
        for c in 0..N {
            for r in c + 1..N {
                b[r] -= self.lu[(r, c)] * b[c];
            }
        }
        for c in (0..N).rev() {
            let mut s = b[c];
            for k in c + 1..N {
                s -= self.lu[(c, k)] * b[k];
            }
            b[c] = s / self.lu[(c, c)];
        }
        b
    }
}

/// Solves `m x = b` by Gaussian elimination with partial pivoting, on the stack.
pub fn solve_dense<const N: usize>(
    mut m: SMatrix<f64, N, N>,
    mut b: SVector<f64, N>,
) -> Option<SVector<f64, N>> {
    for c in 0..N {
        let (mut piv, mut best) = (c, m[(c, c)].abs());
        for r in c + 1..N {
            if m[(r, c)].abs() > best {
                piv = r;
                best = m[(r, c)].abs();
            }
        }
        if !(best > 0.0 && best.is_finite()) {
            return None;
        }
        if piv != c {
            m.swap_rows(piv, c);
            b.swap_rows(piv, c);
        }
        let d = m[(c, c)];
        for r in c + 1..N {
            let f = m[(r, c)] / d;
            if f != 0.0 {
                for k in c..N {
                    m[(r, k)] -= f * m[(c, k)];
                }
                b[r] -= f * b[c];
            }
        }
    }
    for c in (0..N).rev() {
        let mut s = b[c];
        for k in c + 1..N {
            s -= m[(c, k)] * b[k];
        }
        b[c] = s / m[(c, c)];
    }
    Some(b)
}

fn wrms<const N: usize>(v: &SVector<f64, N>, w: &SVector<f64, N>) -> f64 {
    let mut s = 0.0;
    for i in 0..N {
        let r = v[i] / w[i];
        s += r * r;
    }
    (s / N as f64).sqrt()
}

/// One SDIRK step of size h from (t, y): for each stage solve
/// `Y_i = y + h sum_{j<i} a_ij f(Y_j) + h gamma f(Y_i)` by Newton with the analytic Jacobian.
/// The first guess of a stage is the previous stage value.
pub fn sdirk_step<const N: usize, const S: usize>(
    tab: &SdirkTableau<S>,
    sys: &impl OdeSystem<N>,
    t: f64,
    y: &SVector<f64, N>,
    h: f64,
    newton: &NewtonOptions,
) -> Result<SVector<f64, N>, HydraulicError> {
    let mut k = [SVector::<f64, N>::zeros(); S];
    let mut guess = *y;
    let hg = h * tab.gamma;
    // Factorization of I - h gamma J, shared by all stages (same matrix in an SDIRK) until a
    // stage asks for a refresh.
    let mut lu: Option<DenseLu<N>> = None;
    for i in 0..S {
        let ti = t + tab.c[i] * h;
        let mut base = *y;
        for j in 0..i {
            base += k[j] * (h * tab.a[i][j]);
        }
        let mut yi = guess;
        let residual = |y: &SVector<f64, N>| -> Result<SVector<f64, N>, HydraulicError> {
            Ok(y - base - sys.rhs(ti, y)? * hg)
        };
        let mut g = residual(&yi)?;
        let g0_norm = wrms(&g, &sys.weights(&yi));
        let mut converged = false;
        let mut last = f64::INFINITY;
        let mut prev: Option<f64> = None;
        let mut refresh = !newton.simplified;
        for it in 1..=newton.max_iter {
            if refresh || lu.is_none() {
                let jac = sys.jacobian(ti, &yi)?;
                let m = SMatrix::<f64, N, N>::identity() - jac * hg;
                lu = Some(
                    DenseLu::factor(m)
                        .ok_or(HydraulicError::SingularJacobian { t: ti, stage: i })?,
                );
                refresh = !newton.simplified;
                prev = None;
            }
            let dy = lu.as_ref().map_or(g, |f| f.solve(-g));
            let w = sys.weights(&yi);
            let g_norm = wrms(&g, &w);
            // Backtracking on the weighted residual: the element laws have kinks (seat, check
            // valve opening, cavitation band) where full Newton steps can cycle.
            let mut lambda = 1.0;
            let (mut y_try, mut g_try);
            loop {
                y_try = yi + dy * lambda;
                g_try = residual(&y_try)?;
                if wrms(&g_try, &w) <= (1.0 - 1e-4 * lambda) * g_norm || lambda < 1.0 / 64.0 {
                    break;
                }
                lambda *= 0.5;
            }
            yi = y_try;
            g = g_try;
            last = wrms(&(dy * lambda), &sys.weights(&yi));
            if !last.is_finite() {
                return Err(HydraulicError::NewtonDiverged {
                    t: ti,
                    stage: i,
                    iteration: it,
                    residual: last,
                });
            }
            // Convergence: quadratic (fresh Jacobian) -> the update bounds the error; linear
            // (reused Jacobian, rate theta) -> the error is about theta/(1 - theta) x update.
            let done = match prev {
                _ if !newton.simplified => last <= newton.tol,
                None => last <= 0.1 * newton.tol,
                Some(p) => {
                    let theta = last / p;
                    if theta >= 0.5 || lambda < 1.0 {
                        refresh = true; // slow or damped: the reused Jacobian is stale
                    }
                    theta < 1.0 && theta / (1.0 - theta) * last <= newton.tol
                }
            };
            // The correction bounds the error (Hairer & Wanner IV.8); the residual must not
            // have grown, or a wrong Jacobian could pass off a tiny correction as convergence.
            if done && wrms(&g, &sys.weights(&yi)) <= g0_norm.max(newton.tol) {
                converged = true;
                break;
            }
            if lambda < 1.0 {
                refresh = true;
            }
            prev = Some(last);
        }
        if !converged {
            return Err(HydraulicError::NewtonDiverged {
                t: ti,
                stage: i,
                iteration: newton.max_iter,
                residual: last,
            });
        }
        // Stage derivative from the stage equation (exact for the converged iterate).
        k[i] = (yi - base) / hg;
        guess = yi;
    }
    let mut out = *y;
    for i in 0..S {
        out += k[i] * (h * tab.b[i]);
    }
    Ok(out)
}

/// Integrate over [t0, t0 + dt] with `n` fixed sub-steps, projecting after each.
pub fn integrate<const N: usize>(
    opts: &IntegratorOptions,
    sys: &mut impl OdeSystem<N>,
    t0: f64,
    dt: f64,
    y0: &SVector<f64, N>,
) -> Result<SVector<f64, N>, HydraulicError> {
    let n = opts.substeps.max(1);
    let h = dt / n as f64;
    let mut y = *y0;
    // One loop per scheme: the scheme is decided once, not at every sub-step.
    match opts.scheme {
        Scheme::Rk4 => {
            for s in 0..n {
                let t = t0 + s as f64 * h;
                y = rk4_step(sys, t, &y, h)?;
                end_substep(sys, t0, y0, t, h, &mut y)?;
            }
        }
        Scheme::Implicit => {
            let newton = NewtonOptions::default();
            for s in 0..n {
                let t = t0 + s as f64 * h;
                sys.begin_implicit_substep(t, &y);
                y = sdirk_step(&SDIRK3, sys, t, &y, h, &newton)?;
                end_substep(sys, t0, y0, t, h, &mut y)?;
            }
        }
    }
    Ok(y)
}

/// The end of a sub-step of [`integrate`] from `t`: projection, the system's hook, and an error
/// when the state is no longer finite.
#[inline(always)]
fn end_substep<const N: usize>(
    sys: &mut impl OdeSystem<N>,
    t0: f64,
    y0: &SVector<f64, N>,
    t: f64,
    h: f64,
    y: &mut SVector<f64, N>,
) -> Result<(), HydraulicError> {
    sys.project(y);
    sys.end_substep(t + h, y);
    match y.iter().position(|v| !v.is_finite()) {
        None => Ok(()),
        Some(c) => Err(HydraulicError::NonFinite {
            t: t + h,
            component: c,
            substep_s: h,
            rate_per_s: fastest_rate(sys, t0, y0),
        }),
    }
}

/// The fastest rate of `sys` at (t, y), max |df_i/dy_i| [1/s] (NaN when the Jacobian cannot be
/// had): the diagonal is in consistent units whatever the state's, and for the chamber
/// pressures it is the stiff `B/V dQ/dp` that limits an explicit sub-step. Only on failure,
/// at the step's starting state (the last iterates before a blow-up say nothing).
pub fn fastest_rate<const N: usize>(sys: &impl OdeSystem<N>, t: f64, y: &SVector<f64, N>) -> f64 {
    match sys.jacobian(t, y) {
        Ok(j) => (0..N)
            .map(|i| j[(i, i)].abs())
            .filter(|v| v.is_finite())
            .fold(f64::NAN, f64::max),
        Err(_) => f64::NAN,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// y' = -lambda (y - cos t): stiff linear test problem with a known solution.
    struct Prothero {
        lambda: f64,
    }
    impl OdeSystem<1> for Prothero {
        fn rhs(&self, t: f64, y: &SVector<f64, 1>) -> Result<SVector<f64, 1>, HydraulicError> {
            Ok(SVector::<f64, 1>::new(
                -self.lambda * (y[0] - t.cos()) - t.sin(),
            ))
        }
        fn jacobian(
            &self,
            _t: f64,
            _y: &SVector<f64, 1>,
        ) -> Result<SMatrix<f64, 1, 1>, HydraulicError> {
            Ok(SMatrix::<f64, 1, 1>::new(-self.lambda))
        }
        fn weights(&self, _y: &SVector<f64, 1>) -> SVector<f64, 1> {
            SVector::<f64, 1>::new(1e-12)
        }
    }

    fn err(scheme: Scheme, n: usize, lambda: f64) -> f64 {
        let mut sys = Prothero { lambda };
        let y0 = SVector::<f64, 1>::new(1.0);
        let o = IntegratorOptions {
            scheme,
            substeps: n,
        };
        match integrate(&o, &mut sys, 0.0, 1.0, &y0) {
            Ok(y) => (y[0] - 1.0f64.cos()).abs(),
            Err(_) => f64::INFINITY,
        }
    }

    #[test]
    fn dense_lu_solves_like_elimination() {
        // Pivoting on every column (small leading entries force later swaps too).
        let m = SMatrix::<f64, 4, 4>::from_row_slice(&[
            1e-3, 2.0, 3.0, 1.0, //
            4.0, 1e-4, 6.0, 2.0, //
            7.0, 8.0, 1e-5, 3.0, //
            9.0, 1.0, 2.0, 1e-6,
        ]);
        let b = SVector::<f64, 4>::new(1.0, -2.0, 0.5, 3.0);
        let x = DenseLu::factor(m).unwrap().solve(b);
        assert!((m * x - b).norm() < 1e-12, "{}", (m * x - b).norm());
        assert!((x - solve_dense(m, b).unwrap()).norm() < 1e-12);
        assert!(DenseLu::factor(SMatrix::<f64, 2, 2>::zeros()).is_none());
    }

    #[test]
    fn tableaus_are_consistent() {
        for i in 0..4 {
            let s: f64 = RK4.a[i].iter().sum();
            assert!((s - RK4.c[i]).abs() < 1e-15);
        }
        for i in 0..3 {
            let s: f64 = SDIRK3.a[i].iter().sum();
            assert!((s - SDIRK3.c[i]).abs() < 1e-15, "row {i}");
        }
        // Order-3 conditions of the SDIRK.
        let b = SDIRK3.b;
        let c = SDIRK3.c;
        assert!((b.iter().sum::<f64>() - 1.0).abs() < 1e-14);
        assert!((b.iter().zip(&c).map(|(b, c)| b * c).sum::<f64>() - 0.5).abs() < 1e-14);
        assert!((b.iter().zip(&c).map(|(b, c)| b * c * c).sum::<f64>() - 1.0 / 3.0).abs() < 1e-14);
    }

    #[test]
    fn observed_orders() {
        // Non-stiff: RK4 order 4, SDIRK3 order 3.
        let r = err(Scheme::Rk4, 10, 1.0) / err(Scheme::Rk4, 20, 1.0);
        assert!((r.log2() - 4.0).abs() < 0.3, "rk4 order {}", r.log2());
        let r = err(Scheme::Implicit, 20, 1.0) / err(Scheme::Implicit, 40, 1.0);
        assert!((r.log2() - 3.0).abs() < 0.3, "sdirk order {}", r.log2());
    }

    /// y' = -k y^3: nonlinear, so one Newton iteration cannot meet a tight tolerance.
    struct Cubic;
    impl OdeSystem<1> for Cubic {
        fn rhs(&self, _t: f64, y: &SVector<f64, 1>) -> Result<SVector<f64, 1>, HydraulicError> {
            Ok(SVector::<f64, 1>::new(-1e3 * y[0].powi(3)))
        }
        fn jacobian(
            &self,
            _t: f64,
            y: &SVector<f64, 1>,
        ) -> Result<SMatrix<f64, 1, 1>, HydraulicError> {
            Ok(SMatrix::<f64, 1, 1>::new(-3e3 * y[0] * y[0]))
        }
        fn weights(&self, _y: &SVector<f64, 1>) -> SVector<f64, 1> {
            SVector::<f64, 1>::new(1e-14)
        }
    }

    #[test]
    fn newton_failure_names_time_iteration_and_residual() {
        let y0 = SVector::<f64, 1>::new(1.0);
        let opts = NewtonOptions {
            max_iter: 2,
            tol: 1.0,
            simplified: false,
        };
        let e = sdirk_step(&SDIRK3, &Cubic, 0.25, &y0, 0.1, &opts).unwrap_err();
        match &e {
            HydraulicError::NewtonDiverged {
                t,
                iteration,
                residual,
                ..
            } => {
                assert!(*t > 0.25 && *iteration == 2 && *residual > 1.0, "{e:?}");
            }
            other => panic!("unexpected {other:?}"),
        }
        let msg = e.to_string();
        assert!(
            msg.contains("t = ") && msg.contains("iteration 2") && msg.contains("residual"),
            "{msg}"
        );
        // With the default settings it converges and matches the exact solution closely.
        let y = sdirk_step(&SDIRK3, &Cubic, 0.0, &y0, 1e-4, &NewtonOptions::default()).unwrap();
        let exact = 1.0 / (1.0f64 + 2.0 * 1e3 * 1e-4).sqrt();
        assert!((y[0] - exact).abs() < 1e-4, "{} vs {exact}", y[0]);
    }

    #[test]
    fn implicit_is_stable_where_rk4_is_not() {
        // h * lambda = 1e4 / 10 = 1000: far outside RK4's stability interval.
        assert!(err(Scheme::Implicit, 10, 1.0e4) < 1e-4);
        let e = err(Scheme::Rk4, 10, 1.0e4);
        assert!(e >= 1.0 || e.is_nan(), "RK4 should blow up, error {e}");
    }
}
