//! Hinged-blade rotor decks (docs/rotor_deck.md, "Hinged-blade decks"): a blade on a chain of
//! hinges (lag, flap, pitch revolute joints at given radii, each with an optional spring and
//! dashpot; rotations without a hinge are locked), a blade of uniform-section segments and
//! concentrated masses, no pitch link or hydraulic damper. Example: rotors/tm4760.toml (the
//! NASA TM-4760 model blade, docs/validation_tm4760.md).
//!
//! What this module gives: the expansion into a model deck (docs/model_deck.md), the fan plot
//! (rotating equilibrium + linearisation at each speed, as src/rotor/fan.rs) with the rigid and
//! elastic modes told apart by the nodes of their shapes, and the free-decay run (lag displaced
//! by a static moment on the blade root, then ramped off) with its damped frequency and damping
//! ratio from a least-squares fit of a damped sine.
use super::deck::RotorTable;
use crate::hydraulics::DeckError;
use crate::solver::modal::{modes, ModalOptions, Mode, ModeKind};
use crate::solver::statics::{static_solve, StaticOptions};
use crate::solver::{DynamicSolver, NewtonMethod, State};
use crate::structure::deck::{
    BeamDeck, Deck, DynamicDeck, JointDeck, LoadDeck, ModesDeck, NodeDeck, RigidDeck, SensorDeck,
    StaticDeck,
};
use crate::structure::deck_text::{to_toml, DeckBuilder};
use crate::structure::model::{Element, Model};
use crate::structure::section::SectionProps;
use serde::Deserialize;
use std::path::{Path, PathBuf};

/// How a hinged-blade deck is named in its errors.
const HINGED_DECK: &str = "hinged-blade rotor deck";

/// Rotation a hinge frees (hub frame; angle signs as the bearing of docs/rotor_deck.md).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum HingeAxis {
    /// About -z: positive aft (against rotation).
    Lag,
    /// About -y: positive up.
    Flap,
    /// About +x: positive nose up.
    Pitch,
}

impl HingeAxis {
    pub fn name(self) -> &'static str {
        match self {
            HingeAxis::Lag => "lag",
            HingeAxis::Flap => "flap",
            HingeAxis::Pitch => "pitch",
        }
    }
    /// Joint axis and x-direction hint (global, undeformed).
    fn axes(self) -> ([f64; 3], [f64; 3]) {
        match self {
            HingeAxis::Lag => ([0.0, 0.0, -1.0], [1.0, 0.0, 0.0]),
            HingeAxis::Flap => ([0.0, -1.0, 0.0], [1.0, 0.0, 0.0]),
            HingeAxis::Pitch => ([1.0, 0.0, 0.0], [0.0, 1.0, 0.0]),
        }
    }
}

#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Hinge {
    pub axis: HingeAxis,
    /// Radius of the hinge point [m].
    pub r_m: f64,
    #[serde(rename = "stiffness_Nm_per_rad", default)]
    pub k: f64,
    #[serde(rename = "damping_Nms_per_rad", default)]
    pub c: f64,
}

#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BladeSegment {
    /// Outer end of the segment [m] (the first starts at `blade.root_r_m`).
    pub r_end_m: f64,
    pub elements: usize,
    pub section: SectionProps,
}

#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SegmentedBlade {
    /// Start of the blade beam [m] (at or outboard of the last hinge; rigid in between).
    pub root_r_m: f64,
    /// Stiffness-proportional structural damping mu [s] (default 0).
    #[serde(default)]
    pub damping_mu_s: f64,
    #[serde(rename = "segment")]
    pub segments: Vec<BladeSegment>,
}

/// A concentrated mass on the blade, attached rigidly to the nearest blade node.
#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PointMass {
    pub name: String,
    /// Radius of its centre of mass [m].
    pub r_m: f64,
    pub mass_kg: f64,
    /// Centre-of-mass offset from the blade axis, [y (toward the leading edge), z (up)] [m].
    #[serde(default)]
    pub offset_m: [f64; 2],
    /// Principal inertias about its centre of mass, blade axes [x, y, z] [kg m^2].
    #[serde(default)]
    pub inertia_kgm2: [f64; 3],
}

/// Reference frequencies drawn over the fan plot and compared in `fan_comparison.csv`.
#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FanReference {
    /// CSV (relative to the deck): `rpm` then columns named as [`TRACKED`] with `_Hz`.
    pub csv: String,
    /// Legend label of the points.
    pub label: String,
}

#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct HingedSpec {
    pub rotor: RotorTable,
    #[serde(rename = "hinge")]
    pub hinges: Vec<Hinge>,
    pub blade: SegmentedBlade,
    #[serde(rename = "mass", default)]
    pub masses: Vec<PointMass>,
    #[serde(default)]
    pub fan_reference: Option<FanReference>,
}

/// The modes followed in the fan plot of a hinged blade, in this order.
pub const TRACKED: [&str; 7] = [
    "rigid_lag",
    "rigid_flap",
    "flap1",
    "flap2",
    "lag1",
    "flap3",
    "torsion1",
];

impl HingedSpec {
    pub fn parse(text: &str, file: &str) -> Result<Self, DeckError> {
        let spec: HingedSpec = toml::from_str(text)
            .map_err(|e| DeckError::file(file, e.to_string().trim_end()).in_deck(HINGED_DECK))?;
        spec.validate(file)?;
        Ok(spec)
    }

    pub fn from_file(path: &Path) -> Result<Self, DeckError> {
        let file = path.display().to_string();
        let text = std::fs::read_to_string(path)
            .map_err(|e| DeckError::read(&file, e).in_deck(HINGED_DECK))?;
        Self::parse(&text, &file)
    }

    /// Nominal rotor speed [rpm].
    pub fn rpm(&self) -> f64 {
        self.rotor.omega_rad_s * 60.0 / (2.0 * std::f64::consts::PI)
    }

    fn validate(&self, file: &str) -> Result<(), DeckError> {
        let bad = |key: &str, msg: String| DeckError::invalid(file, key, msg).in_deck(HINGED_DECK);
        let fin = |v: f64| v.is_finite();
        self.rotor.check().map_err(|(key, msg)| bad(key, msg))?;
        if self.hinges.is_empty() {
            return Err(bad("hinge", "expected at least one [[hinge]]".into()));
        }
        let mut r_prev = 0.0;
        let mut seen = vec![];
        for (i, h) in self.hinges.iter().enumerate() {
            let key = |k: &str| format!("hinge[{i}].{k}");
            if !(fin(h.r_m) && h.r_m >= r_prev) {
                return Err(bad(
                    &key("r_m"),
                    format!(
                        "expected a finite radius >= {r_prev} (hinges listed from the hub outward), found {}",
                        h.r_m
                    ),
                ));
            }
            r_prev = h.r_m;
            for (k, v) in [("stiffness_Nm_per_rad", h.k), ("damping_Nms_per_rad", h.c)] {
                if !(fin(v) && v >= 0.0) {
                    return Err(bad(
                        &key(k),
                        format!("expected a non-negative number, found {v}"),
                    ));
                }
            }
            if seen.contains(&h.axis) {
                return Err(bad(
                    &key("axis"),
                    format!("a second `{}` hinge (one per axis)", h.axis.name()),
                ));
            }
            seen.push(h.axis);
        }
        let b = &self.blade;
        if !(fin(b.root_r_m) && b.root_r_m >= r_prev) {
            return Err(bad(
                "blade.root_r_m",
                format!(
                    "expected a radius at or outboard of the last hinge ({r_prev} m), found {}",
                    b.root_r_m
                ),
            ));
        }
        if !(fin(b.damping_mu_s) && b.damping_mu_s >= 0.0) {
            return Err(bad(
                "blade.damping_mu_s",
                format!("expected a non-negative number, found {}", b.damping_mu_s),
            ));
        }
        if b.segments.is_empty() {
            return Err(bad(
                "blade.segment",
                "expected at least one [[blade.segment]]".into(),
            ));
        }
        let mut r0 = b.root_r_m;
        for (i, s) in b.segments.iter().enumerate() {
            let key = |k: &str| format!("blade.segment[{i}].{k}");
            if !(fin(s.r_end_m) && s.r_end_m > r0) {
                return Err(bad(
                    &key("r_end_m"),
                    format!(
                        "expected a radius beyond the segment's start {r0} m, found {}",
                        s.r_end_m
                    ),
                ));
            }
            r0 = s.r_end_m;
            if s.elements == 0 {
                return Err(bad(
                    &key("elements"),
                    "expected at least one element".into(),
                ));
            }
            s.section.check().map_err(|(k, what)| {
                let v = toml::Value::try_from(s.section)
                    .ok()
                    .and_then(|t| t.get(k).cloned())
                    .map_or("?".to_string(), |v| v.to_string());
                bad(
                    &key(&format!("section.{k}")),
                    format!("expected {what}, found {v}"),
                )
            })?;
        }
        let tip = r0;
        let rr = self.rotor.radius_m;
        if !(fin(rr) && (rr - tip).abs() <= 1e-9 * rr.abs().max(1.0)) {
            return Err(bad(
                "rotor.radius_m",
                format!("expected the outer end of the last blade segment ({tip} m), found {rr}"),
            ));
        }
        self.validate_masses(file, tip)
    }

    /// The point masses: unique names, on the blade (root to `tip`), positive, finite.
    fn validate_masses(&self, file: &str, tip: f64) -> Result<(), DeckError> {
        let bad = |key: &str, msg: String| DeckError::invalid(file, key, msg).in_deck(HINGED_DECK);
        let fin = |v: f64| v.is_finite();
        let b = &self.blade;
        let mut names: Vec<&str> = vec![];
        for (i, m) in self.masses.iter().enumerate() {
            let key = |k: &str| format!("mass[{i}].{k}");
            if m.name.is_empty() || names.contains(&m.name.as_str()) {
                return Err(bad(
                    &key("name"),
                    format!("expected a unique non-empty name, found `{}`", m.name),
                ));
            }
            names.push(&m.name);
            if !(fin(m.r_m) && m.r_m >= b.root_r_m && m.r_m <= tip) {
                return Err(bad(
                    &key("r_m"),
                    format!(
                        "expected a radius on the blade ({} to {tip} m), found {}",
                        b.root_r_m, m.r_m
                    ),
                ));
            }
            if !(fin(m.mass_kg) && m.mass_kg > 0.0) {
                return Err(bad(
                    &key("mass_kg"),
                    format!("expected a positive mass, found {}", m.mass_kg),
                ));
            }
            if m.offset_m.iter().any(|v| !fin(*v)) {
                return Err(bad(
                    &key("offset_m"),
                    format!("expected two finite numbers, found {:?}", m.offset_m),
                ));
            }
            if m.inertia_kgm2.iter().any(|v| !(fin(*v) && *v >= 0.0)) {
                return Err(bad(
                    &key("inertia_kgm2"),
                    format!(
                        "expected three non-negative numbers, found {:?}",
                        m.inertia_kgm2
                    ),
                ));
            }
        }
        Ok(())
    }

    /// Radii of the blade nodes with their names, root to tip.
    pub fn blade_nodes(&self) -> Vec<(String, f64)> {
        let mut v = vec![];
        let mut r0 = self.blade.root_r_m;
        for (k, s) in self.blade.segments.iter().enumerate() {
            let n = 3 * s.elements;
            if k == 0 {
                v.push((self.root_node(), r0));
            }
            for j in 1..=n {
                v.push((
                    format!("blade_s{k}.n{j}"),
                    r0 + (s.r_end_m - r0) * j as f64 / n as f64,
                ));
            }
            r0 = s.r_end_m;
        }
        v
    }

    /// Name of the blade's first node: the last hinge's node when the blade starts there.
    pub fn root_node(&self) -> String {
        let n = self.hinges.len();
        if self.blade.root_r_m == self.hinges[n - 1].r_m {
            format!("hinge{}", n - 1)
        } else {
            "blade_s0.n0".to_string()
        }
    }

    /// Name of the tip node.
    pub fn tip_node(&self) -> String {
        let k = self.blade.segments.len() - 1;
        format!("blade_s{k}.n{}", 3 * self.blade.segments[k].elements)
    }
}

/// Options of the expansion.
#[derive(Clone, Debug, Default)]
pub struct HingedExpand {
    /// Shaft speed of the prescribed hub rotation and of `[static]` [rad/s] (None: nominal).
    pub omega_rad_s: Option<f64>,
    /// Static moment about the lag hinge axis on the blade root [N m] (positive aft), removed
    /// over `lag_release_time_s` (free-decay release, linear ramp to zero); 0: none.
    pub lag_release_moment_nm: f64,
    pub lag_release_time_s: f64,
    /// `[dynamic]` time step and end time [s] (None: 256 steps per revolution, one revolution).
    pub time_step_s: Option<f64>,
    pub end_time_s: Option<f64>,
    /// Hub clamped instead of driven (the model of a solver working in the frame that turns
    /// with the shaft, [`crate::solver::DynamicSolver::frame_omega`]).
    pub hub_clamped: bool,
}

/// The model deck (docs/model_deck.md): hub node driven at Omega (`shaft`), the hinges as
/// revolute joints `lag`/`flap`/`pitch` through the nodes `hinge0`, `hinge1`, ... (a hinge
/// outboard of the previous one hangs on a rigid offset, `*_base` clamped to its parent), the
/// blade segments `blade_s0`, `blade_s1`, ... sharing their end nodes, the masses as rigid
/// bodies on the nearest blade node.
pub fn expand_deck(spec: &HingedSpec, opts: &HingedExpand) -> Deck {
    let om = opts.omega_rad_s.unwrap_or(spec.rotor.omega_rad_s);
    let mut d = DeckBuilder::new(
        vec![
            "Multibody model deck generated from a hinged-blade rotor deck (docs/rotor_deck.md)."
                .into(),
        ],
        "rotor: single hinged blade",
    );
    d.node(NodeDeck::at("hub", [0.0; 3]));
    if opts.hub_clamped {
        d.joint(JointDeck::new("shaft", "clamp", None, "hub"))
            .comment =
            vec!["hub fixed: the state is relative to the frame turning with the shaft".into()];
    } else {
        d.joint(JointDeck {
            axis: Some([0.0, 0.0, 1.0]),
            omega_rad_s: Some(om),
            ..JointDeck::new("shaft", "revolute", None, "hub")
        });
    }
    let parent = add_hinges(&mut d, spec);
    add_blade(&mut d, spec, &parent);
    add_lag_release(&mut d, spec, opts);
    d.sensor(SensorDeck::at_node("tip", &spec.tip_node()));
    for h in &spec.hinges {
        d.sensor(SensorDeck::at_joint(h.axis.name(), h.axis.name()));
    }
    let period = 2.0 * std::f64::consts::PI / om;
    let deck = d.deck_mut();
    deck.statics = StaticDeck {
        load_steps: 1,
        omega_rad_s: Some([0.0, 0.0, om]),
        ..Default::default()
    };
    deck.dynamic = DynamicDeck {
        time_step_s: Some(opts.time_step_s.unwrap_or(period / 256.0)),
        end_time_s: Some(opts.end_time_s.unwrap_or(period)),
        initial_omega_rad_s: Some([0.0, 0.0, om]),
        start_from_static: true,
        ..Default::default()
    };
    deck.modes = ModesDeck {
        count: 14,
        ..Default::default()
    };
    d.finish()
}

/// The hinges from the hub out; returns the last hinge's node and radius.
fn add_hinges(d: &mut DeckBuilder, spec: &HingedSpec) -> (String, f64) {
    let mut parent = ("hub".to_string(), 0.0);
    for (i, h) in spec.hinges.iter().enumerate() {
        let p = [h.r_m, 0.0, 0.0];
        let a = if h.r_m != parent.1 {
            let base = format!("hinge{i}_base");
            d.node(NodeDeck::at(&base, p));
            let mount = format!("{base}_mount");
            d.joint(JointDeck::new(&mount, "clamp", Some(&parent.0), &base));
            base
        } else {
            parent.0.clone()
        };
        let b = format!("hinge{i}");
        d.node(NodeDeck::at(&b, p));
        let (axis, xd) = h.axis.axes();
        d.joint(JointDeck {
            axis: Some(axis),
            x_direction: Some(xd),
            stiffness: Some(h.k),
            damping: Some(h.c),
            ..JointDeck::new(h.axis.name(), "revolute", Some(&a), &b)
        });
        parent = (b, h.r_m);
    }
    parent
}

/// The blade segments (on the last hinge's node, or clamped to it) and the masses.
fn add_blade(d: &mut DeckBuilder, spec: &HingedSpec, parent: &(String, f64)) {
    let b = &spec.blade;
    let root_start = (b.root_r_m == parent.1).then(|| parent.0.clone());
    let mut r0 = b.root_r_m;
    for (k, seg) in b.segments.iter().enumerate() {
        let start = if k == 0 {
            root_start.clone()
        } else {
            Some(format!(
                "blade_s{}.n{}",
                k - 1,
                3 * b.segments[k - 1].elements
            ))
        };
        d.beam(BeamDeck {
            start_node: start,
            start_m: Some([r0, 0.0, 0.0]),
            end_m: Some([seg.r_end_m, 0.0, 0.0]),
            // the station is not the model's: zero, as the printed deck has always had it
            section: Some(SectionProps {
                s_m: 0.0,
                ..seg.section
            }),
            damping_mu_s: Some(b.damping_mu_s),
            ..BeamDeck::new(&format!("blade_s{k}"), seg.elements)
        });
        r0 = seg.r_end_m;
    }
    if root_start.is_none() {
        d.joint(JointDeck::new(
            "blade_root",
            "clamp",
            Some(&parent.0),
            "blade_s0.n0",
        ));
    }
    let nodes = spec.blade_nodes();
    for m in &spec.masses {
        let (name, rn) = nodes
            .iter()
            .min_by(|a, b| (a.1 - m.r_m).abs().total_cmp(&(b.1 - m.r_m).abs()))
            .cloned()
            .unwrap_or_else(|| (spec.root_node(), b.root_r_m));
        let i = m.inertia_kgm2;
        d.rigid_body(RigidDeck {
            name: m.name.clone(),
            node: name,
            mass_kg: m.mass_kg,
            cm_offset_m: Some([m.r_m - rn, m.offset_m[0], m.offset_m[1]]),
            inertia_kgm2: [[i[0], 0.0, 0.0], [0.0, i[1], 0.0], [0.0, 0.0, i[2]]],
        });
    }
}

/// The free-decay release: a static lag moment at t = 0, ramped to zero.
fn add_lag_release(d: &mut DeckBuilder, spec: &HingedSpec, opts: &HingedExpand) {
    let lag = spec.hinges.iter().any(|h| h.axis == HingeAxis::Lag);
    if opts.lag_release_moment_nm == 0.0 || !lag {
        return;
    }
    let (axis, _) = HingeAxis::Lag.axes();
    let mz = opts.lag_release_moment_nm;
    d.load(LoadDeck {
        name: "lag_release".into(),
        node: spec.root_node(),
        force: [0.0; 3],
        moment: [mz * axis[0], mz * axis[1], mz * axis[2]],
        follower: false,
        time_table: Some(vec![[0.0, 1.0], [opts.lag_release_time_s.max(1e-9), 0.0]]),
    })
    .comment = vec!["Free decay: static lag moment at t = 0, ramped to zero".into()];
}

/// The model deck text ([`expand_deck`] as TOML).
pub fn expand(spec: &HingedSpec, opts: &HingedExpand) -> String {
    to_toml(&expand_deck(spec, opts))
}

/// The model of the expanded deck (relative paths against the deck's folder).
pub fn expanded_model(
    spec: &HingedSpec,
    opts: &HingedExpand,
    file: &Path,
) -> anyhow::Result<Model> {
    super::sim::model_of_expanded(&expand_deck(spec, opts), file)
}

/// Modes at one rotor speed.
#[derive(Clone, Debug)]
pub struct HingedFanPoint {
    pub fraction: f64,
    pub omega_rad_s: f64,
    pub modes: Vec<Mode>,
    /// Damped frequencies `Im(s) / 2 pi` [Hz] of [`TRACKED`] (NaN when not found: e.g. a free
    /// hinge without rotation has a zero eigenvalue, no oscillation).
    pub tracked_hz: [f64; 7],
    /// Damping ratios of [`TRACKED`].
    pub tracked_zeta: [f64; 7],
}

/// Damped frequency `Im(s) / 2 pi` of a mode [Hz] (`freq_hz` is `|s| / 2 pi`).
pub fn damped_hz(m: &Mode) -> f64 {
    m.freq_hz * (1.0 - m.damping_ratio * m.damping_ratio).max(0.0).sqrt()
}

/// Sign changes of a shape component along the blade (values below 1e-3 of the largest are
/// skipped): 0 for a rigid hinge mode, n for the n-th elastic mode.
fn crossings(v: &[f64]) -> usize {
    let mx = v.iter().fold(0.0f64, |m, x| m.max(x.abs()));
    let mut last = 0.0f64;
    let mut n = 0;
    for &x in v {
        if x.abs() <= 1e-3 * mx {
            continue;
        }
        if last != 0.0 && x.signum() != last.signum() {
            n += 1;
        }
        last = x;
    }
    n
}

/// Assign the modes (sorted by frequency) to [`TRACKED`]: by kind (dominant mass-weighted
/// fraction) and, for flap and lag, by the number of nodes of the out-of-plane (z) or in-plane
/// (y) displacement along the blade (0 rigid, 1 first elastic, ...); the first torsion mode.
pub fn track(ms: &[Mode], blade_nodes: &[usize]) -> ([f64; 7], [f64; 7]) {
    let mut hz = [f64::NAN; 7];
    let mut zeta = [f64::NAN; 7];
    for m in ms {
        let comp = |c: usize| -> Vec<f64> { blade_nodes.iter().map(|&i| m.shape[i][c]).collect() };
        let slot = match m.kind {
            ModeKind::Lag => match crossings(&comp(1)) {
                0 => Some(0),
                1 => Some(4),
                _ => None,
            },
            ModeKind::Flap => match crossings(&comp(2)) {
                0 => Some(1),
                1 => Some(2),
                2 => Some(3),
                3 => Some(5),
                _ => None,
            },
            ModeKind::Torsion => Some(6),
            ModeKind::Axial => None,
        };
        if let Some(k) = slot {
            if hz[k].is_nan() {
                hz[k] = damped_hz(m);
                zeta[k] = m.damping_ratio;
            }
        }
    }
    (hz, zeta)
}

/// Spectral shift of the modal analysis [1/s]: a hinge without spring at rest has a zero
/// eigenvalue (singular K), about which the unshifted shift-invert form loses the rest of the
/// spectrum (measured: flap 2 at rest 7% low, 0.0003 Hz for the free flap hinge).
pub const MODAL_SHIFT_RAD_S: f64 = 1.0;

/// Rotating equilibrium at `omega` and the modes about it.
pub fn modes_at(
    spec: &HingedSpec,
    file: &Path,
    omega: f64,
    count: usize,
) -> anyhow::Result<(Model, Vec<Mode>)> {
    let mut model = expanded_model(spec, &HingedExpand::default(), file)?;
    let mut st = State::from_model(&model);
    let rot = if omega > 0.0 {
        Some([0.0, 0.0, omega])
    } else {
        None
    };
    static_solve(
        &mut model,
        &mut st,
        &StaticOptions {
            load_steps: 1,
            omega: rot,
            ..Default::default()
        },
        |_, _, _, _| {},
    )
    .map_err(|e| anyhow::anyhow!("equilibrium at {omega} rad/s: {e}"))?;
    let ms = modes(
        &mut model,
        &st,
        &ModalOptions {
            n_modes: count,
            omega: rot,
            // a free hinge at rest leaves K singular: shift-invert about s = 1/s (docs/rotor_deck.md)
            shift_rad_s: MODAL_SHIFT_RAD_S,
        },
    )?;
    Ok((model, ms))
}

/// Model node ids of the blade nodes, root to tip.
pub fn blade_node_ids(spec: &HingedSpec, model: &Model) -> anyhow::Result<Vec<usize>> {
    spec.blade_nodes()
        .iter()
        .map(|(n, _)| Ok(model.node_id(n)?))
        .collect()
}

/// Fan plot at the speed fractions of the nominal Omega.
pub fn fan(
    spec: &HingedSpec,
    file: &Path,
    fractions: &[f64],
    count: usize,
) -> anyhow::Result<Vec<HingedFanPoint>> {
    let mut out = vec![];
    for &x in fractions {
        if !(x.is_finite() && x >= 0.0) {
            anyhow::bail!("speed fraction {x} must be finite and non-negative");
        }
        let om = x * spec.rotor.omega_rad_s;
        let (model, ms) = modes_at(spec, file, om, count)
            .map_err(|e| anyhow::anyhow!("{} at {x} x Omega: {e}", file.display()))?;
        let ids = blade_node_ids(spec, &model)?;
        let (hz, zeta) = track(&ms, &ids);
        out.push(HingedFanPoint {
            fraction: x,
            omega_rad_s: om,
            modes: ms,
            tracked_hz: hz,
            tracked_zeta: zeta,
        });
    }
    Ok(out)
}

/// One reference row: rotor speed [rpm] and the frequencies of [`TRACKED`] [Hz] (NaN: blank).
#[derive(Clone, Debug, PartialEq)]
pub struct ReferenceRow {
    pub rpm: f64,
    pub hz: [f64; 7],
}

/// Read a reference table: `#` lines are comments; header `rpm` and `NAME_Hz` for the names of
/// [`TRACKED`] (any order, all required).
pub fn read_reference(path: &Path) -> anyhow::Result<Vec<ReferenceRow>> {
    let file = path.display().to_string();
    let text = std::fs::read_to_string(path)
        .map_err(|e| anyhow::anyhow!("reference table {file}: cannot read: {e}"))?;
    let mut lines = text
        .lines()
        .enumerate()
        .filter(|(_, l)| !l.trim().is_empty() && !l.trim_start().starts_with('#'));
    let (_, head) = lines
        .next()
        .ok_or_else(|| anyhow::anyhow!("reference table {file}: no header"))?;
    let head: Vec<&str> = head.split(',').map(str::trim).collect();
    let col = |n: &str| {
        head.iter().position(|h| *h == n).ok_or_else(|| {
            anyhow::anyhow!("reference table {file}: no column `{n}` (header {head:?})")
        })
    };
    let c_rpm = col("rpm")?;
    let cols: Vec<usize> = TRACKED
        .iter()
        .map(|t| col(&format!("{t}_Hz")))
        .collect::<Result<_, _>>()?;
    let mut rows = vec![];
    for (i, l) in lines {
        let v: Vec<&str> = l.split(',').map(str::trim).collect();
        let get = |c: usize| -> anyhow::Result<f64> {
            v.get(c).and_then(|s| s.parse::<f64>().ok()).ok_or_else(|| {
                anyhow::anyhow!(
                    "reference table {file}, line {}: expected a number in column {}",
                    i + 1,
                    head[c]
                )
            })
        };
        let mut hz = [f64::NAN; 7];
        for (k, &c) in cols.iter().enumerate() {
            hz[k] = get(c)?;
        }
        rows.push(ReferenceRow {
            rpm: get(c_rpm)?,
            hz,
        });
    }
    Ok(rows)
}

impl HingedSpec {
    /// The deck's reference table path (relative to the deck's folder), if any.
    pub fn reference_path(&self, deck: &Path) -> Option<PathBuf> {
        self.fan_reference
            .as_ref()
            .map(|r| deck.parent().unwrap_or(Path::new("")).join(&r.csv))
    }
}

/// Options of the free-decay run.
#[derive(Clone, Copy, Debug)]
pub struct DecayOptions {
    /// Rotor speed [rad/s].
    pub omega_rad_s: f64,
    /// Static lag moment [N m] (positive aft) that displaces the blade before the release.
    pub release_moment_nm: f64,
    /// Release: the moment ramps linearly to zero over this time [s] (a step release would
    /// depend on the integrator's convention for the initial acceleration).
    pub release_time_s: f64,
    pub time_step_s: f64,
    pub rho_inf: f64,
    pub newton: NewtonMethod,
    pub newton_rtol: f64,
    /// March in the frame turning with the shaft (hub clamped, centrifugal and Coriolis terms
    /// in the kinematics) instead of the inertial frame with the hub driven.
    pub rotating_frame: bool,
}

/// Free decay of the lag hinge: the blade in rotating equilibrium under a static lag moment,
/// ramped off (`release_time_s`) and marched by the generalized-alpha solver (full nonlinear
/// model; inertial frame with the shaft driven at Omega, or the frame turning with it).
pub struct DecaySim {
    pub solver: DynamicSolver,
    lag: usize,
    /// Lag angle at the unloaded rotating equilibrium [rad].
    pub lag_eq_rad: f64,
}

fn joint_angle(m: &Model, id: usize) -> f64 {
    match &m.elements[id] {
        Element::Joint(j) => j.angle_prev,
        _ => f64::NAN,
    }
}

impl DecaySim {
    /// The initial lag angle is the displaced equilibrium's ([`DecaySim::lag_angle_rad`]
    /// before the first step).
    pub fn new(spec: &HingedSpec, file: &Path, opts: &DecayOptions) -> anyhow::Result<Self> {
        let om = opts.omega_rad_s;
        let rot = Some([0.0, 0.0, om]);
        let sopts = StaticOptions {
            load_steps: 1,
            omega: rot,
            ..Default::default()
        };
        // unloaded equilibrium: the lag angle the decay settles to
        let rf = opts.rotating_frame;
        let mut m0 = expanded_model(
            spec,
            &HingedExpand {
                omega_rad_s: Some(om),
                hub_clamped: rf,
                ..Default::default()
            },
            file,
        )?;
        let mut s0 = State::from_model(&m0);
        static_solve(&mut m0, &mut s0, &sopts, |_, _, _, _| {})
            .map_err(|e| anyhow::anyhow!("unloaded equilibrium at {om} rad/s: {e}"))?;
        let lag0 = m0
            .element_id("lag")
            .ok_or_else(|| anyhow::anyhow!("{}: no lag hinge", file.display()))?;
        let lag_eq_rad = joint_angle(&m0, lag0);
        let mut model = expanded_model(
            spec,
            &HingedExpand {
                omega_rad_s: Some(om),
                lag_release_moment_nm: opts.release_moment_nm,
                lag_release_time_s: opts.release_time_s,
                time_step_s: Some(opts.time_step_s),
                hub_clamped: rf,
                ..Default::default()
            },
            file,
        )?;
        let lag = model
            .element_id("lag")
            .ok_or_else(|| anyhow::anyhow!("{}: no lag hinge", file.display()))?;
        let mut st = State::from_model(&model);
        static_solve(&mut model, &mut st, &sopts, |_, _, _, _| {})
            .map_err(|e| anyhow::anyhow!("displaced equilibrium at {om} rad/s: {e}"))?;
        if rf {
            // at rest in the turning frame: relative velocities and accelerations zero (the
            // static equilibrium holds at t = 0, so these are the consistent initial values)
            for v in [&mut st.v, &mut st.w, &mut st.a, &mut st.al] {
                v.iter_mut().for_each(|x| *x = [0.0; 3]);
            }
        }
        let mut solver = DynamicSolver::new(model, st, opts.time_step_s, opts.rho_inf)?;
        solver.newton.method = opts.newton;
        solver.newton.rtol = opts.newton_rtol;
        if rf {
            solver.frame_omega = Some([0.0, 0.0, om]);
        } else {
            solver.init_accelerations()?;
        }
        Ok(DecaySim {
            solver,
            lag,
            lag_eq_rad,
        })
    }

    /// Lag hinge angle [rad] (positive aft) at the last converged step.
    pub fn lag_angle_rad(&self) -> f64 {
        joint_angle(&self.solver.model, self.lag)
    }

    pub fn step(&mut self) -> anyhow::Result<()> {
        self.solver
            .step()
            .map_err(|e| anyhow::anyhow!("free decay: {e}"))?;
        Ok(())
    }
}

/// Damped frequency [Hz] and damping ratio of a uniformly sampled decay `x` (time step `h`):
/// Levenberg-Marquardt least-squares fit of `x(t) = c + exp(-sigma t) (a cos(w t) + b sin(w t))`
/// (5 parameters, analytic Jacobian) started from `guess = (Hz, zeta)` (e.g. the log
/// decrement's); `zeta = sigma / sqrt(sigma^2 + w^2)`. Faster components (elastic modes still
/// ringing) are residuals, not bias. None when the fit fails.
pub fn fit_damped_sine(x: &[f64], h: f64, guess: (f64, f64)) -> Option<(f64, f64)> {
    use levenberg_marquardt::{LeastSquaresProblem, LevenbergMarquardt};
    use nalgebra::{DMatrix, DVector, Dyn, Owned};
    struct P<'a> {
        x: &'a [f64],
        h: f64,
        p: DVector<f64>,
    }
    impl LeastSquaresProblem<f64, Dyn, Dyn> for P<'_> {
        type ResidualStorage = Owned<f64, Dyn>;
        type JacobianStorage = Owned<f64, Dyn, Dyn>;
        type ParameterStorage = Owned<f64, Dyn>;
        fn set_params(&mut self, p: &DVector<f64>) {
            self.p.copy_from(p);
        }
        fn params(&self) -> DVector<f64> {
            self.p.clone()
        }
        fn residuals(&self) -> Option<DVector<f64>> {
            let [c, a, b, sg, w] = [self.p[0], self.p[1], self.p[2], self.p[3], self.p[4]];
            Some(DVector::from_iterator(
                self.x.len(),
                self.x.iter().enumerate().map(|(k, &v)| {
                    let t = k as f64 * self.h;
                    let (sn, cs) = (w * t).sin_cos();
                    c + (-sg * t).exp() * (a * cs + b * sn) - v
                }),
            ))
        }
        fn jacobian(&self) -> Option<DMatrix<f64>> {
            let [_, a, b, sg, w] = [self.p[0], self.p[1], self.p[2], self.p[3], self.p[4]];
            let mut j = DMatrix::zeros(self.x.len(), 5);
            for k in 0..self.x.len() {
                let t = k as f64 * self.h;
                let (sn, cs) = (w * t).sin_cos();
                let e = (-sg * t).exp();
                j[(k, 0)] = 1.0;
                j[(k, 1)] = e * cs;
                j[(k, 2)] = e * sn;
                j[(k, 3)] = -t * e * (a * cs + b * sn);
                j[(k, 4)] = t * e * (-a * sn + b * cs);
            }
            Some(j)
        }
    }
    if x.len() < 8 || guess.0.is_nan() || guess.0 <= 0.0 {
        return None;
    }
    let w0 = 2.0 * std::f64::consts::PI * guess.0;
    let sg0 = guess.1 * w0 / (1.0 - guess.1 * guess.1).max(1e-12).sqrt();
    let c0 = x.iter().sum::<f64>() / x.len() as f64;
    let p0 = DVector::from_vec(vec![c0, x[0] - c0, 0.0, sg0, w0]);
    let (pb, report) = LevenbergMarquardt::new()
        .with_xtol(1e-12)
        .with_ftol(1e-14)
        .minimize(P { x, h, p: p0 });
    if !report.termination.was_successful() {
        return None;
    }
    let (sg, w) = (pb.p[3], pb.p[4]);
    Some((
        w / (2.0 * std::f64::consts::PI),
        sg / (sg * sg + w * w).sqrt(),
    ))
}

/// Damped frequency [Hz] and damping ratio from the peaks of `x - x_eq` (logarithmic
/// decrement over the peaks found, parabolic interpolation of each peak): the cross-check of
/// [`fit_damped_sine`]. None with fewer than three peaks.
pub fn log_decrement(x: &[f64], x_eq: f64, h: f64) -> Option<(f64, f64)> {
    let mut peaks = vec![];
    for k in 1..x.len().saturating_sub(1) {
        let (a, b, c) = (x[k - 1] - x_eq, x[k] - x_eq, x[k + 1] - x_eq);
        if b > 0.0 && b >= a && b > c {
            // parabola through the three samples
            let den = a - 2.0 * b + c;
            let d = if den != 0.0 { 0.5 * (a - c) / den } else { 0.0 };
            let t = (k as f64 + d) * h;
            let v = b - 0.25 * (a - c) * d;
            peaks.push((t, v));
        }
    }
    if peaks.len() < 3 {
        return None;
    }
    let n = peaks.len() - 1;
    let (t0, v0) = peaks[0];
    let (tn, vn) = peaks[n];
    let period = (tn - t0) / n as f64;
    let delta = (v0 / vn).ln() / n as f64;
    let zeta = delta / (4.0 * std::f64::consts::PI * std::f64::consts::PI + delta * delta).sqrt();
    Some((1.0 / period, zeta))
}
