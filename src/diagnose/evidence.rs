//! Evidence: computed, physically worded observations of the baseline residual and the fit.
use super::fit::{Candidate, Curves};
use std::collections::BTreeMap;

/// Mean residual (measured - baseline) while extending and while compressing (|v| above 20% of
/// the test's peak velocity), over all compared samples.
fn velocity_sign_step(curves: &[Curves]) -> (f64, f64) {
    let (mut sp, mut np, mut sn, mut nn) = (0.0, 0usize, 0.0, 0usize);
    for c in curves {
        let vmax = c.velocity_m_s[c.from..]
            .iter()
            .fold(0.0f64, |a, v| a.max(v.abs()));
        for k in c.from..c.time_s.len() {
            let r = c.measured_n[k] - c.baseline_n[k];
            let v = c.velocity_m_s[k];
            if r.is_nan() {
                // not measured (a dropout or clipped)
            } else if v > 0.2 * vmax {
                sp += r;
                np += 1;
            } else if v < -0.2 * vmax {
                sn += r;
                nn += 1;
            }
        }
    }
    (sp / np.max(1) as f64, sn / nn.max(1) as f64)
}

/// Time per force zero crossing spent within +-band [s] (measured, model).
fn dwell(c: &Curves, band: f64, period: f64) -> (f64, f64) {
    let n = (c.time_s.len() - c.from).max(1) as f64;
    // Over the measured samples only (NaN: a dropout or clipped).
    let measured = c.measured_n[c.from..].iter().filter(|f| !f.is_nan());
    let n_measured = measured.clone().count().max(1) as f64;
    let fm = measured.filter(|f| f.abs() < band).count() as f64 / n_measured;
    let fb = c.baseline_n[c.from..]
        .iter()
        .filter(|f| f.abs() < band)
        .count() as f64
        / n;
    // Two zero crossings per cycle.
    (fm * period / 2.0, fb * period / 2.0)
}

fn peaks(x: &[f64]) -> (f64, f64) {
    x.iter()
        .fold((f64::NEG_INFINITY, f64::INFINITY), |(a, b), &v| {
            (a.max(v), b.min(v))
        })
}

fn period_of(c: &Curves) -> f64 {
    super::data::estimate_period(&c.time_s, &c.stroke_m).unwrap_or(f64::NAN)
}

fn amp(c: &Curves) -> f64 {
    let (hi, lo) = peaks(&c.stroke_m);
    0.5 * (hi - lo)
}

/// Shift (in samples, positive: measured later) of the measured force against the baseline that
/// minimises their RMS difference, searched over +-5% of the cycle and refined by a parabola;
/// returns (shift in samples, RMS at zero shift, RMS at the best integer shift).
fn best_lag(c: &Curves) -> Option<(f64, f64, f64)> {
    let n = c.time_s.len();
    let period = period_of(c);
    let dt = (c.time_s[n - 1] - c.time_s[0]) / (n - 1) as f64;
    let max = ((0.05 * period / dt).ceil() as usize).max(1);
    if c.from + 2 * max + 8 >= n {
        return None;
    }
    let rms = |s: isize| {
        let (mut acc, mut cnt) = (0.0, 0usize);
        for k in c.from + max..n - max {
            let e = c.measured_n[k] - c.baseline_n[(k as isize - s) as usize];
            if !e.is_nan() {
                acc += e * e;
                cnt += 1;
            }
        }
        (acc / cnt.max(1) as f64).sqrt()
    };
    let m = max as isize;
    let vals: Vec<f64> = (-m..=m).map(rms).collect();
    let (ib, &vb) = vals.iter().enumerate().min_by(|a, b| a.1.total_cmp(b.1))?;
    let mut shift = ib as f64 - m as f64;
    if ib > 0 && ib + 1 < vals.len() {
        let (a, b, cc) = (vals[ib - 1], vals[ib], vals[ib + 1]);
        let den = a - 2.0 * b + cc;
        if den > 0.0 {
            shift += 0.5 * (a - cc) / den;
        }
    }
    Some((shift, vals[max], vb))
}

/// Evidence strings of a diagnosis.
pub fn evidence(
    curves: &[Curves],
    sigma: f64,
    cause: &str,
    params: &BTreeMap<String, f64>,
    cands: &[Candidate],
    base_held: f64,
    ext_held: f64,
) -> Vec<String> {
    let mut ev = Vec::new();
    let peak = curves
        .iter()
        .flat_map(|c| c.measured_n.iter())
        .fold(0.0f64, |a, f| a.max(f.abs()));
    ev.push(format!(
        "measurement noise sigma = {sigma:.1} N ({:.2}% of the peak force {peak:.0} N), from second differences",
        100.0 * sigma / peak.max(1e-300)
    ));
    let (rp, rn) = velocity_sign_step(curves);
    ev.push(format!(
        "baseline residual (measured - model) averages {rp:+.1} N while extending and {rn:+.1} N while compressing: a step of {:.1} N across the velocity sign (Coulomb friction would give 2 F_c, negative while extending)",
        rn - rp
    ));
    if let Some(c) = curves.iter().min_by(|a, b| amp(a).total_cmp(&amp(b))) {
        let band = (3.0 * sigma).max(0.02 * peak);
        let (dm, db) = dwell(c, band, period_of(c));
        ev.push(format!(
            "{} (smallest stroke amplitude {:.2} mm): measured force stays within +-{band:.0} N for {:.1} ms around each force zero crossing, baseline model {:.1} ms{}",
            c.name,
            1e3 * amp(c),
            1e3 * dm,
            1e3 * db,
            if dm > 1.5 * db + 0.5e-3 { ": a dwell near zero force (dead band) the baseline lacks" } else { "" }
        ));
    }
    if let Some(c) = curves.iter().max_by(|a, b| amp(a).total_cmp(&amp(b))) {
        let (mp, mn) = peaks(&c.measured_n[c.from..]);
        let (bp, bn) = peaks(&c.baseline_n[c.from..]);
        ev.push(format!(
            "{} (largest amplitude {:.2} mm): measured peaks +{mp:.0} / {mn:.0} N (ratio |neg|/pos {:.3}), baseline +{bp:.0} / {bn:.0} N (ratio {:.3})",
            c.name,
            1e3 * amp(c),
            -mn / mp,
            -bn / bp
        ));
    }
    if let Some(c) = curves.first() {
        if let Some((shift, r0, rb)) = best_lag(c) {
            let n = c.time_s.len();
            let dt = (c.time_s[n - 1] - c.time_s[0]) / (n - 1) as f64;
            let lag = shift * dt;
            ev.push(format!(
                "{}: the measured force {} the baseline model by {:.2} ms ({:.1} deg of the stroke cycle); shifting the model by that much lowers the RMS difference from {r0:.0} to {rb:.0} N{}",
                c.name,
                if lag >= 0.0 { "lags" } else { "leads" },
                1e3 * lag.abs(),
                360.0 * lag.abs() / period_of(c),
                if rb < 0.7 * r0 { ": a phase lag (compliance in the load path)" } else { "" }
            ));
        }
    }
    let per_test: Vec<String> = curves
        .iter()
        .map(|c| {
            let (mp, mn) = peaks(&c.measured_n[c.from..]);
            let (bp, bn) = peaks(&c.baseline_n[c.from..]);
            format!("{:.2} mm: {:.3}", 1e3 * amp(c), (mp - mn) / (bp - bn))
        })
        .collect();
    ev.push(format!(
        "peak-to-peak force measured/baseline by stroke amplitude: {}",
        per_test.join(", ")
    ));
    let what = cause
        .split('+')
        .map(|c| cause_sentence(c, params))
        .collect::<Vec<_>>()
        .join("; ");
    ev.push(what);
    ev.push(format!(
        "held-out RMS error: baseline {base_held:.1} N, extended {ext_held:.1} N (gain {:.3})",
        1.0 - ext_held / base_held
    ));
    if cands.len() >= 2 {
        ev.push(format!(
            "ranking by BIC: {}",
            cands
                .iter()
                .map(|c| format!(
                    "{} {:.0} (held-out {:.1} N)",
                    c.cause, c.bic, c.held_out_rms_N
                ))
                .collect::<Vec<_>>()
                .join("; ")
        ));
    }
    ev
}

fn cause_sentence(cause: &str, params: &BTreeMap<String, f64>) -> String {
    let p = |k: &str| params.get(k).copied().unwrap_or(f64::NAN);
    match cause {
        "seal_friction" => format!(
            "seal friction F_c = {:.0} N: the force swings by ~2 F_c = {:.0} N at every velocity reversal, over a presliding stroke of ~{:.1} um",
            p("F_c_N"),
            2.0 * p("F_c_N"),
            1e6 * p("presliding_m")
        ),
        "free_play" => format!(
            "free play of {:.3} mm in the attachments: no force is transmitted while the stroke crosses the gap after each reversal",
            1e3 * p("gap_m")
        ),
        "compliant_free_play" => format!(
            "free play of {:.3} mm behind a contact stiffness of {:.3e} N/m (rod ends, bearings): no force while the gap is open after each reversal, then a force built up through the contact's compliance",
            1e3 * p("gap_m"),
            p("contact_stiffness_N_per_m")
        ),
        "entrained_air" => format!(
            "entrained air {:.2}% by volume at p_s: the oil is soft near the background pressure, so the force lags and dwells near zero after each reversal",
            100.0 * p("air_fraction")
        ),
        "entrained_air_by_chamber" => format!(
            "entrained air {:.2}% in chamber 0 and {:.2}% in chamber 1 (by volume at p_s): the force lags differently in the two stroke directions and dwells near zero after reversals",
            100.0 * p("air_fraction_0"),
            100.0 * p("air_fraction_1")
        ),
        "area_asymmetry" => format!(
            "rod-side area A1 = {:.4e} m^2: the two stroke directions displace different volumes, so positive and negative peaks differ",
            p("A1_m2")
        ),
        "relief_asymmetry" => format!(
            "relief valves crack at different preloads F_p0 = {:.0} N, F_p1 = {:.0} N: the peak forces are capped asymmetrically",
            p("F_p0_N"),
            p("F_p1_N")
        ),
        "piston_leakage" => format!(
            "piston leakage {:.3e} m^3/(s Pa) through the piston's clearance (viscosity times land length {:.2e} Pa s m): a laminar bypass that lowers the force most at small amplitudes, less the oil the moving piston drags along",
            p("leakage_m3_per_s_Pa"),
            p("leakage_viscosity_length_Pa_s_m")
        ),
        "mount_compliance" => format!(
            "elastic mounts in series, stiffness {:.3e} N/m: the link force lags the damper's own force (a Maxwell element), most visibly as a delayed build-up after each reversal",
            p("mount_stiffness_N_per_m")
        ),
        "accumulator_bleed" => format!(
            "bleed of each chamber to the accumulator, {:.3e} m^3/(s Pa): the mean chamber pressure returns toward p_s instead of being pumped up by the check valves, so the oil is soft and the force dwells near zero at reversals",
            p("accumulator_bleed_m3_per_s_Pa")
        ),
        "oil_temperature" => format!(
            "the oil's temperature, which differs from test to test: density {:.2e} /K and bulk modulus {:.2e} /K lower per kelvin (exponential laws), so a warmer test's orifice force is lower by the density's share; the damper is not at fault for this part",
            p("density_thermal_coefficient_per_K"),
            p("bulk_modulus_thermal_coefficient_per_K")
        ),
        "oil_drift" => format!(
            "the oil warming over the campaign, which records no temperature: density {:.1}% and bulk modulus {:.1}% lower at the last test than at the first (evenly with the tests' order, as given), so later tests' orifice force is lower by the density's share; the damper is not at fault for this part, and a temperature column would let the law per kelvin be fitted",
            100.0 * p("oil_density_drop_fraction"),
            100.0 * p("oil_bulk_modulus_drop_fraction")
        ),
        "recalibration" => format!(
            "re-calibrated coefficients: A_orf = {:.4e} m^2, relief-valve a = {:.4e} m",
            p("A_orf_m2"),
            p("relief_a_m")
        ),
        "force_lag" => format!(
            "the data acquisition: the force channel lags the stroke channel by {:.2} ms (a filter or a sampling delay), which tilts the force-stroke loop like a compliance would; the damper is not at fault for this part",
            1e3 * p("lag_s")
        ),
        "force_offset" => format!(
            "the data acquisition: the force channel carries an offset of {:+.0} N (a zero error), which shifts both peaks alike; the damper is not at fault for this part",
            p("offset_N")
        ),
        "force_gain" => format!(
            "the data acquisition: the force channel reads {:.4} times the force (a calibration error of {:+.1}%), which scales every force alike, relief-valve plateaus included; the damper is not at fault for this part",
            p("gain"),
            100.0 * (p("gain") - 1.0)
        ),
        "force_drift" => format!(
            "the data acquisition: the force channel drifts by {:+.1} N/s from the start of each test (a thermal or bridge drift); the damper is not at fault for this part",
            p("drift_N_per_s")
        ),
        _ => "no candidate beats the baseline by more than the noise-level threshold".to_string(),
    }
}

/// The residual signatures of one force series (measured, baseline or a candidate's
/// prediction), each measured the same way so that a candidate's predicted signature stands
/// beside the measured one (extra key `signatures`).
#[derive(Debug, Clone, serde::Serialize, PartialEq)]
#[allow(non_snake_case)]
pub struct Signature {
    /// `measured`, `baseline` or the candidate's cause.
    pub source: String,
    /// Time per force zero crossing within the dwell band, smallest-amplitude test [ms].
    pub dwell_ms: f64,
    /// Step of (force - baseline) across the velocity sign: compressing mean minus extending
    /// mean, |v| above 20% of the peak velocity, all tests [N].
    pub reversal_step_N: f64,
    /// Lag of the force behind the baseline model that best aligns them (loop tilt),
    /// smallest-amplitude test [ms].
    pub lag_ms: f64,
    /// |negative peak| / positive peak, largest-amplitude test.
    pub peak_ratio: f64,
    /// Mean force above 90% of the positive / below 90% of the negative peak (the relief-valve
    /// plateaus), largest-amplitude test [N].
    pub plateau_pos_N: f64,
    pub plateau_neg_N: f64,
}

/// Signature of `force[test]` (same sample grid as `curves`).
pub fn signature(curves: &[Curves], force: &[Vec<f64>], source: &str, band: f64) -> Signature {
    let small = (0..curves.len()).min_by(|&a, &b| amp(&curves[a]).total_cmp(&amp(&curves[b])));
    let large = (0..curves.len()).max_by(|&a, &b| amp(&curves[a]).total_cmp(&amp(&curves[b])));
    let view = |i: usize| Curves {
        measured_n: force[i].clone(),
        ..curves[i].clone()
    };
    let (mut dwell_ms, mut lag_ms) = (f64::NAN, f64::NAN);
    if let Some(i) = small {
        let c = view(i);
        let period = period_of(&c);
        dwell_ms = 1e3 * dwell(&c, band, period).0;
        let n = c.time_s.len();
        let dt = (c.time_s[n - 1] - c.time_s[0]) / (n - 1) as f64;
        lag_ms = best_lag(&c).map_or(f64::NAN, |(s, _, _)| 1e3 * s * dt);
    }
    let views: Vec<Curves> = (0..curves.len()).map(view).collect();
    let (rp, rn) = velocity_sign_step(&views);
    let (mut peak_ratio, mut plateau_pos, mut plateau_neg) = (f64::NAN, f64::NAN, f64::NAN);
    if let Some(i) = large {
        let f = &force[i][curves[i].from..];
        let (mp, mn) = peaks(f);
        peak_ratio = -mn / mp;
        let mean = |it: Vec<f64>| it.iter().sum::<f64>() / it.len().max(1) as f64;
        plateau_pos = mean(f.iter().copied().filter(|&x| x > 0.9 * mp).collect());
        plateau_neg = mean(f.iter().copied().filter(|&x| x < 0.9 * mn).collect());
    }
    Signature {
        source: source.to_string(),
        dwell_ms,
        reversal_step_N: rn - rp,
        lag_ms,
        peak_ratio,
        plateau_pos_N: plateau_pos,
        plateau_neg_N: plateau_neg,
    }
}

/// Dwell band of the signatures: 3 noise sigma, at least 2% of the peak force (as the evidence).
pub fn dwell_band(curves: &[Curves], sigma: f64) -> f64 {
    let peak = curves
        .iter()
        .flat_map(|c| c.measured_n.iter())
        .fold(0.0f64, |a, f| a.max(f.abs()));
    (3.0 * sigma).max(0.02 * peak)
}

/// Realizations of the noise spread of the signatures ([`signature_noise`]).
pub const NOISE_REALIZATIONS: usize = 32;

/// Spread of the signature that the measurement noise alone gives: the standard deviation of
/// each signature quantity over [`NOISE_REALIZATIONS`] copies of `reference` (a noise-free
/// force on the grid of `curves`, e.g. the extended model's) with white Gaussian noise of
/// `sigma` added (a parametric bootstrap; seeded, so a diagnosis is reproducible). Source
/// `noise_sd`.
pub fn signature_noise(
    curves: &[Curves],
    reference: &[Vec<f64>],
    sigma: f64,
    band: f64,
) -> Signature {
    use rand::SeedableRng;
    use rand_distr::{Distribution, Normal};
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(0x5167_0a7e);
    let normal = Normal::new(0.0, sigma.max(0.0)).unwrap_or(Normal::new(0.0, 0.0).unwrap());
    let sigs: Vec<Signature> = (0..NOISE_REALIZATIONS)
        .map(|_| {
            let noisy: Vec<Vec<f64>> = reference
                .iter()
                .map(|f| f.iter().map(|v| v + normal.sample(&mut rng)).collect())
                .collect();
            signature(curves, &noisy, "noise", band)
        })
        .collect();
    let sd = |f: fn(&Signature) -> f64| {
        let v: Vec<f64> = sigs.iter().map(f).filter(|x| x.is_finite()).collect();
        if v.len() < 2 {
            return f64::NAN;
        }
        let m = v.iter().sum::<f64>() / v.len() as f64;
        (v.iter().map(|x| (x - m).powi(2)).sum::<f64>() / (v.len() - 1) as f64).sqrt()
    };
    Signature {
        source: "noise_sd".into(),
        dwell_ms: sd(|s| s.dwell_ms),
        reversal_step_N: sd(|s| s.reversal_step_N),
        lag_ms: sd(|s| s.lag_ms),
        peak_ratio: sd(|s| s.peak_ratio),
        plateau_pos_N: sd(|s| s.plateau_pos_N),
        plateau_neg_N: sd(|s| s.plateau_neg_N),
    }
}
