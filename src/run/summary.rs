//! Per-model figures of a run: damper force statistics, relief-valve limit check, comparison
//! with the measured damper force (metrics of `crate::analysis::compare` on the measurement's
//! own azimuths) and a residual analysis; written as DIR/summary.json and DIR/<model>/last_rev.csv.
use super::{ModelOutcome, ModelRun, N_HARMONICS};
use crate::analysis::compare::{compare, Metrics, Periodic, PeriodicInterp};
use crate::analysis::harmonics::{harmonics, Harmonic};
use crate::flight::FlightRecord;
use crate::io::{csv_from_columns, OutDir};
use serde_json::{json, Value};

/// Statistics of a signal over the last revolution.
#[derive(Debug, Clone, Copy, serde::Serialize)]
pub struct Stats {
    pub min: f64,
    pub max: f64,
    pub mean: f64,
    pub peak_to_peak: f64,
    pub rms: f64,
}

impl Stats {
    pub fn of(v: &[f64]) -> Stats {
        let n = v.len().max(1) as f64;
        let min = v.iter().cloned().fold(f64::INFINITY, f64::min);
        let max = v.iter().cloned().fold(f64::NEG_INFINITY, f64::max);
        let mean = v.iter().sum::<f64>() / n;
        let rms = (v.iter().map(|x| x * x).sum::<f64>() / n).sqrt();
        Stats {
            min,
            max,
            mean,
            peak_to_peak: max - min,
            rms,
        }
    }
}

/// Relief-valve limit check of a model with force limits.
#[derive(Debug, Clone, Copy, serde::Serialize)]
pub struct LimitCheck {
    pub min_limit_n: f64,
    pub max_limit_n: f64,
    /// min and max force stay within [min_limit, max_limit].
    pub within: bool,
    /// Smallest distance to a limit [N]: min(max_limit - max, min - min_limit); negative when a
    /// limit is exceeded (by that much).
    pub margin_n: f64,
    /// `margin_n` relative to the larger limit magnitude.
    pub margin_rel: f64,
    /// Where the force is beyond a cracking force, is the relief valve of that side open at
    /// every such sample (valve 0 for positive, valve 1 for negative force; docs/formats.md)? Then the
    /// excess is the valve's own regulation (poppet spring and damping: the pressure rises as
    /// the valve opens, Eq. 5) and the valve is limiting the force. None without valve channels.
    pub excess_only_with_valve_open: Option<bool>,
    /// Eq. (5) account of the excess (valve positions and velocities and the valves'
    /// regulation known).
    pub regulation: Option<RegulationCheck>,
}

/// The force beyond a cracking force explained by the relief valve's own Eq. (5): off its seat
/// the valve adds `(A_k/A_front)(k x + c v + m a)` to the cracking force.
#[derive(Debug, Clone, Copy, serde::Serialize)]
pub struct RegulationCheck {
    /// At the sample of the largest excess beyond a cracking force: the excess [N] and its
    /// spring part `(A_k/A_front) k x` and poppet-damping part `(A_k/A_front) c v` [N].
    pub excess_n: f64,
    pub spring_n: f64,
    pub damping_n: f64,
    /// Largest |F - (cracking + spring + damping part)| over all samples beyond a cracking
    /// force [N]: what Eq. (5) without the poppet inertia leaves.
    pub unexplained_n: f64,
}

impl LimitCheck {
    /// Adds the valve-open test from the force and the valve displacement channels, and the
    /// valve velocities where there are any: a poppet on its seat (x = 0) that moves off it
    /// (v > 0) has cracked within the step, its pressure force is past the preload.
    pub fn with_valves(mut self, force: &[f64], x: [&[f64]; 2], v: Option<[&[f64]; 2]>) -> Self {
        let open = |k: usize, i: usize| x[k][i] > 0.0 || v.is_some_and(|v| v[k][i] > 0.0);
        let ok = force.iter().enumerate().all(|(i, &f)| {
            (f <= self.max_limit_n || open(0, i)) && (f >= self.min_limit_n || open(1, i))
        });
        self.excess_only_with_valve_open = Some(ok);
        self
    }
    /// Adds the Eq. (5) account of the force beyond the cracking forces: valve k's spring and
    /// damping parts at every sample beyond limit k (`reg`: the valves' regulation).
    pub fn with_regulation(
        mut self,
        force: &[f64],
        x: [&[f64]; 2],
        v: [&[f64]; 2],
        reg: &[crate::rotor::ReliefRegulation; 2],
    ) -> Self {
        let mut worst: Option<RegulationCheck> = None;
        let mut unexplained = 0.0f64;
        for (i, &f) in force.iter().enumerate() {
            // side k: excess beyond its cracking force, positive outward
            let (k, excess) = if f > self.max_limit_n {
                (0, f - self.max_limit_n)
            } else if f < self.min_limit_n {
                (1, self.min_limit_n - f)
            } else {
                continue;
            };
            let r = &reg[k];
            let spring = r.area_ratio * r.k_n_per_m * x[k][i];
            let damping = r.area_ratio * r.c_n_s_per_m * v[k][i];
            unexplained = unexplained.max((excess - spring - damping).abs());
            if worst.is_none_or(|w| excess > w.excess_n) {
                worst = Some(RegulationCheck {
                    excess_n: excess,
                    spring_n: spring,
                    damping_n: damping,
                    unexplained_n: 0.0,
                });
            }
        }
        self.regulation = worst.map(|w| RegulationCheck {
            unexplained_n: unexplained,
            ..w
        });
        self
    }

    /// Human statement of the check.
    pub fn statement(&self) -> String {
        if self.within {
            format!(
                "within (margin {:.0} N, {:.1}%)",
                self.margin_n,
                100.0 * self.margin_rel
            )
        } else if self.excess_only_with_valve_open == Some(true) {
            let eq5 = self.regulation.map_or(String::new(), |r| {
                format!(
                    "; Eq. (5) of the valve accounts for it: at the peak, poppet spring {:.0} N + poppet damping {:.0} N of the {:.0} N, at most {:.0} N left over any sample (poppet inertia)",
                    r.spring_n, r.damping_n, r.excess_n, r.unexplained_n
                )
            });
            format!(
                "limited by the relief valves: up to {:.0} N ({:.1}%) beyond the cracking force, only while the valve is open or lifting off its seat (its regulated pressure rise){eq5}",
                -self.margin_n,
                -100.0 * self.margin_rel
            )
        } else {
            format!(
                "EXCEEDED by {:.0} N ({:.1}%)",
                -self.margin_n,
                -100.0 * self.margin_rel
            )
        }
    }
}

pub fn limit_check(force: &Stats, limits: (f64, f64)) -> LimitCheck {
    let (lo, hi) = limits;
    let margin = (hi - force.max).min(force.min - lo);
    LimitCheck {
        min_limit_n: lo,
        max_limit_n: hi,
        within: force.min >= lo && force.max <= hi,
        margin_n: margin,
        margin_rel: margin / lo.abs().max(hi.abs()),
        excess_only_with_valve_open: None,
        regulation: None,
    }
}

/// The measured damper force: the record's revolutions averaged azimuth by azimuth.
#[derive(Debug, Clone)]
pub struct Measured {
    pub azimuth_deg: Vec<f64>,
    pub force_n: Vec<f64>,
    /// The record's averaged damper stroke, when it has one.
    pub stroke_m: Option<Vec<f64>>,
    pub revolutions: usize,
    pub synthetic: bool,
}

impl Measured {
    /// The record's averaged damper force, or a note why there is none (not an error: the run
    /// still runs, without metrics).
    pub fn from_record(record: &FlightRecord) -> Result<Measured, String> {
        if record.damper().is_empty() {
            return Err(
                "the flight record has no measured damper force: no comparison metrics".into(),
            );
        }
        let avg = record.damper_average().map_err(|e| {
            format!("the record's damper channel cannot be averaged over revolutions ({e}): no comparison metrics")
        })?;
        if avg.force_N.len() < 2 * N_HARMONICS + 1 {
            return Err(format!(
                "the record's damper channel has {} azimuths per revolution, fewer than the {} that harmonics 0-{N_HARMONICS}/rev need: no comparison metrics",
                avg.force_N.len(),
                2 * N_HARMONICS + 1
            ));
        }
        Ok(Measured {
            azimuth_deg: avg.azimuth_deg,
            force_n: avg.force_N,
            stroke_m: avg.stroke_m,
            revolutions: record.damper_revolutions().len(),
            synthetic: record.meta.synthetic,
        })
    }
}

/// One harmonic as amplitude and phase (`x = A cos(n psi - phase)`).
#[derive(Debug, Clone, Copy, serde::Serialize)]
pub struct AmplitudePhase {
    pub amplitude: f64,
    pub phase_deg: f64,
}

/// 1/rev dynamic stiffness of the damper in the rotor, `K* = -F1/d1` (complex 1/rev harmonics
/// of force and stroke): a spring `F = -k d` gives `K* = k`, a dashpot `F = -c d'` gives
/// `K* = i c Omega`. Storage `K' = Re K*`, loss `K'' = Im K*` [N/m].
#[derive(Debug, Clone, Copy, serde::Serialize)]
#[allow(non_snake_case)]
pub struct DynamicStiffness {
    pub magnitude_N_per_m: f64,
    pub phase_deg: f64,
    pub storage_N_per_m: f64,
    pub loss_N_per_m: f64,
}

impl DynamicStiffness {
    fn of(force: &Harmonic, stroke: &Harmonic) -> Self {
        // complex amplitude of A cos(psi - phi): A exp(-i phi)
        let mag = force.amplitude / stroke.amplitude;
        let ph = (stroke.phase_deg - force.phase_deg + 180.0).to_radians();
        let (s, c) = ph.sin_cos();
        let phase_deg = s.atan2(c).to_degrees();
        DynamicStiffness {
            magnitude_N_per_m: mag,
            phase_deg,
            storage_N_per_m: mag * c,
            loss_N_per_m: mag * s,
        }
    }
}

/// The model's damper stroke against the record's, and the damper's 1/rev dynamic stiffness in
/// the rotor (model and record): separates what the rotor (stroke) and what the damper (force for
/// that stroke) contribute to the force error.
#[derive(Debug, Clone, serde::Serialize)]
pub struct StrokeCheck {
    pub mean_model_m: f64,
    pub mean_measured_m: f64,
    pub rev1_model: AmplitudePhase,
    pub rev1_measured: AmplitudePhase,
    /// RMS of (model - measured) stroke at the measured azimuths [m].
    pub rms_error_m: f64,
    pub stiffness_1rev_model: DynamicStiffness,
    pub stiffness_1rev_measured: DynamicStiffness,
    pub statement: String,
}

/// Stroke comparison and 1/rev dynamic stiffness (model run vs the record's averages).
pub fn stroke_check(run: &ModelRun, meas: &Measured) -> anyhow::Result<Option<StrokeCheck>> {
    let (Some(ms), Some(d), Some(f)) = (
        meas.stroke_m.as_ref(),
        run.channel("damper_stroke_m"),
        run.channel("damper_force_N"),
    ) else {
        return Ok(None);
    };
    let on = |v: &[f64]| -> anyhow::Result<Vec<f64>> {
        let i = PeriodicInterp::new(Periodic::new(&run.azimuth_deg, v))?;
        Ok(meas.azimuth_deg.iter().map(|p| i.at(*p)).collect())
    };
    let (d_mod, f_mod) = (on(d)?, on(f)?);
    let az = &meas.azimuth_deg;
    let hd = harmonics(az, &d_mod, 1)?;
    let hdm = harmonics(az, ms, 1)?;
    let hf = harmonics(az, &f_mod, 1)?;
    let hfm = harmonics(az, &meas.force_n, 1)?;
    let ap = |h: &Harmonic| AmplitudePhase {
        amplitude: h.amplitude,
        phase_deg: h.phase_deg,
    };
    let rms = (d_mod
        .iter()
        .zip(ms)
        .map(|(a, b)| (a - b).powi(2))
        .sum::<f64>()
        / ms.len() as f64)
        .sqrt();
    let (km, kr) = (
        DynamicStiffness::of(&hf[1], &hd[1]),
        DynamicStiffness::of(&hfm[1], &hdm[1]),
    );
    let mut dphi = hd[1].phase_deg - hdm[1].phase_deg;
    dphi -= 360.0 * (dphi / 360.0).round();
    let statement = format!(
        "stroke: mean {:.2} mm (record {:.2}), 1/rev {:.3} mm ({:+.1}% of the record's {:.3} mm), {:.1} deg {} the record's; damper 1/rev dynamic stiffness in the rotor: storage {:.3e} N/m (record {:.3e}), loss {:.3e} N/m (record {:.3e})",
        1e3 * hd[0].cos,
        1e3 * hdm[0].cos,
        1e3 * hd[1].amplitude,
        100.0 * (hd[1].amplitude / hdm[1].amplitude - 1.0),
        1e3 * hdm[1].amplitude,
        dphi.abs(),
        if dphi > 0.0 { "later than" } else { "earlier than" },
        km.storage_N_per_m,
        kr.storage_N_per_m,
        km.loss_N_per_m,
        kr.loss_N_per_m,
    );
    Ok(Some(StrokeCheck {
        mean_model_m: hd[0].cos,
        mean_measured_m: hdm[0].cos,
        rev1_model: ap(&hd[1]),
        rev1_measured: ap(&hdm[1]),
        rms_error_m: rms,
        stiffness_1rev_model: km,
        stiffness_1rev_measured: kr,
        statement,
    }))
}

/// What the residual (model - measured, on the measured azimuths) shows.
#[derive(Debug, Clone, serde::Serialize)]
pub struct Residual {
    /// Harmonics 0..=10/rev of the residual.
    pub harmonics: Vec<Harmonic>,
    /// The three largest residual harmonics (n, amplitude [N]).
    pub dominant: Vec<(usize, f64)>,
    /// Peak asymmetry max / |min| of the force: measured and model.
    pub asymmetry_measured: f64,
    pub asymmetry_model: f64,
    /// Fraction of the revolution with |F| below 5% of the peak |F|: measured and model.
    pub dwell_measured: f64,
    pub dwell_model: f64,
    /// Azimuth shift s [deg] of the model, model(psi - s), that minimizes the RMS error
    /// (searched in [-45, 45] deg, 0.1 deg steps); s > 0: the measurement lags the model.
    pub best_shift_deg: f64,
    /// RMS error at the best shift [N].
    pub rms_at_best_shift_n: f64,
}

/// Fraction of samples with |F| below 5% of the peak |F|.
fn dwell(v: &[f64]) -> f64 {
    let peak = v.iter().fold(0.0f64, |m, x| m.max(x.abs()));
    if peak == 0.0 {
        return 1.0;
    }
    v.iter().filter(|x| x.abs() < 0.05 * peak).count() as f64 / v.len() as f64
}

fn asymmetry(v: &[f64]) -> f64 {
    let max = v.iter().cloned().fold(f64::NEG_INFINITY, f64::max);
    let min = v.iter().cloned().fold(f64::INFINITY, f64::min);
    max / min.abs()
}

/// Residual analysis of `model` (one revolution) against `meas`.
pub fn residual(model: Periodic<'_>, meas: Periodic<'_>) -> anyhow::Result<Residual> {
    let interp = PeriodicInterp::new(model)?;
    let on_meas: Vec<f64> = meas.psi_deg.iter().map(|p| interp.at(*p)).collect();
    let r: Vec<f64> = on_meas.iter().zip(meas.value).map(|(a, b)| a - b).collect();
    let h = harmonics(meas.psi_deg, &r, N_HARMONICS)?;
    let mut dom: Vec<(usize, f64)> = h.iter().map(|h| (h.n, h.amplitude)).collect();
    dom.sort_by(|a, b| b.1.total_cmp(&a.1));
    dom.truncate(3);
    let rms_shift = |s: f64| {
        let se: f64 = meas
            .psi_deg
            .iter()
            .zip(meas.value)
            .map(|(p, y)| (interp.at(p - s) - y).powi(2))
            .sum();
        (se / meas.value.len() as f64).sqrt()
    };
    let (mut best_s, mut best) = (0.0, rms_shift(0.0));
    for k in -450..=450 {
        let s = k as f64 * 0.1;
        let e = rms_shift(s);
        if e < best {
            best = e;
            best_s = s;
        }
    }
    Ok(Residual {
        harmonics: h,
        dominant: dom,
        asymmetry_measured: asymmetry(meas.value),
        asymmetry_model: asymmetry(&on_meas),
        dwell_measured: dwell(meas.value),
        dwell_model: dwell(&on_meas),
        best_shift_deg: best_s,
        rms_at_best_shift_n: best,
    })
}

/// Everything computed for one successful model.
#[derive(Debug, Clone)]
pub struct ModelFigures {
    pub force: Stats,
    pub limits: Option<LimitCheck>,
    pub metrics: Option<Metrics>,
    pub residual: Option<Residual>,
    /// When the record has a stroke: the model's stroke against it.
    pub stroke: Option<StrokeCheck>,
}

pub fn figures(run: &ModelRun, measured: Option<&Measured>) -> anyhow::Result<ModelFigures> {
    let f = run
        .channel("damper_force_N")
        .ok_or_else(|| anyhow::anyhow!("{}: no damper_force_N channel", run.label))?;
    let force = Stats::of(f);
    let limits = run.force_limits_n.map(|l| {
        let c = limit_check(&force, l);
        let v = match (run.channel("v_valve0_m_s"), run.channel("v_valve1_m_s")) {
            (Some(v0), Some(v1)) => Some([v0, v1]),
            _ => None,
        };
        match (run.channel("x_valve0_m"), run.channel("x_valve1_m")) {
            (Some(x0), Some(x1)) => {
                let c = c.with_valves(f, [x0, x1], v);
                match (v, &run.relief_regulation) {
                    (Some(v), Some(reg)) => c.with_regulation(f, [x0, x1], v, reg),
                    _ => c,
                }
            }
            _ => c,
        }
    });
    let stroke = match measured {
        Some(m) => stroke_check(run, m)?,
        None => None,
    };
    let (metrics, residual) = match measured {
        Some(m) => {
            let model = Periodic::new(&run.azimuth_deg, f);
            let meas = Periodic::new(&m.azimuth_deg, &m.force_n);
            (
                Some(compare(model, meas, N_HARMONICS)?),
                Some(residual(model, meas)?),
            )
        }
        None => (None, None),
    };
    Ok(ModelFigures {
        force,
        limits,
        metrics,
        residual,
        stroke,
    })
}

/// A model reproduces the measured force when its correlation with it is at least this (it
/// follows at least half the measurement's variance, r^2 >= 0.49) and its RMS error is below
/// the measurement's RMS about its mean (it does better than the mean alone). Below either, a
/// smallest RMS error ranks wrong shapes, and no model is named the closest.
pub const REPRODUCES_CORRELATION: f64 = 0.7;

/// The model that comes closest (smallest RMS error) and how it ranks against the others.
#[derive(Debug, Clone, serde::Serialize)]
pub struct Ranking {
    /// (model, RMS error [N], correlation), best first.
    pub order: Vec<(String, f64, f64)>,
    /// Whether the first reproduces the measurement ([`REPRODUCES_CORRELATION`]); when not,
    /// no model is named the closest.
    pub reproduces: bool,
    pub statement: String,
}

/// Whether `m` reproduces the measurement ([`REPRODUCES_CORRELATION`]).
pub fn reproduces(m: &Metrics) -> bool {
    m.correlation >= REPRODUCES_CORRELATION && m.rms_error_rel < 1.0
}

pub fn ranking(items: &[(String, &Metrics)]) -> Option<Ranking> {
    let mut ranked: Vec<(String, f64, f64, bool)> = items
        .iter()
        .filter(|(_, m)| m.rms_error.is_finite())
        .map(|(n, m)| (n.clone(), m.rms_error, m.correlation, reproduces(m)))
        .collect();
    if ranked.is_empty() {
        return None;
    }
    ranked.sort_by(|a, b| a.1.total_cmp(&b.1));
    let reproduces = ranked[0].3;
    let order: Vec<(String, f64, f64)> = ranked.into_iter().map(|(n, e, c, _)| (n, e, c)).collect();
    let best = &order[0];
    let statement = if !reproduces {
        let top = order
            .iter()
            .max_by(|a, b| a.2.total_cmp(&b.2))
            .unwrap_or(best);
        format!(
            "no model reproduces the measured force (correlation at least {REPRODUCES_CORRELATION} and an RMS error below the measurement's own RMS): the best correlation is {:.3} ({} model); the smallest RMS error, {:.0} N, is the {} model's",
            top.2, top.0, best.1, best.0
        )
    } else if order.len() == 1 {
        format!(
            "only the {} model was compared: RMS error {:.0} N, correlation {:.3}",
            best.0, best.1, best.2
        )
    } else {
        let next = &order[1];
        format!(
            "the {} model comes closest: RMS error {:.0} N against {:.0} N for the {} model ({:.0}% lower), correlation {:.3} against {:.3}",
            best.0,
            best.1,
            next.1,
            next.0,
            100.0 * (1.0 - best.1 / next.1),
            best.2,
            next.2
        )
    };
    Some(Ranking {
        order,
        reproduces,
        statement,
    })
}

/// Run-level facts written into summary.json.
#[derive(Debug, Clone)]
pub struct RunInfo {
    pub rotor: String,
    pub rotor_model: String,
    pub flight: String,
    pub damper_deck: String,
    pub revs: usize,
    pub steps_per_rev: usize,
    pub substeps: usize,
    pub scheme: String,
    /// Newton method of the structural step ("full" or "modified").
    pub newton: String,
    /// Periodic solver ("shooting" or "march") and its tolerance; `revs` is its budget.
    pub periodic: String,
    pub periodic_tol: f64,
    /// Saved state the models started from (`--initial-state`).
    pub initial_state: Option<String>,
    /// Deck values overridden (`--set KEY=VALUE`), in the order given: (key, TOML value).
    pub overrides: Vec<(String, String)>,
    /// Fingerprint of the inputs that define the model ([`crate::io::inputs_fingerprint`]),
    /// saved with each periodic state.
    pub inputs_sha256: Option<String>,
    pub synthetic: bool,
    pub counter: Option<String>,
    pub wall_s: f64,
    /// A whole-rotor run: its blades, and where they differ (`blades.K.<deck path> = value`).
    pub blades: Option<usize>,
    pub blade_differences: Vec<String>,
    /// A rotor on an airframe: each moving direction described in words (empty without one).
    pub airframe: Vec<String>,
    /// The oil temperature the damper ran at [K] (None: the deck has no oil law).
    pub damper_oil_temperature_k: Option<f64>,
}

/// summary.json as a JSON value.
pub fn summary_json(
    info: &RunInfo,
    outcomes: &[ModelOutcome],
    figs: &[Option<Result<ModelFigures, String>>],
    measured: &Result<Measured, String>,
    rank: Option<&Ranking>,
) -> Value {
    let mut models = serde_json::Map::new();
    for (o, f) in outcomes.iter().zip(figs) {
        let v = match (&o.result, f) {
            (Err(e), _) => json!({"status": "failed", "error": e}),
            (Ok(r), Some(Err(e))) => json!({"status": "failed", "label": r.label, "error": e}),
            (Ok(r), Some(Ok(f))) => model_json(r, f, measured),
            (Ok(r), None) => json!({"status": "failed", "label": r.label, "error": "no figures"}),
        };
        models.insert(o.model.name().to_string(), v);
    }
    let meas = match measured {
        Ok(m) => json!({
            "available": true,
            "source": "record damper channel, revolutions averaged azimuth by azimuth",
            "revolutions_averaged": m.revolutions,
            "samples_per_revolution": m.azimuth_deg.len(),
            "synthetic": m.synthetic,
        }),
        Err(note) => json!({"available": false, "note": note}),
    };
    json!({
        "rotorsim_version": env!("CARGO_PKG_VERSION"),
        "rotor": info.rotor,
        "rotor_model": info.rotor_model,
        "flight_record": info.flight,
        "synthetic": info.synthetic,
        "record_counter": info.counter,
        "damper_deck": info.damper_deck,
        "damper_oil_temperature_K": info.damper_oil_temperature_k,
        "options": {
            "revs": info.revs,
            "steps_per_rev": info.steps_per_rev,
            "substeps": info.substeps,
            "scheme": info.scheme,
            "newton": info.newton,
            "periodic": info.periodic,
            "periodic_tol": info.periodic_tol,
            "max_revs": info.revs,
            "initial_state": info.initial_state,
            "overrides": info.overrides.iter().map(|(k, v)| json!({"key": k, "value": v})).collect::<Vec<_>>(),
            "periodicity_tolerance": info.periodic_tol,
            "harmonics_max_per_rev": N_HARMONICS,
            "all_blades": info.blades,
            "blade_differences": info.blade_differences,
        },
        "wall_time_s": info.wall_s,
        "measured": meas,
        "closest": rank.map(|r| json!({"model": r.order[0].0, "reproduces": r.reproduces, "statement": r.statement, "order": r.order})),
        "models": models,
    })
}

fn model_json(r: &ModelRun, f: &ModelFigures, measured: &Result<Measured, String>) -> Value {
    let t = r.timing;
    let steps = t.steps.max(1) as f64;
    let last = r.last_measure();
    let converged = r.converged();
    let limits = match (&f.limits, r.force_limits_n) {
        (Some(c), _) => serde_json::to_value(c).unwrap_or(Value::Null),
        _ => json!({"applies": false, "note": "this model has no force limits"}),
    };
    let metrics = match (&f.metrics, measured) {
        (Some(m), _) => with_unit(serde_json::to_value(m).unwrap_or(Value::Null), "N"),
        (None, Err(note)) => json!({"note": note}),
        (None, Ok(_)) => Value::Null,
    };
    json!({
        "status": "ok",
        "label": r.label,
        "revolutions": r.revolutions,
        "steps_per_rev": r.steps_per_rev,
        "period_s": r.period_s,
        "periodicity": {
            "channels": r.periodic.monitored.iter().map(|c| c.0.as_str()).collect::<Vec<_>>(),
            "floors": r.periodic.monitored.iter().map(|c| c.1).collect::<Vec<_>>(),
            "last_by_channel": r.periodic.residual_by_channel,
            "history": r.measure_history(),
            "last": last,
            "tolerance": r.periodic.tolerance,
            "converged": converged,
            "statement": periodicity_statement(r),
        },
        "periodic": periodic_json(r),
        "loads": super::loads::loads_json(r),
        "damper_force_N": f.force,
        "relief_valve_limits": limits,
        "wall_time_s": {
            "total": r.wall_s,
            "build": r.build_s,
            "steps": t.total_s,
            "structure": t.total_s - t.hydraulics_s,
            "hydraulics": t.hydraulics_s,
        },
        "steps": t.steps,
        "newton_iterations": t.iterations,
        "newton": {
            "iterations": t.iterations,
            "iterations_per_step": t.iterations as f64 / steps,
            "factorizations": t.factorizations,
            "factorizations_per_step": t.factorizations as f64 / steps,
            "relaxed_steps": t.relaxed_steps,
        },
        "cost_per_step_s": t.total_s / steps,
        "metrics": metrics,
        "residual": with_unit(serde_json::to_value(&f.residual).unwrap_or(Value::Null), "N"),
        "stroke_check": with_unit(serde_json::to_value(&f.stroke).unwrap_or(Value::Null), "m"),
        "channels": r.channel_names,
        "blades": blades_json(r),
        "airframe": airframe_json(r),
        "airloads": airloads_json(r),
    })
}

/// A rotor on an airframe: per moving direction its motion (mean, half peak-to-peak,
/// harmonics) and the momentum check of its equation of motion (null without an airframe).
/// The lifting line's source, inflow, aerofoils and table clamps, with the rotor's thrust
/// coefficient over solidity and power over the revolution beside the record's.
fn airloads_json(r: &ModelRun) -> Value {
    let Some(a) = &r.airloads else {
        return Value::Null;
    };
    let mean = |c: &str| {
        r.channel(c)
            .map(|v| v.iter().sum::<f64>() / v.len().max(1) as f64)
    };
    json!({
        "source": a.source,
        "hybrid_reference": a.reference,
        "inflow": a.inflow,
        "airfoils": a.airfoils,
        "clamped_queries": a.clamped_queries,
        "table_queries": a.table_queries,
        "clamps": a.clamps,
        "thrust_N_mean": mean("rotor_thrust_N"),
        "power_W_mean": mean("rotor_power_W"),
        "CT_over_sigma_mean": mean("rotor_CT_over_sigma"),
        "record_CT_over_sigma": a.record_ct_over_sigma,
        "record_synthetic": a.record_synthetic,
    })
}

fn airframe_json(r: &ModelRun) -> Value {
    let Some(check) = &r.airframe_check else {
        return Value::Null;
    };
    let channels = super::loads::channels_json(r, |c| c.starts_with("airframe_"));
    let balance: Vec<Value> = check
        .directions
        .iter()
        .map(|d| {
            let unit = if matches!(d.direction.as_str(), "roll" | "pitch") {
                "Nm"
            } else {
                "N"
            };
            json!({
                "direction": d.direction,
                format!("max_imbalance_{unit}"): d.max_imbalance,
                format!("max_hub_load_{unit}"): d.max_hub_load,
                "relative": d.max_imbalance / d.max_hub_load.max(f64::MIN_POSITIVE),
                "max_over_step_tolerance": d.max_over_step_tolerance,
            })
        })
        .collect();
    json!({"channels": channels, "momentum_check": balance})
}

/// A whole-rotor run's damper force blade by blade, in words: one line per blade (peak-to-peak
/// and mean), the blades whose force differs from blade 1's by more than 1% of its
/// peak-to-peak marked; empty for a single-blade run.
pub fn blade_force_lines(r: &ModelRun) -> Vec<String> {
    let stats: Vec<(usize, Stats)> = r
        .blade_runs
        .iter()
        .filter_map(|b| Some((b.blade?, Stats::of(b.channel("damper_force_N")?))))
        .collect();
    let Some((_, first)) = stats.first() else {
        return vec![];
    };
    let tol = 0.01 * first.peak_to_peak;
    stats
        .iter()
        .map(|(k, st)| {
            let differs = (st.peak_to_peak - first.peak_to_peak).abs() > tol
                || (st.mean - first.mean).abs() > tol;
            format!(
                "blade {k}: damper force {:.2} kN peak-to-peak, mean {:+.2} kN{}",
                st.peak_to_peak * 1e-3,
                st.mean * 1e-3,
                if *k == 1 {
                    " (the record's damper)"
                } else if differs {
                    " (differs from blade 1)"
                } else {
                    ""
                }
            )
        })
        .collect()
}

/// A whole-rotor run's blades: per blade its place, folder, periodicity, damper force and
/// loads (null for a single-blade run).
fn blades_json(r: &ModelRun) -> Value {
    if r.blade_runs.is_empty() {
        return Value::Null;
    }
    let n = r.blade_runs.len();
    let blades: Vec<Value> = r
        .blade_runs
        .iter()
        .map(|b| {
            let k = b.blade.unwrap_or(0);
            let force = figures(b, None).map(|f| f.force).ok();
            json!({
                "blade": k,
                "azimuth_ahead_of_blade_1_deg": super::rotor::blade_azimuth_deg(k, n),
                "folder": b.folder(),
                "revolutions": b.revolutions,
                "periodic": periodic_json(b),
                "damper_force_N": force,
                "loads": super::loads::loads_json(b),
            })
        })
        .collect();
    json!(blades)
}

/// Members of a metrics-like object in `unit`, suffixed with it (summary.json's rule: every
/// dimensional value's key ends with its unit; `rms_at_best_shift_n` becomes
/// `rms_at_best_shift_N`); harmonic lists get `amplitude_<unit>`, `cos_<unit>`, `sin_<unit>`.
/// Already suffixed keys and dimensionless ones (ratios, correlation, counts, phases in deg)
/// are left alone.
pub fn with_unit(v: Value, unit: &str) -> Value {
    const DIMENSIONAL: [&str; 11] = [
        "rms_error",
        "max_abs_error",
        "peak_to_peak_model",
        "peak_to_peak_measured",
        "peak_to_peak_error",
        "mean_model",
        "mean_measured",
        "amplitude",
        "cos",
        "sin",
        "rms_at_best_shift",
    ];
    match v {
        Value::Object(map) => Value::Object(
            map.into_iter()
                .map(|(k, v)| {
                    let base = k.strip_suffix("_n").unwrap_or(&k);
                    let k = if DIMENSIONAL.contains(&base) {
                        format!("{base}_{unit}")
                    } else {
                        k
                    };
                    (k, with_unit(v, unit))
                })
                .collect(),
        ),
        Value::Array(a) => Value::Array(a.into_iter().map(|x| with_unit(x, unit)).collect()),
        other => other,
    }
}

/// summary.json `periodic` of one model.
pub fn periodic_json(r: &ModelRun) -> Value {
    let p = &r.periodic;
    json!({
        "method": p.method_used.name(),
        "method_requested": p.method.name(),
        "converged": p.converged,
        "residual": p.residual,
        "residual_by_channel": p
            .monitored
            .iter()
            .map(|c| c.0.as_str())
            .zip(&p.residual_by_channel)
            .map(|(c, v)| (c.to_string(), json!(v)))
            .collect::<serde_json::Map<_, _>>(),
        "tolerance": p.tolerance,
        "residual_history": p.residual_history,
        "revolutions_integrated": p.revolutions_integrated,
        "marched_revolutions": p.marched_revolutions,
        "iterations": p.iterations,
        "directions": p.directions,
        "rejected_trials": p.rejected_trials,
        "floquet_directions": p.floquet_directions,
        "floquet_multipliers": p
            .floquet_multipliers
            .iter()
            .map(floquet_entry)
            .collect::<Vec<_>>(),
        "error_estimate": p.error_estimate,
        "message": p.message,
    })
}

/// One multiplier of summary.json: its fields, `resolved` (its residual at most 1% of
/// |mu|: only then are its values to be used) and `shown` (the value as the report shows it,
/// or that the mode is not resolved, with its residual).
fn floquet_entry(m: &crate::periodic::Multiplier) -> serde_json::Value {
    let mut v = json!(m);
    v["resolved"] = json!(m.reliable);
    v["shown"] = json!(if m.reliable {
        format!("|mu| {:.4}", m.magnitude)
    } else {
        super::report::unresolved_text(m)
    });
    v
}

/// Plain statement of the periodicity of the reported revolution.
pub fn periodicity_statement(r: &ModelRun) -> String {
    let p = &r.periodic;
    if p.residual.is_nan() {
        return "periodicity not measured (NaN residual)".into();
    }
    let how = match p.method_used {
        super::PeriodicMethod::Shooting => format!(
            "shooting, {} Newton-Picard iterations, {} revolutions integrated",
            p.iterations, p.revolutions_integrated
        ),
        super::PeriodicMethod::March => {
            format!("marching, {} revolutions", p.revolutions_integrated)
        }
    };
    if p.converged {
        format!(
            "periodic: residual {:.2e} (< {:.0e}) by {how}",
            p.residual, p.tolerance
        )
    } else {
        let iw = p
            .residual_by_channel
            .iter()
            .enumerate()
            .max_by(|a, b| a.1.total_cmp(b.1))
            .map_or(0, |(i, _)| i);
        format!(
            "NOT periodic: residual {:.2e} above the {:.0e} tolerance (largest: {} {:.2e}) after {how}{}; run more revolutions (--revs) or check the transient damping of the rotor deck",
            p.residual,
            p.tolerance,
            p.monitored.get(iw).map_or("", |c| c.0.as_str()),
            p.residual_by_channel.get(iw).copied().unwrap_or(f64::NAN),
            if p.message.is_empty() { String::new() } else { format!(" ({})", p.message) }
        )
    }
}

/// DIR/<model>/periodic_state.json (when the simulation can save its state).
pub fn write_periodic_state(out: &OutDir, r: &ModelRun, info: &RunInfo) -> anyhow::Result<()> {
    let Some(state) = &r.periodic_state else {
        return Ok(());
    };
    let f = super::PeriodicStateFile {
        format: super::periodic::STATE_FORMAT.into(),
        model: r.model.clone(),
        label: r.label.clone(),
        steps_per_rev: r.steps_per_rev,
        period_s: r.period_s,
        converged: r.periodic.converged,
        residual: r.periodic.residual,
        inputs_sha256: info.inputs_sha256.clone(),
        overrides: info.overrides.clone(),
        state: state.clone(),
    };
    out.write(
        &format!("{}/periodic_state.json", r.folder()),
        serde_json::to_string(&f)?.as_bytes(),
    )?;
    Ok(())
}

/// DIR/<model>/last_rev.csv: time_s, azimuth_deg (k 360/N exactly), the record's measured
/// damper force and stroke on those azimuths where it has them, then every channel (units in
/// the names).
pub fn write_last_rev(
    out: &OutDir,
    r: &ModelRun,
    measured: Option<&Measured>,
) -> anyhow::Result<()> {
    let on_model = |m: &Measured, values: &[f64]| -> Vec<f64> {
        periodic_resample(&m.azimuth_deg, values, &r.azimuth_deg)
    };
    let force = measured.map(|m| on_model(m, &m.force_n));
    let stroke = measured.and_then(|m| m.stroke_m.as_deref().map(|d| on_model(m, d)));
    let mut header: Vec<&str> = vec!["time_s", "azimuth_deg"];
    let mut cols: Vec<&[f64]> = vec![&r.time_s, &r.azimuth_deg];
    if let Some(f) = &force {
        header.push("measured_damper_force_N");
        cols.push(f);
    }
    if let Some(d) = &stroke {
        header.push("measured_damper_stroke_m");
        cols.push(d);
    }
    header.extend(r.channel_names.iter().map(|s| s.as_str()));
    cols.extend(r.last_rev.iter().map(|c| c.as_slice()));
    out.write(
        &format!("{}/last_rev.csv", r.folder()),
        csv_from_columns(&header, &cols).as_bytes(),
    )?;
    Ok(())
}

/// DIR/<model>/all_revs.csv: every revolution kept along the way (`--write-all-revs`), one
/// row per sample: revolution (1, 2, ... in the order integrated), shooting_iterate (0 for a
/// marched revolution, k for the k-th accepted shooting iterate), time_s, azimuth_deg, then
/// every channel.
pub fn write_all_revs(out: &OutDir, r: &ModelRun) -> anyhow::Result<()> {
    let n = r.azimuth_deg.len();
    let rows = r.all_revs.len() * n;
    let mut rev = Vec::with_capacity(rows);
    let mut iterate = Vec::with_capacity(rows);
    let mut time = Vec::with_capacity(rows);
    let mut azimuth = Vec::with_capacity(rows);
    let mut channels = vec![Vec::with_capacity(rows); r.channel_names.len()];
    let dt = r.period_s / n as f64;
    for (k, kr) in r.all_revs.iter().enumerate() {
        for j in 0..n {
            rev.push((k + 1) as f64);
            iterate.push(kr.shooting_iterate as f64);
            time.push(kr.start_t_s + j as f64 * dt);
            azimuth.push(r.azimuth_deg[j]);
            for (c, col) in channels.iter_mut().enumerate() {
                col.push(kr.samples[c][j]);
            }
        }
    }
    let mut header: Vec<&str> = vec!["revolution", "shooting_iterate", "time_s", "azimuth_deg"];
    header.extend(r.channel_names.iter().map(|s| s.as_str()));
    let mut cols: Vec<&[f64]> = vec![&rev, &iterate, &time, &azimuth];
    cols.extend(channels.iter().map(|c| c.as_slice()));
    out.write(
        &format!("{}/all_revs.csv", r.folder()),
        csv_from_columns(&header, &cols).as_bytes(),
    )?;
    Ok(())
}

/// `values` on azimuths `from` (one revolution, increasing in [0, 360)) at azimuths `to`:
/// exact where an azimuth coincides (within 1e-9 deg), periodic linear interpolation between.
fn periodic_resample(from: &[f64], values: &[f64], to: &[f64]) -> Vec<f64> {
    let n = from.len();
    to.iter()
        .map(|&psi| {
            // first sample at or after psi
            let k = from.partition_point(|&a| a < psi - 1e-9);
            if k < n && (from[k] - psi).abs() <= 1e-9 {
                return values[k];
            }
            let (i0, i1) = if k == 0 || k == n {
                (n - 1, 0)
            } else {
                (k - 1, k)
            };
            let a0 = from[i0];
            let mut a1 = from[i1];
            if a1 <= a0 {
                a1 += 360.0;
            }
            let mut p = psi;
            if p < a0 {
                p += 360.0;
            }
            let w = (p - a0) / (a1 - a0);
            values[i0] + w * (values[i1] - values[i0])
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Metrics of `model(psi)` against a 1/rev measurement, on 72 azimuths.
    fn metrics_of(model: impl Fn(f64) -> f64) -> Metrics {
        use crate::analysis::compare::{compare, Periodic};
        let psi: Vec<f64> = (0..72).map(|k| k as f64 * 5.0).collect();
        let meas: Vec<f64> = psi.iter().map(|p| 1e3 * p.to_radians().sin()).collect();
        let m: Vec<f64> = psi.iter().map(|p| model(p.to_radians())).collect();
        let pm = Periodic {
            psi_deg: &psi,
            value: &m,
        };
        let pr = Periodic {
            psi_deg: &psi,
            value: &meas,
        };
        compare(pm, pr, 3).unwrap()
    }

    #[test]
    fn a_model_is_named_closest_only_when_it_reproduces_the_measurement() {
        // the right shape, 20% small: correlation 1, RMS error 0.2 of the measurement's
        let good = metrics_of(|p| 800.0 * p.sin());
        // the wrong shape (a 2/rev), however small its RMS error
        let wrong = metrics_of(|p| 100.0 * (2.0 * p).sin());
        let zero = metrics_of(|p| -200.0 * p.sin());
        let r = ranking(&[("a".into(), &wrong), ("b".into(), &good)]).unwrap();
        assert!(r.reproduces && r.order[0].0 == "b", "{r:?}");
        assert!(
            r.statement.starts_with("the b model comes closest"),
            "{}",
            r.statement
        );
        let r = ranking(&[("a".into(), &wrong), ("c".into(), &zero)]).unwrap();
        assert!(!r.reproduces, "{r:?}");
        assert!(
            r.statement
                .starts_with("no model reproduces the measured force"),
            "{}",
            r.statement
        );
        assert!(!r.statement.contains("comes closest"), "{}", r.statement);
    }

    #[test]
    fn measured_values_are_exact_on_shared_azimuths_and_periodic_linear_between() {
        let from: Vec<f64> = (0..8).map(|k| k as f64 * 45.0).collect();
        let values: Vec<f64> = (0..8).map(|k| k as f64).collect();
        let same = periodic_resample(&from, &values, &from);
        assert_eq!(same, values);
        let to = [22.5, 337.5, 350.0, 0.0, 10.0];
        let got = periodic_resample(&from, &values, &to);
        // between 315 deg (7) and 360 = 0 deg (0), linear; 10 deg between 0 and 45
        let want = [0.5, 3.5, 7.0 * (1.0 - 35.0 / 45.0), 0.0, 10.0 / 45.0];
        for (g, w) in got.iter().zip(want) {
            assert!((g - w).abs() < 1e-12, "{got:?} vs {want:?}");
        }
    }

    /// `K* = -F1/d1` on analytic laws, stroke `d = D cos(psi - 40 deg)`: a spring `F = -k d`
    /// gives `K* = k`; a dashpot `F = -c d'` (d' = -D Omega sin(psi - 40 deg)) gives `i c Omega`;
    /// their sum gives both parts.
    #[test]
    fn dynamic_stiffness_of_spring_and_dashpot() {
        let (dd, om, k, c) = (0.004, 27.0, 3.0e5, 1.2e5);
        let psi: Vec<f64> = (0..256).map(|i| i as f64 * 360.0 / 256.0).collect();
        let ph = 40f64.to_radians();
        let d: Vec<f64> = psi
            .iter()
            .map(|p| dd * (p.to_radians() - ph).cos())
            .collect();
        let v: Vec<f64> = psi
            .iter()
            .map(|p| -dd * om * (p.to_radians() - ph).sin())
            .collect();
        let hd = harmonics(&psi, &d, 1).unwrap();
        for (kk, cc) in [(k, 0.0), (0.0, c), (k, c)] {
            let f: Vec<f64> = d.iter().zip(&v).map(|(d, v)| -kk * d - cc * v).collect();
            let hf = harmonics(&psi, &f, 1).unwrap();
            let s = DynamicStiffness::of(&hf[1], &hd[1]);
            assert!((s.storage_N_per_m - kk).abs() < 1e-6 * k, "{s:?}");
            assert!((s.loss_N_per_m - cc * om).abs() < 1e-6 * k, "{s:?}");
            let mag = (kk * kk + (cc * om).powi(2)).sqrt();
            assert!((s.magnitude_N_per_m - mag).abs() < 1e-6 * mag);
        }
    }

    #[test]
    fn stats_of_a_sine() {
        let v: Vec<f64> = (0..360)
            .map(|i| 2.0 * (i as f64).to_radians().sin() + 1.0)
            .collect();
        let s = Stats::of(&v);
        assert!((s.mean - 1.0).abs() < 1e-12);
        assert!((s.peak_to_peak - 4.0).abs() < 1e-12);
        assert!((s.rms - 3.0f64.sqrt()).abs() < 1e-12); // sqrt(1 + 4/2)
    }

    #[test]
    fn limit_margin_sign() {
        let s = Stats::of(&[-90.0, 110.0]);
        let c = limit_check(&s, (-100.0, 100.0));
        assert!(!c.within);
        assert_eq!(c.margin_n, -10.0);
        let c = limit_check(&Stats::of(&[-90.0, 95.0]), (-100.0, 100.0));
        assert!(c.within);
        assert_eq!(c.margin_n, 5.0);
    }

    /// Forces built from Eq. (5), `F = F_crack + (A/A_front)(k x + c v)`, plus 5 N at one sample:
    /// the parts at the peak are recovered and 5 N is left unexplained.
    #[test]
    fn regulation_splits_the_excess_into_spring_and_poppet_damping() {
        let reg = crate::rotor::ReliefRegulation {
            area_ratio: 80.0,
            k_n_per_m: 2.0e4,
            c_n_s_per_m: 200.0,
            preload_pressure_pa: 8.9e6,
            back_area_ratio: 1.0,
        };
        let x = [0.0, 2.0e-5, 1.0e-5];
        let v = [0.0, 0.01, 0.002];
        let eq5 = |i: usize| 100.0 + 80.0 * (2.0e4 * x[i] + 200.0 * v[i]);
        let f = [50.0, eq5(1), eq5(2) + 5.0];
        let z = [0.0; 3];
        let c = limit_check(&Stats::of(&f), (-100.0, 100.0))
            .with_valves(&f, [&x, &z], Some([&v, &z]))
            .with_regulation(&f, [&x, &z], [&v, &z], &[reg, reg]);
        let r = c.regulation.unwrap();
        assert!((r.excess_n - (eq5(1) - 100.0)).abs() < 1e-9);
        assert!((r.spring_n - 80.0 * 2.0e4 * 2.0e-5).abs() < 1e-9); // 32 N
        assert!((r.damping_n - 80.0 * 200.0 * 0.01).abs() < 1e-9); // 160 N
        assert!((r.unexplained_n - 5.0).abs() < 1e-9);
        assert!(c
            .statement()
            .contains("poppet spring 32 N + poppet damping 160 N"));
    }

    #[test]
    fn excess_counts_as_limited_only_with_the_right_valve_open() {
        let f = [-90.0, 110.0, 50.0];
        let c = limit_check(&Stats::of(&f), (-100.0, 100.0));
        // valve 0 (positive force side) open at the excess sample
        let z = [0.0; 3];
        let open = c.with_valves(&f, [&[0.0, 1e-4, 0.0], &z], None);
        assert_eq!(open.excess_only_with_valve_open, Some(true));
        assert!(open
            .statement()
            .starts_with("limited by the relief valves: up to 10 N"));
        // only the wrong valve open: a real exceedance
        let wrong = c.with_valves(&f, [&z, &[0.0, 1e-4, 0.0]], None);
        assert_eq!(wrong.excess_only_with_valve_open, Some(false));
        assert!(wrong.statement().starts_with("EXCEEDED by 10 N"));
        // valve 0 on its seat but lifting off it (cracking within the step)
        let lifting = c.with_valves(&f, [&z, &z], Some([&[0.0, 3e-5, 0.0], &z]));
        assert_eq!(lifting.excess_only_with_valve_open, Some(true));
        // on its seat and not moving, or closing: an exceedance
        let seated = c.with_valves(&f, [&z, &z], Some([&[0.0, -3e-5, 0.0], &z]));
        assert_eq!(seated.excess_only_with_valve_open, Some(false));
    }

    #[test]
    fn residual_finds_a_known_shift_and_asymmetry() {
        let psi: Vec<f64> = (0..256).map(|i| i as f64 * 360.0 / 256.0).collect();
        let model: Vec<f64> = psi.iter().map(|p| p.to_radians().sin()).collect();
        // Measurement lags the model by 10 deg.
        let meas: Vec<f64> = psi.iter().map(|p| (p - 10.0).to_radians().sin()).collect();
        let r = residual(Periodic::new(&psi, &model), Periodic::new(&psi, &meas)).unwrap();
        assert!(
            (r.best_shift_deg - 10.0).abs() < 0.051,
            "{}",
            r.best_shift_deg
        );
        assert!(r.rms_at_best_shift_n < 1e-3);
        assert_eq!(r.dominant[0].0, 1);
        // |2 sin 5 deg| = 0.1743: residual 1/rev amplitude.
        assert!((r.harmonics[1].amplitude - 2.0 * 5f64.to_radians().sin()).abs() < 1e-9);
        assert!((r.asymmetry_measured - 1.0).abs() < 1e-3);
    }
}
