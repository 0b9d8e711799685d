//! The rotor's aerodynamics in the forced response (docs/aerodynamics.md): where the airloads
//! come from (`--airloads measured|computed|hybrid`), the air and free stream of the record,
//! the blade's lifting line from the deck's `[aero]` table, and the hybrid load: the measured
//! airloads plus the lifting line's difference between the blade's motion and a reference
//! motion (the record's measured blade motion, or the periodic solution under the measured
//! airloads itself).
use super::deck::RotorSpec;
use crate::aero::airfoil::{Airfoil, ThinAirfoil};
use crate::aero::c81::C81Table;
use crate::aero::inflow::{DiskLoads, FlightCondition, InflowModel};
use crate::aero::lifting_line::{BladeAero, LiftingLine, RotorAir};
use crate::aero::section::Air;
use crate::flight::FlightRecord;
use crate::structure::beam::SectionLoad;
use crate::structure::kin::TimeTable;
use crate::structure::model::{DistributedLoad, Element, LoadPoint, Model};
use crate::structure::rotation::*;
use std::path::Path;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;

/// Where the blade's airloads come from.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum AirloadSource {
    /// The record's airloads replayed (no aerodynamic feedback).
    #[default]
    Measured,
    /// The lifting line and the inflow with the record's controls: a prediction.
    Computed,
    /// Measured airloads plus the lifting line's difference between the blade's motion and the
    /// record's measured motion (the periodic solution's where the record has none).
    Hybrid,
    /// Measured airloads plus the lifting line's difference between the blade's motion and the
    /// periodic solution under the measured airloads: the periodic answer is the measured
    /// one, the aerodynamics act on transients and the Floquet stability.
    #[serde(rename = "hybrid-periodic")]
    HybridPeriodic,
}

impl AirloadSource {
    pub fn name(self) -> &'static str {
        match self {
            AirloadSource::Measured => "measured",
            AirloadSource::Computed => "computed",
            AirloadSource::Hybrid => "hybrid",
            AirloadSource::HybridPeriodic => "hybrid-periodic",
        }
    }
    /// Whether the lifting line runs.
    pub fn aerodynamic(self) -> bool {
        self != AirloadSource::Measured
    }
    /// Whether the measured airloads are kept and the lifting line adds a difference.
    pub fn hybrid(self) -> bool {
        matches!(self, AirloadSource::Hybrid | AirloadSource::HybridPeriodic)
    }
}

impl std::str::FromStr for AirloadSource {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        match s {
            "measured" => Ok(AirloadSource::Measured),
            "computed" => Ok(AirloadSource::Computed),
            "hybrid" => Ok(AirloadSource::Hybrid),
            "hybrid-periodic" => Ok(AirloadSource::HybridPeriodic),
            _ => Err(format!(
                "unknown airload source `{s}` (expected measured, computed, hybrid or hybrid-periodic)"
            )),
        }
    }
}

/// The air of the record: density and speed of sound from its metadata, the free stream from
/// its advance ratio and shaft tilt (`shaft_tilt_deg`, negative forward: the free stream then
/// flows down through the disk), in the hub frame (x aft, where azimuth 0 points).
pub fn rotor_air(spec: &RotorSpec, record: &FlightRecord) -> anyhow::Result<RotorAir> {
    let meta = &record.meta;
    let need = |v: Option<f64>, key: &str| {
        v.filter(|x| x.is_finite() && *x > 0.0).ok_or_else(|| {
            anyhow::anyhow!(
                "the lifting line needs a positive `{key}` in the flight record's metadata"
            )
        })
    };
    let rho = need(meta.density_kg_m3, "density_kg_m3")?;
    let a = need(meta.speed_of_sound_m_s, "speed_of_sound_m_s")?;
    let mu = meta.advance_ratio.unwrap_or(0.0);
    let tilt = match meta.raw.get("shaft_tilt_deg") {
        None => 0.0,
        Some(v) => v.as_f64().ok_or_else(|| {
            anyhow::anyhow!("flight record metadata `shaft_tilt_deg`: expected a number, found {v}")
        })?,
    };
    let om = spec.rotor.omega_rad_s;
    let big_r = spec.rotor.radius_m;
    let v = mu * om * big_r;
    Ok(RotorAir {
        air: Air {
            density_kg_m3: rho,
            speed_of_sound_m_s: a,
        },
        omega_rad_s: om,
        radius_m: big_r,
        freestream_m_s: [v, 0.0, v * tilt.to_radians().tan()],
        center_m: [0.0; 3],
    })
}

/// The flight condition of the inflow models: advance ratio and the free stream's flow down
/// through the disk, over Omega R.
pub fn flight_condition(air: &RotorAir) -> FlightCondition {
    let vt = air.omega_rad_s * air.radius_m;
    FlightCondition {
        mu: air.freestream_m_s[0].hypot(air.freestream_m_s[1]) / vt,
        lambda_free: -air.freestream_m_s[2] / vt,
    }
}

/// The blade's aerodynamic geometry from the deck's `[aero]` (C81 files against the deck's
/// folder) and its inflow model.
pub fn blade_geometry(spec: &RotorSpec, file: &Path) -> anyhow::Result<(BladeAero, InflowModel)> {
    let Some(a) = &spec.aero else {
        anyhow::bail!(
            "rotor deck {}: the lifting line needs an [aero] table (chord_m, cutout_r_m; docs/rotor_deck.md, \"Aerodynamics\")",
            file.display()
        );
    };
    let dir = file.parent().unwrap_or(Path::new(""));
    let mut airfoils = Vec::with_capacity(a.airfoils.len().max(1));
    for seg in &a.airfoils {
        let foil = match &seg.c81 {
            None => Airfoil::Thin(ThinAirfoil::default()),
            Some(p) => Airfoil::Table(Arc::new(C81Table::from_file(&dir.join(p)).map_err(
                |e| anyhow::anyhow!("rotor deck {}, aero.airfoil: {e}", file.display()),
            )?)),
        };
        airfoils.push((seg.r_end_m, foil));
    }
    if airfoils.is_empty() {
        airfoils.push((spec.rotor.radius_m, Airfoil::Thin(ThinAirfoil::default())));
    }
    let model = a
        .inflow
        .parse::<InflowModel>()
        .map_err(|e| anyhow::anyhow!("rotor deck {}, aero.inflow: {e}", file.display()))?;
    Ok((
        BladeAero {
            root_r_m: spec.blade.root_r_m,
            chord_m: vec![(0.0, a.chord_m)],
            airfoils,
            cutout_r_m: a.cutout_r_m,
            tip_loss_factor: a.tip_loss_factor,
            twist_rad: TimeTable {
                points: spec
                    .blade
                    .twist_deg
                    .iter()
                    .map(|p| (p[0], p[1].to_radians()))
                    .collect(),
            },
        },
        model,
    ))
}

/// The record's airloads as disk loads (revolution average): thrust and its first moments,
/// `N` blades, normal force taken vertical (the inflow's forcing in the hybrid source).
pub fn record_disk_loads(record: &FlightRecord, air: &RotorAir, blades: usize) -> DiskLoads {
    let az = record.azimuths_deg();
    let st = record.stations_r_over_r();
    let revs = record.revolutions().len();
    let big_r = air.radius_m;
    let (mut t, mut cs, mut cc) = (0.0, 0.0, 0.0);
    // trapezoid over the stations, mean over azimuths and revolutions
    for i_rev in 0..revs {
        for (i_az, psi) in az.iter().enumerate() {
            let (s, c) = psi.to_radians().sin_cos();
            for w in 0..st.len().saturating_sub(1) {
                let (r0, r1) = (st[w], st[w + 1]);
                let f0 = record.normal_n_per_m()[record.index(i_rev, i_az, w)];
                let f1 = record.normal_n_per_m()[record.index(i_rev, i_az, w + 1)];
                let dr = (r1 - r0) * big_r;
                t += 0.5 * (f0 + f1) * dr;
                let m = 0.5 * (f0 * r0 + f1 * r1) * dr;
                cs += m * s;
                cc += m * c;
            }
        }
    }
    let k = blades as f64 / (revs * az.len()).max(1) as f64 / air.thrust_scale_n();
    DiskLoads {
        ct: k * t,
        cs: k * cs,
        cc: k * cc,
    }
}

/// The reference motion of the hybrid source: the record's measured rigid blade motion (flap,
/// lag, pitch about the hinge), periodic over the revolution.
pub struct ReferenceMotion {
    motion: crate::flight::PeriodicMotion,
    hinge_r_m: f64,
    omega: f64,
    /// The blade's azimuth ahead of blade 1 (where its motion is read) [rad].
    ahead_rad: f64,
    /// Azimuth of the model's blade at t = 0 [rad] (a whole rotor's blades are turned).
    model_turn_rad: f64,
    /// Per station of the lifting line: the load point's reference position and section frame.
    points: Vec<([f64; 3], [[f64; 3]; 3])>,
    /// The blade's rigid motion at the last time asked (every station of an evaluation shares
    /// it): time, shaft turn, lag-flap turn, pitch turn, relative angular velocity, pitch rate.
    at: Option<RigidAt>,
}

#[derive(Clone, Copy)]
struct RigidAt {
    t: f64,
    rz: [[f64; 3]; 3],
    lf: [[f64; 3]; 3],
    pitch: [[f64; 3]; 3],
    w_rel: [f64; 3],
    w_pitch: [f64; 3],
}

impl ReferenceMotion {
    /// The reference kinematics of station `i` at time t: the load point the blade would have
    /// moving as the record says (hub frame of the model's blade).
    fn rigid_at(&mut self, t: f64) -> RigidAt {
        if let Some(a) = self.at.filter(|a| a.t == t) {
            return a;
        }
        let psi = self.omega * t;
        let m = self.motion.at(psi + self.ahead_rad);
        let lag = exp_map([0.0, 0.0, -m.lag_rad]);
        let flap = exp_map([0.0, -m.flap_rad, 0.0]);
        let lf = mm(&lag, &flap);
        let a = RigidAt {
            t,
            rz: exp_map([0.0, 0.0, psi + self.model_turn_rad]),
            lf,
            pitch: exp_map([m.pitch_rad, 0.0, 0.0]),
            // angular velocity relative to the turning frame (rotating axes)
            w_rel: add(
                [0.0, 0.0, -m.lag_rate_rad_s],
                mv(&lag, [0.0, -m.flap_rate_rad_s, 0.0]),
            ),
            w_pitch: mv(&lf, [m.pitch_rate_rad_s, 0.0, 0.0]),
        };
        self.at = Some(a);
        a
    }

    fn point(&mut self, i: usize, p: &LoadPoint) -> LoadPoint {
        let (x0, r0) = self.points[i];
        let RigidAt {
            rz,
            lf,
            pitch,
            w_rel,
            w_pitch,
            ..
        } = self.rigid_at(p.t);
        let e = [self.hinge_r_m, 0.0, 0.0];
        let d = mv(&lf, sub(x0, e));
        let x_rot = add(e, d);
        let om = [0.0, 0.0, self.omega];
        let v_rot = add(cross(om, x_rot), cross(w_rel, d));
        LoadPoint {
            t: p.t,
            element: p.element,
            s_m: p.s_m,
            x: mv(&rz, x_rot),
            r: mm(&rz, &mm(&lf, &mm(&pitch, &r0))),
            v: mv(&rz, v_rot),
            w: mv(&rz, add(om, add(w_rel, w_pitch))),
        }
    }
}

/// The lifting line's airloads along the periodic solution under the measured airloads, per
/// station and step of the revolution: recorded while the run finds that solution (each step's
/// last evaluation is at its converged state), then adopted as the hybrid's reference.
pub struct PeriodicReference {
    /// Per station, per step of the revolution: force per span (section frame of the load
    /// applied) [N/m] and pitching moment per span [N m/m].
    table: Vec<Vec<([f64; 3], f64)>>,
    h_s: f64,
    /// Recording (false) or adopted (true); the run flips it between the two solutions.
    pub adopted: Arc<AtomicBool>,
}

impl PeriodicReference {
    pub fn new(stations: usize, steps_per_rev: usize, h_s: f64, adopted: Arc<AtomicBool>) -> Self {
        PeriodicReference {
            // NaN until recorded: a step never recorded fails the run visibly, not silently
            table: vec![vec![([f64::NAN; 3], f64::NAN); steps_per_rev]; stations],
            h_s,
            adopted,
        }
    }

    /// Time t as a step of the revolution and the fraction to the next one.
    fn slot(&self, t: f64) -> (usize, f64) {
        let n = self.table.first().map_or(1, Vec::len).max(1);
        let x = t / self.h_s;
        let k = x.floor();
        let f = x - k;
        ((k as i64).rem_euclid(n as i64) as usize, f)
    }

    fn record(&mut self, i: usize, t: f64, a: &SectionLoad) {
        let (k, f) = self.slot(t);
        // only at the steps' own times (the loads of a step are evaluated at its end)
        let k = match f {
            f if f < 1e-6 => k,
            f if f > 1.0 - 1e-6 => (k + 1) % self.table[i].len(),
            _ => return,
        };
        if let Some(row) = self.table.get_mut(i) {
            row[k] = (a.force, a.moment[0]);
        }
    }

    /// The reference at time t (linear between steps: the steps' own times are exact).
    fn at(&self, i: usize, t: f64) -> ([f64; 3], f64) {
        let Some(row) = self.table.get(i) else {
            return ([0.0; 3], 0.0);
        };
        let (k, f) = self.slot(t);
        let (a, b) = (row[k], row[(k + 1) % row.len()]);
        (
            std::array::from_fn(|j| a.0[j] + f * (b.0[j] - a.0[j])),
            a.1 + f * (b.1 - a.1),
        )
    }
}

/// The hybrid's reference motion.
pub enum Reference {
    /// The record's measured rigid blade motion.
    Record(Box<ReferenceMotion>),
    /// The periodic solution under the measured airloads.
    Periodic(PeriodicReference),
}

/// The hybrid blade load: the measured airloads plus `ramp(t)` times the lifting line's
/// airloads at the blade's motion minus those at the reference motion (both with the same
/// inflow), in the section frame. With the deck's control-pitch airload frame the blade's
/// sections meet the air at the rigid pitch, as the measured airloads are applied: the
/// reference motion carries no elastic twist, so the difference is the flap and lag motion's.
pub struct HybridLoad {
    /// The measured airloads; their frame (deformed or control-pitch) is the lifting line's.
    pub measured: super::sim::BladeAirloads,
    pub line: LiftingLine,
    pub reference: Reference,
    /// Per station: the reference airloads at the time they were last computed (they depend
    /// on time only, the hybrid inflow being fixed: once per step, not per iteration).
    pub reference_cache: Vec<(f64, crate::aero::section::SectionAirloads)>,
    /// End of the cyclic ramp [s] (the difference ramps in with the measured harmonics).
    pub t_ramp: f64,
    pub active: Arc<AtomicBool>,
}

impl DistributedLoad for HybridLoad {
    fn eval(&mut self, p: &LoadPoint) -> SectionLoad {
        let (mut l, d) = self.measured.eval_with_turn(p);
        if !self.active.load(Ordering::Relaxed) {
            return l;
        }
        let Some(i) = self.line.station(p) else {
            return l;
        };
        let a = match d {
            0.0 => self.line.evaluate(p),
            d => {
                let (sd, cd) = d.sin_cos();
                let turn = [[1.0, 0.0, 0.0], [0.0, cd, -sd], [0.0, sd, cd]];
                let pc = LoadPoint {
                    r: mm(&p.r, &turn),
                    ..*p
                };
                let mut a = self.line.evaluate(&pc);
                a.force = mv(&turn, a.force);
                a
            }
        };
        let (rf, rm) = match &mut self.reference {
            Reference::Periodic(r) => {
                if !r.adopted.load(Ordering::Relaxed) {
                    r.record(i, p.t, &a);
                    return l;
                }
                r.at(i, p.t)
            }
            Reference::Record(reference) => match self.reference_cache.get(i) {
                Some((t, r)) if *t == p.t => (r.force_n_per_m, r.moment_n_m_per_m),
                _ => {
                    let q = reference.point(i, p);
                    let r = self.line.reference_airloads(i, &q);
                    if let Some(c) = self.reference_cache.get_mut(i) {
                        *c = (p.t, r);
                    }
                    (r.force_n_per_m, r.moment_n_m_per_m)
                }
            },
        };
        let w = super::expand::ramp(p.t, self.t_ramp);
        for ((f, a), r) in l.force.iter_mut().zip(a.force).zip(rf) {
            *f += w * (a - r);
        }
        l.moment[0] += w * (a.moment[0] - rm);
        l
    }
}

/// The computed blade load: the lifting line alone once the dynamics run; the initial
/// equilibrium is found under `statics` (the record's mean airloads, when it has them: a
/// nearby start for the lag and flap under the rotor's drag and thrust).
/// The lifting line takes over from them over the cyclic ramp (a gentle start: the blade's lag
/// settles under the rotor's own drag without a step in its load).
pub struct ComputedLoad<S: DistributedLoad> {
    pub statics: S,
    pub line: LiftingLine,
    pub active: Arc<AtomicBool>,
    /// End of the hand-over [s].
    pub t_ramp: f64,
}

impl<S: DistributedLoad> DistributedLoad for ComputedLoad<S> {
    fn eval(&mut self, p: &LoadPoint) -> SectionLoad {
        if !self.active.load(Ordering::Relaxed) {
            return self.statics.eval(p);
        }
        let a = self.line.evaluate(p);
        let w = super::expand::ramp(p.t, self.t_ramp);
        if w >= 1.0 {
            return a;
        }
        // both follower loads in the section frame
        let s = self.statics.eval(p);
        SectionLoad {
            force: std::array::from_fn(|k| w * a.force[k] + (1.0 - w) * s.force[k]),
            moment: std::array::from_fn(|k| w * a.moment[k] + (1.0 - w) * s.moment[k]),
            follower: true,
        }
    }
}

/// The reference motion for the lifting line `line` on beam `beam` of `model`.
pub fn reference_motion(
    record: &FlightRecord,
    spec: &RotorSpec,
    model: &Model,
    beam: &str,
    line: &LiftingLine,
    ahead_rad: f64,
    model_turn_rad: f64,
) -> anyhow::Result<ReferenceMotion> {
    let Some(motion) = &record.motion else {
        anyhow::bail!(
            "--airloads hybrid needs the record's measured blade motion (STEM.motion.csv, docs/formats.md); this record has none"
        );
    };
    let om = spec.rotor.omega_rad_s;
    let n_az = record.azimuths_deg().len();
    let motion = motion
        .periodic((n_az / 2).saturating_sub(1).min(10), om)
        .map_err(|e| anyhow::anyhow!("the record's blade motion: {e}"))?;
    let kin = model.reference_state();
    let ids = model
        .beams
        .get(beam)
        .ok_or_else(|| anyhow::anyhow!("expanded rotor model has no beam `{beam}`"))?;
    let mut points = vec![([0.0; 3], [[0.0; 3]; 3]); line.stations()];
    for &ei in ids {
        if let Element::Beam(b) = &model.elements[ei] {
            let pts = b.load_points(&b.nodes.map(|i| kin[i]));
            for (g, pt) in b.gm.iter().zip(&pts) {
                let probe = LoadPoint {
                    t: 0.0,
                    element: ei,
                    s_m: g.s_m,
                    x: pt.0,
                    r: pt.1,
                    v: [0.0; 3],
                    w: [0.0; 3],
                };
                if let Some(i) = line.station(&probe) {
                    // along the hub's x axis (a whole rotor's blade is turned in the model)
                    let back = exp_map([0.0, 0.0, -model_turn_rad]);
                    points[i] = (mv(&back, pt.0), mm(&back, &pt.1));
                }
            }
        }
    }
    Ok(ReferenceMotion {
        motion,
        hinge_r_m: spec.retention.hinge_r_m,
        omega: om,
        ahead_rad,
        model_turn_rad,
        points,
        at: None,
    })
}
