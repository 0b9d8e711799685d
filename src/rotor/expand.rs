//! Rotor deck -> typed multibody model deck (docs/model_deck.md). A run builds its model from
//! the typed deck; `rotorsim expand` prints the same deck through the one deck writer
//! ([`crate::structure::deck_text::to_toml`]), so that the printed deck is exactly the model that
//! runs.
//!
//! Layout (hub frame, blade along +x, rotation about +z, y toward the leading edge), paper
//! Fig. 15: hub node driven at Omega (prescribed revolute `shaft`); segment 1 (`seg1`) from the
//! axis to the hinge; elastomeric bearing = revolute joints `lag` (axis -z: positive aft),
//! `flap` (axis -y: positive up), `pitch` (axis +x: positive nose up) through the massless
//! nodes `bearing_lag`, `bearing_flap`; segments 2 and 3 (`seg2`, `seg3`, sharing the horn
//! node); blade (`blade`) clamped to segment 3; pitch horn (rigid body on the horn node) with a
//! spherical joint to the pitch link (`pitch_link`), universal joint at the swashplate node
//! whose prescribed vertical motion in the hub frame gives the pitch; damper between
//! `damper_hub_end` (rigid to the hub) and `damper_blade_end` (rigid to `bearing_lag`, so the
//! stroke is `arm x lag angle`).
use super::deck::{AxisElastomer, BearingAxis, RotorSpec, Segment};
use crate::structure::deck::{
    BeamDeck, Deck, DynamicDeck, ElastomerDeck, HydraulicDeck, JointDeck, ModesDeck, NodeDeck,
    RigidDeck, SensorDeck, StaticDeck,
};
use crate::structure::deck_text::{to_toml, DeckBuilder};
use crate::structure::section::SectionProps;

/// Blade-pitch controls [deg]: `theta = th0 + th1c cos psi + th1s sin psi` (bearing pitch; the
/// blade twist is zero where the record quotes the collective).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Controls {
    pub th0_deg: f64,
    pub th1c_deg: f64,
    pub th1s_deg: f64,
}

impl Controls {
    /// From a flight record's `controls_deg`: collective, lateral cyclic = th1c (cos psi),
    /// longitudinal cyclic = th1s (sin psi) (docs/rotor_model.md, conventions).
    pub fn from_record(c: &crate::flight::record::ControlsDeg) -> Self {
        Controls {
            th0_deg: c.collective,
            th1c_deg: c.lateral_cyclic,
            th1s_deg: c.longitudinal_cyclic,
        }
    }

    /// The controls a blade `dpsi_deg` ahead in azimuth sees at the same time: the shared
    /// swashplate's cyclic turned, `theta(psi + dpsi)` written in `psi`.
    pub fn ahead_by(&self, dpsi_deg: f64) -> Self {
        let (s, c) = dpsi_deg.to_radians().sin_cos();
        Controls {
            th0_deg: self.th0_deg,
            th1c_deg: self.th1c_deg * c + self.th1s_deg * s,
            th1s_deg: self.th1s_deg * c - self.th1c_deg * s,
        }
    }
}

/// Node and element names of the expanded model.
pub mod names {
    pub const HUB: &str = "hub";
    pub const SHAFT: &str = "shaft";
    pub const LAG: &str = "lag";
    pub const FLAP: &str = "flap";
    pub const PITCH: &str = "pitch";
    pub const SWASH_DRIVE: &str = "swashplate_drive";
    pub const DAMPER_HUB_END: &str = "damper_hub_end";
    pub const DAMPER_BLADE_END: &str = "damper_blade_end";
    pub const BLADE: &str = "blade";
    /// Prefix of the airframe's chain nodes and joints (`airframe.x`, ...).
    pub const AIRFRAME: &str = "airframe";
}

/// Smooth ramp 0 -> 1 over `t_ramp` (0.5 (1 - cos(pi t / t_ramp))): zero rate at both ends so
/// that the initial velocities stay consistent with the constraints.
pub fn ramp(t: f64, t_ramp: f64) -> f64 {
    if t_ramp <= 0.0 || t >= t_ramp {
        1.0
    } else if t <= 0.0 {
        0.0
    } else {
        0.5 * (1.0 - (std::f64::consts::PI * t / t_ramp).cos())
    }
}

/// Geometry helpers derived from the deck.
impl RotorSpec {
    /// Bearing pitch [rad] at time t (cyclic ramped in over `cyclic_ramp_revs`).
    pub fn pitch_rad(&self, c: &Controls, t: f64) -> f64 {
        let om = self.rotor.omega_rad_s;
        let tr = self.pitch_control.cyclic_ramp_revs * 2.0 * std::f64::consts::PI / om;
        let psi = om * t;
        (c.th0_deg + ramp(t, tr) * (c.th1c_deg * psi.cos() + c.th1s_deg * psi.sin())).to_radians()
    }

    /// Vertical swashplate displacement [m] (hub frame) that holds the horn tip at the position
    /// it has when the bearing is pitched by `theta` about the pitch axis (x through the hinge).
    pub fn swash_z(&self, theta: f64) -> f64 {
        let h = self.pitch_control.horn_tip_m;
        h[1] * theta.sin() + h[2] * theta.cos() - h[2]
    }

    fn hub_end(&self) -> [f64; 3] {
        let d = &self.damper_attachment;
        [
            self.retention.hinge_r_m - d.reference_length_m,
            d.arm_m,
            d.height_m,
        ]
    }
    fn blade_end(&self) -> [f64; 3] {
        let d = &self.damper_attachment;
        [self.retention.hinge_r_m, d.arm_m, d.height_m]
    }
    fn swash_point(&self) -> [f64; 3] {
        let h = self.pitch_control.horn_tip_m;
        [h[0], h[1], h[2] - self.pitch_control.link_length_m]
    }
}

/// A section as the model deck takes it: the text the deck was printed as never carried the
/// station `s_m`, so it is zero here too.
fn section(p: &SectionProps) -> SectionProps {
    SectionProps { s_m: 0.0, ..*p }
}

/// Inertia of a small sphere of radius `r`: 2/5 m r^2 about each axis.
fn point_inertia(m: f64, r: f64) -> [[f64; 3]; 3] {
    let i = 0.4 * m * r * r;
    [[i, 0.0, 0.0], [0.0, i, 0.0], [0.0, 0.0, i]]
}

/// Options of the expansion.
#[derive(Clone, Debug, Default)]
pub struct ExpandOptions {
    pub controls: Controls,
    /// Revolutions covered by the swashplate displacement table of the printed deck (the
    /// forced response replaces it with the exact law at every step).
    pub table_revs: usize,
    /// Extra lag-hinge spring and damper (linearised damper for modal analyses).
    pub lag_extra_k: f64,
    pub lag_extra_c: f64,
    /// Bearing elastomers as their spring and dashpot equivalents
    /// ([`crate::rotor::deck::BearingTable::equivalent`]; linear analyses of the expanded model, whose modal
    /// analysis would otherwise see only the relaxed spring).
    pub bearing_equivalent: bool,
    /// `[modes] speeds_rad_s`.
    pub speeds_rad_s: Vec<f64>,
    /// The damper as a `[[hydraulic]]` table (None: left out, e.g. when the caller adds the
    /// coupling element itself or represents the damper by a linearised lag-hinge spring).
    pub hydraulic: Option<HydraulicRef>,
}

/// `[[hydraulic]]` damper table of the expanded deck.
#[derive(Clone, Debug)]
pub struct HydraulicRef {
    /// Device deck path relative to the rotor deck's folder (the rotor deck itself holds the
    /// `[damper]` table).
    pub deck: String,
    pub model: String,
    pub scheme: String,
    pub substeps: usize,
}

/// Last node index of a beam of `n` cubic elements.
pub fn last(n: usize) -> usize {
    3 * n
}

/// Where a blade's copy sits in an expanded model: the prefix of its names (empty for the
/// single blade) and its azimuth ahead of blade 1 about the shaft (z).
struct Place {
    prefix: String,
    azimuth_deg: f64,
    rot: [[f64; 3]; 3],
}

impl Place {
    fn reference() -> Self {
        Self::blade("", 0.0)
    }
    fn blade(prefix: &str, azimuth_deg: f64) -> Self {
        let (sn, cs) = azimuth_deg.to_radians().sin_cos();
        Place {
            prefix: prefix.to_string(),
            azimuth_deg,
            rot: [[cs, -sn, 0.0], [sn, cs, 0.0], [0.0, 0.0, 1.0]],
        }
    }
    fn turned(&self) -> bool {
        self.azimuth_deg != 0.0
    }
    /// A point or direction of the reference blade turned to this blade.
    fn p(&self, v: [f64; 3]) -> [f64; 3] {
        if !self.turned() {
            return v;
        }
        let r = &self.rot;
        std::array::from_fn(|i| r[i][0] * v[0] + r[i][1] * v[1] + r[i][2] * v[2])
    }
    /// A name of this blade's copy (the hub is shared).
    fn n(&self, name: &str) -> String {
        if name == names::HUB {
            name.to_string()
        } else {
            format!("{}{name}", self.prefix)
        }
    }
}

/// The pitch link's keys as printed (its e2 direction after its ends).
const PITCH_LINK_KEYS: &[&str] = &["name", "elements", "start_m", "end_m", "e2_direction"];

/// One blade's copy of the model (everything but the hub node, the shaft and the analysis
/// tables), added section by section, so that several copies interleave by section.
struct BladeParts<'a> {
    spec: &'a RotorSpec,
    opts: &'a ExpandOptions,
    place: Place,
    controls: Controls,
}

/// Where the parts a run drives and reads sit in an expanded deck: indices of its items.
#[derive(Clone, Debug, Default)]
pub struct ExpandedItems {
    /// The hub's `[[node]]`.
    pub hub: usize,
    /// The airframe chain's `[[node]]`s, in the order of [`airframe_chain`].
    pub airframe: Vec<usize>,
    pub blades: Vec<BladeItems>,
}

/// One blade's parts in an expanded deck.
#[derive(Clone, Debug, Default)]
pub struct BladeItems {
    /// The swashplate drive's `[[joint]]`.
    pub swash: usize,
    /// The damper's end `[[node]]`s (hub end, blade end).
    pub damper_ends: [usize; 2],
    /// The blade's `[[beam]]`.
    pub blade: usize,
}

/// Index of the item an entry prints.
fn index(e: &crate::structure::deck_text::Entry) -> usize {
    e.item.map_or(0, |(_, i)| i)
}

impl BladeParts<'_> {
    /// Adds the blade's nodes; returns its damper ends.
    fn nodes(&self, d: &mut DeckBuilder) -> [usize; 2] {
        let (spec, pl) = (self.spec, &self.place);
        let e = spec.retention.hinge_r_m;
        let mut node = |name: &str, p: [f64; 3]| index(d.node(NodeDeck::at(&pl.n(name), pl.p(p))));
        node("bearing_lag", [e, 0.0, 0.0]);
        node("bearing_flap", [e, 0.0, 0.0]);
        node("swashplate", spec.swash_point());
        [
            node(names::DAMPER_HUB_END, spec.hub_end()),
            node(names::DAMPER_BLADE_END, spec.blade_end()),
        ]
    }

    /// A straight beam of this blade from `a` to `z` (points of the reference blade); the
    /// beams' default e2 is the global y: a turned blade names its own.
    fn beam(&self, name: &str, elements: usize, a: [f64; 3], z: [f64; 3]) -> BeamDeck {
        let pl = &self.place;
        BeamDeck {
            e2_direction: pl.turned().then(|| pl.p([0.0, 1.0, 0.0])),
            start_m: Some(pl.p(a)),
            end_m: Some(pl.p(z)),
            ..BeamDeck::new(&pl.n(name), elements)
        }
    }

    /// Adds the blade's beams; returns the blade's.
    fn beams(&self, d: &mut DeckBuilder) -> usize {
        let (spec, pl) = (self.spec, &self.place);
        let r = &spec.retention;
        let e = r.hinge_r_m;
        let b = &spec.blade;
        let pc = &spec.pitch_control;
        let n2 = last(r.segment2.elements);
        let seg =
            |name: &str, g: &Segment, a: [f64; 3], z: [f64; 3], start: Option<&str>| BeamDeck {
                start_node: start.map(|n| pl.n(n)),
                section: Some(section(&g.section)),
                damping_mu_s: Some(g.damping_mu_s),
                ..self.beam(name, g.elements, a, z)
            };
        // A beam's first node carries its section frame: the single blade's, along x, is the
        // hub's; a copy of the whole rotor starts its own and is clamped to the hub (joints).
        let whole = !pl.prefix.is_empty();
        let hub = (!whole).then_some(names::HUB);
        d.beam(seg("seg1", &r.segment1, [0.0; 3], [e, 0.0, 0.0], hub));
        let horn = [r.horn_r_m, 0.0, 0.0];
        d.beam(seg("seg2", &r.segment2, [e, 0.0, 0.0], horn, None));
        let seg2_end = format!("seg2.n{n2}");
        let root = [b.root_r_m, 0.0, 0.0];
        d.beam(seg("seg3", &r.segment3, horn, root, Some(&seg2_end)));
        let tip = [spec.rotor.radius_m, 0.0, 0.0];
        let twist = (!b.twist_deg.is_empty()).then(|| {
            b.twist_deg
                .iter()
                .map(|p| [p[0] - b.root_r_m, p[1]])
                .collect()
        });
        let blade = index(d.beam(BeamDeck {
            sections_csv: Some(b.sections_csv.clone()),
            damping_mu_s: Some(b.damping_mu_s),
            twist_deg: twist,
            ..self.beam(names::BLADE, b.elements, root, tip)
        }));
        let link = BeamDeck {
            e2_direction: Some(pl.p([0.0, 1.0, 0.0])),
            section: Some(section(&pc.link_section)),
            ..self.beam(
                "pitch_link",
                pc.link_elements,
                spec.swash_point(),
                pc.horn_tip_m,
            )
        };
        d.beam(link).keys = Some(PITCH_LINK_KEYS);
        blade
    }

    fn bodies(&self, d: &mut DeckBuilder) {
        let (spec, pl) = (self.spec, &self.place);
        let r = &spec.retention;
        let pc = &spec.pitch_control;
        let seg2_end = pl.n(&format!("seg2.n{}", last(r.segment2.elements)));
        // offsets and inertias are in the node's frame, which turns with the blade
        let horn_node = [r.horn_r_m, 0.0, 0.0];
        let h = pc.horn_tip_m;
        d.rigid_body(RigidDeck {
            name: pl.n("pitch_horn"),
            node: seg2_end,
            mass_kg: pc.horn_mass_kg,
            cm_offset_m: Some([0.5 * (h[0] - horn_node[0]), 0.5 * h[1], 0.5 * h[2]]),
            inertia_kgm2: point_inertia(pc.horn_mass_kg, 0.05),
        });
        let da = &spec.damper_attachment;
        for (name, node, m) in [
            ("damper_arm", names::DAMPER_BLADE_END, da.arm_mass_kg),
            ("damper_horn", names::DAMPER_HUB_END, da.horn_mass_kg),
        ] {
            d.rigid_body(RigidDeck {
                name: pl.n(name),
                node: pl.n(node),
                mass_kg: m,
                cm_offset_m: None,
                inertia_kgm2: point_inertia(m, 0.05),
            });
        }
    }

    /// Per bearing axis: stiffness, damping, elastomer.
    fn bearing_axis(&self, a: BearingAxis) -> (f64, f64, Option<AxisElastomer>) {
        let bg = &self.spec.bearing;
        let om = self.spec.rotor.omega_rad_s;
        if self.opts.bearing_equivalent {
            let (k, c) = bg.equivalent(a, om);
            (k, c, None)
        } else {
            let (k, c) = match a {
                BearingAxis::Lag => (bg.lag_k, bg.lag_c),
                BearingAxis::Flap => (bg.flap_k, bg.flap_c),
                BearingAxis::Pitch => (bg.pitch_k, bg.pitch_c),
            };
            (k, c, bg.elastomer(a, om))
        }
    }

    /// The bearing's revolute joints `lag`, `flap`, `pitch`.
    fn bearing(&self, d: &mut DeckBuilder) {
        let (opts, pl) = (self.opts, &self.place);
        let n1 = last(self.spec.retention.segment1.elements);
        let lag = self.bearing_axis(BearingAxis::Lag);
        let lag = (lag.0 + opts.lag_extra_k, lag.1 + opts.lag_extra_c, lag.2);
        let seg1_end = format!("seg1.n{n1}");
        let (x, y) = ([1.0, 0.0, 0.0], [0.0, 1.0, 0.0]);
        for (name, a, b, axis, xd, (k, c, el)) in [
            (
                names::LAG,
                seg1_end.as_str(),
                "bearing_lag",
                [0.0, 0.0, -1.0],
                x,
                lag,
            ),
            (
                names::FLAP,
                "bearing_lag",
                "bearing_flap",
                [0.0, -1.0, 0.0],
                x,
                self.bearing_axis(BearingAxis::Flap),
            ),
            (
                names::PITCH,
                "bearing_flap",
                "seg2.n0",
                x,
                y,
                self.bearing_axis(BearingAxis::Pitch),
            ),
        ] {
            d.joint(JointDeck {
                axis: Some(pl.p(axis)),
                x_direction: Some(pl.p(xd)),
                stiffness: Some(k),
                damping: Some(c),
                elastomer: el.map(|e| ElastomerDeck {
                    loss_factor: e.loss_factor,
                    band_rad_s: e.band_rad_s,
                    reference_rad_s: e.reference_rad_s,
                }),
                ..JointDeck::new(&pl.n(name), "revolute", Some(&pl.n(a)), &pl.n(b))
            });
        }
    }

    /// The swashplate's vertical displacement in the hub frame, tabulated over `table_revs`.
    fn swash_table(&self) -> Vec<[f64; 2]> {
        let (spec, opts, c) = (self.spec, self.opts, &self.controls);
        if c.th1c_deg == 0.0 && c.th1s_deg == 0.0 {
            return vec![[0.0, spec.swash_z(c.th0_deg.to_radians())]];
        }
        let period = 2.0 * std::f64::consts::PI / spec.rotor.omega_rad_s;
        let npts = 64 * opts.table_revs.max(1);
        (0..=npts)
            .map(|k| {
                let t = period * opts.table_revs.max(1) as f64 * k as f64 / npts as f64;
                [t, spec.swash_z(spec.pitch_rad(c, t))]
            })
            .collect()
    }

    /// Adds the blade's joints; returns its swashplate drive.
    fn joints(&self, d: &mut DeckBuilder) -> usize {
        let (spec, pl) = (self.spec, &self.place);
        let r = &spec.retention;
        let pc = &spec.pitch_control;
        self.bearing(d);
        let mut clamp = |name: &str, a: &str, b: &str| {
            d.joint(JointDeck::new(
                &pl.n(name),
                "clamp",
                Some(&pl.n(a)),
                &pl.n(b),
            ));
        };
        if !pl.prefix.is_empty() {
            clamp("hub_mount", names::HUB, "seg1.n0");
        }
        let n3 = last(r.segment3.elements);
        let blade_start = format!("{}.n0", names::BLADE);
        clamp("blade_root", &format!("seg3.n{n3}"), &blade_start);
        clamp("damper_hub_mount", names::HUB, names::DAMPER_HUB_END);
        clamp("damper_arm_mount", "bearing_lag", names::DAMPER_BLADE_END);
        let swash = pl.n("swashplate");
        let e = d.joint(JointDeck {
            displacement_m: Some([0.0, 0.0, 1.0]),
            displacement_table: Some(self.swash_table()),
            ..JointDeck::new(
                &pl.n(names::SWASH_DRIVE),
                "prescribed",
                Some(names::HUB),
                &swash,
            )
        });
        e.comment = vec![
            "Swashplate: z(t) = horn_y sin(theta) + horn_z (cos(theta) - 1), theta = th0 + ramp (th1c cos psi + th1s sin psi)".into(),
        ];
        let drive = index(e);
        let link = pl.n("pitch_link.n0");
        d.joint(JointDeck {
            axis: Some([0.0, 0.0, 1.0]),
            ..JointDeck::new(&pl.n("pitch_link_lower"), "universal", Some(&swash), &link)
        });
        let seg2_end = pl.n(&format!("seg2.n{}", last(r.segment2.elements)));
        let link_end = pl.n(&format!("pitch_link.n{}", last(pc.link_elements)));
        d.joint(JointDeck {
            position_m: Some(pl.p(pc.horn_tip_m)),
            ..JointDeck::new(
                &pl.n("pitch_link_upper"),
                "spherical",
                Some(&seg2_end),
                &link_end,
            )
        });
        drive
    }

    fn hydraulic(&self, d: &mut DeckBuilder) {
        let pl = &self.place;
        let (a, b) = (pl.n(names::DAMPER_HUB_END), pl.n(names::DAMPER_BLADE_END));
        let Some(h) = &self.opts.hydraulic else {
            d.note(vec![format!(
                "Damper: not included here (added by the caller between `{a}` and `{b}`)"
            )]);
            return;
        };
        let e = d.hydraulic(HydraulicDeck {
            name: pl.n("damper"),
            node_a: a,
            position_m: None,
            node_b: b,
            deck: h.deck.clone(),
            model: Some(h.model.clone()),
            scheme: Some(h.scheme.clone()),
            substeps: Some(h.substeps),
            orifice_area_table: None,
            reference_length_m: Some(self.spec.damper_attachment.reference_length_m),
            applied_force: None,
        });
        e.comment = vec![
            "Damper (paper Eqs. 9-16): stroke = arm x lag angle, positive when lag aft lengthens it"
                .into(),
        ];
        // the printed deck has always indented this table: kept so that its text is unchanged
        e.indent = 17;
    }

    fn sensors(&self, d: &mut DeckBuilder) {
        let pl = &self.place;
        let nb = last(self.spec.blade.elements);
        let tip = pl.n(&format!("{}.n{nb}", names::BLADE));
        d.sensor(SensorDeck::at_node(&pl.n("tip"), &tip));
        for (name, joint) in [
            ("lag", names::LAG),
            ("flap", names::FLAP),
            ("pitch", names::PITCH),
        ] {
            d.sensor(SensorDeck::at_joint(&pl.n(name), &pl.n(joint)));
        }
    }
}

/// The model deck of the single blade. Relative paths (section CSV) resolve against the rotor
/// deck's folder.
pub fn expand_deck(spec: &RotorSpec, opts: &ExpandOptions) -> Deck {
    expand_items(spec, opts).0
}

/// [`expand_deck`], with where the run's parts sit in it.
pub fn expand_items(spec: &RotorSpec, opts: &ExpandOptions) -> (Deck, ExpandedItems) {
    let c = &opts.controls;
    let header = vec![
        "Multibody model deck generated by `rotorsim expand` from a rotor deck (docs/rotor_deck.md).".into(),
        "Paths are relative to the rotor deck's folder: save this deck next to it.".into(),
        format!(
            "Controls: th0 = {} deg, th1c = {} deg, th1s = {} deg (cyclic ramped in over {} revolutions).",
            c.th0_deg, c.th1c_deg, c.th1s_deg, spec.pitch_control.cyclic_ramp_revs
        ),
    ];
    let mut d = DeckBuilder::new(
        header,
        "rotor: single blade, root retention, elastomeric bearing, pitch link, damper",
    );
    let b = BladeParts {
        spec,
        opts,
        place: Place::reference(),
        controls: *c,
    };
    let items = add_model(&mut d, spec, opts, &[b]);
    (d.finish(), items)
}

/// The model deck text of the single blade ([`expand_deck`] as TOML).
pub fn expand(spec: &RotorSpec, opts: &ExpandOptions) -> String {
    to_toml(&expand_deck(spec, opts))
}

/// The whole rotor's model deck: blade k (1 to N, its own deck `specs[k-1]`) named `b<k>.`
/// and turned (k-1) 360/N deg ahead of blade 1 about the shaft, seeing the cyclic at its own
/// azimuth; all on one hub driven by the shaft. Relative paths resolve against the rotor deck's
/// folder. No blades: an empty deck.
pub fn expand_rotor_deck(specs: &[RotorSpec], opts: &ExpandOptions) -> Deck {
    expand_rotor_items(specs, opts).0
}

/// [`expand_rotor_deck`], with where the run's parts sit in it.
pub fn expand_rotor_items(specs: &[RotorSpec], opts: &ExpandOptions) -> (Deck, ExpandedItems) {
    let n = specs.len();
    let c = &opts.controls;
    let Some(first) = specs.first() else {
        return Default::default();
    };
    let header = vec![
        "Multibody model deck of the whole rotor generated by `rotorsim expand --all-blades` from a rotor deck (docs/rotor_deck.md).".into(),
        "Paths are relative to the rotor deck's folder: save this deck next to it.".into(),
        format!(
            "Controls: th0 = {} deg, th1c = {} deg, th1s = {} deg at blade 1 (cyclic ramped in over {} revolutions).",
            c.th0_deg, c.th1c_deg, c.th1s_deg, first.pitch_control.cyclic_ramp_revs
        ),
    ];
    let mut d = DeckBuilder::new(
        header,
        &format!("rotor: {n} blades on a driven hub, each with root retention, elastomeric bearing, pitch link, damper"),
    );
    let blades: Vec<BladeParts> = specs
        .iter()
        .enumerate()
        .map(|(i, spec)| {
            let az = i as f64 * 360.0 / n as f64;
            BladeParts {
                spec,
                opts,
                place: Place::blade(&format!("b{}.", i + 1), az),
                controls: c.ahead_by(az),
            }
        })
        .collect();
    let items = add_model(&mut d, first, opts, &blades);
    (d.finish(), items)
}

/// The whole rotor's model deck text ([`expand_rotor_deck`] as TOML; empty without blades).
pub fn expand_rotor(specs: &[RotorSpec], opts: &ExpandOptions) -> String {
    if specs.is_empty() {
        return String::new();
    }
    to_toml(&expand_rotor_deck(specs, opts))
}

/// The airframe's directions in the order of its chain from the ground: the translations by
/// decreasing mass, then the rotations.
pub fn airframe_chain(airframe: &super::deck::AirframeTable) -> Vec<super::deck::AirframeDof> {
    let mut dofs = airframe.dofs();
    let split = dofs.iter().position(|d| d.rotation).unwrap_or(dofs.len());
    dofs[..split].sort_by(|a, b| b.mass.total_cmp(&a.mass));
    dofs
}

/// The translational mass each chain node carries [kg] (in the order of [`airframe_chain`]):
/// the difference of its direction's mass to the next translation's, the last translation
/// all of its own, the rotations none.
pub fn airframe_node_masses(dofs: &[super::deck::AirframeDof]) -> Vec<f64> {
    let split = dofs.iter().position(|d| d.rotation).unwrap_or(dofs.len());
    (0..dofs.len())
        .map(|i| {
            if i >= split {
                0.0
            } else {
                dofs[i].mass - dofs[i + 1..split].first().map_or(0.0, |n| n.mass)
            }
        })
        .collect()
}

/// The airframe as a chain from the ground to the node under the shaft, one link per moving
/// direction (bushing locking all but that direction, with its spring and damper), so that
/// each direction has its own mass. A node moves with every link before it, so its mass
/// counts in all their directions: the translations are ordered by decreasing mass and each
/// node carries the difference to the next (the last the smallest); the rotations' nodes
/// carry inertia about their own axis only and no mass. Returns the last node's name.
pub fn add_airframe(d: &mut DeckBuilder, airframe: &super::deck::AirframeTable) -> Option<String> {
    add_airframe_chain(d, airframe).0
}

/// [`add_airframe`], with the chain's `[[node]]` indices.
fn add_airframe_chain(
    d: &mut DeckBuilder,
    airframe: &super::deck::AirframeTable,
) -> (Option<String>, Vec<usize>) {
    let dofs = airframe_chain(airframe);
    let masses = airframe_node_masses(&dofs);
    let mut prev: Option<String> = None;
    let mut chain = vec![];
    const AXES: [&str; 6] = ["x", "y", "z", "rx", "ry", "rz"];
    for (i, f) in dofs.iter().enumerate() {
        let node = format!("{}.{}", names::AIRFRAME, f.name);
        chain.push(index(d.node(NodeDeck::at(&node, [0.0; 3]))));
        let (mass, inertia) = if f.rotation {
            let mut j = [0.0; 3];
            j[f.axis] = f.mass;
            (0.0, j)
        } else {
            (masses[i], [0.0; 3])
        };
        let [i1, i2, i3] = inertia;
        d.rigid_body(RigidDeck {
            name: format!("{node}.body"),
            node: node.clone(),
            mass_kg: mass,
            cm_offset_m: None,
            inertia_kgm2: [[i1, 0.0, 0.0], [0.0, i2, 0.0], [0.0, 0.0, i3]],
        });
        let free = f.axis + if f.rotation { 3 } else { 0 };
        let locked = (0..6)
            .filter(|&k| k != free)
            .map(|k| AXES[k].to_string())
            .collect();
        let mut k = vec![0.0; 3];
        let mut c = vec![0.0; 3];
        k[f.axis] = f.stiffness;
        c[f.axis] = f.damping;
        let mut j = JointDeck {
            position_m: Some([0.0, 0.0, f.center_z_m]),
            locked: Some(locked),
            ..JointDeck::new(&format!("{node}.link"), "bushing", prev.as_deref(), &node)
        };
        if f.rotation {
            (j.stiffness_r, j.damping_r) = (Some(k), Some(c));
        } else {
            (j.stiffness_t, j.damping_t) = (Some(k), Some(c));
        }
        d.joint(j);
        prev = Some(node);
    }
    (prev, chain)
}

/// Hub, blades (section by section), shaft, analysis tables; returns where the run's parts sit.
fn add_model(
    d: &mut DeckBuilder,
    spec: &RotorSpec,
    opts: &ExpandOptions,
    blades: &[BladeParts],
) -> ExpandedItems {
    let om = spec.rotor.omega_rad_s;
    let period = 2.0 * std::f64::consts::PI / om;
    let mut items = ExpandedItems {
        hub: index(d.node(NodeDeck::at(names::HUB, [0.0; 3]))),
        airframe: vec![],
        blades: vec![BladeItems::default(); blades.len()],
    };
    for (b, it) in blades.iter().zip(&mut items.blades) {
        it.damper_ends = b.nodes(d);
    }
    for (b, it) in blades.iter().zip(&mut items.blades) {
        it.blade = b.beams(d);
    }
    for b in blades {
        b.bodies(d);
    }
    // joints: the shaft turns the hub on the airframe (the whole rotor's model, its blades
    // named b<K>.), or on the ground
    let whole = blades.iter().any(|b| !b.place.prefix.is_empty());
    let mount = match &spec.airframe {
        Some(a) if whole => {
            let (mount, chain) = add_airframe_chain(d, a);
            items.airframe = chain;
            mount
        }
        _ => None,
    };
    d.joint(JointDeck {
        axis: Some([0.0, 0.0, 1.0]),
        omega_rad_s: Some(om),
        ..JointDeck::new(names::SHAFT, "revolute", mount.as_deref(), names::HUB)
    });
    for (b, it) in blades.iter().zip(&mut items.blades) {
        it.swash = b.joints(d);
    }
    for b in blades {
        b.hydraulic(d);
    }
    for b in blades {
        b.sensors(d);
    }
    let deck = d.deck_mut();
    deck.statics = StaticDeck {
        load_steps: 4,
        omega_rad_s: Some([0.0, 0.0, om]),
        ..Default::default()
    };
    deck.dynamic = DynamicDeck {
        time_step_s: Some(period / 256.0),
        end_time_s: Some(period),
        initial_omega_rad_s: Some([0.0, 0.0, om]),
        start_from_static: true,
        ..Default::default()
    };
    deck.modes = ModesDeck {
        count: 14 * blades.len(),
        axis: [0.0, 0.0, 1.0],
        speeds_rad_s: opts.speeds_rad_s.clone(),
    };
    items
}
