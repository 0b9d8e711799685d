//! The stroke over one step, as a device sees it. A structural step hands a device the strokes
//! at its ends and nothing between them: the chord (constant rate). A replay of sampled data
//! knows more, the rate at every sample, and drives the device along the cubic Hermite
//! interpolant through the samples' strokes and rates. On the chord a device driven by its rate
//! (a dashpot, an orifice behind stiff chambers) answers at the end of the step with the
//! interval's mean rate, the rate half a step earlier: the force lags by half a sample. On the
//! Hermite path the rate at the end is the sample's own, and the force carries no lag.
use super::HydraulicError;

/// The stroke `d(s)` for `s` in `[0, dt]` of a step: the chord from `d_i` to `d_f`, or the cubic
/// Hermite interpolant with end rates `v_i`, `v_f`, stored as the chord plus a bubble that
/// vanishes at both ends (so that moving the ends keeps the path's shape between them).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StrokePath {
    /// Step length [s].
    pub dt: f64,
    /// Stroke at the step's start [m].
    pub d_i: f64,
    /// Stroke at the step's end [m].
    pub d_f: f64,
    /// The end rates less the chord's rate, `[v_i - c, v_f - c]` [m/s] (None: the chord).
    bubble: Option<[f64; 2]>,
}

impl StrokePath {
    /// The chord: the stroke linear in time, its rate `(d_f - d_i)/dt` throughout.
    #[inline]
    pub fn linear(dt: f64, d_i: f64, d_f: f64) -> Self {
        Self {
            dt,
            d_i,
            d_f,
            bubble: None,
        }
    }

    /// The cubic Hermite interpolant: strokes `d_i`, `d_f` and rates `v_i`, `v_f` at the ends.
    /// A non-finite rate gives the chord.
    pub fn hermite(dt: f64, d_i: f64, d_f: f64, v_i: f64, v_f: f64) -> Self {
        let c = (d_f - d_i) / dt;
        let bubble = (v_i.is_finite() && v_f.is_finite()).then_some([v_i - c, v_f - c]);
        Self {
            dt,
            d_i,
            d_f,
            bubble,
        }
    }

    /// Whether the path is the chord.
    #[inline]
    pub fn is_linear(&self) -> bool {
        self.bubble.is_none()
    }

    /// The chord's rate `(d_f - d_i)/dt` [m/s]: the mean rate over the step.
    #[inline]
    pub fn chord_rate(&self) -> f64 {
        (self.d_f - self.d_i) / self.dt
    }

    /// Stroke [m] and rate [m/s] at `s` from the step's start. On the chord, `d_i + c s` and
    /// `c` exactly (the same bits as a straight step written out).
    #[inline(always)]
    pub fn at(&self, s: f64) -> (f64, f64) {
        let c = self.chord_rate();
        match self.bubble {
            None => (self.d_i + c * s, c),
            Some([bi, bf]) => {
                let u = s / self.dt;
                let w = 1.0 - u;
                // Hermite basis: h10 = u (1-u)^2, h11 = -u^2 (1-u) and their u-derivatives.
                let d = self.d_i + c * s + self.dt * u * w * (bi * w - bf * u);
                let v = c + bi * w * (1.0 - 3.0 * u) + bf * u * (3.0 * u - 2.0);
                (d, v)
            }
        }
    }

    /// Rate at the step's end [m/s].
    #[inline]
    pub fn end_rate(&self) -> f64 {
        match self.bubble {
            None => self.chord_rate(),
            Some([_, bf]) => self.chord_rate() + bf,
        }
    }

    /// Rate at the step's start [m/s].
    #[inline]
    pub fn start_rate(&self) -> f64 {
        match self.bubble {
            None => self.chord_rate(),
            Some([bi, _]) => self.chord_rate() + bi,
        }
    }

    /// The same path between other end strokes (a device behind a link or a gap: its stroke
    /// is the end's moved by the link's deflection, taken linear over the step).
    #[inline]
    pub fn with_ends(&self, d_i: f64, d_f: f64) -> Self {
        Self { d_i, d_f, ..*self }
    }

    /// The mean of `f(rate)` over the step: `f(c)` on the chord, Simpson's rule on the cubic
    /// (the rate is quadratic in time: exact for an `f` linear in it).
    pub fn mean_of_rate(&self, f: impl Fn(f64) -> f64) -> f64 {
        match self.bubble {
            None => f(self.chord_rate()),
            Some(_) => {
                let (_, vm) = self.at(0.5 * self.dt);
                (f(self.start_rate()) + 4.0 * f(vm) + f(self.end_rate())) / 6.0
            }
        }
    }

    /// Checks the step's length and strokes (finite, `dt > 0`).
    pub fn check(&self, t_i: f64) -> Result<(), HydraulicError> {
        super::check_step(t_i, self.dt, self.d_i, self.d_f)?;
        if let Some([bi, bf]) = self.bubble {
            if !(bi.is_finite() && bf.is_finite()) {
                return Err(HydraulicError::BadStep {
                    t: t_i,
                    reason: format!("non-finite stroke rates at the step's ends ({bi}, {bf})"),
                });
            }
        }
        Ok(())
    }
}

/// The stroke rate at each sample of a sampled stroke: the derivative of the interpolating
/// polynomial through the five nearest samples (two either side; the window shifted at the
/// ends), exact on any grid for a quartic: the phase error of a sine sampled `n` times a cycle
/// is nil and its amplitude error about `(2 pi / n)^4 / 30` (3e-9 at 4.3 Hz and 2 kHz). A
/// sample whose window holds a non-finite stroke gets NaN (the replay takes the chord there).
pub fn sample_rates(t: &[f64], x: &[f64]) -> Vec<f64> {
    let n = t.len().min(x.len());
    if n < 2 {
        return vec![0.0; n];
    }
    let width = n.min(5);
    (0..n)
        .map(|i| {
            let lo = i.saturating_sub(2).min(n - width);
            lagrange_slope(&t[lo..lo + width], &x[lo..lo + width], t[i])
        })
        .collect()
}

/// Derivative at `s` of the polynomial through the points `(t_j, x_j)` (Lagrange form).
fn lagrange_slope(t: &[f64], x: &[f64], s: f64) -> f64 {
    let m = t.len();
    let mut sum = 0.0;
    for j in 0..m {
        let denom: f64 = t
            .iter()
            .enumerate()
            .filter(|&(k, _)| k != j)
            .map(|(_, &tk)| t[j] - tk)
            .product();
        // d/ds prod_{k != j} (s - t_k) = sum_l prod_{k != j, l} (s - t_k)
        let mut num = 0.0;
        for l in (0..m).filter(|&l| l != j) {
            num += t
                .iter()
                .enumerate()
                .filter(|&(k, _)| k != j && k != l)
                .map(|(_, &tk)| s - tk)
                .product::<f64>();
        }
        sum += x[j] * num / denom;
    }
    sum
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_chord_is_the_straight_step_bit_for_bit() {
        let p = StrokePath::linear(3e-4, 0.0123, 0.0127);
        for s in [0.0, 1e-4, 2.9e-4, 3e-4] {
            let c = (0.0127 - 0.0123) / 3e-4;
            assert_eq!(p.at(s), (0.0123 + c * s, c));
        }
        assert_eq!(p.end_rate(), p.chord_rate());
    }

    #[test]
    fn hermite_ends_and_a_cubic_reproduced() {
        // d(s) = 1 + 2 s - 3 s^2 + 5 s^3 is its own Hermite interpolant.
        let d = |s: f64| 1.0 + 2.0 * s - 3.0 * s * s + 5.0 * s * s * s;
        let v = |s: f64| 2.0 - 6.0 * s + 15.0 * s * s;
        let dt = 0.7;
        let p = StrokePath::hermite(dt, d(0.0), d(dt), v(0.0), v(dt));
        for k in 0..=10 {
            let s = dt * k as f64 / 10.0;
            let (ds, vs) = p.at(s);
            assert!((ds - d(s)).abs() < 1e-14, "{s}: {ds} {}", d(s));
            assert!((vs - v(s)).abs() < 1e-13, "{s}: {vs} {}", v(s));
        }
        assert!((p.end_rate() - v(dt)).abs() < 1e-13);
        assert!((p.start_rate() - v(0.0)).abs() < 1e-13);
        // Simpson on a quadratic rate: the mean rate is the chord's.
        assert!((p.mean_of_rate(|r| r) - p.chord_rate()).abs() < 1e-13);
        // Moved ends keep the bubble: the difference is the chord's difference.
        let q = p.with_ends(2.0, 3.0);
        let (a, _) = p.at(0.3);
        let (b, _) = q.at(0.3);
        let chord = |p: &StrokePath, s: f64| p.d_i + p.chord_rate() * s;
        assert!(((b - chord(&q, 0.3)) - (a - chord(&p, 0.3))).abs() < 1e-14);
    }

    #[test]
    fn sample_rates_of_a_sine_have_no_phase() {
        let (w, h) = (2.0 * std::f64::consts::PI * 4.3, 5e-4);
        let t: Vec<f64> = (0..400).map(|k| k as f64 * h).collect();
        let x: Vec<f64> = t.iter().map(|&s| 2e-3 * (w * s).sin()).collect();
        let v = sample_rates(&t, &x);
        let worst = t
            .iter()
            .zip(&v)
            .map(|(&s, &r)| (r - 2e-3 * w * (w * s).cos()).abs())
            .fold(0.0, f64::max);
        // (w h)^4 / 30 of the peak rate inside, (w h)^4 / 5 at the shifted ends
        assert!(worst < 2e-3 * w * 1e-7, "{worst}");
    }

    #[test]
    fn a_gap_gives_nan_rates_nearby_only() {
        let t: Vec<f64> = (0..20).map(|k| k as f64).collect();
        let mut x: Vec<f64> = t.iter().map(|s| s * s).collect();
        x[10] = f64::NAN;
        let v = sample_rates(&t, &x);
        assert!(v[8..=12].iter().all(|r| r.is_nan()));
        assert!((v[5] - 10.0).abs() < 1e-9 && (v[15] - 30.0).abs() < 1e-9);
        let p = StrokePath::hermite(1.0, 0.0, 1.0, v[10], 1.0);
        assert!(p.is_linear());
    }
}
