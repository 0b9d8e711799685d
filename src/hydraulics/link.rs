//! A hydraulic circuit joined to the device's end through a massless link: a gap in series with a
//! contact stiffness (free play as in hardware) or, with no gap, an elastic mount. The model is the
//! quasi-static one of [`CompliantFreePlay`](super::CompliantFreePlay) and
//! [`SeriesMount`](super::SeriesMount) (the link force equals the damper force at every
//! instant), integrated as one ODE instead of a force-balance solve around every step.
//!
//! The piston stroke is `d_h = d + e`, e the link's deflection. Differentiating the force balance
//! `F_link(e) = F(p) = p0 A0 - p1 A1` (Eq. 8) gives the piston velocity `v` at every instant:
//! `k_c (v - d_dot) = A0 p0_dot(v) - A1 p1_dot(v)`, with `k_c = k` in contact and 0 inside the gap,
//! and the pressure rates of Eq. (1) linear in `v` (piecewise, where the cavitation factor acts
//! on an outflow), so `v` has a closed form. Runge-Kutta schemes keep linear invariants, so the
//! balance holds to round-off while the link stays in one regime. A sub-step in which the link
//! crosses the edge of the gap is split at the crossing; what the split leaves of the balance is
//! put back by a projection (contact) or relaxes over a few sub-steps (inside the gap,
//! `F_dot = -F/tau`).
//!
//! With a moving mass `m` (piston, rod and rod end) between the link and the oil, the piston's
//! velocity is a state: `m v_dot = F(p) - F_link`, with the contact a spring and a light dashpot in
//! parallel, `F_link = k pen + c pen_dot` (`c = 2 zeta sqrt(k m)`), which can push but not pull
//! across a gap. The force at the end is then `F_link`, not `F(p)`; the two differ by the
//! inertia and the contact's damping, which is what a gap's impact looks like in a measured force.
//! The sub-steps are refined until `h omega <= 1/4`, omega the mass's frequency on the contact and
//! the oil columns, `sqrt((k + k_oil)/m)` (Eq. 16 for `k_oil`): an undamped contact rings
//! through a whole contact phase, and at `h omega = 1/2` RK4's phase error left 13 N RMS at
//! 1e9 N/m. The end's stroke over a step is the parabola through the last step's start and the
//! step's ends (the chord's velocity jump at every sample would ring the mass too).
use super::circuit::{CircuitDevice, CircuitParams, State, IIMP, IP0, IP1, IV0, IV1, IX0, IX1, NS};
use super::elements::Chamber;
use super::integrators::{explicit_step, OdeSystem, RK4};
use super::{Device, HydraulicError, StepForce, StepResult, StrokePath};
use nalgebra::{SMatrix, SVector};

/// Size of the linked state: the circuit's and the link deflection.
const NL: usize = NS + 1;
/// Index of the link deflection `e = d_h - d` [m].
const IE: usize = NS;
type LState = SVector<f64, NL>;

/// Sub-steps over which a force left inside the gap by a regime change relaxes.
const RELAX_SUBSTEPS: f64 = 4.0;

/// The link: a dead band of total width `2 half_gap` and a contact stiffness `k`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Link {
    pub half_gap: f64,
    pub k: f64,
}

impl Link {
    /// Link force of a deflection `e` [N] and whether the gap is closed (no gap: always).
    #[inline]
    pub fn force(&self, e: f64) -> (f64, bool) {
        if self.half_gap <= 0.0 {
            (self.k * e, true)
        } else if e > self.half_gap {
            (self.k * (e - self.half_gap), true)
        } else if e < -self.half_gap {
            (self.k * (e + self.half_gap), true)
        } else {
            (0.0, false)
        }
    }

    /// Which side is in contact at deflection `e`: +1 or -1, 0 inside the gap (no gap: +1).
    #[inline]
    pub fn side(&self, e: f64) -> i8 {
        if self.half_gap <= 0.0 || e > self.half_gap {
            1
        } else if e < -self.half_gap {
            -1
        } else {
            0
        }
    }

    /// The deflection carrying a force `f` (centred in the gap when it is zero): where a link
    /// starts from a device's initial force.
    #[inline]
    pub fn deflection_of(&self, f: f64) -> f64 {
        if f > 0.0 {
            self.half_gap + f / self.k
        } else if f < 0.0 {
            -self.half_gap + f / self.k
        } else {
            0.0
        }
    }
}

/// The circuit and link over one step, the end's stroke along `path` from `t_i`.
#[derive(Clone, Copy)]
struct LinkSystem<'a> {
    params: &'a CircuitParams,
    link: Link,
    t_i: f64,
    path: StrokePath,
    tau: f64,
    /// The side in contact (`Link::side`) held over a sub-step, so that no Runge-Kutta stage
    /// takes the other regime's law.
    side: i8,
}

#[inline]
fn circuit_part(y: &LState) -> State {
    State::from_fn(|i, _| y[i])
}

impl OdeSystem<NL> for LinkSystem<'_> {
    #[inline(always)]
    fn rhs(&self, t: f64, y: &LState) -> Result<LState, HydraulicError> {
        let (d, d_dot) = self.path.at(t - self.t_i);
        let e = y[IE];
        let yc = circuit_part(y);
        let part = self.params.flow_part::<false>(t, d + e, &yc, None)?;
        let contact = self.side != 0;
        let k_c = if contact { self.link.k } else { 0.0 };
        // Inside the gap the force relaxes to zero; in contact the projection keeps the balance.
        let relax = if contact {
            0.0
        } else {
            self.params.force(&yc) / self.tau
        };
        let ch = &self.params.chambers;
        let p = [yc[IP0], yc[IP1]];
        // h(v) = A0 p0_dot(v) - A1 p1_dot(v) - k_c (v - d_dot) + relax, its slope and the two
        // pressure rates: Eq. (1) of each chamber, affine in v on either side of a zero net
        // inflow (its factor, B/V or B s(p)/V with the cavitation factor s, is returned with it).
        // the pressures' factors once, not at every trial velocity (the same bits)
        let cav = p.map(|p| self.params.fluid.cavitation_factor(p).0);
        let fac =
            [0, 1].map(|k| Chamber::rate_factors(self.params.bulk(k, p[k]).0, cav[k], part.vol[k]));
        // The leakage's drag flow moves with the piston: it adds to the swept area.
        let drag = self.params.drag_area();
        let balance = |v: f64| -> (f64, f64, [f64; 2]) {
            let mut rate = [0.0; 2];
            let mut slope = [0.0; 2];
            for k in 0..2 {
                let q = self.params.net_inflow(k, part.qn[k], v, drag);
                let (r, g) = ch[k].rate_with(&fac[k], q, v);
                rate[k] = r;
                slope[k] = -g * (ch[k].area + drag) * ch[k].lambda;
            }
            (
                ch[0].area * rate[0] - ch[1].area * rate[1] - k_c * (v - d_dot) + relax,
                ch[0].area * slope[0] - ch[1].area * slope[1] - k_c,
                rate,
            )
        };
        // h is continuous, decreasing and affine between the velocities where a chamber's net
        // inflow changes sign with a cavitation factor below one: the root lies between the
        // kinks that bracket it, where one affine solve finds it.
        let mut kinks = [f64::NAN; 2];
        for (k, kink) in kinks.iter_mut().enumerate() {
            if cav[k] != 1.0 {
                *kink = part.qn[k] / ((ch[k].area + drag) * ch[k].lambda);
            }
        }
        if kinks[0] > kinks[1] || kinks[0].is_nan() {
            kinks.swap(0, 1);
        }
        let (mut lo, mut hi) = (f64::NEG_INFINITY, f64::INFINITY);
        for &v in kinks.iter().filter(|v| v.is_finite()) {
            if balance(v).0 > 0.0 {
                lo = v;
            } else {
                hi = v;
                break;
            }
        }
        let probe = match (lo.is_finite(), hi.is_finite()) {
            (true, true) => 0.5 * (lo + hi),
            (true, false) => lo.max(d_dot) + 1.0,
            (false, true) => hi.min(d_dot) - 1.0,
            (false, false) => d_dot,
        };
        let (h, slope, _) = balance(probe);
        // A slope of zero: nothing resists the piston (both chambers emptied inside the gap);
        // it then moves with the end.
        let v = if slope < 0.0 {
            (probe - h / slope).clamp(lo, hi)
        } else {
            d_dot
        };
        let (_, _, rates) = balance(v);
        let mut f = LState::zeros();
        f.fixed_rows_mut::<NS>(0).copy_from(&part.f);
        f[IP0] = rates[0];
        f[IP1] = rates[1];
        f[IE] = v - d_dot;
        Ok(f)
    }

    fn jacobian(&self, _t: f64, _y: &LState) -> Result<SMatrix<f64, NL, NL>, HydraulicError> {
        Err(HydraulicError::BadStep {
            t: self.t_i,
            reason: "the linked circuit is integrated by explicit schemes only".into(),
        })
    }

    fn weights(&self, y: &LState) -> LState {
        const RTOL: f64 = 1e-8;
        const ATOL: [f64; NL] = [0.1, 0.1, 1e-10, 1e-7, 1e-10, 1e-7, 1e-6, 1e-12];
        LState::from_fn(|i, _| ATOL[i] + RTOL * y[i].abs())
    }

    /// Poppets back on their seats (as the circuit's projection); a link in contact back on
    /// its force balance, or at the edge of the gap when the damper's force points the other way.
    fn project(&self, y: &mut LState) {
        for (ix, iv) in [(IX0, IV0), (IX1, IV1)] {
            if y[ix] < 0.0 {
                y[ix] = 0.0;
                y[iv] = y[iv].max(0.0);
            }
        }
        let e = y[IE];
        let g = self.link.half_gap;
        if g <= 0.0 || e.abs() > g {
            let f = self.params.force(&circuit_part(y));
            let s = if g <= 0.0 { 1.0 } else { e.signum() };
            y[IE] = if g <= 0.0 || s * f > 0.0 {
                s * g + f / self.link.k
            } else {
                s * g
            };
        }
    }
}

/// A linked system whose regime (the side in contact) is held over a sub-step.
trait Sided<const N: usize>: OdeSystem<N> + Copy {
    fn with_side(&self, side: i8) -> Self;
}

impl Sided<NL> for LinkSystem<'_> {
    fn with_side(&self, side: i8) -> Self {
        Self { side, ..*self }
    }
}

/// Size of the linked state with a moving mass: the circuit's, the link deflection and the
/// piston velocity.
const NM: usize = NS + 2;
/// Index of the piston velocity `v = d_h_dot` [m/s].
const IW: usize = NS + 1;
type MState = SVector<f64, NM>;

/// The moving mass between the link and the oil, and the damping of the link against it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LinkMass {
    /// Piston, rod and rod end [kg].
    pub mass_kg: f64,
    /// Damping of the contact (or mount) as a fraction of critical against the mass.
    pub damping_ratio: f64,
}

/// The circuit, link and moving mass over one step.
#[derive(Clone, Copy)]
struct MassLinkSystem<'a> {
    params: &'a CircuitParams,
    link: Link,
    mass: f64,
    /// Contact damping `2 zeta sqrt(k m)` [N s/m].
    c: f64,
    t_i: f64,
    /// The end's stroke over the step, `d_i + v_i tau + acc tau^2 / 2` (`tau = t - t_i`), or
    /// the replay's path where it is given (`path`).
    d_i: f64,
    v_i: f64,
    acc: f64,
    path: Option<StrokePath>,
    side: i8,
}

impl MassLinkSystem<'_> {
    /// Force of the link on the end side, `F_link` [N], at deflection `e` and deflection rate
    /// `e_dot`, in the regime `side` (held over a sub-step): a spring and a dashpot in parallel
    /// that push but do not pull across a gap (a mount is bilateral).
    #[inline]
    fn link_force(&self, e: f64, e_dot: f64) -> f64 {
        let g = self.link.half_gap;
        if g <= 0.0 {
            return self.link.k * e + self.c * e_dot;
        }
        match self.side {
            0 => 0.0,
            s if s > 0 => (self.link.k * (e - g) + self.c * e_dot).max(0.0),
            _ => (self.link.k * (e + g) + self.c * e_dot).min(0.0),
        }
    }
}

impl Sided<NM> for MassLinkSystem<'_> {
    fn with_side(&self, side: i8) -> Self {
        Self { side, ..*self }
    }
}

impl OdeSystem<NM> for MassLinkSystem<'_> {
    #[inline(always)]
    fn rhs(&self, t: f64, y: &MState) -> Result<MState, HydraulicError> {
        let tau = t - self.t_i;
        let (d, d_dot) = match &self.path {
            Some(p) => p.at(tau),
            None => (
                self.d_i + tau * (self.v_i + 0.5 * self.acc * tau),
                self.v_i + self.acc * tau,
            ),
        };
        let (e, v) = (y[IE], y[IW]);
        let yc = State::from_fn(|i, _| y[i]);
        let part = self.params.flow_part::<false>(t, d + e, &yc, None)?;
        let mut f = MState::zeros();
        f.fixed_rows_mut::<NS>(0).copy_from(&part.f);
        let drag = self.params.drag_area();
        for (k, ip) in [IP0, IP1].into_iter().enumerate() {
            f[ip] = self
                .params
                .pressure_rate(
                    k,
                    yc[ip],
                    part.vol[k],
                    self.params.net_inflow(k, part.qn[k], v, drag),
                    v,
                )
                .0;
        }
        f[IE] = v - d_dot;
        f[IW] = (self.params.force(&yc) - self.link_force(e, v - d_dot)) / self.mass;
        Ok(f)
    }

    fn jacobian(&self, _t: f64, _y: &MState) -> Result<SMatrix<f64, NM, NM>, HydraulicError> {
        Err(HydraulicError::BadStep {
            t: self.t_i,
            reason: "the linked circuit is integrated by explicit schemes only".into(),
        })
    }

    fn weights(&self, y: &MState) -> MState {
        const RTOL: f64 = 1e-8;
        const ATOL: [f64; NM] = [0.1, 0.1, 1e-10, 1e-7, 1e-10, 1e-7, 1e-6, 1e-12, 1e-9];
        MState::from_fn(|i, _| ATOL[i] + RTOL * y[i].abs())
    }

    /// Poppets back on their seats (as the circuit's projection).
    fn project(&self, y: &mut MState) {
        for (ix, iv) in [(IX0, IV0), (IX1, IV1)] {
            if y[ix] < 0.0 {
                y[ix] = 0.0;
                y[iv] = y[iv].max(0.0);
            }
        }
    }
}

/// RK4 over `n` equal sub-steps, projecting after each. A sub-step in which the link crosses the
/// edge of the gap is split at the crossing (located by linear interpolation of the deflection),
/// so that no sub-step mixes the two regimes' laws beyond the interpolation's error: the regime
/// switch is an event, not a kink inside a Runge-Kutta step.
fn integrate<const N: usize, S: Sided<N>>(
    link: Link,
    sys: &S,
    n: usize,
    t0: f64,
    dt: f64,
    y0: &SVector<f64, N>,
) -> Result<SVector<f64, N>, HydraulicError> {
    let h = dt / n as f64;
    let g = link.half_gap;
    let mut y = *y0;
    for s in 0..n {
        let t = t0 + s as f64 * h;
        let side0 = link.side(y[IE]);
        let mut y1 = explicit_step(&RK4, &sys.with_side(side0), t, &y, h)?;
        let side1 = link.side(y1[IE]);
        if side1 != side0 {
            // The edge crossed: the one the link leaves or reaches.
            let (e0, e1) = (y[IE], y1[IE]);
            let edge = g * f64::from(if side0 != 0 { side0 } else { side1 });
            let theta = ((edge - e0) / (e1 - e0)).clamp(0.0, 1.0);
            let mut ym = explicit_step(&RK4, &sys.with_side(side0), t, &y, theta * h)?;
            ym[IE] = edge;
            sys.project(&mut ym);
            y1 = explicit_step(
                &RK4,
                &sys.with_side(side1),
                t + theta * h,
                &ym,
                (1.0 - theta) * h,
            )?;
        }
        sys.project(&mut y1);
        if let Some(c) = y1.iter().position(|v| !v.is_finite()) {
            return Err(HydraulicError::NonFinite {
                t: t + h,
                component: c,
                substep_s: h,
                rate_per_s: crate::hydraulics::integrators::fastest_rate(
                    &sys.with_side(link.side(y0[IE])),
                    t0,
                    y0,
                ),
            });
        }
        y = y1;
    }
    Ok(y)
}

/// The physical damper behind a link (compliant free play or series mount), integrated as one
/// ODE with the link deflection (module docs). Massless, the same model, force, tangent and state
/// layout as [`CompliantFreePlay`](super::CompliantFreePlay) or
/// [`SeriesMount`](super::SeriesMount) around a [`CircuitDevice`], at one integration per step;
/// with a moving mass ([`LinkedCircuit::with_mass`]), the piston's inertia and the link's damping.
#[derive(Debug, Clone)]
pub struct LinkedCircuit {
    /// The circuit at the committed state (its stroke the piston's `d_h`).
    inner: CircuitDevice,
    link: Link,
    mass: Option<LinkMass>,
    d_h: f64,
    /// Piston velocity [m/s] and force at the end [N] at the committed state (moving mass).
    v_p: f64,
    f_end: f64,
    /// The last committed step's start and end times and start stroke `(t, t_end, d)`: with a
    /// moving mass the end's stroke over a step is the parabola through it and the step's ends.
    prev: Option<(f64, f64, f64)>,
    fresh: bool,
    trial: Option<Trial>,
}

/// A step's end: circuit state, time, piston stroke, piston velocity, force at the end; and the
/// step's start time and stroke.
type Trial = (State, f64, f64, f64, f64, f64, f64);

/// `h omega` of the sub-steps with a moving mass (RK4 is stable to 2.8; module docs).
const H_OMEGA: f64 = 0.25;

impl LinkedCircuit {
    /// A compliant free play (`gap_m > 0`) or a series mount (`gap_m = 0`) of stiffness
    /// `k_n_per_m` around `inner`, integrated by RK4 with the circuit's sub-steps.
    pub fn new(inner: CircuitDevice, gap_m: f64, k_n_per_m: f64) -> Self {
        Self {
            inner,
            link: Link {
                half_gap: 0.5 * gap_m,
                k: k_n_per_m,
            },
            mass: None,
            d_h: 0.0,
            v_p: 0.0,
            f_end: 0.0,
            prev: None,
            fresh: true,
            trial: None,
        }
    }

    /// The same link with a moving mass between it and the oil, and the link's damping.
    pub fn with_mass(mut self, mass: LinkMass) -> Self {
        self.mass = Some(mass);
        self
    }

    /// Piston stroke behind the link at the committed state [m].
    pub fn device_stroke(&self) -> f64 {
        self.d_h
    }

    /// The link (gap and contact stiffness).
    pub fn link(&self) -> Link {
        self.link
    }

    /// The moving mass and the link's damping, if any.
    pub fn mass(&self) -> Option<LinkMass> {
        self.mass
    }

    /// Sub-steps of a step `dt` with a moving mass: the circuit's, or more so that
    /// `h omega <= H_OMEGA` for the mass on the contact and the oil columns (Eq. 16).
    fn mass_substeps(&self, ms: LinkMass, dt: f64, n: usize) -> usize {
        let k_oil = self
            .inner
            .params()
            .static_stiffness(self.inner.state(), self.d_h);
        let omega = ((self.link.k + k_oil) / ms.mass_kg).sqrt() * (2.0 * ms.damping_ratio).max(1.0);
        n.max((dt * omega / H_OMEGA).ceil() as usize)
    }
}

impl Device for LinkedCircuit {
    fn step_along(&mut self, t_i: f64, path: &StrokePath) -> StepResult {
        let (dt, d_i, d_f) = (path.dt, path.d_i, path.d_f);
        let d_dot = (d_f - d_i) / dt;
        if self.fresh {
            let f0 = self.inner.committed_force();
            self.d_h = d_i + self.link.deflection_of(f0);
            self.v_p = path.start_rate();
            self.f_end = f0;
        }
        let opts = self.inner.options();
        let params = self.inner.params();
        let n = opts.substeps.max(1);
        let mut y0 = LState::zeros();
        y0.fixed_rows_mut::<NS>(0).copy_from(self.inner.state());
        y0[IIMP] = 0.0;
        y0[IE] = self.d_h - d_i;
        let (y, force_mean, force_end, v_p) = match self.mass {
            None => {
                let sys = LinkSystem {
                    params,
                    link: self.link,
                    t_i,
                    path: *path,
                    tau: RELAX_SUBSTEPS * dt / n as f64,
                    side: 0,
                };
                let y = integrate(self.link, &sys, n, t_i, dt, &y0)?;
                let f = params.force(&circuit_part(&y));
                (y, y[IIMP] / dt, f, path.end_rate())
            }
            Some(ms) => {
                // The end's stroke: the parabola through the last step's start and this step's
                // ends, so that the end's velocity is continuous to O(dt^2) from step to step. A
                // chord's velocity jump at every sample would ring the mass on its contact. A
                // replay's Hermite path is continuous in velocity already and taken as it is.
                let acc = match self.prev {
                    Some((t_p, t_e, d_p)) if (t_e - t_i).abs() <= 1e-9 * dt && t_i > t_p => {
                        let h_p = t_i - t_p;
                        2.0 * (d_dot - (d_i - d_p) / h_p) / (h_p + dt)
                    }
                    _ => 0.0,
                };
                let v_i = d_dot - 0.5 * acc * dt;
                let sys = MassLinkSystem {
                    params,
                    link: self.link,
                    mass: ms.mass_kg,
                    c: 2.0 * ms.damping_ratio * (self.link.k * ms.mass_kg).sqrt(),
                    t_i,
                    d_i,
                    v_i,
                    acc,
                    path: (!path.is_linear()).then_some(*path),
                    side: 0,
                };
                let ym0 = MState::from_fn(|i, _| if i < NL { y0[i] } else { self.v_p });
                let nm = self.mass_substeps(ms, dt, n);
                let ym = integrate(self.link, &sys, nm, t_i, dt, &ym0)?;
                let e = ym[IE];
                let f_end = sys.with_side(self.link.side(e)).link_force(
                    e,
                    ym[IW] - sys.path.map_or(v_i + acc * dt, |p| p.end_rate()),
                );
                // The end's impulse is the oil's less the momentum the mass gained.
                let imp = ym[IIMP] - ms.mass_kg * (ym[IW] - self.v_p);
                let y = LState::from_fn(|i, _| ym[i]);
                (y, imp / dt, f_end, ym[IW])
            }
        };
        let yc = circuit_part(&y);
        let d_h = d_f + y[IE];
        let (_, contact) = self.link.force(y[IE]);
        // dF/dd_f through the link: the circuit's Eq. (16) stiffness in series with the contact.
        let kd = 0.5 * params.static_stiffness(&yc, d_h);
        let dforce_dstroke = if contact {
            -(kd * self.link.k) / (kd + self.link.k)
        } else {
            0.0
        };
        self.trial = Some((yc, t_i + dt, d_h, v_p, force_end, t_i, d_i));
        Ok(StepForce {
            force_mean,
            dforce_dstroke,
            force_end,
        })
    }

    fn commit(&mut self) {
        if let Some((y, t, d_h, v_p, f_end, t_i, d_i)) = self.trial.take() {
            let mut v = [0.0; NS + 2];
            v[..NS].copy_from_slice(y.as_slice());
            v[NS] = t;
            v[NS + 1] = d_h;
            // Finite by construction (the integrator refuses a non-finite state).
            let _ = self.inner.set_state_values(&v);
            self.d_h = d_h;
            self.v_p = v_p;
            self.f_end = f_end;
            self.prev = Some((t_i, t, d_i));
            self.fresh = false;
        }
    }

    fn channel_names(&self) -> &'static [&'static str] {
        self.inner.channel_names()
    }

    fn channels(&self, out: &mut [f64]) {
        self.inner.channels(out)
    }

    fn committed_force(&self) -> f64 {
        match self.mass {
            None => self.inner.committed_force(),
            Some(_) => self.f_end,
        }
    }

    fn force_scale(&self) -> f64 {
        self.inner.force_scale().max(self.committed_force().abs())
    }

    fn set_substep_envelope(&mut self, on: bool) {
        self.inner.set_substep_envelope(on);
    }

    fn clone_device(&self) -> Box<dyn Device> {
        Box::new(self.clone())
    }

    fn reset(&mut self) {
        self.inner.reset();
        self.d_h = 0.0;
        self.v_p = 0.0;
        self.f_end = 0.0;
        self.prev = None;
        self.fresh = true;
        self.trial = None;
    }

    /// `[d_h, fresh, circuit...]` as the force-balance solve's, then, with a moving mass, the
    /// piston velocity, the force at the end and the last step `[known, t, t_end, d]`.
    fn state_values(&self) -> Vec<f64> {
        let mut v = vec![self.d_h, f64::from(u8::from(self.fresh))];
        v.extend(self.inner.state_values());
        if self.mass.is_some() {
            let (t_p, t_e, d_p) = self.prev.unwrap_or_default();
            let known = f64::from(u8::from(self.prev.is_some()));
            v.extend([self.v_p, self.f_end, known, t_p, t_e, d_p]);
        }
        v
    }

    fn set_state_values(&mut self, v: &[f64]) -> Result<(), HydraulicError> {
        let tail = if self.mass.is_some() { 6 } else { 0 };
        if v.len() < 2 + tail {
            return super::check_state_len("linked circuit", v, 2 + NS + 2 + tail);
        }
        let (head, rest) = v.split_at(v.len() - tail);
        self.inner.set_state_values(&head[2..])?;
        self.d_h = head[0];
        self.fresh = head[1] != 0.0;
        if let [v_p, f_end, known, t_p, t_e, d_p] = rest {
            if !rest.iter().all(|x| x.is_finite()) {
                return Err(HydraulicError::BadState {
                    reason: format!("linked circuit state needs finite values, got {v:?}"),
                });
            }
            self.v_p = *v_p;
            self.f_end = *f_end;
            self.prev = (*known != 0.0).then_some((*t_p, *t_e, *d_p));
        }
        self.trial = None;
        Ok(())
    }
}
