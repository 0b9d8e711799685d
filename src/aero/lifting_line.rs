//! Blade-element lifting line on a beam: at every load point of the blade's beam the section's
//! velocity relative to the air (the blade's own motion, elastic twist and flap and lag rates
//! included, and the hub's, against the free stream and the induced inflow) gives the angle
//! of attack, the Mach number and the airloads of [`super::section::blade_element`]
//! (docs/aerodynamics.md).
//!
//! The rotor's blades share one [`AeroShared`]: the inflow state, read by every evaluation,
//! and the record of the last evaluation at every load point, which at the end of a converged
//! step holds the converged airloads (the rotor simulation integrates them into the disk loads
//! that drive the inflow, and into the output channels).
use super::airfoil::{Airfoil, ClampCounts};
use super::inflow::{DiskLoads, Inflow};
use super::section::{blade_element, Air, SectionAirloads};
use crate::structure::beam::{gauss, SectionLoad, NPTS_M};
use crate::structure::kin::TimeTable;
use crate::structure::model::{DistributedLoad, Element, LoadPoint, Model};
use crate::structure::rotation::*;
use std::sync::{Arc, Mutex};

/// The rotor's air: density, speed of sound, free stream and the geometry the inflow is
/// expressed in.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RotorAir {
    pub air: Air,
    /// Rotor speed [rad/s] and radius [m] (the inflow's velocity scale Omega R).
    pub omega_rad_s: f64,
    pub radius_m: f64,
    /// Velocity of the undisturbed air relative to the ground frame [m/s] (the hub's motion is
    /// in the section velocities).
    pub freestream_m_s: [f64; 3],
    /// Centre of the disk [m] (the shaft on z): radius and azimuth of a point for the inflow.
    pub center_m: [f64; 3],
}

impl RotorAir {
    /// Air velocity at `x` [m/s]: free stream plus the induced inflow (down along -z); and
    /// the inflow ratio there.
    pub fn air_velocity(&self, inflow: &Inflow, x: [f64; 3]) -> ([f64; 3], f64) {
        let d = sub(x, self.center_m);
        let li = inflow.lambda_i_at(d[0] / self.radius_m, d[1] / self.radius_m);
        let w = li * self.omega_rad_s * self.radius_m;
        (
            [
                self.freestream_m_s[0],
                self.freestream_m_s[1],
                self.freestream_m_s[2] - w,
            ],
            li,
        )
    }
    /// Normalisation of the disk loads: `rho pi R^2 (Omega R)^2` [N].
    pub fn thrust_scale_n(&self) -> f64 {
        let vt = self.omega_rad_s * self.radius_m;
        self.air.density_kg_m3 * std::f64::consts::PI * self.radius_m.powi(2) * vt * vt
    }
}

/// One blade's aerodynamic geometry along its beam.
#[derive(Clone, Debug)]
pub struct BladeAero {
    /// Radius of the beam's first point (`r = root_r_m + s_m`) [m].
    pub root_r_m: f64,
    /// Chord at radius r [m]: `(r_m, chord_m)` points, linear between, constant outside.
    pub chord_m: Vec<(f64, f64)>,
    /// Aerofoils by radial segment: `(r_end_m, aerofoil)`, increasing; the last covers the tip.
    pub airfoils: Vec<(f64, Airfoil)>,
    /// Aerodynamic root cut-out [m]: no airloads inboard of it.
    pub cutout_r_m: f64,
    /// Tip-loss factor B: no lift outboard of B R (1: none).
    pub tip_loss_factor: f64,
    /// Built-in twist the blade's beam was built with, `(r_m, rad)` points, linear between and
    /// constant outside (no points: the beam's section frames as they are). The beam carries the
    /// table through its nodes (cubic interpolation over each element); the lifting line turns
    /// each load point's section to the element's cubic projection of the table instead
    /// ([`twist_offsets`]).
    pub twist_rad: TimeTable,
}

/// Legendre polynomials P0..P3 at xi.
fn legendre(xi: f64) -> [f64; 4] {
    [
        1.0,
        xi,
        0.5 * (3.0 * xi * xi - 1.0),
        0.5 * (5.0 * xi * xi - 3.0) * xi,
    ]
}

/// The piecewise-linear twist table `t` over the element from `ra` to `rb` [m] projected onto
/// cubics (least squares over the element): its Legendre coefficients in xi in [-1, 1]. Exact:
/// the integrals are split at the table's points, 3-point Gauss on each piece.
fn cubic_projection(t: &TimeTable, ra: f64, rb: f64) -> [f64; 4] {
    let xi_of = |r: f64| 2.0 * (r - ra) / (rb - ra) - 1.0;
    let mut cuts = vec![-1.0];
    cuts.extend(
        t.points
            .iter()
            .map(|p| xi_of(p.0))
            .filter(|x| *x > -1.0 && *x < 1.0),
    );
    cuts.push(1.0);
    let (g, gw) = gauss(3);
    let mut c = [0.0; 4];
    for w in cuts.windows(2) {
        let (m, h) = (0.5 * (w[0] + w[1]), 0.5 * (w[1] - w[0]));
        for (x, wq) in g.iter().zip(&gw) {
            let xi = m + h * x;
            let y = t.eval(ra + 0.5 * (xi + 1.0) * (rb - ra));
            for (k, pk) in legendre(xi).iter().enumerate() {
                c[k] += wq * h * y * pk;
            }
        }
    }
    std::array::from_fn(|k| c[k] * (2 * k + 1) as f64 / 2.0)
}

/// Per load point of a cubic beam element from `ra` to `rb` [m] (nodes at its thirds, shape
/// functions `n` at the points, the points at `xi` in [-1, 1]): the turn about the section
/// axis from the beam's built-in twist there (the table through the nodes, interpolated) to
/// the element's cubic projection of the table [rad]. With it the element's quadrature
/// integrates the twist's part of the airloads times any cubic in r (thrust, flap moment,
/// torque) exactly, also where the table has a kink or a step inside the element; where the
/// table is linear over the element both are the table and the turn is zero.
fn twist_offsets(t: &TimeTable, ra: f64, rb: f64, pts: &[(f64, [f64; 4])]) -> Vec<f64> {
    if t.points.is_empty() {
        return vec![0.0; pts.len()];
    }
    let c = cubic_projection(t, ra, rb);
    let nodal: [f64; 4] = std::array::from_fn(|i| t.eval(ra + (rb - ra) * i as f64 / 3.0));
    pts.iter()
        .map(|(xi, n)| {
            let projected: f64 = legendre(*xi).iter().zip(c).map(|(p, ck)| p * ck).sum();
            let beam: f64 = n.iter().zip(nodal).map(|(ni, ti)| ni * ti).sum();
            projected - beam
        })
        .collect()
}

/// The share of a load point's strip (`width` from `start` [m]) that lifts, inboard of the
/// tip-loss radius `tip_r`: the lifting span then ends at B R exactly, wherever the points
/// fall (a point at radius `r` with no strip: 1 inboard, 0 outboard).
fn lift_inside(start: f64, width: f64, r: f64, tip_r: f64) -> f64 {
    if width > 0.0 {
        ((tip_r - start) / width).clamp(0.0, 1.0)
    } else if r <= tip_r {
        1.0
    } else {
        0.0
    }
}

/// The section airloads at radius `r_m` between two load points `p0` and `p1` (inboard
/// first) of the last evaluation: the air's in-plane velocity interpolated linearly between
/// them, then the blade element at `r_m` itself (its chord, its aerofoil, lift only inboard of
/// the tip-loss radius). This is what an output station reports: the lifting line at the
/// station's radius, not a blend of two points' loads (which, across the tip-loss radius,
/// would blend a lifting point with one that does not lift). Table lookups here are not
/// counted as the run's.
pub fn section_at(
    geometry: &BladeAero,
    rotor: &RotorAir,
    r_m: f64,
    p0: &PointRecord,
    p1: &PointRecord,
) -> SectionAirloads {
    let w = if p1.r_m > p0.r_m {
        ((r_m - p0.r_m) / (p1.r_m - p0.r_m)).clamp(0.0, 1.0)
    } else {
        0.0
    };
    // the in-plane velocity (toward the trailing edge, up) each point's section saw
    let rho = rotor.air.density_kg_m3;
    let vel = |p: &PointRecord| {
        let speed = (2.0 * p.section.q_pa / rho).max(0.0).sqrt();
        let (s, c) = p.section.alpha_rad.sin_cos();
        [speed * c, speed * s]
    };
    let (v0, v1) = (vel(p0), vel(p1));
    let ut = v0[0] + w * (v1[0] - v0[0]);
    let up = v0[1] + w * (v1[1] - v0[1]);
    if r_m < geometry.cutout_r_m {
        return SectionAirloads::default();
    }
    let lift = if r_m <= geometry.tip_r_m(rotor.radius_m) {
        1.0
    } else {
        0.0
    };
    blade_element(
        [0.0, -ut, up],
        geometry.chord_at(r_m),
        &rotor.air,
        &geometry.airfoils[geometry.airfoil_at(r_m)].1,
        &ClampCounts::default(),
        lift,
    )
}

impl BladeAero {
    /// The tip-loss radius B R [m] of a rotor of radius `radius_m`.
    pub fn tip_r_m(&self, radius_m: f64) -> f64 {
        self.tip_loss_factor * radius_m
    }
    fn chord_at(&self, r: f64) -> f64 {
        let c = &self.chord_m;
        if c.is_empty() {
            return 0.0;
        }
        if r <= c[0].0 {
            return c[0].1;
        }
        for w in c.windows(2) {
            if r <= w[1].0 {
                let t = (r - w[0].0) / (w[1].0 - w[0].0);
                return w[0].1 + t * (w[1].1 - w[0].1);
            }
        }
        c[c.len() - 1].1
    }
    fn airfoil_at(&self, r: f64) -> usize {
        self.airfoils
            .iter()
            .position(|(r_end, _)| r <= *r_end)
            .unwrap_or(self.airfoils.len().saturating_sub(1))
    }
}

/// What the last evaluation at a load point gave.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct PointRecord {
    pub t_s: f64,
    /// Radius [m] and quadrature weight [m] of the point.
    pub r_m: f64,
    pub weight_m: f64,
    /// Disk position of the deformed point over R: x = r cos(psi), y = r sin(psi).
    pub disk_x: f64,
    pub disk_y: f64,
    /// Induced inflow ratio there (positive down).
    pub lambda_i: f64,
    pub section: SectionAirloads,
    /// Force per span in the hub frame of the air [N/m] and the arm from the disk centre [m].
    pub force_n_per_m: [f64; 3],
    pub arm_m: [f64; 3],
    /// Derivative of the force per span along the shaft (+z) with respect to the inflow
    /// ratio there [N/m] (the blade's kinematics held): the lifting line's part of the inflow's
    /// feedback, for solving the inflow with the loads.
    pub dfz_dlambda_n_per_m: f64,
}

/// State shared by the blades of a rotor: the inflow and every load point's last airloads.
pub struct AeroShared {
    pub inflow: Inflow,
    /// Per blade of the model, per load point (element order, then quadrature order).
    pub points: Vec<Vec<PointRecord>>,
}

/// Integrated airloads of the modelled blades.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct RotorAirloads {
    /// Thrust along +z [N], aerodynamic torque against the rotation [N m] and the power it
    /// takes [W].
    pub thrust_n: f64,
    pub torque_nm: f64,
    pub power_w: f64,
    /// The disk loads as coefficients (the inflow's forcing).
    pub disk: DiskLoads,
}

impl AeroShared {
    /// The rotor's airloads: the sum over the modelled blades times `scale` (blades of the
    /// rotor per blade modelled).
    pub fn rotor_airloads(&self, air: &RotorAir, scale: f64) -> RotorAirloads {
        let (mut t, mut q, mut cs, mut cc) = (0.0, 0.0, 0.0, 0.0);
        for p in self.points.iter().flatten() {
            let f = fmul(p.weight_m, p.force_n_per_m);
            t += f[2];
            q -= cross(p.arm_m, f)[2];
            cs += f[2] * p.disk_y;
            cc += f[2] * p.disk_x;
        }
        let n = air.thrust_scale_n();
        RotorAirloads {
            thrust_n: scale * t,
            torque_nm: scale * q,
            power_w: scale * q * air.omega_rad_s,
            disk: DiskLoads {
                ct: scale * t / n,
                cs: scale * cs / n,
                cc: scale * cc / n,
            },
        }
    }

    /// Derivative of the rotor's thrust coefficient with respect to the mean inflow l0, the
    /// blades' kinematics held: the sum over the modelled blades times `scale` (blades of the
    /// rotor per blade modelled). Drees' shape scales with l0 (`lambda_i / l0` at every point);
    /// uniform and Pitt-Peters (whose first-harmonic states are separate) move uniformly.
    /// Negative: more inflow, less lift.
    pub fn thrust_slope(&self, air: &RotorAir, scale: f64) -> f64 {
        let l0 = self.inflow.state()[0];
        let scaled = self.inflow.model() == super::inflow::InflowModel::Drees && l0 != 0.0;
        let mut d = 0.0;
        for p in self.points.iter().flatten() {
            let shape = if scaled { p.lambda_i / l0 } else { 1.0 };
            d += p.weight_m * p.dfz_dlambda_n_per_m * shape;
        }
        scale * d / air.thrust_scale_n()
    }
}

/// A pitch added to the sections' aerodynamic pitch, as a function of time [rad] (a blade
/// model without a pitch degree of freedom, e.g. a verification blade on a flap hinge).
pub type PitchLaw = Arc<dyn Fn(f64) -> f64 + Send + Sync>;

/// Per load point of the beam: radius, chord, aerofoil, lift factor and quadrature weight.
#[derive(Clone, Copy, Debug)]
struct Station {
    s_m: f64,
    r_m: f64,
    chord_m: f64,
    airfoil: usize,
    lift_factor: f64,
    weight_m: f64,
    /// Turn about the section axis from the beam's built-in twist to the lifting line's [rad].
    pitch_offset_rad: f64,
    /// Outside the aerofoil (inboard of the cut-out): no airloads.
    active: bool,
}

/// The lifting line of one blade (a [`DistributedLoad`] on its beam).
pub struct LiftingLine {
    blade: usize,
    rotor: RotorAir,
    airfoils: Vec<Airfoil>,
    clamps: Arc<ClampCounts>,
    shared: Arc<Mutex<AeroShared>>,
    /// Per element id: index of its first station (usize::MAX: not ours).
    first: Vec<usize>,
    stations: Vec<Station>,
    pitch_law: Option<PitchLaw>,
    /// From the model's frame to the hub frame of the air (a single-blade model of a blade
    /// that sits ahead of the model's blade).
    turn: Option<[[f64; 3]; 3]>,
}

impl LiftingLine {
    /// The lifting line on beam `beam` of `model`, blade `blade` of `shared` (its point records
    /// are sized here).
    pub fn new(
        model: &Model,
        beam: &str,
        geometry: &BladeAero,
        rotor: RotorAir,
        clamps: Arc<ClampCounts>,
        shared: Arc<Mutex<AeroShared>>,
        blade: usize,
    ) -> anyhow::Result<Self> {
        let ids = model
            .beams
            .get(beam)
            .ok_or_else(|| anyhow::anyhow!("lifting line: model has no beam `{beam}`"))?;
        if geometry.airfoils.is_empty() {
            anyhow::bail!("lifting line: no aerofoil");
        }
        let n_el = ids.iter().map(|i| i + 1).max().unwrap_or(0);
        let mut first = vec![usize::MAX; n_el];
        let mut stations = Vec::with_capacity(ids.len() * NPTS_M);
        let tip_r = geometry.tip_r_m(rotor.radius_m);
        for &id in ids {
            if let Element::Beam(b) = &model.elements[id] {
                first[id] = stations.len();
                let (ra, rb) = (
                    geometry.root_r_m + b.s_range[0],
                    geometry.root_r_m + b.s_range[1],
                );
                let pts: Vec<(f64, [f64; 4])> =
                    b.gm.iter()
                        .map(|g| {
                            (
                                2.0 * (g.s_m - b.s_range[0]) / (b.s_range[1] - b.s_range[0]) - 1.0,
                                g.n,
                            )
                        })
                        .collect();
                let offsets = twist_offsets(&geometry.twist_rad, ra, rb, &pts);
                // each point's strip of the element: its quadrature weight, in point order
                let mut strip_start = ra;
                for (g, offset) in b.gm.iter().zip(offsets) {
                    let r = geometry.root_r_m + g.s_m;
                    stations.push(Station {
                        s_m: g.s_m,
                        r_m: r,
                        chord_m: geometry.chord_at(r),
                        airfoil: geometry.airfoil_at(r),
                        lift_factor: lift_inside(strip_start, g.wj, r, tip_r),
                        weight_m: g.wj,
                        pitch_offset_rad: offset,
                        active: r >= geometry.cutout_r_m,
                    });
                    strip_start += g.wj;
                }
            }
        }
        {
            let mut sh = shared
                .lock()
                .map_err(|_| anyhow::anyhow!("lifting line: shared state poisoned"))?;
            if sh.points.len() <= blade {
                sh.points.resize(blade + 1, Vec::new());
            }
            sh.points[blade] = stations
                .iter()
                .map(|s| PointRecord {
                    r_m: s.r_m,
                    weight_m: if s.active { s.weight_m } else { 0.0 },
                    ..Default::default()
                })
                .collect();
        }
        Ok(LiftingLine {
            blade,
            rotor,
            airfoils: geometry.airfoils.iter().map(|a| a.1.clone()).collect(),
            clamps,
            shared,
            first,
            stations,
            pitch_law: None,
            turn: None,
        })
    }

    /// Adds `law(t)` to every section's aerodynamic pitch.
    pub fn with_pitch_law(mut self, law: PitchLaw) -> Self {
        self.pitch_law = Some(law);
        self
    }

    /// The model's blade sits `ahead_rad` behind the blade it stands for: its kinematics are
    /// turned forward by that azimuth before they meet the air.
    pub fn with_turn(mut self, ahead_rad: f64) -> Self {
        self.turn = (ahead_rad != 0.0).then(|| exp_map([0.0, 0.0, ahead_rad]));
        self
    }

    /// Stations (load points) of the line.
    pub fn stations(&self) -> usize {
        self.stations.len()
    }

    /// The station of load point `p`, if it is one of the line's.
    pub fn station(&self, p: &LoadPoint) -> Option<usize> {
        let i0 = *self.first.get(p.element)?;
        if i0 == usize::MAX {
            return None;
        }
        (i0..i0 + NPTS_M).find(|&i| self.stations[i].s_m == p.s_m)
    }

    /// The airloads of station `i` with the section at `p` (its frame possibly pitched by the
    /// pitch law): the section's airloads, the frame they are in, the inflow ratio.
    fn airloads(
        &self,
        inflow: &Inflow,
        i: usize,
        p: &LoadPoint,
    ) -> (SectionAirloads, [[f64; 3]; 3], f64, [f64; 3]) {
        let st = &self.stations[i];
        let (x, rp, v, w) = match &self.turn {
            None => (p.x, p.r, p.v, p.w),
            Some(t) => (mv(t, p.x), mm(t, &p.r), mv(t, p.v), mv(t, p.w)),
        };
        let pitch = st.pitch_offset_rad + self.pitch_law.as_ref().map_or(0.0, |law| law(p.t));
        let r = if pitch == 0.0 {
            rp
        } else {
            mm(&rp, &exp_map([pitch, 0.0, 0.0]))
        };
        // three-quarter chord: c/2 behind the quarter-chord reference line
        let arm = mv(&r, [0.0, -0.5 * st.chord_m, 0.0]);
        let v34 = add(v, cross(w, arm));
        let (va, li) = self.rotor.air_velocity(inflow, x);
        let u = mtv(&r, sub(va, v34));
        let a = blade_element(
            u,
            st.chord_m,
            &self.rotor.air,
            &self.airfoils[st.airfoil],
            &self.clamps,
            st.lift_factor,
        );
        (a, r, li, u)
    }

    /// The airloads station `i` would see at the kinematics `p` (a reference motion), with
    /// the current inflow, without recording them; in the section frame of `p`.
    pub fn reference_airloads(&self, i: usize, p: &LoadPoint) -> SectionAirloads {
        if !self.stations[i].active {
            return SectionAirloads::default();
        }
        match self.shared.lock() {
            Ok(sh) => {
                let (mut a, r, _, _) = self.airloads(&sh.inflow, i, p);
                // from the (pitch-law) frame the airloads were computed in to the frame of p
                let rp = match &self.turn {
                    None => p.r,
                    Some(t) => mm(t, &p.r),
                };
                a.force_n_per_m = mtv(&rp, mv(&r, a.force_n_per_m));
                a
            }
            Err(_) => SectionAirloads::default(),
        }
    }

    /// Evaluates and records the airloads at `p`; the load in the section frame of `p`.
    pub fn evaluate(&mut self, p: &LoadPoint) -> SectionLoad {
        let Some(i) = self.station(p) else {
            return SectionLoad::default();
        };
        let Ok(mut sh) = self.shared.lock() else {
            return SectionLoad::default();
        };
        if !self.stations[i].active {
            return SectionLoad {
                follower: true,
                ..Default::default()
            };
        }
        let (a, r, li, u) = self.airloads(&sh.inflow, i, p);
        // hub frame of the air
        let f_hub = mv(&r, a.force_n_per_m);
        // the force's response to the inflow ratio (a forward difference): the inflow moves
        // the air by -d lambda Omega R along the shaft (z)
        let dfz = {
            const EPS: f64 = 1e-5;
            let st = &self.stations[i];
            let dv = self.rotor.omega_rad_s * self.rotor.radius_m * EPS;
            let du = mtv(&r, [0.0, 0.0, -dv]);
            let b = blade_element(
                add(u, du),
                st.chord_m,
                &self.rotor.air,
                &self.airfoils[st.airfoil],
                &ClampCounts::default(),
                st.lift_factor,
            );
            (mv(&r, b.force_n_per_m)[2] - f_hub[2]) / EPS
        };
        let x = match &self.turn {
            None => p.x,
            Some(t) => mv(t, p.x),
        };
        let d = sub(x, self.rotor.center_m);
        if let Some(rec) = sh.points[self.blade].get_mut(i) {
            rec.t_s = p.t;
            rec.disk_x = d[0] / self.rotor.radius_m;
            rec.disk_y = d[1] / self.rotor.radius_m;
            rec.lambda_i = li;
            rec.section = a;
            rec.force_n_per_m = f_hub;
            rec.arm_m = sub(x, self.rotor.center_m);
            rec.dfz_dlambda_n_per_m = dfz;
        }
        // in the section frame of p (the pitch law's frame and the turn undone)
        let rp = match &self.turn {
            None => p.r,
            Some(t) => mm(t, &p.r),
        };
        SectionLoad {
            force: mtv(&rp, f_hub),
            moment: [a.moment_n_m_per_m, 0.0, 0.0],
            follower: true,
        }
    }
}

impl DistributedLoad for LiftingLine {
    fn eval(&mut self, p: &LoadPoint) -> SectionLoad {
        self.evaluate(p)
    }
}

#[cfg(test)]
mod tests {
    use super::{lift_inside, twist_offsets};
    use crate::structure::beam::{gauss, shape};
    use crate::structure::kin::TimeTable;

    /// The twist each load point of an element from `ra` to `rb` meets the air with: the
    /// table through the nodes, interpolated, plus the offset; and the points' radii and weights.
    fn element(t: &TimeTable, ra: f64, rb: f64) -> Vec<(f64, f64, f64)> {
        let (xi, w) = gauss(4);
        let pts: Vec<_> = xi.iter().map(|&x| (x, shape(x).0)).collect();
        let off = twist_offsets(t, ra, rb, &pts);
        let nodal: Vec<f64> = (0..4)
            .map(|i| t.eval(ra + (rb - ra) * i as f64 / 3.0))
            .collect();
        pts.iter()
            .zip(&w)
            .zip(off)
            .map(|(((x, n), wq), o)| {
                let beam: f64 = n.iter().zip(&nodal).map(|(a, b)| a * b).sum();
                (
                    ra + 0.5 * (x + 1.0) * (rb - ra),
                    0.5 * wq * (rb - ra),
                    beam + o,
                )
            })
            .collect()
    }

    /// Where the table is linear over the element, the beam already carries it: no offset.
    #[test]
    fn a_linear_twist_needs_no_offset() {
        let t = TimeTable {
            points: vec![(1.0, 0.2), (6.0, 0.0), (9.0, -0.1)],
        };
        let (xi, _) = gauss(4);
        let pts: Vec<_> = xi.iter().map(|&x| (x, shape(x).0)).collect();
        for o in twist_offsets(&t, 2.0, 2.6, &pts) {
            assert!(o.abs() < 1e-14, "{o}");
        }
        let none = TimeTable { points: vec![] };
        assert!(twist_offsets(&none, 2.0, 2.6, &pts)
            .iter()
            .all(|o| *o == 0.0));
    }

    /// The shipped UH-60A table's step (-1.28 deg between 7.192 and 7.211 m) inside an element:
    /// the load points' twist integrates the table times any cubic in r exactly.
    #[test]
    fn the_element_integrates_a_stepped_twist_exactly() {
        let deg = std::f64::consts::PI / 180.0;
        let points = [
            (6.0524, 0.2548),
            (7.19226, -1.2799),
            (7.21062, -2.5648),
            (7.56167, -3.5369),
            (7.87122, -3.5464),
        ]
        .iter()
        .map(|p| (p.0, p.1 * deg))
        .collect();
        let t = TimeTable { points };
        let (ra, rb) = (7.0462, 7.6124);
        let pts = element(&t, ra, rb);
        for k in 0..4 {
            let got: f64 = pts.iter().map(|(r, w, th)| w * r.powi(k) * th).sum();
            // the integral by fine midpoints
            let n = 200_000;
            let h = (rb - ra) / n as f64;
            let want: f64 = (0..n)
                .map(|i| {
                    let r = ra + (i as f64 + 0.5) * h;
                    h * r.powi(k) * t.eval(r)
                })
                .sum();
            assert!(
                (got - want).abs() < 1e-9 * want.abs().max(1e-3),
                "r^{k}: {got} vs {want}"
            );
        }
    }

    /// Strips of a 3-point Gauss element from 7.6 m to 8.0 m and a tip-loss radius of 7.9 m:
    /// the lifting span (weights times lift factors) ends at 7.9 m exactly.
    #[test]
    fn the_lifting_span_ends_at_the_tip_loss_radius() {
        let (a, l) = (7.6, 0.4);
        let w = [5.0 / 18.0 * l, 8.0 / 18.0 * l, 5.0 / 18.0 * l];
        let x = [0.5 - 0.15f64.sqrt(), 0.5, 0.5 + 0.15f64.sqrt()];
        let mut start = a;
        let mut span = 0.0;
        for (wi, xi) in w.iter().zip(x) {
            span += wi * lift_inside(start, *wi, a + xi * l, 7.9);
            start += wi;
        }
        assert!((span - 0.3).abs() < 1e-12, "{span}");
        // a point without a strip: lifts inboard of the radius only
        assert_eq!(lift_inside(7.0, 0.0, 7.8, 7.9), 1.0);
        assert_eq!(lift_inside(7.0, 0.0, 7.95, 7.9), 0.0);
    }
}
