//! The forced-response simulation of the rotor: expanded model + damper element + airload
//! replay + swashplate law, marched by the generalized-alpha solver (see docs/rotor_model.md).
use super::deck::{AirloadFrame, RotorSpec};
use super::expand::{
    expand_deck, expand_items, expand_rotor_items, names, ramp, Controls, ExpandOptions,
    ExpandedItems,
};
use super::{ForcedResponse, RunOptions, Timing, BASE_CHANNELS};
use crate::flight::replay::{AirloadReplay, ReplayMode, ReplayOptions};
use crate::flight::FlightRecord;
use crate::hydraulics::{DamperDeck, DamperModel};
use crate::solver::statics::{static_solve, StaticOptions};
use crate::solver::{DynamicSolver, NewtonError, State};
use crate::structure::beam::{SectionLoad, NPTS_M};
use crate::structure::deck::{build_deck_ids, Built, BuiltIds, Deck};
use crate::structure::elastomer::Elastomer;
use crate::structure::hydraulic::{HydraulicForceElement, HydraulicProbe};
use crate::structure::kin::TimeTable;
use crate::structure::model::{DistributedLoad, Element, LoadPoint, Model};
use crate::structure::rotation::*;
use std::path::Path;
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::{Arc, Mutex};
use std::time::Instant;

/// Airloads of the record on the blade: mean + ramp(t) (periodic part), follower section loads
/// (docs/formats.md: normal along +z, chord force along -y, moment about +x; the beam reference line
/// is taken as the quarter chord).
pub struct BladeAirloads {
    full: AirloadReplay,
    mean: AirloadReplay,
    /// The blade's azimuth ahead of the reference blade [deg] (whole-rotor runs; else 0).
    ahead_deg: f64,
    root_r_m: f64,
    t_ramp: f64,
    /// Load scale (static load stepping of the initial equilibrium; 1 in the dynamics).
    scale: Arc<AtomicU64>,
    /// `Some` for [`AirloadFrame::ControlPitch`].
    control_pitch: Option<ControlPitch>,
}

/// What [`AirloadFrame::ControlPitch`] needs: the commanded bearing pitch and the reference
/// (built-in) pitch at every load point of the blade.
struct ControlPitch {
    spec: RotorSpec,
    controls: Controls,
    /// Per model element id: (s_m, reference section pitch [rad]) at its load points.
    reference: std::collections::HashMap<usize, [(f64, f64); NPTS_M]>,
    /// The commanded pitch at the last time asked (every load point of an evaluation shares it).
    pitch_at: std::cell::Cell<(f64, f64)>,
}

impl ControlPitch {
    fn new(
        spec: &RotorSpec,
        controls: Controls,
        model: &Model,
        beam: &str,
    ) -> anyhow::Result<Self> {
        let kin = model.reference_state();
        let mut reference = std::collections::HashMap::new();
        let ids = model
            .beams
            .get(beam)
            .ok_or_else(|| anyhow::anyhow!("expanded rotor model has no beam `{beam}`"))?;
        for &ei in ids {
            if let Element::Beam(b) = &model.elements[ei] {
                let pts = b.load_points(&b.nodes.map(|i| kin[i]));
                reference.insert(
                    ei,
                    std::array::from_fn(|q| (b.gm[q].s_m, section_pitch(&pts[q].1))),
                );
            }
        }
        Ok(ControlPitch {
            spec: spec.clone(),
            controls,
            reference,
            pitch_at: std::cell::Cell::new((f64::NAN, 0.0)),
        })
    }

    /// Rigid pitch minus the model's section pitch at `p` [rad]: the turn about the section
    /// axis from the deformed frame to the control-pitch frame.
    fn correction(&self, p: &LoadPoint) -> f64 {
        let reference = self.reference.get(&p.element).and_then(|pts| {
            pts.iter()
                .find(|(s, _)| *s == p.s_m)
                .map(|(_, theta)| *theta)
        });
        match reference {
            Some(theta_ref) => {
                let (t, pitch) = self.pitch_at.get();
                let pitch = if t == p.t {
                    pitch
                } else {
                    let pitch = self.spec.pitch_rad(&self.controls, p.t);
                    self.pitch_at.set((p.t, pitch));
                    pitch
                };
                theta_ref + pitch - section_pitch(&p.r)
            }
            // every load point of the blade was tabulated at construction (same model, same
            // quadrature); anything else is a bug, not input
            None => {
                debug_assert!(
                    false,
                    "no reference pitch at element {} s {}",
                    p.element, p.s_m
                );
                0.0
            }
        }
    }
}

/// Pitch of a section about its own axis relative to the hub plane [rad] (nose up positive):
/// for `R = Rz(-zeta) Ry(-beta) Rx(theta)` the section axis 2 has the vertical component
/// `sin(theta) cos(beta)` and axis 1 `sin(beta)`; rotation about the shaft (z) leaves both.
pub fn section_pitch(r: &[[f64; 3]; 3]) -> f64 {
    let cb = (1.0 - r[2][0] * r[2][0]).max(1e-12).sqrt();
    (r[2][1] / cb).clamp(-1.0, 1.0).asin()
}

impl DistributedLoad for BladeAirloads {
    fn eval(&mut self, p: &LoadPoint) -> SectionLoad {
        self.eval_with_turn(p).0
    }
}

impl BladeAirloads {
    /// The load, and the turn d about the section axis from the section's frame to the frame
    /// the loads are applied in (0 in the deformed frame).
    pub(crate) fn eval_with_turn(&mut self, p: &LoadPoint) -> (SectionLoad, f64) {
        let r = self.root_r_m + p.s_m;
        let m = self.mean.section_loads_ahead(p.t, r, self.ahead_deg);
        let w = ramp(p.t, self.t_ramp);
        let l = if w == 0.0 {
            m
        } else {
            let a = self.full.section_loads_ahead(p.t, r, self.ahead_deg);
            crate::flight::replay::SectionLoads {
                normal_N_per_m: m.normal_N_per_m + w * (a.normal_N_per_m - m.normal_N_per_m),
                chord_N_per_m: m.chord_N_per_m + w * (a.chord_N_per_m - m.chord_N_per_m),
                moment_N_m_per_m: m.moment_N_m_per_m
                    + w * (a.moment_N_m_per_m - m.moment_N_m_per_m),
            }
        };
        let k = f64::from_bits(self.scale.load(Ordering::Relaxed));
        // Control-pitch frame: the loads turned by d about the section axis, so that the
        // normal and chord directions are those of the rigid pitch (docs/rotor_model.md).
        // d comes from the iterate of each residual evaluation, so the residual is exact; the
        // beam's tangent differentiates the frame R only and keeps a twist stiffness this load
        // lacks (a quasi-Newton tangent: 2.83 iterations/step, as in the deformed frame).
        let d = self.control_pitch.as_ref().map_or(0.0, |c| c.correction(p));
        let (sd, cd) = d.sin_cos();
        let (fy, fz) = (
            -l.normal_N_per_m * sd - l.chord_N_per_m * cd,
            l.normal_N_per_m * cd - l.chord_N_per_m * sd,
        );
        (
            SectionLoad {
                force: [0.0, k * fy, k * fz],
                moment: [k * l.moment_N_m_per_m, 0.0, 0.0],
                follower: true,
            },
            d,
        )
    }
}

/// The model of `spec`'s expanded deck (relative paths against `file`'s folder).
pub fn expanded_model(
    spec: &RotorSpec,
    opts: &ExpandOptions,
    file: &Path,
) -> anyhow::Result<Model> {
    model_of_expanded(&expand_deck(spec, opts), file)
}

/// The whole rotor's model (every blade's deck in `specs`, blade 1 first) on one driven hub
/// (relative paths against `file`'s folder). The hub and the airframe's chain are its border
/// nodes: the blades meet only there, so the solver factors each blade on its own.
pub fn whole_rotor_model(
    specs: &[RotorSpec],
    opts: &ExpandOptions,
    file: &Path,
) -> anyhow::Result<Model> {
    let deck = super::expand::expand_rotor_deck(specs, opts);
    Ok(whole_rotor_built(&deck, file)?.model)
}

/// The whole rotor's deck built, with the hub and the airframe's chain as its border nodes.
fn whole_rotor_built(deck: &Deck, file: &Path) -> anyhow::Result<Built> {
    let mut built = built_expanded(deck, file)?;
    let model = &mut built.model;
    let airframe = format!("{}.", names::AIRFRAME);
    model.border_nodes = (0..model.nodes.len())
        .filter(|&i| {
            let name = &model.nodes[i].name;
            name == names::HUB || name.starts_with(&airframe)
        })
        .collect();
    Ok(built)
}

/// The model of a deck expanded from the rotor deck `file`, checked as a read deck is (relative
/// paths against the deck's folder, errors naming the deck as expanded).
pub(crate) fn model_of_expanded(deck: &Deck, file: &Path) -> anyhow::Result<Model> {
    Ok(built_expanded(deck, file)?.model)
}

fn built_expanded(deck: &Deck, file: &Path) -> anyhow::Result<Built> {
    let base = file.parent().map(Path::to_path_buf).unwrap_or_default();
    let name = format!("{} (expanded)", file.display());
    Ok(build_deck_ids(deck, &name, &base)?)
}

/// The model ids of the parts a run drives and reads.
struct RotorIds {
    hub: usize,
    /// The airframe chain's nodes, in the order of [`super::expand::airframe_chain`].
    airframe: Vec<usize>,
    blades: Vec<BladeIds>,
}

/// One blade's parts in the model.
struct BladeIds {
    swash: usize,
    damper_ends: [usize; 2],
    root: usize,
    tip: usize,
}

impl RotorIds {
    /// The ids of the expansion's `items` in the model built with `ids`.
    fn new(items: &ExpandedItems, ids: &BuiltIds) -> anyhow::Result<Self> {
        let missing =
            |what: &str, i: usize| anyhow::anyhow!("expanded rotor model: {what}[{i}] not built");
        let node = |i: usize| ids.nodes.get(i).copied().ok_or_else(|| missing("node", i));
        let blades = items
            .blades
            .iter()
            .map(|b| {
                let beam = ids
                    .beam_nodes
                    .get(b.blade)
                    .ok_or_else(|| missing("beam", b.blade))?;
                let ends = (beam.first().copied(), beam.last().copied());
                let (Some(root), Some(tip)) = ends else {
                    return Err(missing("beam", b.blade));
                };
                Ok(BladeIds {
                    swash: ids
                        .joints
                        .get(b.swash)
                        .copied()
                        .ok_or_else(|| missing("joint", b.swash))?,
                    damper_ends: [node(b.damper_ends[0])?, node(b.damper_ends[1])?],
                    root,
                    tip,
                })
            })
            .collect::<anyhow::Result<_>>()?;
        Ok(RotorIds {
            hub: node(items.hub)?,
            airframe: items
                .airframe
                .iter()
                .map(|&i| node(i))
                .collect::<anyhow::Result<_>>()?,
            blades,
        })
    }
}

/// Newton tolerance of the rotor simulation (relative to the predictor residual).
pub const RTOL: f64 = 1e-7;
/// Tolerance accepted on a retry when Newton stalls below it (see `RotorSim::relaxed_steps`).
pub const RTOL_STALL: f64 = 1e-5;

/// One blade of the simulation: its deck, controls, swashplate drive, damper and channels.
struct BladePart {
    /// Prefix of its model names and channels (`b<K>.` in a whole rotor with an airframe,
    /// empty for blade 1 and the single blade).
    prefix: String,
    spec: RotorSpec,
    controls: Controls,
    swash: usize,
    probe: Arc<HydraulicProbe>,
    /// Scratch for the probe's values (channels() must not allocate).
    scratch: Mutex<Vec<f64>>,
    dev_names: Vec<String>,
    tip: usize,
    root: usize,
    /// The blade's frame in the hub's (its azimuth ahead of blade 1).
    frame: [[f64; 3]; 3],
    /// Undeformed tip in the blade's frame.
    tip_ref: [f64; 3],
    twist_ref: f64,
    /// Blade load channels (after the base and device channels).
    loads: super::loads::LoadChannels,
    /// Damper end nodes and their positions at the start of the last step.
    damper_nodes: [usize; 2],
    damper_x_start: [[f64; 3]; 2],
    /// Relief-valve limits and regulation of its damper (physical model).
    limits: Option<(f64, f64)>,
    regulation: Option<[super::ReliefRegulation; 2]>,
}

/// The airframe under the hub: its moving directions and the node under the shaft.
struct AirframePart {
    dofs: Vec<super::deck::AirframeDof>,
    /// The chain's last node (the shaft's node A), and each direction's node (chain order).
    mount: usize,
    chain: Vec<usize>,
    /// The translational mass of each chain node [kg].
    masses: Vec<f64>,
}

/// Airframe channel names of one direction: displacement, acceleration, the rotor's load on
/// the airframe at the hub (fixed frame), and the airframe's own side of its equation of
/// motion (inertia + damper + spring), consumed by the momentum check.
pub fn airframe_channel_names(d: &super::deck::AirframeDof) -> [String; 4] {
    let n = d.name;
    if d.rotation {
        [
            format!("airframe_{n}_rad"),
            format!("airframe_{n}_accel_rad_s2"),
            format!("airframe_{n}_hub_moment_Nm"),
            format!("{AIRFRAME_EOM_PREFIX}airframe_{n}_Nm"),
        ]
    } else {
        [
            format!("airframe_{n}_m"),
            format!("airframe_{n}_accel_m_s2"),
            format!("airframe_{n}_hub_force_N"),
            format!("{AIRFRAME_EOM_PREFIX}airframe_{n}_N"),
        ]
    }
}

/// Prefix of the channels that feed the airframe's momentum check (not written as outputs).
pub const AIRFRAME_EOM_PREFIX: &str = "eom_";

/// The residual tolerance of the step that ended at each sample [N] (momentum check).
pub const AIRFRAME_STEP_TOLERANCE: &str = "eom_step_tolerance_N";

/// The rotor forced-response simulation: one blade on a driven hub, or the whole rotor (every
/// blade its own copy) on an airframe.
pub struct RotorSim {
    label: String,
    solver: DynamicSolver,
    period: f64,
    omega: f64,
    h: f64,
    physical: bool,
    parts: Vec<BladePart>,
    airframe: Option<AirframePart>,
    hub: usize,
    total_s: f64,
    relaxed_steps: usize,
    /// Newton tolerance of a step (relative to the zero-acceleration predictor residual).
    rtol: f64,
    /// The last step's residual tolerance [N] (for the airframe's momentum check).
    step_tol: f64,
    /// Reference orientation of every node (the chart of the saved coordinates).
    r0: Vec<[[f64; 3]; 3]>,
    /// End of the cyclic ramp [s].
    t_ramp: f64,
    /// Load channels computed (see [`ForcedResponse::set_output_channels`]).
    output_channels: bool,
    /// A blade of a whole-rotor run (its hub loads come from all blades, not by symmetry).
    in_whole_rotor: bool,
    /// The lifting lines and their inflow (computed and hybrid airloads).
    aero: Option<AeroRun>,
    /// The hybrid's periodic reference: whether adopted (None: no such reference).
    reference_adopted: Option<Arc<std::sync::atomic::AtomicBool>>,
}

/// The rotor's aerodynamics in a run: what the lifting lines share, and the output stations.
struct AeroRun {
    source: super::aero::AirloadSource,
    air: crate::aero::lifting_line::RotorAir,
    shared: Arc<Mutex<crate::aero::lifting_line::AeroShared>>,
    clamps: Arc<crate::aero::airfoil::ClampCounts>,
    /// Blades of the rotor per blade modelled (the inflow's thrust).
    scale: f64,
    /// Solidity N c / (pi R) of blade 1's chord.
    solidity: f64,
    /// Whether the blades' airloads drive the inflow (computed) or it stays at the record's.
    coupled: bool,
    /// Output stations r/R (the record's) and radius [m].
    stations: Vec<(f64, f64)>,
    /// The record's airloads (the computed-minus-measured channels) and blade 1's azimuth ahead.
    measured: AirloadReplay,
    ahead_deg: f64,
    /// A blade standing for N identical ones: its disk loads over the last revolution, per
    /// step (NaN: not yet integrated), so that the rotor's are the sum at the N blades'
    /// azimuths, `sum_k f(t - k T/N)` (exact on the periodic solution). Empty when every blade
    /// is modelled or the steps per revolution are not a multiple of N.
    history: Vec<crate::aero::inflow::DiskLoads>,
    blades: usize,
    /// Blade 1's aerodynamic geometry (the output stations' sections are evaluated with it).
    geometry: crate::aero::lifting_line::BladeAero,
    /// Blade 1's aerofoils by segment, in words.
    airfoils: Vec<String>,
    /// The narrowest alpha and Mach limits of its tables (None: the thin fallback only).
    table_limits: Option<[f64; 4]>,
    record_ct_over_sigma: Option<f64>,
    record_synthetic: bool,
}

/// Per output station: angle of attack, Mach, lift, drag and moment coefficients, inflow
/// ratio, normal force and its difference from the record's.
const AERO_STATION_CHANNELS: [&str; 8] = [
    "aero_alpha_deg",
    "aero_mach",
    "aero_cl",
    "aero_cd",
    "aero_cm",
    "aero_inflow_ratio",
    "aero_normal_N_per_m",
    "aero_normal_minus_measured_N_per_m",
];

/// Rotor channels of the aerodynamics (the rotor's thrust and power from the modelled blades
/// times the rotor's blades per modelled blade).
const AERO_ROTOR_CHANNELS: [&str; 4] = [
    "rotor_thrust_N",
    "rotor_power_W",
    "rotor_CT_over_sigma",
    "inflow_ratio_mean",
];

/// Station label of channel names: `r0.775`.
pub fn station_label(r_over_r: f64) -> String {
    format!("r{r_over_r:.3}")
}

/// Relief-valve cracking limits of Eq. (5) with the other chamber at `p_s`:
/// valve 0 cracks at `p0 = (F_p + p_s A_back)/A_front`, so `F_max = p0 A0 - p_s A1`; valve 1
/// mirrors it for negative forces.
pub fn relief_limits(deck: &DamperDeck) -> Option<(f64, f64)> {
    let p = deck.physical.as_ref()?;
    let a0 = p.chambers[0].area;
    let a1 = p.chambers[1].area;
    let ps = p.p_s;
    let hi = p.relief[0]
        .as_ref()
        .map(|v| (v.f_p + ps * v.a_back) / v.a_front * a0 - ps * a1);
    let lo = p.relief[1]
        .as_ref()
        .map(|v| -((v.f_p + ps * v.a_back) / v.a_front * a1 - ps * a0));
    match (lo, hi) {
        (Some(l), Some(h)) => Some((l, h)),
        _ => None,
    }
}

/// Build the simulation of one blade (see [`super::build`]).
pub fn build_sim(
    spec: &RotorSpec,
    file: &Path,
    damper: &DamperDeck,
    model_kind: DamperModel,
    record: &FlightRecord,
    opts: &RunOptions,
) -> anyhow::Result<RotorSim> {
    let ahead = opts.blade_azimuth_deg.unwrap_or(0.0);
    build_parts(
        &[(spec, damper, ahead)],
        false,
        file,
        model_kind,
        record,
        opts,
    )
}

/// Build the whole rotor on its airframe: every blade's deck and damper deck in `blades`
/// (blade 1 first), coupled through the hub, which moves with the airframe of blade 1's deck.
pub fn build_rotor_sim(
    blades: &[(&RotorSpec, &DamperDeck)],
    file: &Path,
    model_kind: DamperModel,
    record: &FlightRecord,
    opts: &RunOptions,
) -> anyhow::Result<RotorSim> {
    let n = blades.len();
    let parts: Vec<(&RotorSpec, &DamperDeck, f64)> = blades
        .iter()
        .enumerate()
        .map(|(i, (s, d))| (*s, *d, i as f64 * 360.0 / n as f64))
        .collect();
    build_parts(&parts, true, file, model_kind, record, opts)
}

/// The lifting lines' shared air, state and clamp counts (computed and hybrid airloads).
type AeroCommon = (
    crate::aero::lifting_line::RotorAir,
    Arc<Mutex<crate::aero::lifting_line::AeroShared>>,
    Arc<crate::aero::airfoil::ClampCounts>,
);

/// What the stages of [`build_parts`] share: the inputs and the run's timing, controls and flags.
struct BuildCtx<'a> {
    whole: bool,
    file: &'a Path,
    model_kind: DamperModel,
    record: &'a FlightRecord,
    opts: &'a RunOptions,
    period: f64,
    base_controls: Controls,
    t_ramp: f64,
    scale: Arc<AtomicU64>,
    source: super::aero::AirloadSource,
    aero_active: Arc<std::sync::atomic::AtomicBool>,
    reference_adopted: Arc<std::sync::atomic::AtomicBool>,
    physical: bool,
}

/// A blade's damper and swashplate as added to the model, before the initial state is known.
struct Pending {
    prefix: String,
    controls: Controls,
    swash: usize,
    probe: Arc<HydraulicProbe>,
    dev_names: Vec<String>,
    damper_nodes: [usize; 2],
    limits: Option<(f64, f64)>,
    regulation: Option<[super::ReliefRegulation; 2]>,
}

/// Builds the rotor simulation's parts from the deck, stage by stage.
fn build_parts(
    blades: &[(&RotorSpec, &DamperDeck, f64)],
    whole: bool,
    file: &Path,
    model_kind: DamperModel,
    record: &FlightRecord,
    opts: &RunOptions,
) -> anyhow::Result<RotorSim> {
    if opts.steps_per_rev < 8 {
        anyhow::bail!("steps per revolution {} is below 8", opts.steps_per_rev);
    }
    let Some(&(spec, _, _)) = blades.first() else {
        anyhow::bail!("a rotor without blades");
    };
    spec.check_record(record, file)?;
    let om = spec.rotor.omega_rad_s;
    let period = 2.0 * std::f64::consts::PI / om;
    let h = period / opts.steps_per_rev as f64;
    let base_controls = Controls::from_record(&record.meta.controls_deg);
    let (mut model, ids) = initial_model(blades, whole, file, base_controls)?;
    let t_ramp = spec.pitch_control.cyclic_ramp_revs * period;
    let scale = Arc::new(AtomicU64::new(0f64.to_bits()));
    // the lifting lines' shared state (computed and hybrid airloads); off in the statics
    let source = opts.airloads;
    let aero_active = Arc::new(std::sync::atomic::AtomicBool::new(false));
    // the hybrid's periodic reference: recorded first, adopted once the run has found it
    let reference_adopted = Arc::new(std::sync::atomic::AtomicBool::new(false));
    let aero_common = aero_common(spec, record, file, source)?;
    let physical = model_kind == DamperModel::Physical;
    let ctx = BuildCtx {
        whole,
        file,
        model_kind,
        record,
        opts,
        period,
        base_controls,
        t_ramp,
        scale,
        source,
        aero_active,
        reference_adopted,
        physical,
    };
    let mut pending = Vec::with_capacity(blades.len());
    for (k, &(bspec, damper, ahead_deg)) in blades.iter().enumerate() {
        let part = ids
            .blades
            .get(k)
            .ok_or_else(|| anyhow::anyhow!("expanded rotor model: no blade {}", k + 1))?;
        pending.push(add_blade(
            &ctx,
            &mut model,
            (k, part),
            (bspec, damper, ahead_deg),
            &aero_common,
        )?);
    }
    let mut st = initial_state(&mut model, &ctx.scale, om)?;
    ctx.aero_active.store(true, Ordering::Relaxed);
    let hub = ids.hub;
    let airframe = airframe_part(spec, whole, &ids.airframe, &mut st)?;
    let r0 = (0..model.nodes.len()).map(|i| model.node_r0(i)).collect();
    let parts = blade_parts(pending, blades, whole, &model, &ids.blades)?;
    let solver = dynamic_solver(model, st, h, opts, source)?;
    let aero = aero_run(&ctx, blades, spec, aero_common)?;
    Ok(RotorSim {
        label: model_kind.name().to_string(),
        solver,
        period,
        omega: om,
        h,
        physical,
        parts,
        airframe,
        hub,
        total_s: 0.0,
        relaxed_steps: 0,
        rtol: opts.newton_rtol,
        step_tol: f64::NAN,
        r0,
        t_ramp,
        output_channels: true,
        in_whole_rotor: whole || opts.blade_azimuth_deg.is_some(),
        aero,
        reference_adopted: (source == super::aero::AirloadSource::HybridPeriodic
            || (source == super::aero::AirloadSource::Hybrid && record.motion.is_none()))
        .then_some(ctx.reference_adopted),
    })
}

/// Expands the deck(s) into the structural model: the whole rotor or one blade; with the ids
/// of the parts the run drives and reads.
fn initial_model(
    blades: &[(&RotorSpec, &DamperDeck, f64)],
    whole: bool,
    file: &Path,
    base_controls: Controls,
) -> anyhow::Result<(Model, RotorIds)> {
    let spec = blades[0].0;
    let (built, items) = if whole {
        let specs: Vec<RotorSpec> = blades.iter().map(|b| b.0.clone()).collect();
        let xo = ExpandOptions {
            controls: base_controls,
            table_revs: 1,
            ..Default::default()
        };
        let (deck, items) = expand_rotor_items(&specs, &xo);
        (whole_rotor_built(&deck, file)?, items)
    } else {
        // a blade ahead of the reference blade sees the shared swashplate's cyclic turned
        let xo = ExpandOptions {
            controls: base_controls.ahead_by(blades[0].2),
            table_revs: 1,
            ..Default::default()
        };
        let (deck, items) = expand_items(spec, &xo);
        (built_expanded(&deck, file)?, items)
    };
    let ids = RotorIds::new(&items, &built.ids)?;
    Ok((built.model, ids))
}

/// Sets up the lifting lines' shared air and inflow (computed and hybrid airloads only).
fn aero_common(
    spec: &RotorSpec,
    record: &FlightRecord,
    file: &Path,
    source: super::aero::AirloadSource,
) -> anyhow::Result<Option<AeroCommon>> {
    Ok(if source.aerodynamic() {
        use crate::aero::inflow::Inflow;
        let air = super::aero::rotor_air(spec, record)?;
        let cond = super::aero::flight_condition(&air);
        let (_, inflow_model) = super::aero::blade_geometry(spec, file)?;
        // the inflow starts from (hybrid: stays at) the record's thrust and moments
        let disk = super::aero::record_disk_loads(record, &air, spec.rotor.blades);
        let mut inflow = Inflow::new(inflow_model, cond);
        inflow.set_state(Inflow::steady(inflow_model, cond, &disk));
        let shared = Arc::new(Mutex::new(crate::aero::lifting_line::AeroShared {
            inflow,
            points: vec![],
        }));
        Some((
            air,
            shared,
            Arc::new(crate::aero::airfoil::ClampCounts::default()),
        ))
    } else {
        None
    })
}

/// Adds blade k's swashplate setting, damper element and airloads to the model.
fn add_blade(
    ctx: &BuildCtx,
    model: &mut Model,
    (k, ids): (usize, &BladeIds),
    (bspec, damper, ahead_deg): (&RotorSpec, &DamperDeck, f64),
    aero_common: &Option<AeroCommon>,
) -> anyhow::Result<Pending> {
    let prefix = if ctx.whole && k > 0 {
        format!("b{}.", k + 1)
    } else if ctx.whole {
        "b1.".to_string()
    } else {
        String::new()
    };
    let nm = |s: &str| format!("{prefix}{s}");
    let controls = ctx.base_controls.ahead_by(ahead_deg);
    let swash = ids.swash;
    set_swash(
        model,
        swash,
        &[(0.0, bspec.swash_z(bspec.pitch_rad(&controls, 0.0)))],
    );
    let device = damper.build(ctx.model_kind, ctx.opts.hydraulics)?;
    let dev_names: Vec<String> = device
        .channel_names()
        .iter()
        .map(|s| s.to_string())
        .collect();
    let [n_hub_end, n_blade_end] = ids.damper_ends;
    // Coupling element (paper Eqs. 9-16), applying the end-of-step force (docs/coupling.md:
    // the step mean F_m is unstable with generalized-alpha for stiff devices).
    let elem = HydraulicForceElement::new(nm("damper"), n_hub_end, n_blade_end, device)
        .with_reference_length(bspec.damper_attachment.reference_length_m);
    let probe = elem.probe();
    model.add_step_element(Box::new(elem))?;
    let record = ctx.record;
    let full = AirloadReplay::new(record, ReplayMode::Average, ReplayOptions::default())?;
    let mean = AirloadReplay::new(
        record,
        ReplayMode::Average,
        ReplayOptions {
            harmonics: Some(0),
            ..Default::default()
        },
    )?;
    let airloads = BladeAirloads {
        full,
        mean,
        ahead_deg,
        root_r_m: bspec.blade.root_r_m,
        t_ramp: ctx.t_ramp,
        scale: ctx.scale.clone(),
        control_pitch: match bspec.blade.airload_frame {
            AirloadFrame::Deformed => None,
            AirloadFrame::ControlPitch => Some(ControlPitch::new(
                bspec,
                controls,
                model,
                &nm(names::BLADE),
            )?),
        },
    };
    let load = blade_distributed_load(
        ctx,
        model,
        k,
        &nm(names::BLADE),
        bspec,
        ahead_deg,
        airloads,
        aero_common,
    )?;
    model.add_distributed_load(&nm(names::BLADE), load)?;
    Ok(Pending {
        prefix,
        controls,
        swash,
        probe,
        dev_names,
        damper_nodes: [n_hub_end, n_blade_end],
        limits: if ctx.physical {
            relief_limits(damper)
        } else {
            None
        },
        regulation: if ctx.physical {
            damper
                .physical
                .as_ref()
                .and_then(super::ReliefRegulation::of)
        } else {
            None
        },
    })
}

/// Makes blade k's airload provider: the replay, or a computed or hybrid lifting line.
#[allow(clippy::too_many_arguments)]
fn blade_distributed_load(
    ctx: &BuildCtx,
    model: &Model,
    k: usize,
    blade: &str,
    bspec: &RotorSpec,
    ahead_deg: f64,
    airloads: BladeAirloads,
    aero_common: &Option<AeroCommon>,
) -> anyhow::Result<Box<dyn DistributedLoad>> {
    let (record, opts, source, t_ramp) = (ctx.record, ctx.opts, ctx.source, ctx.t_ramp);
    Ok(match aero_common {
        None => super::transient::blade_load(
            airloads,
            model,
            blade,
            bspec,
            record,
            opts.steps_per_rev,
            opts.perturbation_damping,
        )?,
        // the lifting line's damping replaces the perturbation damping
        Some((air, shared, clamps)) => {
            use super::aero::{AirloadSource, ComputedLoad, HybridLoad};
            let (geometry, _) = super::aero::blade_geometry(bspec, ctx.file)?;
            let ahead = ahead_deg.to_radians();
            let model_turn = if ctx.whole { ahead } else { 0.0 };
            let line = crate::aero::lifting_line::LiftingLine::new(
                model,
                blade,
                &geometry,
                *air,
                clamps.clone(),
                shared.clone(),
                k,
            )?
            .with_turn(ahead - model_turn);
            if source.hybrid() {
                let stations = line.stations();
                let reference = if source == AirloadSource::Hybrid && record.motion.is_some() {
                    super::aero::Reference::Record(Box::new(super::aero::reference_motion(
                        record, bspec, model, blade, &line, ahead, model_turn,
                    )?))
                } else {
                    super::aero::Reference::Periodic(super::aero::PeriodicReference::new(
                        stations,
                        opts.steps_per_rev,
                        ctx.period / opts.steps_per_rev as f64,
                        ctx.reference_adopted.clone(),
                    ))
                };
                Box::new(HybridLoad {
                    measured: airloads,
                    line,
                    reference,
                    reference_cache: vec![(f64::NAN, Default::default()); stations],
                    t_ramp,
                    active: ctx.aero_active.clone(),
                })
            } else {
                Box::new(ComputedLoad {
                    statics: airloads,
                    line,
                    active: ctx.aero_active.clone(),
                    t_ramp,
                })
            }
        }
    })
}

/// Solves the initial state: rotating static equilibrium under the mean loads and collective.
fn initial_state(model: &mut Model, scale: &AtomicU64, om: f64) -> anyhow::Result<State> {
    let mut st = State::from_model(model);
    let sopts = StaticOptions {
        load_steps: 1,
        omega: Some([0.0, 0.0, om]),
        ..Default::default()
    };
    // first the controls alone, then the mean airloads in load steps (the load factor of
    // static_solve does not scale load providers: the provider's own scale does)
    const STEPS: usize = 8;
    for k in 0..=STEPS {
        scale.store((k as f64 / STEPS as f64).to_bits(), Ordering::Relaxed);
        static_solve(model, &mut st, &sopts, |_, _, _, _| {})
        .map_err(|e| {
            anyhow::anyhow!(
                "rotating equilibrium at t = 0 under {:.0}% of the mean airloads (initial state): {e}",
                100.0 * k as f64 / STEPS as f64
            )
        })?;
    }
    st.set_rigid_rotation([0.0; 3], [0.0, 0.0, om]);
    Ok(st)
}

/// Finds the whole rotor's airframe chain and mount, and starts the airframe at rest.
fn airframe_part(
    spec: &RotorSpec,
    whole: bool,
    chain: &[usize],
    st: &mut State,
) -> anyhow::Result<Option<AirframePart>> {
    Ok(match (&spec.airframe, whole) {
        (Some(a), true) => {
            let dofs = super::expand::airframe_chain(a);
            let chain = chain.to_vec();
            // the airframe does not turn with the rotor: it starts at rest in its deflection
            for &i in &chain {
                st.v[i] = [0.0; 3];
                st.w[i] = [0.0; 3];
                st.a[i] = [0.0; 3];
                st.al[i] = [0.0; 3];
            }
            // the shaft turns the hub on the chain's last node
            let mount = chain.last().copied().ok_or_else(|| {
                anyhow::anyhow!("expanded rotor model: the shaft is not on the airframe")
            })?;
            Some(AirframePart {
                masses: super::expand::airframe_node_masses(&dofs),
                dofs,
                mount,
                chain,
            })
        }
        _ => None,
    })
}

/// Completes each pending blade into its output part: tip, root, frame and load channels.
fn blade_parts(
    pending: Vec<Pending>,
    blades: &[(&RotorSpec, &DamperDeck, f64)],
    whole: bool,
    model: &Model,
    ids: &[BladeIds],
) -> anyhow::Result<Vec<BladePart>> {
    let mut parts = Vec::with_capacity(pending.len());
    for ((p, &(bspec, _, ahead_deg)), b) in pending.into_iter().zip(blades).zip(ids) {
        // where the blade sits in the model: turned in the whole rotor's; a single blade
        // (even one ahead of blade 1 in time) lies along the hub's x axis
        let ahead_deg = if whole { ahead_deg } else { 0.0 };
        let (tip, root) = (b.tip, b.root);
        let (sn, cs) = ahead_deg.to_radians().sin_cos();
        let frame = [[cs, -sn, 0.0], [sn, cs, 0.0], [0.0, 0.0, 1.0]];
        let tip_ref = mtv(&frame, model.nodes[tip].x0);
        let twist_ref = rel_twist(&model.node_r0(root), &model.node_r0(tip));
        let loads =
            super::loads::LoadChannels::for_blade(bspec, model, &p.prefix, ahead_deg.to_radians())?;
        let scratch = Mutex::new(vec![0.0; p.probe.channel_names().len()]);
        parts.push(BladePart {
            prefix: p.prefix,
            spec: bspec.clone(),
            controls: p.controls,
            swash: p.swash,
            probe: p.probe,
            scratch,
            dev_names: p.dev_names,
            tip,
            root,
            frame,
            tip_ref,
            twist_ref,
            loads,
            damper_nodes: p.damper_nodes,
            damper_x_start: [[0.0; 3]; 2],
            limits: p.limits,
            regulation: p.regulation,
        });
    }
    Ok(parts)
}

/// Creates the generalized-alpha solver with the run's Newton settings and initial accelerations.
fn dynamic_solver(
    model: Model,
    st: State,
    h: f64,
    opts: &RunOptions,
    source: super::aero::AirloadSource,
) -> anyhow::Result<DynamicSolver> {
    let mut solver = DynamicSolver::new(model, st, h, opts.rho_inf)?;
    // ||r|| <= 1e-7 ||r_0||: r_0 is the predictor residual (inertia of the whole blade, ~1e6);
    // the hydraulic force is only piecewise smooth (valve seat contact), and its
    // finite-difference tangent stalls Newton near 1e-8 ||r_0|| at some valve events (measured).
    solver.newton.rtol = opts.newton_rtol;
    solver.newton.method = opts.newton;
    if source.aerodynamic() {
        // the lifting line's airloads depend on the velocities, which the iteration matrix
        // does not differentiate: Newton contracts more slowly (a quasi-Newton method)
        solver.newton.max_iterations = 50;
    }
    solver.init_accelerations()?;
    Ok(solver)
}

/// Assembles the run's aerodynamic bookkeeping (computed and hybrid airloads only).
fn aero_run(
    ctx: &BuildCtx,
    blades: &[(&RotorSpec, &DamperDeck, f64)],
    spec: &RotorSpec,
    aero_common: Option<AeroCommon>,
) -> anyhow::Result<Option<AeroRun>> {
    let (record, opts, source) = (ctx.record, ctx.opts, ctx.source);
    Ok(match aero_common {
        None => None,
        Some((air, shared, clamps)) => {
            let geometry = super::aero::blade_geometry(spec, ctx.file)?.0;
            let foils = &geometry.airfoils;
            Some(AeroRun {
                source,
                air,
                shared,
                clamps,
                scale: spec.rotor.blades as f64 / blades.len() as f64,
                solidity: spec.aero.as_ref().map_or(f64::NAN, |a| {
                    spec.rotor.blades as f64 * a.chord_m
                        / (std::f64::consts::PI * spec.rotor.radius_m)
                }),
                coupled: source == super::aero::AirloadSource::Computed,
                stations: record
                    .stations_r_over_r()
                    .iter()
                    .map(|r| (*r, r * spec.rotor.radius_m))
                    .collect(),
                measured: AirloadReplay::new(
                    record,
                    ReplayMode::Average,
                    ReplayOptions::default(),
                )?,
                ahead_deg: blades[0].2,
                history: if blades.len() == 1
                    && spec.rotor.blades > 1
                    && opts.steps_per_rev.is_multiple_of(spec.rotor.blades)
                {
                    let nan = crate::aero::inflow::DiskLoads {
                        ct: f64::NAN,
                        cs: f64::NAN,
                        cc: f64::NAN,
                    };
                    vec![nan; opts.steps_per_rev]
                } else {
                    vec![]
                },
                blades: spec.rotor.blades,
                airfoils: foils
                    .iter()
                    .map(|(r, a)| format!("{} to r = {r} m", a.name()))
                    .collect(),
                table_limits: crate::aero::airfoil::Airfoil::narrowest_limits(
                    foils.iter().map(|(_, a)| a),
                ),
                geometry: geometry.clone(),
                record_ct_over_sigma: record.meta.thrust_coefficient_over_solidity,
                record_synthetic: record.meta.synthetic,
            })
        }
    })
}

fn set_swash(model: &mut Model, id: usize, pts: &[(f64, f64)]) {
    if let Element::Joint(j) = &mut model.elements[id] {
        match &mut j.displacement_m {
            Some((_, tab)) => {
                tab.points.clear();
                tab.points.extend_from_slice(pts);
            }
            None => {
                j.displacement_m = Some((
                    [0.0, 0.0, 1.0],
                    TimeTable {
                        points: pts.to_vec(),
                    },
                ))
            }
        }
    }
}

/// Twist of the tip section relative to the root section about the root's axis 1 [rad].
fn rel_twist(r_root: &[[f64; 3]; 3], r_tip: &[[f64; 3]; 3]) -> f64 {
    log_map(&mtm(r_root, r_tip))[0]
}

impl RotorSim {
    /// Kicks the airframe: adds `velocity_m_s` along the hub's `axis` (0: x, 1: y) to that
    /// direction's node and everything it carries (the chain after it, the hub and the rotor),
    /// a uniform translation velocity that every joint above the direction's own link admits,
    /// then makes the accelerations consistent. Errors when the airframe does not move in that
    /// direction.
    pub fn kick_airframe(&mut self, axis: usize, velocity_m_s: f64) -> anyhow::Result<()> {
        let a = self
            .airframe
            .as_ref()
            .ok_or_else(|| anyhow::anyhow!("the rotor is not on an airframe"))?;
        let k = a
            .dofs
            .iter()
            .position(|d| !d.rotation && d.axis == axis)
            .ok_or_else(|| anyhow::anyhow!("the airframe does not move along hub axis {axis}"))?;
        let fixed: Vec<usize> = a.chain[..k].to_vec();
        let st = &mut self.solver.state;
        for i in 0..st.v.len() {
            if !fixed.contains(&i) {
                st.v[i][axis] += velocity_m_s;
            }
        }
        self.solver
            .init_accelerations()
            .map_err(|e| anyhow::anyhow!("after the airframe kick: {e}"))
    }

    /// The dynamic solver (model and state), e.g. for tests and diagnostics.
    pub fn solver(&self) -> &DynamicSolver {
        &self.solver
    }
    /// Steps accepted at `RTOL_STALL` after Newton stalled between `RTOL_STALL` and `RTOL`.
    pub fn relaxed_steps(&self) -> usize {
        self.relaxed_steps
    }
    /// Lag angle [rad] of blade 1, positive aft (the `lag` joint angle).
    pub fn lag_angle_rad(&self) -> f64 {
        let m = &self.solver.model;
        let name = format!("{}{}", self.parts[0].prefix, names::LAG);
        match m.element_id(&name).map(|i| &m.elements[i]) {
            Some(Element::Joint(j)) => j.angle_prev,
            _ => f64::NAN,
        }
    }
    /// Blades in the model (1 for a single blade).
    pub fn blade_count(&self) -> usize {
        self.parts.len()
    }
    /// Relief-valve limits of blade `k`'s damper (1 to N).
    pub fn blade_force_limits_n(&self, k: usize) -> Option<(f64, f64)> {
        self.parts.get(k.wrapping_sub(1)).and_then(|p| p.limits)
    }

    /// Channel prefix of part `k` (0-based): blade 1 has none, so that the run reads its
    /// channels as a blade's; the others are `b<K>.`.
    fn channel_prefix(&self, k: usize) -> &str {
        if k == 0 {
            ""
        } else {
            &self.parts[k].prefix
        }
    }

    fn part_channel_count(&self, p: &BladePart) -> usize {
        BASE_CHANNELS.len()
            + if self.physical { p.dev_names.len() } else { 0 }
            + p.loads.names().len()
    }

    /// One blade's channels into `out` (its share of `channels`).
    fn part_channels(&self, p: &BladePart, out: &mut [f64]) {
        if let Ok(mut buf) = p.scratch.lock() {
            // probe layout: force_N, stroke_m, stroke_rate_m_s, device channels
            p.probe.read_into(&mut buf);
            out[..3].copy_from_slice(&buf[..3]);
            if self.physical {
                let n = (buf.len() - 3).min(out.len().saturating_sub(6));
                out[6..6 + n].copy_from_slice(&buf[3..3 + n]);
            }
        }
        let st = &self.solver.state;
        let rh = mm(&quat_to_arr(&st.q[self.hub]), &p.frame);
        let tip = mtv(&rh, sub(st.x[p.tip], st.x[self.hub]));
        out[3] = tip[2] - p.tip_ref[2];
        out[4] = -(tip[1] - p.tip_ref[1]);
        let rr = quat_to_arr(&st.q[p.root]);
        let rt = quat_to_arr(&st.q[p.tip]);
        out[5] = rel_twist(&rr, &rt) - p.twist_ref;
        let nl = p.loads.names().len();
        let at = out.len() - nl;
        if !self.output_channels {
            out[at..].fill(f64::NAN);
            return;
        }
        let damper = super::loads::DamperStep {
            nodes: p.damper_nodes,
            x_start: p.damper_x_start,
            force_n: out[0],
        };
        if p.loads
            .values(&self.solver.model, st, &damper, &mut out[at..])
            .is_err()
        {
            // a wiring error of the load channels, checked when they were resolved
            out[at..].fill(f64::NAN);
        }
    }

    /// The airframe's channels: per direction displacement, acceleration, the rotor's load
    /// on it at the hub (the sum of every blade's loads on the hub, fixed frame) and its own
    /// side of the equation of motion.
    fn airframe_channels(&self, a: &AirframePart, out: &mut [f64]) {
        let st = &self.solver.state;
        let m = &self.solver.model;
        let mut hub_load = crate::loads::Resultant::default();
        let mut ok = self.output_channels;
        if ok {
            for p in &self.parts {
                match p.loads.on_hub(m, st) {
                    Ok(l) => hub_load = hub_load.add(&l),
                    Err(_) => ok = false,
                }
            }
        }
        for (k, d) in a.dofs.iter().enumerate() {
            // each direction's own link of the chain: everything after it moves with it
            let i = a.chain[k];
            let phi = log_map(&quat_to_arr(&st.q[i]));
            let (u, v, acc, load) = if d.rotation {
                // about the rotation's centre, which moves with the links before it
                let before = k.checked_sub(1).map_or([0.0; 3], |j| st.x[a.chain[j]]);
                let c = add(before, [0.0, 0.0, d.center_z_m]);
                let about_c = hub_load.moved(st.x[self.hub], c);
                (
                    phi[d.axis],
                    st.w[i][d.axis],
                    st.al[i][d.axis],
                    about_c.moment[d.axis],
                )
            } else {
                (
                    st.x[i][d.axis] - m.nodes[i].x0[d.axis],
                    st.v[i][d.axis],
                    st.a[i][d.axis],
                    hub_load.force[d.axis],
                )
            };
            // inertia: every node after this link that carries mass, each with its own
            // acceleration (a massless node's acceleration is not the dynamics' own)
            let inertia = if d.rotation {
                d.mass * acc
            } else {
                (k..a.dofs.len())
                    .map(|j| a.masses[j] * st.a[a.chain[j]][d.axis])
                    .sum()
            };
            let o = &mut out[4 * k..4 * k + 4];
            o[0] = u;
            // the mass-weighted acceleration of the direction (its nodes with mass)
            o[1] = if d.rotation { acc } else { inertia / d.mass };
            if ok {
                o[2] = load;
                o[3] = inertia + d.damping * v + d.stiffness * u;
            } else {
                o[2] = f64::NAN;
                o[3] = f64::NAN;
            }
        }
    }
}

impl RotorSim {
    /// After a converged step: the inflow driven by the rotor's airloads of that step.
    fn advance_inflow(&mut self) {
        let dpsi = self.omega * self.h;
        let k = (self.solver.state.t / self.h).round() as i64;
        let Some(a) = &mut self.aero else { return };
        if !a.coupled {
            return;
        }
        let Ok(mut sh) = a.shared.lock() else { return };
        let n = a.history.len();
        // the thrust's response to the inflow (every blade of the rotor sees it)
        let slope = sh.thrust_slope(&a.air, a.scale);
        let disk = if n == 0 {
            sh.rotor_airloads(&a.air, a.scale).disk
        } else {
            let own = sh.rotor_airloads(&a.air, 1.0).disk;
            let i = k.rem_euclid(n as i64) as usize;
            a.history[i] = own;
            // the other blades sit k T/N behind: their loads are this blade's then
            let step = n / a.blades;
            let mut sum = crate::aero::inflow::DiskLoads::default();
            for b in 0..a.blades {
                let h = a.history[(i + n - b * step) % n];
                // before a whole revolution is integrated: this blade's own loads
                let h = if h.ct.is_nan() { own } else { h };
                sum.ct += h.ct;
                sum.cs += h.cs;
                sum.cc += h.cc;
            }
            sum
        };
        sh.inflow.advance_coupled(dpsi, &disk, slope);
    }

    /// Where the airloads come from.
    pub fn airload_source(&self) -> super::aero::AirloadSource {
        self.aero
            .as_ref()
            .map_or(super::aero::AirloadSource::Measured, |a| a.source)
    }

    /// Aerofoil-table queries clamped to a table's edge so far, in words (empty: none).
    pub fn aero_clamps(&self) -> String {
        self.aero
            .as_ref()
            .map_or(String::new(), |a| a.clamps.summary_with(a.table_limits))
    }

    /// The rotor's channels, then per station of blade 1 (interpolated in radius between the
    /// lifting line's points, as the last converged evaluation left them).
    fn aero_channels(&self, a: &AeroRun, out: &mut [f64]) {
        let Ok(sh) = a.shared.lock() else {
            out.fill(f64::NAN);
            return;
        };
        let l = sh.rotor_airloads(&a.air, a.scale);
        out[0] = l.thrust_n;
        out[1] = l.power_w;
        out[2] = l.disk.ct / a.solidity;
        out[3] = sh.inflow.state()[0];
        let pts = &sh.points[0];
        let t = self.solver.state.t;
        let nr = AERO_ROTOR_CHANNELS.len();
        let ns = AERO_STATION_CHANNELS.len();
        for (j, (_, r_m)) in a.stations.iter().enumerate() {
            let o = &mut out[nr + ns * j..nr + ns * (j + 1)];
            // the bracketing points (increasing radius along the beam)
            let k = pts.partition_point(|p| p.r_m < *r_m);
            let (p0, p1) = match (k.checked_sub(1).and_then(|i| pts.get(i)), pts.get(k)) {
                (Some(p0), Some(p1)) => (p0, p1),
                (None, Some(p)) | (Some(p), None) => (p, p),
                (None, None) => {
                    o.fill(f64::NAN);
                    continue;
                }
            };
            let w = if p1.r_m > p0.r_m {
                ((r_m - p0.r_m) / (p1.r_m - p0.r_m)).clamp(0.0, 1.0)
            } else {
                0.0
            };
            // the lifting line at the station's own radius (not a blend of two points' loads)
            let sec = crate::aero::lifting_line::section_at(&a.geometry, &a.air, *r_m, p0, p1);
            o[0] = sec.alpha_rad.to_degrees();
            o[1] = sec.mach;
            o[2] = sec.coefficients.cl;
            o[3] = sec.coefficients.cd;
            o[4] = sec.coefficients.cm;
            o[5] = p0.lambda_i + w * (p1.lambda_i - p0.lambda_i);
            o[6] = sec.normal_n_per_m();
            let m = a.measured.section_loads_ahead(t, *r_m, a.ahead_deg);
            o[7] = o[6] - m.normal_N_per_m;
        }
    }
}

impl ForcedResponse for RotorSim {
    fn label(&self) -> &str {
        &self.label
    }
    fn period_s(&self) -> f64 {
        self.period
    }
    fn time_step_s(&self) -> f64 {
        self.h
    }
    fn time_s(&self) -> f64 {
        self.solver.state.t
    }
    fn step(&mut self) -> anyhow::Result<()> {
        let t0 = Instant::now();
        let tn = self.solver.state.t;
        let t1 = tn + self.h;
        for p in &mut self.parts {
            p.damper_x_start = p.damper_nodes.map(|i| self.solver.state.x[i]);
            let z0 = p.spec.swash_z(p.spec.pitch_rad(&p.controls, tn));
            let z1 = p.spec.swash_z(p.spec.pitch_rad(&p.controls, t1));
            set_swash(&mut self.solver.model, p.swash, &[(tn, z0), (t1, z1)]);
        }
        let mut r = self.solver.step();
        self.step_tol = self.solver.residual_tolerance();
        if let Err(NewtonError::Diverged {
            residual, initial, ..
        }) = &r
        {
            // Stalled, not diverged: the device force is only piecewise smooth (valve seat and
            // check-valve switching), Newton can cycle between the two sides of a switch just
            // above the tolerance. Redo the step (the solver kept the last converged state)
            // accepting ||r|| <= RTOL_STALL ||r_0||, and count it.
            if *residual <= RTOL_STALL * initial {
                self.solver.newton.rtol = RTOL_STALL;
                r = self.solver.step();
                self.step_tol = self.solver.residual_tolerance();
                self.solver.newton.rtol = self.rtol;
                self.relaxed_steps += 1;
            }
        }
        self.total_s += t0.elapsed().as_secs_f64();
        r.map_err(|e| {
            anyhow::anyhow!(
                "rotor model ({} damper), azimuth {:.2} deg: {e}",
                self.label,
                t1 / self.period * 360.0
            )
        })?;
        self.advance_inflow();
        Ok(())
    }
    fn channel_names(&self) -> Vec<String> {
        let mut v = Vec::new();
        for (k, p) in self.parts.iter().enumerate() {
            let pre = self.channel_prefix(k);
            v.extend(BASE_CHANNELS.iter().map(|s| format!("{pre}{s}")));
            if self.physical {
                v.extend(p.dev_names.iter().map(|s| format!("{pre}{s}")));
            }
            v.extend(p.loads.names().iter().map(|s| format!("{pre}{s}")));
        }
        if let Some(a) = &self.airframe {
            for d in &a.dofs {
                v.extend(airframe_channel_names(d));
            }
            v.push(AIRFRAME_STEP_TOLERANCE.to_string());
        }
        if let Some(a) = &self.aero {
            v.extend(AERO_ROTOR_CHANNELS.iter().map(|s| s.to_string()));
            for (r, _) in &a.stations {
                let l = station_label(*r);
                v.extend(AERO_STATION_CHANNELS.iter().map(|s| format!("{s}_{l}")));
            }
        }
        v
    }
    fn channels(&self, out: &mut [f64]) {
        let mut at = 0;
        for p in &self.parts {
            let n = self.part_channel_count(p).min(out.len() - at);
            self.part_channels(p, &mut out[at..at + n]);
            at += n;
        }
        if let Some(a) = &self.airframe {
            let n = 4 * a.dofs.len() + 1;
            if out.len() - at >= n {
                self.airframe_channels(a, &mut out[at..at + n - 1]);
                out[at + n - 1] = self.step_tol;
            }
            at += n;
        }
        if let Some(a) = &self.aero {
            let n = AERO_ROTOR_CHANNELS.len() + AERO_STATION_CHANNELS.len() * a.stations.len();
            if out.len() - at.min(out.len()) == n {
                self.aero_channels(a, &mut out[at..]);
            }
        }
    }
    fn force_limits_n(&self) -> Option<(f64, f64)> {
        self.parts[0].limits
    }
    fn blades(&self) -> Option<usize> {
        (!self.in_whole_rotor).then_some(self.parts[0].spec.rotor.blades)
    }
    fn set_output_channels(&mut self, on: bool) {
        self.output_channels = on;
    }
    fn output_channels(&self) -> bool {
        self.output_channels
    }
    fn relief_regulation(&self) -> Option<[super::ReliefRegulation; 2]> {
        self.parts[0].regulation
    }
    fn save_state(&self) -> Option<super::SimState> {
        let snap = self.solver.snapshot();
        let mut coords = snap.coords(&self.r0, 1.0 / self.omega);
        // the inflow's states (coupled inflow), in units of R
        if let Some(a) = self.aero.as_ref().filter(|a| a.coupled) {
            if let Ok(sh) = a.shared.lock() {
                coords.extend(sh.inflow.state().map(|l| l * a.air.radius_m));
            }
        }
        // the bearing elastomers' branch moments (as angles: over the chain's stiffness), so
        // that shooting converges their history with the motion
        for (e, scale) in elastomer_scales(&self.solver.model) {
            coords.extend(snap.joint_elastomers_nm[e].iter().map(|m| m / scale));
        }
        Some(super::SimState {
            t_s: snap.t_s,
            coords,
            solver: Some(snap),
            // the damper ends at the start of the step that ended here: the load channels of
            // the first sample after a restore need them
            aux: self
                .parts
                .iter()
                .flat_map(|p| p.damper_x_start.iter().flatten().copied())
                .chain(
                    self.aero
                        .iter()
                        .flat_map(|a| a.history.iter().flat_map(|d| [d.ct, d.cs, d.cc])),
                )
                .collect(),
        })
    }
    fn restore_state(&mut self, s: &super::SimState) -> anyhow::Result<()> {
        let Some(snap) = &s.solver else {
            anyhow::bail!(
                "the saved state has no structural state (not a state of the elastic rotor model)"
            );
        };
        let mut snap = snap.clone();
        let n = crate::solver::snapshot::COORDS_PER_NODE * snap.nodes();
        let inflow = self.aero.as_ref().filter(|a| a.coupled);
        let extra = if inflow.is_some() { 3 } else { 0 };
        let elastomers = elastomer_scales(&self.solver.model);
        let n_el = elastomers.len() * crate::structure::elastomer::BRANCHES;
        if s.coords.len() != n + extra + n_el {
            anyhow::bail!(
                "the saved state has {} coordinates, its structural state {n}, its inflow {extra} and its bearing elastomers {n_el}",
                s.coords.len()
            );
        }
        snap.set_coords(&self.r0, 1.0 / self.omega, &s.coords[..n]);
        if !elastomers.is_empty() {
            let ne = self.solver.model.elements.len();
            snap.joint_elastomers_nm.resize(ne, vec![]);
            let mut at = n + extra;
            for (e, scale) in elastomers {
                let b = crate::structure::elastomer::BRANCHES;
                snap.joint_elastomers_nm[e] =
                    s.coords[at..at + b].iter().map(|c| c * scale).collect();
                at += b;
            }
        }
        if let Some(a) = inflow {
            if let Ok(mut sh) = a.shared.lock() {
                let r = a.air.radius_m;
                sh.inflow
                    .set_state([s.coords[n] / r, s.coords[n + 1] / r, s.coords[n + 2] / r]);
            }
        }
        snap.t_s = s.t_s;
        self.solver
            .restore(&snap)
            .map_err(|e| anyhow::anyhow!("rotor model ({} damper): {e}", self.label))?;
        if let Some(a) = &mut self.aero {
            // the revolution of disk loads the state was saved with (else: none yet)
            let h = &s.aux[(6 * self.parts.len()).min(s.aux.len())..];
            let whole = h.len() == 3 * a.history.len();
            for (i, d) in a.history.iter_mut().enumerate() {
                let v = h.get(3 * i..3 * i + 3);
                (d.ct, d.cs, d.cc) = match v {
                    Some(v) if whole => (v[0], v[1], v[2]),
                    _ => (f64::NAN, f64::NAN, f64::NAN),
                };
            }
            // the lifting lines' records (output channels, inflow forcing) at the restored state
            self.solver.refresh_distributed_loads();
        }
        let np = self.parts.len();
        let travel = 2.0 * self.omega * self.h * self.parts[0].spec.rotor.radius_m;
        let back = exp_map([0.0, 0.0, -self.omega * self.h]);
        let state = &self.solver.state;
        for (k, p) in self.parts.iter_mut().enumerate() {
            let saved: Option<[[f64; 3]; 2]> = (s.aux.len() >= 6 * np).then(|| {
                std::array::from_fn(|e| std::array::from_fn(|c| s.aux[6 * k + 3 * e + c]))
            });
            // saved with this structural state: within a step's travel of the ends (a state
            // assembled from another model's keeps that model's own)
            let fits = |x: &[[f64; 3]; 2]| {
                (0..2).all(|e| norm3(sub(x[e], state.x[p.damper_nodes[e]])) <= travel)
            };
            p.damper_x_start = if let Some(x) = saved.filter(|x| fits(x)) {
                x
            } else {
                // a state saved without them: the damper ends turned back with the shaft (the
                // lag motion over a step is two orders smaller)
                p.damper_nodes.map(|i| mv(&back, state.x[i]))
            };
        }
        Ok(())
    }
    fn reference_pending(&self) -> bool {
        self.reference_adopted
            .as_ref()
            .is_some_and(|a| !a.load(Ordering::Relaxed))
    }
    fn adopt_reference(&mut self) {
        if let Some(a) = &self.reference_adopted {
            a.store(true, Ordering::Relaxed);
        }
    }
    fn airload_info(&self) -> Option<super::AirloadInfo> {
        let a = self.aero.as_ref()?;
        let inflow = a
            .shared
            .lock()
            .map(|sh| sh.inflow.model().name().to_string())
            .unwrap_or_default();
        Some(super::AirloadInfo {
            source: a.source.name().to_string(),
            reference: match (a.source.hybrid(), &self.reference_adopted) {
                (false, _) => String::new(),
                (true, None) => "the record's measured blade motion".into(),
                (true, Some(_)) => "the periodic solution under the measured airloads".into(),
            },
            inflow,
            airfoils: a.airfoils.clone(),
            clamped_queries: a.clamps.total(),
            table_queries: a.clamps.queries(),
            clamps: a.clamps.summary_with(a.table_limits),
            record_ct_over_sigma: a.record_ct_over_sigma,
            record_synthetic: a.record_synthetic,
        })
    }
    fn periodic_from_s(&self) -> f64 {
        self.t_ramp
    }
    /// Largest of the tip lag (-y), tip flap (z) and tip twist about x times R/10 of any
    /// blade, or an airframe direction's displacement (rotations times R); a coarse label.
    fn mode_label(&self, re: &[f64], im: &[f64]) -> String {
        use crate::solver::snapshot::COORDS_PER_NODE as K;
        if im.len() != re.len() {
            return String::new();
        }
        let radius = self.parts[0].spec.rotor.radius_m;
        let mag = |i: usize| {
            if i < re.len() {
                re[i].hypot(im[i])
            } else {
                0.0
            }
        };
        let mut parts: Vec<(String, f64)> = Vec::new();
        let np = self.parts.len();
        for (b, p) in self.parts.iter().enumerate() {
            let (t, r) = (K * p.tip, K * p.root);
            if re.len() < t + K || re.len() < r + K {
                continue;
            }
            let twist = (re[t + 3] - re[r + 3]).hypot(im[t + 3] - im[r + 3]);
            let who = if np > 1 {
                format!("blade {} ", b + 1)
            } else {
                String::new()
            };
            parts.push((format!("{who}lag"), mag(t + 1)));
            parts.push((format!("{who}flap"), mag(t + 2)));
            parts.push((format!("{who}torsion"), twist * radius / 10.0));
        }
        // the bearing elastomers' branch moments (the last coordinates, as angles): a real
        // mode made of them with little motion is a relaxation of the elastomer (multiplier
        // near `exp(-T / tau)` of a Maxwell branch), not a blade mode; an oscillatory mode is
        // the blade's, whatever the branches do in it
        let n_el = elastomers(&self.solver.model).count() * crate::structure::elastomer::BRANCHES;
        let real_mode = im.iter().all(|x| *x == 0.0);
        if real_mode && n_el > 0 && n_el <= re.len() {
            let el = (re.len() - n_el..re.len())
                .map(|i| mag(i).powi(2))
                .sum::<f64>()
                .sqrt();
            parts.push(("elastomer relaxation".to_string(), el * radius));
        }
        if let Some(a) = &self.airframe {
            let i = K * a.mount;
            for d in &a.dofs {
                let c = i + d.axis + if d.rotation { 3 } else { 0 };
                let w = if d.rotation { radius } else { 1.0 };
                parts.push((format!("airframe {}", d.name), mag(c) * w));
            }
        }
        parts
            .into_iter()
            .max_by(|a, b| a.1.total_cmp(&b.1))
            .map(|p| p.0)
            .unwrap_or_default()
    }
    fn relaxation_times_s(&self) -> Vec<f64> {
        elastomers(&self.solver.model)
            .flat_map(|(_, el)| el.chain.tau_s)
            .collect()
    }
    fn timing(&self) -> Timing {
        Timing {
            total_s: self.total_s,
            hydraulics_s: self
                .parts
                .iter()
                .map(|p| p.probe.hydraulics_seconds())
                .sum(),
            steps: self.solver.steps,
            iterations: self.solver.total_iterations,
            factorizations: self.solver.factorizations,
            relaxed_steps: self.relaxed_steps,
        }
    }
}

/// The model's joints with an elastomer: element index and the elastomer.
fn elastomers(m: &Model) -> impl Iterator<Item = (usize, &Elastomer)> {
    m.elements.iter().enumerate().filter_map(|(i, e)| match e {
        Element::Joint(j) => j.elastomer.as_ref().map(|el| (i, el)),
        _ => None,
    })
}

/// The model's joints with an elastomer: element index and the chain's stiffness scale
/// (`K_inf + sum k_i`, N m/rad) that turns its branch moments into angles.
fn elastomer_scales(m: &Model) -> Vec<(usize, f64)> {
    elastomers(m)
        .map(|(i, el)| (i, el.chain.k_inf + el.chain.k.iter().sum::<f64>()))
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn rot(axis: usize, a: f64) -> [[f64; 3]; 3] {
        let mut th = [0.0; 3];
        th[axis] = a;
        exp_map(th)
    }

    /// `R = Rz(psi) Rz(-zeta) Ry(-beta) Rx(theta)`: hub azimuth, lag aft, flap up, pitch.
    fn section(psi: f64, zeta: f64, beta: f64, theta: f64) -> [[f64; 3]; 3] {
        let r = mm(&rot(2, psi), &rot(2, -zeta));
        mm(&mm(&r, &rot(1, -beta)), &rot(0, theta))
    }

    #[test]
    fn section_pitch_recovers_the_pitch_under_azimuth_lag_and_flap() {
        for (psi, zeta, beta, theta) in [
            (0.0, 0.0, 0.0, 0.2),
            (1.3, 0.08, 0.05, 0.25),
            (4.0, -0.1, 0.2, -0.3),
            (5.5, 0.3, -0.15, 0.6),
        ] {
            let got = section_pitch(&section(psi, zeta, beta, theta));
            assert!((got - theta).abs() < 1e-14, "{got} vs {theta}");
        }
    }

    fn uh60a() -> (RotorSpec, Model, Controls) {
        let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("rotors/uh60a.toml");
        let spec = RotorSpec::from_file(&path).unwrap();
        let controls = Controls {
            th0_deg: 11.0,
            th1c_deg: 2.0,
            th1s_deg: -8.0,
        };
        let xo = ExpandOptions {
            controls,
            table_revs: 1,
            ..Default::default()
        };
        let model = expanded_model(&spec, &xo, &path).unwrap();
        (spec, model, controls)
    }

    /// Built-in twist of the deck (linear table, constant outside), degrees.
    fn table_twist(spec: &RotorSpec, r: f64) -> f64 {
        let t = &spec.blade.twist_deg;
        let tab = TimeTable {
            points: t.iter().map(|p| (p[0], p[1])).collect(),
        };
        tab.eval(r)
    }

    #[test]
    fn reference_pitch_is_the_built_in_twist() {
        let (spec, model, controls) = uh60a();
        let cp = ControlPitch::new(&spec, controls, &model, names::BLADE).unwrap();
        assert_eq!(cp.reference.len(), spec.blade.elements);
        let mut n = 0;
        for pts in cp.reference.values() {
            for &(s, theta) in pts {
                let r = spec.blade.root_r_m + s;
                // the model interpolates the nodal twist over each cubic element (0.566 m):
                // compare on the elements where the table is linear (1.95 - 5.91 m)
                if !(1.96..5.9).contains(&r) {
                    continue;
                }
                let want = table_twist(&spec, r).to_radians();
                assert!((theta - want).abs() < 1e-6, "r = {r}: {theta} vs {want}");
                n += 1;
            }
        }
        assert!(n > 20, "{n} load points checked");
    }

    /// With any elastic twist phi, the control-pitch frame applies the record's loads in the
    /// rigid-pitch directions: in the hub frame the in-plane (lead) component is
    /// `-(N sin(theta) + C cos(theta))` and the vertical `N cos(theta) - C sin(theta)`.
    #[test]
    fn control_pitch_frame_removes_the_elastic_twist_from_the_load_directions() {
        let (spec, model, controls) = uh60a();
        let cp = ControlPitch::new(&spec, controls, &model, names::BLADE).unwrap();
        let (&ei, pts) = cp.reference.iter().next().unwrap();
        let (s, theta_ref) = pts[1];
        let (nf, cf) = (3000.0, -250.0);
        for (t, phi) in [(0.0, 0.0), (0.01, -0.02), (0.1, 0.03), (0.2, -0.05)] {
            let theta_rigid = theta_ref + spec.pitch_rad(&controls, t);
            let psi = spec.rotor.omega_rad_s * t;
            let r = section(psi, 0.0, 0.0, theta_rigid + phi);
            let p = LoadPoint {
                t,
                element: ei,
                s_m: s,
                x: [0.0; 3],
                r,
                v: [0.0; 3],
                w: [0.0; 3],
            };
            let d = cp.correction(&p);
            assert!((d + phi).abs() < 1e-12, "correction {d} vs {}", -phi);
            // the load as BladeAirloads builds it, then into the hub frame
            let (sd, cd) = d.sin_cos();
            let f_sec = [0.0, -nf * sd - cf * cd, nf * cd - cf * sd];
            let f_hub = mtv(&rot(2, psi), mv(&r, f_sec));
            let (st, ct) = theta_rigid.sin_cos();
            assert!((f_hub[1] + nf * st + cf * ct).abs() < 1e-9, "{f_hub:?}");
            assert!((f_hub[2] - (nf * ct - cf * st)).abs() < 1e-9, "{f_hub:?}");
        }
    }
}
