//! Identifiability: which candidates the data cannot tell apart (held-out RMS within the
//! margin of the best, or a parameter the data do not bound), and the next test that would
//! decide: the stroke amplitude or frequency, not in the campaign, where the fitted candidates'
//! predicted forces differ most relative to the noise.
use super::data::Measurement;
use super::fit::simulate;
use crate::hydraulics::DamperDeck;
use rayon::prelude::*;
use serde::Serialize;

/// A harmonic test proposed to decide between candidates (extra key `identifiability`).
#[derive(Debug, Clone, Serialize, PartialEq)]
#[allow(non_snake_case)]
pub struct DecidingTest {
    pub amplitude_m: f64,
    pub frequency_rad_s: f64,
    pub mean_stroke_m: f64,
    /// RMS of the difference of the two predicted forces over cycles 2-3 [N].
    pub predicted_difference_rms_N: f64,
    /// The same difference over the campaign's compared samples [N].
    pub campaign_difference_rms_N: f64,
    pub noise_sigma_N: f64,
    pub statement: String,
}

/// One group of candidates the data cannot separate (extra key `identifiability`).
#[derive(Debug, Clone, Serialize, PartialEq)]
pub struct Identifiability {
    pub candidates: Vec<String>,
    pub why: String,
    /// None when no proposed test separates them by more than the noise.
    pub deciding_test: Option<DecidingTest>,
}

/// Campaign conditions: (amplitude, frequency) of every test, the mean stroke, the sample
/// interval.
pub struct Conditions {
    tests: Vec<(f64, f64)>,
    mean_m: f64,
    dt: f64,
}

impl Conditions {
    pub fn of(data: &[Measurement]) -> Self {
        let tests: Vec<(f64, f64)> = data
            .iter()
            .map(|m| (m.amplitude_m(), 2.0 * std::f64::consts::PI / m.period_s))
            .collect();
        let mean_m = data
            .iter()
            .map(|m| m.stroke_m.iter().sum::<f64>() / m.stroke_m.len() as f64)
            .sum::<f64>()
            / data.len() as f64;
        let dt = data
            .iter()
            .map(|m| (m.time_s[m.time_s.len() - 1] - m.time_s[0]) / (m.time_s.len() - 1) as f64)
            .fold(f64::INFINITY, f64::min);
        // A zero-mean record's mean is its noise-free zero (not a 1e-9 m offset).
        let amax = tests.iter().map(|t| t.0).fold(0.0, f64::max);
        let mean_m = if mean_m.abs() < 1e-4 * amax {
            0.0
        } else {
            mean_m
        };
        Self { tests, mean_m, dt }
    }

    /// Proposed tests: a quarter, half, twice and three times the campaign's smallest or largest
    /// amplitude at its median frequency, and half and twice that frequency at its median
    /// amplitude; conditions within 15% (amplitude and frequency) of a campaign test are left
    /// out (the campaign has them).
    fn proposals(&self) -> Vec<(f64, f64)> {
        let mut a: Vec<f64> = self.tests.iter().map(|t| t.0).collect();
        let mut w: Vec<f64> = self.tests.iter().map(|t| t.1).collect();
        a.sort_by(f64::total_cmp);
        w.sort_by(f64::total_cmp);
        let (amin, amax, amed, wmed) = (a[0], a[a.len() - 1], a[a.len() / 2], w[w.len() / 2]);
        let mut p = vec![
            (0.25 * amin, wmed),
            (0.5 * amin, wmed),
            (2.0 * amax, wmed),
            (3.0 * amax, wmed),
            (amed, 0.5 * wmed),
            (amed, 2.0 * wmed),
        ];
        let near = |x: f64, y: f64| (x / y - 1.0).abs() < 0.15;
        p.retain(|&(pa, pw)| {
            !self
                .tests
                .iter()
                .any(|&(ta, tw)| near(pa, ta) && near(pw, tw))
        });
        p
    }

    /// Stroke-driven harmonic record: 3 cycles at `dt` (about; a whole number per cycle).
    fn harmonic(&self, amp: f64, w: f64) -> Measurement {
        let period = 2.0 * std::f64::consts::PI / w;
        let per = ((period / self.dt).round() as usize).max(64);
        let n = 3 * per + 1;
        let dt = period / per as f64;
        let time_s: Vec<f64> = (0..n).map(|k| k as f64 * dt).collect();
        let stroke_m = time_s
            .iter()
            .map(|t| self.mean_m + amp * (w * t).sin())
            .collect();
        let velocity_m_s = time_s.iter().map(|t| amp * w * (w * t).cos()).collect();
        Measurement {
            name: "proposed".into(),
            force_n: vec![0.0; n],
            time_s,
            stroke_m,
            velocity_m_s,
            period_s: period,
            oil_temperature_k: None,
        }
    }
}

/// The proposed test where two decks' predicted forces differ most (RMS over cycles 2-3); None
/// when none of them can be simulated.
pub fn deciding_test(
    a: &DamperDeck,
    b: &DamperDeck,
    cond: &Conditions,
    max_h: f64,
    campaign_difference: f64,
    sigma: f64,
) -> Option<DecidingTest> {
    let best = cond
        .proposals()
        .into_par_iter()
        .filter_map(|(amp, w)| {
            let m = cond.harmonic(amp, w);
            let n = m.time_s.len();
            let (mut fa, mut fb) = (Vec::with_capacity(n), Vec::with_capacity(n));
            // A proposal beyond the damper's travel (or unstable) cannot be run: skipped.
            simulate(a, &m, n, max_h, &mut fa).ok()?;
            simulate(b, &m, n, max_h, &mut fb).ok()?;
            let from = m.cycle_start(1.0);
            let ss: f64 = fa[from..]
                .iter()
                .zip(&fb[from..])
                .map(|(x, y)| (x - y) * (x - y))
                .sum();
            Some((amp, w, (ss / (n - from) as f64).sqrt()))
        })
        .max_by(|x, y| x.2.total_cmp(&y.2))?;
    let (amp, w, d) = best;
    let camp_a: Vec<String> = {
        let mut v: Vec<f64> = cond.tests.iter().map(|t| t.0 * 1e3).collect();
        v.sort_by(f64::total_cmp);
        v.dedup_by(|x, y| (*x / *y - 1.0).abs() < 0.02);
        v.iter().map(|x| format!("{x:.2}")).collect()
    };
    let statement = format!(
        "run a test at stroke amplitude {:.2} mm and {:.2} rad/s (mean stroke {:.2} mm; the campaign has {} mm at {:.2} rad/s): the two fitted models' forces differ there by {:.1} N RMS ({:.1} noise sigma), against {:.1} N RMS ({:.1} sigma) on the campaign's own data",
        amp * 1e3,
        w,
        cond.mean_m * 1e3,
        camp_a.join(", "),
        {
            let mut v: Vec<f64> = cond.tests.iter().map(|t| t.1).collect();
            v.sort_by(f64::total_cmp);
            v[v.len() / 2]
        },
        d,
        d / sigma.max(1e-12),
        campaign_difference,
        campaign_difference / sigma.max(1e-12),
    );
    Some(DecidingTest {
        amplitude_m: amp,
        frequency_rad_s: w,
        mean_stroke_m: cond.mean_m,
        predicted_difference_rms_N: d,
        campaign_difference_rms_N: campaign_difference,
        noise_sigma_N: sigma,
        statement,
    })
}
