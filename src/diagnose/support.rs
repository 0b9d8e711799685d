//! The naming rule: a cause is named only where the data distinguish its effect from no effect.
//! Every fitted parameter of a candidate has a no-effect value (or band) at which the cause
//! does nothing (a gap of 0, a stiffness of infinity, a gain of 1, a lag within the timing
//! uncertainty); [`no_effect`] is the one table of them. A cause (one part of a name such as
//! `entrained_air+force_lag`) is supported when the 95% interval of at least one of its
//! parameters excludes that parameter's no-effect value: the effect vanishes only when every
//! parameter is at its own, so one parameter the data put away from it is enough. Parameters
//! with no no-effect value of their own (a presliding distance, the leakage's viscosity times
//! land length, a data sheet's temperature, the first relief valve's cracking force beside the
//! second's) do not count. An interval with an unbounded end toward the no-effect value does
//! not exclude it.
use super::acquisition::{Fault, CLIPPING, DROPOUTS};
use super::candidates::Cause;
use crate::hydraulics::DamperDeck;
use serde::Serialize;
use std::collections::BTreeMap;

/// Where a parameter has no effect.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum NoEffect {
    /// At this value.
    Value { value: f64 },
    /// At infinity (a stiffness: the rigid limit).
    Infinity,
    /// Anywhere in `[lo, hi]`: the lag's timing uncertainty, or the other relief valve's
    /// interval (the asymmetry vanishes where the two cracking forces can be equal).
    Band { lo: f64, hi: f64 },
}

impl NoEffect {
    /// Whether the 95% interval `[lo, hi]` excludes the no-effect value: lies wholly on one
    /// side of it (of the whole band). An unbounded end toward it (a lower end of 0 toward a
    /// value of 0, an infinite upper end toward infinity) or a NaN end does not exclude it.
    pub fn excluded_by(self, interval: [f64; 2]) -> bool {
        let [lo, hi] = interval;
        if lo.is_nan() || hi.is_nan() {
            return false;
        }
        match self {
            NoEffect::Value { value } => lo > value || hi < value,
            NoEffect::Infinity => hi.is_finite(),
            NoEffect::Band { lo: a, hi: b } => lo > b || hi < a,
        }
    }

    /// Short text: `0`, `infinity`, `[-2.65e-4, 2.65e-4]`.
    pub fn describe(self) -> String {
        match self {
            NoEffect::Value { value } => format!("{value:.4e}"),
            NoEffect::Infinity => "infinity".into(),
            NoEffect::Band { lo, hi } => format!("[{lo:.3e}, {hi:.3e}]"),
        }
    }
}

/// What the no-effect values depend on beyond the candidate's own fit: the base deck's values
/// (a re-calibration or an asymmetry has no effect where it gives the deck back) and the lag's
/// timing uncertainty.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct NoEffectContext {
    /// Piston area of chamber 0 of the base deck [m^2] (an area asymmetry vanishes at A1 = A0).
    pub a0_m2: f64,
    /// The base deck's orifice area `A_orf` [m^2].
    pub orifice_area_m2: Option<f64>,
    /// The base deck's relief-valve flow-area coefficient `a` [m] (the first valve's).
    pub relief_a_m: Option<f64>,
    /// The base deck's relief-valve cracking forces `F_p` [N].
    pub relief_f_p_n: [Option<f64>; 2],
    /// Half-width of the lag's timing uncertainty [s] ([`timing_uncertainty_s`]).
    pub lag_timing_s: f64,
}

/// The lag's timing uncertainty [s]: `h/2 + |e|`, h the tests' sample interval, e the replay's
/// own delay. Whoever recorded the data had a sampling convention the diagnosis cannot know (the
/// force sampled at the instant, averaged over the sample interval: a lag of half a sample, or
/// at a half-sample offset; a stroke sensor's filter delay), and the replay has its own timing
/// error: a lag within this band is not told apart from none.
pub fn timing_uncertainty_s(sample_interval_s: f64, replay_delay_s: f64) -> f64 {
    0.5 * sample_interval_s.abs() + replay_delay_s.abs()
}

impl NoEffectContext {
    /// From the base deck, the tests' sample interval `h` [s] and the replay's own delay [s].
    pub fn new(base: &DamperDeck, sample_interval_s: f64, replay_delay_s: f64) -> Self {
        let c = base.physical.as_ref();
        Self {
            a0_m2: c.map_or(f64::NAN, |c| c.chambers[0].area),
            orifice_area_m2: c.and_then(|c| c.orifice.map(|o| o.area)),
            relief_a_m: c.and_then(|c| c.relief[0].or(c.relief[1]).map(|r| r.a)),
            relief_f_p_n: c.map_or([None; 2], |c| [0, 1].map(|k| c.relief[k].map(|r| r.f_p))),
            lag_timing_s: timing_uncertainty_s(sample_interval_s, replay_delay_s),
        }
    }
}

/// How a parameter's no-effect value is found (the table of [`rule`]).
#[derive(Debug, Clone, Copy, PartialEq)]
enum Rule {
    Zero,
    One,
    Infinity,
    /// The base deck's chamber-0 area.
    DeckA0,
    /// The base deck's orifice area.
    DeckOrifice,
    /// The base deck's relief-valve `a`.
    DeckReliefA,
    /// Equal to the first relief valve's cracking force: its fitted interval, else the deck's.
    OtherValve,
    /// Within the timing uncertainty.
    LagBand,
    /// No no-effect value of its own (shapes the effect, does not switch it off).
    NoneOfItsOwn,
}

/// The one table: how `param` of the cause `part` has no effect; None when `part` has no such
/// parameter.
fn rule(part: &str, param: &str) -> Option<Rule> {
    use Rule::*;
    if let Some(f) = Fault::from_name(part) {
        if f.param() != param {
            return None;
        }
        return Some(match f {
            Fault::Lag => LagBand,
            Fault::Offset => Zero,
            Fault::Gain => One,
            Fault::Drift => Zero,
        });
    }
    let cause = Cause::CANDIDATES.into_iter().find(|c| c.name() == part)?;
    Some(match (cause, param) {
        (Cause::SealFriction, "F_c_N") => Zero,
        (Cause::SealFriction, "presliding_m") => NoneOfItsOwn,
        (Cause::FreePlay | Cause::CompliantFreePlay, "gap_m") => Zero,
        (Cause::CompliantFreePlay, "contact_stiffness_N_per_m") => Infinity,
        (Cause::EntrainedAir, "air_fraction") => Zero,
        (Cause::EntrainedAirByChamber, "air_fraction_0" | "air_fraction_1") => Zero,
        (Cause::AreaAsymmetry, "A1_m2") => DeckA0,
        (Cause::ReliefAsymmetry, "F_p0_N") => NoneOfItsOwn,
        (Cause::ReliefAsymmetry, "F_p1_N") => OtherValve,
        (Cause::PistonLeakage, "leakage_m3_per_s_Pa") => Zero,
        (Cause::PistonLeakage, "leakage_viscosity_length_Pa_s_m") => NoneOfItsOwn,
        (Cause::AccumulatorBleed, "accumulator_bleed_m3_per_s_Pa") => Zero,
        (Cause::MountCompliance, "mount_stiffness_N_per_m") => Infinity,
        (Cause::Recalibration, "A_orf_m2") => DeckOrifice,
        (Cause::Recalibration, "relief_a_m") => DeckReliefA,
        (
            Cause::OilTemperature,
            "density_thermal_coefficient_per_K" | "bulk_modulus_thermal_coefficient_per_K",
        ) => Zero,
        (Cause::OilTemperature, "oil_reference_temperature_K") => NoneOfItsOwn,
        (Cause::OilDrift, "oil_density_drop_fraction" | "oil_bulk_modulus_drop_fraction") => Zero,
        _ => return None,
    })
}

/// Whether `param` is a parameter of the cause `part` (a part of a candidate's name).
pub fn belongs_to(part: &str, param: &str) -> bool {
    rule(part, param).is_some()
}

/// Whether a part of a name is found by the data screen (clipping, dropouts): read from the
/// data, not fitted, so not subject to the rule.
fn screened(part: &str) -> bool {
    part == CLIPPING || part == DROPOUTS
}

/// The no-effect value of `param` of the cause `part` (docs/diagnosis.md, Method step 6):
/// lag within the timing uncertainty, offset 0, gain 1, drift 0, gap 0, friction force 0, air
/// fraction 0, leakage and bleed conductance 0, mount and contact stiffness infinite, the
/// re-calibrated orifice area and relief `a` the base deck's, A1 the base deck's A0, F_p1 equal
/// to F_p0 (the band of its fitted interval in `intervals`, else the deck's value), the oil's
/// thermal coefficients and drift fractions 0. None for a parameter with none of its own (or
/// not of that cause).
pub fn no_effect(
    part: &str,
    param: &str,
    cx: &NoEffectContext,
    intervals: &BTreeMap<String, [f64; 2]>,
) -> Option<NoEffect> {
    let value = |v: f64| Some(NoEffect::Value { value: v });
    match rule(part, param)? {
        Rule::Zero => value(0.0),
        Rule::One => value(1.0),
        Rule::Infinity => Some(NoEffect::Infinity),
        Rule::DeckA0 => value(cx.a0_m2),
        Rule::DeckOrifice => value(cx.orifice_area_m2?),
        Rule::DeckReliefA => value(cx.relief_a_m?),
        Rule::OtherValve => match intervals.get("F_p0_N") {
            Some(&[lo, hi]) => Some(NoEffect::Band { lo, hi }),
            None => value(cx.relief_f_p_n[0]?),
        },
        Rule::LagBand => Some(NoEffect::Band {
            lo: -cx.lag_timing_s,
            hi: cx.lag_timing_s,
        }),
        Rule::NoneOfItsOwn => None,
    }
}

/// The no-effect value of every parameter of a candidate named `name` (`a` or `a+b`) that has
/// one, keyed by parameter name.
pub fn no_effects(
    name: &str,
    parameters: &BTreeMap<String, f64>,
    intervals: &BTreeMap<String, [f64; 2]>,
    cx: &NoEffectContext,
) -> BTreeMap<String, NoEffect> {
    let mut out = BTreeMap::new();
    for part in name.split('+') {
        for p in parameters.keys() {
            if let Some(n) = no_effect(part, p, cx, intervals) {
                out.insert(p.clone(), n);
            }
        }
    }
    out
}

/// Whether one cause of a name is supported by the data.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct PartSupport {
    /// The cause (one part of a name such as `entrained_air+force_lag`).
    pub name: String,
    /// The 95% interval of at least one of its parameters excludes that parameter's
    /// no-effect value (screened faults: read from the data, always).
    pub supported: bool,
    /// Which interval excludes which no-effect value, or that none does.
    pub reason: String,
}

fn interval_text(p: &str, x: Option<f64>, iv: [f64; 2]) -> String {
    let x = x.map_or(String::new(), |x| format!(" {x:.4e}"));
    let end = |v: f64| {
        if v.is_finite() {
            format!("{v:.3e}")
        } else {
            "unbounded".into()
        }
    };
    format!("{p}{x} (95% {} to {})", end(iv[0]), end(iv[1]))
}

/// The rule applied to each cause of the name `name` (`a`, `a+b`, `a+fault`), each with its
/// own parameters' intervals and no-effect values (`no_effect` as from [`no_effects`]). `none`
/// gives no part.
pub fn support(
    name: &str,
    parameters: &BTreeMap<String, f64>,
    intervals: &BTreeMap<String, [f64; 2]>,
    no_effect: &BTreeMap<String, NoEffect>,
) -> Vec<PartSupport> {
    if name == "none" || name.is_empty() {
        return vec![];
    }
    name.split('+')
        .map(|part| {
            if screened(part) {
                return PartSupport {
                    name: part.into(),
                    supported: true,
                    reason: "read from the data by the screen, not fitted".into(),
                };
            }
            let mut within = Vec::new();
            for (p, _) in parameters.iter().filter(|(p, _)| belongs_to(part, p)) {
                let (Some(&ne), Some(&iv)) = (no_effect.get(p), intervals.get(p)) else {
                    continue;
                };
                let text = interval_text(p, parameters.get(p).copied(), iv);
                let what = if matches!(Fault::from_name(part), Some(Fault::Lag)) {
                    format!("the timing uncertainty {}", ne.describe())
                } else {
                    format!("its no-effect value {}", ne.describe())
                };
                if ne.excluded_by(iv) {
                    return PartSupport {
                        name: part.into(),
                        supported: true,
                        reason: format!("{text} excludes {what}"),
                    };
                }
                within.push(format!("{text} does not exclude {what}"));
            }
            PartSupport {
                name: part.into(),
                supported: false,
                reason: if within.is_empty() {
                    "no fitted parameter with a no-effect value and an interval".into()
                } else {
                    format!(
                        "the data do not distinguish {part} from no effect: {}",
                        within.join("; ")
                    )
                },
            }
        })
        .collect()
}

/// Whether every part of a name is supported.
pub fn all_supported(parts: &[PartSupport]) -> bool {
    parts.iter().all(|p| p.supported)
}

/// A candidate that passed the tests of its role (the first cause's BIC and held-out threshold,
/// or a companion's tests) but is not named: the data do not distinguish at least one of its
/// causes from no effect (`considered_not_supported` in diagnosis.json).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct NotSupported {
    /// The candidate's name, as in `candidates`.
    pub name: String,
    /// `cause` (in the first cause's place) or `companion` (a pair beside the first cause).
    pub role: String,
    /// Fitted values.
    pub parameters: BTreeMap<String, f64>,
    /// 95% intervals (with the spread across tests where it was chosen before the rule).
    pub intervals: BTreeMap<String, [f64; 2]>,
    /// The no-effect value or band of every parameter that has one.
    pub no_effect: BTreeMap<String, NoEffect>,
    /// The parts of the name the data do not support.
    pub parts_not_supported: Vec<String>,
    /// One sentence.
    pub reason: String,
}

impl NotSupported {
    /// The record of a candidate and its parts' support (at least one not supported).
    pub fn new(
        name: &str,
        role: &str,
        parameters: &BTreeMap<String, f64>,
        intervals: &BTreeMap<String, [f64; 2]>,
        no_effect: BTreeMap<String, NoEffect>,
        parts: &[PartSupport],
        context: &str,
    ) -> Self {
        let bad: Vec<&PartSupport> = parts.iter().filter(|p| !p.supported).collect();
        let reason = format!(
            "{context}, but {}",
            bad.iter()
                .map(|p| p.reason.as_str())
                .collect::<Vec<_>>()
                .join("; and ")
        );
        Self {
            name: name.into(),
            role: role.into(),
            parameters: parameters.clone(),
            intervals: intervals.clone(),
            no_effect,
            parts_not_supported: bad.iter().map(|p| p.name.clone()).collect(),
            reason,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn cx() -> NoEffectContext {
        NoEffectContext {
            a0_m2: 1.6e-3,
            orifice_area_m2: Some(1.8e-6),
            relief_a_m: Some(0.0157),
            relief_f_p_n: [Some(178.0), Some(178.0)],
            // 2 kHz, the replay's own delay 14.7 us
            lag_timing_s: timing_uncertainty_s(5e-4, -1.47e-5),
        }
    }

    fn supported(name: &str, p: &[(&str, f64, [f64; 2])]) -> Vec<PartSupport> {
        let params: BTreeMap<String, f64> = p.iter().map(|(n, x, _)| (n.to_string(), *x)).collect();
        let ivs: BTreeMap<String, [f64; 2]> =
            p.iter().map(|(n, _, i)| (n.to_string(), *i)).collect();
        let ne = no_effects(name, &params, &ivs, &cx());
        support(name, &params, &ivs, &ne)
    }

    #[test]
    fn the_table_gives_each_parameter_its_no_effect_value() {
        let c = cx();
        let none = BTreeMap::new();
        let v = |value| Some(NoEffect::Value { value });
        let ne = |part, p| no_effect(part, p, &c, &none);
        assert_eq!(ne("force_offset", "offset_N"), v(0.0));
        assert_eq!(ne("force_gain", "gain"), v(1.0));
        assert_eq!(ne("force_drift", "drift_N_per_s"), v(0.0));
        let Some(NoEffect::Band { lo, hi }) = ne("force_lag", "lag_s") else {
            panic!("the lag's no effect is a band");
        };
        assert!((hi - 2.647e-4).abs() < 1e-12 && lo == -hi, "{lo} {hi}");
        assert_eq!(ne("seal_friction", "F_c_N"), v(0.0));
        assert_eq!(ne("seal_friction", "presliding_m"), None);
        assert_eq!(ne("free_play", "gap_m"), v(0.0));
        assert_eq!(ne("compliant_free_play", "gap_m"), v(0.0));
        assert_eq!(
            ne("compliant_free_play", "contact_stiffness_N_per_m"),
            Some(NoEffect::Infinity)
        );
        assert_eq!(
            ne("mount_compliance", "mount_stiffness_N_per_m"),
            Some(NoEffect::Infinity)
        );
        assert_eq!(ne("entrained_air", "air_fraction"), v(0.0));
        assert_eq!(ne("entrained_air_by_chamber", "air_fraction_1"), v(0.0));
        assert_eq!(ne("piston_leakage", "leakage_m3_per_s_Pa"), v(0.0));
        assert_eq!(
            ne("piston_leakage", "leakage_viscosity_length_Pa_s_m"),
            None
        );
        assert_eq!(
            ne("accumulator_bleed", "accumulator_bleed_m3_per_s_Pa"),
            v(0.0)
        );
        assert_eq!(ne("area_asymmetry", "A1_m2"), v(1.6e-3));
        assert_eq!(ne("recalibration", "A_orf_m2"), v(1.8e-6));
        assert_eq!(ne("recalibration", "relief_a_m"), v(0.0157));
        assert_eq!(ne("relief_asymmetry", "F_p0_N"), None);
        assert_eq!(ne("relief_asymmetry", "F_p1_N"), v(178.0));
        let fitted = BTreeMap::from([("F_p0_N".to_string(), [150.0, 170.0])]);
        assert_eq!(
            no_effect("relief_asymmetry", "F_p1_N", &c, &fitted),
            Some(NoEffect::Band {
                lo: 150.0,
                hi: 170.0
            })
        );
        assert_eq!(
            ne("oil_temperature", "density_thermal_coefficient_per_K"),
            v(0.0)
        );
        assert_eq!(ne("oil_temperature", "oil_reference_temperature_K"), None);
        assert_eq!(ne("oil_drift", "oil_bulk_modulus_drop_fraction"), v(0.0));
        // Not a parameter of that cause.
        assert_eq!(ne("free_play", "air_fraction"), None);
        assert!(!belongs_to("force_gain", "offset_N"));
    }

    #[test]
    fn every_parameter_of_every_candidate_is_in_the_table() {
        use crate::diagnose::candidates::Scales;
        let deck = crate::hydraulics::DamperDeck::from_file(std::path::Path::new(concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/flightdata/damper_nominal.toml"
        )))
        .unwrap();
        let s = Scales {
            peak_force_n: 1e4,
            min_amplitude_m: 1e-3,
            oil_span_k: 20.0,
            oil_reference_unknown: true,
            oil_drift: true,
        };
        let mut deck = deck;
        deck.oil = Some(crate::hydraulics::OilTemperature {
            temperature_k: 300.0,
            density_per_k: 0.0,
            bulk_modulus_per_k: 0.0,
            viscosity_per_k: 0.0,
        });
        for c in Cause::CANDIDATES {
            let spec = c.params(&deck, s).unwrap_or_else(|| panic!("{}", c.name()));
            let mut own = 0;
            for p in &spec {
                assert!(belongs_to(c.name(), p.name), "{} {}", c.name(), p.name);
                own += no_effect(c.name(), p.name, &cx(), &BTreeMap::new()).is_some() as usize;
            }
            assert!(
                own >= 1,
                "{} has no parameter with a no-effect value",
                c.name()
            );
        }
        for f in Fault::ALL {
            assert!(no_effect(f.name(), f.param(), &cx(), &BTreeMap::new()).is_some());
        }
    }

    #[test]
    fn an_interval_straddling_the_no_effect_value_is_not_supported() {
        let p = supported("force_offset", &[("offset_N", 12.0, [-3.0, 27.0])]);
        assert!(!p[0].supported, "{p:?}");
        assert!(p[0].reason.contains("no effect"), "{}", p[0].reason);
        let p = supported("force_offset", &[("offset_N", 12.0, [3.0, 21.0])]);
        assert!(p[0].supported, "{p:?}");
        let p = supported("force_gain", &[("gain", 1.01, [0.995, 1.025])]);
        assert!(!p[0].supported, "{p:?}");
        let p = supported("area_asymmetry", &[("A1_m2", 1.55e-3, [1.50e-3, 1.61e-3])]);
        assert!(!p[0].supported, "{p:?}");
        let p = supported("area_asymmetry", &[("A1_m2", 1.40e-3, [1.35e-3, 1.45e-3])]);
        assert!(p[0].supported, "{p:?}");
        // The relief valves: F_p1 within F_p0's interval is no asymmetry.
        let p = supported(
            "relief_asymmetry",
            &[
                ("F_p0_N", 180.0, [170.0, 190.0]),
                ("F_p1_N", 160.0, [150.0, 172.0]),
            ],
        );
        assert!(!p[0].supported, "{p:?}");
        let p = supported(
            "relief_asymmetry",
            &[
                ("F_p0_N", 180.0, [170.0, 190.0]),
                ("F_p1_N", 140.0, [130.0, 150.0]),
            ],
        );
        assert!(p[0].supported, "{p:?}");
    }

    #[test]
    fn an_interval_unbounded_toward_the_no_effect_value_is_not_supported() {
        let p = supported("free_play", &[("gap_m", 1e-5, [0.0, 3e-5])]);
        assert!(!p[0].supported, "{p:?}");
        let p = supported("free_play", &[("gap_m", 1e-4, [0.8e-4, 1.2e-4])]);
        assert!(p[0].supported, "{p:?}");
        let p = supported(
            "mount_compliance",
            &[("mount_stiffness_N_per_m", 5e8, [1e8, f64::INFINITY])],
        );
        assert!(!p[0].supported, "{p:?}");
        let p = supported(
            "mount_compliance",
            &[("mount_stiffness_N_per_m", 5e7, [4e7, 6e7])],
        );
        assert!(p[0].supported, "{p:?}");
        // Unbounded away from it still excludes it.
        let p = supported(
            "entrained_air",
            &[("air_fraction", 0.01, [1e-3, f64::INFINITY])],
        );
        assert!(p[0].supported, "{p:?}");
        // NaN never supports.
        let p = supported("entrained_air", &[("air_fraction", 0.01, [f64::NAN, 0.02])]);
        assert!(!p[0].supported, "{p:?}");
    }

    #[test]
    fn a_multi_parameter_cause_needs_one_parameter_away_from_no_effect() {
        // The gap unbounded toward 0 but the contact stiffness finite: still an effect.
        let p = supported(
            "compliant_free_play",
            &[
                ("gap_m", 1e-6, [0.0, 1e-5]),
                ("contact_stiffness_N_per_m", 5e7, [4e7, 6e7]),
            ],
        );
        assert!(p[0].supported, "{p:?}");
        let p = supported(
            "compliant_free_play",
            &[
                ("gap_m", 1e-6, [0.0, 1e-5]),
                ("contact_stiffness_N_per_m", 5e9, [1e8, f64::INFINITY]),
            ],
        );
        assert!(!p[0].supported, "{p:?}");
        // A parameter with no no-effect value of its own does not count.
        let p = supported(
            "piston_leakage",
            &[
                ("leakage_m3_per_s_Pa", 1e-13, [0.0, 1e-12]),
                ("leakage_viscosity_length_Pa_s_m", 3e-4, [2e-4, 4e-4]),
            ],
        );
        assert!(!p[0].supported, "{p:?}");
    }

    #[test]
    fn a_lag_within_the_timing_uncertainty_is_not_supported() {
        // The blind suite's case: 0.17 ms, -0.16 to +0.50 ms.
        let p = supported("force_lag", &[("lag_s", 1.7e-4, [-1.6e-4, 5.0e-4])]);
        assert!(!p[0].supported, "{p:?}");
        assert!(
            p[0].reason.contains("timing uncertainty"),
            "{}",
            p[0].reason
        );
        // A tight interval within half a sample (plus the replay's delay) of zero: the force
        // averaged over the sample interval, not a fault.
        let p = supported("force_lag", &[("lag_s", 2.5e-4, [2.4e-4, 2.6e-4])]);
        assert!(!p[0].supported, "{p:?}");
        // Just beyond half a sample but within the replay's delay on top.
        let p = supported("force_lag", &[("lag_s", 2.6e-4, [2.55e-4, 2.7e-4])]);
        assert!(!p[0].supported, "{p:?}");
        // A 1.3 ms lag with a tight interval is a fault of the acquisition.
        let p = supported("force_lag", &[("lag_s", 1.3e-3, [1.25e-3, 1.35e-3])]);
        assert!(p[0].supported, "{p:?}");
        // Either sign.
        let p = supported("force_lag", &[("lag_s", -1.3e-3, [-1.35e-3, -1.25e-3])]);
        assert!(p[0].supported, "{p:?}");
    }

    #[test]
    fn each_part_of_a_name_is_judged_with_its_own_interval() {
        let p = supported(
            "entrained_air+force_lag",
            &[
                ("air_fraction", 0.01, [0.008, 0.012]),
                ("lag_s", 1.7e-4, [1.0e-4, 2.4e-4]),
            ],
        );
        assert_eq!(p.len(), 2);
        assert!(p[0].supported && !p[1].supported, "{p:?}");
        assert!(!all_supported(&p));
        let p = supported(
            "seal_friction+force_clipping",
            &[
                ("F_c_N", 300.0, [250.0, 350.0]),
                ("clip_high_N", 9000.0, [9000.0, 9000.0]),
            ],
        );
        assert!(all_supported(&p), "{p:?}");
        assert!(support("none", &BTreeMap::new(), &BTreeMap::new(), &BTreeMap::new()).is_empty());
    }
}
