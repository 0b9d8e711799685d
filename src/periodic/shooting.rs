//! Newton-Picard shooting with a recycled Krylov subspace.
//!
//! The fixed point `x = Phi(x)` solves `(I - M) dx = r`, `r = Phi(x) - x`, `M = dPhi/dx` the
//! monodromy matrix. A periodically forced structure has a few slow modes (multipliers near
//! the unit circle: they make marching slow) and many fast ones (multipliers near 0). Per
//! iteration:
//!
//! 1. Newton on a subspace: directions `S` (orthonormal) with images `Y = M S` from
//!    finite-difference periods `(Phi(x + eps s) - Phi(x)) / eps`; `c` minimises
//!    `||r - (S - Y) c||`. While that least-squares residual `rho` is above `eta ||r||`, `rho`
//!    itself (orthogonalised) becomes the next direction: for a linear map this builds the
//!    Krylov space of GMRES on `(I - M) dx = r`, one period per direction.
//! 2. Picard on the rest: `dx = S c + rho` (the part of `r` the subspace does not explain is
//!    taken as one marched period would take it).
//! 3. Globalisation: the step is halved (up to `max_halvings` times) until the residual
//!    norm decreases; the relief valves make the map only piecewise smooth.
//!
//! The subspace is kept across iterations (the map changes little between iterates), so
//! later iterations cost one period each unless the residual leaves the subspace. Its Ritz
//! values are the least-damped Floquet multipliers ([`super::floquet`]).
use super::floquet::{dot, ritz_pairs, RitzPair};
use super::PeriodMap;
use faer::linalg::solvers::SolveLstsq;
use faer::Mat;

/// Options of [`shoot`].
#[derive(Clone, Copy, Debug)]
pub struct ShootingOptions {
    /// Stop when [`PeriodMap::residual`] and the estimated distance to the periodic
    /// solution ([`ShootingOutcome::error_estimate`]) are at or below it.
    pub tol: f64,
    /// Most periods integrated in all (the map's count, marched periods included).
    pub max_periods: usize,
    /// Subspace accuracy: new directions while the least-squares residual exceeds
    /// `eta ||r||`.
    pub eta: f64,
    /// Most subspace directions.
    pub max_dirs: usize,
    /// Finite-difference step along a unit direction, in the map's coordinates.
    pub fd_step: f64,
    /// Step halvings before giving up.
    pub max_halvings: usize,
    /// No new direction once the newest one contracts at least this much in one period
    /// (`||M d|| <= picard_rate`): what is left of the residual is then taken by Picard.
    pub picard_rate: f64,
    /// Directions the subspace has at least when the solver stops converged (more Floquet
    /// multipliers, one period each).
    pub min_dirs: usize,
    /// After convergence, the Ritz pairs to resolve: the first `resolve_wanted` (least
    /// damped first) with |mu| at least `resolve_floor` get new directions (each the
    /// residual `M v - mu v` of the least damped one not resolved, one period each) until their
    /// residuals are at most [`super::floquet::RELIABLE_RESIDUAL`] of |mu|, at most
    /// `resolve_dirs` of them (0: none).
    pub resolve_wanted: usize,
    pub resolve_floor: f64,
    pub resolve_dirs: usize,
}

impl Default for ShootingOptions {
    fn default() -> Self {
        ShootingOptions {
            tol: 1e-4,
            max_periods: 75,
            eta: 0.2,
            max_dirs: 40,
            fd_step: 1e-4,
            max_halvings: 3,
            picard_rate: 0.2,
            min_dirs: 0,
            resolve_wanted: 0,
            resolve_floor: 0.0,
            resolve_dirs: 0,
        }
    }
}

/// Why [`shoot`] stopped.
#[derive(Clone, Debug, PartialEq)]
pub enum Stop {
    Converged,
    /// `max_periods` reached first.
    Budget,
    /// No step decreased the residual.
    LineSearch,
    /// The map failed (the error's message).
    Failed(String),
}

/// What [`shoot`] found.
pub struct ShootingOutcome {
    pub stop: Stop,
    /// Residual of the accepted point after each iteration (the first: the starting point).
    pub residual_history: Vec<f64>,
    /// Newton-Picard iterations (accepted steps).
    pub iterations: usize,
    /// Periods spent on subspace directions and on rejected trials.
    pub directions: usize,
    pub rejected_trials: usize,
    /// Of `directions`, those added after convergence to resolve the wanted Ritz pairs
    /// ([`ShootingOptions::resolve_dirs`]).
    pub resolve_directions: usize,
    /// Ritz pairs of the subspace, least damped first.
    pub ritz: Vec<RitzPair>,
    /// Estimated distance of the accepted point to the periodic solution, over the whole
    /// period: the last step's change `d_k` times `q / (1 - q)`, `q = r_k / r_(k-1)` the
    /// observed contraction of the residual (`e_k = q e_(k-1)`, `d_k = e_(k-1) - e_k`). None
    /// before the first step.
    pub error_estimate: Option<f64>,
}

impl ShootingOutcome {
    pub fn converged(&self) -> bool {
        self.stop == Stop::Converged
    }
}

/// Contraction per step assumed at most when estimating the distance to the solution.
const MAX_CONTRACTION: f64 = 0.9;

fn norm(v: &[f64]) -> f64 {
    dot(v, v).sqrt()
}

/// `(c, rho)`: least squares `min ||r - (S - Y) c||` and its residual.
fn project(s: &[Vec<f64>], y: &[Vec<f64>], r: &[f64]) -> (Vec<f64>, Vec<f64>) {
    let k = s.len();
    if k == 0 {
        return (vec![], r.to_vec());
    }
    let n = r.len();
    let a = Mat::<f64>::from_fn(n, k, |i, j| s[j][i] - y[j][i]);
    let rhs = Mat::<f64>::from_fn(n, 1, |i, _| r[i]);
    let sol = a.col_piv_qr().solve_lstsq(&rhs);
    let c: Vec<f64> = (0..k).map(|j| sol[(j, 0)]).collect();
    let mut rho = r.to_vec();
    for j in 0..k {
        for i in 0..n {
            rho[i] -= c[j] * (s[j][i] - y[j][i]);
        }
    }
    (c, rho)
}

/// `d` orthogonalised against the orthonormal `s` (twice: classical Gram-Schmidt loses
/// orthogonality otherwise) and normalised; None when nothing new is left.
fn new_direction(s: &[Vec<f64>], d: &[f64]) -> Option<Vec<f64>> {
    let mut d = d.to_vec();
    let n0 = norm(&d);
    for _ in 0..2 {
        for si in s {
            let c = dot(si, &d);
            for (x, v) in d.iter_mut().zip(si) {
                *x -= c * v;
            }
        }
    }
    let n = norm(&d);
    if n.is_nan() || n <= 1e-10 * n0 {
        return None;
    }
    d.iter_mut().for_each(|x| *x /= n);
    Some(d)
}

/// Size of the Newton-Picard step `S c + rho` from the accepted point on the subspace as it
/// is (no period integrated).
fn next_step_norm(map: &dyn PeriodMap, s: &[Vec<f64>], y: &[Vec<f64>]) -> f64 {
    let (x, f) = map.accepted();
    let r: Vec<f64> = f.iter().zip(x).map(|(a, b)| a - b).collect();
    let (c, mut dx) = project(s, y, &r);
    for (cj, sj) in c.iter().zip(s) {
        for (d, v) in dx.iter_mut().zip(sj) {
            *d += cj * v;
        }
    }
    norm(&dx)
}

/// Adds one direction `d` (unit) and its image `M d` about the accepted point.
fn add_direction(
    map: &mut dyn PeriodMap,
    o: &ShootingOptions,
    s: &mut Vec<Vec<f64>>,
    y: &mut Vec<Vec<f64>>,
    d: Vec<f64>,
) -> anyhow::Result<()> {
    let (x, f) = map.accepted();
    let (x, f) = (x.to_vec(), f.to_vec());
    let xp: Vec<f64> = x.iter().zip(&d).map(|(a, b)| a + o.fd_step * b).collect();
    let fp = map.perturbed(&xp)?;
    y.push(
        fp.iter()
            .zip(&f)
            .map(|(a, b)| (a - b) / o.fd_step)
            .collect(),
    );
    s.push(d);
    Ok(())
}

/// Directions added about the periodic solution until the wanted Ritz pairs are resolved
/// ([`ShootingOptions::resolve_wanted`]): each the residual `M v - mu v` of the least damped
/// pair not yet resolved (its real part, or its imaginary part when that has
/// more left outside span(S)), orthogonalised; its image costs one period. Returns how many.
fn resolve(
    map: &mut dyn PeriodMap,
    o: &ShootingOptions,
    s: &mut Vec<Vec<f64>>,
    y: &mut Vec<Vec<f64>>,
) -> anyhow::Result<usize> {
    let mut added = 0;
    while added < o.resolve_dirs && map.periods() < o.max_periods {
        let pairs = ritz_pairs(s, y);
        // the least damped first: the slow modes matter most and converge first
        let Some(worst) = pairs
            .iter()
            .take(o.resolve_wanted)
            .find(|p| p.multiplier.magnitude >= o.resolve_floor && !p.multiplier.reliable)
        else {
            break;
        };
        let d = [&worst.residual_re, &worst.residual_im]
            .into_iter()
            .filter_map(|r| new_direction(s, r).map(|d| (norm(r), d)))
            .max_by(|a, b| a.0.total_cmp(&b.0))
            .map(|x| x.1);
        let Some(d) = d else {
            break;
        };
        add_direction(map, o, s, y, d)?;
        added += 1;
    }
    Ok(added)
}

/// Drive `map` to a periodic solution (see the module documentation); the map reports its
/// own progress.
pub fn shoot(map: &mut dyn PeriodMap, o: &ShootingOptions) -> ShootingOutcome {
    let mut s: Vec<Vec<f64>> = Vec::new();
    let mut y: Vec<Vec<f64>> = Vec::new();
    let mut out = ShootingOutcome {
        stop: Stop::Budget,
        residual_history: vec![map.residual()],
        iterations: 0,
        directions: 0,
        rejected_trials: 0,
        resolve_directions: 0,
        ritz: vec![],
        error_estimate: None,
    };
    let result = (|| -> anyhow::Result<Stop> {
        loop {
            if map.residual() <= o.tol && out.error_estimate.is_none_or(|e| e <= o.tol) {
                // more multipliers if asked, about the periodic solution
                while s.len() < o.min_dirs && map.periods() < o.max_periods {
                    let seed = match y.last() {
                        Some(v) => v.clone(),
                        None => {
                            let (x, f) = map.accepted();
                            f.iter().zip(x).map(|(a, b)| a - b).collect()
                        }
                    };
                    let Some(d) = new_direction(&s, &seed) else {
                        break;
                    };
                    add_direction(map, o, &mut s, &mut y, d)?;
                    out.directions += 1;
                }
                out.resolve_directions = resolve(map, o, &mut s, &mut y)?;
                out.directions += out.resolve_directions;
                return Ok(Stop::Converged);
            }
            if map.periods() >= o.max_periods {
                return Ok(Stop::Budget);
            }
            let (x, f) = map.accepted();
            let (x, f) = (x.to_vec(), f.to_vec());
            let r: Vec<f64> = f.iter().zip(&x).map(|(a, b)| a - b).collect();
            let rn = norm(&r);
            let (mut c, mut rho) = project(&s, &y, &r);
            // residual met, distance not: one step on the subspace as it is
            let mut fast = map.residual() <= o.tol;
            // keep one period for the trial
            while norm(&rho) > o.eta * rn
                && !fast
                && s.len() < o.max_dirs
                && map.periods() + 1 < o.max_periods
            {
                let Some(d) = new_direction(&s, &rho) else {
                    break;
                };
                add_direction(map, o, &mut s, &mut y, d)?;
                out.directions += 1;
                fast = y.last().is_some_and(|v| norm(v) <= o.picard_rate);
                (c, rho) = project(&s, &y, &r);
            }
            let mut dx = rho;
            for (cj, sj) in c.iter().zip(&s) {
                for (d, v) in dx.iter_mut().zip(sj) {
                    *d += cj * v;
                }
            }
            let mut lam = 1.0;
            let mut halvings = 0;
            loop {
                if map.periods() >= o.max_periods {
                    return Ok(Stop::Budget);
                }
                let xt: Vec<f64> = x.iter().zip(&dx).map(|(a, b)| a + lam * b).collect();
                let ft = map.trial(&xt)?;
                let rt: f64 = norm(&ft.iter().zip(&xt).map(|(a, b)| a - b).collect::<Vec<_>>());
                if rt.is_finite() && rt < rn {
                    map.accept();
                    break;
                }
                out.rejected_trials += 1;
                halvings += 1;
                if halvings > o.max_halvings {
                    return Ok(Stop::LineSearch);
                }
                lam *= 0.5;
            }
            out.iterations += 1;
            out.residual_history.push(map.residual());
            let taken = lam * norm(&dx);
            let next = next_step_norm(map, &s, &y);
            out.error_estimate = map.step_change().map(|d| {
                let h = &out.residual_history;
                // a contraction slower than 0.9 per step is taken as 0.9
                let q = (h[h.len() - 1] / h[h.len() - 2]).min(MAX_CONTRACTION);
                // the residual can contract faster than the distance along a slow mode
                // (distance r_j / (1 - mu_j)): the next Newton-Picard step on the subspace,
                // scaled as the step just taken moved the channels, estimates it
                let newton = if taken > 0.0 { d * next / taken } else { 0.0 };
                (d * q / (1.0 - q)).max(newton)
            });
        }
    })();
    out.stop = result.unwrap_or_else(|e| Stop::Failed(format!("{e:#}")));
    out.ritz = ritz_pairs(&s, &y);
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `Phi(x) = M x + b` with a known spectrum; the map counts periods like a simulation.
    struct Affine {
        m: Vec<Vec<f64>>,
        b: Vec<f64>,
        x: Vec<f64>,
        f: Vec<f64>,
        trial: Option<(Vec<f64>, Vec<f64>)>,
        periods: usize,
        step: Option<f64>,
        /// `quad * x_0^2` added to component 2: a smooth nonlinearity.
        quad: f64,
    }

    impl Affine {
        fn phi(&mut self, x: &[f64]) -> Vec<f64> {
            self.periods += 1;
            let mut f: Vec<f64> = self
                .m
                .iter()
                .zip(&self.b)
                .map(|(row, b)| dot(row, x) + b)
                .collect();
            f[2] += self.quad * x[0] * x[0];
            f
        }
        /// Block diagonal: a slow rotation (0.99, 0.3 rad), a slow real 0.97 and fast ones
        /// below 0.05; started after three marched periods, as a simulation would start.
        fn slow_and_fast(quad: f64) -> Self {
            let n = 12;
            let mut m = vec![vec![0.0; n]; n];
            let (c, s) = (0.99 * 0.3f64.cos(), 0.99 * 0.3f64.sin());
            m[0][0] = c;
            m[0][1] = -s;
            m[1][0] = s;
            m[1][1] = c;
            m[2][2] = 0.97;
            for i in 3..n {
                m[i][i] = 0.05 * (i as f64 / n as f64);
                if i + 1 < n {
                    m[i][i + 1] = 0.01;
                }
            }
            let b: Vec<f64> = (0..n).map(|i| 1.0 + 0.1 * i as f64).collect();
            let x0 = vec![0.0; n];
            let mut map = Affine {
                m,
                b,
                x: x0.clone(),
                f: vec![],
                trial: None,
                periods: 0,
                step: None,
                quad,
            };
            map.f = map.phi(&x0);
            for _ in 0..3 {
                map.x = map.f.clone();
                map.f = map.phi(&map.x.clone());
            }
            map
        }
    }

    impl PeriodMap for Affine {
        fn accepted(&self) -> (&[f64], &[f64]) {
            (&self.x, &self.f)
        }
        fn perturbed(&mut self, x: &[f64]) -> anyhow::Result<Vec<f64>> {
            Ok(self.phi(x))
        }
        fn trial(&mut self, x: &[f64]) -> anyhow::Result<Vec<f64>> {
            let f = self.phi(x);
            self.trial = Some((x.to_vec(), f.clone()));
            Ok(f)
        }
        fn accept(&mut self) {
            if let Some((x, f)) = self.trial.take() {
                let d: Vec<f64> = x.iter().zip(&self.x).map(|(a, b)| a - b).collect();
                self.step = Some(norm(&d));
                self.x = x;
                self.f = f;
            }
        }
        fn residual(&self) -> f64 {
            norm(
                &self
                    .f
                    .iter()
                    .zip(&self.x)
                    .map(|(a, b)| a - b)
                    .collect::<Vec<_>>(),
            )
        }
        fn periods(&self) -> usize {
            self.periods
        }
        fn step_change(&self) -> Option<f64> {
            self.step
        }
    }

    #[test]
    fn slow_modes_by_newton_fast_ones_by_picard() {
        let mut map = Affine::slow_and_fast(0.0);
        let o = ShootingOptions {
            tol: 1e-10,
            ..Default::default()
        };
        let out = shoot(&mut map, &o);
        assert!(out.converged(), "{:?} {:?}", out.stop, out.residual_history);
        // marching would need ~2300 periods for the 0.99 mode; here 4 marched, 6 directions
        // (3 slow, the rest until the newest contracts by 5x) and a trial per iteration
        assert!(map.periods <= 4 + 6 + 4, "{} periods", map.periods);
        let mu = &out.ritz[0].multiplier;
        assert!((mu.magnitude - 0.99).abs() < 1e-9, "{mu:?}");
        assert!((mu.frequency_per_rev * 2.0 * std::f64::consts::PI - 0.3).abs() < 1e-9);
        assert!((out.ritz[1].multiplier.re - 0.97).abs() < 1e-9);
    }

    #[test]
    fn the_error_estimate_is_the_distance_to_the_fixed_point() {
        // nonlinear, so Newton takes several steps; the fixed point by Picard iterations
        // (the slowest mode contracts by 0.99: 10^4 periods leave 1e-44 of the start)
        let mut map = Affine::slow_and_fast(2e-3);
        let mut exact = map.x.clone();
        for _ in 0..10_000 {
            exact = map.phi(&exact);
        }
        map.periods = 0;
        for tol in [1e-4, 1e-7] {
            let mut map = Affine::slow_and_fast(2e-3);
            let o = ShootingOptions {
                tol,
                ..Default::default()
            };
            let out = shoot(&mut map, &o);
            assert!(out.converged(), "{:?} {:?}", out.stop, out.residual_history);
            let err = norm(
                &map.x
                    .iter()
                    .zip(&exact)
                    .map(|(a, b)| a - b)
                    .collect::<Vec<_>>(),
            );
            let est = out.error_estimate.unwrap();
            assert!(est <= tol, "{est}");
            // on the safe side: Newton converges superlinearly, so the contraction of the
            // last step overstates the remaining error (by 10x here at 1e-4), never understates
            assert!(
                err <= est,
                "tol {tol:.0e}: true {err:.2e}, estimate {est:.2e}, residuals {:?}",
                out.residual_history
            );
        }
    }
}
