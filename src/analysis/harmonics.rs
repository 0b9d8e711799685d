//! Harmonic content of a periodic signal sampled over one revolution.
//!
//! A least-squares fit of `y(psi) = a0 + sum_n (a_n cos n psi + b_n sin n psi)`: on uniform
//! azimuths it equals the discrete Fourier transform, and it also accepts the non-uniform or
//! partial azimuth sets that measured channels sometimes have.
use nalgebra::{DMatrix, DVector};

/// One harmonic `n/rev`: `a cos(n psi) + b sin(n psi) = amplitude cos(n psi - phase)`.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct Harmonic {
    pub n: usize,
    pub cos: f64,
    pub sin: f64,
    pub amplitude: f64,
    pub phase_deg: f64,
}

/// Errors of the harmonic fit.
#[derive(Debug, thiserror::Error, PartialEq)]
pub enum HarmonicError {
    #[error(
        "harmonic fit needs at least {needed} distinct azimuths for {n_max} harmonics, got {got}"
    )]
    TooFewSamples {
        needed: usize,
        got: usize,
        n_max: usize,
    },
    #[error("azimuth and value arrays differ in length ({0} vs {1})")]
    Length(usize, usize),
    #[error("non-finite sample at index {0}")]
    NonFinite(usize),
}

/// Fits harmonics 0..=n_max/rev to samples `y` at azimuths `psi_deg`.
pub fn harmonics(psi_deg: &[f64], y: &[f64], n_max: usize) -> Result<Vec<Harmonic>, HarmonicError> {
    if psi_deg.len() != y.len() {
        return Err(HarmonicError::Length(psi_deg.len(), y.len()));
    }
    if let Some(i) = psi_deg
        .iter()
        .zip(y)
        .position(|(p, v)| !p.is_finite() || !v.is_finite())
    {
        return Err(HarmonicError::NonFinite(i));
    }
    let needed = 2 * n_max + 1;
    if y.len() < needed {
        return Err(HarmonicError::TooFewSamples {
            needed,
            got: y.len(),
            n_max,
        });
    }
    let m = y.len();
    let a = DMatrix::from_fn(m, needed, |i, j| {
        let psi = psi_deg[i].to_radians();
        if j == 0 {
            1.0
        } else {
            let n = j.div_ceil(2) as f64;
            if j % 2 == 1 {
                (n * psi).cos()
            } else {
                (n * psi).sin()
            }
        }
    });
    let rhs = DVector::from_column_slice(y);
    let svd = a.svd(true, true);
    // Rank deficiency (e.g. duplicated azimuths only) shows up as tiny singular values.
    let smax = svd.singular_values.max();
    let rank = svd
        .singular_values
        .iter()
        .filter(|s| **s > 1e-10 * smax)
        .count();
    if rank < needed {
        return Err(HarmonicError::TooFewSamples {
            needed,
            got: rank,
            n_max,
        });
    }
    let c = svd
        .solve(&rhs, 1e-12 * smax)
        .expect("SVD computed with U and V");
    let mut out = Vec::with_capacity(n_max + 1);
    out.push(Harmonic {
        n: 0,
        cos: c[0],
        sin: 0.0,
        amplitude: c[0].abs(),
        phase_deg: 0.0,
    });
    for n in 1..=n_max {
        let (ac, bs) = (c[2 * n - 1], c[2 * n]);
        out.push(Harmonic {
            n,
            cos: ac,
            sin: bs,
            amplitude: ac.hypot(bs),
            phase_deg: bs.atan2(ac).to_degrees(),
        });
    }
    Ok(out)
}

/// Evaluates a harmonic series at `psi_deg`.
pub fn evaluate(h: &[Harmonic], psi_deg: f64) -> f64 {
    let psi = psi_deg.to_radians();
    h.iter()
        .map(|h| {
            if h.n == 0 {
                h.cos
            } else {
                let n = h.n as f64;
                h.cos * (n * psi).cos() + h.sin * (n * psi).sin()
            }
        })
        .sum()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn signal(psi: f64) -> f64 {
        let p = psi.to_radians();
        3.0 + 2.0 * p.cos() - 0.5 * p.sin() + 0.25 * (4.0 * p - 0.3).cos()
    }

    #[test]
    fn recovers_known_harmonics_on_uniform_grid() {
        let psi: Vec<f64> = (0..256).map(|i| i as f64 * 360.0 / 256.0).collect();
        let y: Vec<f64> = psi.iter().map(|p| signal(*p)).collect();
        let h = harmonics(&psi, &y, 10).unwrap();
        assert!((h[0].cos - 3.0).abs() < 1e-12);
        assert!((h[1].cos - 2.0).abs() < 1e-12 && (h[1].sin + 0.5).abs() < 1e-12);
        assert!((h[4].amplitude - 0.25).abs() < 1e-12);
        assert!((h[4].phase_deg - 0.3f64.to_degrees()).abs() < 1e-9);
        for k in [2, 3, 5, 6, 7, 8, 9, 10] {
            assert!(h[k].amplitude < 1e-12, "harmonic {k}");
        }
        for p in [0.0, 17.3, 359.0] {
            assert!((evaluate(&h, p) - signal(p)).abs() < 1e-12);
        }
    }

    #[test]
    fn non_uniform_azimuths_give_the_same_fit() {
        let psi: Vec<f64> = (0..90)
            .map(|i| (i as f64 * 4.1).powf(1.01) % 360.0)
            .collect();
        let y: Vec<f64> = psi.iter().map(|p| signal(*p)).collect();
        let h = harmonics(&psi, &y, 6).unwrap();
        assert!((h[4].amplitude - 0.25).abs() < 1e-10);
    }

    #[test]
    fn too_few_samples_is_an_error() {
        let e = harmonics(&[0.0, 90.0, 180.0], &[1.0, 2.0, 3.0], 10).unwrap_err();
        assert!(matches!(e, HarmonicError::TooFewSamples { needed: 21, .. }));
        let e = harmonics(&[0.0; 30], &[1.0; 30], 2).unwrap_err();
        assert!(matches!(e, HarmonicError::TooFewSamples { .. }), "{e:?}");
        assert_eq!(
            harmonics(&[0.0, 1.0], &[f64::NAN, 1.0], 0).unwrap_err(),
            HarmonicError::NonFinite(0)
        );
    }
}
