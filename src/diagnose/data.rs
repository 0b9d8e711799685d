//! Measured data for a diagnosis: checks (force present, enough samples per cycle,
//! enough cycles), the screen for dropouts and clipping, stroking period, noise level.
use super::DiagnoseError;
use crate::hydraulics::bench::BenchTest;

/// Minimum samples per stroke cycle.
pub const MIN_SAMPLES_PER_CYCLE: usize = 32;
/// Minimum number of stroke cycles per test.
pub const MIN_CYCLES: usize = 2;

/// One stroke-driven measurement with force (SI).
#[derive(Debug, Clone, PartialEq)]
pub struct Measurement {
    pub name: String,
    pub time_s: Vec<f64>,
    pub stroke_m: Vec<f64>,
    pub force_n: Vec<f64>,
    /// Stroke rate [m/s] (measured, or differentiated; periodic where the record is periodic).
    pub velocity_m_s: Vec<f64>,
    /// Stroking period [s] (estimated or known).
    pub period_s: f64,
    /// The test's oil temperature [K] (the mean of its column; None without one): a test lasts
    /// seconds, the oil warms over minutes.
    pub oil_temperature_k: Option<f64>,
}

impl Measurement {
    /// From a bench test (errors without a force column); the period is estimated from the
    /// stroke's mean crossings.
    pub fn from_bench(t: &BenchTest) -> Result<Self, DiagnoseError> {
        let force = t.force_n.clone().ok_or_else(|| DiagnoseError::NoForce {
            test: t.name.clone(),
        })?;
        let period =
            estimate_period(&t.time_s, &t.stroke_m).ok_or_else(|| DiagnoseError::NoCycle {
                test: t.name.clone(),
            })?;
        // Differentiated across a stroke dropout from the bridged stroke (the dropout's rows
        // stay missing in the stroke itself, for the screen); a dropout too long to bridge is
        // the screen's error.
        let vel = t.velocity_m_s.clone().unwrap_or_else(|| {
            let mut x = t.stroke_m.clone();
            if bridge(&t.name, "stroke", &t.time_s, &mut x, period).is_err() {
                x.clone_from(&t.stroke_m);
            }
            crate::hydraulics::bench::differentiate(&t.time_s, &x)
        });
        Ok(Self {
            name: t.name.clone(),
            time_s: t.time_s.clone(),
            stroke_m: t.stroke_m.clone(),
            force_n: force,
            velocity_m_s: vel,
            period_s: period,
            oil_temperature_k: t
                .oil_temperature_k
                .as_ref()
                .map(|v| v.iter().sum::<f64>() / v.len() as f64),
        })
    }

    /// Stroke amplitude (half the peak-to-peak) [m].
    pub fn amplitude_m(&self) -> f64 {
        let (lo, hi) = min_max(&self.stroke_m);
        0.5 * (hi - lo)
    }

    /// Peak absolute force [N].
    pub fn peak_force_n(&self) -> f64 {
        self.force_n.iter().fold(0.0f64, |a, f| a.max(f.abs()))
    }

    /// Number of the sample where cycle `c` starts (time >= t0 + c T).
    pub fn cycle_start(&self, c: f64) -> usize {
        let t = self.time_s[0] + c * self.period_s;
        self.time_s.partition_point(|&x| x < t - 1e-12)
    }

    /// Number of whole-or-partial cycles recorded.
    pub fn cycles(&self) -> f64 {
        (self.time_s[self.time_s.len() - 1] - self.time_s[0]) / self.period_s
    }
}

pub(crate) fn min_max(x: &[f64]) -> (f64, f64) {
    x.iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &v| {
            (a.min(v), b.max(v))
        })
}

/// Period from the mean upward crossings of x (with a hysteresis of 10% of the half range);
/// samples where x is missing (NaN) are skipped.
pub fn estimate_period(t: &[f64], x: &[f64]) -> Option<f64> {
    if x.iter().any(|v| v.is_nan()) {
        let (t, x): (Vec<f64>, Vec<f64>) = t
            .iter()
            .zip(x)
            .filter(|(_, x)| !x.is_nan())
            .map(|(t, x)| (*t, *x))
            .unzip();
        return estimate_period(&t, &x);
    }
    if x.is_empty() {
        return None;
    }
    let (lo, hi) = min_max(x);
    if hi.partial_cmp(&lo) != Some(std::cmp::Ordering::Greater) {
        return None;
    }
    let mid = 0.5 * (lo + hi);
    let h = 0.1 * (hi - lo) * 0.5;
    let mut armed = x[0] < mid - h;
    let mut crossings = Vec::new();
    for i in 1..x.len() {
        if x[i] < mid - h {
            armed = true;
        }
        if armed && x[i - 1] < mid && x[i] >= mid {
            let s = (mid - x[i - 1]) / (x[i] - x[i - 1]);
            crossings.push(t[i - 1] + s * (t[i] - t[i - 1]));
            armed = false;
        }
    }
    if crossings.len() < 2 {
        return None;
    }
    Some((crossings[crossings.len() - 1] - crossings[0]) / (crossings.len() - 1) as f64)
}

/// Noise standard deviation from second differences, robustly: for white noise of standard
/// deviation s, `f[i+1] - 2 f[i] + f[i-1]` has standard deviation `sqrt(6) s`; the median
/// absolute value (/0.6745) ignores the few samples at relief-valve openings and reversals. The
/// signal's own second difference (`F (omega dt)^2`, ~3 N at 2 kHz) is negligible.
pub fn noise_sigma(force: &[f64]) -> f64 {
    if force.len() < 3 {
        return 0.0;
    }
    // Triples with a sample not measured (NaN: a dropout or clipped) are skipped.
    let mut d: Vec<f64> = force
        .windows(3)
        .map(|w| (w[2] - 2.0 * w[1] + w[0]).abs())
        .filter(|v| !v.is_nan())
        .collect();
    if d.is_empty() {
        return 0.0;
    }
    let mid = d.len() / 2;
    let (_, m, _) = d.select_nth_unstable_by(mid, |a, b| a.total_cmp(b));
    *m / 0.6745 / 6f64.sqrt()
}

/// Periodic central difference of x sampled uniformly over whole periods (`x[n]` follows
/// `x[n-1]` as `x[0]` does), for records known to be periodic (flight records).
pub fn periodic_derivative(x: &[f64], dt: f64) -> Vec<f64> {
    let n = x.len();
    (0..n)
        .map(|i| (x[(i + 1) % n] - x[(i + n - 1) % n]) / (2.0 * dt))
        .collect()
}

/// Longest dropout of the stroke (or velocity) channel bridged, as a fraction of the stroking
/// period: a straight line over 1/64 of a sine cycle is off by at most 0.12% of its amplitude.
pub const MAX_BRIDGE_PERIOD_FRACTION: f64 = 1.0 / 64.0;

/// What the acquisition screen found in one test and did about it (diagnosis.json
/// `acquisition_screen`): dropouts (rows whose stroke, velocity or force is missing) and
/// clipping (samples at the load cell's range). Neither is dropped silently: the force there
/// is not compared, the stroke is bridged, and both are named as acquisition faults.
#[allow(non_snake_case)]
#[derive(Debug, Clone, serde::Serialize, PartialEq)]
pub struct Screened {
    pub test: String,
    /// Rows with a missing (NaN) stroke, velocity or force; their force is not compared.
    pub dropout_rows: usize,
    /// Of those, rows whose stroke or velocity was missing, bridged by a straight line in time.
    pub bridged_rows: usize,
    /// Time of the first dropout [s].
    pub first_dropout_s: Option<f64>,
    /// The force channel's upper and lower rail [N] where the force sits there (clipping).
    pub clip_high_N: Option<f64>,
    pub clip_low_N: Option<f64>,
    /// Samples at a rail; their force is not compared.
    pub clipped_samples: usize,
    /// Samples in the test.
    pub samples: usize,
}

/// Screens every measurement for dropouts and clipping: returns the measurements with the
/// stroke and velocity bridged across dropouts and the force of dropouts and clipped samples
/// set to NaN (not compared), and what was found in each test. A stroke dropout longer than
/// [`MAX_BRIDGE_PERIOD_FRACTION`] of the period, at the first or last sample, or a test left
/// with fewer than half its force samples, is an error.
pub fn screen(ms: &[Measurement]) -> Result<(Vec<Measurement>, Vec<Screened>), DiagnoseError> {
    let mut out = Vec::with_capacity(ms.len());
    let mut found = Vec::with_capacity(ms.len());
    for m in ms {
        let n = m.time_s.len();
        let mut m = m.clone();
        let missing: Vec<bool> = (0..n)
            .map(|i| {
                !(m.stroke_m[i].is_finite()
                    && m.velocity_m_s[i].is_finite()
                    && m.force_n[i].is_finite())
            })
            .collect();
        let dropout_rows = missing.iter().filter(|&&b| b).count();
        let bridged_rows = (0..n)
            .filter(|&i| !(m.stroke_m[i].is_finite() && m.velocity_m_s[i].is_finite()))
            .count();
        for (channel, x) in [
            ("stroke", &mut m.stroke_m),
            ("velocity", &mut m.velocity_m_s),
        ] {
            bridge(&m.name, channel, &m.time_s, x, m.period_s)?;
        }
        for (f, &b) in m.force_n.iter_mut().zip(&missing) {
            if b {
                *f = f64::NAN;
            }
        }
        // Clipping: several samples exactly at the extreme value (noisy data never repeats its
        // maximum to the last digit).
        // `min_max` passes over NaN (f64::min and max return the other operand).
        let (lo, hi) = min_max(&m.force_n);
        let mut clip = [None, None];
        let mut clipped = 0;
        for (k, v) in [hi, lo].into_iter().enumerate() {
            if !v.is_finite() {
                continue;
            }
            let count = m.force_n.iter().filter(|&&f| f == v).count();
            if count >= 3.max(n / 500) {
                clip[k] = Some(v);
                clipped += count;
                for f in m.force_n.iter_mut().filter(|f| **f == v) {
                    *f = f64::NAN;
                }
            }
        }
        let kept = m.force_n.iter().filter(|f| f.is_finite()).count();
        if 2 * kept < n {
            return Err(DiagnoseError::Unusable {
                test: m.name.clone(),
                kept,
                samples: n,
                dropouts: dropout_rows,
                clipped,
            });
        }
        found.push(Screened {
            test: m.name.clone(),
            dropout_rows,
            bridged_rows,
            first_dropout_s: missing.iter().position(|&b| b).map(|i| m.time_s[i]),
            clip_high_N: clip[0],
            clip_low_N: clip[1],
            clipped_samples: clipped,
            samples: n,
        });
        out.push(m);
    }
    Ok((out, found))
}

/// Bridges runs of non-finite values of `x` by straight lines in time. Errors on a run at
/// either end or longer than [`MAX_BRIDGE_PERIOD_FRACTION`] of `period_s`.
fn bridge(
    test: &str,
    channel: &'static str,
    t: &[f64],
    x: &mut [f64],
    period_s: f64,
) -> Result<(), DiagnoseError> {
    let n = x.len();
    let mut i = 0;
    while i < n {
        if x[i].is_finite() {
            i += 1;
            continue;
        }
        let j = (i..n).find(|&k| x[k].is_finite()).unwrap_or(n);
        let err = |reason: String| DiagnoseError::Dropout {
            test: test.to_string(),
            channel,
            from_s: t[i],
            to_s: t[j - 1],
            reason,
        };
        if i == 0 || j == n {
            return Err(err(format!(
                "at the {} of the test, where no straight line can bridge it: trim the record",
                if i == 0 { "start" } else { "end" }
            )));
        }
        let span = t[j] - t[i - 1];
        if span > MAX_BRIDGE_PERIOD_FRACTION * period_s {
            return Err(err(format!(
                "{:.2} ms between the samples around it, more than 1/64 of the stroking period ({:.2} ms) that a straight line bridges",
                1e3 * span,
                1e3 * MAX_BRIDGE_PERIOD_FRACTION * period_s
            )));
        }
        let (x0, x1) = (x[i - 1], x[j]);
        for k in i..j {
            x[k] = x0 + (x1 - x0) * (t[k] - t[i - 1]) / span;
        }
        i = j;
    }
    Ok(())
}

/// Checks every measurement; returns the limitations (what the data cannot decide) that do not
/// stop the diagnosis.
pub fn check_measurements(ms: &[Measurement]) -> Result<Vec<String>, DiagnoseError> {
    if ms.is_empty() {
        return Err(DiagnoseError::Empty);
    }
    let mut notes = Vec::new();
    for m in ms {
        let n = m.time_s.len();
        let spc = m.period_s / ((m.time_s[n - 1] - m.time_s[0]) / (n - 1) as f64);
        if spc < MIN_SAMPLES_PER_CYCLE as f64 {
            return Err(DiagnoseError::SampleRate {
                test: m.name.clone(),
                samples_per_cycle: spc,
                period_s: m.period_s,
                min: MIN_SAMPLES_PER_CYCLE,
            });
        }
        if m.cycles() < MIN_CYCLES as f64 - 0.02 {
            return Err(DiagnoseError::TooShort {
                test: m.name.clone(),
                cycles: m.cycles(),
                min: MIN_CYCLES,
            });
        }
    }
    let amps: Vec<f64> = ms.iter().map(Measurement::amplitude_m).collect();
    let (alo, ahi) = min_max(&amps);
    if ahi < 1.15 * alo {
        notes.push(format!(
            "one stroke amplitude only ({:.3} mm): amplitude-dependent effects (piston leakage, entrained air, orifice/relief-valve re-calibration) cannot be separated reliably; validation on held-out cycles, not held-out amplitudes; test more amplitudes to decide",
            1e3 * ahi
        ));
    }
    Ok(notes)
}
