//! Convergence to a periodic solution, monitored once per revolution.
//!
//! For each monitored channel the measure is the largest change of any sample from one revolution
//! to the next, divided by the channel's peak-to-peak over the newer revolution (a floor keeps a
//! channel that is nearly constant from dividing by zero). The run's measure is the largest over
//! channels; it falls below a tolerance (1e-3 by default) once transients have died out.

/// Relative change of one revolution `cur` with respect to the previous one `prev`, sampled at
/// the same azimuths. `floor` is the smallest scale used (in the channel's unit).
pub fn relative_change(prev: &[f64], cur: &[f64], floor: f64) -> f64 {
    assert_eq!(prev.len(), cur.len(), "revolutions sampled alike");
    let d = max_nan_poisoned(
        &prev
            .iter()
            .zip(cur)
            .map(|(a, b)| (b - a).abs())
            .collect::<Vec<_>>(),
    );
    d / scale(cur, floor)
}

/// Change of a channel over one revolution, end against start, relative to its peak-to-peak
/// over the revolution (`samples[0]` is the start, `end` the value after the last step): the
/// periodicity residual `|c(Phi(x)) - c(x)| / ptp` of a revolution map (docs/periodic.md).
pub fn boundary_change(samples: &[f64], end: f64, floor: f64) -> f64 {
    let d = (end - samples[0]).abs();
    if d.is_nan() {
        return f64::NAN;
    }
    d / scale(samples, floor)
}

/// Peak-to-peak of `v`, at least `floor`; NaN if any value is NaN.
fn scale(v: &[f64], floor: f64) -> f64 {
    if v.iter().any(|x| x.is_nan()) {
        return f64::NAN;
    }
    let (lo, hi) = v
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(l, h), x| {
            (l.min(*x), h.max(*x))
        });
    (hi - lo).max(floor)
}

/// Largest value, NaN if any value is NaN (`f64::max` would silently drop it).
pub fn max_nan_poisoned(v: &[f64]) -> f64 {
    if v.iter().any(|x| x.is_nan()) {
        f64::NAN
    } else {
        v.iter().fold(0.0f64, |m, x| m.max(*x))
    }
}

/// Per-revolution periodicity history of several named channels.
#[derive(Debug, Clone, serde::Serialize)]
pub struct PeriodicityMonitor {
    pub channels: Vec<String>,
    pub floors: Vec<f64>,
    /// `history[r][c]`: measure of channel `c` after revolution `r` (revolution 0 has none).
    pub history: Vec<Vec<f64>>,
    #[serde(skip)]
    previous: Option<Vec<Vec<f64>>>,
}

impl PeriodicityMonitor {
    pub fn new(channels: &[(&str, f64)]) -> Self {
        Self {
            channels: channels.iter().map(|c| c.0.to_string()).collect(),
            floors: channels.iter().map(|c| c.1).collect(),
            history: Vec::new(),
            previous: None,
        }
    }

    /// Records one completed revolution (`samples[c]` for each channel), returning the measure
    /// (max over channels), or `None` for the first revolution.
    pub fn push_revolution(&mut self, samples: Vec<Vec<f64>>) -> Option<f64> {
        assert_eq!(samples.len(), self.channels.len());
        let out = self.previous.as_ref().map(|prev| {
            let per: Vec<f64> = prev
                .iter()
                .zip(&samples)
                .zip(&self.floors)
                .map(|((p, c), f)| relative_change(p, c, *f))
                .collect();
            let m = max_nan_poisoned(&per);
            self.history.push(per);
            m
        });
        self.previous = Some(samples);
        out
    }

    /// The latest measure (max over channels).
    pub fn latest(&self) -> Option<f64> {
        self.history.last().map(|v| max_nan_poisoned(v))
    }

    /// True once the latest measure is below `tol`.
    pub fn converged(&self, tol: f64) -> bool {
        self.latest().is_some_and(|m| m < tol)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn decaying_transient_converges_at_the_analytic_revolution() {
        // y_r(psi) = sin(psi) + 0.5^r cos(psi): change between revolutions r-1 and r is
        // 0.5^r * max|cos| = 0.5^r, ptp ~ 2 sqrt(1 + 0.25^r).
        let psi: Vec<f64> = (0..256)
            .map(|i| i as f64 * 2.0 * std::f64::consts::PI / 256.0)
            .collect();
        let mut mon = PeriodicityMonitor::new(&[("force_N", 1.0)]);
        let mut first_converged = None;
        for r in 0..20 {
            let y: Vec<f64> = psi
                .iter()
                .map(|p| p.sin() + 0.5f64.powi(r) * p.cos())
                .collect();
            let m = mon.push_revolution(vec![y]);
            if r == 0 {
                assert!(m.is_none());
                continue;
            }
            let m = m.unwrap();
            let expect = 0.5f64.powi(r) / (2.0 * (1.0 + 0.25f64.powi(r)).sqrt());
            assert!(
                (m - expect).abs() < 1e-3 * expect + 1e-12,
                "rev {r}: {m} vs {expect}"
            );
            if first_converged.is_none() && mon.converged(1e-3) {
                first_converged = Some(r);
            }
        }
        // 0.5^r / 2 < 1e-3  <=>  r >= 9.
        assert_eq!(first_converged, Some(9));
    }

    #[test]
    fn boundary_change_of_a_decaying_revolution() {
        // y(psi) = sin(psi) + 0.5 e^{-psi / 2 pi} over one revolution: start 0.5, end 0.5/e
        let n = 256;
        let y: Vec<f64> = (0..n)
            .map(|i| {
                let p = i as f64 * 2.0 * std::f64::consts::PI / n as f64;
                p.sin() + 0.5 * (-p / (2.0 * std::f64::consts::PI)).exp()
            })
            .collect();
        let end = 0.5 * (-1.0f64).exp();
        let (lo, hi) = y
            .iter()
            .fold((f64::MAX, f64::MIN), |(l, h), v| (l.min(*v), h.max(*v)));
        let want = (0.5 - end) / (hi - lo);
        assert!((boundary_change(&y, end, 1e-3) - want).abs() < 1e-15);
        // a flat channel is judged on its floor
        assert_eq!(boundary_change(&[1.0, 1.0], 1.5, 2.0), 0.25);
        assert!(boundary_change(&[1.0, f64::NAN], 1.0, 1.0).is_nan());
        assert!(boundary_change(&[1.0, 2.0], f64::NAN, 1.0).is_nan());
    }

    #[test]
    fn nan_is_never_periodic() {
        let mut mon = PeriodicityMonitor::new(&[("x", 1.0)]);
        mon.push_revolution(vec![vec![1.0, 2.0]]);
        let m = mon.push_revolution(vec![vec![f64::NAN, 2.0]]).unwrap();
        assert!(m.is_nan());
        assert!(max_nan_poisoned(&[f64::NAN, 1.0]).is_nan());
        assert!(max_nan_poisoned(&[1.0, f64::NAN]).is_nan());
        let mut two = PeriodicityMonitor::new(&[("a", 1.0), ("b", 1.0)]);
        two.push_revolution(vec![vec![1.0, 2.0], vec![1.0, 2.0]]);
        two.push_revolution(vec![vec![f64::NAN, 2.0], vec![1.0, 2.0]]);
        assert!(two.latest().unwrap().is_nan());
        assert!(!mon.converged(1e-3));
    }
}
