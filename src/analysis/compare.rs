//! Model-versus-measurement metrics, computed on the measurement's own azimuths.
//!
//! The model's last revolution (any azimuth grid) is interpolated periodically to each measured
//! azimuth; the metrics then compare sample by sample, so no measured value is resampled.
use super::harmonics::{harmonics, Harmonic, HarmonicError};

/// Errors of the comparison.
#[derive(Debug, thiserror::Error, PartialEq)]
pub enum CompareError {
    #[error("{what}: azimuths and values differ in length ({a} vs {b})")]
    Length {
        what: &'static str,
        a: usize,
        b: usize,
    },
    #[error("{what}: needs at least {needed} samples, got {got}")]
    TooFew {
        what: &'static str,
        needed: usize,
        got: usize,
    },
    #[error("{what}: non-finite value at index {index}")]
    NonFinite { what: &'static str, index: usize },
    #[error(transparent)]
    Harmonics(#[from] HarmonicError),
}

/// A signal over one revolution.
#[derive(Debug, Clone, Copy)]
pub struct Periodic<'a> {
    pub psi_deg: &'a [f64],
    pub value: &'a [f64],
}

impl<'a> Periodic<'a> {
    /// Values at azimuths [deg].
    pub fn new(psi_deg: &'a [f64], value: &'a [f64]) -> Self {
        Periodic { psi_deg, value }
    }
}

fn check(what: &'static str, s: Periodic<'_>, needed: usize) -> Result<(), CompareError> {
    if s.psi_deg.len() != s.value.len() {
        return Err(CompareError::Length {
            what,
            a: s.psi_deg.len(),
            b: s.value.len(),
        });
    }
    if s.value.len() < needed {
        return Err(CompareError::TooFew {
            what,
            needed,
            got: s.value.len(),
        });
    }
    if let Some(index) = s
        .psi_deg
        .iter()
        .zip(s.value)
        .position(|(p, v)| !p.is_finite() || !v.is_finite())
    {
        return Err(CompareError::NonFinite { what, index });
    }
    Ok(())
}

/// Periodic linear interpolation of a one-revolution signal at `psi_deg` (any angle).
/// The samples need not be sorted; they are treated as points on the circle.
pub struct PeriodicInterp {
    psi: Vec<f64>,
    val: Vec<f64>,
}

impl PeriodicInterp {
    pub fn new(s: Periodic<'_>) -> Result<Self, CompareError> {
        check("model", s, 2)?;
        let mut idx: Vec<usize> = (0..s.value.len()).collect();
        let wrapped: Vec<f64> = s.psi_deg.iter().map(|p| p.rem_euclid(360.0)).collect();
        idx.sort_by(|&a, &b| wrapped[a].total_cmp(&wrapped[b]));
        Ok(Self {
            psi: idx.iter().map(|&i| wrapped[i]).collect(),
            val: idx.iter().map(|&i| s.value[i]).collect(),
        })
    }

    /// Value at `psi_deg`: exact at the samples, linear between them, across 360 too.
    pub fn at(&self, psi_deg: f64) -> f64 {
        let p = psi_deg.rem_euclid(360.0);
        let n = self.psi.len();
        let k = self.psi.partition_point(|&q| q <= p);
        let (i0, i1) = if k == 0 || k == n {
            (n - 1, 0)
        } else {
            (k - 1, k)
        };
        let (p0, p1) = (self.psi[i0], self.psi[i1]);
        let span = (p1 - p0).rem_euclid(360.0);
        if span == 0.0 {
            return self.val[i0];
        }
        let w = (p - p0).rem_euclid(360.0) / span;
        self.val[i0] + w * (self.val[i1] - self.val[i0])
    }
}

/// Comparison metrics of a model signal against a measured one.
#[derive(Debug, Clone, serde::Serialize)]
pub struct Metrics {
    /// Root mean square of (model - measured) at the measured azimuths.
    pub rms_error: f64,
    /// RMS error relative to the measurement's RMS about its mean.
    pub rms_error_rel: f64,
    pub max_abs_error: f64,
    pub peak_to_peak_model: f64,
    pub peak_to_peak_measured: f64,
    /// Peak-to-peak of the model minus that of the measurement.
    pub peak_to_peak_error: f64,
    pub mean_model: f64,
    pub mean_measured: f64,
    /// Pearson correlation coefficient.
    pub correlation: f64,
    /// Harmonics 0..=n of the model (sampled at the measured azimuths) and of the measurement.
    pub harmonics_model: Vec<Harmonic>,
    pub harmonics_measured: Vec<Harmonic>,
    pub samples: usize,
}

fn mean(v: &[f64]) -> f64 {
    v.iter().sum::<f64>() / v.len() as f64
}

fn ptp(v: &[f64]) -> f64 {
    let (lo, hi) = v
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(l, h), x| {
            (l.min(*x), h.max(*x))
        });
    hi - lo
}

/// Least-squares slope of the points `(x, y)` (a growth rate from `(t, ln A)`); NaN for fewer
/// than two distinct `x`.
pub fn slope(pts: &[(f64, f64)]) -> f64 {
    let n = pts.len() as f64;
    let (mx, my) = pts
        .iter()
        .fold((0.0, 0.0), |(p, q), s| (p + s.0 / n, q + s.1 / n));
    let (sxy, sxx) = pts.iter().fold((0.0, 0.0), |(p, q), s| {
        (p + (s.0 - mx) * (s.1 - my), q + (s.0 - mx) * (s.0 - mx))
    });
    sxy / sxx
}

/// Compares `model` (one revolution) with `measured`, on the measured azimuths, with harmonics
/// up to `n_harmonics`/rev.
pub fn compare(
    model: Periodic<'_>,
    measured: Periodic<'_>,
    n_harmonics: usize,
) -> Result<Metrics, CompareError> {
    check("measured", measured, 2 * n_harmonics + 1)?;
    let interp = PeriodicInterp::new(model)?;
    let m: Vec<f64> = measured.psi_deg.iter().map(|p| interp.at(*p)).collect();
    let y = measured.value;
    let n = y.len() as f64;
    let (mm, my) = (mean(&m), mean(y));
    let mut se = 0.0;
    let mut max_abs: f64 = 0.0;
    let (mut sxy, mut sxx, mut syy) = (0.0, 0.0, 0.0);
    for (a, b) in m.iter().zip(y) {
        let e = a - b;
        se += e * e;
        max_abs = max_abs.max(e.abs());
        sxy += (a - mm) * (b - my);
        sxx += (a - mm) * (a - mm);
        syy += (b - my) * (b - my);
    }
    let rms_error = (se / n).sqrt();
    let rms_meas = (syy / n).sqrt();
    let correlation = if sxx > 0.0 && syy > 0.0 {
        sxy / (sxx * syy).sqrt()
    } else {
        f64::NAN
    };
    let (pm, py) = (ptp(&m), ptp(y));
    Ok(Metrics {
        rms_error,
        rms_error_rel: if rms_meas > 0.0 {
            rms_error / rms_meas
        } else {
            f64::NAN
        },
        max_abs_error: max_abs,
        peak_to_peak_model: pm,
        peak_to_peak_measured: py,
        peak_to_peak_error: pm - py,
        mean_model: mm,
        mean_measured: my,
        correlation,
        harmonics_model: harmonics(measured.psi_deg, &m, n_harmonics)?,
        harmonics_measured: harmonics(measured.psi_deg, y, n_harmonics)?,
        samples: y.len(),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn grid(n: usize) -> Vec<f64> {
        (0..n).map(|i| i as f64 * 360.0 / n as f64).collect()
    }

    #[test]
    fn interpolation_is_exact_at_samples_and_periodic() {
        let psi = grid(8);
        let v: Vec<f64> = (0..8).map(|i| (i * i) as f64).collect();
        let f = PeriodicInterp::new(Periodic::new(&psi, &v)).unwrap();
        for (p, x) in psi.iter().zip(&v) {
            assert_eq!(f.at(*p), *x);
            assert_eq!(f.at(*p + 360.0), *x);
            assert_eq!(f.at(*p - 720.0), *x);
        }
        // Between the last sample (315 deg, 49) and 360 = 0 deg (0): halfway is 24.5.
        assert!((f.at(337.5) - 24.5).abs() < 1e-12);
        assert!((f.at(-22.5) - 24.5).abs() < 1e-12);
    }

    #[test]
    fn identical_signals_have_zero_error_and_unit_correlation() {
        let psi = grid(256);
        let y: Vec<f64> = psi.iter().map(|p| p.to_radians().sin() * 1e4).collect();
        let s = Periodic::new(&psi, &y);
        let m = compare(s, s, 10).unwrap();
        assert_eq!(m.rms_error, 0.0);
        assert!((m.correlation - 1.0).abs() < 1e-12);
        assert_eq!(m.peak_to_peak_error, 0.0);
    }

    #[test]
    fn known_offset_and_scale_give_analytic_metrics() {
        // model = 2 sin + 1 against measured = sin: error = sin + 1,
        // RMS error = sqrt(1/2 + 1), ptp error = 2, correlation 1.
        let psi = grid(360);
        let meas: Vec<f64> = psi.iter().map(|p| p.to_radians().sin()).collect();
        let model: Vec<f64> = meas.iter().map(|v| 2.0 * v + 1.0).collect();
        let m = compare(Periodic::new(&psi, &model), Periodic::new(&psi, &meas), 10).unwrap();
        assert!((m.rms_error - 1.5f64.sqrt()).abs() < 1e-12);
        assert!((m.peak_to_peak_error - 2.0).abs() < 1e-12);
        assert!((m.correlation - 1.0).abs() < 1e-12);
        assert!((m.harmonics_model[1].amplitude - 2.0).abs() < 1e-12);
        assert!((m.harmonics_model[0].cos - 1.0).abs() < 1e-12);
    }

    #[test]
    fn model_on_another_grid_is_compared_at_measured_azimuths() {
        // A linear-in-psi model segment is reproduced exactly by linear interpolation.
        let psi_model = grid(256);
        let model: Vec<f64> = psi_model.iter().map(|p| 3.0 * p).collect();
        let psi_meas: Vec<f64> = (0..100).map(|i| 1.0 + 3.3 * i as f64).collect();
        let meas: Vec<f64> = psi_meas.iter().map(|p| 3.0 * p).collect();
        let m = compare(
            Periodic::new(&psi_model, &model),
            Periodic::new(&psi_meas, &meas),
            3,
        )
        .unwrap();
        assert!(m.rms_error < 1e-9, "{}", m.rms_error);
    }

    #[test]
    fn bad_input_is_reported() {
        let psi = grid(4);
        let e = compare(
            Periodic {
                psi_deg: &psi,
                value: &[1.0, 2.0, 3.0, 4.0],
            },
            Periodic {
                psi_deg: &psi,
                value: &[1.0, f64::NAN, 3.0, 4.0],
            },
            1,
        )
        .unwrap_err();
        assert_eq!(
            e,
            CompareError::NonFinite {
                what: "measured",
                index: 1
            }
        );
    }
}
