//! The damper deck of docs/formats.md: the `[damper]` table of any TOML file (other top-level tables
//! are ignored; unknown keys inside `[damper...]` tables are errors).
use super::circuit::{ActuatorParams, CircuitDevice, CircuitParams};
use super::dashpot::{LinearDashpot, MonotoneTable, NonlinearDashpot};
use super::elements::{Chamber, CheckValve, Orifice, OrificeViscosity, ReliefValve};
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
use serde::{Deserialize, Serialize};
use std::path::Path;
use toml::{Table, Value};

/// Default laminar transition of the flow laws when the deck omits `dp_laminar_Pa`.
pub const DEFAULT_DP_LAMINAR_PA: f64 = 1.0e3;
/// Default cavitation band when the deck omits `p_cav_Pa`.
pub const DEFAULT_P_CAV_PA: f64 = 1.0e4;

/// A deck error: which deck, the file, the key (a dotted path) and what was expected of it.
/// One type for every deck read here and above (rotor, damper, actuator, model decks).
#[derive(Debug, thiserror::Error)]
pub enum DeckError {
    /// The file cannot be read.
    #[error("{deck} {file}: cannot read: {source}")]
    Read {
        deck: &'static str,
        file: String,
        #[source]
        source: std::io::Error,
    },
    /// The file as a whole: not TOML, or a model beyond the budget.
    #[error("{deck} {file}: {message}")]
    File {
        deck: &'static str,
        file: String,
        message: String,
    },
    /// One key of the deck and what is wrong with it.
    #[error("{deck} {file}{}", problem.describe(key))]
    Key {
        deck: &'static str,
        file: String,
        key: String,
        problem: Problem,
    },
}

/// What is wrong with a key of a deck.
#[derive(Debug, Clone, PartialEq)]
pub enum Problem {
    /// The key names a table the deck must hold.
    MissingTable,
    /// A key the table must hold, and what it takes.
    Missing { expected: String },
    /// A key the table does not know, and the keys it knows.
    Unknown { known: String },
    /// The value as written, and what was expected.
    Bad { value: String, expected: String },
    /// A rule of the deck the key breaks.
    Invalid(String),
}

impl Problem {
    fn describe(&self, key: &str) -> String {
        match self {
            Self::MissingTable => format!(": missing table [{key}]"),
            Self::Missing { expected } => format!(": missing key `{key}` ({expected})"),
            Self::Unknown { known } => format!(": unknown key `{key}` (known keys: {known})"),
            Self::Bad { value, expected } if value.is_empty() => {
                format!(": key `{key}`: {expected}")
            }
            Self::Bad { value, expected } => format!(": key `{key}` = {value}: {expected}"),
            Self::Invalid(msg) => format!(", {key}: {msg}"),
        }
    }
}

/// How a deck is named in messages when the caller does not say which it is.
const DECK: &str = "deck";

impl DeckError {
    /// The file cannot be read.
    pub fn read(file: &str, source: std::io::Error) -> Self {
        Self::Read {
            deck: DECK,
            file: file.into(),
            source,
        }
    }
    /// The file as a whole (`message` says what is wrong).
    pub fn file(file: &str, message: impl Into<String>) -> Self {
        Self::File {
            deck: DECK,
            file: file.into(),
            message: message.into(),
        }
    }
    /// The same error, the deck named as `deck` ("rotor deck"): what the user passed it as.
    pub fn in_deck(mut self, name: &'static str) -> Self {
        match &mut self {
            Self::Read { deck, .. } | Self::File { deck, .. } | Self::Key { deck, .. } => {
                *deck = name
            }
        }
        self
    }
    pub fn key(file: &str, key: impl Into<String>, problem: Problem) -> Self {
        Self::Key {
            deck: DECK,
            file: file.into(),
            key: key.into(),
            problem,
        }
    }
    /// `key` breaks a rule of the deck (`msg` says which).
    pub fn invalid(file: &str, key: impl Into<String>, msg: impl Into<String>) -> Self {
        Self::key(file, key, Problem::Invalid(msg.into()))
    }
    fn bad(file: &str, key: impl Into<String>, value: String, expected: impl Into<String>) -> Self {
        let expected = expected.into();
        Self::key(file, key, Problem::Bad { value, expected })
    }
    fn missing_table(file: &str, table: &str) -> Self {
        Self::key(file, table, Problem::MissingTable)
    }
    /// TOML that does not parse (the message gives the line).
    pub fn syntax(file: &str, e: &toml::de::Error) -> Self {
        Self::file(
            file,
            format!("not valid TOML: {}", e.to_string().trim_end()),
        )
    }
    /// A serde error of the typed tables read from a parsed TOML table: the key path it names
    /// (the tables it sits in, then the field) and what serde expected.
    pub fn schema(file: &str, mut e: toml::de::Error) -> Self {
        let msg = e.message().trim_end().to_string();
        // Without its input the error shows the keys it was raised under: `in `a.b``.
        e.set_input(None);
        let shown = e.to_string();
        let path = shown
            .lines()
            .last()
            .and_then(|l| l.strip_prefix("in `")?.strip_suffix('`'))
            .unwrap_or("");
        let join = |leaf: &str| match path {
            "" => leaf.to_string(),
            p => format!("{p}.{leaf}"),
        };
        let quoted = |s: &str| s.split('`').nth(1).map(str::to_string);
        if let Some(rest) = msg.strip_prefix("unknown field ") {
            let name = quoted(rest).unwrap_or_default();
            let known = rest
                .split_once(", expected ")
                .map_or("", |(_, k)| k)
                .trim_start_matches("one of ")
                .replace('`', "");
            return Self::key(file, join(&name), Problem::Unknown { known });
        }
        if let Some(rest) = msg.strip_prefix("missing field ") {
            let name = quoted(rest).unwrap_or_default();
            let expected = "a value".to_string();
            return Self::key(file, join(&name), Problem::Missing { expected });
        }
        if let Some((found, wanted)) = msg
            .strip_prefix("invalid type: ")
            .and_then(|m| m.split_once(", expected "))
        {
            let wanted = match wanted {
                "f64" => "a number",
                "a sequence" => "an array",
                w if w.starts_with("struct ") => "a table",
                w => w,
            };
            return Self::bad(file, path, found.into(), format!("expected {wanted}"));
        }
        Self::bad(file, path, String::new(), msg)
    }
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
    /// The seal's presliding stiffness sigma0 [N/m] as `[damper.physical]` gives it with
    /// `seal_friction_N` (the Dahl friction of [`SealFriction::dahl`] in `friction`).
    pub seal_presliding_stiffness_n_per_m: Option<f64>,
}

/// The damper deck file as written: `[damper]` and its tables, keys with their units (other
/// top-level tables are ignored). Read by [`DamperDeck::from_toml_str`] (serde for the shape,
/// [`DamperDeck::from_file_tables`] for the values), written by [`DamperDeck::to_toml`].
#[derive(Debug, Clone, Default, Serialize, Deserialize)]
pub struct DamperFile {
    pub damper: Option<DamperTable>,
}

/// `[damper]`: the default model and the tables of the models the deck holds.
#[derive(Debug, Clone, Default, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct DamperTable {
    pub model: Option<String>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub linear: Option<LinearTable>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub nonlinear: Option<NonlinearTable>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub physical: Option<PhysicalTable>,
}

/// `[damper.linear]`.
#[derive(Debug, Clone, Default, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
#[allow(non_snake_case)]
pub struct LinearTable {
    pub c_N_s_per_m: Option<f64>,
}

/// `[damper.nonlinear]`: force against velocity.
#[derive(Debug, Clone, Default, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
#[allow(non_snake_case)]
pub struct NonlinearTable {
    pub velocity_m_s: Option<Vec<f64>>,
    pub force_N: Option<Vec<f64>>,
}

/// `[damper.physical]`: the two-chamber circuit (docs/formats.md). Options where the deck may
/// leave a key out; required keys are Options too, so that a missing one is reported with
/// what it takes.
#[derive(Debug, Clone, Default, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
#[allow(non_snake_case)]
pub struct PhysicalTable {
    pub A0_m2: Option<f64>,
    pub A1_m2: Option<f64>,
    pub V0_m3: Option<f64>,
    pub V1_m3: Option<f64>,
    pub rho_kg_m3: Option<f64>,
    pub bulk_alpha_per_Pa: Option<f64>,
    pub bulk_beta_per_Pa2: Option<f64>,
    pub A_orf_m2: Option<f64>,
    pub Cd: Option<f64>,
    pub p_s_Pa: Option<f64>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub dp_laminar_Pa: Option<f64>,
    pub check_valve_area_m2: Option<f64>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub p_cav_Pa: Option<f64>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub mu_Pa_s: Option<f64>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub orifice_length_m: Option<f64>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub seal_friction_N: Option<f64>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub seal_presliding_stiffness_N_per_m: Option<f64>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub relief_valve_0: Option<ReliefValveTable>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub relief_valve_1: Option<ReliefValveTable>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub extensions: Option<ExtensionsTable>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub oil: Option<OilTable>,
}

/// `[damper.physical.relief_valve_K]` (Eq. 5-7; the discharge coefficient is the deck's `Cd`).
#[derive(Debug, Clone, Default, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
#[allow(non_snake_case)]
pub struct ReliefValveTable {
    pub m_kg: Option<f64>,
    pub c_N_s_per_m: Option<f64>,
    pub k_N_per_m: Option<f64>,
    pub F_p_N: Option<f64>,
    pub A_front_m2: Option<f64>,
    pub A_back_m2: Option<f64>,
    pub a_m: Option<f64>,
    pub b: Option<f64>,
}

/// `[damper.physical.extensions]` (all optional; absent or 0 = off).
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
#[allow(non_snake_case)]
pub struct ExtensionsTable {
    #[serde(skip_serializing_if = "Option::is_none")]
    pub seal_friction_N: Option<f64>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub stribeck_static_N: Option<f64>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub stribeck_velocity_m_s: Option<f64>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub friction_smoothing_m_s: Option<f64>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub seal_presliding_m: Option<f64>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub free_play_m: Option<f64>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub free_play_contact_stiffness_N_per_m: Option<f64>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub mount_stiffness_N_per_m: Option<f64>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub link_mass_kg: Option<f64>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub link_damping_ratio: Option<f64>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub air_fraction: Option<f64>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub leakage_m3_per_s_Pa: Option<f64>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub leakage_viscosity_length_Pa_s_m: Option<f64>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub air_fraction_0: Option<f64>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub air_fraction_1: Option<f64>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub accumulator_bleed_m3_per_s_Pa: Option<f64>,
}

/// `[damper.physical.oil]`: the properties of `[damper.physical]` hold at
/// `reference_temperature_K`; the deck runs at `temperature_K` (default: the reference).
#[derive(Debug, Clone, Default, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
#[allow(non_snake_case)]
pub struct OilTable {
    pub reference_temperature_K: Option<f64>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub temperature_K: Option<f64>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub density_thermal_coefficient_per_K: Option<f64>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub bulk_modulus_thermal_coefficient_per_K: Option<f64>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub viscosity_thermal_coefficient_per_K: Option<f64>,
}

/// The actuator deck file: `[actuator]` (paper Table 1 names with units; other top-level tables
/// are ignored).
#[derive(Debug, Clone, Default, Serialize, Deserialize)]
pub struct ActuatorFile {
    pub actuator: Option<ActuatorTable>,
}

/// `[actuator]` (`dp_laminar_Pa` optional).
#[derive(Debug, Clone, Default, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
#[allow(non_snake_case)]
pub struct ActuatorTable {
    pub A0_m2: Option<f64>,
    pub A1_m2: Option<f64>,
    pub V0_m3: Option<f64>,
    pub V1_m3: Option<f64>,
    pub p_E0_Pa: Option<f64>,
    pub p_E1_Pa: Option<f64>,
    pub A_orf0_m2: Option<f64>,
    pub A_orf1_m2: Option<f64>,
    pub Cd0: Option<f64>,
    pub Cd1: Option<f64>,
    pub p_s_Pa: Option<f64>,
    pub B_Pa: Option<f64>,
    pub rho_kg_m3: Option<f64>,
    pub check_valve_area_m2: Option<f64>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub dp_laminar_Pa: Option<f64>,
}

/// Parses `text` as TOML and reads its tables into `T` (serde), errors naming `file` and the key.
pub fn read_tables<T: serde::de::DeserializeOwned>(text: &str, file: &str) -> Result<T, DeckError> {
    let root: Table = text.parse().map_err(|e| DeckError::syntax(file, &e))?;
    typed_tables(root, file)
}

/// Reads parsed TOML into `T` (serde), errors naming `file` and the key.
pub fn typed_tables<T: serde::de::DeserializeOwned>(
    root: Table,
    file: &str,
) -> Result<T, DeckError> {
    Value::Table(root)
        .try_into()
        .map_err(|e| DeckError::schema(file, e))
}

/// Values of one table checked against what they take, errors naming the file and the key.
struct Check<'a> {
    file: &'a str,
    table: &'a str,
}

impl Check<'_> {
    fn key(&self, k: &str) -> String {
        format!("{}.{k}", self.table)
    }

    /// A value the table must hold: finite and `ok` (`expected` says what it takes).
    fn req(
        &self,
        k: &str,
        v: Option<f64>,
        expected: &str,
        ok: fn(f64) -> bool,
    ) -> Result<f64, DeckError> {
        let Some(x) = v else {
            let expected = expected.into();
            return Err(DeckError::key(
                self.file,
                self.key(k),
                Problem::Missing { expected },
            ));
        };
        self.value(k, x, expected, ok)
    }

    /// A value the table may leave out.
    fn opt(
        &self,
        k: &str,
        v: Option<f64>,
        expected: &str,
        ok: fn(f64) -> bool,
    ) -> Result<Option<f64>, DeckError> {
        v.map(|x| self.value(k, x, expected, ok)).transpose()
    }

    fn value(
        &self,
        k: &str,
        x: f64,
        expected: &str,
        ok: fn(f64) -> bool,
    ) -> Result<f64, DeckError> {
        if !x.is_finite() {
            let e = format!("expected a finite number ({expected})");
            return Err(self.bad(k, x, e));
        }
        if !ok(x) {
            return Err(self.bad(k, x, format!("expected {expected}")));
        }
        Ok(x)
    }

    fn bad(&self, k: &str, x: f64, expected: impl Into<String>) -> DeckError {
        DeckError::bad(self.file, self.key(k), shown(x), expected)
    }

    /// An array of finite numbers the table must hold.
    fn array(&self, k: &str, v: &Option<Vec<f64>>) -> Result<Vec<f64>, DeckError> {
        let expected = "array of numbers";
        let Some(v) = v else {
            let expected = "an array of numbers".into();
            return Err(DeckError::key(
                self.file,
                self.key(k),
                Problem::Missing { expected },
            ));
        };
        for x in v {
            self.value(k, *x, expected, |_| true)?;
        }
        Ok(v.clone())
    }
}

/// A number as TOML writes it (for messages).
fn shown(x: f64) -> String {
    Value::Float(x).to_string()
}

fn positive(x: f64) -> bool {
    x > 0.0
}
fn non_negative(x: f64) -> bool {
    x >= 0.0
}
fn discharge(x: f64) -> bool {
    x > 0.0 && x <= 1.0
}
fn fraction(x: f64) -> bool {
    (0.0..1.0).contains(&x)
}

impl DamperDeck {
    /// Reads a deck file.
    pub fn from_file(path: &Path) -> Result<Self, DeckError> {
        let file = path.display().to_string();
        let text =
            std::fs::read_to_string(path).map_err(|source| DeckError::read(&file, source))?;
        Self::from_toml_str(&text, &file)
    }

    /// Parses deck text; `source_name` names it in errors.
    pub fn from_toml_str(text: &str, source_name: &str) -> Result<Self, DeckError> {
        let tables: DamperFile = read_tables(text, source_name)?;
        Self::from_file_tables(&tables, source_name)
    }

    /// Reads the `[damper]` table of parsed TOML (other top-level tables are ignored).
    pub fn from_toml_table(root: Table, source_name: &str) -> Result<Self, DeckError> {
        let tables: DamperFile = typed_tables(root, source_name)?;
        Self::from_file_tables(&tables, source_name)
    }

    /// The deck of the typed tables `f`, each value checked; `file` names it in errors.
    pub fn from_file_tables(f: &DamperFile, file: &str) -> Result<Self, DeckError> {
        let damper = f
            .damper
            .as_ref()
            .ok_or_else(|| DeckError::missing_table(file, "damper"))?;
        let model = match &damper.model {
            None => {
                let expected = "physical, linear or nonlinear".into();
                let problem = Problem::Missing { expected };
                return Err(DeckError::key(file, "damper.model", problem));
            }
            Some(s) => s.parse::<DamperModel>().map_err(|e| {
                DeckError::bad(
                    file,
                    "damper.model",
                    Value::String(s.clone()).to_string(),
                    e,
                )
            })?,
        };
        let linear = match &damper.linear {
            None => None,
            Some(t) => Some(
                Check {
                    file,
                    table: "damper.linear",
                }
                .req(
                    "c_N_s_per_m",
                    t.c_N_s_per_m,
                    "a non-negative damping coefficient (0: an inoperative damper)",
                    non_negative,
                )?,
            ),
        };
        let nonlinear = match &damper.nonlinear {
            None => None,
            Some(t) => {
                let p = "damper.nonlinear";
                let cx = Check { file, table: p };
                let v = cx.array("velocity_m_s", &t.velocity_m_s)?;
                let f = cx.array("force_N", &t.force_N)?;
                MonotoneTable::new(v.clone(), f.clone()).map_err(|e| {
                    let key = format!("{p}.velocity_m_s/force_N");
                    DeckError::bad(file, key, format!("{v:?} / {f:?}"), e)
                })?;
                Some((v, f))
            }
        };
        let (physical, extensions, oil) = match &damper.physical {
            None => (None, DeviceExtensions::default(), None),
            Some(t) => {
                let mut c = physical_params(file, t)?;
                let mut e = match &t.extensions {
                    None => DeviceExtensions::default(),
                    Some(et) => extensions(file, et, &mut c)?,
                };
                seal_dahl(file, t, &mut e)?;
                // After the extensions: the leakage and bleed move with the temperature too.
                let oil = match &t.oil {
                    None => None,
                    Some(ot) => Some(oil_law(file, ot, &mut c)?),
                };
                (Some(c), e, oil)
            }
        };
        let deck = Self {
            source: file.into(),
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
}

/// The circuit of `[damper.physical]` (its extensions and oil are read after it).
fn physical_params(file: &str, t: &PhysicalTable) -> Result<CircuitParams, DeckError> {
    let p = "damper.physical";
    let cx = Check { file, table: p };
    let area = |k, v| cx.req(k, v, "a positive area in m^2", positive);
    let vol = |k, v| cx.req(k, v, "a positive volume in m^3", positive);
    let a0 = area("A0_m2", t.A0_m2)?;
    let a1 = area("A1_m2", t.A1_m2)?;
    let v0 = vol("V0_m3", t.V0_m3)?;
    let v1 = vol("V1_m3", t.V1_m3)?;
    let rho = cx.req(
        "rho_kg_m3",
        t.rho_kg_m3,
        "a positive density in kg/m^3",
        positive,
    )?;
    let alpha = cx.req(
        "bulk_alpha_per_Pa",
        t.bulk_alpha_per_Pa,
        "a positive alpha in 1/Pa (Eq. 3)",
        positive,
    )?;
    let beta = cx.req(
        "bulk_beta_per_Pa2",
        t.bulk_beta_per_Pa2,
        "a non-negative beta in 1/Pa^2 (Eq. 3)",
        non_negative,
    )?;
    let a_orf = cx.req(
        "A_orf_m2",
        t.A_orf_m2,
        "a non-negative orifice area in m^2",
        non_negative,
    )?;
    let cd = cx.req("Cd", t.Cd, "a discharge coefficient in (0, 1]", discharge)?;
    let p_s = cx.req(
        "p_s_Pa",
        t.p_s_Pa,
        "a non-negative background pressure in Pa",
        non_negative,
    )?;
    let dp_l = cx
        .opt(
            "dp_laminar_Pa",
            t.dp_laminar_Pa,
            "a positive pressure in Pa",
            positive,
        )?
        .unwrap_or(DEFAULT_DP_LAMINAR_PA);
    let p_cav = cx
        .opt(
            "p_cav_Pa",
            t.p_cav_Pa,
            "a non-negative pressure in Pa (0 disables)",
            non_negative,
        )?
        .unwrap_or(DEFAULT_P_CAV_PA);
    let cva = cx.req(
        "check_valve_area_m2",
        t.check_valve_area_m2,
        "a non-negative area in m^2 (0 disables)",
        non_negative,
    )?;
    let viscosity = orifice_viscosity(&cx, t)?;
    let mut relief = [None, None];
    for (k, (r, vt)) in relief
        .iter_mut()
        .zip([&t.relief_valve_0, &t.relief_valve_1])
        .enumerate()
    {
        let Some(vt) = vt else { continue };
        let vp = format!("{p}.relief_valve_{k}");
        let cx = Check { file, table: &vp };
        let pos = |key, v, what: &str| cx.req(key, v, what, positive);
        let nonneg = |key, v, what: &str| cx.req(key, v, what, non_negative);
        *r = Some(ReliefValve {
            m: pos("m_kg", vt.m_kg, "a positive poppet mass in kg")?,
            c: nonneg(
                "c_N_s_per_m",
                vt.c_N_s_per_m,
                "a non-negative poppet damping in N s/m",
            )?,
            k: pos(
                "k_N_per_m",
                vt.k_N_per_m,
                "a positive spring constant in N/m",
            )?,
            f_p: nonneg("F_p_N", vt.F_p_N, "a non-negative preload in N")?,
            a_front: pos("A_front_m2", vt.A_front_m2, "a positive area in m^2")?,
            a_back: nonneg("A_back_m2", vt.A_back_m2, "a non-negative area in m^2")?,
            a: nonneg("a_m", vt.a_m, "a non-negative coefficient in m (Eq. 7)")?,
            b: nonneg("b", vt.b, "a non-negative coefficient (Eq. 7)")?,
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
        ext: HydraulicExtensions {
            orifice_viscosity: viscosity,
            ..Default::default()
        },
    })
}

/// Largest oil viscosity that makes sense [Pa s] (MIL-PRF-5606 at -54 C is ~2.5e3 mm^2/s,
/// about 2.2 Pa s).
pub const MU_MAX_PA_S: f64 = 10.0;
/// Largest orifice bore length that makes sense [m].
pub const ORIFICE_LENGTH_MAX_M: f64 = 1.0;

/// `mu_Pa_s` and `orifice_length_m` of `[damper.physical]`: both (the orifice's
/// laminar-to-turbulent law) or neither (Eq. 4 regularised below `dp_laminar_Pa`).
fn orifice_viscosity(cx: &Check, t: &PhysicalTable) -> Result<Option<OrificeViscosity>, DeckError> {
    let mu = cx.opt(
        "mu_Pa_s",
        t.mu_Pa_s,
        "a dynamic viscosity in Pa s, above 0 and below 10",
        |x| x > 0.0 && x < MU_MAX_PA_S,
    )?;
    let length = cx.opt(
        "orifice_length_m",
        t.orifice_length_m,
        "an orifice bore length in m, at least 0 and below 1",
        |x| (0.0..ORIFICE_LENGTH_MAX_M).contains(&x),
    )?;
    match (mu, length) {
        (Some(mu), Some(length)) => Ok(Some(OrificeViscosity { mu, length })),
        (None, None) => Ok(None),
        (Some(mu), None) => Err(cx.bad(
            "mu_Pa_s",
            mu,
            "the orifice's viscous law needs its bore too: give orifice_length_m (0 for a sharp edge) with mu_Pa_s",
        )),
        (None, Some(l)) => Err(cx.bad(
            "orifice_length_m",
            l,
            "the orifice's viscous law needs the oil's viscosity too: give mu_Pa_s with orifice_length_m",
        )),
    }
}

/// `seal_friction_N` and `seal_presliding_stiffness_N_per_m` of `[damper.physical]`: the
/// seal's Dahl friction (0 or absent: none), set on `e` unless `[damper.physical.extensions]`
/// gives a seal friction of its own, which takes its place.
fn seal_dahl(file: &str, t: &PhysicalTable, e: &mut DeviceExtensions) -> Result<(), DeckError> {
    let cx = Check {
        file,
        table: "damper.physical",
    };
    let f_c = cx.opt(
        "seal_friction_N",
        t.seal_friction_N,
        "a non-negative force in N (0: no seal friction)",
        non_negative,
    )?;
    let sigma0 = cx.opt(
        "seal_presliding_stiffness_N_per_m",
        t.seal_presliding_stiffness_N_per_m,
        "a positive stiffness in N/m",
        positive,
    )?;
    match (f_c.filter(|f| *f > 0.0), sigma0) {
        (Some(f), Some(k)) => {
            // a friction law of the extensions (e.g. one a diagnosis fitted) takes the place of
            // the data sheet's
            if e.friction.is_none() {
                e.friction = Some(SealFriction::dahl(f, k));
                e.seal_presliding_stiffness_n_per_m = Some(k);
            }
            Ok(())
        }
        (Some(f), None) => Err(cx.bad(
            "seal_friction_N",
            f,
            "a seal friction needs its presliding stiffness: give seal_presliding_stiffness_N_per_m (N/m) too",
        )),
        (None, Some(k)) if f_c.is_none() => Err(cx.bad(
            "seal_presliding_stiffness_N_per_m",
            k,
            "the presliding stiffness belongs to the seal friction: give seal_friction_N too",
        )),
        _ => Ok(()),
    }
}

/// `[damper.physical.oil]`: the properties above hold at `reference_temperature_K`; they are
/// moved to `temperature_K` (default: the reference).
fn oil_law(file: &str, t: &OilTable, c: &mut CircuitParams) -> Result<OilTemperature, DeckError> {
    let cx = Check {
        file,
        table: "damper.physical.oil",
    };
    let kelvin = oil_temperature_expected();
    let t_ref = cx.req(
        "reference_temperature_K",
        t.reference_temperature_K,
        &kelvin,
        is_oil_temperature_k,
    )?;
    let t_run = cx
        .opt(
            "temperature_K",
            t.temperature_K,
            &kelvin,
            is_oil_temperature_k,
        )?
        .unwrap_or(t_ref);
    let coef = |k, v| -> Result<f64, DeckError> {
        let ok = |x| (0.0..=OIL_COEFFICIENT_MAX_PER_K).contains(&x);
        Ok(cx
            .opt(k, v, "a coefficient in 1/K, 0 to 0.1", ok)?
            .unwrap_or(0.0))
    };
    let law = OilTemperature {
        temperature_k: t_ref,
        density_per_k: coef(
            "density_thermal_coefficient_per_K",
            t.density_thermal_coefficient_per_K,
        )?,
        bulk_modulus_per_k: coef(
            "bulk_modulus_thermal_coefficient_per_K",
            t.bulk_modulus_thermal_coefficient_per_K,
        )?,
        viscosity_per_k: coef(
            "viscosity_thermal_coefficient_per_K",
            t.viscosity_thermal_coefficient_per_K,
        )?,
    };
    Ok(law.move_to(c, t_run))
}

/// `[damper.physical.extensions]`: the device-level ones returned, the hydraulic ones (air,
/// leakage, bleed) set on `c`.
fn extensions(
    file: &str,
    t: &ExtensionsTable,
    c: &mut CircuitParams,
) -> Result<DeviceExtensions, DeckError> {
    let p = "damper.physical.extensions";
    let cx = Check { file, table: p };
    let force = "a non-negative force in N";
    let velocity = "a positive velocity in m/s";
    let f_c = cx.opt("seal_friction_N", t.seal_friction_N, force, non_negative)?;
    let f_s = cx.opt(
        "stribeck_static_N",
        t.stribeck_static_N,
        force,
        non_negative,
    )?;
    let v_s = cx.opt(
        "stribeck_velocity_m_s",
        t.stribeck_velocity_m_s,
        velocity,
        positive,
    )?;
    let v_eps = cx.opt(
        "friction_smoothing_m_s",
        t.friction_smoothing_m_s,
        velocity,
        positive,
    )?;
    let gap = cx.opt(
        "free_play_m",
        t.free_play_m,
        "a non-negative gap in m",
        non_negative,
    )?;
    let volume_fraction = "a volume fraction in [0, 1)";
    let air = cx.opt("air_fraction", t.air_fraction, volume_fraction, fraction)?;
    let conductance = "a non-negative conductance in m^3/(s Pa)";
    let leak = cx.opt(
        "leakage_m3_per_s_Pa",
        t.leakage_m3_per_s_Pa,
        conductance,
        non_negative,
    )?;
    let mu_l = cx.opt(
        "leakage_viscosity_length_Pa_s_m",
        t.leakage_viscosity_length_Pa_s_m,
        "a non-negative viscosity times seal land length in Pa s m",
        non_negative,
    )?;
    let bleed = cx.opt(
        "accumulator_bleed_m3_per_s_Pa",
        t.accumulator_bleed_m3_per_s_Pa,
        conductance,
        non_negative,
    )?;
    if let Some(k) = bleed.filter(|k| *k > 0.0) {
        c.ext.bleed = Some(Leakage { conductance: k });
    }
    let mut e = DeviceExtensions {
        mount_stiffness_n_per_m: cx.opt(
            "mount_stiffness_N_per_m",
            t.mount_stiffness_N_per_m,
            "a positive stiffness in N/m (absent: rigid mounts)",
            positive,
        )?,
        free_play_contact_stiffness_n_per_m: cx.opt(
            "free_play_contact_stiffness_N_per_m",
            t.free_play_contact_stiffness_N_per_m,
            "a positive stiffness in N/m (absent: a rigid gap)",
            positive,
        )?,
        ..Default::default()
    };
    e.link_mass = link_mass(&cx, t)?;
    let presliding = cx.opt(
        "seal_presliding_m",
        t.seal_presliding_m,
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
    } else if let Some(x) = presliding.filter(|x| *x > 0.0) {
        return Err(cx.bad(
            "seal_presliding_m",
            x,
            "presliding belongs to the seal friction: give seal_friction_N too",
        ));
    }
    if let Some(g) = gap.filter(|g| *g > 0.0) {
        e.free_play = Some(FreePlay { gap: g });
    }
    hydraulic_extensions(&cx, t, c, air, leak, mu_l)?;
    Ok(e)
}

/// The link's moving mass and its damping (a fraction of critical against that mass).
fn link_mass(cx: &Check, t: &ExtensionsTable) -> Result<Option<LinkMass>, DeckError> {
    let mass = cx.opt(
        "link_mass_kg",
        t.link_mass_kg,
        "a positive mass in kg",
        positive,
    )?;
    let zeta = cx.opt(
        "link_damping_ratio",
        t.link_damping_ratio,
        "a non-negative fraction of critical damping",
        non_negative,
    )?;
    match (mass, zeta) {
        (Some(m), z) => Ok(Some(LinkMass {
            mass_kg: m,
            damping_ratio: z.unwrap_or(0.0),
        })),
        (None, Some(z)) => Err(cx.bad(
                "link_damping_ratio",
                z,
                "the link's damping is a fraction of critical against its moving mass: give link_mass_kg too",
            )),
        (None, None) => Ok(None),
    }
}

/// Entrained air (whole damper and by chamber) and annular leakage, set on `c`.
fn hydraulic_extensions(
    cx: &Check,
    t: &ExtensionsTable,
    c: &mut CircuitParams,
    air: Option<f64>,
    leak: Option<f64>,
    mu_l: Option<f64>,
) -> Result<(), DeckError> {
    let volume_fraction = "a volume fraction in [0, 1)";
    // Entrained air is given at the background pressure, which must then be positive.
    let p_s = c.p_s;
    let at_p_s = |key: &str, a: f64| {
        if p_s <= 0.0 {
            return Err(cx.bad(
                key,
                a,
                "entrained air is given at the background pressure p_s_Pa, which must then be positive",
            ));
        }
        Ok(EntrainedAir {
            fraction: a,
            p_ref: p_s,
        })
    };
    if let Some(a) = air.filter(|a| *a > 0.0) {
        c.ext.air = Some(at_p_s("air_fraction", a)?);
    }
    if let Some(k) = leak.filter(|k| *k > 0.0) {
        c.ext.leakage = Some(AnnularLeakage {
            conductance: k,
            viscosity_length: mu_l.unwrap_or(0.0),
        });
    }
    let by_chamber = [
        ("air_fraction_0", t.air_fraction_0),
        ("air_fraction_1", t.air_fraction_1),
    ];
    for (ch, (key, v)) in by_chamber.into_iter().enumerate() {
        if let Some(a) = cx
            .opt(key, v, volume_fraction, fraction)?
            .filter(|a| *a > 0.0)
        {
            c.ext.air_by_chamber[ch] = Some(at_p_s(key, a)?);
        }
    }
    Ok(())
}

impl DamperDeck {
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
            let key = "damper.physical.oil.temperature_K";
            let e = oil_temperature_expected();
            return Err(DeckError::bad(&self.source, key, format!("{t_k}"), e));
        }
        let mut d = self.clone();
        match (d.physical.as_mut(), self.oil) {
            (Some(c), Some(law)) => {
                d.oil = Some(law.move_to(c, t_k));
                Ok(d)
            }
            _ => Err(DeckError::missing_table(
                &self.source,
                "damper.physical.oil",
            )),
        }
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

    /// Where the physical damper's small-amplitude damping comes from, in words (None without
    /// a physical table or orifice): the oil's viscosity through the orifice, or, on a deck
    /// without `mu_Pa_s`, the numerical `dp_laminar_Pa` of Eq. (4)'s regularisation, with the
    /// zero-amplitude damping `A0^2 dQ/d(dp)^-1` it gives.
    pub fn small_amplitude_damping(&self) -> Option<String> {
        let c = self.physical.as_ref()?;
        let a = c.chambers[0].area;
        let slope = match c.viscous_orifice() {
            Some(v) => 1.0 / v.r,
            None => c.orifice?.flow(&c.flow_law(), 0.0).1,
        };
        let c0 = a * a / slope;
        let friction = match self.extensions.friction {
            Some(f) if f.has_presliding() => format!(
                "; seal friction {} N with presliding {:.3e} m",
                f.f_c, f.presliding_m
            ),
            Some(f) => format!("; seal friction {} N", f.f_c),
            None => String::new(),
        };
        Some(match c.ext.orifice_viscosity {
            Some(v) => format!(
                "orifice laminar at small amplitude (mu_Pa_s = {}, orifice_length_m = {}): {c0:.1} N s/m at zero amplitude{friction}",
                v.mu, v.length
            ),
            None => format!(
                "orifice regularised below dp_laminar_Pa = {} (a numerical value, no mu_Pa_s): {c0:.1} N s/m at zero amplitude{friction}",
                c.dp_laminar
            ),
        })
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
            let table = format!("damper.{}", model.name());
            Err(DeckError::missing_table(&self.source, &table))
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
                    let key = "damper.physical.extensions.link_mass_kg";
                    let mass = format!("{}", e.link_mass.map_or(0.0, |m| m.mass_kg));
                    return Err(DeckError::bad(&self.source, key, mass, why));
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
                let table = MonotoneTable::new(v, f).map_err(|e| {
                    DeckError::bad(&self.source, "damper.nonlinear", String::new(), e)
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
            .ok_or_else(|| DeckError::missing_table(&self.source, "damper.physical"))?;
        Ok(CircuitDevice::new(params, opts))
    }
}

impl DamperDeck {
    /// The deck as its file's tables: what [`DamperDeck::from_file_tables`] reads back to this
    /// deck (the oil's reference is the temperature the properties hold at).
    pub fn to_file_tables(&self) -> DamperFile {
        let physical = self.physical.as_ref().map(|c| {
            let cd = c
                .orifice
                .map(|o| o.cd)
                .or(c.check.map(|v| v.cd))
                .or(c.relief.iter().flatten().next().map(|r| r.cd))
                .unwrap_or(0.611);
            let valve = |k: usize| {
                c.relief[k].map(|r| ReliefValveTable {
                    m_kg: Some(r.m),
                    c_N_s_per_m: Some(r.c),
                    k_N_per_m: Some(r.k),
                    F_p_N: Some(r.f_p),
                    A_front_m2: Some(r.a_front),
                    A_back_m2: Some(r.a_back),
                    a_m: Some(r.a),
                    b: Some(r.b),
                })
            };
            let e = &self.extensions;
            // the Dahl friction is written where it is read, in [damper.physical]
            let dahl = e.friction.filter(|f| f.is_dahl());
            let friction = e.friction.filter(|f| !f.is_dahl());
            let sigma0 = dahl.map(|f| {
                e.seal_presliding_stiffness_n_per_m
                    .filter(|k| f.f_c / k == f.presliding_m)
                    .unwrap_or(f.f_c / f.presliding_m)
            });
            let leakage = c.ext.leakage;
            let ext = ExtensionsTable {
                seal_friction_N: friction.map(|f| f.f_c),
                stribeck_static_N: friction.map(|f| f.f_s),
                stribeck_velocity_m_s: friction.map(|f| f.v_s),
                friction_smoothing_m_s: friction.map(|f| f.v_eps),
                seal_presliding_m: friction
                    .filter(|f| f.has_presliding())
                    .map(|f| f.presliding_m),
                free_play_m: e.free_play.map(|p| p.gap),
                free_play_contact_stiffness_N_per_m: e.free_play_contact_stiffness_n_per_m,
                mount_stiffness_N_per_m: e.mount_stiffness_n_per_m,
                link_mass_kg: e.link_mass.map(|m| m.mass_kg),
                link_damping_ratio: e.link_mass.map(|m| m.damping_ratio),
                air_fraction: c.ext.air.map(|a| a.fraction),
                leakage_m3_per_s_Pa: leakage.map(|l| l.conductance),
                leakage_viscosity_length_Pa_s_m: leakage
                    .map(|l| l.viscosity_length)
                    .filter(|x| *x > 0.0),
                air_fraction_0: c.ext.air_by_chamber[0].map(|a| a.fraction),
                air_fraction_1: c.ext.air_by_chamber[1].map(|a| a.fraction),
                accumulator_bleed_m3_per_s_Pa: c.ext.bleed.map(|l| l.conductance),
            };
            PhysicalTable {
                A0_m2: Some(c.chambers[0].area),
                A1_m2: Some(c.chambers[1].area),
                V0_m3: Some(c.chambers[0].volume0),
                V1_m3: Some(c.chambers[1].volume0),
                rho_kg_m3: Some(c.fluid.rho),
                bulk_alpha_per_Pa: Some(c.fluid.alpha),
                bulk_beta_per_Pa2: Some(c.fluid.beta),
                A_orf_m2: Some(c.orifice.map_or(0.0, |o| o.area)),
                Cd: Some(cd),
                p_s_Pa: Some(c.p_s),
                dp_laminar_Pa: Some(c.dp_laminar),
                check_valve_area_m2: Some(c.check.map_or(0.0, |v| v.area)),
                p_cav_Pa: Some(c.fluid.p_cav),
                mu_Pa_s: c.ext.orifice_viscosity.map(|v| v.mu),
                orifice_length_m: c.ext.orifice_viscosity.map(|v| v.length),
                seal_friction_N: dahl.map(|f| f.f_c),
                seal_presliding_stiffness_N_per_m: sigma0,
                relief_valve_0: valve(0),
                relief_valve_1: valve(1),
                extensions: (ext != ExtensionsTable::default()).then_some(ext),
                oil: self.oil.map(|o| OilTable {
                    reference_temperature_K: Some(o.temperature_k),
                    temperature_K: None,
                    density_thermal_coefficient_per_K: Some(o.density_per_k),
                    bulk_modulus_thermal_coefficient_per_K: Some(o.bulk_modulus_per_k),
                    viscosity_thermal_coefficient_per_K: Some(o.viscosity_per_k),
                }),
            }
        });
        DamperFile {
            damper: Some(DamperTable {
                model: Some(self.model.name().into()),
                linear: self.linear_c_n_s_per_m.map(|c| LinearTable {
                    c_N_s_per_m: Some(c),
                }),
                nonlinear: self.nonlinear.clone().map(|(v, f)| NonlinearTable {
                    velocity_m_s: Some(v),
                    force_N: Some(f),
                }),
                physical,
            }),
        }
    }

    /// The deck as TOML (`[damper]` of docs/formats.md plus `[damper.physical.extensions]` where
    /// any extension is on), readable by [`DamperDeck::from_toml_str`]; numbers use the shortest
    /// round-trip formatting, so the deck reads back to the same values.
    pub fn to_toml(&self) -> String {
        let text = toml::to_string(&self.to_file_tables()).expect("damper tables are TOML");
        shortest_numbers(&text)
    }
}

/// `text` (TOML written by serde) with every number of its `key = value` lines in the shortest
/// round-trip form with an exponent where small or large (`1.8e-6`, not `0.0000018`).
fn shortest_numbers(text: &str) -> String {
    let mut out = String::with_capacity(text.len());
    for line in text.lines() {
        match line.split_once(" = ") {
            Some((k, v)) if !line.starts_with('[') => {
                out.push_str(k);
                out.push_str(" = ");
                out.push_str(&shortest_value(v));
            }
            _ => out.push_str(line),
        }
        out.push('\n');
    }
    out
}

fn shortest_value(v: &str) -> String {
    if let Some(items) = v.strip_prefix('[').and_then(|s| s.strip_suffix(']')) {
        let items: Vec<String> = items.split(", ").map(shortest_value).collect();
        return format!("[{}]", items.join(", "));
    }
    match v.parse::<f64>() {
        Ok(x) if !v.starts_with('"') => num(x),
        _ => v.to_string(),
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

/// Reads the linear actuator of an `[actuator]` table ([`ActuatorTable`]; paper Table 1
/// names with units; `dp_laminar_Pa` optional). Other top-level tables are ignored.
pub fn actuator_from_toml_str(text: &str, source_name: &str) -> Result<ActuatorParams, DeckError> {
    let f: ActuatorFile = read_tables(text, source_name)?;
    let t = f
        .actuator
        .ok_or_else(|| DeckError::missing_table(source_name, "actuator"))?;
    let cx = Check {
        file: source_name,
        table: "actuator",
    };
    let pos = |k, v, what: &str| cx.req(k, v, what, positive);
    let nonneg = |k, v, what: &str| cx.req(k, v, what, non_negative);
    let cd = |k, v| cx.req(k, v, "a discharge coefficient in (0, 1]", discharge);
    let (area, volume) = ("a positive area in m^2", "a positive volume in m^3");
    let (pressure, orifice) = (
        "a non-negative pressure in Pa",
        "a non-negative area in m^2",
    );
    Ok(ActuatorParams {
        area_m2: [pos("A0_m2", t.A0_m2, area)?, pos("A1_m2", t.A1_m2, area)?],
        volume0_m3: [
            pos("V0_m3", t.V0_m3, volume)?,
            pos("V1_m3", t.V1_m3, volume)?,
        ],
        p_entrance_pa: [
            nonneg("p_E0_Pa", t.p_E0_Pa, pressure)?,
            nonneg("p_E1_Pa", t.p_E1_Pa, pressure)?,
        ],
        orifice_area_m2: [
            nonneg("A_orf0_m2", t.A_orf0_m2, orifice)?,
            nonneg("A_orf1_m2", t.A_orf1_m2, orifice)?,
        ],
        cd: [cd("Cd0", t.Cd0)?, cd("Cd1", t.Cd1)?],
        p_s_pa: nonneg("p_s_Pa", t.p_s_Pa, pressure)?,
        bulk_modulus_pa: pos("B_Pa", t.B_Pa, "a positive bulk modulus in Pa")?,
        rho_kg_m3: pos("rho_kg_m3", t.rho_kg_m3, "a positive density in kg/m^3")?,
        check_valve_area_m2: nonneg(
            "check_valve_area_m2",
            t.check_valve_area_m2,
            "a non-negative area in m^2 (0 disables)",
        )?,
        dp_laminar_pa: cx
            .opt(
                "dp_laminar_Pa",
                t.dp_laminar_Pa,
                "a positive pressure in Pa",
                positive,
            )?
            .unwrap_or(DEFAULT_DP_LAMINAR_PA),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn written_numbers_are_shortest_and_read_back() {
        let root = env!("CARGO_MANIFEST_DIR");
        let d = DamperDeck::from_file(Path::new(&format!("{root}/rotors/uh60a.toml"))).unwrap();
        let text = d.to_toml();
        assert!(text.contains("\nA_orf_m2 = 1.8e-6\n"), "{text}");
        assert!(text.contains("\nrho_kg_m3 = 850.0\n"), "{text}");
        assert_eq!(DamperDeck::from_toml_str(&text, "back").unwrap(), {
            let mut d = d.clone();
            d.source = "back".into();
            d
        });
    }

    #[test]
    fn serde_errors_name_the_key() {
        let e = |t: &str| {
            DamperDeck::from_toml_str(t, "d.toml")
                .unwrap_err()
                .to_string()
        };
        let m = e("[damper]\nmodel = \"linear\"\n[damper.linear]\nc_N_s_per_mm = 1.0\n");
        assert!(
            m.starts_with(
                "deck d.toml: unknown key `damper.linear.c_N_s_per_mm` (known keys: c_N_s_per_m"
            ),
            "{m}"
        );
        let m = e("[damper]\nmodel = \"linear\"\n[damper.linear]\nc_N_s_per_m = \"x\"\n");
        assert!(
            m.contains("`damper.linear.c_N_s_per_m` = string \"x\": expected a number"),
            "{m}"
        );
        let m = e("[damper]\nmodel = \"linear\"\n[damper.linear]\n");
        assert!(
            m.contains("missing key `damper.linear.c_N_s_per_m` (a non-negative"),
            "{m}"
        );
    }
}
