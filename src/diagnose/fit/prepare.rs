//! The first stages of a diagnosis: the data as they are compared (the oil's reference, the
//! screen, the checks), the split into fit and held-out windows, the noise and scales, and the
//! baseline's replays.
use super::{
    bic, measured_samples, oil_reference_k, oil_span_k, rms_over, simulate, DiagnoseOptions, Window,
};
use crate::diagnose::candidates::{oil_drift_temperature_k, Scales};
use crate::diagnose::data::{check_measurements, noise_sigma, screen, Measurement, Screened};
use crate::diagnose::DiagnoseError;
use crate::hydraulics::{DamperDeck, OilTemperature};
use std::borrow::Cow;

/// What the data are besides the samples compared: the screen, the limitations found, the
/// oil's reference, how the split was made.
pub(super) struct Campaign {
    pub(super) screened: Vec<Screened>,
    pub(super) limitations: Vec<String>,
    pub(super) oil_span: f64,
    /// The given deck has no oil law.
    pub(super) oil_reference_unknown: bool,
    /// The tests carry the drift's stand-in temperatures.
    pub(super) oil_drift: bool,
    /// The oil law of the deck before a drift removed it.
    pub(super) given_oil: Option<OilTemperature>,
    /// The checks found a single stroke amplitude.
    pub(super) one_amp: bool,
    /// How the split was made (`validation.method`).
    pub(super) method: String,
    /// Each test's role in the split.
    pub(super) roles: Vec<String>,
}

/// Stage 1, the data: the oil's reference, the screen (dropouts, clipping), the checks.
/// Returns the deck and the screened data, as compared.
#[allow(clippy::type_complexity)]
pub(super) fn prepare<'a>(
    base: &'a DamperDeck,
    data: &[Measurement],
) -> Result<(Cow<'a, DamperDeck>, Vec<Measurement>, Campaign), DiagnoseError> {
    // Every test with its oil temperature and a deck without the oil's law: the data sheet is
    // taken to hold at the tests' median temperature (a law with no coefficients moves
    // nothing, bit for bit; the `oil_temperature` candidate fits them).
    let oil_reference_unknown = base.oil.is_none();
    let mut deck = Cow::Borrowed(base);
    if let (Some(t), None) = (oil_reference_k(data), base.oil) {
        deck = Cow::Owned(DamperDeck {
            oil: Some(OilTemperature {
                temperature_k: t,
                density_per_k: 0.0,
                bulk_modulus_per_k: 0.0,
                viscosity_per_k: 0.0,
            }),
            ..base.clone()
        });
    }
    // Dropouts and clipping: the force there is not compared, the stroke bridged (`screen`).
    let (mut screened_data, screened) = screen(data)?;
    let oil_span = oil_span_k(&screened_data);
    // No test records its oil temperature: three tests or more carry stand-in temperatures
    // rising with their order, read only by the `oil_drift` candidate's law (every other
    // candidate's deck has none, so nothing moves).
    let oil_drift =
        screened_data.len() >= 3 && screened_data.iter().all(|m| m.oil_temperature_k.is_none());
    let given_oil = deck.oil;
    if oil_drift {
        let n = screened_data.len();
        for (i, m) in screened_data.iter_mut().enumerate() {
            m.oil_temperature_k = Some(oil_drift_temperature_k(i, n));
        }
        deck = Cow::Owned(DamperDeck {
            oil: None,
            ..deck.into_owned()
        });
    }
    let data = &screened_data[..];
    let mut limitations = check_measurements(data)?;
    let recorded = data
        .iter()
        .filter(|m| m.oil_temperature_k.is_some())
        .count();
    if !oil_drift && recorded > 0 && recorded < data.len() {
        limitations.push(format!(
            "{recorded} of {} tests record the oil temperature: the oil is neither fitted to the temperatures nor as a drift (record it in every test, or in none)",
            data.len()
        ));
    }
    let unused = oil_reference_unknown && !oil_drift && oil_span < 0.5;
    if let (true, Some(t)) = (unused, oil_reference_k(data)) {
        limitations.push(format!(
            "the oil temperature recorded ({t:.1} K) moves nothing: the deck has no [damper.physical.oil] law, and a single temperature cannot fit one"
        ));
    }
    let one_amp = limitations
        .iter()
        .any(|l| l.starts_with("one stroke amplitude"));
    let campaign = Campaign {
        screened,
        limitations,
        oil_span,
        oil_reference_unknown,
        oil_drift,
        given_oil,
        one_amp,
        method: String::new(),
        roles: Vec::new(),
    };
    Ok((deck, screened_data, campaign))
}

/// Test `i` from its second cycle to its end.
pub(super) fn full(data: &[Measurement], i: usize) -> Window {
    Window {
        test: i,
        from: data[i].cycle_start(1.0),
        to: data[i].time_s.len(),
    }
}

/// Stage 2, the split: by amplitude (alternate tests in amplitude order are held out), else by
/// cycles. Returns the fit and held-out windows; `campaign` takes how they were chosen and
/// each test's role.
pub(super) fn split(
    data: &[Measurement],
    opts: &DiagnoseOptions,
    campaign: &mut Campaign,
) -> (Vec<Window>, Vec<Window>) {
    let mut order: Vec<usize> = (0..data.len()).collect();
    order.sort_by(|&a, &b| data[a].amplitude_m().total_cmp(&data[b].amplitude_m()));
    if !campaign.one_amp && data.len() >= 2 {
        let train: Vec<usize> = order.iter().step_by(2).copied().collect();
        let held: Vec<usize> = order.iter().skip(1).step_by(2).copied().collect();
        let fit_w = train
            .iter()
            .map(|&i| Window {
                to: data[i]
                    .cycle_start(opts.fit_cycles as f64)
                    .min(data[i].time_s.len()),
                ..full(data, i)
            })
            .collect();
        let held_w = held.iter().map(|&i| full(data, i)).collect();
        campaign.method = format!(
            "held-out tests: fit on {} test(s) (alternate amplitudes, cycles 2-{} each), validated on {} other test(s) at amplitudes in between",
            train.len(),
            opts.fit_cycles,
            held.len()
        );
        campaign.roles = (0..data.len())
            .map(|i| if held.contains(&i) { "held-out" } else { "fit" }.to_string())
            .collect();
        return (fit_w, held_w);
    }
    // One amplitude: fit on the first cycles of every test, validate on the later ones.
    let mut fw = Vec::new();
    let mut hw = Vec::new();
    for (i, m) in data.iter().enumerate() {
        let cyc = m.cycles().floor();
        let split = (opts.fit_cycles as f64)
            .min((1.0 + cyc) / 2.0)
            .max(2.0)
            .min(cyc);
        let s = m.cycle_start(split).min(m.time_s.len());
        fw.push(Window {
            to: s,
            ..full(data, i)
        });
        if s + 8 < m.time_s.len() {
            hw.push(Window {
                test: i,
                from: s,
                to: m.time_s.len(),
            });
        }
    }
    if hw.is_empty() {
        campaign
            .limitations
            .push("too few cycles to hold any out: validation repeats the fit data".into());
        hw = fw.clone();
    }
    campaign.method = format!(
        "held-out cycles: {} test(s) at one amplitude; fit on the first cycles (from cycle 2), validated on the later cycles of the same test(s), which test repeatability, not extrapolation to other amplitudes",
        data.len()
    );
    campaign.roles = vec!["fit (early cycles) + held-out (late cycles)".to_string(); data.len()];
    (fw, hw)
}

/// What every later stage reads: the deck and data as compared, the split, the noise and the
/// scales of the fit.
pub(super) struct Ctx<'a> {
    pub(super) base: &'a DamperDeck,
    pub(super) data: &'a [Measurement],
    pub(super) opts: &'a DiagnoseOptions,
    pub(super) scales: Scales,
    /// Residual scale of the fits [N] (the peak force, at least 1).
    pub(super) scale: f64,
    /// Noise of the measured force [N].
    pub(super) sigma: f64,
    pub(super) fit_w: Vec<Window>,
    pub(super) held_w: Vec<Window>,
    /// Every test from its second cycle.
    pub(super) all_w: Vec<Window>,
    pub(super) n_fit: usize,
    /// Held-out RMS gain a cause must exceed [N] (noise level).
    pub(super) threshold: f64,
}

impl<'a> Ctx<'a> {
    /// Stage 3, the noise and scales of the split data.
    pub(super) fn new(
        base: &'a DamperDeck,
        data: &'a [Measurement],
        (fit_w, held_w): (Vec<Window>, Vec<Window>),
        opts: &'a DiagnoseOptions,
        campaign: &Campaign,
    ) -> Ctx<'a> {
        let sig2: f64 = data
            .iter()
            .map(|m| noise_sigma(&m.force_n).powi(2))
            .sum::<f64>()
            / data.len() as f64;
        let sigma = sig2.sqrt();
        let peak = data
            .iter()
            .map(Measurement::peak_force_n)
            .fold(0.0, f64::max);
        let scales = Scales {
            peak_force_n: peak,
            min_amplitude_m: data
                .iter()
                .map(Measurement::amplitude_m)
                .fold(f64::INFINITY, f64::min),
            oil_span_k: campaign.oil_span,
            oil_reference_unknown: campaign.oil_reference_unknown,
            oil_drift: campaign.oil_drift,
        };
        let n_held = measured_samples(&held_w, data);
        Ctx {
            base,
            data,
            opts,
            scales,
            scale: peak.max(1.0),
            sigma,
            n_fit: measured_samples(&fit_w, data),
            fit_w,
            held_w,
            all_w: (0..data.len()).map(|i| full(data, i)).collect(),
            threshold: 0.05 * sigma + 3.0 * sigma / (2.0 * n_held.max(1) as f64).sqrt(),
        }
    }

    /// Full replays of every test with `deck`.
    pub(super) fn sim_all(&self, deck: &DamperDeck) -> Result<Vec<Vec<f64>>, DiagnoseError> {
        self.data
            .iter()
            .map(|m| {
                let mut out = Vec::with_capacity(m.time_s.len());
                simulate(deck, m, m.time_s.len(), self.opts.max_substep_s, &mut out).map_err(
                    |source| DiagnoseError::Model {
                        test: m.name.clone(),
                        source,
                    },
                )?;
                Ok(out)
            })
            .collect()
    }
}

/// The base deck's replays and its marks on the split.
pub(super) struct Baseline {
    pub(super) sim: Vec<Vec<f64>>,
    /// RMS over every test [N].
    pub(super) rms: f64,
    /// RMS over the held-out windows [N].
    pub(super) held: f64,
    pub(super) bic: f64,
}

/// Stage 4, the baseline: the base deck replayed on every test.
pub(super) fn baseline(cx: &Ctx) -> Result<Baseline, DiagnoseError> {
    let sim = cx.sim_all(cx.base)?;
    let rms = rms_over(&cx.all_w, &sim, cx.data);
    let held = rms_over(&cx.held_w, &sim, cx.data);
    let fit_rss = rms_over(&cx.fit_w, &sim, cx.data).powi(2) * cx.n_fit as f64;
    Ok(Baseline {
        bic: bic(fit_rss, cx.n_fit, 0),
        sim,
        rms,
        held,
    })
}
