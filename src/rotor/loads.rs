//! Blade load channels of the rotor model (docs/loads.md): section loads at the `[outputs]`
//! stations (deformed section frame, and the unpitched blade frame), the pitch-link load, the
//! blade root loads at the hub centre (rotating hub frame), the bearing's joint angles and the
//! moments its joints carry about their axes, and, for the run-time equilibrium check, the
//! same root loads from the applied and inertial loads of the blade system and the pitch-link
//! reaction.
use super::deck::{RotorSpec, SECTION_KINDS};
use super::expand::names;
use crate::loads::{self, Resultant};
use crate::solver::State;
use crate::structure::beam::{Interp, PointDensity, NPTS_M};
use crate::structure::kin::{EvalCtx, NodeKin};
use crate::structure::model::{Element, Model};
use crate::structure::rotation::*;
use std::sync::Mutex;

/// Prefix of the channels that only feed the equilibrium check (not written as outputs).
pub const CHECK_PREFIX: &str = "check_";

/// Root channel names, force then moment (x, y, z of the rotating hub frame).
pub const ROOT_CHANNELS: [&str; 6] = [
    "root_fx_N",
    "root_fy_N",
    "root_fz_N",
    "root_mx_Nm",
    "root_my_Nm",
    "root_mz_Nm",
];

pub const PITCH_LINK_CHANNEL: &str = "pitch_link_force_N";

/// The elastomeric bearing's angles (its three revolute joints: lag about -z, flap about -y,
/// pitch about +x of the hub frame, in that order from the hub), positive lag back, flap up,
/// pitch nose up: the rigid blade motion a flight record's motion channels measure.
pub const HINGE_CHANNELS: [&str; 3] = ["lag_hinge_rad", "flap_hinge_rad", "pitch_bearing_rad"];

/// The moment each of the bearing's joints carries about its own axis (its spring and damper,
/// `k psi + c psi'`), in the order and with the signs of [`HINGE_CHANNELS`]: what the blade's
/// side exerts on the hub's side, positive when it resists a positive angle (docs/loads.md).
pub const HINGE_MOMENT_CHANNELS: [&str; 3] = [
    "lag_hinge_moment_Nm",
    "flap_hinge_moment_Nm",
    "pitch_bearing_moment_Nm",
];

/// The pitch-link load's contributors (docs/loads.md, "Pitch-link contributors"): the moment
/// balance about the pitch axis of what is outboard of the pitch joint (retention segments 2
/// and 3, blade, pitch horn), each moment as the link tension that balances it. The bearing
/// (its spring, dashpot and elastomer together), the applied loads (airloads), the inertial
/// loads (centrifugal and propeller moments included), gravity, and the pitch link's own
/// part between its mid-length (where [`PITCH_LINK_CHANNEL`] is taken) and the horn: its
/// shear's moment at the horn and its upper half's axial inertia and weight. They sum to the
/// link load when the balance holds (the residual is checked, docs/loads.md).
pub const PITCH_LINK_CONTRIBUTOR_CHANNELS: [&str; 5] = [
    "pitch_link_from_bearing_N",
    "pitch_link_from_airloads_N",
    "pitch_link_from_inertia_N",
    "pitch_link_from_gravity_N",
    "pitch_link_from_link_N",
];

/// The link tension's arm about the pitch axis, signed: the tension's moment about the axis
/// (nose up positive) per newton [m].
pub const PITCH_LINK_ARM_CHANNEL: &str = "pitch_link_arm_m";

/// Infix of the section channels in the unpitched blade frame
/// (`flap_moment_unpitched_r0.05_Nm`, docs/loads.md).
pub const UNPITCHED: &str = "unpitched";

/// The section kinds that differ between the deformed section frame and the unpitched blade
/// frame (both share e1: torsion and axial force are the same in both).
pub const UNPITCHED_KINDS: [&str; 4] = ["flap_moment", "chord_moment", "shear_flap", "shear_chord"];

/// Name of section channel `kind` (with `unit`) at r/R `x`, in the deformed section frame
/// (`unpitched` false: `flap_moment_r0.50_Nm`) or the unpitched blade frame
/// (`flap_moment_unpitched_r0.50_Nm`).
pub fn section_channel(kind: &str, unit: &str, x: f64, unpitched: bool) -> String {
    if unpitched {
        format!("{kind}_{UNPITCHED}_r{x:.2}_{unit}")
    } else {
        format!("{kind}_r{x:.2}_{unit}")
    }
}

/// The damper's end nodes (hub end, blade end), their positions at the start of the last
/// step and the force it applied over the step (positive along the blade end's line).
#[derive(Clone, Copy, Debug)]
pub struct DamperStep {
    pub nodes: [usize; 2],
    pub x_start: [[f64; 3]; 2],
    pub force_n: f64,
}

struct Station {
    elem: usize,
    s_m: f64,
}

/// One beam element of the blade system at the current state (computed once per sample).
#[derive(Clone, Copy)]
struct ElemData {
    elem: usize,
    k: [NodeKin<f64>; 4],
    ip: Interp,
    d: [PointDensity; NPTS_M],
}

/// Which elements carry which load, resolved once from the expanded model.
pub struct LoadChannels {
    stations: Vec<Station>,
    /// Indices into [`SECTION_KINDS`] written at every station.
    kinds: Vec<usize>,
    /// Of those, the ones also written in the unpitched blade frame ([`UNPITCHED_KINDS`]).
    unpitched_kinds: Vec<usize>,
    names: Vec<String>,
    link: Station,
    hub: usize,
    /// Elements joining the blade system to the hub node: the retention's first beam element
    /// and the damper's hub mount.
    hub_cut: Vec<usize>,
    /// Beam elements of the blade system (retention segments and blade), and its rigid bodies
    /// (horn, damper lever and bracket).
    beams: Vec<usize>,
    rigid: Vec<usize>,
    /// Per station: its element's index in `beams`.
    station_beam: Vec<usize>,
    /// Per-sample element data (preallocated: the channels are read every step).
    scratch: Mutex<Vec<ElemData>>,
    /// The pitch link's joint on the horn, and the horn node.
    link_joint: usize,
    horn_node: usize,
    lam_off: Vec<usize>,
    /// The blade's frame in the hub's: its azimuth ahead of the hub's x axis (whole rotor).
    frame: [[f64; 3]; 3],
    /// The swashplate drive that carries the pitch link to the hub (whole rotor, for the
    /// loads on the hub).
    swash_drive: usize,
    /// The bearing's lag, flap and pitch joints ([`HINGE_CHANNELS`]).
    hinges: [usize; 3],
    /// First element of `beams` outboard of the pitch joint (segment 2's first), and the
    /// pitch link's node at the horn.
    outboard_from: usize,
    link_top: usize,
}

fn beam_ids<'a>(m: &'a Model, name: &str) -> anyhow::Result<&'a [usize]> {
    m.beams
        .get(name)
        .map(|v| v.as_slice())
        .ok_or_else(|| anyhow::anyhow!("expanded rotor model has no beam `{name}`"))
}

/// Loads at the state `st` as the solver evaluates them (inertia included).
fn eval_ctx(m: &Model, st: &State) -> EvalCtx {
    EvalCtx {
        t: st.t,
        load_factor: 1.0,
        gravity: m.gravity,
        cscale: 1.0,
        inertia: true,
        dt: 0.0,
    }
}

fn element(m: &Model, name: &str) -> anyhow::Result<usize> {
    m.element_id(name)
        .ok_or_else(|| anyhow::anyhow!("expanded rotor model has no element `{name}`"))
}

impl LoadChannels {
    pub fn new(spec: &RotorSpec, m: &Model) -> anyhow::Result<Self> {
        Self::for_blade(spec, m, "", 0.0)
    }

    /// The channels of the blade whose model names start with `prefix` (a whole rotor's
    /// `b<K>.`), `ahead_rad` ahead of the hub's x axis: its root loads are in its own
    /// rotating frame (x along the blade).
    pub fn for_blade(
        spec: &RotorSpec,
        m: &Model,
        prefix: &str,
        ahead_rad: f64,
    ) -> anyhow::Result<Self> {
        let n = |s: &str| format!("{prefix}{s}");
        let beam_ids = |m: &'_ Model, b: &str| -> anyhow::Result<Vec<usize>> {
            Ok(beam_ids(m, &n(b))?.to_vec())
        };
        let element = |m: &Model, e: &str| element(m, &n(e));
        let r = &spec.retention;
        let mut stations = vec![];
        for (radius, _) in spec.load_stations() {
            let (beam, s) = if radius >= spec.blade.root_r_m {
                (names::BLADE, radius - spec.blade.root_r_m)
            } else if radius >= r.horn_r_m {
                ("seg3", radius - r.horn_r_m)
            } else if radius >= r.hinge_r_m {
                ("seg2", radius - r.hinge_r_m)
            } else {
                ("seg1", radius)
            };
            let elem = loads::element_at(m, &beam_ids(m, beam)?, s).ok_or_else(|| {
                anyhow::anyhow!("no element of `{beam}` at r = {radius} m (outputs station)")
            })?;
            stations.push(Station { elem, s_m: s });
        }
        let kinds: Vec<usize> = spec
            .outputs
            .section_channels
            .iter()
            .filter_map(|k| SECTION_KINDS.iter().position(|c| c.0 == k))
            .collect();
        let unpitched_kinds: Vec<usize> = kinds
            .iter()
            .copied()
            .filter(|&k| UNPITCHED_KINDS.contains(&SECTION_KINDS[k].0))
            .collect();
        let mut names_v = vec![];
        for (_, x) in spec.load_stations() {
            for &k in &kinds {
                let (kind, unit) = SECTION_KINDS[k];
                names_v.push(section_channel(kind, unit, x, false));
            }
        }
        names_v.push(PITCH_LINK_CHANNEL.to_string());
        names_v.extend(ROOT_CHANNELS.iter().map(|s| s.to_string()));
        names_v.extend(ROOT_CHANNELS.iter().map(|s| format!("{CHECK_PREFIX}{s}")));
        names_v.extend(HINGE_CHANNELS.iter().map(|s| s.to_string()));
        // added channels follow the original ones, so that their order is kept
        names_v.extend(HINGE_MOMENT_CHANNELS.iter().map(|s| s.to_string()));
        for (_, x) in spec.load_stations() {
            for &k in &unpitched_kinds {
                let (kind, unit) = SECTION_KINDS[k];
                names_v.push(section_channel(kind, unit, x, true));
            }
        }
        names_v.extend(
            PITCH_LINK_CONTRIBUTOR_CHANNELS
                .iter()
                .map(|s| s.to_string()),
        );
        names_v.push(PITCH_LINK_ARM_CHANNEL.to_string());
        let hinges = [
            element(m, names::LAG)?,
            element(m, names::FLAP)?,
            element(m, names::PITCH)?,
        ];
        let link_ids = beam_ids(m, "pitch_link")?;
        let half = 0.5 * spec.pitch_control.link_length_m;
        let link = Station {
            elem: loads::element_at(m, &link_ids, half)
                .ok_or_else(|| anyhow::anyhow!("no pitch-link element at mid-length"))?,
            s_m: half,
        };
        let hub = m.node_id(names::HUB)?;
        let hub_cut = vec![beam_ids(m, "seg1")?[0], element(m, "damper_hub_mount")?];
        let mut beams = vec![];
        let outboard_from = beam_ids(m, "seg1")?.len();
        for b in ["seg1", "seg2", "seg3", names::BLADE] {
            beams.extend_from_slice(&beam_ids(m, b)?);
        }
        let mut rigid = vec![];
        for b in ["pitch_horn", "damper_arm", "damper_horn"] {
            rigid.push(element(m, b)?);
        }
        let station_beam = stations
            .iter()
            .map(|s| {
                beams.iter().position(|&e| e == s.elem).ok_or_else(|| {
                    anyhow::anyhow!("station element {} is not a blade-system beam", s.elem)
                })
            })
            .collect::<anyhow::Result<Vec<_>>>()?;
        let scratch = Mutex::new(Vec::with_capacity(beams.len()));
        let link_joint = element(m, "pitch_link_upper")?;
        let swash_drive = element(m, names::SWASH_DRIVE)?;
        let (sn, cs) = ahead_rad.sin_cos();
        let horn_node = match &m.elements[link_joint] {
            Element::Joint(j) => j
                .node_a
                .ok_or_else(|| anyhow::anyhow!("pitch_link_upper has no horn node"))?,
            _ => anyhow::bail!("pitch_link_upper is not a joint"),
        };
        let link_top = match &m.elements[link_joint] {
            Element::Joint(j) => j.node_b,
            _ => anyhow::bail!("pitch_link_upper is not a joint"),
        };
        Ok(LoadChannels {
            stations,
            kinds,
            unpitched_kinds,
            names: names_v,
            link,
            hub,
            hub_cut,
            beams,
            rigid,
            station_beam,
            scratch,
            link_joint,
            horn_node,
            lam_off: loads::lambda_offsets(m),
            frame: [[cs, -sn, 0.0], [sn, cs, 0.0], [0.0, 0.0, 1.0]],
            swash_drive,
            hinges,
            outboard_from,
            link_top,
        })
    }

    /// What this blade's system (retention, blade, damper, pitch link through the
    /// swashplate) exerts on the hub node, global, moment about the hub centre: the loads the
    /// hub passes to the shaft.
    pub fn on_hub(&self, m: &Model, st: &State) -> anyhow::Result<Resultant> {
        let ctx = eval_ctx(m, st);
        let e0 = self.beams[0];
        let Element::Beam(b0) = &m.elements[e0] else {
            anyhow::bail!("element {e0} is not a beam");
        };
        let k = b0.nodes.map(|i| st.node_kin(i));
        let ip = b0.interp(&k);
        let d = b0.densities_with(&k, &ip.rg, &ctx);
        let root = self.root(m, st, &ctx, &ElemData { elem: e0, k, ip, d })?;
        Ok(root.add(&loads::element_on_node(
            m,
            st,
            &ctx,
            &self.lam_off,
            self.swash_drive,
            self.hub,
        )?))
    }

    /// What the blade system exerts on the hub, global, about the hub centre: the
    /// retention's first element (`first`, its node 0 on the hub) and the damper's hub mount.
    fn root(
        &self,
        m: &Model,
        st: &State,
        ctx: &EvalCtx,
        first: &ElemData,
    ) -> anyhow::Result<Resultant> {
        let Element::Beam(b0) = &m.elements[first.elem] else {
            anyhow::bail!("element {} is not a beam", first.elem);
        };
        let (res, _, _) = b0.recovery(&first.k, &first.ip, &first.d, b0.s_range[0]);
        let mut root = Resultant {
            force: [-res[0], -res[1], -res[2]],
            moment: [-res[3], -res[4], -res[5]],
        };
        for &e in &self.hub_cut[1..] {
            root = root.add(&loads::element_on_node(
                m,
                st,
                ctx,
                &self.lam_off,
                e,
                self.hub,
            )?);
        }
        Ok(root)
    }

    /// Channel names, in the order of [`LoadChannels::values`].
    pub fn names(&self) -> &[String] {
        &self.names
    }

    /// Every channel at the current state (`out.len()` = `names().len()`). `damper`: the
    /// damper's last step, for its forces in the equilibrium check.
    pub fn values(
        &self,
        m: &Model,
        st: &State,
        damper: &DamperStep,
        out: &mut [f64],
    ) -> anyhow::Result<()> {
        if out.len() != self.names.len() {
            anyhow::bail!(
                "{} load channel values asked for, {} channels",
                out.len(),
                self.names.len()
            );
        }
        let ctx = eval_ctx(m, st);
        let mut data = self
            .scratch
            .lock()
            .map_err(|_| anyhow::anyhow!("load channel scratch poisoned"))?;
        data.clear();
        for &e in &self.beams {
            let Element::Beam(b) = &m.elements[e] else {
                anyhow::bail!("element {e} is not a beam");
            };
            let k = b.nodes.map(|n| st.node_kin(n));
            let ip = b.interp(&k);
            let d = b.densities_with(&k, &ip.rg, &ctx);
            data.push(ElemData { elem: e, k, ip, d });
        }
        let xh = st.x[self.hub];
        let rh = mm(&quat_to_arr(&st.q[self.hub]), &self.frame);
        // the shaft axis: the unpitched blade frame's second axis is normal to it
        let up = [rh[0][2], rh[1][2], rh[2][2]];
        // the unpitched section channels come last but for the pitch-link contributors
        let n_link = PITCH_LINK_CONTRIBUTOR_CHANNELS.len() + 1;
        let mut iu = out.len() - n_link - self.stations.len() * self.unpitched_kinds.len();
        let mut i = 0;
        let all = |c: &loads::SectionComponents| {
            [
                c.flap_nm,
                c.chord_nm,
                c.torsion_nm,
                c.shear_flap_n,
                c.shear_chord_n,
                c.axial_n,
            ]
        };
        for (s, &j) in self.stations.iter().zip(&self.station_beam) {
            let e = &data[j];
            let Element::Beam(b) = &m.elements[e.elem] else {
                anyhow::bail!("element {} is not a beam", e.elem);
            };
            let sec = loads::section_from(b, &e.k, &e.ip, &e.d, s.s_m);
            let c = all(&sec.components());
            for &k in &self.kinds {
                out[i] = c[k];
                i += 1;
            }
            let u = all(&sec.unpitched_components(up));
            for &k in &self.unpitched_kinds {
                out[iu] = u[k];
                iu += 1;
            }
        }
        let link_section = loads::section(m, st, &ctx, self.link.elem, self.link.s_m)?;
        let link_tension = link_section.components().axial_n;
        out[i] = link_tension;
        i += 1;
        // what the blade system exerts on the hub, about the hub centre, from this sample's
        // data of the retention's first element
        let root = self.root(m, st, &ctx, &data[0])?;
        // the same from the other side: applied and inertial loads of the blade system plus
        // the pitch link's pull on the horn
        let mut body = loads::applied_and_inertial(m, st, &ctx, &self.rigid, xh)?;
        for e in data.iter() {
            body = body.add(&loads::densities_resultant(&e.d, xh));
        }
        let link =
            loads::element_on_node(m, st, &ctx, &self.lam_off, self.link_joint, self.horn_node)?
                .moved(st.x[self.horn_node], xh);
        // The damper's end forces act along the mean direction of the step (paper Eqs. 12-13),
        // not along the final line: a couple u_f x F e_m, with the line turning by Omega h in
        // a step about half a step behind (docs/loads.md)
        let [a, b] = damper.nodes;
        let u_i = sub(damper.x_start[1], damper.x_start[0]);
        let u_f = sub(st.x[b], st.x[a]);
        let l_m = 0.5 * (norm3(u_i) + norm3(u_f));
        let e_m = fmul(0.5 / l_m, add(u_i, u_f));
        let f_b = fmul(damper.force_n, e_m);
        let couple = Resultant {
            force: [0.0; 3],
            moment: cross(u_f, f_b),
        };
        let check = body.add(&link).add(&couple);
        for r in [root, check] {
            let l = r.in_frame(&rh);
            out[i..i + 3].copy_from_slice(&l.force);
            out[i + 3..i + 6].copy_from_slice(&l.moment);
            i += 6;
        }
        let kin = |n: Option<usize>| n.map_or_else(NodeKin::ground, |n| st.node_kin(n));
        for (q, &e) in self.hinges.iter().enumerate() {
            let Element::Joint(j) = &m.elements[e] else {
                anyhow::bail!("element {e} is not a joint");
            };
            let (a, b) = (kin(j.node_a), kin(Some(j.node_b)));
            out[i + q] = j.angle(&a, &b);
            out[i + 3 + q] = j.axis_moment(&a, &b);
        }
        let k = out.len() - n_link;
        let link_axis = [
            link_section.frame[0][0],
            link_section.frame[1][0],
            link_section.frame[2][0],
        ];
        self.pitch_link_contributors(
            m,
            st,
            &ctx,
            &data[self.outboard_from..],
            link_tension,
            link_axis,
            &mut out[k..],
        )
    }

    /// The pitch-link contributors and the link's arm ([`PITCH_LINK_CONTRIBUTOR_CHANNELS`],
    /// [`PITCH_LINK_ARM_CHANNEL`]) into `out`, from the moment balance about the pitch joint's
    /// axis of the parts outboard of it (`outboard`: their beams' data). `link_axis`: the
    /// link's direction at mid-length, toward the horn (tension pulls the horn against it).
    #[allow(clippy::too_many_arguments)]
    fn pitch_link_contributors(
        &self,
        m: &Model,
        st: &State,
        ctx: &EvalCtx,
        outboard: &[ElemData],
        link_tension: f64,
        link_axis: [f64; 3],
        out: &mut [f64],
    ) -> anyhow::Result<()> {
        let kin = |n: Option<usize>| n.map_or_else(NodeKin::ground, |n| st.node_kin(n));
        let Element::Joint(pj) = &m.elements[self.hinges[2]] else {
            anyhow::bail!("element {} is not a joint", self.hinges[2]);
        };
        let (ka, kb) = (kin(pj.node_a), kin(Some(pj.node_b)));
        // the pitch axis: the joint's z through its point, as node A carries them
        let fa = mm(&ka.r, &pj.qa);
        let z = [fa[0][2], fa[1][2], fa[2][2]];
        let p = add(ka.x, mv(&ka.r, pj.da));
        let about = |r: &Resultant| dot(r.moment, z);
        // applied loads alone, then with gravity; the rest of the densities is inertia
        let applied_ctx = EvalCtx {
            inertia: false,
            gravity: [0.0; 3],
            ..*ctx
        };
        let with_gravity_ctx = EvalCtx {
            inertia: false,
            ..*ctx
        };
        let horn = &self.rigid[..1];
        let mut full = loads::applied_and_inertial(m, st, ctx, horn, p)?;
        let mut applied = loads::applied_and_inertial(m, st, &applied_ctx, horn, p)?;
        let mut with_gravity = loads::applied_and_inertial(m, st, &with_gravity_ctx, horn, p)?;
        let has_gravity = ctx.gravity != [0.0; 3];
        for e in outboard {
            let Element::Beam(b) = &m.elements[e.elem] else {
                anyhow::bail!("element {} is not a beam", e.elem);
            };
            full = full.add(&loads::densities_resultant(&e.d, p));
            let d = b.densities_with(&e.k, &e.ip.rg, &applied_ctx);
            let a = loads::densities_resultant(&d, p);
            applied = applied.add(&a);
            with_gravity = with_gravity.add(&if has_gravity {
                loads::densities_resultant(&b.densities_with(&e.k, &e.ip.rg, &with_gravity_ctx), p)
            } else {
                a
            });
        }
        let m_air = about(&applied);
        let m_grav = about(&with_gravity) - m_air;
        let m_inertia = about(&full) - about(&with_gravity);
        // the bearing's moment on the blade side resists the pitch angle
        let m_bearing = -pj.axis_moment(&ka, &kb);
        let horn_load =
            loads::element_on_node(m, st, ctx, &self.lam_off, self.link_joint, self.horn_node)?
                .moved(st.x[self.horn_node], p);
        let arm = dot(cross(sub(st.x[self.link_top], p), fmul(-1.0, link_axis)), z);
        // balance: tension x arm + the others' moments = 0 (the link's own part being the
        // difference between its mid-length tension and its moment at the horn)
        out[0] = -m_bearing / arm;
        out[1] = -m_air / arm;
        out[2] = -m_inertia / arm;
        out[3] = -m_grav / arm;
        out[4] = link_tension - about(&horn_load) / arm;
        out[5] = arm;
        Ok(())
    }
}
