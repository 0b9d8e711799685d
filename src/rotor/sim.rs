//! The forced-response simulation of the rotor: expanded model + damper element + airload
//! replay + swashplate law, marched by the generalized-alpha solver (see docs/rotor_model.md).
use super::deck::RotorSpec;
use super::expand::{expand, names, ramp, Controls, ExpandOptions};
use super::{ForcedResponse, RunOptions, Timing, BASE_CHANNELS};
use crate::flight::replay::{AirloadReplay, ReplayMode, ReplayOptions};
use crate::flight::FlightRecord;
use crate::hydraulics::{DamperDeck, DamperModel, Device};
use crate::solver::statics::{static_solve, StaticOptions};
use crate::solver::{DynamicSolver, State};
use crate::structure::beam::SectionLoad;
use crate::structure::deck::parse_deck;
use crate::structure::kin::TimeTable;
use crate::structure::model::{
    DistributedLoad, Element, ElementError, ElementOutput, LoadPoint, Model, StepElement,
};
use crate::structure::rotation::*;
use std::path::Path;
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::{Arc, Mutex};
use std::time::Instant;

/// Committed damper quantities shared between the element (inside the model) and the
/// simulation (channels).
#[derive(Debug, Default)]
pub struct DamperProbe {
    pub force_n: f64,
    pub stroke_m: f64,
    pub stroke_rate_m_s: f64,
    pub channels: Vec<f64>,
    pub hydraulics_s: f64,
}

/// Damper between two nodes (paper Eqs. 9-16 coupling): the stroke is the change of the
/// distance between the end points from `l0`; the device integrates over the structural step
/// with the stroke moving linearly from `d_i` to `d_f` and returns the step-mean force `F_m`
/// (Eq. 13), applied along the current line of the damper.
pub struct DamperElement {
    name: String,
    nodes: [usize; 2],
    l0: f64,
    device: Box<dyn Device>,
    probe: Arc<Mutex<DamperProbe>>,
    trial: Option<(f64, f64, f64)>,
    hyd_s: f64,
}

impl DamperElement {
    pub fn new(name: &str, nodes: [usize; 2], l0: f64, device: Box<dyn Device>) -> Self {
        let n = device.channel_names().len();
        DamperElement {
            name: name.into(),
            nodes,
            l0,
            device,
            probe: Arc::new(Mutex::new(DamperProbe {
                channels: vec![0.0; n],
                ..Default::default()
            })),
            trial: None,
            hyd_s: 0.0,
        }
    }
    pub fn probe(&self) -> Arc<Mutex<DamperProbe>> {
        self.probe.clone()
    }
}

fn len(d: [f64; 3]) -> f64 {
    dot(d, d).sqrt()
}

impl StepElement for DamperElement {
    fn name(&self) -> &str {
        &self.name
    }
    fn nodes(&self) -> [usize; 2] {
        self.nodes
    }
    fn evaluate(
        &mut self,
        t_i: f64,
        dt: f64,
        x_i: [[f64; 3]; 2],
        x_f: [[f64; 3]; 2],
        out: &mut ElementOutput,
    ) -> Result<(), ElementError> {
        let df = sub(x_f[1], x_f[0]);
        let l = len(df);
        let d_f = l - self.l0;
        if dt <= 0.0 {
            // static analyses: a damper carries no static force
            *out = ElementOutput::default();
            return Ok(());
        }
        let d_i = len(sub(x_i[1], x_i[0])) - self.l0;
        let t0 = Instant::now();
        let r = self.device.trial_step(t_i, dt, d_i, d_f);
        self.hyd_s += t0.elapsed().as_secs_f64();
        let sf = r.map_err(|e| ElementError {
            element: self.name.clone(),
            msg: e.to_string(),
        })?;
        let n = fmul(1.0 / l, df);
        let fm = sf.force_mean;
        let k = sf.dforce_dstroke;
        // force on node 1 (blade end) = F n, on node 0 = -F n
        let mut jac = [[0.0; 3]; 3];
        for i in 0..3 {
            for j in 0..3 {
                let dij = if i == j { 1.0 } else { 0.0 };
                jac[i][j] = k * n[i] * n[j] + fm * (dij - n[i] * n[j]) / l;
            }
        }
        out.force = [fmul(-fm, n), fmul(fm, n)];
        for i in 0..3 {
            for j in 0..3 {
                // d f1 / d x1 = jac, d f1 / d x0 = -jac, f0 = -f1
                out.jac[1][1][i][j] = jac[i][j];
                out.jac[1][0][i][j] = -jac[i][j];
                out.jac[0][1][i][j] = -jac[i][j];
                out.jac[0][0][i][j] = jac[i][j];
            }
        }
        self.trial = Some((sf.force_end, d_f, (d_f - d_i) / dt));
        Ok(())
    }
    fn commit(&mut self) {
        self.device.commit();
        if let Some((f, d, v)) = self.trial.take() {
            if let Ok(mut p) = self.probe.lock() {
                p.force_n = f;
                p.stroke_m = d;
                p.stroke_rate_m_s = v;
                p.hydraulics_s = self.hyd_s;
                let n = p.channels.len();
                self.device.channels(&mut p.channels[..n]);
            }
        }
    }
    fn sensors(&self) -> Vec<(String, f64)> {
        let p = self
            .probe
            .lock()
            .map(|p| (p.force_n, p.stroke_m, p.stroke_rate_m_s));
        let (f, d, v) = p.unwrap_or_default();
        vec![
            ("force_N".into(), f),
            ("stroke_m".into(), d),
            ("stroke_rate_m_s".into(), v),
        ]
    }
}

/// Airloads of the record on the blade: mean + ramp(t) (periodic part), follower section loads
/// (FORMATS: normal along +z, chord force along -y, moment about +x; the beam reference line
/// is taken as the quarter chord).
pub struct BladeAirloads {
    full: AirloadReplay,
    mean: AirloadReplay,
    root_r_m: f64,
    t_ramp: f64,
    /// Load scale (static load stepping of the initial equilibrium; 1 in the dynamics).
    scale: Arc<AtomicU64>,
}

impl DistributedLoad for BladeAirloads {
    fn eval(&mut self, p: &LoadPoint) -> SectionLoad {
        let r = self.root_r_m + p.s_m;
        let m = self.mean.section_loads(p.t, r);
        let w = ramp(p.t, self.t_ramp);
        let l = if w == 0.0 {
            m
        } else {
            let a = self.full.section_loads(p.t, r);
            crate::flight::replay::SectionLoads {
                normal_N_per_m: m.normal_N_per_m + w * (a.normal_N_per_m - m.normal_N_per_m),
                chord_N_per_m: m.chord_N_per_m + w * (a.chord_N_per_m - m.chord_N_per_m),
                moment_N_m_per_m: m.moment_N_m_per_m
                    + w * (a.moment_N_m_per_m - m.moment_N_m_per_m),
            }
        };
        let k = f64::from_bits(self.scale.load(Ordering::Relaxed));
        SectionLoad {
            force: [0.0, -k * l.chord_N_per_m, k * l.normal_N_per_m],
            moment: [k * l.moment_N_m_per_m, 0.0, 0.0],
            follower: true,
        }
    }
}

/// Parse the expanded deck of `spec` into a model (relative paths against `base`).
pub fn expanded_model(
    spec: &RotorSpec,
    opts: &ExpandOptions,
    file: &Path,
) -> anyhow::Result<Model> {
    let text = expand(spec, opts);
    let base = file.parent().map(Path::to_path_buf).unwrap_or_default();
    let name = format!("{} (expanded)", file.display());
    let (_, model) = parse_deck(&text, &name, &base)?;
    Ok(model)
}

fn joint_id(m: &Model, name: &str) -> anyhow::Result<usize> {
    m.element_id(name)
        .ok_or_else(|| anyhow::anyhow!("expanded rotor model has no joint `{name}`"))
}

/// The rotor forced-response simulation.
pub struct RotorSim {
    label: String,
    solver: DynamicSolver,
    spec: RotorSpec,
    controls: Controls,
    period: f64,
    h: f64,
    probe: Arc<Mutex<DamperProbe>>,
    dev_names: Vec<String>,
    physical: bool,
    limits: Option<(f64, f64)>,
    swash: usize,
    hub: usize,
    tip: usize,
    root: usize,
    tip_ref: [f64; 3],
    twist_ref: f64,
    total_s: f64,
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

/// Build the simulation (see [`super::build`]).
pub fn build_sim(
    spec: &RotorSpec,
    file: &Path,
    damper: &DamperDeck,
    model_kind: DamperModel,
    record: &FlightRecord,
    opts: &RunOptions,
) -> anyhow::Result<RotorSim> {
    if opts.steps_per_rev < 8 {
        anyhow::bail!("steps per revolution {} is below 8", opts.steps_per_rev);
    }
    let om = spec.rotor.omega_rad_s;
    let rec_om = record.meta.rotor_speed_rad_s;
    if (rec_om - om).abs() > 1e-3 * om {
        anyhow::bail!(
            "flight record rotor speed {rec_om} rad/s differs from the rotor deck's {om} rad/s ({})",
            file.display()
        );
    }
    let controls = Controls::from_record(&record.meta.controls_deg);
    let period = 2.0 * std::f64::consts::PI / om;
    let h = period / opts.steps_per_rev as f64;
    let xo = ExpandOptions {
        controls,
        table_revs: 1,
        ..Default::default()
    };
    let mut model = expanded_model(spec, &xo, file)?;
    let swash = joint_id(&model, names::SWASH_DRIVE)?;
    set_swash(
        &mut model,
        swash,
        &[(0.0, spec.swash_z(spec.pitch_rad(&controls, 0.0)))],
    );
    // damper
    let device = damper.build(model_kind, opts.hydraulics)?;
    let dev_names: Vec<String> = device
        .channel_names()
        .iter()
        .map(|s| s.to_string())
        .collect();
    let n_hub_end = model.node_id(names::DAMPER_HUB_END)?;
    let n_blade_end = model.node_id(names::DAMPER_BLADE_END)?;
    let elem = DamperElement::new(
        "damper",
        [n_hub_end, n_blade_end],
        spec.damper_attachment.reference_length_m,
        device,
    );
    let probe = elem.probe();
    model.add_step_element(Box::new(elem))?;
    // airloads
    let full = AirloadReplay::new(record, ReplayMode::Average, ReplayOptions::default())?;
    let mean = AirloadReplay::new(
        record,
        ReplayMode::Average,
        ReplayOptions {
            harmonics: Some(0),
            ..Default::default()
        },
    )?;
    let t_ramp = spec.pitch_control.cyclic_ramp_revs * period;
    let scale = Arc::new(AtomicU64::new(0f64.to_bits()));
    model.add_distributed_load(
        names::BLADE,
        Box::new(BladeAirloads {
            full,
            mean,
            root_r_m: spec.blade.root_r_m,
            t_ramp,
            scale: scale.clone(),
        }),
    )?;
    // initial state: rotating static equilibrium under the mean loads and the collective
    let mut st = State::from_model(&model);
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
        static_solve(&mut model, &mut st, &sopts, |a, b, c, d| {
            if std::env::var_os("ROTORSIM_DEBUG").is_some() {
                eprintln!("static step {k}: {a} {b} {c} {d:e}")
            }
        })
        .map_err(|e| {
            anyhow::anyhow!(
                "rotating equilibrium at t = 0 under {:.0}% of the mean airloads (initial state): {e}",
                100.0 * k as f64 / STEPS as f64
            )
        })?;
    }
    st.set_rigid_rotation([0.0; 3], [0.0, 0.0, om]);
    let hub = model.node_id(names::HUB)?;
    let tip = model.node_id(&format!("{}.n{}", names::BLADE, 3 * spec.blade.elements))?;
    let root = model.node_id(&format!("{}.n0", names::BLADE))?;
    let tip_ref = model.nodes[tip].x0;
    let twist_ref = rel_twist(&model.node_r0(root), &model.node_r0(tip));
    let mut solver = DynamicSolver::new(model, st, h, opts.rho_inf)?;
    solver.init_accelerations()?;
    let physical = model_kind == DamperModel::Physical;
    Ok(RotorSim {
        label: model_kind.name().to_string(),
        solver,
        spec: spec.clone(),
        controls,
        period,
        h,
        probe,
        dev_names,
        physical,
        limits: if physical {
            relief_limits(damper)
        } else {
            None
        },
        swash,
        hub,
        tip,
        root,
        tip_ref,
        twist_ref,
        total_s: 0.0,
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
    /// The dynamic solver (model and state), e.g. for tests and diagnostics.
    pub fn solver(&self) -> &DynamicSolver {
        &self.solver
    }
    /// Lag angle [rad], positive aft (the `lag` joint angle).
    pub fn lag_angle_rad(&self) -> f64 {
        let m = &self.solver.model;
        match m.element_id(names::LAG).map(|i| &m.elements[i]) {
            Some(Element::Joint(j)) => j.angle_prev,
            _ => f64::NAN,
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
        let z0 = self.spec.swash_z(self.spec.pitch_rad(&self.controls, tn));
        let z1 = self.spec.swash_z(self.spec.pitch_rad(&self.controls, t1));
        set_swash(&mut self.solver.model, self.swash, &[(tn, z0), (t1, z1)]);
        let r = self.solver.step();
        self.total_s += t0.elapsed().as_secs_f64();
        r.map_err(|e| {
            anyhow::anyhow!(
                "rotor model ({} damper), azimuth {:.2} deg: {e}",
                self.label,
                t1 / self.period * 360.0
            )
        })?;
        Ok(())
    }
    fn channel_names(&self) -> Vec<String> {
        let mut v: Vec<String> = BASE_CHANNELS.iter().map(|s| s.to_string()).collect();
        if self.physical {
            v.extend(self.dev_names.iter().cloned());
        }
        v
    }
    fn channels(&self, out: &mut [f64]) {
        if let Ok(p) = self.probe.lock() {
            out[0] = p.force_n;
            out[1] = p.stroke_m;
            out[2] = p.stroke_rate_m_s;
            if self.physical {
                let n = p.channels.len().min(out.len().saturating_sub(6));
                out[6..6 + n].copy_from_slice(&p.channels[..n]);
            }
        }
        let st = &self.solver.state;
        let rh = quat_to_arr(&st.q[self.hub]);
        let p = mtv(&rh, sub(st.x[self.tip], st.x[self.hub]));
        out[3] = p[2] - self.tip_ref[2];
        out[4] = -(p[1] - self.tip_ref[1]);
        let rr = quat_to_arr(&st.q[self.root]);
        let rt = quat_to_arr(&st.q[self.tip]);
        out[5] = rel_twist(&rr, &rt) - self.twist_ref;
    }
    fn force_limits_n(&self) -> Option<(f64, f64)> {
        self.limits
    }
    fn timing(&self) -> Timing {
        let hyd = self.probe.lock().map(|p| p.hydraulics_s).unwrap_or(0.0);
        Timing {
            total_s: self.total_s,
            hydraulics_s: hyd,
            steps: self.solver.steps,
            iterations: self.solver.total_iterations,
        }
    }
}
