//! Floquet multipliers from a subspace of the monodromy matrix (Rayleigh-Ritz).
//!
//! With orthonormal directions `S` (columns) and `Y = M S` their images under the monodromy
//! matrix `M = dPhi/dx`, the Ritz values of `M` on span(S) are the eigenvalues of the small
//! matrix `H = S^T Y`; its eigenvectors `z` give the Ritz vectors `S z`. A multiplier `mu` of a
//! mode `e^{s t}` is `e^{s T}`: `s T = ln|mu| + i arg(mu)`, so the frequency is known modulo
//! 1/rev (reported in [0, 1/2] /rev) and the damping ratio follows from that frequency.
//!
//! A Ritz pair is an eigenpair of `M` only as far as span(S) contains the mode. Its residual
//! `||M v - mu v|| / ||v||` with `v = S z`, `M v = Y z` (no further period) bounds the distance
//! of `mu` to an eigenvalue of `M` for a normal `M` (Bauer-Fike; Saad, Numerical Methods for
//! Large Eigenvalue Problems, 2011, Th. 3.6); a multiplier whose residual exceeds
//! [`RELIABLE_RESIDUAL`] of its magnitude is marked unreliable. The bound is a guarantee
//! only for a normal `M`; the Ritz value is often closer than its residual (see
//! docs/periodic.md for the UH-60A run).
use faer::Mat;

/// Largest residual `||M v - mu v|| / ||v||`, relative to `|mu|`, of a multiplier reported as
/// reliable: for a normal `M` an eigenvalue then lies within 1% of `mu`.
pub const RELIABLE_RESIDUAL: f64 = 1e-2;

/// One Floquet multiplier with its mode.
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Multiplier {
    pub re: f64,
    pub im: f64,
    /// |mu|: decay of the mode per period.
    pub magnitude: f64,
    /// arg(mu) / 2 pi in [0, 1/2]: frequency modulo 1/rev [cycles per period].
    pub frequency_per_rev: f64,
    /// `-ln|mu| / sqrt(ln|mu|^2 + arg(mu)^2)` (1 for a real positive multiplier; a real
    /// negative one is a half-per-rev oscillation).
    pub damping_ratio: f64,
    /// Which motion dominates the mode (the simulation's label, e.g. "lag").
    #[serde(default, skip_serializing_if = "String::is_empty")]
    pub mode: String,
    /// `||M v - mu v|| / ||v||` of the Ritz pair (NaN when not computed).
    #[serde(default = "nan")]
    pub residual: f64,
    /// Whether `residual` is at most [`RELIABLE_RESIDUAL`] x `magnitude`.
    #[serde(default)]
    pub reliable: bool,
}

fn nan() -> f64 {
    f64::NAN
}

impl Multiplier {
    pub fn new(re: f64, im: f64) -> Self {
        let mag = re.hypot(im);
        let arg = im.atan2(re).abs();
        let sigma = mag.ln();
        let damping_ratio = if mag == 0.0 {
            1.0
        } else {
            -sigma / sigma.hypot(arg)
        };
        Multiplier {
            re,
            im,
            magnitude: mag,
            frequency_per_rev: arg / (2.0 * std::f64::consts::PI),
            damping_ratio,
            mode: String::new(),
            residual: f64::NAN,
            reliable: false,
        }
    }

    /// Sets the residual and whether it is small enough.
    pub fn with_residual(mut self, r: f64) -> Self {
        self.residual = r;
        self.reliable = r <= RELIABLE_RESIDUAL * self.magnitude;
        self
    }
}

/// A Ritz pair: the multiplier and its vector (real and imaginary parts, in the coordinates
/// of the directions).
pub struct RitzPair {
    pub multiplier: Multiplier,
    pub vector_re: Vec<f64>,
    pub vector_im: Vec<f64>,
    /// `M v - mu v` (real and imaginary parts): its part outside span(S) is the direction that
    /// would resolve the pair next (the Arnoldi/Davidson expansion).
    pub residual_re: Vec<f64>,
    pub residual_im: Vec<f64>,
}

/// Ritz pairs of `M` on span(`s`) from `y = M s` (`s` orthonormal), least damped first (largest
/// |mu|); complex pairs give one entry (Im >= 0), with its residual (module docs).
pub fn ritz_pairs(s: &[Vec<f64>], y: &[Vec<f64>]) -> Vec<RitzPair> {
    let k = s.len();
    if k == 0 {
        return vec![];
    }
    let h = Mat::<f64>::from_fn(k, k, |i, j| dot(&s[i], &y[j]));
    let Ok(eig) = h.eigen() else {
        return vec![];
    };
    let (u, lam) = (eig.U(), eig.S());
    let n = s[0].len();
    let mut out: Vec<RitzPair> = (0..k)
        .filter(|&j| lam.column_vector()[j].im >= 0.0)
        .map(|j| {
            let l = lam.column_vector()[j];
            let (mut vr, mut vi) = (vec![0.0; n], vec![0.0; n]);
            let (mut mr, mut mi) = (vec![0.0; n], vec![0.0; n]);
            for (i, (si, yi)) in s.iter().zip(y).enumerate() {
                let z = u[(i, j)];
                for (p, (v, w)) in si.iter().zip(yi).enumerate() {
                    vr[p] += z.re * v;
                    vi[p] += z.im * v;
                    mr[p] += z.re * w;
                    mi[p] += z.im * w;
                }
            }
            // M v - mu v, complex
            let rr: Vec<f64> = (0..n)
                .map(|p| mr[p] - (l.re * vr[p] - l.im * vi[p]))
                .collect();
            let ri: Vec<f64> = (0..n)
                .map(|p| mi[p] - (l.re * vi[p] + l.im * vr[p]))
                .collect();
            let r2 = dot(&rr, &rr) + dot(&ri, &ri);
            let v2 = dot(&vr, &vr) + dot(&vi, &vi);
            RitzPair {
                multiplier: Multiplier::new(l.re, l.im).with_residual((r2 / v2).sqrt()),
                vector_re: vr,
                vector_im: vi,
                residual_re: rr,
                residual_im: ri,
            }
        })
        .collect();
    out.sort_by(|a, b| b.multiplier.magnitude.total_cmp(&a.multiplier.magnitude));
    out
}

pub(crate) fn dot(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| x * y).sum()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn multiplier_of_a_damped_mode() {
        // s = -zeta w + i w sqrt(1 - zeta^2), T = 1, w = 2 pi 0.3
        let (zeta, w) = (0.05f64, 2.0 * std::f64::consts::PI * 0.3);
        let wd = w * (1.0 - zeta * zeta).sqrt();
        let mu = (-zeta * w).exp();
        let m = Multiplier::new(mu * wd.cos(), mu * wd.sin());
        assert!((m.frequency_per_rev - wd / (2.0 * std::f64::consts::PI)).abs() < 1e-14);
        assert!(
            (m.damping_ratio - zeta).abs() < 1e-14,
            "{}",
            m.damping_ratio
        );
    }

    #[test]
    fn ritz_values_of_a_rotation_with_decay() {
        // M = 0.9 R(0.4) on the plane of e0, e1 and 0.2 on e2: all of it in span(S)
        let (c, s) = (0.9 * 0.4f64.cos(), 0.9 * 0.4f64.sin());
        let m = [[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 0.2]];
        let basis: Vec<Vec<f64>> = (0..3)
            .map(|i| (0..3).map(|j| f64::from(u8::from(i == j))).collect())
            .collect();
        let images: Vec<Vec<f64>> = basis
            .iter()
            .map(|v| (0..3).map(|i| dot(&m[i], v)).collect())
            .collect();
        let p = ritz_pairs(&basis, &images);
        assert_eq!(p.len(), 2);
        assert!((p[0].multiplier.magnitude - 0.9).abs() < 1e-14);
        assert!(
            (p[0].multiplier.frequency_per_rev - 0.4 / (2.0 * std::f64::consts::PI)).abs() < 1e-14
        );
        assert!((p[1].multiplier.re - 0.2).abs() < 1e-14);
        // span(S) is invariant: exact eigenpairs
        assert!(p
            .iter()
            .all(|q| q.multiplier.residual < 1e-14 && q.multiplier.reliable));
    }

    /// A subspace that misses part of a mode: `M = diag(0.98, 0.5)` on span of
    /// `s = (cos a, sin a)`. The Ritz value is `0.98 c^2 + 0.5 s^2` and its residual is
    /// `|M s - mu s| = 0.48 |c s|` (the component of `M s` normal to `s`).
    #[test]
    fn ritz_value_of_a_subspace_that_misses_the_mode_carries_its_residual() {
        for a in [1e-5f64, 0.2] {
            let (c, sn) = (a.cos(), a.sin());
            let s = vec![vec![c, sn]];
            let y = vec![vec![0.98 * c, 0.5 * sn]];
            let p = ritz_pairs(&s, &y);
            let mu = 0.98 * c * c + 0.5 * sn * sn;
            assert!((p[0].multiplier.re - mu).abs() < 1e-15);
            let r = 0.48 * (c * sn).abs();
            assert!((p[0].multiplier.residual - r).abs() < 1e-15 * (1.0 + r));
            assert_eq!(p[0].multiplier.reliable, a < 0.1);
        }
    }
}
