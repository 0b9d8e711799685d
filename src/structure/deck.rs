//! Model deck (TOML), documented in docs/model_deck.md. Unknown keys are rejected; every
//! reference (node, beam, joint) is checked and reported with the deck file and the key.
use super::beam::BeamLoad;
use super::elastomer::{Elastomer, MaxwellChain};
use super::hydraulic::{AppliedForce, HydraulicForceElement, HydraulicProbe};
use super::joint::{AngleLaw, BushingCoeffs, JointKind};
use super::kin::TimeTable;
use super::model::{frame_from_axis, Element, Model, SensorKind};
use super::rigid::{PointLoad, RigidBody};
use super::rotation::*;
use super::section::{SectionProps, SectionTable};
use crate::hydraulics::{
    actuator_from_toml_str, CircuitDevice, DamperDeck, DamperModel, Device, IntegratorOptions,
    PiecewiseLinear, Scheme,
};
use serde::Deserialize;
use std::path::{Path, PathBuf};
use std::sync::Arc;

/// The deck error of every deck reader (file, key and what was expected).
pub use crate::hydraulics::DeckError;

#[derive(Clone, Debug, Deserialize, Default, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct Deck {
    #[serde(default)]
    pub title: Option<String>,
    #[serde(default)]
    pub gravity_m_s2: [f64; 3],
    #[serde(default, rename = "node")]
    pub nodes: Vec<NodeDeck>,
    #[serde(default, rename = "beam")]
    pub beams: Vec<BeamDeck>,
    #[serde(default, rename = "rigid_body")]
    pub rigid_bodies: Vec<RigidDeck>,
    #[serde(default, rename = "joint")]
    pub joints: Vec<JointDeck>,
    #[serde(default, rename = "load")]
    pub loads: Vec<LoadDeck>,
    #[serde(default, rename = "distributed_load")]
    pub distributed_loads: Vec<DistDeck>,
    #[serde(default, rename = "sensor")]
    pub sensors: Vec<SensorDeck>,
    #[serde(default, rename = "hydraulic")]
    pub hydraulics: Vec<HydraulicDeck>,
    #[serde(default, rename = "static")]
    pub statics: StaticDeck,
    #[serde(default)]
    pub dynamic: DynamicDeck,
    #[serde(default)]
    pub modes: ModesDeck,
    /// Probes of the `[[hydraulic]]` elements (name, probe), filled when the model is built.
    #[serde(skip)]
    pub hydraulic_probes: BuiltProbes,
    /// How the deck is printed (comments, order of its items): not what it builds.
    #[serde(skip)]
    pub layout: super::deck_text::Layout,
}

/// The probes of a built deck's `[[hydraulic]]` elements. They are results of the build, not
/// part of what the deck says: decks compare equal whatever their probes.
#[derive(Clone, Debug, Default)]
pub struct BuiltProbes(pub Vec<(String, Arc<HydraulicProbe>)>);

impl PartialEq for BuiltProbes {
    fn eq(&self, _: &Self) -> bool {
        true
    }
}

impl std::ops::Deref for BuiltProbes {
    type Target = Vec<(String, Arc<HydraulicProbe>)>;
    fn deref(&self) -> &Self::Target {
        &self.0
    }
}

/// `[[hydraulic]]`: a hydraulic device (actuator, damper or dashpot) between two nodes
/// (paper Eqs. 9-16, [`HydraulicForceElement`]).
#[derive(Clone, Debug, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct HydraulicDeck {
    pub name: String,
    /// First attachment node, or `"ground"` (then `position_m` is the ground point).
    pub node_a: String,
    /// Ground attachment point when `node_a = "ground"`.
    #[serde(default)]
    pub position_m: Option<[f64; 3]>,
    pub node_b: String,
    /// Device deck (TOML with an `[actuator]` or a `[damper]` table), relative to the model deck.
    pub deck: String,
    /// Damper model (`physical`, `linear`, `nonlinear`; default: the damper deck's own).
    #[serde(default)]
    pub model: Option<String>,
    /// Sub-step scheme of the hydraulic states: `rk4` (default) or `implicit`.
    #[serde(default)]
    pub scheme: Option<String>,
    /// Sub-steps per structural step (default 25).
    #[serde(default)]
    pub substeps: Option<usize>,
    /// Actuator throttle schedule `[[t_s, factor], ...]` scaling both entrance orifice areas.
    #[serde(default)]
    pub orifice_area_table: Option<Vec<[f64; 2]>>,
    /// Length at zero stroke (default: the initial distance of the attachment points).
    #[serde(default)]
    pub reference_length_m: Option<f64>,
    /// Step force applied along e_m: `end` (default, force at t_f) or `mean` (the paper's F_m).
    #[serde(default)]
    pub applied_force: Option<String>,
}

#[derive(Clone, Debug, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct NodeDeck {
    pub name: String,
    pub position_m: [f64; 3],
    #[serde(default)]
    pub rotation_vector_rad: [f64; 3],
}

#[derive(Clone, Debug, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct ArcDeck {
    pub center_m: [f64; 3],
    pub radius_m: f64,
    pub start_deg: f64,
    pub end_deg: f64,
    #[serde(default = "z_axis")]
    pub normal: [f64; 3],
    /// Direction of angle 0 in the arc plane.
    #[serde(default = "x_axis")]
    pub zero_direction: [f64; 3],
}

fn z_axis() -> [f64; 3] {
    [0.0, 0.0, 1.0]
}
fn x_axis() -> [f64; 3] {
    [1.0, 0.0, 0.0]
}
fn y_axis() -> [f64; 3] {
    [0.0, 1.0, 0.0]
}

#[derive(Clone, Debug, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct BeamDeck {
    pub name: String,
    pub elements: usize,
    #[serde(default)]
    pub start_m: Option<[f64; 3]>,
    #[serde(default)]
    pub end_m: Option<[f64; 3]>,
    #[serde(default)]
    pub arc: Option<ArcDeck>,
    /// Existing node used as the first beam node (its position must match the start).
    #[serde(default)]
    pub start_node: Option<String>,
    /// Section e2 direction (absent: global y).
    #[serde(default)]
    pub e2_direction: Option<[f64; 3]>,
    #[serde(default)]
    pub sections_csv: Option<String>,
    #[serde(default)]
    pub section: Option<SectionProps>,
    #[serde(default)]
    pub sections: Option<Vec<SectionProps>>,
    #[serde(default)]
    pub damping_mu_s: Option<f64>,
    /// Built-in twist of a straight beam about its axis, `[[s_m, deg], ...]` (piecewise linear
    /// in the arc length from the first node, constant beyond the ends; positive about +e1).
    #[serde(default)]
    pub twist_deg: Option<Vec<[f64; 2]>>,
}

impl BeamDeck {
    /// The section e2 direction (default global y).
    pub fn e2(&self) -> [f64; 3] {
        self.e2_direction.unwrap_or_else(y_axis)
    }
    /// The stiffness-proportional damping [s] (default 0).
    pub fn damping(&self) -> f64 {
        self.damping_mu_s.unwrap_or(0.0)
    }
}

#[derive(Clone, Debug, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct RigidDeck {
    pub name: String,
    pub node: String,
    pub mass_kg: f64,
    #[serde(default)]
    pub cm_offset_m: Option<[f64; 3]>,
    pub inertia_kgm2: [[f64; 3]; 3],
}

#[derive(Clone, Debug, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct JointDeck {
    pub name: String,
    #[serde(rename = "type")]
    pub kind: String,
    #[serde(default)]
    pub node_a: Option<String>,
    pub node_b: String,
    #[serde(default)]
    pub position_m: Option<[f64; 3]>,
    /// Joint z axis (revolute axis), global (absent: z).
    #[serde(default)]
    pub axis: Option<[f64; 3]>,
    /// Joint x direction (absent: x).
    #[serde(default)]
    pub x_direction: Option<[f64; 3]>,
    #[serde(default, rename = "stiffness_Nm_per_rad")]
    pub stiffness: Option<f64>,
    #[serde(default, rename = "damping_Nms_per_rad")]
    pub damping: Option<f64>,
    #[serde(default)]
    pub omega_rad_s: Option<f64>,
    /// (t_s, angle_rad) pairs added to omega t.
    #[serde(default)]
    pub angle_table: Option<Vec<[f64; 2]>>,
    #[serde(default)]
    pub displacement_m: Option<[f64; 3]>,
    /// (t_s, factor) pairs scaling displacement_m.
    #[serde(default)]
    pub displacement_table: Option<Vec<[f64; 2]>>,
    /// Bushing springs and dampers per joint axis [x, y, z] (lists, so that a wrong length is
    /// reported with the joint's name).
    #[serde(default, rename = "stiffness_N_per_m")]
    pub stiffness_t: Option<Vec<f64>>,
    #[serde(default, rename = "damping_Ns_per_m")]
    pub damping_t: Option<Vec<f64>>,
    #[serde(default, rename = "rot_stiffness_Nm_per_rad")]
    pub stiffness_r: Option<Vec<f64>>,
    #[serde(default, rename = "rot_damping_Nms_per_rad")]
    pub damping_r: Option<Vec<f64>>,
    /// Bushing axes locked by multipliers, any of `AXES` once each.
    #[serde(default)]
    pub locked: Option<Vec<String>>,
    /// An elastomer about a revolute joint's axis; `stiffness_Nm_per_rad` is then its storage
    /// stiffness at the reference frequency.
    #[serde(default)]
    pub elastomer: Option<ElastomerDeck>,
}

/// An elastomer about a joint axis: a Maxwell chain fitted to a constant loss factor over a
/// band of frequencies (src/structure/elastomer.rs).
#[derive(Clone, Debug, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct ElastomerDeck {
    pub loss_factor: f64,
    pub band_rad_s: [f64; 2],
    /// Frequency at which the storage stiffness is the joint's `stiffness_Nm_per_rad`.
    pub reference_rad_s: f64,
}

/// A bushing's axis names in `Joint::bushing_locked` order: translations, then rotations.
const AXES: [&str; 6] = ["x", "y", "z", "rx", "ry", "rz"];

/// Locked flags from checked axis names.
fn locked_axes(names: &Option<Vec<String>>) -> [bool; 6] {
    let names = names.as_deref().unwrap_or_default();
    std::array::from_fn(|i| names.iter().any(|n| n == AXES[i]))
}

impl JointDeck {
    /// The joint axis (default z).
    pub fn axis(&self) -> [f64; 3] {
        self.axis.unwrap_or_else(z_axis)
    }
    /// The joint x direction (default x).
    pub fn x_direction(&self) -> [f64; 3] {
        self.x_direction.unwrap_or_else(x_axis)
    }
    /// The revolute spring [N m/rad] (default 0).
    pub fn stiffness(&self) -> f64 {
        self.stiffness.unwrap_or(0.0)
    }
    /// The revolute damper [N m s/rad] (default 0).
    pub fn damping(&self) -> f64 {
        self.damping.unwrap_or(0.0)
    }
    /// The bushing keys with their values (deck spelling).
    fn bushing_keys(&self) -> [(&'static str, &Option<Vec<f64>>); 4] {
        [
            ("stiffness_N_per_m", &self.stiffness_t),
            ("damping_Ns_per_m", &self.damping_t),
            ("rot_stiffness_Nm_per_rad", &self.stiffness_r),
            ("rot_damping_Nms_per_rad", &self.damping_r),
        ]
    }
}

/// A bushing's per-axis values: absent = zeros; checked by `validate`.
fn axes3(v: &Option<Vec<f64>>) -> [f64; 3] {
    match v {
        Some(v) if v.len() == 3 => [v[0], v[1], v[2]],
        _ => [0.0; 3],
    }
}

#[derive(Clone, Debug, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct LoadDeck {
    pub name: String,
    pub node: String,
    #[serde(default, rename = "force_N")]
    pub force: [f64; 3],
    #[serde(default, rename = "moment_Nm")]
    pub moment: [f64; 3],
    #[serde(default)]
    pub follower: bool,
    #[serde(default)]
    pub time_table: Option<Vec<[f64; 2]>>,
}

#[derive(Clone, Debug, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct DistDeck {
    pub beam: String,
    #[serde(default, rename = "force_N_per_m")]
    pub force: [f64; 3],
    #[serde(default, rename = "moment_Nm_per_m")]
    pub moment: [f64; 3],
    #[serde(default)]
    pub follower: bool,
    #[serde(default)]
    pub time_table: Option<Vec<[f64; 2]>>,
}

#[derive(Clone, Debug, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct SensorDeck {
    pub name: String,
    #[serde(default)]
    pub node: Option<String>,
    #[serde(default)]
    pub joint: Option<String>,
    #[serde(default)]
    pub beam: Option<String>,
    #[serde(default)]
    pub s_m: Option<f64>,
}

#[derive(Clone, Debug, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct StaticDeck {
    #[serde(default = "ten")]
    pub load_steps: usize,
    #[serde(default = "max_it")]
    pub max_iterations: usize,
    /// Steady rotation about the origin (rotating-frame equilibrium).
    #[serde(default)]
    pub omega_rad_s: Option<[f64; 3]>,
}

impl Default for StaticDeck {
    fn default() -> Self {
        StaticDeck {
            load_steps: 10,
            max_iterations: 25,
            omega_rad_s: None,
        }
    }
}

fn ten() -> usize {
    10
}
fn max_it() -> usize {
    25
}
fn one() -> usize {
    1
}
fn rho_default() -> f64 {
    0.9
}

#[derive(Clone, Debug, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct DynamicDeck {
    #[serde(default)]
    pub time_step_s: Option<f64>,
    #[serde(default)]
    pub end_time_s: Option<f64>,
    #[serde(default = "rho_default")]
    pub rho_inf: f64,
    #[serde(default = "one")]
    pub output_every: usize,
    #[serde(default = "max_it")]
    pub max_iterations: usize,
    /// Initial rigid rotation (rad/s) about the origin applied to all nodes.
    #[serde(default)]
    pub initial_omega_rad_s: Option<[f64; 3]>,
    /// Start from the static equilibrium of the deck's loads at t = 0.
    #[serde(default)]
    pub start_from_static: bool,
}

/// Without a `[dynamic]` table: the defaults of its keys (time step and end time absent).
impl Default for DynamicDeck {
    fn default() -> Self {
        DynamicDeck {
            time_step_s: None,
            end_time_s: None,
            rho_inf: rho_default(),
            output_every: 1,
            max_iterations: max_it(),
            initial_omega_rad_s: None,
            start_from_static: false,
        }
    }
}

#[derive(Clone, Debug, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct ModesDeck {
    #[serde(default = "ten")]
    pub count: usize,
    /// Rotation axis for rotating-frame analyses.
    #[serde(default = "z_axis")]
    pub axis: [f64; 3],
    /// Rotation speeds for a fan plot (empty = non-rotating only).
    #[serde(default)]
    pub speeds_rad_s: Vec<f64>,
}

impl Default for ModesDeck {
    fn default() -> Self {
        ModesDeck {
            count: 10,
            axis: z_axis(),
            speeds_rad_s: vec![],
        }
    }
}

fn table(t: &Option<Vec<[f64; 2]>>) -> TimeTable {
    TimeTable {
        points: t
            .as_ref()
            .map(|v| v.iter().map(|p| (p[0], p[1])).collect())
            .unwrap_or_default(),
    }
}

/// Twist table `[[s_m, deg]]` as a piecewise-linear function of s (strictly increasing s).
fn twist_table(t: &[[f64; 2]]) -> Result<TimeTable, String> {
    if t.is_empty() {
        return Err("expected at least one [s_m, deg] pair".into());
    }
    if t.iter().any(|p| !p[0].is_finite() || !p[1].is_finite()) {
        return Err("values must be finite".into());
    }
    if t.windows(2).any(|w| w[1][0] <= w[0][0]) {
        return Err("s_m must be strictly increasing".into());
    }
    Ok(TimeTable {
        points: t.iter().map(|p| (p[0], p[1])).collect(),
    })
}

/// Parse a deck and build the model.
impl Deck {
    /// Unknowns (node dofs and joint multipliers) and stored matrix entries of the model this
    /// deck builds, counted from the deck alone: a beam of E cubic elements has 3E + 1 nodes
    /// and E dense 24 x 24 blocks; a joint at most 6 multipliers on two nodes.
    pub fn size_estimate(&self) -> (f64, f64) {
        let mut nodes = (self.nodes.len() + self.rigid_bodies.len()) as f64;
        let mut entries = 0.0;
        for b in &self.beams {
            let e = b.elements as f64;
            nodes += 3.0 * e + 1.0;
            entries += 576.0 * e;
        }
        let lambdas = 6.0 * self.joints.len() as f64;
        entries += 18.0 * 18.0 * self.joints.len() as f64;
        let ndof = 6.0 * nodes + lambdas;
        (ndof, entries + ndof)
    }

    /// The deck at `path` and every file it references (section tables, device decks),
    /// relative paths resolved as the reader resolves them: a result's inputs.
    pub fn input_files(&self, path: &Path) -> Vec<PathBuf> {
        let base = path.parent().map(Path::to_path_buf).unwrap_or_default();
        let resolve = |p: &str| {
            let pb = PathBuf::from(p);
            if pb.is_absolute() {
                pb
            } else {
                base.join(pb)
            }
        };
        let mut files = vec![path.to_path_buf()];
        for f in self
            .beams
            .iter()
            .filter_map(|b| b.sections_csv.as_deref())
            .chain(self.hydraulics.iter().map(|h| h.deck.as_str()))
        {
            let f = resolve(f);
            if !files.contains(&f) {
                files.push(f);
            }
        }
        files
    }
}

pub fn load_deck(path: &Path) -> Result<(Deck, Model), DeckError> {
    load_deck_within(path, |_| Ok(()))
}

/// As [`load_deck`], with `budget` run on the parsed deck before its model is built: a deck
/// whose model would not fit (too many elements for memory, a run of years) is refused before
/// anything is allocated for it.
pub fn load_deck_within(
    path: &Path,
    budget: impl FnOnce(&Deck) -> Result<(), String>,
) -> Result<(Deck, Model), DeckError> {
    let file = path.display().to_string();
    let text = std::fs::read_to_string(path).map_err(|source| DeckError::read(&file, source))?;
    let base = path.parent().map(Path::to_path_buf).unwrap_or_default();
    let mut deck = deserialize(&text, &file)?;
    budget(&deck).map_err(|message| DeckError::file(&file, message))?;
    let (model, probes) = build(&deck, &file, &base)?;
    deck.hydraulic_probes = BuiltProbes(probes);
    Ok((deck, model))
}

fn deserialize(text: &str, file: &str) -> Result<Deck, DeckError> {
    let deck: Deck = toml::from_str(text).map_err(|e| {
        let msg = e.to_string().trim_end().to_string();
        let at = e.span().and_then(|sp| array_table_at(text, sp.start));
        DeckError::file(file, at.map(|t| format!("in {t}: {msg}")).unwrap_or(msg))
    })?;
    validate(&deck).map_err(|(key, msg)| DeckError::invalid(file, key, msg))?;
    Ok(deck)
}

/// The `[[table]]` entry holding byte `offset` of `text`, as `joint[1] `NAME`` (the spelling
/// of the value errors), so that a serde error (unknown key, wrong type) names the element too.
fn array_table_at(text: &str, offset: usize) -> Option<String> {
    let mut counts: std::collections::HashMap<&str, usize> = Default::default();
    let mut cur: Option<(&str, usize, usize)> = None; // table, index, byte start of its body
    let mut pos = 0;
    for line in text.split_inclusive('\n') {
        if pos > offset {
            break;
        }
        let t = line.trim();
        if let Some(name) = t.strip_prefix("[[").and_then(|r| r.split("]]").next()) {
            let name = name.trim();
            let i = counts.entry(name).or_insert(0);
            cur = Some((name, *i, pos + line.len()));
            *i += 1;
        } else if t.starts_with('[') {
            cur = None;
        }
        pos += line.len();
    }
    let (table, index, body) = cur?;
    let mut label = format!("{table}[{index}]");
    for line in text[body..].lines() {
        let t = line.trim();
        if t.starts_with('[') {
            break;
        }
        if let Some(v) = t.strip_prefix("name").map(str::trim_start) {
            if let Some(v) = v.strip_prefix('=') {
                label = format!("{label} `{}`", v.trim().trim_matches('"'));
                break;
            }
        }
    }
    Some(label)
}

/// A value check: Err names the key and says what was expected.
type Check = Result<(), (String, String)>;

fn finite(key: &str, x: f64) -> Check {
    if x.is_finite() {
        Ok(())
    } else {
        Err((key.into(), format!("{x}: expected a finite number")))
    }
}

fn non_negative(key: &str, x: f64) -> Check {
    if x.is_finite() && x >= 0.0 {
        Ok(())
    } else {
        Err((key.into(), format!("{x}: expected a finite number >= 0")))
    }
}

fn positive(key: &str, x: f64) -> Check {
    if x.is_finite() && x > 0.0 {
        Ok(())
    } else {
        Err((key.into(), format!("{x}: expected a finite number > 0")))
    }
}

fn finite3(key: &str, v: [f64; 3]) -> Check {
    if v.iter().all(|x| x.is_finite()) {
        Ok(())
    } else {
        Err((key.into(), format!("{v:?}: expected three finite numbers")))
    }
}

fn direction(key: &str, v: [f64; 3]) -> Check {
    finite3(key, v)?;
    if dot(v, v).sqrt() > 0.0 {
        Ok(())
    } else {
        Err((key.into(), format!("{v:?}: expected a non-zero direction")))
    }
}

fn counted(key: &str, n: usize) -> Check {
    if n >= 1 {
        Ok(())
    } else {
        Err((key.into(), "0: expected at least 1".into()))
    }
}

/// Bushing keys: three finite non-negative values each, only on a bushing; `locked` names
/// axes once each; a bushing has no revolute spring, prescribed motion, spring or damper on a
/// locked axis, or all-zero coefficients without a lock (either would do nothing).
fn bushing_values(key: &str, j: &JointDeck) -> Check {
    let bushing = j.kind == "bushing";
    if let Some(names) = &j.locked {
        let k = format!("{key}.locked");
        if !bushing {
            return Err((
                k,
                format!("only for type = \"bushing\" (this joint is `{}`)", j.kind),
            ));
        }
        for (i, n) in names.iter().enumerate() {
            if !AXES.contains(&n.as_str()) {
                return Err((
                    k,
                    format!("unknown axis `{n}` (expected any of x, y, z, rx, ry, rz)"),
                ));
            }
            if names[..i].contains(n) {
                return Err((k, format!("axis `{n}` given twice")));
            }
        }
    }
    for (name, v) in j.bushing_keys() {
        let Some(v) = v else { continue };
        let k = format!("{key}.{name}");
        if !bushing {
            return Err((
                k,
                format!("only for type = \"bushing\" (this joint is `{}`)", j.kind),
            ));
        }
        if v.len() != 3 {
            return Err((
                k,
                format!("{v:?}: expected 3 values [x, y, z] along the joint axes"),
            ));
        }
        for &x in v {
            non_negative(&k, x)?;
        }
    }
    if !bushing {
        return Ok(());
    }
    let other = [
        ("stiffness_Nm_per_rad", j.stiffness() != 0.0),
        ("damping_Nms_per_rad", j.damping() != 0.0),
        ("omega_rad_s", j.omega_rad_s.is_some()),
        ("angle_table", j.angle_table.is_some()),
        ("displacement_m", j.displacement_m.is_some()),
        ("displacement_table", j.displacement_table.is_some()),
    ];
    if let Some((name, _)) = other.iter().find(|(_, given)| *given) {
        return Err((
            format!("{key}.{name}"),
            "not allowed on a bushing (use rot_stiffness_Nm_per_rad, rot_damping_Nms_per_rad)"
                .into(),
        ));
    }
    let locked = locked_axes(&j.locked);
    for (n, (name, v)) in j.bushing_keys().iter().enumerate() {
        // stiffness_N_per_m and damping_Ns_per_m on x, y, z; the rotational ones on rx, ry, rz
        let first = if n < 2 { 0 } else { 3 };
        let Some(v) = v else { continue };
        if let Some(i) = (0..3).find(|&i| v[i] != 0.0 && locked[first + i]) {
            return Err((
                format!("{key}.{name}"),
                format!(
                    "{v:?}: `{}` is locked, so a spring or damper on it does nothing (give 0.0)",
                    AXES[first + i]
                ),
            ));
        }
    }
    let all_zero = j
        .bushing_keys()
        .iter()
        .all(|(_, v)| v.iter().flatten().all(|&x| x == 0.0));
    if all_zero && !locked.contains(&true) {
        return Err((
            format!("{key}.stiffness_N_per_m"),
            "a bushing with all stiffnesses and dampings zero and no locked axis does nothing: give at least one of stiffness_N_per_m, damping_Ns_per_m, rot_stiffness_Nm_per_rad, rot_damping_Nms_per_rad, locked".into(),
        ));
    }
    Ok(())
}

/// `[[t_s, value], ...]`: finite pairs with non-decreasing times.
fn time_pairs(key: &str, t: &Option<Vec<[f64; 2]>>) -> Check {
    let Some(t) = t else { return Ok(()) };
    if let Some(p) = t.iter().find(|p| !p[0].is_finite() || !p[1].is_finite()) {
        return Err((
            key.into(),
            format!("{p:?}: expected finite [t_s, value] pairs"),
        ));
    }
    if let Some(w) = t.windows(2).find(|w| w[1][0] < w[0][0]) {
        return Err((
            key.into(),
            format!(
                "time {} after {}: expected non-decreasing times",
                w[1][0], w[0][0]
            ),
        ));
    }
    Ok(())
}

fn named(key: &str, name: &str) -> Check {
    if name.trim().is_empty() {
        Err((format!("{key}.name"), "expected a non-empty name".into()))
    } else {
        Ok(())
    }
}

/// Every value of the deck that its type does not already constrain: finite numbers, signs,
/// ranges and the consistency of values within one table. Node, joint and beam references are
/// checked when the model is built.
fn validate(d: &Deck) -> Check {
    finite3("gravity_m_s2", d.gravity_m_s2)?;
    for (i, n) in d.nodes.iter().enumerate() {
        let key = format!("node[{i}] `{}`", n.name);
        named(&key, &n.name)?;
        finite3(&format!("{key}.position_m"), n.position_m)?;
        finite3(&format!("{key}.rotation_vector_rad"), n.rotation_vector_rad)?;
    }
    for (i, b) in d.beams.iter().enumerate() {
        validate_beam(i, b)?;
    }
    for (i, r) in d.rigid_bodies.iter().enumerate() {
        let key = format!("rigid_body[{i}] `{}`", r.name);
        named(&key, &r.name)?;
        non_negative(&format!("{key}.mass_kg"), r.mass_kg)?;
        finite3(
            &format!("{key}.cm_offset_m"),
            r.cm_offset_m.unwrap_or_default(),
        )?;
        if r.inertia_kgm2.iter().flatten().any(|x| !x.is_finite()) {
            return Err((
                format!("{key}.inertia_kgm2"),
                format!("{:?}: expected finite numbers", r.inertia_kgm2),
            ));
        }
        if (0..3).any(|k| r.inertia_kgm2[k][k] < 0.0) {
            return Err((
                format!("{key}.inertia_kgm2"),
                format!(
                    "{:?}: expected non-negative diagonal moments of inertia",
                    r.inertia_kgm2
                ),
            ));
        }
    }
    for (i, j) in d.joints.iter().enumerate() {
        let key = format!("joint[{i}] `{}`", j.name);
        named(&key, &j.name)?;
        if let Some(p) = j.position_m {
            finite3(&format!("{key}.position_m"), p)?;
        }
        direction(&format!("{key}.axis"), j.axis())?;
        direction(&format!("{key}.x_direction"), j.x_direction())?;
        non_negative(&format!("{key}.stiffness_Nm_per_rad"), j.stiffness())?;
        non_negative(&format!("{key}.damping_Nms_per_rad"), j.damping())?;
        if let Some(w) = j.omega_rad_s {
            finite(&format!("{key}.omega_rad_s"), w)?;
        }
        time_pairs(&format!("{key}.angle_table"), &j.angle_table)?;
        if let Some(u) = j.displacement_m {
            finite3(&format!("{key}.displacement_m"), u)?;
        }
        time_pairs(&format!("{key}.displacement_table"), &j.displacement_table)?;
        bushing_values(&key, j)?;
    }
    for (i, l) in d.loads.iter().enumerate() {
        let key = format!("load[{i}] `{}`", l.name);
        named(&key, &l.name)?;
        finite3(&format!("{key}.force_N"), l.force)?;
        finite3(&format!("{key}.moment_Nm"), l.moment)?;
        time_pairs(&format!("{key}.time_table"), &l.time_table)?;
    }
    for (i, l) in d.distributed_loads.iter().enumerate() {
        let key = format!("distributed_load[{i}]");
        finite3(&format!("{key}.force_N_per_m"), l.force)?;
        finite3(&format!("{key}.moment_Nm_per_m"), l.moment)?;
        time_pairs(&format!("{key}.time_table"), &l.time_table)?;
    }
    for (i, s) in d.sensors.iter().enumerate() {
        let key = format!("sensor[{i}] `{}`", s.name);
        named(&key, &s.name)?;
        if let Some(first) = d.sensors[..i].iter().position(|o| o.name == s.name) {
            return Err((
                format!("{key}.name"),
                format!(
                    "`{}` also names sensor[{first}]: expected unique sensor names",
                    s.name
                ),
            ));
        }
        if let Some(x) = s.s_m {
            non_negative(&format!("{key}.s_m"), x)?;
        }
    }
    for (i, h) in d.hydraulics.iter().enumerate() {
        let key = format!("hydraulic[{i}] `{}`", h.name);
        if let Some(l) = h.reference_length_m {
            positive(&format!("{key}.reference_length_m"), l)?;
        }
    }
    validate_tables(d)
}

/// A `[[beam]]`: its counts, directions and length, its arc.
fn validate_beam(i: usize, b: &BeamDeck) -> Check {
    let key = format!("beam[{i}] `{}`", b.name);
    named(&key, &b.name)?;
    counted(&format!("{key}.elements"), b.elements)?;
    non_negative(&format!("{key}.damping_mu_s"), b.damping())?;
    direction(&format!("{key}.e2_direction"), b.e2())?;
    if let Some(a) = b.start_m {
        finite3(&format!("{key}.start_m"), a)?;
    }
    if let Some(e) = b.end_m {
        finite3(&format!("{key}.end_m"), e)?;
    }
    if let (Some(a), Some(e)) = (b.start_m, b.end_m) {
        let t = sub(e, a);
        let len = dot(t, t).sqrt();
        if len <= 0.0 {
            return Err((
                format!("{key}.end_m"),
                format!("{e:?} equals start_m: expected a beam of positive length"),
            ));
        }
        let e2 = b.e2();
        let c = cross(t, e2);
        if dot(c, c).sqrt() <= 1e-9 * len * dot(e2, e2).sqrt() {
            return Err((
                format!("{key}.e2_direction"),
                format!("{e2:?} is along the beam axis: expected a direction across it"),
            ));
        }
    }
    if let Some(arc) = &b.arc {
        let k = format!("{key}.arc");
        finite3(&format!("{k}.center_m"), arc.center_m)?;
        positive(&format!("{k}.radius_m"), arc.radius_m)?;
        finite(&format!("{k}.start_deg"), arc.start_deg)?;
        finite(&format!("{k}.end_deg"), arc.end_deg)?;
        if arc.start_deg == arc.end_deg {
            return Err((
                format!("{k}.end_deg"),
                "equals start_deg: expected an arc of positive length".into(),
            ));
        }
        direction(&format!("{k}.normal"), arc.normal)?;
        let n = arc.normal;
        let z = arc.zero_direction;
        direction(&format!("{k}.zero_direction"), z)?;
        let c = cross(n, z);
        if dot(c, c).sqrt() <= 1e-9 * dot(n, n).sqrt() * dot(z, z).sqrt() {
            return Err((
                format!("{k}.zero_direction"),
                format!("{z:?} is along the normal: expected a direction in the arc plane"),
            ));
        }
    }
    Ok(())
}

/// The `[static]`, `[dynamic]` and `[modes]` tables.
fn validate_tables(d: &Deck) -> Check {
    let st = &d.statics;
    counted("static.load_steps", st.load_steps)?;
    counted("static.max_iterations", st.max_iterations)?;
    if let Some(w) = st.omega_rad_s {
        finite3("static.omega_rad_s", w)?;
    }
    let dy = &d.dynamic;
    if let Some(h) = dy.time_step_s {
        positive("dynamic.time_step_s", h)?;
    }
    if let Some(t) = dy.end_time_s {
        positive("dynamic.end_time_s", t)?;
    }
    if !(0.0..=1.0).contains(&dy.rho_inf) {
        return Err((
            "dynamic.rho_inf".into(),
            format!("{}: expected a number in [0, 1]", dy.rho_inf),
        ));
    }
    counted("dynamic.output_every", dy.output_every)?;
    counted("dynamic.max_iterations", dy.max_iterations)?;
    if let Some(w) = dy.initial_omega_rad_s {
        finite3("dynamic.initial_omega_rad_s", w)?;
    }
    let mo = &d.modes;
    counted("modes.count", mo.count)?;
    direction("modes.axis", mo.axis)?;
    for &w in &mo.speeds_rad_s {
        finite("modes.speeds_rad_s", w)?;
    }
    Ok(())
}

/// Parse deck text (`file` names it in errors; relative CSV paths resolve against `base`).
pub fn parse_deck(text: &str, file: &str, base: &Path) -> Result<(Deck, Model), DeckError> {
    let mut deck = deserialize(text, file)?;
    let (model, probes) = build(&deck, file, base)?;
    deck.hydraulic_probes = BuiltProbes(probes);
    Ok((deck, model))
}

/// A model built from a typed deck, with the probes of its `[[hydraulic]]` elements and the
/// model ids of its items.
pub struct Built {
    pub model: Model,
    pub probes: Probes,
    pub ids: BuiltIds,
}

/// The model ids of a built deck's items, by their index in the deck.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct BuiltIds {
    /// The node of each `[[node]]`.
    pub nodes: Vec<usize>,
    /// The nodes of each `[[beam]]`, first to last.
    pub beam_nodes: Vec<Vec<usize>>,
    /// The element of each `[[joint]]`.
    pub joints: Vec<usize>,
}

/// Checks a typed deck as reading one checks it, then builds its model and the probes of its
/// `[[hydraulic]]` elements (`file` names it in errors; relative paths resolve against `base`).
pub fn build_deck(d: &Deck, file: &str, base: &Path) -> Result<(Model, Probes), DeckError> {
    validate(d).map_err(|(key, msg)| DeckError::invalid(file, key, msg))?;
    build(d, file, base)
}

/// [`build_deck`], with the model ids of the deck's items.
pub fn build_deck_ids(d: &Deck, file: &str, base: &Path) -> Result<Built, DeckError> {
    let (model, probes) = build_deck(d, file, base)?;
    let ids = built_ids(d, &model)
        .map_err(|key| DeckError::invalid(file, key, "not found in the built model"))?;
    Ok(Built { model, probes, ids })
}

/// The ids of the deck's items in its built model (Err: the key of an item not found).
fn built_ids(d: &Deck, m: &Model) -> Result<BuiltIds, String> {
    let nodes = d
        .nodes
        .iter()
        .enumerate()
        .map(|(i, n)| m.node_id(&n.name).map_err(|_| format!("node[{i}]")))
        .collect::<Result<_, _>>()?;
    let joints = d
        .joints
        .iter()
        .enumerate()
        .map(|(i, j)| m.element_id(&j.name).ok_or(format!("joint[{i}]")))
        .collect::<Result<_, _>>()?;
    let mut beam_nodes = vec![];
    for (i, b) in d.beams.iter().enumerate() {
        let elements = m.beams.get(&b.name).ok_or(format!("beam[{i}]"))?;
        let mut v = vec![];
        // consecutive elements share their end node
        for (k, &e) in elements.iter().enumerate() {
            if let Some(Element::Beam(be)) = m.elements.get(e) {
                v.extend_from_slice(&be.nodes[usize::from(k > 0)..]);
            }
        }
        beam_nodes.push(v);
    }
    Ok(BuiltIds {
        nodes,
        beam_nodes,
        joints,
    })
}

/// The probes of the `[[hydraulic]]` elements (name, probe).
pub type Probes = Vec<(String, Arc<HydraulicProbe>)>;

/// What every build stage needs: the deck file (named in errors) and the base directory.
struct Ctx<'a> {
    file: &'a str,
    base: &'a Path,
}

impl Ctx<'_> {
    /// An invalid-value error at `key` of this deck.
    fn inv(&self, key: String, msg: String) -> DeckError {
        DeckError::invalid(self.file, key, msg)
    }

    /// The id of node `name`, or an error at `key` if it does not exist.
    fn node(&self, m: &Model, key: &str, name: &str) -> Result<usize, DeckError> {
        m.node_id(name).map_err(|_| self.inv(key.into(), format!("node `{name}` does not exist (declare it in [[node]] or use a beam node `beam.nK`)")))
    }
}

/// Builds the structural model from a checked deck, stage by stage in deck-section order.
fn build(d: &Deck, file: &str, base: &Path) -> Result<(Model, Probes), DeckError> {
    let ctx = Ctx { file, base };
    let mut m = Model::new();
    m.gravity = d.gravity_m_s2;
    add_nodes(&ctx, &mut m, d)?;
    for (i, b) in d.beams.iter().enumerate() {
        add_beam(&ctx, &mut m, i, b)?;
    }
    add_rigid_bodies(&ctx, &mut m, d)?;
    for (i, j) in d.joints.iter().enumerate() {
        add_joint(&ctx, &mut m, i, j)?;
    }
    add_loads(&ctx, &mut m, d)?;
    let probes = add_hydraulics(&ctx, &mut m, d)?;
    for (i, s) in d.sensors.iter().enumerate() {
        add_sensor(&ctx, &mut m, i, s)?;
    }
    check_connected(&ctx, &m)?;
    Ok((m, probes))
}

/// Adds the `[[node]]` nodes.
fn add_nodes(ctx: &Ctx, m: &mut Model, d: &Deck) -> Result<(), DeckError> {
    for (i, n) in d.nodes.iter().enumerate() {
        let r = exp_map(n.rotation_vector_rad);
        m.add_node(&n.name, n.position_m, r)
            .map_err(|e| ctx.inv(format!("node[{i}] `{}`", n.name), e.to_string()))?;
    }
    Ok(())
}

/// Reads the section table of one beam (from exactly one of its three section keys).
fn beam_sections(ctx: &Ctx, b: &BeamDeck, key: &str) -> Result<SectionTable, DeckError> {
    let inv = |k: String, msg: String| ctx.inv(k, msg);
    let (file, base, key) = (ctx.file, ctx.base, key.to_string());
    let sec = match (&b.sections_csv, &b.section, &b.sections) {
        (Some(p), None, None) => {
            let pb = PathBuf::from(p);
            let pb = if pb.is_absolute() { pb } else { base.join(pb) };
            SectionTable::from_csv(&pb).map_err(|e| inv(format!("{key}.sections_csv"), e.to_string()))?
        }
        (None, Some(s), None) => SectionTable::new(vec![*s], file).map_err(|e| inv(format!("{key}.section"), e.to_string()))?,
        (None, None, Some(v)) => SectionTable::new(v.clone(), file).map_err(|e| inv(format!("{key}.sections"), e.to_string()))?,
        (None, None, None) => return Err(inv(key, "missing section data: give exactly one of `sections_csv`, `section` (uniform) or `sections` (inline table)".into())),
        _ => return Err(inv(key, "give only one of `sections_csv`, `section`, `sections`".into())),
    };
    Ok(sec)
}

/// Adds one `[[beam]]` (straight, twisted straight or arc) and checks its start node.
fn add_beam(ctx: &Ctx, m: &mut Model, i: usize, b: &BeamDeck) -> Result<(), DeckError> {
    let inv = |k: String, msg: String| ctx.inv(k, msg);
    let key = format!("beam[{i}] `{}`", b.name);
    let sec = beam_sections(ctx, b, &key)?;
    let first = match &b.start_node {
        Some(n) => Some(ctx.node(m, &format!("{key}.start_node"), n)?),
        None => None,
    };
    if b.elements == 0 {
        return Err(inv(format!("{key}.elements"), "must be at least 1".into()));
    }
    if b.twist_deg.is_some() && b.arc.is_some() {
        return Err(inv(
            format!("{key}.twist_deg"),
            "only straight beams (`start_m`, `end_m`) take a twist table".into(),
        ));
    }
    let res = match (&b.arc, b.start_m, b.end_m) {
        (None, Some(a), Some(e)) if b.twist_deg.is_some() => {
            let tw = twist_table(b.twist_deg.as_deref().unwrap_or_default())
                .map_err(|msg| inv(format!("{key}.twist_deg"), msg))?;
            let (len, curve) = twisted_curve(a, e, b.e2(), tw);
            m.add_beam(&b.name, b.elements, len, &curve, &sec, b.damping(), first)
        }
        (None, Some(a), Some(e)) => {
            m.add_straight_beam(&b.name, b.elements, a, e, b.e2(), &sec, b.damping(), first)
        }
        (Some(arc), None, None) => {
            let (len, curve) = arc_curve(arc);
            m.add_beam(&b.name, b.elements, len, &curve, &sec, b.damping(), first)
        }
        _ => {
            return Err(inv(
                key,
                "give either `start_m` and `end_m` (straight) or `arc`".into(),
            ))
        }
    };
    let ids = res.map_err(|e| inv(key.clone(), e.to_string()))?;
    if let (Some(f), Some(a)) = (first, b.start_m) {
        let d = sub(m.nodes[f].x0, a);
        if dot(d, d).sqrt() > 1e-9 * (1.0 + dot(a, a).sqrt()) {
            return Err(inv(
                format!("{key}.start_node"),
                "start node position differs from start_m".into(),
            ));
        }
    }
    let _ = ids;
    Ok(())
}

/// A beam curve's point: position and frame.
type Pose = ([f64; 3], [[f64; 3]; 3]);

/// Length and curve (position, frame at arc length s) of a straight beam from `a` to `e`
/// twisted by the table `tw`.
fn twisted_curve(
    a: [f64; 3],
    e: [f64; 3],
    e2_direction: [f64; 3],
    tw: TimeTable,
) -> (f64, impl Fn(f64) -> Pose) {
    let d = sub(e, a);
    let len = dot(d, d).sqrt();
    let r = frame_from_axis(d, e2_direction);
    let curve = move |s: f64| {
        let r_tw = mm(&r, &exp_map([tw.eval(s).to_radians(), 0.0, 0.0]));
        (add(a, fmul(s / len, d)), r_tw)
    };
    (len, curve)
}

/// Length and curve (position, frame at arc length s) of a circular-arc beam.
fn arc_curve(arc: &ArcDeck) -> (f64, impl Fn(f64) -> Pose) {
    let n = arc.normal;
    let nn = fmul(1.0 / dot(n, n).sqrt(), n);
    let u0 = sub(arc.zero_direction, fmul(dot(arc.zero_direction, nn), nn));
    let u = fmul(1.0 / dot(u0, u0).sqrt(), u0);
    let v = cross(nn, u);
    let (a0, a1) = (arc.start_deg.to_radians(), arc.end_deg.to_radians());
    let sgn = if a1 >= a0 { 1.0 } else { -1.0 };
    let r = arc.radius_m;
    let c = arc.center_m;
    let len = r * (a1 - a0).abs();
    let curve = move |s: f64| {
        let p = a0 + sgn * s / r;
        let x = add(c, add(fmul(r * p.cos(), u), fmul(r * p.sin(), v)));
        let t = fmul(sgn, add(fmul(-p.sin(), u), fmul(p.cos(), v)));
        let e2 = cross(nn, t);
        (
            [x[0], x[1], x[2]],
            [
                [t[0], e2[0], nn[0]],
                [t[1], e2[1], nn[1]],
                [t[2], e2[2], nn[2]],
            ],
        )
    };
    (len, curve)
}

/// Adds the `[[rigid_body]]` elements.
fn add_rigid_bodies(ctx: &Ctx, m: &mut Model, d: &Deck) -> Result<(), DeckError> {
    let inv = |k: String, msg: String| ctx.inv(k, msg);
    for (i, r) in d.rigid_bodies.iter().enumerate() {
        let key = format!("rigid_body[{i}] `{}`", r.name);
        let n = ctx.node(m, &format!("{key}.node"), &r.node)?;
        if r.mass_kg < 0.0 {
            return Err(inv(format!("{key}.mass_kg"), "must be non-negative".into()));
        }
        m.add_element(Element::Rigid(RigidBody {
            name: r.name.clone(),
            node: n,
            mass_kg: r.mass_kg,
            cm_offset_m: r.cm_offset_m.unwrap_or_default(),
            inertia_kgm2: r.inertia_kgm2,
        }))
        .map_err(|e| inv(key, e.to_string()))?;
    }
    Ok(())
}

/// Adds one `[[joint]]` (kind, nodes, frame), then sets its properties.
fn add_joint(ctx: &Ctx, m: &mut Model, i: usize, j: &JointDeck) -> Result<(), DeckError> {
    let inv = |k: String, msg: String| ctx.inv(k, msg);
    let key = format!("joint[{i}] `{}`", j.name);
    let kind = match j.kind.as_str() {
        "clamp" | "prescribed" => JointKind::Clamp,
        "revolute" => JointKind::Revolute,
        "universal" => JointKind::Universal,
        "spherical" => JointKind::Spherical,
        "bushing" => JointKind::Bushing,
        other => return Err(inv(format!("{key}.type"), format!("unknown joint type `{other}` (expected clamp, revolute, universal, spherical, prescribed, bushing)"))),
    };
    let a = match j.node_a.as_deref() {
        None | Some("ground") => None,
        Some(n) => Some(ctx.node(m, &format!("{key}.node_a"), n)?),
    };
    let b = ctx.node(m, &format!("{key}.node_b"), &j.node_b)?;
    let p = j.position_m.unwrap_or(m.nodes[b].x0);
    let q = frame_from_axis(j.axis(), j.x_direction());
    // frame_from_axis gives columns (axis, ~x, .): reorder to (x, y, z = axis)
    let q = [
        [q[0][1], q[0][2], q[0][0]],
        [q[1][1], q[1][2], q[1][0]],
        [q[2][1], q[2][2], q[2][0]],
    ];
    let id = m
        .add_joint(&j.name, kind, a, b, p, q)
        .map_err(|e| inv(key.clone(), e.to_string()))?;
    joint_properties(ctx, m, id, j, kind, &key)
}

/// Sets the springs, dampers, bushing, prescribed motion and elastomer of joint element `id`.
fn joint_properties(
    ctx: &Ctx,
    m: &mut Model,
    id: usize,
    j: &JointDeck,
    kind: JointKind,
    key: &str,
) -> Result<(), DeckError> {
    let inv = |k: String, msg: String| ctx.inv(k, msg);
    if let Element::Joint(jj) = &mut m.elements[id] {
        jj.spring_nm_per_rad = j.stiffness();
        jj.damper_nms_per_rad = j.damping();
        jj.bushing = BushingCoeffs {
            k_n_per_m: axes3(&j.stiffness_t),
            c_ns_per_m: axes3(&j.damping_t),
            k_nm_per_rad: axes3(&j.stiffness_r),
            c_nms_per_rad: axes3(&j.damping_r),
        };
        jj.bushing_locked = locked_axes(&j.locked);
        if j.omega_rad_s.is_some() || j.angle_table.is_some() {
            if !matches!(kind, JointKind::Revolute | JointKind::Clamp) {
                return Err(inv(
                    format!("{key}.omega_rad_s"),
                    "prescribed rotation needs a revolute or prescribed joint".into(),
                ));
            }
            jj.prescribed_angle = Some(AngleLaw {
                omega_rad_s: j.omega_rad_s.unwrap_or(0.0),
                table: j.angle_table.as_ref().map(|_| table(&j.angle_table)),
            });
        }
        if let Some(u) = j.displacement_m {
            jj.displacement_m = Some((u, table(&j.displacement_table)));
        }
        if let Some(el) = &j.elastomer {
            let ek = format!("{key}.elastomer");
            if kind != JointKind::Revolute || jj.prescribed_angle.is_some() {
                return Err(inv(
                    ek,
                    "an elastomer acts about a free revolute axis (type = \"revolute\" without omega_rad_s or angle_table)".into(),
                ));
            }
            if j.stiffness().is_nan() || j.stiffness() <= 0.0 {
                return Err(inv(
                    format!("{key}.stiffness_Nm_per_rad"),
                    "an elastomer needs its storage stiffness here: expected > 0".into(),
                ));
            }
            let [lo, hi] = el.band_rad_s;
            let chain =
                MaxwellChain::fit(j.stiffness(), el.loss_factor, lo, hi, el.reference_rad_s)
                    .map_err(|e| inv(ek, e))?;
            jj.spring_nm_per_rad = 0.0;
            jj.elastomer = Some(Elastomer::new(chain));
        }
    }
    Ok(())
}

/// Adds the `[[load]]` point loads and the `[[distributed_load]]` beam loads.
fn add_loads(ctx: &Ctx, m: &mut Model, d: &Deck) -> Result<(), DeckError> {
    let inv = |k: String, msg: String| ctx.inv(k, msg);
    for (i, l) in d.loads.iter().enumerate() {
        let key = format!("load[{i}] `{}`", l.name);
        let n = ctx.node(m, &format!("{key}.node"), &l.node)?;
        m.add_element(Element::Load(PointLoad {
            name: l.name.clone(),
            node: n,
            force_n: l.force,
            moment_nm: l.moment,
            follower: l.follower,
            time: table(&l.time_table),
        }))
        .map_err(|e| inv(key, e.to_string()))?;
    }
    for (i, l) in d.distributed_loads.iter().enumerate() {
        let key = format!("distributed_load[{i}]");
        m.add_beam_load(
            &l.beam,
            BeamLoad {
                force_n_per_m: l.force,
                moment_nm_per_m: l.moment,
                follower: l.follower,
                time: table(&l.time_table),
            },
        )
        .map_err(|e| inv(format!("{key}.beam"), e.to_string()))?;
    }
    Ok(())
}

/// Adds the `[[hydraulic]]` step elements and returns their probes.
fn add_hydraulics(ctx: &Ctx, m: &mut Model, d: &Deck) -> Result<Probes, DeckError> {
    let mut probes = vec![];
    for (i, h) in d.hydraulics.iter().enumerate() {
        let key = format!("hydraulic[{i}] `{}`", h.name);
        let (elem, probe) = hydraulic_element(m, h, &key, ctx.file, ctx.base)?;
        m.add_step_element(Box::new(elem))
            .map_err(|e| ctx.inv(key, e.to_string()))?;
        probes.push((h.name.clone(), probe));
    }
    Ok(probes)
}

/// Adds one `[[sensor]]` on a node, a joint or a beam section.
fn add_sensor(ctx: &Ctx, m: &mut Model, i: usize, s: &SensorDeck) -> Result<(), DeckError> {
    let inv = |k: String, msg: String| ctx.inv(k, msg);
    let key = format!("sensor[{i}] `{}`", s.name);
    let kind = match (&s.node, &s.joint, &s.beam) {
        (Some(n), None, None) => SensorKind::Node(ctx.node(m, &format!("{key}.node"), n)?),
        (None, Some(j), None) => {
            let id = m
                .element_id(j)
                .filter(|&id| matches!(m.elements[id], Element::Joint(_)))
                .ok_or_else(|| {
                    inv(
                        format!("{key}.joint"),
                        format!("joint `{j}` does not exist"),
                    )
                })?;
            SensorKind::Joint(id)
        }
        (None, None, Some(b)) => section_sensor(ctx, m, &key, s, b)?,
        _ => {
            return Err(inv(
                key,
                "give exactly one of `node`, `joint`, `beam` (with `s_m`)".into(),
            ))
        }
    };
    m.add_sensor(&s.name, kind);
    Ok(())
}

/// The section sensor at station `s_m` of beam `b` (checked to lie on the beam).
fn section_sensor(
    ctx: &Ctx,
    m: &Model,
    key: &str,
    s: &SensorDeck,
    b: &str,
) -> Result<SensorKind, DeckError> {
    let inv = |k: String, msg: String| ctx.inv(k, msg);
    let ids = m
        .beams
        .get(b)
        .cloned()
        .ok_or_else(|| inv(format!("{key}.beam"), format!("beam `{b}` does not exist")))?;
    let s_m = s.s_m.unwrap_or(0.0);
    let len = ids
        .iter()
        .filter_map(|&id| match &m.elements[id] {
            Element::Beam(e) => Some(e.s_range[1]),
            _ => None,
        })
        .fold(0.0, f64::max);
    if s_m > len * (1.0 + 1e-9) {
        return Err(inv(
            format!("{key}.s_m"),
            format!("{s_m}: expected a station on beam `{b}`, 0 to {len} m"),
        ));
    }
    Ok(SensorKind::Section {
        elements: ids,
        s_m: s.s_m.unwrap_or(0.0),
    })
}

/// Fails on the first node that no element or joint uses.
fn check_connected(ctx: &Ctx, m: &Model) -> Result<(), DeckError> {
    let mut used = vec![false; m.nodes.len()];
    for e in &m.elements {
        for n in e.node_list() {
            used[n] = true;
        }
    }
    if let Some(i) = used.iter().position(|u| !u) {
        return Err(ctx.inv(
            format!("node `{}`", m.nodes[i].name),
            "not connected to any element or joint (it would have no mass and no stiffness)".into(),
        ));
    }
    Ok(())
}

/// Builds the element of one `[[hydraulic]]` table (creating and clamping its ground node).
fn hydraulic_element(
    m: &mut Model,
    h: &HydraulicDeck,
    key: &str,
    file: &str,
    base: &Path,
) -> Result<(HydraulicForceElement, Arc<HydraulicProbe>), DeckError> {
    let inv = |k: &str, msg: String| DeckError::invalid(file, format!("{key}.{k}"), msg);
    if h.name.is_empty() {
        return Err(inv("name", "must not be empty".into()));
    }
    let (a, b) = attachments(m, h, &inv)?;
    if a == b {
        return Err(inv("node_b", "the device connects a node to itself".into()));
    }
    let scheme = match h.scheme.as_deref() {
        None => Scheme::Rk4,
        Some(s) => s.parse::<Scheme>().map_err(|e| inv("scheme", e))?,
    };
    let substeps = h.substeps.unwrap_or(IntegratorOptions::default().substeps);
    if substeps == 0 {
        return Err(inv("substeps", "must be at least 1".into()));
    }
    let opts = IntegratorOptions { scheme, substeps };
    let pb = PathBuf::from(&h.deck);
    let path = if pb.is_absolute() { pb } else { base.join(pb) };
    let dfile = path.display().to_string();
    let text = std::fs::read_to_string(&path)
        .map_err(|e| inv("deck", format!("cannot read device deck {dfile}: {e}")))?;
    let root: toml::Table = text.parse().map_err(|e: toml::de::Error| {
        inv(
            "deck",
            format!(
                "device deck {dfile} is not valid TOML: {}",
                e.to_string().trim_end()
            ),
        )
    })?;
    let device = device_of(h, &root, &text, &dfile, opts, &inv)?;
    let applied = match h.applied_force.as_deref() {
        None | Some("end") => AppliedForce::End,
        Some("mean") => AppliedForce::Mean,
        Some(o) => {
            return Err(inv(
                "applied_force",
                format!("unknown `{o}` (expected end or mean)"),
            ))
        }
    };
    let mut elem =
        HydraulicForceElement::new(h.name.clone(), a, b, device).with_applied_force(applied);
    let l0 = {
        let d = sub(m.nodes[b].x0, m.nodes[a].x0);
        dot(d, d).sqrt()
    };
    if l0 <= 0.0 {
        return Err(inv(
            "node_b",
            "the attachment points coincide: the device has no direction".into(),
        ));
    }
    let l_ref = match h.reference_length_m {
        Some(l) if l > 0.0 && l.is_finite() => l,
        Some(l) => {
            return Err(inv(
                "reference_length_m",
                format!("{l}: expected a positive length in m"),
            ))
        }
        None => l0,
    };
    elem = elem.with_reference_length(l_ref);
    let probe = elem.probe();
    Ok((elem, probe))
}

/// The device of a `[[hydraulic]]` element: its deck's `[actuator]` or `[damper]`, with the
/// element's model, sub-stepping and orifice schedule.
fn device_of(
    h: &HydraulicDeck,
    root: &toml::Table,
    text: &str,
    dfile: &str,
    opts: IntegratorOptions,
    inv: &dyn Fn(&str, String) -> DeckError,
) -> Result<Box<dyn Device>, DeckError> {
    let device: Box<dyn Device> = match (root.contains_key("actuator"), root.contains_key("damper"))
    {
        (true, true) => {
            return Err(inv(
                "deck",
                format!(
                "device deck {dfile} has both [actuator] and [damper]: give one device per deck"
            ),
            ))
        }
        (false, false) => {
            return Err(inv(
                "deck",
                format!("device deck {dfile} has neither an [actuator] nor a [damper] table"),
            ))
        }
        (true, false) => {
            if let Some(md) = h.model.as_deref().filter(|md| *md != "physical") {
                return Err(inv(
                    "model",
                    format!("`{md}`: an actuator deck ({dfile}) has only the physical model"),
                ));
            }
            let params =
                actuator_from_toml_str(text, dfile).map_err(|e| inv("deck", e.to_string()))?;
            let mut dev = CircuitDevice::new(params.to_circuit(), opts);
            if let Some(tab) = &h.orifice_area_table {
                let sch = PiecewiseLinear::new(
                    tab.iter().map(|p| p[0]).collect(),
                    tab.iter().map(|p| p[1]).collect(),
                )
                .map_err(|e| {
                    inv(
                        "orifice_area_table",
                        format!("expected [[t_s, factor], ...] with increasing times: {e}"),
                    )
                })?;
                if let Some(p) = tab.iter().find(|p| p[1] < 0.0) {
                    return Err(inv(
                        "orifice_area_table",
                        format!(
                            "factor {} at t = {} s is negative (areas scale by factors >= 0)",
                            p[1], p[0]
                        ),
                    ));
                }
                dev.set_orifice_area_schedule(sch);
            }
            Box::new(dev)
        }
        (false, true) => {
            if h.orifice_area_table.is_some() {
                return Err(inv(
                    "orifice_area_table",
                    format!("only for actuator decks ([actuator]); {dfile} is a damper deck"),
                ));
            }
            let dd =
                DamperDeck::from_toml_str(text, dfile).map_err(|e| inv("deck", e.to_string()))?;
            let model = match h.model.as_deref() {
                None => dd.model,
                Some(s) => s.parse::<DamperModel>().map_err(|e| inv("model", e))?,
            };
            dd.build(model, opts)
                .map_err(|e| inv("model", e.to_string()))?
        }
    };
    Ok(device)
}

/// The nodes a `[[hydraulic]]` element joins: `node_a` (or a clamped ground point) and `node_b`.
fn attachments(
    m: &mut Model,
    h: &HydraulicDeck,
    inv: &dyn Fn(&str, String) -> DeckError,
) -> Result<(usize, usize), DeckError> {
    let node = |m: &Model, k: &str, name: &str| {
        m.node_id(name).map_err(|_| {
            inv(
                k,
                format!("node `{name}` does not exist (declare it in [[node]] or use a beam node `beam.nK`)"),
            )
        })
    };
    let b = node(m, "node_b", &h.node_b)?;
    let a = match (h.node_a.as_str(), h.position_m) {
        ("ground", Some(p)) => {
            if !p.iter().all(|x| x.is_finite()) {
                return Err(inv("position_m", format!("{p:?} is not a finite point")));
            }
            let id = m
                .add_node(&format!("{}.ground", h.name), p, ident())
                .map_err(|e| inv("name", e.to_string()))?;
            m.clamp(&format!("{}.ground_clamp", h.name), id)
                .map_err(|e| inv("name", e.to_string()))?;
            id
        }
        ("ground", None) => {
            return Err(inv(
                "position_m",
                "required with node_a = \"ground\": the ground attachment point [x, y, z] in m"
                    .into(),
            ))
        }
        (n, None) => node(m, "node_a", n)?,
        (_, Some(_)) => {
            return Err(inv(
                "position_m",
                "only allowed with node_a = \"ground\" (a node's position is its own)".into(),
            ))
        }
    };
    Ok((a, b))
}
