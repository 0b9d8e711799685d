//! The candidate model extensions: each a physical element of the hydraulic library (or a
//! re-calibration of uncertain nominal coefficients), with its fitted parameters and bounds.
use crate::hydraulics::{
    AnnularLeakage, DamperDeck, EntrainedAir, FreePlay, Leakage, OilTemperature, SealFriction,
};
use std::borrow::Cow;

/// Named causes (docs/formats.md `cause`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Cause {
    None,
    SealFriction,
    FreePlay,
    EntrainedAir,
    AreaAsymmetry,
    ReliefAsymmetry,
    PistonLeakage,
    /// Entrained air, a different fraction in each chamber.
    EntrainedAirByChamber,
    /// Elastic mounts in series (attachment compliance).
    MountCompliance,
    /// Bleed of both chambers to the accumulator at p_s.
    AccumulatorBleed,
    /// Re-calibration of the orifice area (C_d A_orf) and relief-valve flow-area coefficient a.
    Recalibration,
    /// Free play behind a contact stiffness (gap and stiffness fitted together).
    CompliantFreePlay,
    /// The oil's temperature, changing from test to test: density and bulk modulus move with
    /// it (needs each test's temperature).
    OilTemperature,
    /// The oil warming over a campaign that records no temperature: density and bulk modulus
    /// falling evenly (in log) with the tests' order.
    OilDrift,
}

/// Temperature the drift's stand-in law starts from at the first test [K].
pub const OIL_DRIFT_REFERENCE_K: f64 = 293.15;
/// The stand-in law's temperature rise from the first test to the last [K]: the drift is
/// fitted as a fraction over the campaign, carried by an oil law over this span.
pub const OIL_DRIFT_SPAN_K: f64 = 100.0;

/// Stand-in temperature [K] of test `i` of `n` in a campaign fitted as a drift of its oil.
pub fn oil_drift_temperature_k(i: usize, n: usize) -> f64 {
    OIL_DRIFT_REFERENCE_K + OIL_DRIFT_SPAN_K * i as f64 / (n.max(2) - 1) as f64
}

/// One fitted parameter: name (with unit), bounds, starting values (multi-start).
#[derive(Debug, Clone, PartialEq)]
pub struct ParamSpec {
    pub name: &'static str,
    pub lo: f64,
    pub hi: f64,
    pub starts: Vec<f64>,
}

/// What the fit needs to know about the data to bound the parameters.
#[derive(Debug, Clone, Copy)]
pub struct Scales {
    pub peak_force_n: f64,
    pub min_amplitude_m: f64,
    /// Spread of the tests' oil temperatures [K] (0 when a test has none).
    pub oil_span_k: f64,
    /// The deck does not say at which temperature its values hold: the oil's candidate fits it.
    pub oil_reference_unknown: bool,
    /// No test records its oil temperature and there are at least three: the tests carry the
    /// drift's stand-in temperatures (in the order given) and the oil may be fitted as a drift.
    pub oil_drift: bool,
}

impl Cause {
    pub const CANDIDATES: [Cause; 13] = [
        Cause::SealFriction,
        Cause::FreePlay,
        Cause::CompliantFreePlay,
        Cause::EntrainedAir,
        Cause::EntrainedAirByChamber,
        Cause::AreaAsymmetry,
        Cause::ReliefAsymmetry,
        Cause::PistonLeakage,
        Cause::AccumulatorBleed,
        Cause::MountCompliance,
        Cause::Recalibration,
        Cause::OilTemperature,
        Cause::OilDrift,
    ];

    pub fn name(self) -> &'static str {
        match self {
            Cause::None => "none",
            Cause::SealFriction => "seal_friction",
            Cause::FreePlay => "free_play",
            Cause::EntrainedAir => "entrained_air",
            Cause::AreaAsymmetry => "area_asymmetry",
            Cause::ReliefAsymmetry => "relief_asymmetry",
            Cause::PistonLeakage => "piston_leakage",
            Cause::AccumulatorBleed => "accumulator_bleed",
            Cause::MountCompliance => "mount_compliance",
            Cause::EntrainedAirByChamber => "entrained_air_by_chamber",
            Cause::Recalibration => "recalibration",
            Cause::CompliantFreePlay => "compliant_free_play",
            Cause::OilTemperature => "oil_temperature",
            Cause::OilDrift => "oil_drift",
        }
    }

    /// The fitted parameters and their bounds for a base deck (None: not applicable, e.g.
    /// relief asymmetry without relief valves).
    pub fn params(self, base: &DamperDeck, s: Scales) -> Option<Vec<ParamSpec>> {
        let c = base.physical.as_ref()?;
        let p = |name, lo: f64, hi: f64, starts: Vec<f64>| ParamSpec {
            name,
            lo,
            hi,
            starts,
        };
        Some(match self {
            Cause::None => vec![],
            Cause::SealFriction => {
                let f = s.peak_force_n.max(1.0);
                // Presliding from a tenth of a micron (the sliding law at any stroke here) to
                // a millimetre.
                vec![
                    p("F_c_N", 1e-3 * f, 0.3 * f, vec![0.01 * f, 0.05 * f]),
                    p("presliding_m", 1e-7, 1e-3, vec![1e-5]),
                ]
            }
            Cause::FreePlay => {
                let a = s.min_amplitude_m;
                vec![p(
                    "gap_m",
                    1e-3 * a,
                    1.5 * a,
                    vec![0.03 * a, 0.15 * a, 0.5 * a],
                )]
            }
            Cause::CompliantFreePlay => {
                let a = s.min_amplitude_m;
                // Up to 1e11 N/m: far stiffer than the oil column (~1e8), the rigid-gap limit.
                vec![
                    p("gap_m", 1e-3 * a, 1.5 * a, vec![0.03 * a, 0.15 * a]),
                    p("contact_stiffness_N_per_m", 1e6, 1e11, vec![5e7, 1e9]),
                ]
            }
            Cause::EntrainedAir => vec![p("air_fraction", 1e-5, 0.3, vec![3e-3, 3e-2])],
            Cause::EntrainedAirByChamber => vec![
                p("air_fraction_0", 1e-5, 0.3, vec![1e-3, 3e-2]),
                p("air_fraction_1", 1e-5, 0.3, vec![1e-3, 3e-2]),
            ],
            Cause::AreaAsymmetry => {
                let a1 = c.chambers[1].area;
                vec![p("A1_m2", 0.4 * a1, 1.3 * a1, vec![0.9 * a1])]
            }
            Cause::ReliefAsymmetry => {
                let (r0, r1) = (c.relief[0]?, c.relief[1]?);
                vec![
                    p("F_p0_N", 0.2 * r0.f_p, 5.0 * r0.f_p, vec![r0.f_p]),
                    p("F_p1_N", 0.2 * r1.f_p, 5.0 * r1.f_p, vec![r1.f_p]),
                ]
            }
            // Viscosity times land length, mu L: hydraulic oils 0.005-0.1 Pa s, seal lands
            // 2-100 mm (the drag flow it gives with k is the annulus's own, not a free area).
            Cause::PistonLeakage => vec![
                p("leakage_m3_per_s_Pa", 1e-15, 1e-8, vec![1e-12, 1e-11]),
                p("leakage_viscosity_length_Pa_s_m", 1e-5, 1e-2, vec![3e-4]),
            ],
            Cause::MountCompliance => vec![p("mount_stiffness_N_per_m", 1e6, 1e10, vec![1e7, 1e8])],
            Cause::AccumulatorBleed => vec![p(
                "accumulator_bleed_m3_per_s_Pa",
                1e-15,
                1e-8,
                vec![1e-12, 1e-11],
            )],
            // With the tests at different temperatures (the base deck then has the law's
            // reference: the data sheet's, else the tests' median). Mineral oils: c_rho ~7e-4,
            // c_B ~5e-3 per K.
            Cause::OilTemperature => {
                let law = base.oil?;
                if s.oil_span_k < 0.5 {
                    return None;
                }
                let mut v = vec![
                    p("density_thermal_coefficient_per_K", 1e-6, 5e-3, vec![7e-4]),
                    p(
                        "bulk_modulus_thermal_coefficient_per_K",
                        1e-6,
                        3e-2,
                        vec![5e-3],
                    ),
                ];
                // The data sheet's temperature, unknown: within 60 K beyond the tests' range
                // (the law's temperature is then the tests' median).
                if s.oil_reference_unknown {
                    let (t, w) = (law.temperature_k, 0.5 * s.oil_span_k + 60.0);
                    v.push(p(
                        "oil_reference_temperature_K",
                        (t - w).max(1.0),
                        t + w,
                        vec![t],
                    ));
                }
                v
            }
            // Fractions lost from the first test to the last (mineral oil warming by 60 K:
            // density ~4%, bulk modulus ~25%).
            Cause::OilDrift => {
                if !s.oil_drift {
                    return None;
                }
                vec![
                    p("oil_density_drop_fraction", 1e-5, 0.3, vec![0.04]),
                    p("oil_bulk_modulus_drop_fraction", 1e-5, 0.8, vec![0.25]),
                ]
            }
            Cause::Recalibration => {
                let a = c.orifice?.area;
                let mut v = vec![p("A_orf_m2", 0.2 * a, 5.0 * a, vec![a])];
                if let Some(r) = c.relief[0].or(c.relief[1]) {
                    // The relief valves' opening is seen only in the strokes that open them:
                    // the fit has local minima far from the data sheet's value.
                    v.push(p(
                        "relief_a_m",
                        0.05 * r.a,
                        20.0 * r.a,
                        vec![r.a, 0.3 * r.a, 3.0 * r.a],
                    ));
                }
                v
            }
        })
    }

    /// The base deck with this extension set to the parameter values `x` (same order as
    /// [`Cause::params`]).
    pub fn apply(self, base: &DamperDeck, x: &[f64]) -> DamperDeck {
        let mut d = base.clone();
        let Some(c) = d.physical.as_mut() else {
            return d;
        };
        match self {
            Cause::None => {}
            Cause::SealFriction => {
                d.extensions.friction = Some(SealFriction {
                    presliding_m: x.get(1).copied().unwrap_or(0.0),
                    ..SealFriction::coulomb(x[0])
                })
            }
            Cause::FreePlay => d.extensions.free_play = Some(FreePlay { gap: x[0] }),
            Cause::CompliantFreePlay => {
                d.extensions.free_play = Some(FreePlay { gap: x[0] });
                d.extensions.free_play_contact_stiffness_n_per_m = Some(x[1]);
            }
            Cause::EntrainedAir => {
                c.ext.air = Some(EntrainedAir {
                    fraction: x[0],
                    p_ref: c.p_s.max(crate::hydraulics::extensions::AIR_P_MIN_PA),
                })
            }
            Cause::EntrainedAirByChamber => {
                for (slot, &a) in c.ext.air_by_chamber.iter_mut().zip(x) {
                    *slot = Some(EntrainedAir {
                        fraction: a,
                        p_ref: c.p_s.max(crate::hydraulics::extensions::AIR_P_MIN_PA),
                    });
                }
            }
            Cause::AreaAsymmetry => c.chambers[1].area = x[0],
            Cause::ReliefAsymmetry => {
                for (k, v) in x.iter().enumerate().take(2) {
                    if let Some(r) = c.relief[k].as_mut() {
                        r.f_p = *v;
                    }
                }
            }
            Cause::PistonLeakage => {
                c.ext.leakage = Some(AnnularLeakage {
                    conductance: x[0],
                    viscosity_length: x.get(1).copied().unwrap_or(0.0),
                })
            }
            Cause::AccumulatorBleed => c.ext.bleed = Some(Leakage { conductance: x[0] }),
            Cause::MountCompliance => d.extensions.mount_stiffness_n_per_m = Some(x[0]),
            Cause::OilTemperature => {
                if let Some(o) = d.oil.as_mut() {
                    o.density_per_k = x[0];
                    o.bulk_modulus_per_k = x[1];
                    // the data sheet's values hold at the fitted temperature
                    if let Some(&t) = x.get(2) {
                        o.temperature_k = t;
                    }
                }
            }
            // The law that takes the tests' stand-in temperatures to these fractions.
            Cause::OilDrift => {
                let per_k = |f: f64| OilTemperature::loss_exponent(f) / OIL_DRIFT_SPAN_K;
                d.oil = Some(OilTemperature {
                    temperature_k: OIL_DRIFT_REFERENCE_K,
                    density_per_k: per_k(x[0]),
                    bulk_modulus_per_k: per_k(x[1]),
                    viscosity_per_k: 0.0,
                });
            }
            Cause::Recalibration => {
                if let Some(o) = c.orifice.as_mut() {
                    o.area = x[0];
                }
                if let Some(&a) = x.get(1) {
                    for r in c.relief.iter_mut().flatten() {
                        r.a = a;
                    }
                }
            }
        }
        d
    }
}

/// Name of a combination of causes, e.g. `entrained_air+free_play`.
pub fn combined_name(causes: &[Cause]) -> String {
    causes
        .iter()
        .map(|c| c.name())
        .collect::<Vec<_>>()
        .join("+")
}

/// The base a combination is built on. A moving mass on the data sheet (`link_mass_kg`) is
/// modelled behind one link on the bare circuit (src/hydraulics/link.rs); beside seal friction,
/// a rigid gap or a second link the link is quasi-static, so such a combination leaves the mass
/// out.
fn combination_base<'a>(causes: &[Cause], base: &'a DamperDeck) -> Cow<'a, DamperDeck> {
    let links = causes
        .iter()
        .filter(|c| matches!(c, Cause::CompliantFreePlay | Cause::MountCompliance))
        .count();
    let e = &base.extensions;
    let beside = e.friction.is_some()
        || e.free_play.is_some() && e.free_play_contact_stiffness_n_per_m.is_none()
        || causes
            .iter()
            .any(|c| matches!(c, Cause::SealFriction | Cause::FreePlay));
    if base.extensions.link_mass.is_some() && links > 0 && (links > 1 || beside) {
        let mut b = base.clone();
        b.extensions.link_mass = None;
        Cow::Owned(b)
    } else {
        Cow::Borrowed(base)
    }
}

/// Parameters of a combination (concatenated; None if any cause is not applicable).
pub fn combined_params(causes: &[Cause], base: &DamperDeck, s: Scales) -> Option<Vec<ParamSpec>> {
    let base = &*combination_base(causes, base);
    let mut v = Vec::new();
    for c in causes {
        v.extend(c.params(base, s)?);
    }
    Some(v)
}

/// The base deck with every cause of a combination applied, each taking its share of `x`.
pub fn apply_all(causes: &[Cause], base: &DamperDeck, s: Scales, x: &[f64]) -> DamperDeck {
    let base = &*combination_base(causes, base);
    let mut d = base.clone();
    let mut i = 0;
    for c in causes {
        let k = c.params(base, s).map_or(0, |p| p.len());
        d = c.apply(&d, &x[i..i + k]);
        i += k;
    }
    d
}
