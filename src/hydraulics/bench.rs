//! Virtual test bench: harmonic stroking sweeps (paper Figs. 13-14) and replay of measured bench
//! tests (bench CSV of docs/formats.md).
use super::{sample_rates, Device, HydraulicError, StrokePath};
use std::path::Path;

/// Inches to metres.
pub const IN_TO_M: f64 = 0.0254;
/// Pounds-force to newtons.
pub const LB_TO_N: f64 = 4.448_221_615_260_5;

/// Harmonic sweep settings: `d(t) = (v/omega) sin(omega t)` for each peak velocity `v`.
#[derive(Debug, Clone, PartialEq)]
pub struct SweepOptions {
    pub omega_rad_s: f64,
    pub peak_velocities_m_s: Vec<f64>,
    pub cycles: usize,
    pub steps_per_cycle: usize,
}

impl Default for SweepOptions {
    /// The paper's bench: omega = 27.02 rad/s, 0.5 ... 10 in/s, 10 cycles, 256 steps per cycle.
    fn default() -> Self {
        Self {
            omega_rad_s: 27.02,
            peak_velocities_m_s: [0.5, 1.0, 2.0, 3.0, 4.0, 6.0, 8.0, 10.0]
                .iter()
                .map(|v| v * IN_TO_M)
                .collect(),
            cycles: 10,
            steps_per_cycle: 256,
        }
    }
}

/// Time history of one bench run, one row per step end (and the initial instant).
#[derive(Debug, Clone, Default, PartialEq)]
pub struct History {
    pub time_s: Vec<f64>,
    pub stroke_m: Vec<f64>,
    pub velocity_m_s: Vec<f64>,
    /// Device force at the sample instant (Eq. 8), i.e. `force_end` of the step ending there.
    pub force_n: Vec<f64>,
    /// Step-averaged force of the step ending at the sample (NaN at t = 0).
    pub force_mean_n: Vec<f64>,
    pub channel_names: Vec<&'static str>,
    /// channels[c][sample]
    pub channels: Vec<Vec<f64>>,
}

impl History {
    fn new(dev: &dyn Device, cap: usize) -> Self {
        let names = dev.channel_names().to_vec();
        Self {
            channels: vec![Vec::with_capacity(cap); names.len()],
            channel_names: names,
            ..Default::default()
        }
    }

    #[allow(clippy::too_many_arguments)]
    fn push(&mut self, dev: &dyn Device, buf: &mut [f64], t: f64, d: f64, v: f64, f: f64, fm: f64) {
        self.time_s.push(t);
        self.stroke_m.push(d);
        self.velocity_m_s.push(v);
        self.force_n.push(f);
        self.force_mean_n.push(fm);
        dev.channels(buf);
        for (c, x) in self.channels.iter_mut().zip(buf.iter()) {
            c.push(*x);
        }
    }
}

/// Result of one harmonic run.
#[derive(Debug, Clone, PartialEq)]
pub struct HarmonicRun {
    pub peak_velocity_m_s: f64,
    /// Stroke amplitude `A = v/omega` [m].
    pub amplitude_m: f64,
    /// Largest force over the last cycle [N] (at every output sample).
    pub peak_force_pos_n: f64,
    /// Smallest (most negative) force over the last cycle [N].
    pub peak_force_neg_n: f64,
    /// Energy dissipated in the last cycle, `-int F d_dot dt` [J] (positive for a damper).
    pub dissipated_last_cycle_j: f64,
    /// Storage stiffness K' [N/m]: in-phase first harmonic of the reaction `-F` over the last
    /// cycle, divided by the amplitude.
    pub storage_stiffness_n_per_m: f64,
    /// Loss stiffness K'' [N/m]: quadrature (velocity-phase) first harmonic of `-F` over the last
    /// cycle, divided by the amplitude; `pi A^2 K''` is the first harmonic's energy per cycle.
    pub loss_stiffness_n_per_m: f64,
    /// Output samples per step (1: one sample at every step end).
    pub samples_per_step: usize,
    /// Steps per cycle of the run.
    pub steps_per_cycle: usize,
    pub history: History,
}

/// Runs one harmonic test on a fresh copy of `device` (reset to its initial state).
/// `keep_history` false skips recording the channels (benchmarks).
pub fn harmonic_run(
    device: &dyn Device,
    omega: f64,
    peak_velocity: f64,
    cycles: usize,
    steps_per_cycle: usize,
    keep_history: bool,
) -> Result<HarmonicRun, HydraulicError> {
    harmonic_run_sampled(
        device,
        omega,
        peak_velocity,
        cycles,
        steps_per_cycle,
        1,
        keep_history,
    )
}

/// As [`harmonic_run`], with `samples_per_step` output samples in every step: each step's
/// stroke (linear from `d_i` to `d_f`, as the coupled analysis hands it over) is fed to the
/// device in that many equal pieces, one sample at the end of each. The stroke the device sees
/// is the same; a device built with `substeps / samples_per_step` sub-steps integrates with the
/// same sub-step, so only the sampling changes (peaks between step ends are seen).
pub fn harmonic_run_sampled(
    device: &dyn Device,
    omega: f64,
    peak_velocity: f64,
    cycles: usize,
    steps_per_cycle: usize,
    samples_per_step: usize,
    keep_history: bool,
) -> Result<HarmonicRun, HydraulicError> {
    if cycles == 0
        || steps_per_cycle == 0
        || samples_per_step == 0
        || !(omega > 0.0 && omega.is_finite())
        || !peak_velocity.is_finite()
    {
        return Err(HydraulicError::BadStep {
            t: 0.0,
            reason: format!(
                "harmonic run needs cycles >= 1 ({cycles}), steps per cycle >= 1 ({steps_per_cycle}), samples per step >= 1 ({samples_per_step}), omega > 0 ({omega} rad/s) and a finite peak velocity ({peak_velocity} m/s)"
            ),
        });
    }
    let mut dev = device.clone_device();
    dev.reset();
    let period = 2.0 * std::f64::consts::PI / omega;
    let m = samples_per_step;
    let n = cycles * steps_per_cycle;
    let dt = period / steps_per_cycle as f64;
    let dts = dt / m as f64;
    let amp = peak_velocity / omega;
    let stroke = |k: usize| amp * (omega * k as f64 * dt).sin();
    let mut hist = History::new(dev.as_ref(), if keep_history { n * m + 1 } else { 0 });
    let mut buf = vec![0.0; hist.channel_names.len()];
    let f0 = dev.committed_force();
    if keep_history {
        hist.push(
            dev.as_ref(),
            &mut buf,
            0.0,
            0.0,
            peak_velocity,
            f0,
            f64::NAN,
        );
    }
    let (mut fmax, mut fmin, mut work) = (f64::NEG_INFINITY, f64::INFINITY, 0.0);
    // First-harmonic integrals of the reaction -F over the last cycle.
    let (mut in_phase, mut quadrature) = (0.0, 0.0);
    let last_start = n - steps_per_cycle;
    for k in 0..n {
        let (d_i, d_f) = (stroke(k), stroke(k + 1));
        let t_k = k as f64 * dt;
        for j in 0..m {
            // The step's linear stroke at the piece ends (exact ends at j = 0 and j = m).
            let at = |j: usize| {
                if j == m {
                    d_f
                } else {
                    d_i + (d_f - d_i) * (j as f64 / m as f64)
                }
            };
            let (p_i, p_f) = (at(j), at(j + 1));
            let t_i = t_k + j as f64 * dts;
            let t_f = t_i + dts;
            let sf = dev.trial_step(t_i, dts, p_i, p_f)?;
            dev.commit();
            if k >= last_start {
                fmax = fmax.max(sf.force_end);
                fmin = fmin.min(sf.force_end);
                // Exact work of the piece-averaged force over the piece (Eq. 11).
                work += sf.force_mean * (p_f - p_i);
                // int sin and int cos over the piece, exact; the force is its piece mean.
                let (wi, wf) = (omega * t_i, omega * t_f);
                in_phase -= sf.force_mean * (wi.cos() - wf.cos()) / omega;
                quadrature -= sf.force_mean * (wf.sin() - wi.sin()) / omega;
            }
            if keep_history {
                hist.push(
                    dev.as_ref(),
                    &mut buf,
                    t_f,
                    p_f,
                    peak_velocity * (omega * t_f).cos(),
                    sf.force_end,
                    sf.force_mean,
                );
            }
        }
    }
    // Fourier coefficients of -F against sin and cos, over one period, per unit amplitude.
    let scale = if amp != 0.0 {
        2.0 / (period * amp)
    } else {
        f64::NAN
    };
    Ok(HarmonicRun {
        peak_velocity_m_s: peak_velocity,
        amplitude_m: amp,
        peak_force_pos_n: fmax,
        peak_force_neg_n: fmin,
        dissipated_last_cycle_j: -work,
        storage_stiffness_n_per_m: in_phase * scale,
        loss_stiffness_n_per_m: quadrature * scale,
        samples_per_step: m,
        steps_per_cycle,
        history: hist,
    })
}

/// Runs the sweep: one fresh harmonic run per peak velocity.
pub fn harmonic_sweep(
    device: &dyn Device,
    opts: &SweepOptions,
    keep_history: bool,
) -> Result<Vec<HarmonicRun>, HydraulicError> {
    opts.peak_velocities_m_s
        .iter()
        .map(|&v| {
            harmonic_run(
                device,
                opts.omega_rad_s,
                v,
                opts.cycles,
                opts.steps_per_cycle,
                keep_history,
            )
        })
        .collect()
}

/// Errors reading a bench measurement CSV, naming the file and line or column.
#[derive(Debug, thiserror::Error)]
pub enum BenchCsvError {
    #[error("cannot read bench file {file}: {message}")]
    Read { file: String, message: String },
    #[error("bench file {file}: missing column `{column}` (header: {header})")]
    MissingColumn {
        file: String,
        column: String,
        header: String,
    },
    #[error("bench file {file}: column `{column}` has an unknown unit (accepted: {accepted})")]
    UnknownUnit {
        file: String,
        column: String,
        accepted: String,
    },
    #[error("bench file {file}, line {line}: {message}")]
    Line {
        file: String,
        line: usize,
        message: String,
    },
    #[error("bench file {file}: {message}")]
    Other { file: String, message: String },
}

/// One measured bench test, in SI.
#[derive(Debug, Clone, PartialEq)]
pub struct BenchTest {
    pub name: String,
    pub time_s: Vec<f64>,
    pub stroke_m: Vec<f64>,
    pub force_n: Option<Vec<f64>>,
    pub velocity_m_s: Option<Vec<f64>>,
    /// Oil temperature [K] (optional column).
    pub oil_temperature_k: Option<Vec<f64>>,
}

/// (quantity, accepted headers with their factor and offset to SI: `si = x factor + offset`)
#[allow(clippy::type_complexity)]
const QUANTITIES: &[(&str, &[(&str, f64, f64)])] = &[
    ("time", &[("time_s", 1.0, 0.0), ("time_ms", 1e-3, 0.0)]),
    (
        "stroke",
        &[("stroke_m", 1.0, 0.0), ("stroke_in", IN_TO_M, 0.0)],
    ),
    (
        "force",
        &[("force_N", 1.0, 0.0), ("force_lb", LB_TO_N, 0.0)],
    ),
    (
        "velocity",
        &[("velocity_m_s", 1.0, 0.0), ("velocity_in_s", IN_TO_M, 0.0)],
    ),
    (
        "oil_temperature",
        &[
            ("oil_temperature_K", 1.0, 0.0),
            ("oil_temperature_C", 1.0, 273.15),
        ],
    ),
];

/// Reads a bench CSV file (docs/formats.md): `time_s`, `stroke_m` required, `force_N`,
/// `velocity_m_s` optional, alternates `stroke_in`, `force_lb`, `velocity_in_s`.
pub fn read_bench_csv(path: &Path) -> Result<BenchTest, BenchCsvError> {
    read_with(path, false)
}

/// Reads a bench CSV file as [`read_bench_csv`] does, but an empty or `NaN` cell of the stroke,
/// force or velocity is read as NaN (a dropout: the channel lost that sample) instead of an
/// error; the time must still be given on every row.
pub fn read_bench_csv_with_dropouts(path: &Path) -> Result<BenchTest, BenchCsvError> {
    read_with(path, true)
}

fn read_with(path: &Path, dropouts: bool) -> Result<BenchTest, BenchCsvError> {
    let file = path.display().to_string();
    let text = std::fs::read_to_string(path).map_err(|e| BenchCsvError::Read {
        file: file.clone(),
        message: e.to_string(),
    })?;
    let name = path
        .file_stem()
        .map_or_else(|| "test".to_string(), |s| s.to_string_lossy().into_owned());
    parse(&text, &file, &name, dropouts)
}

/// Parses bench CSV text; `file` names it in errors.
pub fn parse_bench_csv(text: &str, file: &str, name: &str) -> Result<BenchTest, BenchCsvError> {
    parse(text, file, name, false)
}

/// Parses bench CSV text as [`read_bench_csv_with_dropouts`] reads a file.
pub fn parse_bench_csv_with_dropouts(
    text: &str,
    file: &str,
    name: &str,
) -> Result<BenchTest, BenchCsvError> {
    parse(text, file, name, true)
}

fn parse(text: &str, file: &str, name: &str, dropouts: bool) -> Result<BenchTest, BenchCsvError> {
    let mut rdr = csv::ReaderBuilder::new()
        .has_headers(true)
        .trim(csv::Trim::All)
        .from_reader(text.as_bytes());
    let header: Vec<String> = rdr
        .headers()
        .map_err(|e| BenchCsvError::Read {
            file: file.into(),
            message: e.to_string(),
        })?
        .iter()
        .map(str::to_string)
        .collect();
    let joined = header.join(",");
    // Column index and SI factor per quantity.
    let mut cols: [Option<(usize, f64, f64)>; 5] = [None; 5];
    for (ci, h) in header.iter().enumerate() {
        let Some(qi) = QUANTITIES
            .iter()
            .position(|(q, _)| h.starts_with(&format!("{q}_")) || h == q)
        else {
            continue; // other columns are allowed and ignored
        };
        let (q, alts) = QUANTITIES[qi];
        let Some(&(_, factor, offset)) = alts.iter().find(|(n, _, _)| n == h) else {
            return Err(BenchCsvError::UnknownUnit {
                file: file.into(),
                column: h.clone(),
                accepted: alts.iter().map(|a| a.0).collect::<Vec<_>>().join(", "),
            });
        };
        if cols[qi].is_some() {
            return Err(BenchCsvError::Other {
                file: file.into(),
                message: format!("two columns give the {q} (`{h}` and another)"),
            });
        }
        cols[qi] = Some((ci, factor, offset));
    }
    for qi in 0..2 {
        if cols[qi].is_none() {
            return Err(BenchCsvError::MissingColumn {
                file: file.into(),
                column: QUANTITIES[qi].1[0].0.into(),
                header: joined,
            });
        }
    }
    let mut data: [Vec<f64>; 5] = Default::default();
    for (ri, rec) in rdr.records().enumerate() {
        let line = ri + 2;
        let rec = rec.map_err(|e| BenchCsvError::Line {
            file: file.into(),
            line,
            message: e.to_string(),
        })?;
        for qi in 0..5 {
            let Some((ci, factor, offset)) = cols[qi] else {
                continue;
            };
            let cell = rec.get(ci).unwrap_or("");
            // A temperature is read once per test (its mean): no dropouts of its own.
            if dropouts
                && (1..4).contains(&qi)
                && (cell.is_empty() || cell.eq_ignore_ascii_case("nan"))
            {
                data[qi].push(f64::NAN);
                continue;
            }
            let x: f64 = cell.parse().map_err(|_| BenchCsvError::Line {
                file: file.into(),
                line,
                message: format!("`{}` = '{cell}' is not a number", header[ci]),
            })?;
            if !x.is_finite() {
                return Err(BenchCsvError::Line {
                    file: file.into(),
                    line,
                    message: format!("`{}` = {cell} is not finite", header[ci]),
                });
            }
            data[qi].push(x * factor + offset);
        }
        let t = &data[0];
        if t.len() >= 2 && t[t.len() - 1] <= t[t.len() - 2] {
            return Err(BenchCsvError::Line {
                file: file.into(),
                line,
                message: format!(
                    "time {} s does not increase (previous {} s)",
                    t[t.len() - 1],
                    t[t.len() - 2]
                ),
            });
        }
    }
    if data[0].len() < 2 {
        return Err(BenchCsvError::Other {
            file: file.into(),
            message: "need at least two samples".into(),
        });
    }
    let [time_s, stroke_m, force, vel, temp] = data;
    let (lo, hi) = super::temperature::OIL_TEMPERATURE_RANGE_K;
    if let Some(k) = temp
        .iter()
        .position(|&t| !super::temperature::is_oil_temperature_k(t))
    {
        return Err(BenchCsvError::Line {
            file: file.into(),
            line: k + 2,
            message: format!(
                "oil temperature {} K is outside {lo}-{hi} K (a column in C must say so: oil_temperature_C)",
                temp[k]
            ),
        });
    }
    Ok(BenchTest {
        name: name.into(),
        time_s,
        stroke_m,
        force_n: cols[2].map(|_| force),
        velocity_m_s: cols[3].map(|_| vel),
        oil_temperature_k: cols[4].map(|_| temp),
    })
}

impl BenchTest {
    /// A stroke history given as arrays (time [s], stroke [m]), checked as the bench CSV reader
    /// checks a file: equal lengths, at least two samples, finite values, increasing time.
    /// `source` names the history in errors.
    pub fn from_arrays(
        source: &str,
        time_s: Vec<f64>,
        stroke_m: Vec<f64>,
    ) -> Result<Self, BenchCsvError> {
        let other = |message: String| BenchCsvError::Other {
            file: source.into(),
            message,
        };
        if time_s.len() != stroke_m.len() {
            return Err(other(format!(
                "time_s has {} samples and stroke_m {}: they must have the same length",
                time_s.len(),
                stroke_m.len()
            )));
        }
        if time_s.len() < 2 {
            return Err(other("need at least two samples".into()));
        }
        for (name, x) in [("time_s", &time_s), ("stroke_m", &stroke_m)] {
            if let Some(i) = x.iter().position(|v| !v.is_finite()) {
                return Err(other(format!("{name}[{i}] = {} is not finite", x[i])));
            }
        }
        if let Some(i) = time_s.windows(2).position(|w| w[1] <= w[0]) {
            return Err(other(format!(
                "time_s[{}] = {} s does not increase (previous {} s)",
                i + 1,
                time_s[i + 1],
                time_s[i]
            )));
        }
        Ok(Self {
            name: source.into(),
            time_s,
            stroke_m,
            force_n: None,
            velocity_m_s: None,
            oil_temperature_k: None,
        })
    }
}

/// Model response to a measured stroke history.
#[derive(Debug, Clone, PartialEq)]
pub struct Replay {
    /// Model force at each sample (force_end of the step ending there; the initial state's force
    /// at the first sample).
    pub force_model_n: Vec<f64>,
    /// RMS of model - measured [N] over all samples (None without a measured force).
    pub rms_error_n: Option<f64>,
    pub history: History,
}

/// The force of [`replay`] alone, at each sample of a stroke history (`time_s` strictly
/// increasing, equal lengths, at least one sample), without the channels: the sub-step
/// envelope is not recorded and nothing but the force is kept.
pub fn replay_force(
    device: &dyn Device,
    time_s: &[f64],
    stroke_m: &[f64],
) -> Result<Vec<f64>, HydraulicError> {
    let n = time_s.len().min(stroke_m.len());
    let mut force = Vec::with_capacity(n);
    if n == 0 {
        return Ok(force);
    }
    let mut dev = device.clone_device();
    dev.set_substep_envelope(false);
    dev.reset();
    let first = dev.trial_step(time_s[0], 1e-9, stroke_m[0], stroke_m[0])?;
    dev.reset();
    force.push(first.force_end);
    let rates = sample_rates(&time_s[..n], &stroke_m[..n]);
    for k in 0..n - 1 {
        let sf = dev.trial_step_path(time_s[k], &sample_path(time_s, stroke_m, &rates, k))?;
        dev.commit();
        force.push(sf.force_end);
    }
    Ok(force)
}

/// The stroke from sample `k` to sample `k + 1` of a replay: the cubic Hermite interpolant with
/// the samples' rates ([`sample_rates`]), so that the force at each sample carries no lag of
/// the replay's own (the chord's rate is the rate half a sample earlier).
pub fn sample_path(time_s: &[f64], stroke_m: &[f64], rates: &[f64], k: usize) -> StrokePath {
    StrokePath::hermite(
        time_s[k + 1] - time_s[k],
        stroke_m[k],
        stroke_m[k + 1],
        rates[k],
        rates[k + 1],
    )
}

/// Drives `device` (reset first) with the measured stroke, one step per sample interval, the
/// stroke between samples the cubic Hermite interpolant of [`sample_path`].
pub fn replay(device: &dyn Device, test: &BenchTest) -> Result<Replay, HydraulicError> {
    let mut dev = device.clone_device();
    dev.reset();
    let n = test.time_s.len();
    let mut hist = History::new(dev.as_ref(), n);
    let mut buf = vec![0.0; hist.channel_names.len()];
    let mut force = Vec::with_capacity(n);
    // Velocity column: measured if given, else central differences of the stroke.
    let vel = test
        .velocity_m_s
        .clone()
        .unwrap_or_else(|| differentiate(&test.time_s, &test.stroke_m));
    // First sample: the device's force with no step taken yet is its initial (static) force.
    let first = dev.trial_step(test.time_s[0], 1e-9, test.stroke_m[0], test.stroke_m[0])?;
    dev.reset();
    force.push(first.force_end);
    hist.push(
        dev.as_ref(),
        &mut buf,
        test.time_s[0],
        test.stroke_m[0],
        vel[0],
        first.force_end,
        f64::NAN,
    );
    let rates = sample_rates(&test.time_s, &test.stroke_m);
    for k in 0..n - 1 {
        let path = sample_path(&test.time_s, &test.stroke_m, &rates, k);
        let sf = dev.trial_step_path(test.time_s[k], &path)?;
        dev.commit();
        force.push(sf.force_end);
        hist.push(
            dev.as_ref(),
            &mut buf,
            test.time_s[k + 1],
            test.stroke_m[k + 1],
            vel[k + 1],
            sf.force_end,
            sf.force_mean,
        );
    }
    let rms = test.force_n.as_ref().map(|m| {
        let s: f64 = m.iter().zip(&force).map(|(a, b)| (a - b) * (a - b)).sum();
        (s / n as f64).sqrt()
    });
    Ok(Replay {
        force_model_n: force,
        rms_error_n: rms,
        history: hist,
    })
}

/// The stroke's period [s]: the median interval between upward crossings of the stroke's
/// mid-range `(max + min)/2`, a crossing counting only after the stroke was below the mid-range
/// by a tenth of the half-range (so measurement noise near the mid-range does not count twice).
/// Crossing instants are interpolated linearly between samples. None with fewer than two
/// crossings (not a periodic stroke, or less than one cycle of it).
pub fn stroke_period(time_s: &[f64], stroke_m: &[f64]) -> Option<f64> {
    let (lo, hi) = stroke_m
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &x| {
            (a.min(x), b.max(x))
        });
    if hi <= lo {
        return None;
    }
    let mid = 0.5 * (lo + hi);
    let arm = mid - 0.1 * 0.5 * (hi - lo);
    let mut armed = false;
    let mut ups = Vec::new();
    for i in 1..stroke_m.len().min(time_s.len()) {
        let (a, b) = (stroke_m[i - 1], stroke_m[i]);
        if a < arm || b < arm {
            armed = true;
        }
        if armed && a < mid && b >= mid {
            let f = (mid - a) / (b - a);
            ups.push(time_s[i - 1] + f * (time_s[i] - time_s[i - 1]));
            armed = b < arm;
        }
    }
    let mut d: Vec<f64> = ups.windows(2).map(|w| w[1] - w[0]).collect();
    if d.is_empty() {
        return None;
    }
    d.sort_by(f64::total_cmp);
    Some(d[d.len() / 2])
}

/// Error of a replay's model force against the measured force, over the samples from a given
/// instant on.
#[derive(Debug, Clone, PartialEq)]
pub struct ReplayMetrics {
    /// Samples the metrics use (those at or after `from_s`).
    pub samples_used: usize,
    /// First instant used [s].
    pub from_s: f64,
    /// RMS of model - measured [N].
    pub rms_error_n: f64,
    /// RMS error over the RMS of the measured force about its mean.
    pub rms_error_rel: f64,
    /// Largest |model - measured| [N].
    pub max_abs_error_n: f64,
}

/// The replay's error over the samples at or after `from_s` (None without a measured force or
/// without a sample from `from_s` on).
pub fn replay_metrics(
    test: &BenchTest,
    force_model_n: &[f64],
    from_s: f64,
) -> Option<ReplayMetrics> {
    let m = test.force_n.as_ref()?;
    let idx: Vec<usize> = (0..m.len().min(force_model_n.len()))
        .filter(|&i| test.time_s[i] >= from_s)
        .collect();
    if idx.is_empty() {
        return None;
    }
    let n = idx.len() as f64;
    let mean = idx.iter().map(|&i| m[i]).sum::<f64>() / n;
    let (mut se, mut sm, mut mx) = (0.0, 0.0, 0.0f64);
    for &i in &idx {
        let e = force_model_n[i] - m[i];
        se += e * e;
        sm += (m[i] - mean) * (m[i] - mean);
        mx = mx.max(e.abs());
    }
    let rms = (se / n).sqrt();
    Some(ReplayMetrics {
        samples_used: idx.len(),
        from_s: test.time_s[idx[0]],
        rms_error_n: rms,
        rms_error_rel: rms / (sm / n).sqrt(),
        max_abs_error_n: mx,
    })
}

/// Central differences (one-sided at the ends) on a non-uniform grid.
pub fn differentiate(t: &[f64], x: &[f64]) -> Vec<f64> {
    let n = t.len();
    (0..n)
        .map(|i| {
            let (a, b) = (i.saturating_sub(1), (i + 1).min(n - 1));
            (x[b] - x[a]) / (t[b] - t[a])
        })
        .collect()
}

/// Relative tolerance of the converged bench: the estimated error of every output (peaks, K',
/// K'', energy per cycle, equivalent damping) over its scale ([`RunError::relative`]).
pub const REFINE_TOLERANCE: f64 = 2e-3;
/// Doublings of the steps per cycle the converged bench may take (16x the first).
pub const REFINE_MAX_DOUBLINGS: u32 = 4;

/// Estimated discretisation error of a harmonic run's outputs, in their units (absolute
/// values).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RunError {
    pub peak_force_pos_n: f64,
    pub peak_force_neg_n: f64,
    pub storage_stiffness_n_per_m: f64,
    pub loss_stiffness_n_per_m: f64,
    pub dissipated_last_cycle_j: f64,
    /// Of `energy / (pi omega A^2)` [N s/m].
    pub equivalent_damping_n_s_per_m: f64,
}

impl RunError {
    /// `factor |a - b|` for every output of two runs at the same frequency and amplitude.
    pub fn between(a: &HarmonicRun, b: &HarmonicRun, omega: f64, factor: f64) -> Self {
        let d = |x: f64, y: f64| factor * (x - y).abs();
        let e = d(a.dissipated_last_cycle_j, b.dissipated_last_cycle_j);
        let amp = b.amplitude_m;
        Self {
            peak_force_pos_n: d(a.peak_force_pos_n, b.peak_force_pos_n),
            peak_force_neg_n: d(a.peak_force_neg_n, b.peak_force_neg_n),
            storage_stiffness_n_per_m: d(a.storage_stiffness_n_per_m, b.storage_stiffness_n_per_m),
            loss_stiffness_n_per_m: d(a.loss_stiffness_n_per_m, b.loss_stiffness_n_per_m),
            dissipated_last_cycle_j: e,
            equivalent_damping_n_s_per_m: e / (std::f64::consts::PI * omega * amp * amp),
        }
    }

    /// The largest error over its output's scale: the peaks over the larger peak magnitude,
    /// K' and K'' over the dynamic stiffness `|K*| = sqrt(K'^2 + K''^2)`, the energy per
    /// cycle over `pi A^2 |K*|` (the equivalent damping's error over `|K*|/omega` is the same
    /// ratio). A scale of zero makes any non-zero error infinite.
    pub fn relative(&self, run: &HarmonicRun) -> f64 {
        let ratio = |e: f64, scale: f64| {
            if e == 0.0 {
                0.0
            } else if scale > 0.0 {
                e / scale
            } else {
                f64::INFINITY
            }
        };
        let peak = run.peak_force_pos_n.abs().max(run.peak_force_neg_n.abs());
        let k = run
            .storage_stiffness_n_per_m
            .hypot(run.loss_stiffness_n_per_m);
        let e = std::f64::consts::PI * run.amplitude_m * run.amplitude_m * k;
        [
            ratio(self.peak_force_pos_n, peak),
            ratio(self.peak_force_neg_n, peak),
            ratio(self.storage_stiffness_n_per_m, k),
            ratio(self.loss_stiffness_n_per_m, k),
            ratio(self.dissipated_last_cycle_j, e),
        ]
        .into_iter()
        .fold(
            0.0,
            |a, x| if x.is_nan() { f64::INFINITY } else { a.max(x) },
        )
    }
}

/// How a bench run's discretisation error is known.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Convergence {
    /// Refined by doubling the steps per cycle until the estimated error is within the
    /// tolerance.
    Converged,
    /// Refined up to the cap without reaching the tolerance: the error is the last estimate.
    NotConverged,
    /// Run as asked; the error from one extra run at twice the steps per cycle.
    Estimated,
    /// Run as asked; the extra run failed (its reason in [`RunEstimate::note`]).
    NotEstimated,
}

impl Convergence {
    /// The name written in bench_summary.csv's `convergence` column.
    pub fn name(self) -> &'static str {
        match self {
            Convergence::Converged => "converged",
            Convergence::NotConverged => "not_converged",
            Convergence::Estimated => "estimated",
            Convergence::NotEstimated => "not_estimated",
        }
    }
}

/// A harmonic run with its estimated discretisation error.
#[derive(Debug, Clone, PartialEq)]
pub struct RefinedRun {
    pub run: HarmonicRun,
    pub estimate: RunEstimate,
}

/// The estimated discretisation error of a harmonic run.
#[derive(Debug, Clone, PartialEq)]
pub struct RunEstimate {
    /// Steps per cycle of the run.
    pub steps_per_cycle: usize,
    /// Estimated error of `run`'s outputs (None: not estimated).
    pub error: Option<RunError>,
    /// `error` relative to the outputs' scales ([`RunError::relative`]; NaN when not estimated).
    pub relative_error: f64,
    pub status: Convergence,
    /// Why the error is not estimated (empty otherwise).
    pub note: String,
}

/// The converged harmonic run: runs at `steps_per_cycle` and at twice as many (the device's
/// sub-steps per step unchanged, so the hydraulic sub-step halves with the step), doubling
/// until the estimated error of every output is within `tolerance` of its scale or
/// `max_doublings` is reached. The estimate assumes first-order convergence (seat contact,
/// check-valve opening and peaks read at the samples converge at first order at worst): the
/// error of the finer run is the difference between the two, whatever the order above one.
#[allow(clippy::too_many_arguments)]
pub fn harmonic_run_converged(
    device: &dyn Device,
    omega: f64,
    peak_velocity: f64,
    cycles: usize,
    steps_per_cycle: usize,
    samples_per_step: usize,
    keep_history: bool,
    tolerance: f64,
    max_doublings: u32,
) -> Result<RefinedRun, HydraulicError> {
    let run = |n: usize| {
        harmonic_run_sampled(
            device,
            omega,
            peak_velocity,
            cycles,
            n,
            samples_per_step,
            keep_history,
        )
    };
    let mut n = steps_per_cycle;
    let mut prev = run(n)?;
    let mut doublings = 0;
    loop {
        n *= 2;
        doublings += 1;
        let cur = run(n)?;
        let err = RunError::between(&prev, &cur, omega, 1.0);
        let rel = err.relative(&cur);
        let status = if rel <= tolerance {
            Convergence::Converged
        } else if doublings >= max_doublings.max(1) {
            Convergence::NotConverged
        } else {
            prev = cur;
            continue;
        };
        return Ok(RefinedRun {
            run: cur,
            estimate: RunEstimate {
                steps_per_cycle: n,
                error: Some(err),
                relative_error: rel,
                status,
                note: String::new(),
            },
        });
    }
}

/// The run as asked, at `steps_per_cycle`, with its error estimated from one extra run at
/// twice the steps per cycle: twice their difference (first order: the run as asked is twice
/// as far from the limit as the finer one). A failing extra run leaves the error unestimated.
pub fn harmonic_run_estimated(
    device: &dyn Device,
    omega: f64,
    peak_velocity: f64,
    cycles: usize,
    steps_per_cycle: usize,
    samples_per_step: usize,
    keep_history: bool,
) -> Result<RefinedRun, HydraulicError> {
    let run = harmonic_run_sampled(
        device,
        omega,
        peak_velocity,
        cycles,
        steps_per_cycle,
        samples_per_step,
        keep_history,
    )?;
    let fine = harmonic_run_sampled(
        device,
        omega,
        peak_velocity,
        cycles,
        2 * steps_per_cycle,
        samples_per_step,
        false,
    );
    let (error, relative_error, status, note) = match fine {
        Ok(f) => {
            let e = RunError::between(&run, &f, omega, 2.0);
            (
                Some(e),
                e.relative(&run),
                Convergence::Estimated,
                String::new(),
            )
        }
        Err(e) => (
            None,
            f64::NAN,
            Convergence::NotEstimated,
            format!(
                "the run at {} steps per cycle failed: {e}",
                2 * steps_per_cycle
            ),
        ),
    };
    Ok(RefinedRun {
        run,
        estimate: RunEstimate {
            steps_per_cycle,
            error,
            relative_error,
            status,
            note,
        },
    })
}
