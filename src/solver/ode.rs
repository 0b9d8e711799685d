//! Fixed-step integration of `y' = f(t, y)` on slices, the monodromy matrix of a periodic
//! linear system and the tracking of its Floquet multipliers from reference exponents.
//!
//! The reduced rotor models of stability/ use these three pieces; they know no rotor: a
//! system is an [`OdeRhs`] and a mode is an exponent with whatever label its owner gives it.
use faer::{c64, Mat};
use std::f64::consts::PI;

/// An ODE `y' = f(t, y)` evaluated in place (no allocation per call).
pub trait OdeRhs {
    type Error;
    /// Moves the system to time `t`; an integrator calls it once for each distinct stage
    /// time of a step, before the stages at that time.
    fn set_time(&mut self, t: f64) -> Result<(), Self::Error>;
    /// `dy = f(t, y)` at the time of the last [`OdeRhs::set_time`].
    fn rhs(&mut self, y: &[f64], dy: &mut [f64]);
    /// [`OdeRhs::rhs`] on each column of length `m` of `y` (a matrix of states, column-major).
    fn rhs_columns(&mut self, y: &[f64], dy: &mut [f64], m: usize) {
        for (yc, dc) in y.chunks_exact(m).zip(dy.chunks_exact_mut(m)) {
            self.rhs(yc, dc);
        }
    }
}

/// The columns of a matrix of states, each integrated by the same system.
struct Columns<'a, S> {
    sys: &'a mut S,
    m: usize,
}

impl<S: OdeRhs> OdeRhs for Columns<'_, S> {
    type Error = S::Error;
    fn set_time(&mut self, t: f64) -> Result<(), S::Error> {
        self.sys.set_time(t)
    }
    fn rhs(&mut self, y: &[f64], dy: &mut [f64]) {
        self.sys.rhs_columns(y, dy, self.m);
    }
}

/// Classical fourth-order Runge-Kutta with its stage buffers allocated once.
pub struct Rk4 {
    k1: Vec<f64>,
    k2: Vec<f64>,
    k3: Vec<f64>,
    k4: Vec<f64>,
    tmp: Vec<f64>,
}

impl Rk4 {
    /// Buffers for states of `len` entries.
    pub fn new(len: usize) -> Self {
        Rk4 {
            k1: vec![0.0; len],
            k2: vec![0.0; len],
            k3: vec![0.0; len],
            k4: vec![0.0; len],
            tmp: vec![0.0; len],
        }
    }

    /// One step of length `h` from `(t, y)`, `y` replaced by the state at `t + h`.
    pub fn step<S: OdeRhs>(
        &mut self,
        sys: &mut S,
        t: f64,
        h: f64,
        y: &mut [f64],
    ) -> Result<(), S::Error> {
        let axpy = |out: &mut [f64], y: &[f64], a: f64, k: &[f64]| {
            for ((o, yi), ki) in out.iter_mut().zip(y).zip(k) {
                *o = yi + a * ki;
            }
        };
        sys.set_time(t)?;
        sys.rhs(y, &mut self.k1);
        sys.set_time(t + 0.5 * h)?;
        axpy(&mut self.tmp, y, 0.5 * h, &self.k1);
        sys.rhs(&self.tmp, &mut self.k2);
        axpy(&mut self.tmp, y, 0.5 * h, &self.k2);
        sys.rhs(&self.tmp, &mut self.k3);
        sys.set_time(t + h)?;
        axpy(&mut self.tmp, y, h, &self.k3);
        sys.rhs(&self.tmp, &mut self.k4);
        for (i, yi) in y.iter_mut().enumerate() {
            *yi += h / 6.0 * (self.k1[i] + 2.0 * self.k2[i] + 2.0 * self.k3[i] + self.k4[i]);
        }
        Ok(())
    }
}

/// The monodromy matrix was not finite (the system or its step is unstable).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct NotFinite;

/// The monodromy matrix of a linear system of `m` states over one `period`: `steps` RK4 steps
/// from `t = 0` on all `m` columns of the identity at once; column-major `m x m`.
pub fn monodromy<S: OdeRhs>(
    sys: &mut S,
    m: usize,
    period: f64,
    steps: usize,
) -> Result<Vec<f64>, S::Error>
where
    S::Error: From<NotFinite>,
{
    let mut y = vec![0.0; m * m];
    for i in 0..m {
        y[i * m + i] = 1.0;
    }
    let mut ws = Rk4::new(m * m);
    let h = period / steps as f64;
    let mut cols = Columns { sys, m };
    for step in 0..steps {
        ws.step(&mut cols, step as f64 * h, h, &mut y)?;
    }
    if y.iter().any(|v| !v.is_finite()) {
        return Err(NotFinite.into());
    }
    Ok(y)
}

/// Eigenvalues of the column-major `m x m` matrix `phi` (the Floquet multipliers of a
/// monodromy matrix); the eigen-solver's failure in words.
pub fn multipliers(phi: &[f64], m: usize) -> Result<Vec<c64>, String> {
    Mat::<f64>::from_fn(m, m, |i, j| phi[j * m + i])
        .eigenvalues()
        .map_err(|e| format!("{e:?}"))
}

/// Matches multipliers `mu` over one `period` to reference exponents `refs` (nearest
/// `lambda T` in the log plane, imaginary part modulo `2 pi`; greedy over all pairs, closest
/// first) and resolves each matched exponent's imaginary part to the multiple of `omega =
/// 2 pi / T` nearest its reference. Unmatched references are returned unchanged; each keeps
/// its payload (e.g. a label).
pub fn track<T: Clone>(refs: &[(c64, T)], mu: &[c64], period: f64, omega: f64) -> Vec<(c64, T)> {
    let logs: Vec<c64> = mu.iter().map(|m| m.ln()).collect();
    let wrap = |a: f64| a - 2.0 * PI * (a / (2.0 * PI)).round();
    let mut pairs: Vec<(f64, usize, usize)> = Vec::with_capacity(refs.len() * logs.len());
    for (r, (l, _)) in refs.iter().enumerate() {
        for (j, lg) in logs.iter().enumerate() {
            let d = (lg.re - l.re * period).hypot(wrap(lg.im - l.im * period));
            pairs.push((d, r, j));
        }
    }
    pairs.sort_by(|a, b| a.0.total_cmp(&b.0));
    let mut taken_r = vec![false; refs.len()];
    let mut taken_j = vec![false; logs.len()];
    let mut out = refs.to_vec();
    for (_, r, j) in pairs {
        if taken_r[r] || taken_j[j] {
            continue;
        }
        taken_r[r] = true;
        taken_j[j] = true;
        let lam = logs[j] / period;
        let shift = ((refs[r].0.im - lam.im) / omega).round();
        out[r].0 = c64::new(lam.re, lam.im + shift * omega);
    }
    out
}

/// Floquet exponents continued from reference exponents `refs` (of a system whose exponents
/// are known, e.g. a constant-coefficient one) through the multipliers of each stage of a
/// homotopy to the system wanted, each stage matched to the previous one by [`track`]: the
/// last stage's exponents with the labels of the references. `omega = 2 pi / period`, given
/// as the caller has it (the frequencies are resolved to its multiples).
pub fn continue_exponents<T: Clone, E>(
    mut refs: Vec<(c64, T)>,
    stages: usize,
    period: f64,
    omega: f64,
    mut multipliers_of_stage: impl FnMut(usize) -> Result<Vec<c64>, E>,
) -> Result<Vec<(c64, T)>, E> {
    for stage in 0..stages {
        let mu = multipliers_of_stage(stage)?;
        refs = track(&refs, &mu, period, omega);
    }
    Ok(refs)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `y' = A y` with a constant 2 x 2 `A`.
    struct Linear([[f64; 2]; 2]);

    impl OdeRhs for Linear {
        type Error = NotFinite;
        fn set_time(&mut self, _t: f64) -> Result<(), NotFinite> {
            Ok(())
        }
        fn rhs(&mut self, y: &[f64], dy: &mut [f64]) {
            let a = &self.0;
            dy[0] = a[0][0] * y[0] + a[0][1] * y[1];
            dy[1] = a[1][0] * y[0] + a[1][1] * y[1];
        }
    }

    /// `exp(A t)` of the damped oscillator `x'' + 2 z w x' + w^2 x = 0`, state `(x, x')`.
    fn oscillator(z: f64, w: f64, t: f64) -> [[f64; 2]; 2] {
        let wd = w * (1.0 - z * z).sqrt();
        let e = (-z * w * t).exp();
        let (s, c) = (wd * t).sin_cos();
        [
            [e * (c + z * w / wd * s), e * s / wd],
            [-e * w * w / wd * s, e * (c - z * w / wd * s)],
        ]
    }

    #[test]
    fn rk4_on_a_damped_oscillator_converges_at_fourth_order_to_the_exponential() {
        let (z, w, t_end) = (0.1, 3.0, 2.0);
        let exact = oscillator(z, w, t_end);
        let a = [[0.0, 1.0], [-w * w, -2.0 * z * w]];
        let err = |steps: usize| {
            let mut y = [1.0, 0.0];
            let mut rk = Rk4::new(2);
            let h = t_end / steps as f64;
            for s in 0..steps {
                rk.step(&mut Linear(a), s as f64 * h, h, &mut y).unwrap();
            }
            (y[0] - exact[0][0]).hypot(y[1] - exact[1][0])
        };
        let (e1, e2) = (err(200), err(400));
        assert!(e1 < 1e-7, "{e1}");
        // halving the step divides the error by 2^4
        let order = (e1 / e2).log2();
        assert!((order - 4.0).abs() < 0.1, "order {order}");
    }

    #[test]
    fn monodromy_of_a_constant_system_is_its_matrix_exponential() {
        let (z, w, period) = (0.05, 2.0 * PI * 1.3, 1.0);
        let a = [[0.0, 1.0], [-w * w, -2.0 * z * w]];
        let phi = monodromy(&mut Linear(a), 2, period, 2000).unwrap();
        let exact = oscillator(z, w, period);
        for i in 0..2 {
            for j in 0..2 {
                let scale = w.max(1.0);
                assert!(
                    (phi[j * 2 + i] - exact[i][j]).abs() < 1e-9 * scale,
                    "({i}, {j}): {} against {}",
                    phi[j * 2 + i],
                    exact[i][j]
                );
            }
        }
    }

    /// Floquet multipliers of a constant system are `exp(lambda T)`; tracking them from the
    /// exponents resolves the frequency lost modulo `omega` (here 1.3/rev, seen as 0.3/rev).
    #[test]
    fn tracked_multipliers_give_back_the_exponents_of_a_constant_system() {
        let (z, w, period) = (0.05, 2.0 * PI * 1.3, 1.0);
        let a = [[0.0, 1.0], [-w * w, -2.0 * z * w]];
        let phi = monodromy(&mut Linear(a), 2, period, 2000).unwrap();
        let mu = multipliers(&phi, 2).unwrap();
        let lam = c64::new(-z * w, w * (1.0 - z * z).sqrt());
        for m in &mu {
            let l = if m.im >= 0.0 { lam } else { lam.conj() };
            let e = (l * period).exp();
            assert!((m - e).norm() < 1e-9, "{m:?} against {e:?}");
        }
        // references off by a little: the tracked exponents are the exact ones
        let refs = vec![
            (c64::new(lam.re * 1.1, lam.im + 0.2), "forward"),
            (c64::new(lam.re * 1.1, -lam.im - 0.2), "backward"),
        ];
        let out = continue_exponents(refs, 3, period, 2.0 * PI / period, |_| {
            Ok::<_, NotFinite>(mu.clone())
        })
        .unwrap();
        assert_eq!(out[0].1, "forward");
        assert!((out[0].0 - lam).norm() < 1e-8, "{:?}", out[0].0);
        assert!((out[1].0 - lam.conj()).norm() < 1e-8, "{:?}", out[1].0);
    }

    /// Mathieu's equation `x'' + (a + 2 q cos 2t) x = 0` for small `q`: the multipliers of
    /// its period `pi` lie on the unit circle (it is Hamiltonian and, away from the tongues,
    /// stable) with `mu + 1/mu = trace`, and to first order in `q` the exponent is `i sqrt(a)`
    /// (the tongues' width is `O(q)` only at `sqrt(a)` integer). Inside the first tongue
    /// (`a = 1`, `q = 0.1`) the growth per period is `exp(pi q / 2)` to first order.
    #[test]
    fn mathieu_multipliers_against_the_perturbation_results() {
        struct Mathieu {
            a: f64,
            q: f64,
            k: f64,
        }
        impl OdeRhs for Mathieu {
            type Error = NotFinite;
            fn set_time(&mut self, t: f64) -> Result<(), NotFinite> {
                self.k = self.a + 2.0 * self.q * (2.0 * t).cos();
                Ok(())
            }
            fn rhs(&mut self, y: &[f64], dy: &mut [f64]) {
                dy[0] = y[1];
                dy[1] = -self.k * y[0];
            }
        }
        let mono = |a: f64, q: f64| {
            let phi = monodromy(&mut Mathieu { a, q, k: 0.0 }, 2, PI, 4000).unwrap();
            multipliers(&phi, 2).unwrap()
        };
        // q = 0: exactly exp(+-i sqrt(a) pi)
        let mu = mono(2.0, 0.0);
        let e = c64::new(0.0, 2f64.sqrt() * PI).exp();
        for m in &mu {
            assert!(
                (m - e).norm() < 1e-10 || (m - e.conj()).norm() < 1e-10,
                "{m:?}"
            );
        }
        // stable, small q: unit modulus (area-preserving map), product 1
        let mu = mono(2.0, 0.05);
        assert!(mu.iter().all(|m| (m.norm() - 1.0).abs() < 1e-9), "{mu:?}");
        // first instability tongue: real multipliers, growth exp(pi q / 2) to O(q^2)
        let q = 0.01;
        let mu = mono(1.0, q);
        let big = mu.iter().map(|m| m.norm()).fold(0.0, f64::max);
        let expected = (PI * q / 2.0).exp();
        assert!(
            (big - expected).abs() < 2.0 * q * q,
            "{big} against {expected}"
        );
        assert!(
            mu.iter().all(|m| m.im.abs() < 1e-12 && m.re < 0.0),
            "{mu:?}"
        );
    }
}
