//! Acquisition faults: candidates where the data acquisition, not the damper, is wrong. The
//! recorded force is `y(t) = g F(t - tau) + o + d (t - t0)`: the damper's force `F` seen
//! through a channel that lags the stroke by `tau`, reads `g` times too much (calibration),
//! carries an offset `o` and drifts by `d` per second from the start `t0` of each test. Each
//! fault is fitted alone, on top of the model it corrects (the baseline or a fitted physical
//! cause), so its fit needs no damper replay: offset, gain and drift are linear least squares,
//! the lag a one-dimensional search.
use super::data::Measurement;

/// One acquisition fault (docs/formats.md `cause`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Fault {
    /// The force channel lags the stroke channel by `lag_s`.
    Lag,
    /// A constant `offset_N` on the force.
    Offset,
    /// The force reads `gain` times the true force.
    Gain,
    /// The force drifts by `drift_N_per_s` from the start of each test.
    Drift,
}

impl Fault {
    pub const ALL: [Fault; 4] = [Fault::Lag, Fault::Offset, Fault::Gain, Fault::Drift];

    pub fn name(self) -> &'static str {
        match self {
            Fault::Lag => "force_lag",
            Fault::Offset => "force_offset",
            Fault::Gain => "force_gain",
            Fault::Drift => "force_drift",
        }
    }

    /// The fitted parameter (unit in the name).
    pub fn param(self) -> &'static str {
        match self {
            Fault::Lag => "lag_s",
            Fault::Offset => "offset_N",
            Fault::Gain => "gain",
            Fault::Drift => "drift_N_per_s",
        }
    }

    pub fn from_name(name: &str) -> Option<Fault> {
        Fault::ALL.into_iter().find(|f| f.name() == name)
    }

    /// The recorded force of a model force `f` sampled at `t` with this fault at `value`.
    pub fn apply(self, value: f64, t: &[f64], f: &[f64]) -> Vec<f64> {
        match self {
            Fault::Lag => (0..t.len()).map(|i| at(t, f, t[i] - value)).collect(),
            Fault::Offset => f.iter().map(|x| x + value).collect(),
            Fault::Gain => f.iter().map(|x| value * x).collect(),
            Fault::Drift => t
                .iter()
                .zip(f)
                .map(|(ti, x)| x + value * (ti - t[0]))
                .collect(),
        }
    }

    /// Inverse of [`Fault::apply`] on the recorded force `y`: what the damper's force was,
    /// for refitting a physical cause beside the fault.
    pub fn correct(self, value: f64, t: &[f64], y: &[f64]) -> Vec<f64> {
        match self {
            Fault::Lag => (0..t.len()).map(|i| at(t, y, t[i] + value)).collect(),
            Fault::Offset => y.iter().map(|x| x - value).collect(),
            Fault::Gain => y.iter().map(|x| x / value).collect(),
            Fault::Drift => t
                .iter()
                .zip(y)
                .map(|(ti, x)| x - value * (ti - t[0]))
                .collect(),
        }
    }
}

/// Clipping at the load cell's range, found by the data screen (not fitted).
pub const CLIPPING: &str = "force_clipping";
/// Rows missing a value, found by the data screen (not fitted).
pub const DROPOUTS: &str = "force_dropouts";

/// Whether `name` is an acquisition fault: fitted, or found by the data screen.
pub fn is_fault(name: &str) -> bool {
    Fault::from_name(name).is_some() || name == CLIPPING || name == DROPOUTS
}

/// Whether every part of a cause's name (`a` or `a+b`) is an acquisition fault: the damper
/// itself is then the baseline's.
pub fn only_faults(cause: &str) -> bool {
    cause.split('+').all(is_fault)
}

/// The part of a cause's name the damper model was fitted with: the name without the faults the
/// data screen found (`none` when nothing else is left).
pub fn fitted_cause(cause: &str) -> String {
    let parts: Vec<&str> = cause
        .split('+')
        .filter(|n| *n != CLIPPING && *n != DROPOUTS)
        .collect();
    if parts.is_empty() {
        "none".into()
    } else {
        parts.join("+")
    }
}

/// `f` at time `s` by linear interpolation between samples (held constant outside the record).
/// At 2 kHz the interpolation error of a 4/rev stroke's force is ~1e-4 of the force, far below
/// the 1% noise of a load cell.
fn at(t: &[f64], f: &[f64], s: f64) -> f64 {
    let n = t.len();
    if s <= t[0] {
        return f[0];
    }
    if s >= t[n - 1] {
        return f[n - 1];
    }
    let k = t.partition_point(|&x| x <= s).clamp(1, n - 1);
    let (t0, t1) = (t[k - 1], t[k]);
    let w = (s - t0) / (t1 - t0);
    f[k - 1] + w * (f[k] - f[k - 1])
}

/// Samples `[from, to)` of test `test`, compared with the model.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Span {
    pub test: usize,
    pub from: usize,
    pub to: usize,
}

/// A fault fitted over spans: its value, the residual sum of squares there, the sensitivity
/// `sum (dy/dvalue)^2` at the fit (for its interval) and the model evaluations it took.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FaultFit {
    pub value: f64,
    pub rss: f64,
    pub sensitivity: f64,
    pub evaluations: usize,
}

fn rss(fault: Fault, v: f64, data: &[Measurement], model: &[Vec<f64>], spans: &[Span]) -> f64 {
    spans
        .iter()
        .map(|s| {
            let m = &data[s.test];
            let y = fault.apply(v, &m.time_s, &model[s.test]);
            y[s.from..s.to]
                .iter()
                .zip(&m.force_n[s.from..s.to])
                .filter(|(_, b)| !b.is_nan())
                .map(|(a, b)| (a - b) * (a - b))
                .sum::<f64>()
        })
        .sum()
}

/// The minimiser of `e` on `[a, b]` by golden-section search, to a bracket of width `tol`
/// (the bracket's middle).
fn golden_section(e: &mut impl FnMut(f64) -> f64, mut a: f64, mut b: f64, tol: f64) -> f64 {
    let g = 0.5 * (5f64.sqrt() - 1.0);
    let (mut c, mut d) = (b - g * (b - a), a + g * (b - a));
    let (mut fc, mut fd) = (e(c), e(d));
    while b - a > tol {
        if fc < fd {
            (b, d, fd) = (d, c, fc);
            c = b - g * (b - a);
            fc = e(c);
        } else {
            (a, c, fc) = (c, d, fd);
            d = a + g * (b - a);
            fd = e(d);
        }
    }
    0.5 * (a + b)
}

/// The lag within `[-band, band]` that best aligns `model` with the recorded force over
/// `spans` (golden-section search; RSS is smooth in the lag at this scale), and the model so
/// shifted, one full series per test. What a sampling convention alone can do to a model: the
/// no-effect reference a cause must beat ([`super::support::timing_uncertainty_s`]).
pub fn aligned_within(
    data: &[Measurement],
    model: &[Vec<f64>],
    spans: &[Span],
    band: f64,
) -> (f64, Vec<Vec<f64>>) {
    let e = |v: f64| rss(Fault::Lag, v, data, model, spans);
    let mid = golden_section(
        &mut |v| e(v),
        -band.abs(),
        band.abs(),
        1e-3 * band.abs().max(1e-9),
    );
    // the ends of the band and no lag too: the optimum may sit on one
    let lag = [0.0, -band.abs(), mid, band.abs()]
        .into_iter()
        .min_by(|x, y| e(*x).total_cmp(&e(*y)))
        .unwrap_or(0.0);
    let shifted = data
        .iter()
        .zip(model)
        .map(|(m, f)| Fault::Lag.apply(lag, &m.time_s, f))
        .collect();
    (lag, shifted)
}

/// Gains a calibration error can have: a channel reading half or twice the force (or with the
/// wrong sign) has the wrong unit or wiring, not a calibration error, and a damper model that
/// predicts almost no force must not be scaled up to the data.
pub const GAIN_RANGE: [f64; 2] = [0.5, 2.0];

/// Longest lag searched: a quarter of the shortest stroking period (a lag beyond it is a
/// phase error no data acquisition makes).
fn max_lag(data: &[Measurement], spans: &[Span]) -> f64 {
    spans
        .iter()
        .map(|s| 0.25 * data[s.test].period_s)
        .fold(f64::INFINITY, f64::min)
}

/// Fits `fault` to the recorded force of `data` over `spans`, on top of the model force
/// `model` (one full series per test). Offset, gain and drift by linear least squares (their
/// sensitivities 1, `F` and `t - t0`); the lag by a scan over whole samples up to a quarter
/// period, refined by golden-section search between the neighbours of the best sample.
pub fn fit(fault: Fault, data: &[Measurement], model: &[Vec<f64>], spans: &[Span]) -> FaultFit {
    let each = |g: &mut dyn FnMut(f64, f64, f64)| {
        for s in spans {
            let m = &data[s.test];
            let t0 = m.time_s[0];
            let r = s.from..s.to;
            for ((t, f), y) in m.time_s[r.clone()]
                .iter()
                .zip(&model[s.test][r.clone()])
                .zip(&m.force_n[r])
                .filter(|(_, y)| !y.is_nan())
            {
                g(t - t0, *f, *y);
            }
        }
    };
    let linear = |col: &dyn Fn(f64, f64) -> f64, target: &dyn Fn(f64, f64) -> f64| {
        let (mut num, mut den) = (0.0, 0.0);
        each(&mut |tau, f, y| {
            let c = col(tau, f);
            num += c * target(f, y);
            den += c * c;
        });
        (num / den, den)
    };
    let (value, sensitivity, evaluations) = match fault {
        Fault::Offset => {
            let (v, s) = linear(&|_, _| 1.0, &|f, y| y - f);
            (v, s, 1)
        }
        Fault::Gain => {
            let (v, s) = linear(&|_, f| f, &|_, y| y);
            // RSS is quadratic in the gain: the bounded optimum is the clamped one.
            (v.clamp(GAIN_RANGE[0], GAIN_RANGE[1]), s, 1)
        }
        Fault::Drift => {
            let (v, s) = linear(&|tau, _| tau, &|f, y| y - f);
            (v, s, 1)
        }
        Fault::Lag => {
            let dt = spans
                .iter()
                .map(|s| {
                    let t = &data[s.test].time_s;
                    (t[t.len() - 1] - t[0]) / (t.len() - 1).max(1) as f64
                })
                .fold(f64::INFINITY, f64::min);
            let kmax = (max_lag(data, spans) / dt).floor().max(1.0) as i64;
            let mut evals = 0;
            let mut e = |v: f64| {
                evals += 1;
                rss(fault, v, data, model, spans)
            };
            // Either sign: the force channel may lag the stroke channel or lead it (a stroke
            // sensor's filter delays the stroke).
            let (mut kbest, mut best) = (0, f64::INFINITY);
            for k in -kmax..=kmax {
                let r = e(k as f64 * dt);
                if r < best {
                    (kbest, best) = (k, r);
                }
            }
            // Golden section on [k-1, k+1] samples (RSS is smooth between samples).
            let v = golden_section(
                &mut e,
                (kbest as f64 - 1.0) * dt,
                (kbest as f64 + 1.0) * dt,
                1e-4 * dt,
            );
            // Sensitivity: sum of (dF/dt)^2 at the lagged times (central differences).
            let h = 0.5 * dt;
            let mut s2 = 0.0;
            for s in spans {
                let m = &data[s.test];
                let p = fault.apply(v + h, &m.time_s, &model[s.test]);
                let q = fault.apply(v - h, &m.time_s, &model[s.test]);
                s2 += (s.from..s.to)
                    .filter(|&i| !m.force_n[i].is_nan())
                    .map(|i| ((p[i] - q[i]) / (2.0 * h)).powi(2))
                    .sum::<f64>();
            }
            (v, s2, evals)
        }
    };
    FaultFit {
        value,
        rss: rss(fault, value, data, model, spans),
        sensitivity,
        evaluations,
    }
}

/// The faults that are linear in the recorded force (`y = g F + o + d (t - t0)`), in the order
/// of [`Fault::ALL`]: they are fitted together by one least-squares solve.
pub const LINEAR: [Fault; 3] = [Fault::Offset, Fault::Gain, Fault::Drift];

/// The pairs of linear faults tried together (a load cell with a wrong calibration and a zero
/// offset, a zero that drifts beside either), each in the order of [`Fault::ALL`].
pub fn linear_pairs() -> Vec<[Fault; 2]> {
    let mut v = Vec::new();
    for (i, &a) in LINEAR.iter().enumerate() {
        for &b in &LINEAR[i + 1..] {
            v.push([a, b]);
        }
    }
    v
}

/// The recorded force of a model force `f` with every fault of `faults` at its value: the gain
/// scales the force, then offset and drift add (`y = g F + o + d (t - t0)`); a lag first.
pub fn apply_all(faults: &[Fault], values: &[f64], t: &[f64], f: &[f64]) -> Vec<f64> {
    let mut y = f.to_vec();
    for kind in [Fault::Lag, Fault::Gain, Fault::Offset, Fault::Drift] {
        if let Some(i) = faults.iter().position(|&g| g == kind) {
            y = kind.apply(values[i], t, &y);
        }
    }
    y
}

/// Inverse of [`apply_all`] on the recorded force `y`.
pub fn correct_all(faults: &[Fault], values: &[f64], t: &[f64], y: &[f64]) -> Vec<f64> {
    let mut f = y.to_vec();
    for kind in [Fault::Drift, Fault::Offset, Fault::Gain, Fault::Lag] {
        if let Some(i) = faults.iter().position(|&g| g == kind) {
            f = kind.correct(values[i], t, &f);
        }
    }
    f
}

/// Linear faults (`LINEAR`) fitted together on top of `model` over `spans`: one least-squares
/// solve on the columns 1 (offset), F (gain) and t - t0 (drift). Each fit's `sensitivity` is
/// `1 / (A^T A)^-1_cc`, so [`interval`] gives the joint fit's marginal interval. None when
/// a fault is not linear, the columns are dependent or the gain leaves [`GAIN_RANGE`].
pub fn fit_linear(
    faults: &[Fault],
    data: &[Measurement],
    model: &[Vec<f64>],
    spans: &[Span],
) -> Option<Vec<FaultFit>> {
    if faults.is_empty() || !faults.iter().all(|f| LINEAR.contains(f)) {
        return None;
    }
    let k = faults.len();
    let has_gain = faults.contains(&Fault::Gain);
    let mut ata = nalgebra::DMatrix::<f64>::zeros(k, k);
    let mut atb = nalgebra::DVector::<f64>::zeros(k);
    let mut col = vec![0.0; k];
    for s in spans {
        let m = &data[s.test];
        let t0 = m.time_s[0];
        let r = s.from..s.to;
        for ((&f, &t), &y) in model[s.test][r.clone()]
            .iter()
            .zip(&m.time_s[r.clone()])
            .zip(&m.force_n[r])
            .filter(|(_, y)| !y.is_nan())
        {
            for (c, fault) in col.iter_mut().zip(faults) {
                *c = match fault {
                    Fault::Offset => 1.0,
                    Fault::Gain => f,
                    _ => t - t0,
                };
            }
            let b = if has_gain { y } else { y - f };
            for r in 0..k {
                atb[r] += col[r] * b;
                for c in 0..k {
                    ata[(r, c)] += col[r] * col[c];
                }
            }
        }
    }
    let inv = ata.try_inverse()?;
    let x = &inv * atb;
    if let Some(g) = faults.iter().position(|&f| f == Fault::Gain) {
        if !(GAIN_RANGE[0]..=GAIN_RANGE[1]).contains(&x[g]) {
            return None;
        }
    }
    let values: Vec<f64> = x.iter().copied().collect();
    let rss: f64 = spans
        .iter()
        .map(|s| {
            let m = &data[s.test];
            let y = apply_all(faults, &values, &m.time_s, &model[s.test]);
            (s.from..s.to)
                .filter(|&i| !m.force_n[i].is_nan())
                .map(|i| (y[i] - m.force_n[i]).powi(2))
                .sum::<f64>()
        })
        .sum();
    Some(
        (0..k)
            .map(|c| FaultFit {
                value: values[c],
                rss,
                sensitivity: 1.0 / inv[(c, c)],
                evaluations: 1,
            })
            .collect(),
    )
}

/// 95% interval of a fitted fault: the noise's scatter `sigma^2 / S` (S the sensitivity) plus
/// the model-form bound of the physical causes' intervals (`r_sys = n ms - (n - 1) sigma^2`,
/// biasing the value by at most `sqrt(r_sys / S)`), in the parameter itself (it may be of
/// either sign).
pub fn interval(fit: &FaultFit, n: usize, sigma: f64, ms: f64) -> [f64; 2] {
    if fit.sensitivity <= 0.0 || !fit.sensitivity.is_finite() || n <= 1 {
        return [f64::NEG_INFINITY, f64::INFINITY];
    }
    let s2 = sigma * sigma;
    let r_sys = (n as f64 * ms - (n - 1) as f64 * s2).max(0.0);
    let half = super::fit::Z95 * (s2 / fit.sensitivity).sqrt() + (r_sys / fit.sensitivity).sqrt();
    [fit.value - half, fit.value + half]
}

#[cfg(test)]
mod tests {
    use super::*;

    fn test_data(faults: &[(Fault, f64)]) -> (Vec<Measurement>, Vec<Vec<f64>>) {
        let n = 2001;
        let t: Vec<f64> = (0..n).map(|k| k as f64 / 2000.0).collect();
        let model: Vec<f64> = t
            .iter()
            .map(|&s| 1e4 * (27.0 * s).sin() + 3e3 * (81.0 * s + 0.4).sin())
            .collect();
        let mut y = model.clone();
        for &(f, v) in faults {
            y = f.apply(v, &t, &y);
        }
        let m = Measurement {
            name: "t".into(),
            time_s: t.clone(),
            stroke_m: vec![0.0; n],
            force_n: y,
            velocity_m_s: vec![0.0; n],
            period_s: 2.0 * std::f64::consts::PI / 27.0,
            oil_temperature_k: None,
        };
        (vec![m], vec![model])
    }

    #[test]
    fn each_fault_is_recovered_from_its_own_transform() {
        let spans = [Span {
            test: 0,
            from: 100,
            to: 2001,
        }];
        for (f, v, tol) in [
            (Fault::Offset, -312.5, 1e-9),
            (Fault::Gain, 1.047, 1e-12),
            (Fault::Drift, 187.0, 1e-9),
            // linear interpolation of the lagged model: exact at the sample times only
            (Fault::Lag, 1.3e-3, 1e-3),
        ] {
            let (d, model) = test_data(&[(f, v)]);
            let r = fit(f, &d, &model, &spans);
            assert!(
                ((r.value - v) / v).abs() < tol,
                "{}: {} against {v}",
                f.name(),
                r.value
            );
            assert!(r.rss < 1e-6 * 1e8 * 1900.0, "{}: rss {}", f.name(), r.rss);
        }
    }

    #[test]
    fn the_gain_stays_within_a_calibration_error() {
        // data of the opposite sign and 100 times the model: the least-squares gain is -100,
        // the fit stops at the range's lower end
        let (mut d, model) = test_data(&[]);
        for y in &mut d[0].force_n {
            *y *= -100.0;
        }
        let spans = [Span {
            test: 0,
            from: 0,
            to: 2001,
        }];
        let r = fit(Fault::Gain, &d, &model, &spans);
        assert_eq!(r.value, GAIN_RANGE[0]);
    }

    #[test]
    fn correct_undoes_apply() {
        let (d, model) = test_data(&[]);
        let t = &d[0].time_s;
        for (f, v) in [
            (Fault::Offset, 40.0),
            (Fault::Gain, 0.96),
            (Fault::Drift, -55.0),
            (Fault::Lag, 2e-3),
        ] {
            let back = f.correct(v, t, &f.apply(v, t, &model[0]));
            // the lag's round trip loses the ends (held constant) and interpolates twice
            let err = back[10..1990]
                .iter()
                .zip(&model[0][10..1990])
                .map(|(a, b)| (a - b).abs())
                .fold(0.0, f64::max);
            let tol = if f == Fault::Lag { 20.0 } else { 1e-9 };
            assert!(err < tol, "{}: {err}", f.name());
        }
    }

    #[test]
    fn linear_faults_together_are_recovered_and_undone() {
        let spans = [Span {
            test: 0,
            from: 100,
            to: 2001,
        }];
        for pair in linear_pairs() {
            let truth: Vec<f64> = pair
                .iter()
                .map(|f| match f {
                    Fault::Offset => -312.5,
                    Fault::Gain => 1.047,
                    _ => 187.0,
                })
                .collect();
            let (mut d, model) = test_data(&[]);
            d[0].force_n = apply_all(&pair, &truth, &d[0].time_s, &model[0]);
            let r = fit_linear(&pair, &d, &model, &spans).expect("fit");
            for (f, v) in r.iter().zip(&truth) {
                assert!(
                    ((f.value - v) / v).abs() < 1e-9,
                    "{pair:?}: {} for {v}",
                    f.value
                );
                assert!(f.rss < 1e-9 * 1e8);
            }
            let back = correct_all(&pair, &truth, &d[0].time_s, &d[0].force_n);
            let err = back
                .iter()
                .zip(&model[0])
                .map(|(a, b)| (a - b).abs())
                .fold(0.0, f64::max);
            assert!(err < 1e-9, "{pair:?}: {err}");
        }
        assert_eq!(linear_pairs().len(), 3);
    }

    #[test]
    fn a_linear_fault_alone_fits_as_fit_does() {
        let spans = [Span {
            test: 0,
            from: 100,
            to: 2001,
        }];
        let (d, model) = test_data(&[(Fault::Offset, 40.0), (Fault::Drift, -55.0)]);
        for f in LINEAR {
            let a = fit(f, &d, &model, &spans);
            let b = fit_linear(&[f], &d, &model, &spans).expect("fit")[0];
            assert!((a.value - b.value).abs() <= 1e-9 * a.value.abs().max(1.0));
            assert!((a.sensitivity - b.sensitivity).abs() <= 1e-9 * a.sensitivity);
        }
    }

    #[test]
    fn interval_of_a_linear_fault_is_the_least_squares_one() {
        // offset over n samples with white noise sigma: sigma / sqrt(n) standard error
        let fit = FaultFit {
            value: 10.0,
            rss: 0.0,
            sensitivity: 400.0,
            evaluations: 1,
        };
        let iv = interval(&fit, 400, 2.0, 4.0 * 399.0 / 400.0);
        let half = super::super::fit::Z95 * 2.0 / 20.0;
        assert!((iv[1] - 10.0 - half).abs() < 1e-12 && (10.0 - iv[0] - half).abs() < 1e-12);
    }
}
