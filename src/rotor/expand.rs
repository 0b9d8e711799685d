//! Rotor deck -> multibody model deck (docs/model_deck.md), printed by `rotorsim expand` and
//! parsed back by [`crate::rotor::build`] and `rotorsim modes --rotor`, so that the printed deck
//! is exactly the model that runs.
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
use crate::structure::section::SectionProps;
use std::fmt::Write as _;

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

/// A value as TOML writes it back exactly (shortest round-trip form).
pub(crate) fn f(v: f64) -> String {
    format!("{v:?}")
}

pub(crate) fn v3(v: [f64; 3]) -> String {
    format!("[{}, {}, {}]", f(v[0]), f(v[1]), f(v[2]))
}

/// A model-deck section table (inline TOML), offsets only where non-zero.
pub(crate) fn section(p: &SectionProps) -> String {
    let mut s = format!(
        "{{ EA_N = {}, GA2_N = {}, GA3_N = {}, GJ_Nm2 = {}, EI2_Nm2 = {}, EI3_Nm2 = {}, m_kg_per_m = {}, I1_kgm = {}, I2_kgm = {}, I3_kgm = {}",
        f(p.ea), f(p.ga2), f(p.ga3), f(p.gj), f(p.ei2), f(p.ei3), f(p.m), f(p.i1), f(p.i2), f(p.i3)
    );
    for (k, v) in [
        ("cm2_m", p.cm2),
        ("cm3_m", p.cm3),
        ("sc2_m", p.sc2),
        ("sc3_m", p.sc3),
        ("ca2_m", p.ca2),
        ("ca3_m", p.ca3),
    ] {
        if v != 0.0 {
            let _ = write!(s, ", {k} = {}", f(v));
        }
    }
    s.push_str(" }");
    s
}

fn point_inertia(m: f64, r: f64) -> String {
    // small sphere of radius r: 2/5 m r^2
    let i = 0.4 * m * r * r;
    format!(
        "[[{}, 0.0, 0.0], [0.0, {}, 0.0], [0.0, 0.0, {}]]",
        f(i),
        f(i),
        f(i)
    )
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

/// Writes one blade's copy of the model (everything but the hub node, the shaft and the
/// analysis tables), section by section, so that several copies interleave by section.
struct BladeWriter<'a> {
    spec: &'a RotorSpec,
    opts: &'a ExpandOptions,
    place: Place,
    controls: Controls,
}

impl BladeWriter<'_> {
    fn nodes(&self, s: &mut String) {
        let (spec, pl) = (self.spec, &self.place);
        let e = spec.retention.hinge_r_m;
        let node = |s: &mut String, name: &str, p: [f64; 3]| {
            let _ = writeln!(
                s,
                "[[node]]\nname = \"{}\"\nposition_m = {}\n",
                pl.n(name),
                v3(pl.p(p))
            );
        };
        node(s, "bearing_lag", [e, 0.0, 0.0]);
        node(s, "bearing_flap", [e, 0.0, 0.0]);
        node(s, "swashplate", spec.swash_point());
        node(s, names::DAMPER_HUB_END, spec.hub_end());
        node(s, names::DAMPER_BLADE_END, spec.blade_end());
    }

    fn beams(&self, s: &mut String) {
        let (spec, pl) = (self.spec, &self.place);
        let r = &spec.retention;
        let e = r.hinge_r_m;
        let b = &spec.blade;
        let pc = &spec.pitch_control;
        let n2 = last(r.segment2.elements);
        // the beams' default e2 is the global y: a turned blade names its own
        let e2 = |s: &mut String| {
            if pl.turned() {
                let _ = writeln!(s, "e2_direction = {}", v3(pl.p([0.0, 1.0, 0.0])));
            }
        };
        let seg = |s: &mut String,
                   name: &str,
                   g: &Segment,
                   a: [f64; 3],
                   z: [f64; 3],
                   start: Option<&str>| {
            let _ = writeln!(
                s,
                "[[beam]]\nname = \"{}\"\nelements = {}",
                pl.n(name),
                g.elements
            );
            if let Some(n) = start {
                let _ = writeln!(s, "start_node = \"{}\"", pl.n(n));
            }
            e2(s);
            let _ = writeln!(
                s,
                "start_m = {}\nend_m = {}\nsection = {}\ndamping_mu_s = {}\n",
                v3(pl.p(a)),
                v3(pl.p(z)),
                section(&g.section),
                f(g.damping_mu_s)
            );
        };
        // A beam's first node carries its section frame: the single blade's, along x, is the
        // hub's; a copy of the whole rotor starts its own and is clamped to the hub (joints).
        let whole = !pl.prefix.is_empty();
        seg(
            s,
            "seg1",
            &r.segment1,
            [0.0; 3],
            [e, 0.0, 0.0],
            (!whole).then_some(names::HUB),
        );
        seg(
            s,
            "seg2",
            &r.segment2,
            [e, 0.0, 0.0],
            [r.horn_r_m, 0.0, 0.0],
            None,
        );
        let seg2_end = format!("seg2.n{n2}");
        seg(
            s,
            "seg3",
            &r.segment3,
            [r.horn_r_m, 0.0, 0.0],
            [b.root_r_m, 0.0, 0.0],
            Some(&seg2_end),
        );
        let _ = writeln!(
            s,
            "[[beam]]\nname = \"{}\"\nelements = {}",
            pl.n(names::BLADE),
            b.elements
        );
        e2(s);
        let _ = writeln!(
            s,
            "start_m = {}\nend_m = {}\nsections_csv = \"{}\"\ndamping_mu_s = {}",
            v3(pl.p([b.root_r_m, 0.0, 0.0])),
            v3(pl.p([spec.rotor.radius_m, 0.0, 0.0])),
            b.sections_csv,
            f(b.damping_mu_s)
        );
        if !b.twist_deg.is_empty() {
            let pts: Vec<String> = b
                .twist_deg
                .iter()
                .map(|p| format!("[{}, {}]", f(p[0] - b.root_r_m), f(p[1])))
                .collect();
            let _ = writeln!(s, "twist_deg = [{}]", pts.join(", "));
        }
        s.push('\n');
        let sp = spec.swash_point();
        let _ = writeln!(
            s,
            "[[beam]]\nname = \"{}\"\nelements = {}\nstart_m = {}\nend_m = {}\ne2_direction = {}\nsection = {}\n",
            pl.n("pitch_link"),
            pc.link_elements,
            v3(pl.p(sp)),
            v3(pl.p(pc.horn_tip_m)),
            v3(pl.p([0.0, 1.0, 0.0])),
            section(&pc.link_section)
        );
    }

    fn bodies(&self, s: &mut String) {
        let (spec, pl) = (self.spec, &self.place);
        let r = &spec.retention;
        let pc = &spec.pitch_control;
        let seg2_end = pl.n(&format!("seg2.n{}", last(r.segment2.elements)));
        // offsets and inertias are in the node's frame, which turns with the blade
        let horn_node = [r.horn_r_m, 0.0, 0.0];
        let h = pc.horn_tip_m;
        let _ = writeln!(
            s,
            "[[rigid_body]]\nname = \"{}\"\nnode = \"{seg2_end}\"\nmass_kg = {}\ncm_offset_m = {}\ninertia_kgm2 = {}\n",
            pl.n("pitch_horn"),
            f(pc.horn_mass_kg),
            v3([0.5 * (h[0] - horn_node[0]), 0.5 * h[1], 0.5 * h[2]]),
            point_inertia(pc.horn_mass_kg, 0.05)
        );
        let da = &spec.damper_attachment;
        let _ = writeln!(
            s,
            "[[rigid_body]]\nname = \"{}\"\nnode = \"{}\"\nmass_kg = {}\ninertia_kgm2 = {}\n",
            pl.n("damper_arm"),
            pl.n(names::DAMPER_BLADE_END),
            f(da.arm_mass_kg),
            point_inertia(da.arm_mass_kg, 0.05)
        );
        let _ = writeln!(
            s,
            "[[rigid_body]]\nname = \"{}\"\nnode = \"{}\"\nmass_kg = {}\ninertia_kgm2 = {}\n",
            pl.n("damper_horn"),
            pl.n(names::DAMPER_HUB_END),
            f(da.horn_mass_kg),
            point_inertia(da.horn_mass_kg, 0.05)
        );
    }

    fn joints(&self, s: &mut String) {
        let (spec, opts, pl) = (self.spec, self.opts, &self.place);
        let r = &spec.retention;
        let pc = &spec.pitch_control;
        let period = 2.0 * std::f64::consts::PI / spec.rotor.omega_rad_s;
        let n1 = last(r.segment1.elements);
        let n3 = last(r.segment3.elements);
        let npl = last(pc.link_elements);
        let seg2_end = format!("seg2.n{}", last(r.segment2.elements));
        let c = &self.controls;
        let bg = &spec.bearing;
        let rev = |s: &mut String,
                   name: &str,
                   a: &str,
                   bn: &str,
                   axis: [f64; 3],
                   xd: [f64; 3],
                   k: f64,
                   c: f64,
                   el: Option<AxisElastomer>| {
            let _ = writeln!(
                s,
                "[[joint]]\nname = \"{}\"\ntype = \"revolute\"\nnode_a = \"{}\"\nnode_b = \"{}\"\naxis = {}\nx_direction = {}\nstiffness_Nm_per_rad = {}\ndamping_Nms_per_rad = {}",
                pl.n(name),
                pl.n(a),
                pl.n(bn),
                v3(pl.p(axis)),
                v3(pl.p(xd)),
                f(k),
                f(c)
            );
            if let Some(e) = el {
                let _ = writeln!(
                    s,
                    "elastomer = {{ loss_factor = {}, band_rad_s = [{}, {}], reference_rad_s = {} }}",
                    f(e.loss_factor),
                    f(e.band_rad_s[0]),
                    f(e.band_rad_s[1]),
                    f(e.reference_rad_s)
                );
            }
            s.push('\n');
        };
        let om = spec.rotor.omega_rad_s;
        // per axis: stiffness, damping, elastomer
        let axis = |a: BearingAxis| {
            if opts.bearing_equivalent {
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
        };
        let (lag, flap, pitch) = (
            axis(BearingAxis::Lag),
            axis(BearingAxis::Flap),
            axis(BearingAxis::Pitch),
        );
        rev(
            s,
            names::LAG,
            &format!("seg1.n{n1}"),
            "bearing_lag",
            [0.0, 0.0, -1.0],
            [1.0, 0.0, 0.0],
            lag.0 + opts.lag_extra_k,
            lag.1 + opts.lag_extra_c,
            lag.2,
        );
        rev(
            s,
            names::FLAP,
            "bearing_lag",
            "bearing_flap",
            [0.0, -1.0, 0.0],
            [1.0, 0.0, 0.0],
            flap.0,
            flap.1,
            flap.2,
        );
        rev(
            s,
            names::PITCH,
            "bearing_flap",
            "seg2.n0",
            [1.0, 0.0, 0.0],
            [0.0, 1.0, 0.0],
            pitch.0,
            pitch.1,
            pitch.2,
        );
        let clamp = |s: &mut String, name: &str, a: &str, bn: &str| {
            let _ = writeln!(
                s,
                "[[joint]]\nname = \"{}\"\ntype = \"clamp\"\nnode_a = \"{}\"\nnode_b = \"{}\"\n",
                pl.n(name),
                pl.n(a),
                pl.n(bn)
            );
        };
        if !pl.prefix.is_empty() {
            clamp(s, "hub_mount", names::HUB, "seg1.n0");
        }
        clamp(
            s,
            "blade_root",
            &format!("seg3.n{n3}"),
            &format!("{}.n0", names::BLADE),
        );
        clamp(s, "damper_hub_mount", names::HUB, names::DAMPER_HUB_END);
        clamp(
            s,
            "damper_arm_mount",
            "bearing_lag",
            names::DAMPER_BLADE_END,
        );
        // swashplate: vertical displacement in the hub frame, table over `table_revs`
        let npts = 64 * opts.table_revs.max(1);
        let mut table = vec![];
        if c.th1c_deg == 0.0 && c.th1s_deg == 0.0 {
            table.push(format!(
                "[0.0, {}]",
                f(spec.swash_z(c.th0_deg.to_radians()))
            ));
        } else {
            for k in 0..=npts {
                let t = period * opts.table_revs.max(1) as f64 * k as f64 / npts as f64;
                table.push(format!(
                    "[{}, {}]",
                    f(t),
                    f(spec.swash_z(spec.pitch_rad(c, t)))
                ));
            }
        }
        let _ = writeln!(
            s,
            "# Swashplate: z(t) = horn_y sin(theta) + horn_z (cos(theta) - 1), theta = th0 + ramp (th1c cos psi + th1s sin psi)\n\
             [[joint]]\nname = \"{}\"\ntype = \"prescribed\"\nnode_a = \"{}\"\nnode_b = \"{}\"\ndisplacement_m = [0.0, 0.0, 1.0]\ndisplacement_table = [{}]\n",
            pl.n(names::SWASH_DRIVE),
            names::HUB,
            pl.n("swashplate"),
            table.join(", ")
        );
        let _ = writeln!(
            s,
            "[[joint]]\nname = \"{}\"\ntype = \"universal\"\nnode_a = \"{}\"\nnode_b = \"{}\"\naxis = [0.0, 0.0, 1.0]\n",
            pl.n("pitch_link_lower"),
            pl.n("swashplate"),
            pl.n("pitch_link.n0")
        );
        let _ = writeln!(
            s,
            "[[joint]]\nname = \"{}\"\ntype = \"spherical\"\nnode_a = \"{}\"\nnode_b = \"{}\"\nposition_m = {}\n",
            pl.n("pitch_link_upper"),
            pl.n(&seg2_end),
            pl.n(&format!("pitch_link.n{npl}")),
            v3(pl.p(pc.horn_tip_m))
        );
    }

    fn hydraulic(&self, s: &mut String) {
        let pl = &self.place;
        match &self.opts.hydraulic {
            Some(h) => {
                let _ = writeln!(
                    s,
                    "# Damper (paper Eqs. 9-16): stroke = arm x lag angle, positive when lag aft lengthens it
                 [[hydraulic]]
name = \"{}\"
node_a = \"{}\"
node_b = \"{}\"
deck = \"{}\"
model = \"{}\"
scheme = \"{}\"
substeps = {}
reference_length_m = {}
",
                    pl.n("damper"),
                    pl.n(names::DAMPER_HUB_END),
                    pl.n(names::DAMPER_BLADE_END),
                    h.deck,
                    h.model,
                    h.scheme,
                    h.substeps,
                    f(self.spec.damper_attachment.reference_length_m)
                );
            }
            None => {
                let _ = writeln!(
                    s,
                    "# Damper: not included here (added by the caller between `{}` and `{}`)
",
                    pl.n(names::DAMPER_HUB_END),
                    pl.n(names::DAMPER_BLADE_END)
                );
            }
        }
    }

    fn sensors(&self, s: &mut String) {
        let pl = &self.place;
        let nb = last(self.spec.blade.elements);
        let _ = writeln!(
            s,
            "[[sensor]]\nname = \"{}\"\nnode = \"{}\"\n\n[[sensor]]\nname = \"{}\"\njoint = \"{}\"\n\n[[sensor]]\nname = \"{}\"\njoint = \"{}\"\n\n[[sensor]]\nname = \"{}\"\njoint = \"{}\"\n",
            pl.n("tip"),
            pl.n(&format!("{}.n{nb}", names::BLADE)),
            pl.n("lag"),
            pl.n(names::LAG),
            pl.n("flap"),
            pl.n(names::FLAP),
            pl.n("pitch"),
            pl.n(names::PITCH),
        );
    }
}

/// The model deck text. Relative paths (section CSV) resolve against the rotor deck's folder.
pub fn expand(spec: &RotorSpec, opts: &ExpandOptions) -> String {
    let c = &opts.controls;
    let mut s = String::new();
    let _ = writeln!(
        s,
        "# Multibody model deck generated by `rotorsim expand` from a rotor deck (docs/rotor_deck.md).\n\
         # Paths are relative to the rotor deck's folder: save this deck next to it.\n\
         # Controls: th0 = {} deg, th1c = {} deg, th1s = {} deg (cyclic ramped in over {} revolutions).\n\
         title = \"rotor: single blade, root retention, elastomeric bearing, pitch link, damper\"\n",
        c.th0_deg, c.th1c_deg, c.th1s_deg, spec.pitch_control.cyclic_ramp_revs
    );
    let w = BladeWriter {
        spec,
        opts,
        place: Place::reference(),
        controls: *c,
    };
    write_model(&mut s, spec, opts, &[w]);
    s
}

/// The whole rotor's model deck: blade k (1 to N, its own deck `specs[k-1]`) named `b<k>.`
/// and turned (k-1) 360/N deg ahead of blade 1 about the shaft, seeing the cyclic at its own
/// azimuth; all on one hub driven by the shaft. Relative paths resolve against the rotor deck's
/// folder.
pub fn expand_rotor(specs: &[RotorSpec], opts: &ExpandOptions) -> String {
    let n = specs.len();
    let c = &opts.controls;
    let mut s = String::new();
    let Some(first) = specs.first() else {
        return s;
    };
    let _ = writeln!(
        s,
        "# Multibody model deck of the whole rotor generated by `rotorsim expand --all-blades` from a rotor deck (docs/rotor_deck.md).\n\
         # Paths are relative to the rotor deck's folder: save this deck next to it.\n\
         # Controls: th0 = {} deg, th1c = {} deg, th1s = {} deg at blade 1 (cyclic ramped in over {} revolutions).\n\
         title = \"rotor: {n} blades on a driven hub, each with root retention, elastomeric bearing, pitch link, damper\"\n",
        c.th0_deg, c.th1c_deg, c.th1s_deg, first.pitch_control.cyclic_ramp_revs
    );
    let writers: Vec<BladeWriter> = specs
        .iter()
        .enumerate()
        .map(|(i, spec)| {
            let az = i as f64 * 360.0 / n as f64;
            BladeWriter {
                spec,
                opts,
                place: Place::blade(&format!("b{}.", i + 1), az),
                controls: c.ahead_by(az),
            }
        })
        .collect();
    write_model(&mut s, first, opts, &writers);
    s
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
pub fn write_airframe(s: &mut String, airframe: &super::deck::AirframeTable) -> Option<String> {
    let dofs = airframe_chain(airframe);
    let masses = airframe_node_masses(&dofs);
    let mut prev: Option<String> = None;
    const AXES: [&str; 6] = ["x", "y", "z", "rx", "ry", "rz"];
    for (i, d) in dofs.iter().enumerate() {
        let node = format!("{}.{}", names::AIRFRAME, d.name);
        let _ = writeln!(
            s,
            "[[node]]\nname = \"{node}\"\nposition_m = {}\n",
            v3([0.0; 3])
        );
        let (mass, inertia) = if d.rotation {
            let mut j = [0.0; 3];
            j[d.axis] = d.mass;
            (0.0, j)
        } else {
            (masses[i], [0.0; 3])
        };
        let _ = writeln!(
            s,
            "[[rigid_body]]\nname = \"{node}.body\"\nnode = \"{node}\"\nmass_kg = {}\ninertia_kgm2 = [[{}, 0.0, 0.0], [0.0, {}, 0.0], [0.0, 0.0, {}]]\n",
            f(mass),
            f(inertia[0]),
            f(inertia[1]),
            f(inertia[2])
        );
        let free = d.axis + if d.rotation { 3 } else { 0 };
        let locked: Vec<String> = (0..6)
            .filter(|&k| k != free)
            .map(|k| format!("\"{}\"", AXES[k]))
            .collect();
        let mut k = [0.0; 3];
        let mut c = [0.0; 3];
        k[d.axis] = d.stiffness;
        c[d.axis] = d.damping;
        let (kk, ck) = if d.rotation {
            ("rot_stiffness_Nm_per_rad", "rot_damping_Nms_per_rad")
        } else {
            ("stiffness_N_per_m", "damping_Ns_per_m")
        };
        let _ = write!(s, "[[joint]]\nname = \"{node}.link\"\ntype = \"bushing\"\n");
        if let Some(p) = &prev {
            let _ = writeln!(s, "node_a = \"{p}\"");
        }
        let _ = writeln!(
            s,
            "node_b = \"{node}\"\nposition_m = {}\nlocked = [{}]\n{kk} = {}\n{ck} = {}\n",
            v3([0.0, 0.0, d.center_z_m]),
            locked.join(", "),
            v3(k),
            v3(c)
        );
        prev = Some(node);
    }
    prev
}

/// Hub, blades (section by section), shaft, analysis tables.
fn write_model(s: &mut String, spec: &RotorSpec, opts: &ExpandOptions, blades: &[BladeWriter]) {
    let om = spec.rotor.omega_rad_s;
    let period = 2.0 * std::f64::consts::PI / om;
    let _ = writeln!(
        s,
        "[[node]]\nname = \"{}\"\nposition_m = {}\n",
        names::HUB,
        v3([0.0; 3])
    );
    for b in blades {
        b.nodes(s);
    }
    for b in blades {
        b.beams(s);
    }
    // rigid bodies
    for b in blades {
        b.bodies(s);
    }
    // joints: the shaft turns the hub on the airframe (the whole rotor's model, its blades
    // named b<K>.), or on the ground
    let whole = blades.iter().any(|b| !b.place.prefix.is_empty());
    let mount = match &spec.airframe {
        Some(a) if whole => write_airframe(s, a),
        _ => None,
    };
    let _ = write!(
        s,
        "[[joint]]\nname = \"{}\"\ntype = \"revolute\"\n",
        names::SHAFT
    );
    if let Some(m) = &mount {
        let _ = writeln!(s, "node_a = \"{m}\"");
    }
    let _ = writeln!(
        s,
        "node_b = \"{}\"\naxis = [0.0, 0.0, 1.0]\nomega_rad_s = {}\n",
        names::HUB,
        f(om)
    );
    for b in blades {
        b.joints(s);
    }
    for b in blades {
        b.hydraulic(s);
    }
    for b in blades {
        b.sensors(s);
    }
    let _ = writeln!(
        s,
        "[static]\nload_steps = 4\nomega_rad_s = [0.0, 0.0, {}]\n\n[dynamic]\ntime_step_s = {}\nend_time_s = {}\ninitial_omega_rad_s = [0.0, 0.0, {}]\nstart_from_static = true\n",
        f(om),
        f(period / 256.0),
        f(period),
        f(om)
    );
    let sp: Vec<String> = opts.speeds_rad_s.iter().map(|v| f(*v)).collect();
    let _ = writeln!(
        s,
        "[modes]\ncount = {}\naxis = [0.0, 0.0, 1.0]\nspeeds_rad_s = [{}]",
        14 * blades.len(),
        sp.join(", ")
    );
}
