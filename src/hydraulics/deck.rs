//! The damper deck of docs/formats.md: the `[damper]` table of any TOML file (other top-level tables
//! are ignored; unknown keys inside `[damper...]` tables are errors).
use super::circuit::{ActuatorParams, CircuitDevice, CircuitParams};
use super::dashpot::{LinearDashpot, MonotoneTable, NonlinearDashpot};
use super::elements::{Chamber, CheckValve, Orifice, ReliefValve};
use super::extensions::{
    AnnularLeakage, CompliantFreePlay, EntrainedAir, ExtendedDamper, FreePlay, HydraulicExtensions,
    Leakage, SealFriction, SeriesMount,
};
use super::fluid::Fluid;
use super::integrators::{IntegratorOptions, Scheme};
use super::link::{LinkMass, LinkedCircuit};
use super::temperature::{
    is_oil_temperature_k, oil_temperature_expected, OilTemperature, OIL_COEFFICIENT_MAX_PER_K,
};
use super::Device;
use std::path::Path;
use toml::{Table, Value};

/// Default laminar transition of the flow laws when the deck omits `dp_laminar_Pa`.
pub const DEFAULT_DP_LAMINAR_PA: f64 = 1.0e3;
/// Default cavitation band when the deck omits `p_cav_Pa`.
pub const DEFAULT_P_CAV_PA: f64 = 1.0e4;

/// Deck errors, naming the file and the key.
#[derive(Debug, thiserror::Error)]
pub enum DeckError {
    #[error("cannot read deck {file}: {source}")]
    Read {
        file: String,
        #[source]
        source: std::io::Error,
    },
    #[error("deck {file} is not valid TOML: {message}")]
    Parse { file: String, message: String },
    #[error("deck {file}: missing table [{table}]")]
    MissingTable { file: String, table: String },
    #[error("deck {file}: missing key `{key}` ({expected})")]
    MissingKey {
        file: String,
        key: String,
        expected: String,
    },
    #[error("deck {file}: unknown key `{key}` (known keys: {known})")]
    UnknownKey {
        file: String,
        key: String,
        known: String,
    },
    #[error("deck {file}: key `{key}` = {value}: {expected}")]
    BadValue {
        file: String,
        key: String,
        value: String,
        expected: String,
    },
}

/// Damper model selection.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum DamperModel {
    Physical,
    Linear,
    Nonlinear,
}

impl DamperModel {
    pub fn name(self) -> &'static str {
        match self {
            Self::Physical => "physical",
            Self::Linear => "linear",
            Self::Nonlinear => "nonlinear",
        }
    }
}

impl std::str::FromStr for DamperModel {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        match s {
            "physical" => Ok(Self::Physical),
            "linear" => Ok(Self::Linear),
            "nonlinear" => Ok(Self::Nonlinear),
            _ => Err(format!(
                "unknown damper model '{s}' (expected physical, linear or nonlinear)"
            )),
        }
    }
}

/// A loaded damper deck: the default model and whichever model tables the deck holds.
#[derive(Debug, Clone, PartialEq)]
pub struct DamperDeck {
    /// File (or source name) the deck came from, for messages.
    pub source: String,
    pub model: DamperModel,
    pub linear_c_n_s_per_m: Option<f64>,
    pub nonlinear: Option<(Vec<f64>, Vec<f64>)>,
    pub physical: Option<CircuitParams>,
    /// Device-level extensions of the physical model (`[damper.physical.extensions]`: seal
    /// friction, free play); the hydraulic ones (air, leakage) live in `physical.ext`.
    pub extensions: DeviceExtensions,
    /// The oil's temperature law (`[damper.physical.oil]`); `physical` holds at its
    /// `temperature_k`.
    pub oil: Option<OilTemperature>,
}

/// Keys of `[damper.physical.oil]`.
pub const OIL_KEYS: &[&str] = &[
    "reference_temperature_K",
    "temperature_K",
    "density_thermal_coefficient_per_K",
    "bulk_modulus_thermal_coefficient_per_K",
    "viscosity_thermal_coefficient_per_K",
];

/// Seal friction and free play of the physical damper (default: none).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct DeviceExtensions {
    pub friction: Option<SealFriction>,
    pub free_play: Option<FreePlay>,
    /// Stiffness of elastic mounts in series [N/m].
    pub mount_stiffness_n_per_m: Option<f64>,
    /// Contact stiffness behind the free play [N/m] (None: a rigid gap).
    pub free_play_contact_stiffness_n_per_m: Option<f64>,
    /// Moving mass between the link (compliant free play or mount) and the oil, and the link's
    /// damping (None: a massless, quasi-static link; without a link the mass moves with the end
    /// and its inertia force is left out).
    pub link_mass: Option<LinkMass>,
}

/// Keys of `[damper.physical.extensions]` (all optional; absent or 0 = off).
pub const EXTENSION_KEYS: &[&str] = &[
    "seal_friction_N",
    "stribeck_static_N",
    "stribeck_velocity_m_s",
    "friction_smoothing_m_s",
    "seal_presliding_m",
    "free_play_m",
    "air_fraction",
    "leakage_m3_per_s_Pa",
    "leakage_viscosity_length_Pa_s_m",
    "accumulator_bleed_m3_per_s_Pa",
    "air_fraction_0",
    "air_fraction_1",
    "mount_stiffness_N_per_m",
    "free_play_contact_stiffness_N_per_m",
    "link_mass_kg",
    "link_damping_ratio",
];

struct Ctx<'a> {
    file: &'a str,
}

impl Ctx<'_> {
    fn table<'t>(
        &self,
        parent: &'t Table,
        path: &str,
        name: &str,
    ) -> Result<Option<&'t Table>, DeckError> {
        match parent.get(name) {
            None => Ok(None),
            Some(Value::Table(t)) => Ok(Some(t)),
            Some(v) => Err(self.bad(&format!("{path}.{name}"), v, "expected a table")),
        }
    }

    fn bad(&self, key: &str, v: &Value, expected: &str) -> DeckError {
        DeckError::BadValue {
            file: self.file.into(),
            key: key.into(),
            value: v.to_string(),
            expected: expected.into(),
        }
    }

    fn known(&self, t: &Table, path: &str, keys: &[&str]) -> Result<(), DeckError> {
        for k in t.keys() {
            if !keys.contains(&k.as_str()) {
                return Err(DeckError::UnknownKey {
                    file: self.file.into(),
                    key: format!("{path}.{k}"),
                    known: keys.join(", "),
                });
            }
        }
        Ok(())
    }

    fn num(&self, t: &Table, path: &str, key: &str, expected: &str) -> Result<f64, DeckError> {
        let full = format!("{path}.{key}");
        match t.get(key) {
            None => Err(DeckError::MissingKey {
                file: self.file.into(),
                key: full,
                expected: expected.into(),
            }),
            Some(v) => self.as_num(v, &full, expected),
        }
    }

    fn as_num(&self, v: &Value, full: &str, expected: &str) -> Result<f64, DeckError> {
        let x = match v {
            Value::Float(x) => *x,
            Value::Integer(i) => *i as f64,
            _ => return Err(self.bad(full, v, &format!("expected a number ({expected})"))),
        };
        if !x.is_finite() {
            return Err(self.bad(full, v, &format!("expected a finite number ({expected})")));
        }
        Ok(x)
    }

    /// Number satisfying `ok`, e.g. positive.
    fn num_where(
        &self,
        t: &Table,
        path: &str,
        key: &str,
        expected: &str,
        ok: fn(f64) -> bool,
    ) -> Result<f64, DeckError> {
        let x = self.num(t, path, key, expected)?;
        if !ok(x) {
            return Err(self.bad(
                &format!("{path}.{key}"),
                &t[key],
                &format!("expected {expected}"),
            ));
        }
        Ok(x)
    }

    fn array(&self, t: &Table, path: &str, key: &str) -> Result<Vec<f64>, DeckError> {
        let full = format!("{path}.{key}");
        match t.get(key) {
            None => Err(DeckError::MissingKey {
                file: self.file.into(),
                key: full,
                expected: "an array of numbers".into(),
            }),
            Some(Value::Array(a)) => a
                .iter()
                .map(|v| self.as_num(v, &full, "array of numbers"))
                .collect(),
            Some(v) => Err(self.bad(&full, v, "expected an array of numbers")),
        }
    }
}

fn positive(x: f64) -> bool {
    x > 0.0
}
fn non_negative(x: f64) -> bool {
    x >= 0.0
}

const PHYSICAL_KEYS: &[&str] = &[
    "A0_m2",
    "A1_m2",
    "V0_m3",
    "V1_m3",
    "rho_kg_m3",
    "bulk_alpha_per_Pa",
    "bulk_beta_per_Pa2",
    "A_orf_m2",
    "Cd",
    "p_s_Pa",
    "dp_laminar_Pa",
    "check_valve_area_m2",
    "p_cav_Pa",
    "relief_valve_0",
    "relief_valve_1",
    "extensions",
    "oil",
];
const VALVE_KEYS: &[&str] = &[
    "m_kg",
    "c_N_s_per_m",
    "k_N_per_m",
    "F_p_N",
    "A_front_m2",
    "A_back_m2",
    "a_m",
    "b",
];

impl DamperDeck {
    /// Reads a deck file.
    pub fn from_file(path: &Path) -> Result<Self, DeckError> {
        let file = path.display().to_string();
        let text = std::fs::read_to_string(path).map_err(|source| DeckError::Read {
            file: file.clone(),
            source,
        })?;
        Self::from_toml_str(&text, &file)
    }

    /// Parses deck text; `source_name` names it in errors.
    pub fn from_toml_str(text: &str, source_name: &str) -> Result<Self, DeckError> {
        let cx = Ctx { file: source_name };
        let root: Table = text
            .parse()
            .map_err(|e: toml::de::Error| DeckError::Parse {
                file: source_name.into(),
                message: e.to_string().trim_end().to_string(),
            })?;
        let damper = cx
            .table(&root, "", "damper")?
            .ok_or_else(|| DeckError::MissingTable {
                file: source_name.into(),
                table: "damper".into(),
            })?;
        cx.known(
            damper,
            "damper",
            &["model", "linear", "nonlinear", "physical"],
        )?;
        let model = match damper.get("model") {
            None => {
                return Err(DeckError::MissingKey {
                    file: source_name.into(),
                    key: "damper.model".into(),
                    expected: "physical, linear or nonlinear".into(),
                })
            }
            Some(Value::String(s)) => s
                .parse::<DamperModel>()
                .map_err(|e| cx.bad("damper.model", &damper["model"], &e))?,
            Some(v) => {
                return Err(cx.bad(
                    "damper.model",
                    v,
                    "expected a string: physical, linear or nonlinear",
                ))
            }
        };

        let linear = match cx.table(damper, "damper", "linear")? {
            None => None,
            Some(t) => {
                cx.known(t, "damper.linear", &["c_N_s_per_m"])?;
                Some(cx.num_where(
                    t,
                    "damper.linear",
                    "c_N_s_per_m",
                    "a non-negative damping coefficient (0: an inoperative damper)",
                    non_negative,
                )?)
            }
        };

        let nonlinear = match cx.table(damper, "damper", "nonlinear")? {
            None => None,
            Some(t) => {
                let p = "damper.nonlinear";
                cx.known(t, p, &["velocity_m_s", "force_N"])?;
                let v = cx.array(t, p, "velocity_m_s")?;
                let f = cx.array(t, p, "force_N")?;
                MonotoneTable::new(v.clone(), f.clone()).map_err(|e| DeckError::BadValue {
                    file: source_name.into(),
                    key: format!("{p}.velocity_m_s/force_N"),
                    value: format!("{v:?} / {f:?}"),
                    expected: e,
                })?;
                Some((v, f))
            }
        };

        let (physical, extensions, oil) = match cx.table(damper, "damper", "physical")? {
            None => (None, DeviceExtensions::default(), None),
            Some(t) => {
                let mut c = Self::parse_physical(&cx, t)?;
                let e = match cx.table(t, "damper.physical", "extensions")? {
                    None => DeviceExtensions::default(),
                    Some(et) => Self::parse_extensions(&cx, et, &mut c)?,
                };
                // After the extensions: the leakage and bleed move with the temperature too.
                let oil = match cx.table(t, "damper.physical", "oil")? {
                    None => None,
                    Some(ot) => Some(Self::parse_oil(&cx, ot, &mut c)?),
                };
                (Some(c), e, oil)
            }
        };

        let deck = Self {
            source: source_name.into(),
            model,
            linear_c_n_s_per_m: linear,
            nonlinear,
            physical,
            extensions,
            oil,
        };
        // The default model's table must be there.
        deck.require(model)?;
        Ok(deck)
    }

    fn parse_physical(cx: &Ctx, t: &Table) -> Result<CircuitParams, DeckError> {
        let p = "damper.physical";
        cx.known(t, p, PHYSICAL_KEYS)?;
        let area = |k| cx.num_where(t, p, k, "a positive area in m^2", positive);
        let vol = |k| cx.num_where(t, p, k, "a positive volume in m^3", positive);
        let a0 = area("A0_m2")?;
        let a1 = area("A1_m2")?;
        let v0 = vol("V0_m3")?;
        let v1 = vol("V1_m3")?;
        let rho = cx.num_where(t, p, "rho_kg_m3", "a positive density in kg/m^3", positive)?;
        let alpha = cx.num_where(
            t,
            p,
            "bulk_alpha_per_Pa",
            "a positive alpha in 1/Pa (Eq. 3)",
            positive,
        )?;
        let beta = cx.num_where(
            t,
            p,
            "bulk_beta_per_Pa2",
            "a non-negative beta in 1/Pa^2 (Eq. 3)",
            non_negative,
        )?;
        let a_orf = cx.num_where(
            t,
            p,
            "A_orf_m2",
            "a non-negative orifice area in m^2",
            non_negative,
        )?;
        let cd = cx.num_where(t, p, "Cd", "a discharge coefficient in (0, 1]", |x| {
            x > 0.0 && x <= 1.0
        })?;
        let p_s = cx.num_where(
            t,
            p,
            "p_s_Pa",
            "a non-negative background pressure in Pa",
            non_negative,
        )?;
        let dp_l = if t.contains_key("dp_laminar_Pa") {
            cx.num_where(t, p, "dp_laminar_Pa", "a positive pressure in Pa", positive)?
        } else {
            DEFAULT_DP_LAMINAR_PA
        };
        let p_cav = if t.contains_key("p_cav_Pa") {
            cx.num_where(
                t,
                p,
                "p_cav_Pa",
                "a non-negative pressure in Pa (0 disables)",
                non_negative,
            )?
        } else {
            DEFAULT_P_CAV_PA
        };
        let cva = cx.num_where(
            t,
            p,
            "check_valve_area_m2",
            "a non-negative area in m^2 (0 disables)",
            non_negative,
        )?;
        let mut relief = [None, None];
        for (k, r) in relief.iter_mut().enumerate() {
            let name = format!("relief_valve_{k}");
            let Some(vt) = cx.table(t, p, &name)? else {
                continue;
            };
            let vp = format!("{p}.{name}");
            cx.known(vt, &vp, VALVE_KEYS)?;
            let pos = |key: &str, what: &str| cx.num_where(vt, &vp, key, what, positive);
            *r = Some(ReliefValve {
                m: pos("m_kg", "a positive poppet mass in kg")?,
                c: cx.num_where(
                    vt,
                    &vp,
                    "c_N_s_per_m",
                    "a non-negative poppet damping in N s/m",
                    non_negative,
                )?,
                k: pos("k_N_per_m", "a positive spring constant in N/m")?,
                f_p: cx.num_where(
                    vt,
                    &vp,
                    "F_p_N",
                    "a non-negative preload in N",
                    non_negative,
                )?,
                a_front: pos("A_front_m2", "a positive area in m^2")?,
                a_back: cx.num_where(
                    vt,
                    &vp,
                    "A_back_m2",
                    "a non-negative area in m^2",
                    non_negative,
                )?,
                a: cx.num_where(
                    vt,
                    &vp,
                    "a_m",
                    "a non-negative coefficient in m (Eq. 7)",
                    non_negative,
                )?,
                b: cx.num_where(
                    vt,
                    &vp,
                    "b",
                    "a non-negative coefficient (Eq. 7)",
                    non_negative,
                )?,
                cd,
            });
        }
        Ok(CircuitParams {
            fluid: Fluid {
                rho,
                alpha,
                beta,
                p_cav,
            },
            dp_laminar: dp_l,
            chambers: [
                Chamber {
                    area: a0,
                    volume0: v0,
                    lambda: 1.0,
                },
                Chamber {
                    area: a1,
                    volume0: v1,
                    lambda: -1.0,
                },
            ],
            orifice: (a_orf > 0.0).then_some(Orifice { area: a_orf, cd }),
            relief,
            check: (cva > 0.0).then_some(CheckValve { area: cva, cd }),
            entrance: None,
            p_s,
            p_init: [p_s; 2],
            ext: HydraulicExtensions::default(),
        })
    }

    /// `[damper.physical.oil]`: the properties above hold at `reference_temperature_K`; they are
    /// moved to `temperature_K` (default: the reference).
    fn parse_oil(cx: &Ctx, t: &Table, c: &mut CircuitParams) -> Result<OilTemperature, DeckError> {
        let p = "damper.physical.oil";
        cx.known(t, p, OIL_KEYS)?;
        let kelvin = oil_temperature_expected();
        let t_ref = cx.num_where(
            t,
            p,
            "reference_temperature_K",
            &kelvin,
            is_oil_temperature_k,
        )?;
        let t_run = if t.contains_key("temperature_K") {
            cx.num_where(t, p, "temperature_K", &kelvin, is_oil_temperature_k)?
        } else {
            t_ref
        };
        let coef = |k: &str| -> Result<f64, DeckError> {
            if t.contains_key(k) {
                cx.num_where(t, p, k, "a coefficient in 1/K, 0 to 0.1", |x| {
                    (0.0..=OIL_COEFFICIENT_MAX_PER_K).contains(&x)
                })
            } else {
                Ok(0.0)
            }
        };
        let law = OilTemperature {
            temperature_k: t_ref,
            density_per_k: coef("density_thermal_coefficient_per_K")?,
            bulk_modulus_per_k: coef("bulk_modulus_thermal_coefficient_per_K")?,
            viscosity_per_k: coef("viscosity_thermal_coefficient_per_K")?,
        };
        Ok(law.move_to(c, t_run))
    }

    /// The deck at the oil temperature `t_k` [K] where both are known (a temperature and the
    /// deck's oil law), else the deck as it is (e.g. a flight record's or a bench test's).
    pub fn at_known_oil_temperature(
        &self,
        t_k: Option<f64>,
    ) -> Result<std::borrow::Cow<'_, DamperDeck>, DeckError> {
        match (t_k, self.oil) {
            (Some(t), Some(_)) => Ok(std::borrow::Cow::Owned(self.at_oil_temperature(t)?)),
            _ => Ok(std::borrow::Cow::Borrowed(self)),
        }
    }

    /// The deck with its oil at `t_k` [K] (the properties moved by `[damper.physical.oil]`).
    pub fn at_oil_temperature(&self, t_k: f64) -> Result<DamperDeck, DeckError> {
        if !is_oil_temperature_k(t_k) {
            return Err(DeckError::BadValue {
                file: self.source.clone(),
                key: "damper.physical.oil.temperature_K".into(),
                value: format!("{t_k}"),
                expected: oil_temperature_expected(),
            });
        }
        let mut d = self.clone();
        match (d.physical.as_mut(), self.oil) {
            (Some(c), Some(law)) => {
                d.oil = Some(law.move_to(c, t_k));
                Ok(d)
            }
            _ => Err(DeckError::MissingTable {
                file: self.source.clone(),
                table: "damper.physical.oil".into(),
            }),
        }
    }

    fn parse_extensions(
        cx: &Ctx,
        t: &Table,
        c: &mut CircuitParams,
    ) -> Result<DeviceExtensions, DeckError> {
        let p = "damper.physical.extensions";
        cx.known(t, p, EXTENSION_KEYS)?;
        let opt = |k: &str, what: &str, ok: fn(f64) -> bool| -> Result<Option<f64>, DeckError> {
            if t.contains_key(k) {
                cx.num_where(t, p, k, what, ok).map(Some)
            } else {
                Ok(None)
            }
        };
        let f_c = opt("seal_friction_N", "a non-negative force in N", non_negative)?;
        let f_s = opt(
            "stribeck_static_N",
            "a non-negative force in N",
            non_negative,
        )?;
        let v_s = opt(
            "stribeck_velocity_m_s",
            "a positive velocity in m/s",
            positive,
        )?;
        let v_eps = opt(
            "friction_smoothing_m_s",
            "a positive velocity in m/s",
            positive,
        )?;
        let gap = opt("free_play_m", "a non-negative gap in m", non_negative)?;
        let air = opt("air_fraction", "a volume fraction in [0, 1)", |x| {
            (0.0..1.0).contains(&x)
        })?;
        let leak = opt(
            "leakage_m3_per_s_Pa",
            "a non-negative conductance in m^3/(s Pa)",
            non_negative,
        )?;
        let mu_l = opt(
            "leakage_viscosity_length_Pa_s_m",
            "a non-negative viscosity times seal land length in Pa s m",
            non_negative,
        )?;
        let bleed = opt(
            "accumulator_bleed_m3_per_s_Pa",
            "a non-negative conductance in m^3/(s Pa)",
            non_negative,
        )?;
        if let Some(k) = bleed.filter(|k| *k > 0.0) {
            c.ext.bleed = Some(Leakage { conductance: k });
        }
        let mut e = DeviceExtensions {
            mount_stiffness_n_per_m: opt(
                "mount_stiffness_N_per_m",
                "a positive stiffness in N/m (absent: rigid mounts)",
                positive,
            )?,
            free_play_contact_stiffness_n_per_m: opt(
                "free_play_contact_stiffness_N_per_m",
                "a positive stiffness in N/m (absent: a rigid gap)",
                positive,
            )?,
            ..Default::default()
        };
        let mass = opt("link_mass_kg", "a positive mass in kg", positive)?;
        let zeta = opt(
            "link_damping_ratio",
            "a non-negative fraction of critical damping",
            non_negative,
        )?;
        if let Some(m) = mass {
            e.link_mass = Some(LinkMass {
                mass_kg: m,
                damping_ratio: zeta.unwrap_or(0.0),
            });
        } else if zeta.is_some() {
            return Err(cx.bad(
                &format!("{p}.link_damping_ratio"),
                &t["link_damping_ratio"],
                "the link's damping is a fraction of critical against its moving mass: give link_mass_kg too",
            ));
        }
        let presliding = opt(
            "seal_presliding_m",
            "a non-negative presliding displacement in m (0: none)",
            non_negative,
        )?;
        let f_c = f_c.unwrap_or(0.0);
        let f_s = f_s.unwrap_or(f_c);
        if f_c > 0.0 || f_s > 0.0 {
            let d = SealFriction::coulomb(f_c);
            e.friction = Some(SealFriction {
                f_c,
                f_s,
                v_s: v_s.unwrap_or(d.v_s),
                v_eps: v_eps.unwrap_or(d.v_eps),
                presliding_m: presliding.unwrap_or(0.0),
            });
        } else if presliding.is_some_and(|x| x > 0.0) {
            return Err(cx.bad(
                &format!("{p}.seal_presliding_m"),
                &t["seal_presliding_m"],
                "presliding belongs to the seal friction: give seal_friction_N too",
            ));
        }
        if let Some(g) = gap.filter(|g| *g > 0.0) {
            e.free_play = Some(FreePlay { gap: g });
        }
        if let Some(a) = air.filter(|a| *a > 0.0) {
            if c.p_s <= 0.0 {
                return Err(cx.bad(
                    &format!("{p}.air_fraction"),
                    &t["air_fraction"],
                    "entrained air is given at the background pressure p_s_Pa, which must then be positive",
                ));
            }
            c.ext.air = Some(EntrainedAir {
                fraction: a,
                p_ref: c.p_s,
            });
        }
        if let Some(k) = leak.filter(|k| *k > 0.0) {
            c.ext.leakage = Some(AnnularLeakage {
                conductance: k,
                viscosity_length: mu_l.unwrap_or(0.0),
            });
        }
        for ch in 0..2 {
            let key = format!("air_fraction_{ch}");
            let v = opt(&key, "a volume fraction in [0, 1)", |x| {
                (0.0..1.0).contains(&x)
            })?;
            if let Some(a) = v.filter(|a| *a > 0.0) {
                if c.p_s <= 0.0 {
                    return Err(cx.bad(
                        &format!("{p}.{key}"),
                        &t[key.as_str()],
                        "entrained air is given at the background pressure p_s_Pa, which must then be positive",
                    ));
                }
                c.ext.air_by_chamber[ch] = Some(EntrainedAir {
                    fraction: a,
                    p_ref: c.p_s,
                });
            }
        }
        Ok(e)
    }

    /// Physical values of the `[damper.physical]` table beyond the usual, each with its key and
    /// the reason: said beside a failure of the physical model, whose message alone (a
    /// non-finite state, a Newton failure) cannot name the deck value behind it. Validation
    /// accepts them: a research deck may go there on purpose.
    pub fn physical_review(&self) -> Vec<String> {
        let mut v = vec![];
        let Some(c) = &self.physical else { return v };
        let b = 1.0 / c.fluid.alpha;
        if b > 1e12 {
            v.push(format!(
                "damper.physical.bulk_alpha_per_Pa = {:e} /Pa is a bulk modulus of {b:.3e} Pa, \
                 stiffer than any solid (steel 1.6e11 Pa; hydraulic oils 1-2e9 Pa)",
                c.fluid.alpha
            ));
        } else if b < 1e7 {
            v.push(format!(
                "damper.physical.bulk_alpha_per_Pa = {:e} /Pa is a bulk modulus of {b:.3e} Pa, \
                 softer than oil holding much air (hydraulic oils 1-2e9 Pa)",
                c.fluid.alpha
            ));
        }
        for (k, ch) in c.chambers.iter().enumerate() {
            let travel = ch.volume0 / ch.area;
            if travel < 1e-3 {
                v.push(format!(
                    "damper.physical.V{k}_m3 / A{k}_m2 = {:e} m^3 / {:e} m^2 gives chamber {k} a \
                     travel of {travel:.3e} m, below a millimetre (a lead-lag damper strokes \
                     about 10 mm either way)",
                    ch.volume0, ch.area
                ));
            }
        }
        v
    }

    /// Refuses a stroke history reaching `max_stroke_m` (either way; `what` names it) that
    /// empties a chamber of the physical table: `A |d| >= V` (Eq. 2).
    pub fn check_stroke(&self, max_stroke_m: f64, what: &str) -> Result<(), String> {
        let Some(c) = &self.physical else {
            return Ok(());
        };
        for (k, ch) in c.chambers.iter().enumerate() {
            let travel = ch.volume0 / ch.area;
            if max_stroke_m >= travel {
                return Err(format!(
                    "{what}: a stroke of {max_stroke_m:.4e} m empties chamber {k} of the damper \
                     deck {}: its travel is damper.physical.V{k}_m3 / A{k}_m2 = {:e} m^3 / {:e} \
                     m^2 = {travel:.4e} m (Eq. 2: V = V0 + A lambda d must stay positive); check \
                     the areas and volumes, or the stroke's units",
                    self.source, ch.volume0, ch.area
                ));
            }
        }
        Ok(())
    }

    /// `error` with the deck's [`DamperDeck::physical_review`] beside it, when it has one.
    pub fn with_review(&self, error: String) -> String {
        let r = self.physical_review();
        if r.is_empty() {
            error
        } else {
            format!(
                "{error}; the damper deck {} has values beyond the usual: {}",
                self.source,
                r.join("; ")
            )
        }
    }

    /// Errors unless the deck holds the table of `model`.
    pub fn require(&self, model: DamperModel) -> Result<(), DeckError> {
        let present = match model {
            DamperModel::Physical => self.physical.is_some(),
            DamperModel::Linear => self.linear_c_n_s_per_m.is_some(),
            DamperModel::Nonlinear => self.nonlinear.is_some(),
        };
        if present {
            Ok(())
        } else {
            Err(DeckError::MissingTable {
                file: self.source.clone(),
                table: format!("damper.{}", model.name()),
            })
        }
    }

    /// Builds a device of the given model (errors when the deck lacks that model's table).
    pub fn build(
        &self,
        model: DamperModel,
        opts: IntegratorOptions,
    ) -> Result<Box<dyn Device>, DeckError> {
        self.require(model)?;
        Ok(match model {
            DamperModel::Physical => {
                let dev = self.physical_device(opts)?;
                let e = self.extensions;
                // A contact stiffness turns the rigid gap into the compliant one (outside friction).
                let rigid_play = e
                    .free_play
                    .filter(|_| e.free_play_contact_stiffness_n_per_m.is_none());
                // One link (compliant free play or mount) on the bare circuit, explicit scheme:
                // integrated with the circuit as one ODE, one integration per step.
                let link = match (
                    e.free_play_contact_stiffness_n_per_m,
                    e.mount_stiffness_n_per_m,
                ) {
                    (Some(k), None) => Some((e.free_play.map_or(0.0, |p| p.gap), k)),
                    (None, Some(k)) => Some((0.0, k)),
                    _ => None,
                };
                let one_ode = e.friction.is_none() && rigid_play.is_none();
                if let Some((gap, k)) = link.filter(|_| one_ode && opts.scheme == Scheme::Rk4) {
                    let linked = LinkedCircuit::new(dev, gap, k);
                    return Ok(Box::new(match e.link_mass {
                        Some(m) => linked.with_mass(m),
                        None => linked,
                    }));
                }
                let two_links = e.free_play_contact_stiffness_n_per_m.is_some()
                    && e.mount_stiffness_n_per_m.is_some();
                // Without a link the moving mass moves with the end (its m a is left out).
                if e.link_mass.is_some() && (link.is_some() || two_links) {
                    let why = if two_links {
                        "a moving mass needs one link: a compliant free play or a mount, not both"
                    } else if !one_ode {
                        "a moving mass is modelled on the bare circuit: no seal friction or rigid gap beside it"
                    } else {
                        "a moving mass is integrated by RK4 only (scheme rk4)"
                    };
                    return Err(DeckError::BadValue {
                        file: self.source.clone(),
                        key: "damper.physical.extensions.link_mass_kg".into(),
                        value: format!("{}", e.link_mass.map_or(0.0, |m| m.mass_kg)),
                        expected: why.into(),
                    });
                }
                let dev: Box<dyn Device> = if e.friction.is_some() || rigid_play.is_some() {
                    Box::new(ExtendedDamper::new(dev, e.friction, rigid_play))
                } else {
                    Box::new(dev)
                };
                let dev: Box<dyn Device> = match e.free_play_contact_stiffness_n_per_m {
                    Some(k) => Box::new(CompliantFreePlay::new(
                        dev,
                        e.free_play.map_or(0.0, |p| p.gap),
                        k,
                    )),
                    None => dev,
                };
                match e.mount_stiffness_n_per_m {
                    Some(k) => Box::new(SeriesMount::new(dev, k)),
                    None => dev,
                }
            }
            DamperModel::Linear => Box::new(LinearDashpot::new(
                self.linear_c_n_s_per_m.unwrap_or_default(),
            )),
            DamperModel::Nonlinear => {
                let (v, f) = self.nonlinear.clone().unwrap_or_default();
                let table = MonotoneTable::new(v, f).map_err(|e| DeckError::BadValue {
                    file: self.source.clone(),
                    key: "damper.nonlinear".into(),
                    value: String::new(),
                    expected: e,
                })?;
                Box::new(NonlinearDashpot::new(table))
            }
        })
    }

    /// The physical model as a concrete device (for access to its parameters and state).
    pub fn physical_device(&self, opts: IntegratorOptions) -> Result<CircuitDevice, DeckError> {
        self.require(DamperModel::Physical)?;
        let params = self
            .physical
            .clone()
            .ok_or_else(|| DeckError::MissingTable {
                file: self.source.clone(),
                table: "damper.physical".into(),
            })?;
        Ok(CircuitDevice::new(params, opts))
    }
}

impl DamperDeck {
    /// The deck as TOML (`[damper]` of docs/formats.md plus `[damper.physical.extensions]` where
    /// any extension is on), readable by [`DamperDeck::from_toml_str`]; numbers use the shortest
    /// round-trip formatting, so the deck reads back to the same values.
    pub fn to_toml(&self) -> String {
        use std::fmt::Write as _;
        let mut s = String::new();
        let _ = writeln!(s, "[damper]\nmodel = \"{}\"", self.model.name());
        if let Some(c) = self.linear_c_n_s_per_m {
            let _ = writeln!(s, "\n[damper.linear]\nc_N_s_per_m = {}", num(c));
        }
        if let Some((v, f)) = &self.nonlinear {
            let _ = writeln!(
                s,
                "\n[damper.nonlinear]\nvelocity_m_s = {}\nforce_N = {}",
                arr(v),
                arr(f)
            );
        }
        if let Some(c) = &self.physical {
            let cd = c
                .orifice
                .map(|o| o.cd)
                .or(c.check.map(|v| v.cd))
                .or(c.relief.iter().flatten().next().map(|r| r.cd))
                .unwrap_or(0.611);
            let kv = [
                ("A0_m2", c.chambers[0].area),
                ("A1_m2", c.chambers[1].area),
                ("V0_m3", c.chambers[0].volume0),
                ("V1_m3", c.chambers[1].volume0),
                ("rho_kg_m3", c.fluid.rho),
                ("bulk_alpha_per_Pa", c.fluid.alpha),
                ("bulk_beta_per_Pa2", c.fluid.beta),
                ("A_orf_m2", c.orifice.map_or(0.0, |o| o.area)),
                ("Cd", cd),
                ("p_s_Pa", c.p_s),
                ("dp_laminar_Pa", c.dp_laminar),
                ("check_valve_area_m2", c.check.map_or(0.0, |v| v.area)),
                ("p_cav_Pa", c.fluid.p_cav),
            ];
            s.push_str("\n[damper.physical]\n");
            for (k, v) in kv {
                let _ = writeln!(s, "{k} = {}", num(v));
            }
            for (k, rv) in c.relief.iter().enumerate() {
                let Some(r) = rv else { continue };
                let _ = writeln!(s, "\n[damper.physical.relief_valve_{k}]");
                for (key, v) in [
                    ("m_kg", r.m),
                    ("c_N_s_per_m", r.c),
                    ("k_N_per_m", r.k),
                    ("F_p_N", r.f_p),
                    ("A_front_m2", r.a_front),
                    ("A_back_m2", r.a_back),
                    ("a_m", r.a),
                    ("b", r.b),
                ] {
                    let _ = writeln!(s, "{key} = {}", num(v));
                }
            }
            let e = &self.extensions;
            let mut ext = Vec::new();
            if let Some(f) = e.friction {
                ext.push(("seal_friction_N", f.f_c));
                ext.push(("stribeck_static_N", f.f_s));
                ext.push(("stribeck_velocity_m_s", f.v_s));
                ext.push(("friction_smoothing_m_s", f.v_eps));
                if f.has_presliding() {
                    ext.push(("seal_presliding_m", f.presliding_m));
                }
            }
            if let Some(p) = e.free_play {
                ext.push(("free_play_m", p.gap));
            }
            if let Some(k) = e.free_play_contact_stiffness_n_per_m {
                ext.push(("free_play_contact_stiffness_N_per_m", k));
            }
            if let Some(k) = e.mount_stiffness_n_per_m {
                ext.push(("mount_stiffness_N_per_m", k));
            }
            if let Some(m) = e.link_mass {
                ext.push(("link_mass_kg", m.mass_kg));
                ext.push(("link_damping_ratio", m.damping_ratio));
            }
            if let Some(a) = c.ext.air {
                ext.push(("air_fraction", a.fraction));
            }
            if let Some(l) = c.ext.leakage {
                ext.push(("leakage_m3_per_s_Pa", l.conductance));
                if l.viscosity_length > 0.0 {
                    ext.push(("leakage_viscosity_length_Pa_s_m", l.viscosity_length));
                }
            }
            for (ch, a) in c.ext.air_by_chamber.iter().enumerate() {
                if let Some(a) = a {
                    ext.push((["air_fraction_0", "air_fraction_1"][ch], a.fraction));
                }
            }
            if let Some(l) = c.ext.bleed {
                ext.push(("accumulator_bleed_m3_per_s_Pa", l.conductance));
            }
            if !ext.is_empty() {
                s.push_str("\n[damper.physical.extensions]\n");
                for (k, v) in ext {
                    let _ = writeln!(s, "{k} = {}", num(v));
                }
            }
            if let Some(o) = &self.oil {
                // The properties above hold at the law's temperature: that is their reference.
                s.push_str("\n[damper.physical.oil]\n");
                for (k, v) in [
                    ("reference_temperature_K", o.temperature_k),
                    ("density_thermal_coefficient_per_K", o.density_per_k),
                    (
                        "bulk_modulus_thermal_coefficient_per_K",
                        o.bulk_modulus_per_k,
                    ),
                    ("viscosity_thermal_coefficient_per_K", o.viscosity_per_k),
                ] {
                    let _ = writeln!(s, "{k} = {}", num(v));
                }
            }
        }
        s
    }
}

/// Shortest round-trip float, always with a decimal point or exponent (TOML float).
fn num(x: f64) -> String {
    let s = format!("{x:?}");
    if s.contains('.') || s.contains('e') || s.contains("inf") || s.contains("NaN") {
        s
    } else {
        format!("{s}.0")
    }
}

fn arr(v: &[f64]) -> String {
    format!(
        "[{}]",
        v.iter().map(|x| num(*x)).collect::<Vec<_>>().join(", ")
    )
}

pub const ACTUATOR_KEYS: &[&str] = &[
    "A0_m2",
    "A1_m2",
    "V0_m3",
    "V1_m3",
    "p_E0_Pa",
    "p_E1_Pa",
    "A_orf0_m2",
    "A_orf1_m2",
    "Cd0",
    "Cd1",
    "p_s_Pa",
    "B_Pa",
    "rho_kg_m3",
    "check_valve_area_m2",
    "dp_laminar_Pa",
];

/// Reads the linear actuator of an `[actuator]` table (keys: [`ACTUATOR_KEYS`]; paper Table 1
/// names with units; `dp_laminar_Pa` optional). Other top-level tables are ignored.
pub fn actuator_from_toml_str(text: &str, source_name: &str) -> Result<ActuatorParams, DeckError> {
    let cx = Ctx { file: source_name };
    let root: Table = text
        .parse()
        .map_err(|e: toml::de::Error| DeckError::Parse {
            file: source_name.into(),
            message: e.to_string().trim_end().to_string(),
        })?;
    let p = "actuator";
    let t = cx
        .table(&root, "", p)?
        .ok_or_else(|| DeckError::MissingTable {
            file: source_name.into(),
            table: p.into(),
        })?;
    cx.known(t, p, ACTUATOR_KEYS)?;
    let pos = |k: &str, what: &str| cx.num_where(t, p, k, what, positive);
    let nonneg = |k: &str, what: &str| cx.num_where(t, p, k, what, non_negative);
    let cd = |k: &str| {
        cx.num_where(t, p, k, "a discharge coefficient in (0, 1]", |x| {
            x > 0.0 && x <= 1.0
        })
    };
    Ok(ActuatorParams {
        area_m2: [
            pos("A0_m2", "a positive area in m^2")?,
            pos("A1_m2", "a positive area in m^2")?,
        ],
        volume0_m3: [
            pos("V0_m3", "a positive volume in m^3")?,
            pos("V1_m3", "a positive volume in m^3")?,
        ],
        p_entrance_pa: [
            nonneg("p_E0_Pa", "a non-negative pressure in Pa")?,
            nonneg("p_E1_Pa", "a non-negative pressure in Pa")?,
        ],
        orifice_area_m2: [
            nonneg("A_orf0_m2", "a non-negative area in m^2")?,
            nonneg("A_orf1_m2", "a non-negative area in m^2")?,
        ],
        cd: [cd("Cd0")?, cd("Cd1")?],
        p_s_pa: nonneg("p_s_Pa", "a non-negative pressure in Pa")?,
        bulk_modulus_pa: pos("B_Pa", "a positive bulk modulus in Pa")?,
        rho_kg_m3: pos("rho_kg_m3", "a positive density in kg/m^3")?,
        check_valve_area_m2: nonneg(
            "check_valve_area_m2",
            "a non-negative area in m^2 (0 disables)",
        )?,
        dp_laminar_pa: if t.contains_key("dp_laminar_Pa") {
            pos("dp_laminar_Pa", "a positive pressure in Pa")?
        } else {
            DEFAULT_DP_LAMINAR_PA
        },
    })
}
