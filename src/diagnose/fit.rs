//! Fitting and ranking: every candidate's parameters by Levenberg-Marquardt (bounded through a
//! logistic-log transform, multi-start), BIC on the fit data, RMS on held-out data, and the
//! choice of the cause.
use super::acquisition::{self, Fault, Span};
use super::candidates::{apply_all, combined_params, Cause, ParamSpec, Scales};
use super::data::{min_max, Measurement};
use super::support::{NoEffect, NotSupported, PartSupport};
use super::DiagnoseError;

mod assemble;
mod choice;
mod pairs;
mod prepare;
mod search;
mod singles;
use crate::hydraulics::{
    bench::sample_path, sample_rates, DamperDeck, DamperModel, Device, HydraulicError,
    IntegratorOptions, Scheme, StrokePath,
};
use levenberg_marquardt::{LeastSquaresProblem, LevenbergMarquardt};
use nalgebra::{DVector, Dyn, Owned};
use rayon::prelude::*;
use serde::Serialize;
use std::collections::BTreeMap;

/// Settings of a diagnosis.
#[derive(Debug, Clone, PartialEq)]
pub struct DiagnoseOptions {
    /// Cycles simulated per training test during the fit (the first one settles the model from
    /// its initial state and is not compared).
    pub fit_cycles: usize,
    /// Largest RK4 sub-step [s] (the explicit stability limit of the damper's stiffest flow
    /// path; 3e-5 s holds for the UH-60A-class dampers of this repository).
    pub max_substep_s: f64,
    /// Candidates to try (default: all).
    pub candidates: Vec<Cause>,
    /// Levenberg-Marquardt patience (function evaluations per parameter, the crate's measure).
    pub patience: usize,
    /// Try pairs of causes when the best single one leaves a systematic residual.
    pub pairs: bool,
    /// Acquisition faults to try (default: all).
    pub faults: Vec<Fault>,
}

impl Default for DiagnoseOptions {
    fn default() -> Self {
        Self {
            fit_cycles: 3,
            max_substep_s: 3.0e-5,
            candidates: Cause::CANDIDATES.to_vec(),
            patience: 8,
            pairs: true,
            faults: Fault::ALL.to_vec(),
        }
    }
}

impl DiagnoseOptions {
    /// No candidate, fault or pair: the base deck replayed and validated on the diagnosis'
    /// split (its held-out RMS is `validation.baseline_rms_N`), e.g. to see what a given deck
    /// reaches.
    pub fn baseline_only() -> Self {
        Self {
            candidates: vec![],
            faults: vec![],
            pairs: false,
            ..Self::default()
        }
    }
}

/// Samples `[from, to)` of test `test` compared with the model.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Window {
    test: usize,
    from: usize,
    to: usize,
}

/// `validation` of docs/formats.md.
#[derive(Debug, Clone, Serialize, PartialEq)]
#[allow(non_snake_case)]
pub struct Validation {
    pub method: String,
    pub baseline_rms_N: f64,
    pub extended_rms_N: f64,
}

/// One row of `candidates` (docs/formats.md, plus `held_out_rms_N`, `k`, `fit_evaluations`).
#[derive(Debug, Clone, Serialize, PartialEq)]
#[allow(non_snake_case)]
pub struct Candidate {
    pub cause: String,
    pub rms_N: f64,
    pub bic: f64,
    pub parameters: BTreeMap<String, f64>,
    pub held_out_rms_N: f64,
    /// 95% interval `[lo, hi]` of every fitted parameter (Jacobian of the fit with the noise).
    pub intervals: BTreeMap<String, [f64; 2]>,
    pub k: usize,
    pub fit_evaluations: usize,
    /// How the fit was cut short, if it was (a screened pair).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub note: Option<String>,
    /// Fit failure (model failure at every start), if any.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub failure: Option<String>,
}

/// A companion tried beside the best single cause (extra key `companions`).
#[derive(Debug, Clone, Serialize, PartialEq)]
pub struct Companion {
    pub pair: String,
    pub companion: String,
    /// Passes both tests against the single cause (lower BIC, held-out gain above threshold).
    pub passes: bool,
    /// The pair is the chosen cause.
    pub kept: bool,
    pub reason: String,
    /// Held-out test statistic of the companion (`criterion_companions`), when the pair was
    /// fitted.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub held_out_z: Option<f64>,
}

/// Per-test summary (extra key `tests`).
#[derive(Debug, Clone, Serialize, PartialEq)]
#[allow(non_snake_case)]
pub struct TestSummary {
    pub name: String,
    pub role: String,
    pub amplitude_m: f64,
    pub peak_force_N: f64,
    pub baseline_rms_N: f64,
    pub extended_rms_N: f64,
}

/// The diagnosis report (DIR/diagnosis.json; docs/formats.md keys first, then extra keys).
#[derive(Debug, Clone, Serialize, PartialEq)]
#[allow(non_snake_case)]
pub struct Diagnosis {
    pub cause: String,
    pub parameters: BTreeMap<String, f64>,
    /// 95% interval of every parameter of the cause.
    pub parameter_intervals: BTreeMap<String, [f64; 2]>,
    /// Every parameter of the cause fitted to each test alone (fewer than three tests: to each
    /// cycle from the second), and its spread across them.
    pub parameter_spread: BTreeMap<String, ParameterSpread>,
    /// Which limit of free play behind a contact stiffness the data support, when a compliant
    /// or gap cause is in play.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub free_play_limit: Option<String>,
    /// Whether companions were tried for the best single cause, and why.
    pub pair_stage: String,
    /// Every companion tried, kept or dropped and why.
    pub companions: Vec<Companion>,
    pub baseline_rms_N: f64,
    pub extended_rms_N: f64,
    pub gain: f64,
    pub validation: Validation,
    pub candidates: Vec<Candidate>,
    pub evidence: Vec<String>,
    pub noise_sigma_N: f64,
    pub threshold_N: f64,
    pub baseline_bic: f64,
    pub criterion: String,
    /// The companions' held-out test: statistic, correction and the z each had to exceed.
    pub criterion_companions: String,
    pub limitations: Vec<String>,
    /// Dropouts and clipping found in each test (what was not compared, what was bridged).
    pub acquisition_screen: Vec<super::data::Screened>,
    /// Residual signatures of the measured force, the baseline and every candidate's
    /// prediction, measured alike.
    pub signatures: Vec<super::evidence::Signature>,
    /// Candidates the data cannot tell apart, why, and the test that would decide.
    pub identifiability: Vec<super::identify::Identifiability>,
    pub tests: Vec<TestSummary>,
    /// The no-effect value (or band) of every parameter of the cause that has one
    /// ([`super::support::no_effect`]).
    pub parameter_no_effect: BTreeMap<String, NoEffect>,
    /// Candidates that passed the tests of their role (first cause or companion) but are not
    /// named: the data do not distinguish one of their causes from no effect.
    pub considered_not_supported: Vec<NotSupported>,
    /// The naming rule, as text, with the lag's timing uncertainty of these data.
    pub criterion_naming: String,
}

impl Diagnosis {
    /// The naming rule checked on the named cause: one entry per cause of the name (`a`,
    /// `a+b`, `a+force_lag`, screened faults too; none for `none`), `supported` when the 95%
    /// interval of at least one of its parameters (`parameter_intervals`) excludes that
    /// parameter's no-effect value (`parameter_no_effect`; the lag: lies wholly outside its
    /// timing uncertainty), with the reason (which interval, which value). A diagnosis names
    /// only supported causes, so every entry of a diagnosis made by [`diagnose`] is supported;
    /// a test can assert it on any diagnosis, e.g.
    /// `assert!(d.named_parameters_supported().iter().all(|p| p.supported))`.
    pub fn named_parameters_supported(&self) -> Vec<PartSupport> {
        super::support::support(
            &self.cause,
            &self.parameters,
            &self.parameter_intervals,
            &self.parameter_no_effect,
        )
    }
}

/// Measured, baseline and extended force of one test (for the report).
#[derive(Debug, Clone, PartialEq)]
pub struct Curves {
    pub name: String,
    pub role: String,
    pub time_s: Vec<f64>,
    pub stroke_m: Vec<f64>,
    pub velocity_m_s: Vec<f64>,
    pub measured_n: Vec<f64>,
    pub baseline_n: Vec<f64>,
    pub extended_n: Vec<f64>,
    /// First compared sample (the model settles before).
    pub from: usize,
}

/// Everything a diagnosis produces.
#[derive(Debug, Clone)]
pub struct Outcome {
    pub diagnosis: Diagnosis,
    /// The base deck with the chosen extension (the base deck itself for `none`).
    pub extended: DamperDeck,
    pub curves: Vec<Curves>,
}

/// Median of the tests' oil temperatures [K] when every test has one.
fn oil_reference_k(data: &[Measurement]) -> Option<f64> {
    let mut t: Vec<f64> = data
        .iter()
        .map(|m| m.oil_temperature_k)
        .collect::<Option<_>>()?;
    if t.is_empty() {
        return None;
    }
    t.sort_by(f64::total_cmp);
    Some(0.5 * (t[(t.len() - 1) / 2] + t[t.len() / 2]))
}

/// Spread (max - min) of the tests' oil temperatures [K]; 0 unless every test has one.
fn oil_span_k(data: &[Measurement]) -> f64 {
    let t: Option<Vec<f64>> = data.iter().map(|m| m.oil_temperature_k).collect();
    t.map_or(0.0, |t| {
        let (lo, hi) = min_max(&t);
        (hi - lo).max(0.0)
    })
}

/// Device of a deck for a test's sample interval (RK4, sub-steps from `max_h`).
fn device(deck: &DamperDeck, dt: f64, max_h: f64) -> Result<Box<dyn Device>, HydraulicError> {
    let substeps = ((dt / max_h).ceil() as usize).max(1);
    let mut dev = deck
        .build(
            DamperModel::Physical,
            IntegratorOptions {
                scheme: Scheme::Rk4,
                substeps,
            },
        )
        .map_err(|e| HydraulicError::BadStep {
            t: 0.0,
            reason: e.to_string(),
        })?;
    // the fits read the force only
    dev.set_substep_envelope(false);
    Ok(dev)
}

/// Longest step of the fine replay that measures the replay's own delay ([`replay_delay`]):
/// the same Hermite path between samples as the replay's, in shorter steps. What is left is
/// the delay of one step per sample along that path (each step's sub-steps and the force read
/// at its end).
pub const FINE_REPLAY_STEP_S: f64 = 1.25e-4;

/// Model force at the first `n` samples of a stroke-driven replay (force at the end of each
/// sample interval, one step per sample as `bench::replay`); on a non-finite state the
/// sub-steps are doubled (twice).
pub fn simulate(
    deck: &DamperDeck,
    m: &Measurement,
    n: usize,
    max_h: f64,
    out: &mut Vec<f64>,
) -> Result<(), HydraulicError> {
    simulate_split(deck, m, n, max_h, 1, out)
}

/// [`simulate`] with each sample interval split into `split` steps along the replay's path
/// between samples ([`sample_path`]).
pub fn simulate_split(
    deck: &DamperDeck,
    m: &Measurement,
    n: usize,
    max_h: f64,
    split: usize,
    out: &mut Vec<f64>,
) -> Result<(), HydraulicError> {
    // The deck at the test's oil temperature, where both are known.
    let deck = deck
        .at_known_oil_temperature(m.oil_temperature_k)
        .map_err(|e| HydraulicError::BadStep {
            t: 0.0,
            reason: e.to_string(),
        })?;
    let deck = deck.as_ref();
    let n = n.min(m.time_s.len());
    let dt = (m.time_s[n - 1] - m.time_s[0]) / (n - 1).max(1) as f64;
    let split = split.max(1);
    let (t, x) = (&m.time_s[..n], &m.stroke_m[..n]);
    let rates = sample_rates(t, x);
    let mut h = max_h;
    let mut attempt = 0;
    loop {
        let mut dev = device(deck, dt / split as f64, h)?;
        out.clear();
        let r = (|| {
            out.push(dev.committed_force());
            for k in 0..n - 1 {
                let path = sample_path(t, x, &rates, k);
                let force = if split == 1 {
                    let f = dev.trial_step_path(t[k], &path)?.force_end;
                    dev.commit();
                    f
                } else {
                    // the sample's path cut into `split` pieces, each the same cubic
                    let step = path.dt / split as f64;
                    let (mut p0, mut f) = (path.at(0.0), f64::NAN);
                    for j in 1..=split {
                        let p1 = if j == split {
                            (x[k + 1], path.end_rate())
                        } else {
                            path.at(j as f64 * step)
                        };
                        let piece = StrokePath::hermite(step, p0.0, p1.0, p0.1, p1.1);
                        f = dev
                            .trial_step_path(t[k] + (j - 1) as f64 * step, &piece)?
                            .force_end;
                        dev.commit();
                        p0 = p1;
                    }
                    f
                };
                if !force.is_finite() {
                    return Err(HydraulicError::NonFinite {
                        t: t[k + 1],
                        component: 0,
                        substep_s: f64::NAN,
                        rate_per_s: f64::NAN,
                    });
                }
                out.push(force);
            }
            Ok(())
        })();
        match r {
            Ok(()) => return Ok(()),
            Err(e @ HydraulicError::NonFinite { .. }) if attempt < 2 => {
                let _ = e;
                h *= 0.5;
                attempt += 1;
            }
            Err(e) => return Err(e),
        }
    }
}

/// Bounded parameter transform: `x = lo (hi/lo)^s(z)`, s the logistic function.
fn to_x(spec: &[ParamSpec], z: &[f64]) -> Vec<f64> {
    spec.iter()
        .zip(z)
        .map(|(p, &z)| p.lo * (p.hi / p.lo).powf(1.0 / (1.0 + (-z).exp())))
        .collect()
}

fn to_z(p: &ParamSpec, x: f64) -> f64 {
    let s = ((x / p.lo).ln() / (p.hi / p.lo).ln()).clamp(1e-6, 1.0 - 1e-6);
    (s / (1.0 - s)).ln()
}

struct Problem<'a> {
    cause: &'a [Cause],
    scales: Scales,
    base: &'a DamperDeck,
    spec: &'a [ParamSpec],
    data: &'a [Measurement],
    windows: &'a [Window],
    max_h: f64,
    scale: f64,
    z: DVector<f64>,
    r: Option<DVector<f64>>,
    evals: std::cell::Cell<usize>,
}

/// Residuals `(model - measured)/scale` over `windows` of the deck with a cause applied at `x`.
#[allow(clippy::too_many_arguments)]
fn residuals_x(
    cause: &[Cause],
    scales: Scales,
    base: &DamperDeck,
    x: &[f64],
    data: &[Measurement],
    windows: &[Window],
    max_h: f64,
    scale: f64,
) -> Option<DVector<f64>> {
    let deck = apply_all(cause, base, scales, x);
    let n: usize = windows.iter().map(|w| w.to - w.from).sum();
    let mut r = DVector::zeros(n);
    let mut buf = Vec::new();
    let mut i = 0;
    for w in windows {
        let m = &data[w.test];
        simulate(&deck, m, w.to, max_h, &mut buf).ok()?;
        for (b, f) in buf[w.from..w.to].iter().zip(&m.force_n[w.from..w.to]) {
            // A force not measured (a dropout or clipped: NaN) is not compared.
            r[i] = if f.is_nan() { 0.0 } else { (b - f) / scale };
            i += 1;
        }
    }
    Some(r)
}

/// Normal quantile of a two-sided 95% interval.
pub(super) const Z95: f64 = 1.959_963_984_540_054;

/// 95% intervals of fitted parameters: the noise's scatter plus a bound on the bias that
/// model-form error puts on them. J is the Jacobian of the fit residuals by central differences
/// in `ln x` (step 1%, the residual is only piecewise smooth) and `C = (J^T J)^-1`.
/// - Noise: `ln x` has the covariance `sigma^2 C` (sigma the measured noise).
/// - Model form: what the noise does not explain, `r_sys = n ms - (n - k) sigma^2`, is error of
///   the model's form (`ms` the larger mean square residual of the fit and held-out data). The part of it along the columns of J has been absorbed by the fit and
///   biases `ln x_c` by at most `sqrt(r_par C_cc)` (Cauchy-Schwarz), r_par its squared norm. It
///   cannot be seen in the residual; it is taken as large as the part that can, `r_sys`.
///
/// The half-width is `1.96 sqrt(sigma^2 C_cc) + sqrt(r_sys C_cc)`. Returns `[lo, hi]` per
/// parameter (`[0, inf]` where the data do not constrain it).
#[allow(clippy::too_many_arguments)]
fn intervals(
    cause: &[Cause],
    scales: Scales,
    base: &DamperDeck,
    x: &[f64],
    data: &[Measurement],
    windows: &[Window],
    max_h: f64,
    sigma: f64,
    ms: f64,
) -> Vec<[f64; 2]> {
    let k = x.len();
    let unbounded = vec![[0.0, f64::INFINITY]; k];
    let n = measured_samples(windows, data);
    if k == 0 || n <= k {
        return unbounded;
    }
    let Some(j) = jacobian_ln(cause, scales, base, x, data, windows, max_h) else {
        return unbounded;
    };
    let s2 = sigma.powi(2);
    let r_sys = (n as f64 * ms - (n - k) as f64 * s2).max(0.0);
    let Some(cov) = (j.transpose() * &j).try_inverse() else {
        return unbounded;
    };
    (0..k)
        .map(|c| {
            let v = cov[(c, c)];
            if v.is_finite() && v >= 0.0 {
                let half = Z95 * (s2 * v).sqrt() + (r_sys * v).sqrt();
                // exp overflows to inf for an unconstrained parameter: reported as such.
                [x[c] * (-half).exp(), x[c] * half.exp()]
            } else {
                [0.0, f64::INFINITY]
            }
        })
        .collect()
}

/// Jacobian of the residuals (in N) over `windows` in `ln x`, by central differences (step 1%:
/// the residual is only piecewise smooth); None where a replay fails.
#[allow(clippy::too_many_arguments)]
fn jacobian_ln(
    cause: &[Cause],
    scales: Scales,
    base: &DamperDeck,
    x: &[f64],
    data: &[Measurement],
    windows: &[Window],
    max_h: f64,
) -> Option<nalgebra::DMatrix<f64>> {
    let n: usize = windows.iter().map(|w| w.to - w.from).sum();
    let h: f64 = 0.01;
    let mut j = nalgebra::DMatrix::zeros(n, x.len());
    for c in 0..x.len() {
        let mut xp = x.to_vec();
        let mut xm = x.to_vec();
        xp[c] *= h.exp();
        xm[c] *= (-h).exp();
        let rp = residuals_x(cause, scales, base, &xp, data, windows, max_h, 1.0)?;
        let rm = residuals_x(cause, scales, base, &xm, data, windows, max_h, 1.0)?;
        j.set_column(c, &((rp - rm) / (2.0 * h)));
    }
    Some(j)
}

/// `parameter_spread` of diagnosis.json: a parameter of the cause fitted to each test alone.
#[derive(Debug, Clone, Serialize, PartialEq)]
pub struct ParameterSpread {
    /// Fitted to each test alone (from its second cycle), by test name; `null` where that test
    /// does not bound the parameter (its own 95% noise interval wider than a factor of 10).
    pub per_test: BTreeMap<String, Option<f64>>,
    /// Standard deviation of `ln x` across the tests beyond what the noise explains
    /// (DerSimonian-Laird); 0 when the tests agree within their noise.
    pub spread_ln: f64,
    /// Cochran's heterogeneity statistic Q of the per-test values (about `tests - 1` when they
    /// differ by noise alone).
    pub heterogeneity_q: f64,
    /// Tests that bound the parameter (fewer than three: no spread is estimated).
    pub tests: usize,
}

/// The cause's parameters fitted to each test alone (warm started at the joint fit `x`), and
/// per parameter the spread of `ln x` across tests beyond the noise: each test's value has the
/// noise variance `sigma^2 (J^T J)^-1` of its own fit, and the spread is DerSimonian and
/// Laird's between-test variance `tau^2 = max(0, (Q - (m - 1)) / (S1 - S2/S1))`, Q Cochran's
/// statistic, `S1 = sum w`, `S2 = sum w^2`, `w` the inverse noise variances, m the tests. A
/// model of the right form gives every test the same parameter up to noise (tau ~ 0); a
/// parameter that moves with amplitude or frequency is standing in for something the model
/// does not have, and no single value is known better than that spread.
#[allow(clippy::too_many_arguments)]
fn parameter_spread(
    cause: &[Cause],
    scales: Scales,
    base: &DamperDeck,
    spec: &[ParamSpec],
    x: &[f64],
    data: &[Measurement],
    windows: &[Window],
    labels: &[String],
    opts: &DiagnoseOptions,
    sigma: f64,
    scale: f64,
) -> Vec<ParameterSpread> {
    let z0: Vec<f64> = spec.iter().zip(x).map(|(p, &v)| to_z(p, v)).collect();
    let per_test: Vec<Option<(Vec<f64>, Vec<f64>)>> = windows
        .par_iter()
        .map(|w| {
            let one = std::slice::from_ref(w);
            let f = fit_one(
                cause,
                scales,
                base,
                spec,
                z0.clone(),
                data,
                one,
                opts,
                opts.patience,
                scale,
            )?;
            let j = jacobian_ln(cause, scales, base, &f.x, data, one, opts.max_substep_s)?;
            let cov = (j.transpose() * &j).try_inverse()?;
            let var: Vec<f64> = (0..x.len()).map(|c| sigma * sigma * cov[(c, c)]).collect();
            Some((f.x, var))
        })
        .collect();
    (0..x.len())
        .map(|c| {
            let mut values = BTreeMap::new();
            let mut pts: Vec<(f64, f64)> = Vec::new();
            for (label, r) in labels.iter().zip(&per_test) {
                // A test bounds the parameter when its own 95% interval is within a factor of 10.
                let v = r.as_ref().and_then(|(xi, var)| {
                    (var[c] > 0.0 && Z95 * var[c].sqrt() < 10f64.ln() && xi[c] > 0.0)
                        .then_some((xi[c], var[c]))
                });
                values.insert(label.clone(), v.map(|v| v.0));
                if let Some((xi, var)) = v {
                    pts.push((xi.ln(), 1.0 / var));
                }
            }
            let m = pts.len();
            let (mut tau2, mut q) = (0.0, 0.0);
            if m >= 3 {
                let s1: f64 = pts.iter().map(|p| p.1).sum();
                let s2: f64 = pts.iter().map(|p| p.1 * p.1).sum();
                let mean = pts.iter().map(|p| p.0 * p.1).sum::<f64>() / s1;
                q = pts.iter().map(|p| p.1 * (p.0 - mean).powi(2)).sum();
                let den = s1 - s2 / s1;
                if den > 0.0 {
                    tau2 = ((q - (m - 1) as f64) / den).max(0.0);
                }
            }
            ParameterSpread {
                per_test: values,
                spread_ln: tau2.sqrt(),
                heterogeneity_q: q,
                tests: m,
            }
        })
        .collect()
}

impl Problem<'_> {
    fn residuals_at(&self, z: &[f64]) -> Option<DVector<f64>> {
        self.evals.set(self.evals.get() + 1);
        residuals_x(
            self.cause,
            self.scales,
            self.base,
            &to_x(self.spec, z),
            self.data,
            self.windows,
            self.max_h,
            self.scale,
        )
    }
}

impl LeastSquaresProblem<f64, Dyn, Dyn> for Problem<'_> {
    type ResidualStorage = Owned<f64, Dyn>;
    type JacobianStorage = Owned<f64, Dyn, Dyn>;
    type ParameterStorage = Owned<f64, Dyn>;

    fn set_params(&mut self, z: &DVector<f64>) {
        self.z.copy_from(z);
        self.r = self.residuals_at(z.as_slice());
    }

    fn params(&self) -> DVector<f64> {
        self.z.clone()
    }

    fn residuals(&self) -> Option<DVector<f64>> {
        self.r.clone()
    }

    /// Forward differences in z (step 1e-3: the residual is only piecewise smooth).
    fn jacobian(&self) -> Option<nalgebra::DMatrix<f64>> {
        let r0 = self.r.as_ref()?;
        let k = self.z.len();
        let mut j = nalgebra::DMatrix::zeros(r0.len(), k);
        for c in 0..k {
            let mut z = self.z.clone();
            let h = 1e-3;
            z[c] += h;
            let r = self.residuals_at(z.as_slice())?;
            j.set_column(c, &((r - r0) / h));
        }
        Some(j)
    }
}

/// A fitted and evaluated candidate: row, full replays, deck, fitted parameters.
type Evaluated = (Candidate, Option<Vec<Vec<f64>>>, DamperDeck, Vec<f64>);

/// Result of one Levenberg-Marquardt run of one candidate from one start.
struct Fit {
    x: Vec<f64>,
    /// Where it stopped, in the transformed parameters (a start for a longer run).
    z: Vec<f64>,
    rss: f64,
    evals: usize,
}

#[allow(clippy::too_many_arguments)]
fn fit_one(
    cause: &[Cause],
    scales: Scales,
    base: &DamperDeck,
    spec: &[ParamSpec],
    z0: Vec<f64>,
    data: &[Measurement],
    windows: &[Window],
    opts: &DiagnoseOptions,
    patience: usize,
    scale: f64,
) -> Option<Fit> {
    let mut pb = Problem {
        cause,
        scales,
        base,
        spec,
        data,
        windows,
        max_h: opts.max_substep_s,
        scale,
        z: DVector::from_vec(z0.clone()),
        r: None,
        evals: std::cell::Cell::new(0),
    };
    pb.set_params(&DVector::from_vec(z0));
    pb.r.as_ref()?;
    let (pb, _report) = LevenbergMarquardt::new()
        .with_xtol(1e-4)
        .with_ftol(1e-6)
        .with_patience(patience)
        .minimize(pb);
    // The crate leaves the best point set; re-evaluate where it stopped without residuals.
    let r = match &pb.r {
        Some(r) => r.clone(),
        None => pb.residuals_at(pb.z.as_slice())?,
    };
    Some(Fit {
        x: to_x(spec, pb.z.as_slice()),
        z: pb.z.as_slice().to_vec(),
        rss: r.norm_squared() * scale * scale,
        evals: pb.evals.get(),
    })
}

/// RMS of the difference of two replays over `windows`.
fn diff_rms(windows: &[Window], a: &[Vec<f64>], b: &[Vec<f64>]) -> f64 {
    let (mut s, mut n) = (0.0, 0usize);
    for w in windows {
        for (x, y) in a[w.test][w.from..w.to].iter().zip(&b[w.test][w.from..w.to]) {
            s += (x - y) * (x - y);
            n += 1;
        }
    }
    (s / n.max(1) as f64).sqrt()
}

fn rms_over(windows: &[Window], model: &[Vec<f64>], data: &[Measurement]) -> f64 {
    let (mut s, mut n) = (0.0, 0usize);
    for w in windows {
        let (a, b) = (&model[w.test], &data[w.test].force_n);
        for (x, y) in a[w.from..w.to].iter().zip(&b[w.from..w.to]) {
            if !y.is_nan() {
                s += (x - y) * (x - y);
                n += 1;
            }
        }
    }
    (s / n.max(1) as f64).sqrt()
}

/// Measured force samples over `windows` (NaN, not measured, excluded).
fn measured_samples(windows: &[Window], data: &[Measurement]) -> usize {
    windows
        .iter()
        .map(|w| {
            data[w.test].force_n[w.from..w.to]
                .iter()
                .filter(|f| !f.is_nan())
                .count()
        })
        .sum()
}

/// BIC = n ln(RSS/n) + k ln n (Gaussian errors of unknown variance).
pub fn bic(rss: f64, n: usize, k: usize) -> f64 {
    let n = n.max(1) as f64;
    n * (rss.max(1e-300) / n).ln() + k as f64 * n.ln()
}

/// Where a fault candidate is fitted and judged.
struct FaultContext<'a> {
    data: &'a [Measurement],
    fit_w: &'a [Window],
    held_w: &'a [Window],
    all_w: &'a [Window],
    sigma: f64,
    /// The replay's own delay ([`replay_delay`]), added to a fitted `force_lag`.
    replay_delay_s: f64,
}

/// Delay [s] of the one-step-per-sample replay `straight` of `deck` behind the damper: the
/// lag of `straight` behind a fine replay (steps of at most [`FINE_REPLAY_STEP_S`], the stroke
/// a cubic between samples) over `spans`, fitted as `force_lag` is. A lag fitted against the
/// replay is short by it (O(dt^2): 14.7 us of a 1.3 ms lag at 2 kHz).
fn replay_delay(
    deck: &DamperDeck,
    data: &[Measurement],
    straight: &[Vec<f64>],
    spans: &[Span],
    max_h: f64,
) -> Result<f64, DiagnoseError> {
    let mut fine = Vec::with_capacity(data.len());
    let mut as_data = Vec::with_capacity(data.len());
    for (m, s) in data.iter().zip(straight) {
        let n = m.time_s.len();
        let dt = (m.time_s[n - 1] - m.time_s[0]) / (n - 1).max(1) as f64;
        let split = ((dt / FINE_REPLAY_STEP_S).ceil() as usize).max(1);
        let mut f = Vec::with_capacity(n);
        simulate_split(deck, m, n, 0.25 * max_h, split, &mut f).map_err(|source| {
            DiagnoseError::Model {
                test: m.name.clone(),
                source,
            }
        })?;
        fine.push(f);
        as_data.push(Measurement {
            force_n: s.clone(),
            ..m.clone()
        });
    }
    Ok(acquisition::fit(Fault::Lag, &as_data, &fine, spans).value)
}

fn spans(w: &[Window]) -> Vec<Span> {
    w.iter()
        .map(|w| Span {
            test: w.test,
            from: w.from,
            to: w.to,
        })
        .collect()
}

/// Acquisition faults fitted on top of a model: the baseline (`on` None; the deck `base`) or a
/// fitted physical cause (`on`, named `cause+fault`, its parameters kept). One fault by
/// [`acquisition::fit`]; several (linear ones: gain, offset, drift) together by
/// [`acquisition::fit_linear`], named `force_offset+force_gain`.
fn fault_candidate(
    faults: &[Fault],
    on: Option<&Evaluated>,
    baseline: &[Vec<f64>],
    base: &DamperDeck,
    cx: &FaultContext,
) -> Option<Evaluated> {
    let model: &[Vec<f64>] = match on {
        Some(e) => e.1.as_deref()?,
        None => baseline,
    };
    let data = cx.data;
    let sp = spans(cx.fit_w);
    let fits = match faults {
        [one] => vec![acquisition::fit(*one, data, model, &sp)],
        _ => acquisition::fit_linear(faults, data, model, &sp)?,
    };
    if fits.iter().any(|f| !f.value.is_finite()) {
        return None;
    }
    let values: Vec<f64> = fits.iter().map(|f| f.value).collect();
    let sim: Vec<Vec<f64>> = data
        .iter()
        .zip(model)
        .map(|(m, s)| acquisition::apply_all(faults, &values, &m.time_s, s))
        .collect();
    let n_fit = measured_samples(cx.fit_w, cx.data);
    let held = rms_over(cx.held_w, &sim, data);
    let rss = fits[0].rss;
    let ms = (rss / n_fit.max(1) as f64).max(held * held);
    let names: Vec<&str> = faults.iter().map(|f| f.name()).collect();
    let (cause, mut parameters, mut intervals, k, deck, mut x, evals) = match on {
        Some(e) => (
            format!("{}+{}", e.0.cause, names.join("+")),
            e.0.parameters.clone(),
            e.0.intervals.clone(),
            e.0.k + faults.len(),
            e.2.clone(),
            e.3.clone(),
            e.0.fit_evaluations,
        ),
        None => (
            names.join("+"),
            BTreeMap::new(),
            BTreeMap::new(),
            faults.len(),
            base.clone(),
            vec![],
            0,
        ),
    };
    for (&fault, f) in faults.iter().zip(&fits) {
        let iv = acquisition::interval(f, n_fit, cx.sigma, ms);
        // The lag against the replay, reported against the damper (`x` keeps the former: the
        // fault's correction of the data works on the replay).
        let shift = if fault == Fault::Lag {
            cx.replay_delay_s
        } else {
            0.0
        };
        parameters.insert(fault.param().into(), f.value + shift);
        intervals.insert(fault.param().into(), [iv[0] + shift, iv[1] + shift]);
        x.push(f.value);
    }
    let row = Candidate {
        cause,
        rms_N: rms_over(cx.all_w, &sim, data),
        bic: bic(rss, n_fit, k),
        parameters,
        held_out_rms_N: held,
        intervals,
        k,
        fit_evaluations: evals + fits.iter().map(|f| f.evaluations).max().unwrap_or(0),
        note: on.map(|e| {
            format!(
                "the {} fitted on top of {} as fitted alone (not a joint fit)",
                if faults.len() == 1 { "fault" } else { "faults" },
                e.0.cause
            )
        }),
        failure: None,
    };
    Some((row, Some(sim), deck, x))
}

/// A pair against the single it extends (`reference`: its BIC and held-out RMS): it must
/// lower the BIC and improve the held-out RMS by more than `threshold`.
fn judge_pair(e: &Evaluated, reference: (f64, f64), threshold: f64) -> (bool, String) {
    let r = &e.0;
    let d_bic = reference.0 - r.bic;
    let d_held = reference.1 - r.held_out_rms_N;
    let by_bic = d_bic > 0.0;
    let by_held = d_held > threshold;
    let reason = format!(
        "BIC {} by {:.1} ({}); held-out RMS {} by {:.1} N against a threshold of {:.1} N ({})",
        if by_bic { "lower" } else { "higher" },
        d_bic.abs(),
        if by_bic {
            "earns its parameters"
        } else {
            "does not earn its parameters"
        },
        if d_held >= 0.0 { "lower" } else { "higher" },
        d_held.abs(),
        threshold,
        if by_held {
            "improves held-out data"
        } else {
            "no held-out improvement"
        },
    );
    (e.1.is_some() && by_bic && by_held, reason)
}

/// Family-wise false-alarm rate of the companions' held-out test.
const COMPANION_ALPHA: f64 = 0.05;

/// Held-out test statistic of a pair against its single (module docs of the choice):
/// `sum(e d) / (sigma ||d||)`, `e = y - mu_single`, `d = mu_pair - mu_single` over `windows`.
fn held_out_z(
    windows: &[Window],
    single: &[Vec<f64>],
    pair: &[Vec<f64>],
    data: &[Measurement],
    sigma: f64,
) -> f64 {
    let (mut ed, mut dd) = (0.0, 0.0);
    for w in windows {
        let (s, p, y) = (&single[w.test], &pair[w.test], &data[w.test].force_n);
        for i in (w.from..w.to).filter(|&i| !y[i].is_nan()) {
            let d = p[i] - s[i];
            ed += (y[i] - s[i]) * d;
            dd += d * d;
        }
    }
    if dd > 0.0 {
        ed / (sigma * dd.sqrt())
    } else {
        0.0
    }
}

/// Standard normal quantile by bisection on `erfc` (to 1e-12).
fn normal_quantile(p: f64) -> f64 {
    let cdf = |z: f64| 0.5 * libm::erfc(-z / std::f64::consts::SQRT_2);
    let (mut lo, mut hi) = (-40.0, 40.0);
    while hi - lo > 1e-12 {
        let m = 0.5 * (lo + hi);
        if cdf(m) < p {
            lo = m;
        } else {
            hi = m;
        }
    }
    0.5 * (lo + hi)
}

type Named = (String, BTreeMap<String, f64>, BTreeMap<String, [f64; 2]>);

/// Names the faults the screen found beside the fitted cause: `force_clipping` (`clip_high_N`,
/// `clip_low_N`: the tightest rails of any test, read from the data, so their intervals are
/// the values themselves) and `force_dropouts` (`dropout_rows`, over all tests); the cause
/// becomes `cause+force_clipping`, or `force_clipping` alone for `none`.
fn name_screened(
    screened: &[super::data::Screened],
    (cause, mut params, mut iv): Named,
    evidence: &mut Vec<String>,
    limitations: &mut Vec<String>,
) -> Named {
    let mut names: Vec<&str> = Vec::new();
    let hi = screened
        .iter()
        .filter_map(|s| s.clip_high_N)
        .min_by(f64::total_cmp);
    let lo = screened
        .iter()
        .filter_map(|s| s.clip_low_N)
        .max_by(f64::total_cmp);
    let clipped: usize = screened.iter().map(|s| s.clipped_samples).sum();
    if clipped > 0 {
        names.push(acquisition::CLIPPING);
        let mut rails = Vec::new();
        for (key, v) in [("clip_high_N", hi), ("clip_low_N", lo)] {
            if let Some(v) = v {
                params.insert(key.into(), v);
                iv.insert(key.into(), [v, v]);
                rails.push(format!("{v:+.0} N"));
            }
        }
        let tests: Vec<&str> = screened
            .iter()
            .filter(|s| s.clipped_samples > 0)
            .map(|s| s.test.as_str())
            .collect();
        evidence.push(format!(
            "the data acquisition: the force channel is clipped at {} (the load cell's range) in {} of {} tests ({clipped} samples): those samples are not compared; the damper is not at fault for this part",
            rails.join(" and "),
            tests.len(),
            screened.len()
        ));
        limitations.push(format!(
            "force clipped ({}: {}): the force beyond the range is not measured, so effects that show at the peaks (relief valves, area asymmetry) are judged on the unclipped samples only; re-record with a larger range to see them",
            rails.join(", "),
            tests.join(", ")
        ));
    }
    let dropouts: usize = screened.iter().map(|s| s.dropout_rows).sum();
    if dropouts > 0 {
        names.push(acquisition::DROPOUTS);
        params.insert("dropout_rows".into(), dropouts as f64);
        iv.insert("dropout_rows".into(), [dropouts as f64; 2]);
        let bridged: usize = screened.iter().map(|s| s.bridged_rows).sum();
        let first = screened
            .iter()
            .find_map(|s| s.first_dropout_s.map(|t| format!("{} at {t:.4} s", s.test)));
        evidence.push(format!(
            "the data acquisition: {dropouts} rows miss a value (dropouts; the first in {}): their force is not compared, and the stroke of {bridged} of them is bridged by straight lines; the damper is not at fault for this part",
            first.unwrap_or_default()
        ));
    }
    if names.is_empty() {
        return (cause, params, iv);
    }
    let named = if cause == "none" {
        names.join("+")
    } else {
        format!("{cause}+{}", names.join("+"))
    };
    (named, params, iv)
}

/// The tests' sample interval [s]: each test's median step, the largest of them (the lag's
/// timing uncertainty is half of it).
fn sample_interval_s(data: &[Measurement]) -> f64 {
    data.iter()
        .map(|m| {
            let mut d: Vec<f64> = m.time_s.windows(2).map(|w| w[1] - w[0]).collect();
            if d.is_empty() {
                return 0.0;
            }
            let mid = d.len() / 2;
            *d.select_nth_unstable_by(mid, f64::total_cmp).1
        })
        .fold(0.0, f64::max)
}

/// Whether a candidate's name holds an acquisition fault.
fn has_fault(name: &str) -> bool {
    name.split('+').any(|n| Fault::from_name(n).is_some())
}

/// Runs the diagnosis of `base` against `data`, in stages (the modules below): the data and
/// their split, the baseline, the single causes, their companions, the companions' tests, the
/// choice, the report.
pub fn diagnose(
    base: &DamperDeck,
    data: &[Measurement],
    opts: &DiagnoseOptions,
) -> Result<Outcome, DiagnoseError> {
    if base.physical.is_none() {
        return Err(DiagnoseError::NoPhysical);
    }
    let (base, data, mut campaign) = prepare::prepare(base, data)?;
    let windows = prepare::split(&data, opts, &mut campaign);
    let cx = prepare::Ctx::new(&base, &data, windows, opts, &campaign);
    let baseline = prepare::baseline(&cx)?;
    let (s, mut evaluated) = singles::singles(&cx, &baseline)?;
    let mut pairing = pairs::companions(&cx, &s, &mut evaluated);
    let mut refused: Vec<String> = Vec::new();
    let mut not_supported: Vec<NotSupported> = Vec::new();
    let test = choice::held_out_test(&cx, &evaluated, &mut pairing, &mut refused);
    choice::name_companions(
        &s,
        &evaluated,
        &mut pairing,
        &mut refused,
        &mut not_supported,
    );
    if let Some(b) = pairing.refit_single.take() {
        if let Some(slot) = evaluated.iter_mut().find(|e| e.0.cause == b.0.cause) {
            *slot = b;
        }
    }
    evaluated.sort_by(|a, b| a.0.bic.total_cmp(&b.0.bic));
    if let Some(d) = &s.demoted {
        demote_behind(&mut evaluated, d);
    }
    let choice = choice::choose(&cx, &s, &evaluated, &pairing, &refused, &mut not_supported);
    choice::passed_over(
        &cx,
        &s,
        &evaluated,
        &pairing,
        &choice.spread_refused,
        &mut not_supported,
    );
    let decided = assemble::Decided {
        pairing,
        test,
        choice,
        not_supported,
    };
    Ok(assemble::assemble(&cx, &s, &evaluated, campaign, decided))
}

/// Two forms of the same element (or one nesting the other) are not a pair.
fn nested(a: Cause, b: Cause) -> bool {
    let air = |c| matches!(c, Cause::EntrainedAir | Cause::EntrainedAirByChamber);
    let play = |c| matches!(c, Cause::CompliantFreePlay);
    let series = |c| matches!(c, Cause::FreePlay | Cause::MountCompliance);
    (air(a) && air(b)) || (play(a) && series(b)) || (series(a) && play(b))
}

/// The limit a compliant free play gives way to: its BIC is within [`BIC_STRONG`] of exactly
/// one limit (pure compliance or rigid gap) and decisively below the other. The limit then
/// takes the lead of the ranking and the compliant row follows it; returns the demoted name.
fn demote_compliant_play(evaluated: &mut [Evaluated]) -> Option<String> {
    let bic = |n: &str| {
        evaluated
            .iter()
            .find(|e| e.0.cause == n && e.1.is_some())
            .map(|e| e.0.bic)
    };
    let c = bic("compliant_free_play")?;
    let m = bic("mount_compliance").unwrap_or(f64::INFINITY);
    let r = bic("free_play").unwrap_or(f64::INFINITY);
    let near_m = m - c <= BIC_STRONG;
    let near_r = r - c <= BIC_STRONG;
    if near_m == near_r {
        return None;
    }
    let name = "compliant_free_play".to_string();
    demote_behind(evaluated, &name);
    Some(name)
}

/// Moves a row just behind the best of its limits (`mount_compliance`, `free_play`) when it is
/// ahead of them.
fn demote_behind(evaluated: &mut [Evaluated], name: &str) {
    let Some(i) = evaluated.iter().position(|e| e.0.cause == name) else {
        return;
    };
    let Some(j) = evaluated
        .iter()
        .position(|e| e.0.cause == "mount_compliance" || e.0.cause == "free_play")
    else {
        return;
    };
    if j > i {
        evaluated[i..=j].rotate_left(1);
    }
}

/// Levenberg-Marquardt patience of a scouting run from one of several starts.
const SCOUT_PATIENCE: usize = 1;
/// Starts of a screened candidate scouted after each start is judged by its residual alone.
const SCREEN_STARTS: usize = 3;
/// Pairs run to convergence after all of them are scouted.
const PAIRS_CONVERGED: usize = 3;

/// Strong evidence on the BIC scale (a difference of 10: odds of ~150 to 1).
const BIC_STRONG: f64 = 10.0;

/// Which limit of a gap behind a contact stiffness the data support: the compliant free play
/// nests the pure compliance (gap -> 0, `mount_compliance`) and the rigid gap (stiffness -> inf,
/// `free_play`); compared by BIC, with the fitted intervals.
/// `cause_iv`: the cause's intervals (with its spread across tests), used when the compliant
/// free play is the cause.
fn free_play_limit(
    cause: &str,
    evaluated: &[Evaluated],
    cause_iv: &BTreeMap<String, [f64; 2]>,
) -> Option<String> {
    let names = ["compliant_free_play", "mount_compliance", "free_play"];
    if !cause.split('+').any(|c| names.contains(&c)) {
        return None;
    }
    let row = |n: &str| {
        evaluated
            .iter()
            .map(|e| &e.0)
            .find(|r| r.cause == n && r.bic.is_finite())
    };
    let cfp = row(names[0])?;
    let (gap, k) = (
        cfp.parameters.get("gap_m")?,
        cfp.parameters.get("contact_stiffness_N_per_m")?,
    );
    let ivs = if cfp.cause == cause {
        cause_iv
    } else {
        &cfp.intervals
    };
    let iv = |p: &str| ivs.get(p).copied().unwrap_or([0.0, f64::INFINITY]);
    let (gi, ki) = (iv("gap_m"), iv("contact_stiffness_N_per_m"));
    let d_mount = row(names[1]).map_or(f64::INFINITY, |r| r.bic - cfp.bic);
    let d_rigid = row(names[2]).map_or(f64::INFINITY, |r| r.bic - cfp.bic);
    let fitted = format!(
        "gap {gap:.3e} m (95% {:.3e}-{:.3e}) behind a contact stiffness {k:.3e} N/m (95% {:.3e}-{:.3e}); BIC below pure compliance by {d_mount:.1}, below the rigid gap by {d_rigid:.1}",
        gi[0], gi[1], ki[0], ki[1]
    );
    let verdict = if d_mount > BIC_STRONG && d_rigid > BIC_STRONG {
        "the data support a gap behind a finite contact stiffness (neither limit)"
    } else if d_mount <= BIC_STRONG && d_rigid <= BIC_STRONG {
        "the data cannot tell the pure-compliance and rigid-gap limits from a compliant gap"
    } else if d_mount <= BIC_STRONG {
        "the data support the pure-compliance limit (no gap resolved: mount_compliance)"
    } else {
        "the data support the rigid-gap limit (contact stiffness not resolved: free_play)"
    };
    Some(format!("{verdict}: {fitted}"))
}

/// What the identifiability analysis needs of the diagnosis.
struct IdContext<'a> {
    base_bic: f64,
    base_held: f64,
    /// Held-out RMS difference below which two candidates count as tied.
    margin: f64,
    sigma: f64,
    one_amp: bool,
    scales: Scales,
    base: &'a DamperDeck,
    max_h: f64,
}

/// Most ties reported (the closest by held-out RMS).
const MAX_TIES: usize = 3;

/// Causes of a candidate's name (`a` or `a+b`).
fn causes_of(name: &str) -> Option<Vec<Cause>> {
    name.split('+')
        .map(|n| Cause::CANDIDATES.iter().copied().find(|c| c.name() == n))
        .collect()
}

/// Candidates the data cannot separate from the chosen cause: the same number of causes,
/// passing against the baseline too, held-out RMS within `margin` of the chosen one's; and the
/// chosen cause's parameters whose 95% interval is unbounded. Each with the proposed test where
/// the two fitted models differ most.
fn identifiability(
    chosen: Option<&Evaluated>,
    evaluated: &[Evaluated],
    data: &[Measurement],
    all_w: &[Window],
    cx: IdContext,
) -> Vec<super::identify::Identifiability> {
    use super::identify::{deciding_test, Conditions, Identifiability};
    let Some((lead, Some(lead_sim), lead_deck, lead_x)) = chosen else {
        return vec![];
    };
    let cond = Conditions::of(data);
    let pair = lead.cause.contains('+');
    let mut ties: Vec<&Evaluated> = evaluated
        .iter()
        .filter(|e| {
            e.0.cause != lead.cause
                && e.1.is_some()
                && e.0.cause.contains('+') == pair
                && e.0.bic < cx.base_bic
                && cx.base_held - e.0.held_out_rms_N > 0.0
                && (e.0.held_out_rms_N - lead.held_out_rms_N).abs() < cx.margin
        })
        .collect();
    ties.sort_by(|a, b| a.0.held_out_rms_N.total_cmp(&b.0.held_out_rms_N));
    ties.truncate(MAX_TIES);
    let mut out = Vec::new();
    for e in ties {
        let sim = e.1.as_ref().expect("filtered on a replay");
        let camp = diff_rms(all_w, lead_sim, sim);
        let why = format!(
            "held-out RMS {:.1} vs {:.1} N: a difference of {:.1} N, below the margin of {:.1} N ({}); BIC {:.1} vs {:.1}; their fitted forces differ by {:.1} N RMS on the campaign (noise sigma {:.1} N){}",
            lead.held_out_rms_N,
            e.0.held_out_rms_N,
            (e.0.held_out_rms_N - lead.held_out_rms_N).abs(),
            cx.margin,
            if cx.one_amp {
                "one amplitude: the larger of the threshold and 5% of the baseline's held-out RMS"
            } else {
                "the threshold of the choice"
            },
            lead.bic,
            e.0.bic,
            camp,
            cx.sigma,
            if cx.one_amp {
                "; the campaign has one stroke amplitude and frequency, where effects that scale differently with amplitude or frequency can look alike"
            } else {
                ""
            }
        );
        // A test stroke decides between damper models; an acquisition fault is decided by
        // checking the acquisition itself.
        let (why, deciding) = if has_fault(&lead.cause) || has_fault(&e.0.cause) {
            (
                format!("{why}; one of them is an acquisition fault: a check of the data acquisition decides (a static load against a reference load cell for gain and offset, the zero reading before and after a test for drift, the phase of the force and stroke channels on a known signal for a lag)"),
                None,
            )
        } else {
            (
                why,
                deciding_test(lead_deck, &e.2, &cond, cx.max_h, camp, cx.sigma),
            )
        };
        out.push(Identifiability {
            candidates: vec![lead.cause.clone(), e.0.cause.clone()],
            why,
            deciding_test: deciding,
        });
    }
    // Parameters the data do not bound: the cause with the parameter doubled (or halved at the
    // upper bound) against the fit.
    if let Some(causes) = causes_of(&lead.cause) {
        if let Some(spec) = combined_params(&causes, cx.base, cx.scales) {
            for (i, p) in spec.iter().enumerate() {
                let Some(&[lo, hi]) = lead.intervals.get(p.name) else {
                    continue;
                };
                if hi.is_finite() && lo > 0.0 {
                    continue;
                }
                let mut x = lead_x.clone();
                x[i] = if 2.0 * x[i] <= p.hi {
                    2.0 * x[i]
                } else {
                    0.5 * x[i]
                };
                let other = apply_all(&causes, cx.base, cx.scales, &x);
                let camp = match data
                    .iter()
                    .map(|m| {
                        let mut f = Vec::new();
                        simulate(&other, m, m.time_s.len(), cx.max_h, &mut f).map(|_| f)
                    })
                    .collect::<Result<Vec<_>, _>>()
                {
                    Ok(sim) => diff_rms(all_w, lead_sim, &sim),
                    Err(_) => f64::NAN,
                };
                out.push(Identifiability {
                    candidates: vec![lead.cause.clone()],
                    why: format!(
                        "{} = {:.4e} is not bounded by the data (95% interval {:.3e} - {:.3e}): the fit's residual hardly changes with it; compared with the same cause at {:.4e}",
                        p.name, lead_x[i], lo, hi, x[i]
                    ),
                    deciding_test: deciding_test(lead_deck, &other, &cond, cx.max_h, camp, cx.sigma),
                });
            }
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The replay, one step per sample along the Hermite path, has no delay of its own behind
    /// the damper: against the same path in steps of at most 0.125 ms, below 1 us at 1 and
    /// 2 kHz (the chord between samples gave 14.7 us at 2 kHz, 59 us at 1 kHz).
    #[test]
    fn the_replay_has_no_delay_of_its_own() {
        let path = concat!(env!("CARGO_MANIFEST_DIR"), "/rotors/uh60a.toml");
        let deck = DamperDeck::from_file(std::path::Path::new(path)).unwrap();
        let (f_hz, amp_m, periods) = (4.3, 2.0e-3, 2.0);
        let delay = |rate_hz: f64| {
            let n = (periods * rate_hz / f_hz).round() as usize + 1;
            let w = 2.0 * std::f64::consts::PI * f_hz;
            let time_s: Vec<f64> = (0..n).map(|i| i as f64 / rate_hz).collect();
            let m = Measurement {
                name: format!("{rate_hz} Hz"),
                stroke_m: time_s.iter().map(|t| amp_m * (w * t).sin()).collect(),
                velocity_m_s: time_s.iter().map(|t| amp_m * w * (w * t).cos()).collect(),
                force_n: vec![0.0; n],
                period_s: 1.0 / f_hz,
                oil_temperature_k: None,
                time_s,
            };
            let mut straight = Vec::new();
            simulate(&deck, &m, n, 3.0e-5, &mut straight).unwrap();
            // the second period: the start-up transient gone
            let spans = [Span {
                test: 0,
                from: n / 2,
                to: n,
            }];
            replay_delay(&deck, &[m], &[straight], &spans, 3.0e-5).unwrap()
        };
        let (d1, d2) = (delay(1000.0), delay(2000.0));
        assert!(
            d1.abs() < 1e-6 && d2.abs() < 1e-6,
            "1 kHz {d1:e} s, 2 kHz {d2:e} s"
        );
    }

    #[test]
    fn normal_quantile_matches_the_tabulated_values() {
        assert!((normal_quantile(0.975) - Z95).abs() < 1e-9);
        // z_(1 - 0.05/10) = 2.5758293035489 (Abramowitz and Stegun, Table 26.5)
        assert!((normal_quantile(0.995) - 2.575_829_303_548_9).abs() < 1e-9);
        assert!(normal_quantile(0.5).abs() < 1e-9);
    }

    #[test]
    fn held_out_z_is_the_residuals_projection_on_the_pairs_change() {
        // e = 3 d / ||d|| sigma: z = 3 whatever the size of d
        let w = [Window {
            test: 0,
            from: 0,
            to: 4,
        }];
        let single = vec![vec![0.0; 4]];
        let d = [1.0, -2.0, 0.5, 2.0];
        let nd = d.iter().map(|x| x * x).sum::<f64>().sqrt();
        let sigma = 7.0;
        let pair = vec![d.iter().map(|x| 10.0 * x).collect::<Vec<f64>>()];
        let m = Measurement {
            name: "t".into(),
            time_s: vec![0.0, 1.0, 2.0, 3.0],
            stroke_m: vec![0.0; 4],
            force_n: d.iter().map(|x| 3.0 * sigma * x / nd).collect(),
            velocity_m_s: vec![0.0; 4],
            period_s: 1.0,
            oil_temperature_k: None,
        };
        let z = held_out_z(&w, &single, &pair, &[m], sigma);
        assert!((z - 3.0).abs() < 1e-12, "{z}");
    }
}
