//! Rotor deck schema (docs/rotor_deck.md). Unknown keys are errors naming the file, line and
//! key; the `[damper]` table is read separately by [`crate::hydraulics::DamperDeck`].
use crate::hydraulics::DeckError;
use crate::structure::section::SectionProps;
use serde::Deserialize;
use std::path::Path;

/// The whole rotor deck file.
#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RotorSpec {
    pub rotor: RotorTable,
    pub blade: BladeTable,
    pub retention: RetentionTable,
    pub bearing: BearingTable,
    pub pitch_control: PitchControlTable,
    pub damper_attachment: DamperAttachment,
    /// Load output channels (docs/loads.md); defaults when absent.
    #[serde(default)]
    pub outputs: OutputsTable,
    /// Read by `DamperDeck` (kept opaque here).
    #[serde(default)]
    pub damper: Option<toml::Value>,
    /// Per-blade differences `[blades.K.<deck path>]`, read by `RotorDeck` (kept opaque here;
    /// always None in `RotorDeck::spec`, the base deck).
    #[serde(default)]
    pub blades: Option<toml::Value>,
    /// The airframe under the hub (docs/rotor_deck.md); a deck with one runs the whole rotor.
    #[serde(default)]
    pub airframe: Option<AirframeTable>,
    /// The blade's aerodynamics (docs/rotor_deck.md, "Aerodynamics"): what the lifting line of
    /// `--airloads computed|hybrid` needs.
    #[serde(default)]
    pub aero: Option<AeroTable>,
}

/// The blade's aerodynamic description.
#[derive(Clone, Debug, Deserialize, serde::Serialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct AeroTable {
    /// Chord [m] (constant along the blade).
    pub chord_m: f64,
    /// Start of the aerofoil [m]: no airloads inboard.
    pub cutout_r_m: f64,
    /// Tip-loss factor B: no lift outboard of B R (1: none).
    #[serde(default = "one_f64")]
    pub tip_loss_factor: f64,
    /// Inflow model: "uniform" (Glauert momentum), "drees" (linear) or "pitt-peters" (3-state
    /// dynamic inflow).
    #[serde(default = "default_inflow")]
    pub inflow: String,
    /// Aerofoils by radial segment, inboard first; none: the thin aerofoil (2 pi alpha).
    #[serde(rename = "airfoil", default)]
    pub airfoils: Vec<AirfoilSegment>,
}

/// One radial segment's aerofoil: a C81 table, or the thin aerofoil.
#[derive(Clone, Debug, Deserialize, serde::Serialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct AirfoilSegment {
    /// Outer end of the segment [m] (the last one covers the tip whatever its value).
    pub r_end_m: f64,
    /// C81 table file (relative paths: against the deck's folder); absent: thin aerofoil.
    #[serde(default)]
    pub c81: Option<String>,
}

fn one_f64() -> f64 {
    1.0
}

fn default_inflow() -> String {
    "drees".into()
}

impl AeroTable {
    /// Positive chord, cut-out inside the blade, B in (0, 1], a known inflow model, segments
    /// increasing; `Err((key, expected))`.
    fn check(&self, radius_m: f64) -> Result<(), (String, String)> {
        if !(self.chord_m.is_finite() && self.chord_m > 0.0) {
            return Err((
                "aero.chord_m".into(),
                format!("expected a positive number, found {}", self.chord_m),
            ));
        }
        if !(self.cutout_r_m.is_finite() && self.cutout_r_m >= 0.0 && self.cutout_r_m < radius_m) {
            return Err((
                "aero.cutout_r_m".into(),
                format!(
                    "expected a radius in [0, rotor.radius_m = {radius_m}), found {}",
                    self.cutout_r_m
                ),
            ));
        }
        if !(self.tip_loss_factor > 0.0 && self.tip_loss_factor <= 1.0) {
            return Err((
                "aero.tip_loss_factor".into(),
                format!(
                    "expected a number in (0, 1], found {}",
                    self.tip_loss_factor
                ),
            ));
        }
        if self
            .inflow
            .parse::<crate::aero::inflow::InflowModel>()
            .is_err()
        {
            return Err((
                "aero.inflow".into(),
                format!(
                    "expected \"uniform\", \"drees\" or \"pitt-peters\", found \"{}\"",
                    self.inflow
                ),
            ));
        }
        let mut prev = f64::NEG_INFINITY;
        for (i, a) in self.airfoils.iter().enumerate() {
            if !(a.r_end_m.is_finite() && a.r_end_m > prev) {
                return Err((
                    format!("aero.airfoil[{i}].r_end_m"),
                    format!(
                        "expected radii increasing from segment to segment, found {}",
                        a.r_end_m
                    ),
                ));
            }
            prev = a.r_end_m;
        }
        Ok(())
    }
}

/// The airframe under the hub: a mass, spring and damper in each of the hub's directions that
/// move (any subset of x, y, z, roll, pitch; the others are rigid), in the fixed frame.
/// Roll and pitch turn about a centre on the shaft (`center_z_m` above the hub; 0 by default).
#[derive(Clone, Debug, Default, Deserialize, serde::Serialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct AirframeTable {
    #[serde(default)]
    pub x: Option<AirframeTranslation>,
    #[serde(default)]
    pub y: Option<AirframeTranslation>,
    #[serde(default)]
    pub z: Option<AirframeTranslation>,
    #[serde(default)]
    pub roll: Option<AirframeRotation>,
    #[serde(default)]
    pub pitch: Option<AirframeRotation>,
    /// The modal form: the airframe's modes at the hub (instead of the directions above).
    #[serde(default)]
    pub mode: Vec<AirframeMode>,
}

/// One airframe mode seen from the hub: `q` its modal coordinate, the hub moving `phi q`
/// (m in x, y, z; rad in roll, pitch), kinetic energy `1/2 M q_dot^2`.
#[derive(Clone, Debug, Deserialize, serde::Serialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct AirframeMode {
    #[serde(rename = "frequency_Hz")]
    pub frequency_hz: f64,
    #[serde(default)]
    pub damping_ratio: f64,
    /// Generalized mass M for the mode shape's normalisation [kg].
    pub generalized_mass_kg: f64,
    /// The hub's displacement per unit modal coordinate: one of x, y, z, roll, pitch, or a
    /// rotation with the in-plane translation it carries (roll with y, pitch with x: a roll
    /// or pitch about a centre below or above the hub).
    pub participation: Participation,
}

#[derive(Clone, Debug, Default, Deserialize, serde::Serialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct Participation {
    #[serde(default)]
    pub x: f64,
    #[serde(default)]
    pub y: f64,
    #[serde(default)]
    pub z: f64,
    #[serde(default)]
    pub roll: f64,
    #[serde(default)]
    pub pitch: f64,
}

/// A translation of the hub: the airframe's effective mass, spring and damper in it.
#[derive(Clone, Debug, Deserialize, serde::Serialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct AirframeTranslation {
    pub mass_kg: f64,
    #[serde(rename = "stiffness_N_per_m")]
    pub stiffness: f64,
    #[serde(default, rename = "damping_Ns_per_m")]
    pub damping: f64,
}

/// A rotation of the hub about its centre: the airframe's effective inertia, spring, damper.
#[derive(Clone, Debug, Deserialize, serde::Serialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct AirframeRotation {
    #[serde(rename = "inertia_kg_m2")]
    pub inertia: f64,
    #[serde(rename = "stiffness_Nm_per_rad")]
    pub stiffness: f64,
    #[serde(default, rename = "damping_Nms_per_rad")]
    pub damping: f64,
    /// Height of the rotation's centre above the hub [m] (0: the hub centre; negative: below
    /// it, e.g. the airframe's centre of gravity).
    #[serde(default)]
    pub center_z_m: f64,
}

/// One moving direction of the airframe, in the order x, y, z, roll, pitch.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct AirframeDof {
    /// `x`, `y`, `z`, `roll` or `pitch` (the deck's key).
    pub name: &'static str,
    /// Axis 0-2 (x, y, z) of the hub's fixed frame.
    pub axis: usize,
    pub rotation: bool,
    /// Mass [kg] or inertia [kg m^2].
    pub mass: f64,
    /// [N/m] or [N m/rad].
    pub stiffness: f64,
    /// [N s/m] or [N m s/rad].
    pub damping: f64,
    /// Rotations: height of the axis's centre above the hub centre [m] (0 but for a mode whose
    /// rotation carries an in-plane hub translation).
    pub center_z_m: f64,
}

impl AirframeDof {
    /// Undamped natural frequency of the airframe alone in this direction [Hz].
    pub fn frequency_hz(&self) -> f64 {
        (self.stiffness / self.mass).sqrt() / (2.0 * std::f64::consts::PI)
    }
    /// Damping ratio of the airframe alone in this direction.
    pub fn damping_ratio(&self) -> f64 {
        self.damping / (2.0 * (self.stiffness * self.mass).sqrt())
    }
    /// Deck keys of the mass, stiffness and damping.
    pub fn keys(&self) -> [&'static str; 3] {
        if self.rotation {
            [
                "inertia_kg_m2",
                "stiffness_Nm_per_rad",
                "damping_Nms_per_rad",
            ]
        } else {
            ["mass_kg", "stiffness_N_per_m", "damping_Ns_per_m"]
        }
    }
}

impl AirframeMode {
    /// The one direction the mode moves, as the chain builds it (None: an unsupported
    /// participation, refused by the check). With `phi` the participation of the direction:
    /// mass `M / phi^2`, spring `M omega^2 / phi^2`, damper `2 zeta omega M / phi^2`.
    fn dof(&self) -> Option<AirframeDof> {
        let p = &self.participation;
        let all = [
            ("x", p.x),
            ("y", p.y),
            ("z", p.z),
            ("roll", p.roll),
            ("pitch", p.pitch),
        ];
        let nz: Vec<usize> = (0..5).filter(|&i| all[i].1 != 0.0).collect();
        // (direction index, centre height): a rotation about x through (0, 0, c) moves the hub
        // by y = c theta; about y, by x = -c theta
        let (i, center) = match nz.as_slice() {
            [i] => (*i, 0.0),
            [1, 3] => (3, p.y / p.roll),
            [0, 4] => (4, -p.x / p.pitch),
            _ => return None,
        };
        let phi = all[i].1;
        let w = 2.0 * std::f64::consts::PI * self.frequency_hz;
        let m = self.generalized_mass_kg / (phi * phi);
        Some(AirframeDof {
            name: all[i].0,
            axis: if i < 3 { i } else { i - 3 },
            rotation: i >= 3,
            mass: m,
            stiffness: m * w * w,
            damping: 2.0 * self.damping_ratio * w * m,
            center_z_m: center,
        })
    }
}

impl AirframeTable {
    /// The modal form's rules: positive frequency and generalized mass, non-negative damping
    /// ratio, a supported participation, no direction in two modes, no direction keys beside.
    fn check_modes(&self) -> Result<(), (String, String)> {
        if let Some(d) = [
            ("x", self.x.is_some()),
            ("y", self.y.is_some()),
            ("z", self.z.is_some()),
            ("roll", self.roll.is_some()),
            ("pitch", self.pitch.is_some()),
        ]
        .iter()
        .find(|d| d.1)
        {
            return Err((
                format!("airframe.{}", d.0),
                "an airframe is given either by directions or by modes ([[airframe.mode]]), not both".into(),
            ));
        }
        let mut used: Vec<&str> = Vec::new();
        for (i, m) in self.mode.iter().enumerate() {
            let key = |k: &str| format!("airframe.mode[{i}].{k}");
            for (k, v, positive) in [
                ("frequency_Hz", m.frequency_hz, true),
                ("generalized_mass_kg", m.generalized_mass_kg, true),
                ("damping_ratio", m.damping_ratio, false),
            ] {
                if !(v.is_finite() && if positive { v > 0.0 } else { v >= 0.0 }) {
                    let what = if positive {
                        "a positive number"
                    } else {
                        "a non-negative number"
                    };
                    return Err((key(k), format!("expected {what}, found {v}")));
                }
            }
            let p = &m.participation;
            if [p.x, p.y, p.z, p.roll, p.pitch]
                .iter()
                .any(|v| !v.is_finite())
            {
                return Err((key("participation"), "expected finite numbers".into()));
            }
            let Some(d) = m.dof() else {
                return Err((
                    key("participation"),
                    "expected one of x, y, z, roll, pitch, or roll with y, or pitch with x (a rotation about a centre above or below the hub); other combinations are not supported".into(),
                ));
            };
            let dirs: Vec<&str> = [
                ("x", p.x),
                ("y", p.y),
                ("z", p.z),
                ("roll", p.roll),
                ("pitch", p.pitch),
            ]
            .iter()
            .filter(|v| v.1 != 0.0)
            .map(|v| v.0)
            .collect();
            if let Some(twice) = dirs.iter().find(|x| used.contains(x)) {
                return Err((
                    key("participation"),
                    format!("{twice} moves in an earlier mode too: each hub direction may move in one mode only (the chain gives each mode its own direction)"),
                ));
            }
            used.extend(dirs);
            let _ = d;
        }
        Ok(())
    }

    /// The directions that move, in the order x, y, z, roll, pitch.
    pub fn dofs(&self) -> Vec<AirframeDof> {
        let t = |name, axis, v: &Option<AirframeTranslation>| {
            v.as_ref().map(|v| AirframeDof {
                name,
                axis,
                rotation: false,
                mass: v.mass_kg,
                stiffness: v.stiffness,
                damping: v.damping,
                center_z_m: 0.0,
            })
        };
        let r = |name, axis, v: &Option<AirframeRotation>| {
            v.as_ref().map(|v| AirframeDof {
                name,
                axis,
                rotation: true,
                mass: v.inertia,
                stiffness: v.stiffness,
                damping: v.damping,
                center_z_m: v.center_z_m,
            })
        };
        if !self.mode.is_empty() {
            let mut v: Vec<AirframeDof> = self.mode.iter().filter_map(AirframeMode::dof).collect();
            // translations first (the chain's order), rotations after
            v.sort_by_key(|d| (d.rotation, d.axis));
            return v;
        }
        [
            t("x", 0, &self.x),
            t("y", 1, &self.y),
            t("z", 2, &self.z),
            r("roll", 0, &self.roll),
            r("pitch", 1, &self.pitch),
        ]
        .into_iter()
        .flatten()
        .collect()
    }

    /// Each moving direction in words: mass, spring, damper, frequency and damping ratio.
    pub fn describe(&self) -> Vec<String> {
        self.dofs()
            .iter()
            .map(|d| {
                let (m, k, c) = if d.rotation {
                    ("kg m^2", "N m/rad", "N m s/rad")
                } else {
                    ("kg", "N/m", "N s/m")
                };
                let center = if d.center_z_m != 0.0 {
                    format!(", about a centre {:.3} m above the hub", d.center_z_m)
                } else {
                    String::new()
                };
                format!(
                    "{}: {} {m}, spring {} {k}, damper {} {c} ({:.3} Hz, damping ratio {:.3}{center})",
                    d.name,
                    d.mass,
                    d.stiffness,
                    d.damping,
                    d.frequency_hz(),
                    d.damping_ratio()
                )
            })
            .collect()
    }

    /// Positive masses and stiffnesses, non-negative dampings, at least one direction;
    /// `Err((key, expected))`.
    fn check(&self) -> Result<(), (String, String)> {
        if !self.mode.is_empty() {
            return self.check_modes();
        }
        let dofs = self.dofs();
        if dofs.is_empty() {
            return Err((
                "airframe".into(),
                "an airframe table without a moving direction: give at least one of x, y, z, roll, pitch".into(),
            ));
        }
        for d in &dofs {
            let [km, kk, kc] = d.keys();
            for (k, v, positive) in [
                (km, d.mass, true),
                (kk, d.stiffness, true),
                (kc, d.damping, false),
            ] {
                let ok = v.is_finite() && if positive { v > 0.0 } else { v >= 0.0 };
                if !ok {
                    let what = if k == kk {
                        "a positive number (a direction without a spring has no periodic solution; leave the direction out to make it rigid)"
                    } else if positive {
                        "a positive number"
                    } else {
                        "a non-negative number"
                    };
                    return Err((
                        format!("airframe.{}.{k}", d.name),
                        format!("expected {what}, found {v}"),
                    ));
                }
            }
            if !d.center_z_m.is_finite() {
                return Err((
                    format!("airframe.{}.center_z_m", d.name),
                    format!("expected a finite height in m, found {}", d.center_z_m),
                ));
            }
        }
        Ok(())
    }
}

#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RotorTable {
    pub omega_rad_s: f64,
    pub radius_m: f64,
    pub blades: usize,
}

impl RotorTable {
    /// The rules of `[rotor]` both kinds of deck share: the failing key and what was expected.
    /// (The radius is checked by each kind against its blade.)
    pub fn check(&self) -> Result<(), (&'static str, String)> {
        let w = self.omega_rad_s;
        if !(w.is_finite() && w > 0.0) {
            return Err((
                "rotor.omega_rad_s",
                format!("expected a positive number, found {w}"),
            ));
        }
        if self.blades == 0 {
            return Err(("rotor.blades", "expected at least 1 blade".into()));
        }
        Ok(())
    }
}

#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BladeTable {
    /// Section table (relative paths: against the deck's folder), `s_m = r - root_r_m`.
    pub sections_csv: String,
    pub elements: usize,
    pub root_r_m: f64,
    #[serde(default)]
    pub damping_mu_s: f64,
    /// Built-in twist `[[r_m, deg], ...]`.
    #[serde(default)]
    pub twist_deg: Vec<[f64; 2]>,
    /// Gain g of the perturbation aerodynamic damping (src/rotor/transient.rs); 0 disables.
    #[serde(default)]
    pub perturbation_damping_gain: f64,
    /// Its delay in revolutions (default 1).
    #[serde(default = "one")]
    pub perturbation_damping_delay_revs: usize,
    /// Section frame in which the record's airloads are applied (default `deformed`).
    #[serde(default)]
    pub airload_frame: AirloadFrame,
}

/// Section frame of the replayed airloads. The in-plane load is the small difference of two
/// large projections (`N sin(theta) + C cos(theta)` aft), so a pitch difference between the frame
/// the loads were measured in and the model's frame moves the lag moment by `N d(theta)` per
/// unit span (docs/rotor_model.md, "Airload frame").
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum AirloadFrame {
    /// docs/formats.md: the deformed (follower) section frame of the model, elastic twist included.
    #[default]
    Deformed,
    /// The deformed frame turned about the section axis to the rigid pitch, bearing pitch from
    /// the controls plus the built-in twist: the frame of a blade rigid in torsion and control
    /// (for records whose loads are given in that frame, such as the shipped synthetic one).
    ControlPitch,
}

impl AirloadFrame {
    pub fn name(self) -> &'static str {
        match self {
            AirloadFrame::Deformed => "deformed",
            AirloadFrame::ControlPitch => "control_pitch",
        }
    }
}

fn one() -> usize {
    1
}

#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Segment {
    pub elements: usize,
    pub section: SectionProps,
    #[serde(default)]
    pub damping_mu_s: f64,
}

#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RetentionTable {
    pub hinge_r_m: f64,
    pub horn_r_m: f64,
    pub segment1: Segment,
    pub segment2: Segment,
    pub segment3: Segment,
}

#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BearingTable {
    #[serde(rename = "lag_stiffness_Nm_per_rad")]
    pub lag_k: f64,
    #[serde(rename = "flap_stiffness_Nm_per_rad")]
    pub flap_k: f64,
    #[serde(rename = "pitch_stiffness_Nm_per_rad")]
    pub pitch_k: f64,
    #[serde(rename = "lag_damping_Nms_per_rad", default)]
    pub lag_c: f64,
    #[serde(rename = "flap_damping_Nms_per_rad", default)]
    pub flap_c: f64,
    #[serde(rename = "pitch_damping_Nms_per_rad", default)]
    pub pitch_c: f64,
    /// Elastomer per axis: a constant loss factor over `elastomer_band_per_rev`, the axis's
    /// stiffness being its storage stiffness at `<axis>_reference_per_rev` (no damping key on
    /// that axis then).
    #[serde(default)]
    pub lag_loss_factor: Option<f64>,
    #[serde(default)]
    pub flap_loss_factor: Option<f64>,
    #[serde(default)]
    pub pitch_loss_factor: Option<f64>,
    #[serde(default = "one_per_rev", rename = "lag_reference_per_rev")]
    pub lag_reference: f64,
    #[serde(default = "one_per_rev", rename = "flap_reference_per_rev")]
    pub flap_reference: f64,
    #[serde(default = "one_per_rev", rename = "pitch_reference_per_rev")]
    pub pitch_reference: f64,
    #[serde(default = "elastomer_band", rename = "elastomer_band_per_rev")]
    pub elastomer_band: [f64; 2],
}

fn one_per_rev() -> f64 {
    1.0
}

/// Default band of an elastomer's constant loss factor [per rev]: from below the lag
/// frequency (about 0.27/rev on an articulated rotor) to 4/rev.
fn elastomer_band() -> [f64; 2] {
    [0.25, 4.0]
}

fn kv(key: &str, msg: &str) -> (String, String) {
    (key.to_string(), msg.to_string())
}

/// One axis of the elastomeric bearing.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum BearingAxis {
    Lag,
    Flap,
    Pitch,
}

impl BearingAxis {
    pub const ALL: [BearingAxis; 3] = [BearingAxis::Lag, BearingAxis::Flap, BearingAxis::Pitch];
    pub fn name(self) -> &'static str {
        match self {
            BearingAxis::Lag => "lag",
            BearingAxis::Flap => "flap",
            BearingAxis::Pitch => "pitch",
        }
    }
}

/// An axis's elastomer as the deck states it, frequencies in rad/s.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct AxisElastomer {
    pub loss_factor: f64,
    pub band_rad_s: [f64; 2],
    pub reference_rad_s: f64,
}

impl BearingTable {
    /// Stiffness, damping and loss factor (if an elastomer) of an axis.
    fn axis(&self, a: BearingAxis) -> (f64, f64, Option<f64>, f64) {
        match a {
            BearingAxis::Lag => (
                self.lag_k,
                self.lag_c,
                self.lag_loss_factor,
                self.lag_reference,
            ),
            BearingAxis::Flap => (
                self.flap_k,
                self.flap_c,
                self.flap_loss_factor,
                self.flap_reference,
            ),
            BearingAxis::Pitch => (
                self.pitch_k,
                self.pitch_c,
                self.pitch_loss_factor,
                self.pitch_reference,
            ),
        }
    }

    /// The axis's elastomer at rotor speed `omega` [rad/s] (None: a spring and a dashpot).
    pub fn elastomer(&self, a: BearingAxis, omega: f64) -> Option<AxisElastomer> {
        let (_, _, eta, r) = self.axis(a);
        eta.map(|loss_factor| AxisElastomer {
            loss_factor,
            band_rad_s: self.elastomer_band.map(|x| x * omega),
            reference_rad_s: r * omega,
        })
    }

    /// Spring and dashpot of an axis [N m/rad, N m s/rad] for the linear models (fan plot,
    /// ground and air resonance, amplitude checks): the deck's own, or an elastomer's storage
    /// stiffness and `K''/w` at its reference frequency (exact there, and within its loss
    /// factor's frequency dependence elsewhere).
    pub fn equivalent(&self, a: BearingAxis, omega: f64) -> (f64, f64) {
        let (k, c, _, _) = self.axis(a);
        match self.elastomer(a, omega) {
            None => (k, c),
            Some(e) => (k, e.loss_factor * k / e.reference_rad_s),
        }
    }

    /// Checks the elastomer keys: positive loss factors and references in the band, no
    /// damping key beside a loss factor, and a chain that fits (passive) at `omega`.
    fn check_elastomers(&self, omega: f64) -> Result<(), (String, String)> {
        let [lo, hi] = self.elastomer_band;
        if !(lo.is_finite() && hi.is_finite() && lo > 0.0 && hi > lo) {
            return Err(kv(
                "bearing.elastomer_band_per_rev",
                &format!("[{lo}, {hi}]: expected 0 < low < high"),
            ));
        }
        for a in BearingAxis::ALL {
            let n = a.name();
            let (k, c, eta, r) = self.axis(a);
            let Some(eta) = eta else { continue };
            if !(eta.is_finite() && eta > 0.0 && eta < 1.0) {
                return Err(kv(
                    &format!("bearing.{n}_loss_factor"),
                    &format!("{eta}: expected between 0 and 1"),
                ));
            }
            if c != 0.0 {
                return Err(kv(
                    &format!("bearing.{n}_damping_Nms_per_rad"),
                    &format!("the {n} axis is an elastomer (bearing.{n}_loss_factor): its damping comes from the loss factor; remove one of the two"),
                ));
            }
            if !(r >= lo && r <= hi) {
                return Err(kv(
                    &format!("bearing.{n}_reference_per_rev"),
                    &format!("{r}: expected within bearing.elastomer_band_per_rev [{lo}, {hi}]"),
                ));
            }
            if k.is_nan() || k <= 0.0 {
                return Err(kv(
                    &format!("bearing.{n}_stiffness_Nm_per_rad"),
                    "an elastomer needs a positive storage stiffness",
                ));
            }
            let e = self.elastomer(a, omega).expect("loss factor given");
            crate::structure::elastomer::MaxwellChain::fit(
                k,
                eta,
                e.band_rad_s[0],
                e.band_rad_s[1],
                e.reference_rad_s,
            )
            .map_err(|m| kv(&format!("bearing.{n}_loss_factor"), &m))?;
        }
        Ok(())
    }
}

#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PitchControlTable {
    /// Pitch-link attachment on the horn (spherical joint), hub frame [m].
    pub horn_tip_m: [f64; 3],
    pub horn_mass_kg: f64,
    pub link_length_m: f64,
    pub link_elements: usize,
    pub link_section: SectionProps,
    /// Cyclic and airload harmonics ramp in over this many revolutions (forced response).
    #[serde(default = "two")]
    pub cyclic_ramp_revs: f64,
}

fn two() -> f64 {
    2.0
}

#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct DamperAttachment {
    /// Distance of the damper line from the lag hinge axis [m] (stroke = arm x lag angle).
    pub arm_m: f64,
    /// Pin-to-pin length at zero lag [m] (zero stroke).
    pub reference_length_m: f64,
    /// Height of the damper line above the hinge plane [m].
    #[serde(default)]
    pub height_m: f64,
    pub arm_mass_kg: f64,
    pub horn_mass_kg: f64,
}

/// Section kinds of the `[outputs]` table, in channel order, with their units.
pub const SECTION_KINDS: [(&str, &str); 6] = [
    ("flap_moment", "Nm"),
    ("chord_moment", "Nm"),
    ("torsion_moment", "Nm"),
    ("shear_flap", "N"),
    ("shear_chord", "N"),
    ("axial_force", "N"),
];

/// `[outputs]`: where section loads are recovered and which (docs/loads.md).
#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct OutputsTable {
    /// Blade stations r/R (default 0.1 to 0.9 by 0.1).
    #[serde(rename = "stations_r_over_R", default = "default_stations")]
    pub stations_r_over_r: Vec<f64>,
    /// Also the section just outboard of the bearing (r = hinge_r_m) and of the pitch horn
    /// (r = horn_r_m).
    #[serde(default = "yes")]
    pub bearing_station: bool,
    #[serde(default = "yes")]
    pub horn_station: bool,
    /// Section channels at every station (default all of [`SECTION_KINDS`]).
    #[serde(default = "default_kinds")]
    pub section_channels: Vec<String>,
}

impl Default for OutputsTable {
    fn default() -> Self {
        OutputsTable {
            stations_r_over_r: default_stations(),
            bearing_station: true,
            horn_station: true,
            section_channels: default_kinds(),
        }
    }
}

fn default_stations() -> Vec<f64> {
    (1..=9).map(|k| k as f64 / 10.0).collect()
}
fn default_kinds() -> Vec<String> {
    SECTION_KINDS.iter().map(|k| k.0.to_string()).collect()
}
fn yes() -> bool {
    true
}

/// Mass moments of a blade about its lag hinge: what turns with the lag angle (the blade's
/// section table and the retention outboard of the hinge, segments 2 and 3).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LagMoments {
    pub mass_kg: f64,
    /// First moment about the hinge [kg m].
    pub first_moment_kg_m: f64,
    /// Second moment about the hinge [kg m^2].
    pub inertia_kg_m2: f64,
}

/// The error for a hinged-blade deck given where an elastomeric rotor is read.
fn hinged_deck(file: &str) -> DeckError {
    DeckError::file(
        file,
        "a hinged-blade deck ([[hinge]] tables, docs/rotor_deck.md \"Hinged-blade decks\") has no pitch link or damper: only `rotorsim modes --rotor` reads it",
    )
    .in_deck(ROTOR_DECK)
}

impl RotorSpec {
    /// The bearing's lag spring and dashpot for the linear models (an elastomer's equivalent
    /// at its reference frequency, [`BearingTable::equivalent`]).
    pub fn bearing_lag(&self) -> (f64, f64) {
        self.bearing
            .equivalent(BearingAxis::Lag, self.rotor.omega_rad_s)
    }

    /// The bearing's flap spring and dashpot for the linear models.
    pub fn bearing_flap(&self) -> (f64, f64) {
        self.bearing
            .equivalent(BearingAxis::Flap, self.rotor.omega_rad_s)
    }

    /// The blade's [`LagMoments`]: trapezoid on a fine grid of the section table (piecewise
    /// linear) from `blade.root_r_m` to the tip, plus retention segments 2 and 3 (uniform); the
    /// root hardware (horn, damper lever) is left out. `deck_path`: where the section table's
    /// path is relative to.
    pub fn lag_moments(&self, deck_path: &std::path::Path) -> anyhow::Result<LagMoments> {
        use crate::structure::section::SectionTable;
        let e = self.retention.hinge_r_m;
        let (r0, radius) = (self.blade.root_r_m, self.rotor.radius_m);
        let csv = deck_path
            .parent()
            .unwrap_or(std::path::Path::new(""))
            .join(&self.blade.sections_csv);
        let table = SectionTable::from_csv(&csv)?;
        let (mut m0, mut s1, mut i2) = (0.0, 0.0, 0.0);
        let n = 4000;
        let ds = (radius - r0) / n as f64;
        for k in 0..=n {
            let s = k as f64 * ds;
            let w = if k == 0 || k == n { 0.5 * ds } else { ds };
            let m = table.at(s).m;
            let x = r0 + s - e;
            m0 += w * m;
            s1 += w * m * x;
            i2 += w * m * x * x;
        }
        for (seg, a, b) in [
            (&self.retention.segment2, e, self.retention.horn_r_m),
            (&self.retention.segment3, self.retention.horn_r_m, r0),
        ] {
            let m = seg.section.m;
            m0 += m * (b - a);
            s1 += m * ((b - e).powi(2) - (a - e).powi(2)) / 2.0;
            i2 += m * ((b - e).powi(3) - (a - e).powi(3)) / 3.0;
        }
        Ok(LagMoments {
            mass_kg: m0,
            first_moment_kg_m: s1,
            inertia_kg_m2: i2,
        })
    }

    /// Unknowns and stored matrix entries of the expanded model, estimated as for a model deck
    /// (a cubic beam element adds 3 nodes of 6 dofs; a dozen joints and bodies beside them).
    pub fn size_estimate(&self) -> (f64, f64) {
        let e: f64 = self.element_counts().iter().map(|(_, n)| *n as f64).sum();
        let nodes = 3.0 * e + 5.0 + 8.0;
        let lambdas = 6.0 * 12.0;
        let ndof = 6.0 * nodes + lambdas;
        (ndof, 576.0 * e + 324.0 * 12.0 + ndof)
    }

    /// The element counts of the deck by key.
    fn element_counts(&self) -> [(&'static str, usize); 5] {
        [
            ("blade.elements", self.blade.elements),
            (
                "retention.segment1.elements",
                self.retention.segment1.elements,
            ),
            (
                "retention.segment2.elements",
                self.retention.segment2.elements,
            ),
            (
                "retention.segment3.elements",
                self.retention.segment3.elements,
            ),
            (
                "pitch_control.link_elements",
                self.pitch_control.link_elements,
            ),
        ]
    }

    /// Refuses `estimate` (of `what`, a cost of this deck's model) beyond the budget, naming the
    /// deck file and its largest element count.
    pub fn check_budget(
        &self,
        deck: &Path,
        what: &str,
        estimate: crate::solver::budget::Estimate,
    ) -> anyhow::Result<()> {
        let (key, n) = self
            .element_counts()
            .into_iter()
            .max_by_key(|(_, n)| *n)
            .unwrap_or(("blade.elements", 0));
        let (ndof, _) = self.size_estimate();
        estimate
            .check(
                &format!("{}: {what} of {ndof:.0} unknowns", deck.display()),
                &format!("the largest element count is {key} = {n}; use fewer elements"),
            )
            .map_err(Into::into)
    }

    /// The flight record must be of this rotor: its rotor speed (0.1%), radius (1%: records
    /// quote R rounded) and, where the record states them, the number of blades, the lag hinge
    /// offset and the damper arm (2%). A record of another rotor, or in other units, is refused
    /// before anything runs, naming both keys.
    pub fn check_record(
        &self,
        record: &crate::flight::FlightRecord,
        deck: &Path,
    ) -> anyhow::Result<()> {
        let m = &record.meta;
        let differs = |rkey: &str, rv: f64, dkey: &str, dv: f64, unit: &str, tol: f64| {
            if rv.is_finite() && (rv - dv).abs() <= tol * dv.abs() {
                return Ok(());
            }
            Err(anyhow::anyhow!(
                "flight record {rkey} = {rv} {unit} differs from the rotor deck {} {dkey} = {dv} {unit}                  by more than {}%: the record is of another rotor (or in other units)",
                deck.display(),
                tol * 100.0
            ))
        };
        let om = self.rotor.omega_rad_s;
        let rec_om = m.rotor_speed_rad_s;
        if !rec_om.is_finite() || (rec_om - om).abs() > 1e-3 * om {
            anyhow::bail!(
                "flight record rotor speed {rec_om} rad/s differs from the rotor deck's {om} rad/s ({})",
                deck.display()
            );
        }
        differs(
            "radius_m",
            m.radius_m,
            "rotor.radius_m",
            self.rotor.radius_m,
            "m",
            0.01,
        )?;
        let raw = |k: &str| m.raw.get(k).and_then(|v| v.as_f64());
        if let Some(nb) = raw("number_of_blades") {
            differs(
                "number_of_blades",
                nb,
                "rotor.blades",
                self.rotor.blades as f64,
                "",
                0.0,
            )?;
        }
        if let Some(e) = raw("lag_hinge_offset_m") {
            differs(
                "lag_hinge_offset_m",
                e,
                "retention.hinge_r_m",
                self.retention.hinge_r_m,
                "m",
                0.02,
            )?;
        }
        if let Some(a) = raw("damper_arm_m") {
            differs(
                "damper_arm_m",
                a,
                "damper_attachment.arm_m",
                self.damper_attachment.arm_m,
                "m",
                0.02,
            )?;
        }
        Ok(())
    }

    /// Stations of section loads: (r [m], r/R) in increasing r, the bearing and horn stations
    /// included when asked.
    pub fn load_stations(&self) -> Vec<(f64, f64)> {
        let big_r = self.rotor.radius_m;
        let mut v: Vec<(f64, f64)> = self
            .outputs
            .stations_r_over_r
            .iter()
            .map(|x| (x * big_r, *x))
            .collect();
        if self.outputs.bearing_station {
            v.push((self.retention.hinge_r_m, self.retention.hinge_r_m / big_r));
        }
        if self.outputs.horn_station {
            v.push((self.retention.horn_r_m, self.retention.horn_r_m / big_r));
        }
        v.sort_by(|a, b| a.0.total_cmp(&b.0));
        v
    }

    /// Parse deck text; `file` names it in errors (toml reports line and column).
    pub fn parse(text: &str, file: &str) -> Result<Self, DeckError> {
        if super::RotorKind::of_text(text) == super::RotorKind::Hinged {
            return Err(hinged_deck(file));
        }
        let spec: RotorSpec = toml::from_str(text)
            .map_err(|e| DeckError::file(file, e.to_string().trim_end()).in_deck(ROTOR_DECK))?;
        spec.validate(file)?;
        Ok(spec)
    }

    pub fn from_file(path: &Path) -> Result<Self, DeckError> {
        let file = path.display().to_string();
        let text = std::fs::read_to_string(path)
            .map_err(|e| DeckError::read(&file, e).in_deck(ROTOR_DECK))?;
        Self::parse(&text, &file)
    }

    /// The deck of parsed (and possibly overridden) tables, validated like [`RotorSpec::parse`].
    pub fn from_table(root: &toml::Table, file: &str) -> Result<Self, DeckError> {
        if root.contains_key("hinge") {
            return Err(hinged_deck(file));
        }
        let spec = Self::schema(root)
            .map_err(|e| DeckError::file(file, e.message().trim_end()).in_deck(ROTOR_DECK))?;
        spec.validate(file)?;
        Ok(spec)
    }

    /// The tables read by the schema alone (no value checked).
    pub fn schema(root: &toml::Table) -> Result<Self, toml::de::Error> {
        toml::Value::Table(root.clone()).try_into()
    }

    fn validate(&self, file: &str) -> Result<(), DeckError> {
        self.check_parts(file)?;
        self.check_geometry(file)?;
        self.check_values(file)?;
        self.check_outputs(file)
    }

    /// Rotor speed, airframe, aerodynamics, blade count, sections and the finite values.
    fn check_parts(&self, file: &str) -> Result<(), DeckError> {
        let bad = |key: &str, msg: &str| deck_error(file, key, msg);
        let nonneg = |key: &str, v: f64| check_non_negative(file, key, v);
        self.rotor.check().map_err(|(k, what)| bad(k, &what))?;
        if let Some(a) = &self.airframe {
            a.check().map_err(|(k, what)| bad(&k, &what))?;
        }
        if let Some(a) = &self.aero {
            a.check(self.rotor.radius_m)
                .map_err(|(k, what)| bad(&k, &what))?;
        }
        for (key, sec) in [
            (
                "retention.segment1.section",
                &self.retention.segment1.section,
            ),
            (
                "retention.segment2.section",
                &self.retention.segment2.section,
            ),
            (
                "retention.segment3.section",
                &self.retention.segment3.section,
            ),
            (
                "pitch_control.link_section",
                &self.pitch_control.link_section,
            ),
        ] {
            sec.check().map_err(|(k, what)| {
                let v = toml::Value::try_from(sec)
                    .ok()
                    .and_then(|t| t.get(k).cloned())
                    .map_or("?".to_string(), |v| v.to_string());
                bad(
                    &format!("{key}.{k}"),
                    &format!("expected {what}, found {v}"),
                )
            })?;
        }
        for (key, seg) in [
            ("retention.segment1.damping_mu_s", &self.retention.segment1),
            ("retention.segment2.damping_mu_s", &self.retention.segment2),
            ("retention.segment3.damping_mu_s", &self.retention.segment3),
        ] {
            nonneg(key, seg.damping_mu_s)?;
        }
        if self.pitch_control.horn_tip_m.iter().any(|v| !v.is_finite()) {
            return Err(bad(
                "pitch_control.horn_tip_m",
                &format!(
                    "expected three finite coordinates, found {:?}",
                    self.pitch_control.horn_tip_m
                ),
            ));
        }
        if let Some(p) = self
            .blade
            .twist_deg
            .iter()
            .find(|p| !(p[0].is_finite() && p[1].is_finite()))
        {
            return Err(bad(
                "blade.twist_deg",
                &format!("expected finite [r_m, deg] pairs, found {p:?}"),
            ));
        }
        Ok(())
    }

    /// Radii in order and element counts.
    fn check_geometry(&self, file: &str) -> Result<(), DeckError> {
        let bad = |key: &str, msg: &str| deck_error(file, key, msg);
        let pos = |key: &str, v: f64| check_positive(file, key, v);
        pos("rotor.radius_m", self.rotor.radius_m)?;
        let r = &self.retention;
        pos("retention.hinge_r_m", r.hinge_r_m)?;
        if !(r.horn_r_m > r.hinge_r_m && r.horn_r_m < self.blade.root_r_m) {
            return Err(bad(
                "retention.horn_r_m",
                "expected hinge_r_m < horn_r_m < blade.root_r_m",
            ));
        }
        if self.blade.root_r_m >= self.rotor.radius_m {
            return Err(bad("blade.root_r_m", "expected less than rotor.radius_m"));
        }
        for (k, n) in [
            ("blade.elements", self.blade.elements),
            ("retention.segment1.elements", r.segment1.elements),
            ("retention.segment2.elements", r.segment2.elements),
            ("retention.segment3.elements", r.segment3.elements),
            (
                "pitch_control.link_elements",
                self.pitch_control.link_elements,
            ),
        ] {
            if n == 0 {
                return Err(bad(k, "expected at least one element"));
            }
        }
        if self.blade.perturbation_damping_delay_revs == 0 {
            return Err(bad(
                "blade.perturbation_damping_delay_revs",
                "expected at least 1 revolution",
            ));
        }
        Ok(())
    }

    /// Bearing, masses, lengths and the pitch horn and twist tables.
    fn check_values(&self, file: &str) -> Result<(), DeckError> {
        let bad = |key: &str, msg: &str| deck_error(file, key, msg);
        let pos = |key: &str, v: f64| check_positive(file, key, v);
        let nonneg = |key: &str, v: f64| check_non_negative(file, key, v);
        let b = &self.bearing;
        for (k, v) in [
            ("bearing.lag_stiffness_Nm_per_rad", b.lag_k),
            ("bearing.flap_stiffness_Nm_per_rad", b.flap_k),
            ("bearing.pitch_stiffness_Nm_per_rad", b.pitch_k),
            ("bearing.lag_damping_Nms_per_rad", b.lag_c),
            ("bearing.flap_damping_Nms_per_rad", b.flap_c),
            ("bearing.pitch_damping_Nms_per_rad", b.pitch_c),
            (
                "pitch_control.horn_mass_kg",
                self.pitch_control.horn_mass_kg,
            ),
            (
                "pitch_control.cyclic_ramp_revs",
                self.pitch_control.cyclic_ramp_revs,
            ),
            (
                "damper_attachment.arm_mass_kg",
                self.damper_attachment.arm_mass_kg,
            ),
            (
                "damper_attachment.horn_mass_kg",
                self.damper_attachment.horn_mass_kg,
            ),
            ("blade.damping_mu_s", self.blade.damping_mu_s),
            (
                "blade.perturbation_damping_gain",
                self.blade.perturbation_damping_gain,
            ),
        ] {
            nonneg(k, v)?;
        }
        self.bearing
            .check_elastomers(self.rotor.omega_rad_s)
            .map_err(|(k, m)| bad(&k, &m))?;
        pos(
            "pitch_control.link_length_m",
            self.pitch_control.link_length_m,
        )?;
        pos("damper_attachment.arm_m", self.damper_attachment.arm_m)?;
        pos(
            "damper_attachment.reference_length_m",
            self.damper_attachment.reference_length_m,
        )?;
        let h = self.pitch_control.horn_tip_m;
        if (h[1].powi(2) + h[2].powi(2)).sqrt() < 1e-3 {
            return Err(bad(
                "pitch_control.horn_tip_m",
                "the horn tip must lie off the pitch axis (y or z offset)",
            ));
        }
        let tw = &self.blade.twist_deg;
        if tw.windows(2).any(|w| w[1][0] <= w[0][0]) {
            return Err(bad("blade.twist_deg", "r_m must be strictly increasing"));
        }
        Ok(())
    }

    /// Output stations and section channels.
    fn check_outputs(&self, file: &str) -> Result<(), DeckError> {
        let bad = |key: &str, msg: &str| deck_error(file, key, msg);
        let o = &self.outputs;
        let lo = self.retention.hinge_r_m / self.rotor.radius_m;
        for x in &o.stations_r_over_r {
            if !(x.is_finite() && *x >= lo && *x <= 1.0) {
                return Err(bad(
                    "outputs.stations_r_over_R",
                    &format!(
                        "{x} is outside the blade: expected hinge_r_m / radius_m = {lo:.4} to 1"
                    ),
                ));
            }
        }
        for k in &o.section_channels {
            if !SECTION_KINDS.iter().any(|c| c.0 == k) {
                let known: Vec<&str> = SECTION_KINDS.iter().map(|c| c.0).collect();
                return Err(bad(
                    "outputs.section_channels",
                    &format!(
                        "unknown channel `{k}`, expected some of {}",
                        known.join(", ")
                    ),
                ));
            }
        }
        // channel names carry r/R to two decimals: two stations must not share one
        let mut names: Vec<String> = self
            .load_stations()
            .iter()
            .map(|(_, x)| format!("{x:.2}"))
            .collect();
        let n = names.len();
        names.dedup();
        if names.len() != n {
            return Err(bad(
                "outputs.stations_r_over_R",
                "two stations (the bearing and horn stations included) round to the same r/R at two decimals",
            ));
        }
        Ok(())
    }
}

/// How a rotor deck is named in its errors.
pub(crate) const ROTOR_DECK: &str = "rotor deck";

pub(crate) fn deck_error(file: &str, key: &str, msg: &str) -> DeckError {
    DeckError::invalid(file, key, msg).in_deck(ROTOR_DECK)
}

fn check_positive(file: &str, key: &str, v: f64) -> Result<(), DeckError> {
    if v.is_finite() && v > 0.0 {
        Ok(())
    } else {
        Err(deck_error(
            file,
            key,
            &format!("expected a positive number, found {v}"),
        ))
    }
}

fn check_non_negative(file: &str, key: &str, v: f64) -> Result<(), DeckError> {
    if v.is_finite() && v >= 0.0 {
        Ok(())
    } else {
        Err(deck_error(
            file,
            key,
            &format!("expected a non-negative number, found {v}"),
        ))
    }
}
