//! Measured data for a diagnosis: checks (force present, no clipping, enough samples per cycle,
//! enough cycles), stroking period, noise level.
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
}

impl Measurement {
    /// From a bench test (errors without a force column); the period is estimated from the
    /// stroke's mean crossings.
    pub fn from_bench(t: &BenchTest) -> Result<Self, DiagnoseError> {
        let force = t.force_n.clone().ok_or_else(|| DiagnoseError::NoForce {
            test: t.name.clone(),
        })?;
        let vel = t
            .velocity_m_s
            .clone()
            .unwrap_or_else(|| crate::hydraulics::bench::differentiate(&t.time_s, &t.stroke_m));
        let period =
            estimate_period(&t.time_s, &t.stroke_m).ok_or_else(|| DiagnoseError::NoCycle {
                test: t.name.clone(),
            })?;
        Ok(Self {
            name: t.name.clone(),
            time_s: t.time_s.clone(),
            stroke_m: t.stroke_m.clone(),
            force_n: force,
            velocity_m_s: vel,
            period_s: period,
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

/// Period from the mean upward crossings of x (with a hysteresis of 10% of the half range).
pub fn estimate_period(t: &[f64], x: &[f64]) -> Option<f64> {
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
    let mut d: Vec<f64> = force
        .windows(3)
        .map(|w| (w[2] - 2.0 * w[1] + w[0]).abs())
        .collect();
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
        // Clipping: a flat top, several samples exactly at the extreme value (noisy data never
        // repeats its maximum to the last digit).
        let (lo, hi) = min_max(&m.force_n);
        for v in [lo, hi] {
            let count = m.force_n.iter().filter(|&&f| f == v).count();
            if count >= 3.max(n / 500) {
                return Err(DiagnoseError::Clipping {
                    test: m.name.clone(),
                    value: v,
                    count,
                });
            }
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
