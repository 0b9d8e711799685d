//! Two-chamber hydraulic circuits: the simple damper, the damper with two pressure relief valves
//! and check valves, and the linear actuator (entrance orifices) of the paper, all as one element
//! assembly on the state `[p0, p1, x0, x0_dot, x1, x1_dot, impulse]`. Absent elements contribute
//! nothing; the impulse `int F dt` is integrated alongside so that `F_m` of Eq. (13) has the
//! order of the scheme.
use super::elements::{Chamber, CheckValve, FlowLaw, Orifice, ReliefValve, ViscousOrificeLaw};
use super::extensions::HydraulicExtensions;
use super::fluid::Fluid;
use super::integrators::{integrate, IntegratorOptions, OdeSystem, Scheme};
use super::{Device, HydraulicError, StepForce, StepResult, StrokePath};
use nalgebra::{SMatrix, SVector};
use std::sync::Arc;

/// Size of the circuit state.
pub const NS: usize = 7;
/// Circuit state `[p0, p1, x0, x0_dot, x1, x1_dot, impulse]` (Pa, Pa, m, m/s, m, m/s, N s).
pub type State = SVector<f64, NS>;
/// Jacobian of the circuit right-hand side.
pub type Jacobian = SMatrix<f64, NS, NS>;

pub const IP0: usize = 0;
pub const IP1: usize = 1;
pub const IX0: usize = 2;
pub const IV0: usize = 3;
pub const IX1: usize = 4;
pub const IV1: usize = 5;
pub const IIMP: usize = 6;

/// Piecewise-linear function of time (held constant outside its knots); cloneable data, used
/// e.g. to ramp an actuator's orifice areas (paper: 0 -> nominal over 0.5 s -> 0 at 1.0 s).
#[derive(Debug, Clone, PartialEq)]
pub struct PiecewiseLinear {
    t: Vec<f64>,
    v: Vec<f64>,
}

impl PiecewiseLinear {
    /// Knots `t` (strictly increasing, finite) and values `v` of equal length >= 1.
    pub fn new(t: Vec<f64>, v: Vec<f64>) -> Result<Self, String> {
        if t.is_empty() || t.len() != v.len() {
            return Err(format!(
                "schedule needs equal, non-zero numbers of times and values (got {} and {})",
                t.len(),
                v.len()
            ));
        }
        if t.iter().chain(&v).any(|x| !x.is_finite()) {
            return Err("schedule has a non-finite time or value".into());
        }
        if let Some(i) = t.windows(2).position(|w| w[1] <= w[0]) {
            return Err(format!("schedule times not increasing at knot {}", i + 1));
        }
        Ok(Self { t, v })
    }

    /// The paper's actuator ramp: 0 at t = 0, 1 at `t_up`, 0 again at `t_down`.
    pub fn ramp_up_down(t_up: f64, t_down: f64) -> Self {
        Self {
            t: vec![0.0, t_up, t_down],
            v: vec![0.0, 1.0, 0.0],
        }
    }

    /// Value at `t`.
    #[inline]
    pub fn eval(&self, t: f64) -> f64 {
        let n = self.t.len();
        if t <= self.t[0] {
            return self.v[0];
        }
        if t >= self.t[n - 1] {
            return self.v[n - 1];
        }
        let i = self.t.partition_point(|&k| k <= t) - 1;
        let s = (t - self.t[i]) / (self.t[i + 1] - self.t[i]);
        self.v[i] + s * (self.v[i + 1] - self.v[i])
    }
}

/// Entrance orifices of a linear actuator: orifice k feeds chamber k from the entrance pressure
/// `p_E,k`; both areas are scaled by an optional time schedule (the control valves).
#[derive(Debug, Clone, PartialEq)]
pub struct EntranceOrifices {
    pub orifices: [Orifice; 2],
    pub p_entrance: [f64; 2],
    pub area_schedule: Option<PiecewiseLinear>,
}

/// Element assembly of a two-chamber device. Chamber 0 has lambda = +1, chamber 1 lambda = -1.
#[derive(Debug, Clone, PartialEq)]
pub struct CircuitParams {
    pub fluid: Fluid,
    /// Laminar transition of every flow law [Pa] (> 0).
    pub dp_laminar: f64,
    pub chambers: [Chamber; 2],
    /// Orifice between the chambers, positive flow 0 -> 1.
    pub orifice: Option<Orifice>,
    /// Relief valve k relieves chamber k (valve 0: flow 0 -> 1; valve 1: flow 1 -> 0).
    pub relief: [Option<ReliefValve>; 2],
    /// Check valves feeding each chamber from `p_s`.
    pub check: Option<CheckValve>,
    /// Actuator entrance orifices.
    pub entrance: Option<EntranceOrifices>,
    /// Background pressure p_s [Pa].
    pub p_s: f64,
    /// Initial chamber pressures [Pa].
    pub p_init: [f64; 2],
    /// Entrained air and piston leakage (default: none, the paper's model).
    pub ext: HydraulicExtensions,
}

/// Linear actuator properties (paper Table 1 via [`ActuatorParams::paper_table1`]).
#[derive(Debug, Clone, PartialEq)]
pub struct ActuatorParams {
    pub area_m2: [f64; 2],
    pub volume0_m3: [f64; 2],
    pub p_entrance_pa: [f64; 2],
    pub orifice_area_m2: [f64; 2],
    pub cd: [f64; 2],
    pub p_s_pa: f64,
    pub bulk_modulus_pa: f64,
    pub rho_kg_m3: f64,
    /// Check valve area (0 disables).
    pub check_valve_area_m2: f64,
    pub dp_laminar_pa: f64,
}

impl ActuatorParams {
    /// Table 1 of the paper. Table 1 prints B = 1.53 MPa; the text gives ~1.5 GPa for typical
    /// oils and 1.53 MPa would make the actuator ~1000x softer than its observed behaviour, so
    /// 1.53 GPa is used. Density (not in Table 1): 850 kg/m^3. Check valve area: our choice.
    pub fn paper_table1() -> Self {
        Self {
            area_m2: [7.85e-5; 2],
            volume0_m3: [9.42e-6; 2],
            p_entrance_pa: [1.25e6; 2],
            orifice_area_m2: [6.0e-6; 2],
            cd: [0.611; 2],
            p_s_pa: 1.0e6,
            bulk_modulus_pa: 1.53e9,
            rho_kg_m3: 850.0,
            check_valve_area_m2: 6.0e-6,
            dp_laminar_pa: 1.0e3,
        }
    }

    /// Element assembly of the actuator (chambers start at p_s).
    pub fn to_circuit(&self) -> CircuitParams {
        let ch = |k: usize, lambda: f64| Chamber {
            area: self.area_m2[k],
            volume0: self.volume0_m3[k],
            lambda,
        };
        let orf = |k: usize| Orifice {
            area: self.orifice_area_m2[k],
            cd: self.cd[k],
        };
        CircuitParams {
            fluid: Fluid::constant_bulk(self.rho_kg_m3, self.bulk_modulus_pa),
            dp_laminar: self.dp_laminar_pa,
            chambers: [ch(0, 1.0), ch(1, -1.0)],
            orifice: None,
            relief: [None, None],
            check: (self.check_valve_area_m2 > 0.0).then_some(CheckValve {
                area: self.check_valve_area_m2,
                cd: self.cd[0],
            }),
            entrance: Some(EntranceOrifices {
                orifices: [orf(0), orf(1)],
                p_entrance: self.p_entrance_pa,
                area_schedule: None,
            }),
            p_s: self.p_s_pa,
            p_init: [self.p_s_pa; 2],
            ext: HydraulicExtensions::default(),
        }
    }
}

/// Flow rates of a circuit at one instant [m^3/s].
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct Flows {
    /// Orifice, positive 0 -> 1.
    pub orifice: f64,
    /// Relief valve k, positive out of the chamber it relieves.
    pub relief: [f64; 2],
    /// Check valve into chamber k.
    pub check: [f64; 2],
    /// Entrance orifice into chamber k.
    pub entrance: [f64; 2],
    /// Piston leakage, positive 0 -> 1.
    pub leakage: f64,
    /// Bleed to the accumulator out of chamber k.
    pub bleed: [f64; 2],
}

impl CircuitParams {
    /// The regularised Eq. (4) law of the valves (and of an orifice without viscosity).
    pub fn flow_law(&self) -> FlowLaw {
        self.law()
    }

    fn law(&self) -> FlowLaw {
        FlowLaw {
            rho: self.fluid.rho,
            dp_laminar: self.dp_laminar,
        }
    }

    /// The inter-chamber orifice's laminar-to-turbulent law, where the deck gives the oil's
    /// viscosity and the bore (None: Eq. 4 regularised below `dp_laminar`).
    #[inline(always)]
    pub fn viscous_orifice(&self) -> Option<ViscousOrificeLaw> {
        match (&self.orifice, &self.ext.orifice_viscosity) {
            (Some(o), Some(v)) => Some(v.law(o, self.fluid.rho)),
            _ => None,
        }
    }

    /// How fast the chambers' pressure difference relaxes through the viscous orifice at zero
    /// stroke and the initial pressures, `(B0/V0 + B1/V1) / R_lam` [1/s] (None: Eq. 4's law,
    /// whose regularised slope is far gentler). An explicit sub-step longer than the stability
    /// limit of its scheme over this rate amplifies instead of damping where the flow reverses.
    pub fn orifice_rate_per_s(&self) -> Option<f64> {
        let law = self.viscous_orifice()?;
        let stiffness: f64 = (0..2)
            .map(|k| self.bulk(k, self.p_init[k]).0 / self.chambers[k].volume0)
            .sum();
        Some(stiffness / law.r)
    }

    /// Bulk modulus of the contents of chamber k at p: Eq. (3), or the oil/air mixture.
    #[inline(always)]
    pub fn bulk(&self, k: usize, p: f64) -> (f64, f64) {
        match self.ext.air_of(k) {
            None => self.fluid.bulk(p),
            Some(a) => a.bulk(&self.fluid, p),
        }
    }

    /// Force of Eq. (8), `F = p0 A0 - p1 A1`.
    #[inline]
    pub fn force(&self, y: &State) -> f64 {
        y[IP0] * self.chambers[0].area - y[IP1] * self.chambers[1].area
    }

    /// Static stiffness of Eq. (16), `B A0^2/V0 + B A1^2/V1`, at the state's pressures and the
    /// volumes at stroke `d` (positive number).
    pub fn static_stiffness(&self, y: &State, d: f64) -> f64 {
        let mut k = 0.0;
        for (i, c) in self.chambers.iter().enumerate() {
            let (b, _) = self.bulk(i, y[i]);
            k += b * c.area * c.area / c.volume(d);
        }
        k
    }

    /// The Couette flow of the piston leakage per unit piston velocity [m^2] (0 without it),
    /// from the growing chamber into the shrinking one; the bore is the larger chamber area.
    #[inline]
    pub fn drag_area(&self) -> f64 {
        match &self.ext.leakage {
            Some(l) if l.viscosity_length > 0.0 => {
                l.drag_area(self.chambers[0].area.max(self.chambers[1].area))
            }
            _ => 0.0,
        }
    }

    /// Net inflow into chamber k at piston velocity w: `qn` of [`FlowPart`] less the leakage's
    /// drag flow out of it, `lambda_k c w` (c = [`CircuitParams::drag_area`], computed once by
    /// the caller).
    #[inline(always)]
    pub fn net_inflow(&self, k: usize, qn: f64, w: f64, drag: f64) -> f64 {
        if drag == 0.0 {
            qn
        } else {
            qn - self.chambers[k].lambda * drag * w
        }
    }

    /// The relief valves' flows of [`CircuitParams::evaluate`] alone (NaN where it errs): what
    /// the sub-step envelope records, without the rest of the right-hand side.
    fn relief_flows(&self, d: f64, y: &State) -> [f64; 2] {
        if self.chambers.iter().any(|c| c.volume(d) <= 0.0) {
            return [f64::NAN; 2];
        }
        let law = self.law();
        let (p0, p1) = (y[IP0], y[IP1]);
        let q = |k: usize, dp: f64, ix: usize| {
            self.relief[k].map_or(0.0, |rv| rv.flow(&law, dp, y[ix]).0)
        };
        [q(0, p0 - p1, IX0), q(1, p1 - p0, IX1)]
    }

    /// Initial state: chambers at `p_init`, poppets seated, zero impulse.
    pub fn initial_state(&self) -> State {
        let mut y = State::zeros();
        y[IP0] = self.p_init[0];
        y[IP1] = self.p_init[1];
        y
    }

    /// Right-hand side (and, when `JAC`, its Jacobian) with the flows, at time t, stroke d,
    /// stroke rate d_dot. Chamber pressures: Eq. (1); flows: Eqs. (4), (6)-(7); poppets: Eq. (5).
    /// `contact`: `None` decides seat contact from `y` ([`ReliefValve::poppet_rate`]);
    /// `Some(held)` imposes it (valve k held on its seat iff `held[k]`), as the implicit scheme does
    /// over a sub-step.
    #[inline(always)]
    pub fn evaluate<const JAC: bool>(
        &self,
        t: f64,
        d: f64,
        d_dot: f64,
        y: &State,
        contact: Option<[bool; 2]>,
    ) -> Result<(State, Jacobian, Flows), HydraulicError> {
        let FlowPart {
            mut f,
            mut j,
            mut fl,
            qn: _,
            vol,
            dq,
        } = self.flow_part::<JAC>(t, d, y, contact)?;
        let drag = self.drag_area();
        // The net volume rates with the orifice's and relief valves' flows added last: the
        // turbulent flows hang on the square root, and the pressure's dependency chain is the
        // cost of an explicit sub-step (the damper's own right-hand side sums the same way).
        let mut rest = [
            fl.check[0] + fl.entrance[0] - fl.bleed[0] - fl.leakage,
            fl.check[1] + fl.entrance[1] - fl.bleed[1] + fl.leakage,
        ];
        if drag != 0.0 {
            for (k, q) in rest.iter_mut().enumerate() {
                *q = self.net_inflow(k, *q, d_dot, drag);
            }
            fl.leakage += self.chambers[0].lambda * drag * d_dot;
        }
        let ch = &self.chambers;
        let rest = [0, 1].map(|k| rest[k] - ch[k].area * ch[k].lambda * d_dot);
        let (o, r) = (fl.orifice, fl.relief);
        let net = [(rest[0] - o) + (r[1] - r[0]), (rest[1] + o) + (r[0] - r[1])];
        for (k, ip) in [(0, IP0), (1, IP1)] {
            let (rate, drate_dp, b_over_v) = Chamber::pressure_rate_of_net(
                &self.fluid,
                self.bulk(k, y[ip]),
                y[ip],
                vol[k],
                net[k],
            );
            f[ip] = rate;
            if JAC {
                for (c, dqc) in dq[k].iter().enumerate() {
                    j[(ip, c)] = b_over_v * dqc;
                }
                j[(ip, ip)] += drate_dp;
            }
        }
        Ok((f, j, fl))
    }

    /// Eq. (1) for chamber k at pressure p, volume v, net inflow `qn` and stroke rate `d_dot`:
    /// `(p_dot, dp_dot/dp, dp_dot/dQ)`, with the bulk modulus of the chamber's contents.
    #[inline(always)]
    pub fn pressure_rate(&self, k: usize, p: f64, v: f64, qn: f64, d_dot: f64) -> (f64, f64, f64) {
        self.chambers[k].pressure_rate_with_bulk(&self.fluid, self.bulk(k, p), p, v, qn, d_dot)
    }

    /// Everything of [`CircuitParams::evaluate`] but the chamber pressure rates: the poppet
    /// rates, the impulse rate (Eq. 8), the flows and the net inflow into each chamber, which
    /// with the stroke rate give the pressure rates (Eq. 1).
    #[inline(always)]
    pub fn flow_part<const JAC: bool>(
        &self,
        t: f64,
        d: f64,
        y: &State,
        contact: Option<[bool; 2]>,
    ) -> Result<FlowPart, HydraulicError> {
        let law = self.law();
        let (p0, p1) = (y[IP0], y[IP1]);
        let mut vol = [0.0; 2];
        for (k, c) in self.chambers.iter().enumerate() {
            vol[k] = c.volume(d);
            if vol[k] <= 0.0 {
                return Err(HydraulicError::ChamberVolume {
                    chamber: k,
                    volume_m3: vol[k],
                    stroke_m: d,
                    t,
                    area_m2: c.area,
                    volume0_m3: c.volume0,
                });
            }
        }
        let mut fl = Flows::default();
        let mut f = State::zeros();
        let mut j = Jacobian::zeros();
        // dQn_k/dy_j of the net inflows into chambers 0 and 1.
        let mut dq = [[0.0; NS]; 2];

        if let Some(o) = &self.orifice {
            let (q, dqd) = match self.viscous_orifice() {
                Some(v) => v.flow(p0 - p1),
                None => o.flow(&law, p0 - p1),
            };
            fl.orifice = q;
            dq[0][IP0] -= dqd;
            dq[0][IP1] += dqd;
            dq[1][IP0] += dqd;
            dq[1][IP1] -= dqd;
        }
        if let Some(lk) = &self.ext.leakage {
            let g = lk.conductance;
            fl.leakage = g * (p0 - p1);
            dq[0][IP0] -= g;
            dq[0][IP1] += g;
            dq[1][IP0] += g;
            dq[1][IP1] -= g;
        }
        if let Some(bl) = &self.ext.bleed {
            let g = bl.conductance;
            for (k, ip) in [(0, IP0), (1, IP1)] {
                fl.bleed[k] = g * (y[ip] - self.p_s);
                dq[k][ip] -= g;
            }
        }
        for k in 0..2 {
            let Some(rv) = &self.relief[k] else { continue };
            let (ix, iv) = if k == 0 { (IX0, IV0) } else { (IX1, IV1) };
            let (pf, pb, ifr, ibk) = if k == 0 {
                (p0, p1, IP0, IP1)
            } else {
                (p1, p0, IP1, IP0)
            };
            let (x, v) = (y[ix], y[iv]);
            let (q, dqp, dqx) = rv.flow(&law, pf - pb, x);
            fl.relief[k] = q;
            // out of chamber k (front), into the other (back)
            dq[k][ifr] -= dqp;
            dq[k][ibk] += dqp;
            dq[k][ix] -= dqx;
            dq[1 - k][ifr] += dqp;
            dq[1 - k][ibk] -= dqp;
            dq[1 - k][ix] += dqx;
            let pr = match contact {
                None => rv.poppet_rate(pf, pb, x, v),
                Some(held) => rv.poppet_rate_with(pf, pb, x, v, held[k]),
            };
            f[ix] = pr.x_dot;
            f[iv] = pr.v_dot;
            if JAC && !pr.held {
                j[(ix, iv)] = 1.0;
                j[(iv, ifr)] = rv.a_front / rv.m;
                j[(iv, ibk)] = -rv.a_back / rv.m;
                j[(iv, ix)] = -rv.k / rv.m;
                j[(iv, iv)] = -rv.c / rv.m;
            }
        }
        if let Some(cv) = &self.check {
            for (k, ip) in [(0, IP0), (1, IP1)] {
                let (q, dqp) = cv.inflow(&law, self.p_s, y[ip]);
                fl.check[k] = q;
                dq[k][ip] += dqp;
            }
        }
        if let Some(en) = &self.entrance {
            let s = en.area_schedule.as_ref().map_or(1.0, |sch| sch.eval(t));
            for (k, ip) in [(0, IP0), (1, IP1)] {
                let (q, dqd) = en.orifices[k].flow(&law, en.p_entrance[k] - y[ip]);
                fl.entrance[k] = s * q;
                dq[k][ip] -= s * dqd;
            }
        }
        let qn = [
            -fl.orifice - fl.leakage - fl.relief[0] + fl.relief[1] + fl.check[0] + fl.entrance[0]
                - fl.bleed[0],
            fl.orifice + fl.leakage + fl.relief[0] - fl.relief[1] + fl.check[1] + fl.entrance[1]
                - fl.bleed[1],
        ];
        f[IIMP] = self.force(y);
        if JAC {
            j[(IIMP, IP0)] = self.chambers[0].area;
            j[(IIMP, IP1)] = -self.chambers[1].area;
        }
        Ok(FlowPart {
            f,
            j,
            fl,
            qn,
            vol,
            dq,
        })
    }
}

/// The circuit's right-hand side without the chamber pressure rates ([`CircuitParams::flow_part`]).
#[derive(Debug, Clone, Copy)]
pub struct FlowPart {
    /// Rates of the poppets and the impulse; zero in the pressure rows.
    pub f: State,
    /// Jacobian rows of the poppets and the impulse (when asked for).
    pub j: Jacobian,
    pub fl: Flows,
    /// Net inflow into each chamber from its flow paths [m^3/s], but the piston leakage's drag
    /// flow, which needs the piston velocity ([`CircuitParams::net_inflow`]).
    pub qn: [f64; 2],
    /// Chamber volumes [m^3].
    pub vol: [f64; 2],
    /// dQn_k/dy of the net inflows (when asked for).
    pub dq: [[f64; NS]; 2],
}

/// The circuit over one step: stroke linear in time from `d_i` at `t_i`.
#[derive(Debug, Clone, Copy)]
pub struct StepSystem<'a> {
    pub params: &'a CircuitParams,
    pub t_i: f64,
    /// The stroke over the step.
    pub path: StrokePath,
    /// Seat contact frozen over the current implicit sub-step.
    pub contact: Option<[bool; 2]>,
    /// Relief-valve extremes over the sub-steps integrated (None: not recorded).
    pub envelope: Option<SubstepEnvelope>,
    /// The damper's right-hand side with its constants computed once (None: the general one).
    fast: Option<DamperRhs>,
}

impl<'a> StepSystem<'a> {
    /// The circuit over the step from `t_i` along `path`; `fast` takes the damper's
    /// specialised right-hand side where it applies (explicit schemes: no contact held).
    pub fn new(params: &'a CircuitParams, t_i: f64, path: StrokePath, fast: bool) -> Self {
        Self {
            params,
            t_i,
            path,
            contact: None,
            envelope: None,
            fast: if fast { DamperRhs::new(params) } else { None },
        }
    }
}

/// The right-hand side of a damper circuit (no entrance orifices, leakage, bleed or entrained
/// air) with what depends only on the parameters computed once, bit for bit
/// [`CircuitParams::evaluate`] without the Jacobian, the flows or a held contact: the same
/// expressions in the same order; the absent elements' flows (+0) left out of the sums (exact:
/// subtracting +0 is the identity; adding +0 changes at most the sign of a zero, and once the
/// check valve's flow, never -0, is added no sum is -0); one square root of `|p0 - p1|` shared
/// by the orifice and both relief valves. Both sum the orifice's and relief valves' flows last
/// and multiply by reciprocals (`2/rho`, `1/V`, `1/m`, `1/alpha`): an explicit sub-step costs
/// the latency of the pressures' dependency chain, which divisions lengthen (docs/performance.md).
#[derive(Debug, Clone, Copy)]
struct DamperRhs {
    /// `2/rho` of the turbulent law ([`FlowLaw::unit_flow`]).
    two_over_rho: f64,
    /// `1/m` of each relief poppet ([`ReliefValve::poppet_rate`]; 0 without one).
    inv_m: [f64; 2],
    dp_l: f64,
    /// `sqrt(2 dp_l / rho)`, the laminar branch's scale ([`FlowLaw::unit_flow`]).
    u_l: f64,
    /// `C_d A` of the orifice (0 without one) and of the check valves (0 without them).
    cda_orifice: f64,
    cda_check: f64,
    /// `A lambda` of each chamber.
    a_lambda: [f64; 2],
    /// The orifice's laminar-to-turbulent law (None: Eq. 4 regularised).
    viscous: Option<ViscousOrificeLaw>,
}

impl DamperRhs {
    fn new(p: &CircuitParams) -> Option<Self> {
        let e = &p.ext;
        let cda_check = p.check.map_or(0.0, |c| c.cd * c.area);
        // a check valve flow of -0 would keep a sum's zero sign (doc above): general path
        let plain = p.entrance.is_none()
            && e.leakage.is_none()
            && e.bleed.is_none()
            && e.air_of(0).is_none()
            && e.air_of(1).is_none()
            && cda_check.is_sign_positive();
        plain.then(|| Self {
            two_over_rho: 2.0 / p.fluid.rho,
            inv_m: [0, 1].map(|k| p.relief[k].map_or(0.0, |r| 1.0 / r.m)),
            dp_l: p.dp_laminar,
            u_l: (2.0 * p.dp_laminar / p.fluid.rho).sqrt(),
            cda_orifice: p.orifice.map_or(0.0, |o| o.cd * o.area),
            cda_check,
            a_lambda: [0, 1].map(|k| p.chambers[k].area * p.chambers[k].lambda),
            viscous: p.viscous_orifice(),
        })
    }

    /// [`FlowLaw::unit_flow`] below the laminar transition.
    #[inline(always)]
    fn laminar(&self, dp: f64) -> f64 {
        let r = dp / self.dp_l;
        self.u_l * (5.0 * r - r * r * r) * 0.25
    }

    /// [`FlowLaw::one_sided_flow`].
    #[inline(always)]
    fn one_sided(&self, dp: f64) -> f64 {
        if dp <= 0.0 {
            0.0
        } else if dp >= self.dp_l {
            (dp * self.two_over_rho).sqrt()
        } else {
            let r = dp / self.dp_l;
            self.u_l * (5.0 * r * r - 3.0 * r * r * r) * 0.5
        }
    }

    /// f(t, y) at stroke `d` and stroke rate `d_dot`.
    #[inline(always)]
    fn rhs(
        &self,
        params: &CircuitParams,
        t: f64,
        d: f64,
        d_dot: f64,
        y: &State,
    ) -> Result<State, HydraulicError> {
        let ch = &params.chambers;
        let vol = [0, 1].map(|k| ch[k].volume0 + self.a_lambda[k] * d);
        if !(vol[0] > 0.0 && vol[1] > 0.0) {
            // the general path names the chamber
            return Ok(params.evaluate::<false>(t, d, d_dot, y, None)?.0);
        }
        let (p0, p1) = (y[IP0], y[IP1]);
        let mut f = State::zeros();
        let dp = p0 - p1;
        let a = dp.abs();
        let turbulent = a >= self.dp_l;
        let s = if turbulent {
            (a * self.two_over_rho).sqrt()
        } else {
            0.0
        };
        // unit flow of p0 - p1 or of p1 - p0 (the same |dp|)
        let unit = |dp: f64| {
            if turbulent {
                s.copysign(dp)
            } else {
                self.laminar(dp)
            }
        };
        let o = if let Some(v) = &self.viscous {
            v.flow(dp).0
        } else if params.orifice.is_some() {
            self.cda_orifice * unit(dp)
        } else {
            0.0
        };
        let mut r = [0.0; 2];
        for (k, (ix, iv, pf, pb)) in [(IX0, IV0, p0, p1), (IX1, IV1, p1, p0)]
            .into_iter()
            .enumerate()
        {
            let Some(rv) = &params.relief[k] else {
                continue;
            };
            let (x, v) = (y[ix], y[iv]);
            let (area, _) = rv.flow_area(x);
            if area != 0.0 {
                r[k] = rv.cd * area * unit(pf - pb);
            }
            let fo = rv.opening_force(pf, pb);
            if !(x <= 0.0 && v <= 0.0 && fo <= 0.0) {
                f[ix] = v;
                f[iv] = (fo - rv.k * x - rv.c * v) * self.inv_m[k];
            }
        }
        let mut c = [0.0; 2];
        if params.check.is_some() {
            for (k, p) in [p0, p1].into_iter().enumerate() {
                c[k] = self.cda_check * self.one_sided(params.p_s - p);
            }
        }
        // the orifice's flow enters last: the pressure's dependency chain stays short
        let rest = [0, 1].map(|k| c[k] - self.a_lambda[k] * d_dot);
        let net = [(rest[0] - o) + (r[1] - r[0]), (rest[1] + o) + (r[0] - r[1])];
        for (k, ip) in [(0, IP0), (1, IP1)] {
            let p = y[ip];
            let (b, _) = params.fluid.bulk(p);
            let net = net[k];
            let iv = 1.0 / vol[k];
            f[ip] = if net < 0.0 {
                let (sc, _) = params.fluid.cavitation_factor(p);
                b * sc * iv * net
            } else {
                b * iv * net
            };
        }
        f[IIMP] = params.force(y);
        Ok(f)
    }
}

/// Relief-valve poppet displacement, velocity and flow of both valves at the end of every
/// hydraulic sub-step of a step, as their minimum and maximum: the poppets move within a
/// structural step, so a value sampled once per step aliases that motion.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SubstepEnvelope {
    /// [x_valve0, x_valve1, v_valve0, v_valve1, q_valve0, q_valve1] (m, m/s, m^3/s).
    pub min: [f64; 6],
    pub max: [f64; 6],
}

impl SubstepEnvelope {
    /// Nothing seen yet (min +inf, max -inf).
    pub const EMPTY: Self = SubstepEnvelope {
        min: [f64::INFINITY; 6],
        max: [f64::NEG_INFINITY; 6],
    };

    /// Not recorded.
    pub const NOT_RECORDED: Self = SubstepEnvelope {
        min: [f64::NAN; 6],
        max: [f64::NAN; 6],
    };

    /// The envelope of one state (both bounds the values at that state).
    fn at(params: &CircuitParams, d: f64, y: &State) -> Self {
        let mut e = Self::EMPTY;
        e.add(params, d, y);
        e
    }

    fn add(&mut self, params: &CircuitParams, d: f64, y: &State) {
        let q = params.relief_flows(d, y);
        let v = [y[IX0], y[IX1], y[IV0], y[IV1], q[0], q[1]];
        for ((lo, hi), x) in self.min.iter_mut().zip(&mut self.max).zip(v) {
            *lo = lo.min(x);
            *hi = hi.max(x);
        }
    }
}

impl OdeSystem<NS> for StepSystem<'_> {
    #[inline(always)]
    fn rhs(&self, t: f64, y: &State) -> Result<State, HydraulicError> {
        let (d, d_dot) = self.path.at(t - self.t_i);
        if let (Some(fast), None) = (&self.fast, self.contact) {
            return fast.rhs(self.params, t, d, d_dot, y);
        }
        Ok(self
            .params
            .evaluate::<false>(t, d, d_dot, y, self.contact)?
            .0)
    }
    fn jacobian(&self, t: f64, y: &State) -> Result<Jacobian, HydraulicError> {
        let (d, d_dot) = self.path.at(t - self.t_i);
        Ok(self
            .params
            .evaluate::<true>(t, d, d_dot, y, self.contact)?
            .1)
    }
    fn weights(&self, y: &State) -> State {
        const RTOL: f64 = 1e-8;
        const ATOL: [f64; NS] = [0.1, 0.1, 1e-10, 1e-7, 1e-10, 1e-7, 1e-6];
        State::from_fn(|i, _| ATOL[i] + RTOL * y[i].abs())
    }
    /// Implicit scheme: the seat contact of each poppet is decided at the start of the sub-step
    /// and held fixed over it (a fixed active set keeps Newton on a smooth problem).
    fn begin_implicit_substep(&mut self, _t: f64, y: &State) {
        let mut held = [false; 2];
        for (k, (ix, iv, ifr, ibk)) in [(IX0, IV0, IP0, IP1), (IX1, IV1, IP1, IP0)]
            .into_iter()
            .enumerate()
        {
            if let Some(rv) = &self.params.relief[k] {
                held[k] = rv.poppet_rate(y[ifr], y[ibk], y[ix], y[iv]).held;
            }
        }
        self.contact = Some(held);
    }

    /// Seat contact: a poppet found below its seat after a sub-step is put back on it and its
    /// closing velocity removed (perfectly inelastic impact).
    fn project(&self, y: &mut State) {
        for (ix, iv) in [(IX0, IV0), (IX1, IV1)] {
            if y[ix] < 0.0 {
                y[ix] = 0.0;
                y[iv] = y[iv].max(0.0);
            }
        }
    }

    fn end_substep(&mut self, t: f64, y: &State) {
        if let Some(mut e) = self.envelope {
            let (d, _) = self.path.at(t - self.t_i);
            e.add(self.params, d, y);
            self.envelope = Some(e);
        }
    }
}

/// How a circuit device estimates `dF_m/dd_f`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Tangent {
    /// Eq. (16) static stiffness, `-(1/2)(B A0^2/V0 + B A1^2/V1)` (the paper's choice; cheap).
    #[default]
    Eq16,
    /// Forward difference of `F_m` in `d_f` (one extra integration of the step, step size
    /// 1e-7 of the chamber length scale `V0/A0`): the true derivative including the flows.
    FiniteDifference,
}

/// A two-chamber hydraulic device (damper, damper with relief valves, actuator).
#[derive(Debug, Clone)]
pub struct CircuitDevice {
    params: Arc<CircuitParams>,
    opts: IntegratorOptions,
    tangent: Tangent,
    committed: State,
    committed_t: f64,
    committed_d: f64,
    trial: Option<(State, f64, f64)>,
    /// Relief-valve extremes over the sub-steps of the committed step [0] and of the trial [1]
    /// (boxed: keeps the device small where it is held by value).
    envelope: Box<[SubstepEnvelope; 2]>,
    /// Record the envelope ([`Device::set_substep_envelope`]).
    record_envelope: bool,
}

const DAMPER_CHANNELS: &[&str] = &[
    "p0_Pa",
    "p1_Pa",
    "q_orifice_m3_s",
    "x_valve0_m",
    "x_valve1_m",
    "q_valve0_m3_s",
    "q_valve1_m3_s",
    "q_check0_m3_s",
    "q_check1_m3_s",
    "v_valve0_m_s",
    "v_valve1_m_s",
    // min and max over the hydraulic sub-steps of the step ending at the sample
    "x_valve0_substep_min_m",
    "x_valve1_substep_min_m",
    "v_valve0_substep_min_m_s",
    "v_valve1_substep_min_m_s",
    "q_valve0_substep_min_m3_s",
    "q_valve1_substep_min_m3_s",
    "x_valve0_substep_max_m",
    "x_valve1_substep_max_m",
    "v_valve0_substep_max_m_s",
    "v_valve1_substep_max_m_s",
    "q_valve0_substep_max_m3_s",
    "q_valve1_substep_max_m3_s",
];

/// A channel holding the minimum or maximum of a quantity over the hydraulic sub-steps of a
/// structural step (the damper layout's last channels).
pub fn is_substep_envelope(name: &str) -> bool {
    name.contains("_substep_min_") || name.contains("_substep_max_")
}

/// Channels of the damper layout before the sub-step envelope.
const DAMPER_POINT_CHANNELS: usize = 11;

const ACTUATOR_CHANNELS: &[&str] = &[
    "p0_Pa",
    "p1_Pa",
    "q_orifice_m3_s",
    "x_valve0_m",
    "x_valve1_m",
    "q_valve0_m3_s",
    "q_valve1_m3_s",
    "q_check0_m3_s",
    "q_check1_m3_s",
    "q_entrance0_m3_s",
    "q_entrance1_m3_s",
    "v_valve0_m_s",
    "v_valve1_m_s",
];

impl CircuitDevice {
    pub fn new(params: CircuitParams, opts: IntegratorOptions) -> Self {
        let y0 = params.initial_state();
        let envelope = SubstepEnvelope::at(&params, 0.0, &y0);
        Self {
            params: Arc::new(params),
            opts,
            tangent: Tangent::Eq16,
            committed: y0,
            committed_t: 0.0,
            committed_d: 0.0,
            trial: None,
            envelope: Box::new([envelope; 2]),
            record_envelope: true,
        }
    }

    /// The envelope of the committed state alone, when recorded.
    fn envelope_at_commit(&self) -> SubstepEnvelope {
        if self.record_envelope {
            SubstepEnvelope::at(&self.params, self.committed_d, &self.committed)
        } else {
            SubstepEnvelope::NOT_RECORDED
        }
    }

    pub fn params(&self) -> &CircuitParams {
        &self.params
    }

    /// Mutable parameters (copy-on-write when shared with clones).
    pub fn params_mut(&mut self) -> &mut CircuitParams {
        Arc::make_mut(&mut self.params)
    }

    /// Selects the estimate of `dforce_dstroke`.
    pub fn set_tangent(&mut self, tangent: Tangent) {
        self.tangent = tangent;
    }

    pub fn options(&self) -> IntegratorOptions {
        self.opts
    }

    pub fn set_options(&mut self, opts: IntegratorOptions) {
        self.opts = opts;
    }

    /// Scale the actuator entrance orifice areas by `schedule(t)` (no effect without entrance
    /// orifices).
    pub fn set_orifice_area_schedule(&mut self, schedule: PiecewiseLinear) {
        if let Some(en) = &mut self.params_mut().entrance {
            en.area_schedule = Some(schedule);
        }
    }

    /// Committed state.
    pub fn state(&self) -> &State {
        &self.committed
    }

    /// Flows at the committed state.
    pub fn flows(&self) -> Flows {
        self.params
            .evaluate::<false>(
                self.committed_t,
                self.committed_d,
                0.0,
                &self.committed,
                None,
            )
            .map(|r| r.2)
            .unwrap_or_default()
    }
}

impl Device for CircuitDevice {
    fn step_along(&mut self, t_i: f64, path: &StrokePath) -> StepResult {
        let (dt, d_i, d_f) = (path.dt, path.d_i, path.d_f);
        let explicit = self.opts.scheme == Scheme::Rk4;
        let mut sys = StepSystem::new(&self.params, t_i, *path, explicit);
        // the step's start included, so consecutive envelopes join
        sys.envelope = self
            .record_envelope
            .then(|| SubstepEnvelope::at(&self.params, d_i, &self.committed));
        let mut y0 = self.committed;
        y0[IIMP] = 0.0;
        let y = integrate(&self.opts, &mut sys, t_i, dt, &y0)?;
        let envelope = sys.envelope.take().unwrap_or(SubstepEnvelope::NOT_RECORDED);
        let force_mean = y[IIMP] / dt;
        let dforce_dstroke = match self.tangent {
            Tangent::Eq16 => -0.5 * self.params.static_stiffness(&y, d_f),
            Tangent::FiniteDifference => {
                let c = &self.params.chambers[0];
                let h = 1e-7 * c.volume0 / c.area;
                sys.path = path.with_ends(d_i, d_f + h);
                sys.contact = None;
                let yh = integrate(&self.opts, &mut sys, t_i, dt, &y0)?;
                (yh[IIMP] / dt - force_mean) / h
            }
        };
        let out = StepForce {
            force_mean,
            dforce_dstroke,
            force_end: self.params.force(&y),
        };
        self.trial = Some((y, t_i + dt, d_f));
        self.envelope[1] = envelope;
        Ok(out)
    }

    fn commit(&mut self) {
        if let Some((y, t, d)) = self.trial.take() {
            self.committed = y;
            self.committed_t = t;
            self.committed_d = d;
            self.envelope[0] = self.envelope[1];
        }
    }

    fn channel_names(&self) -> &'static [&'static str] {
        if self.params.entrance.is_some() {
            ACTUATOR_CHANNELS
        } else {
            DAMPER_CHANNELS
        }
    }

    fn channels(&self, out: &mut [f64]) {
        let y = &self.committed;
        let fl = self.flows();
        let vals = [
            y[IP0],
            y[IP1],
            fl.orifice,
            y[IX0],
            y[IX1],
            fl.relief[0],
            fl.relief[1],
            fl.check[0],
            fl.check[1],
            fl.entrance[0],
            fl.entrance[1],
        ];
        // valve (poppet) velocities are appended after the other channels of either layout,
        // then (damper layout) the sub-step envelope
        let names = self.channel_names().len();
        let points = if self.params.entrance.is_some() {
            names
        } else {
            DAMPER_POINT_CHANNELS
        };
        let n = points - 2;
        for (o, v) in out.iter_mut().take(n).zip(vals) {
            *o = v;
        }
        if out.len() >= n + 2 {
            out[n] = y[IV0];
            out[n + 1] = y[IV1];
        }
        if points < names && out.len() >= names {
            let e = &self.envelope[0];
            out[points..points + 6].copy_from_slice(&e.min);
            out[points + 6..points + 12].copy_from_slice(&e.max);
        }
    }

    fn committed_force(&self) -> f64 {
        self.params.force(&self.committed)
    }

    fn force_scale(&self) -> f64 {
        let y = &self.committed;
        (y[IP0] * self.params.chambers[0].area).abs()
            + (y[IP1] * self.params.chambers[1].area).abs()
    }

    fn clone_device(&self) -> Box<dyn Device> {
        Box::new(self.clone())
    }

    fn reset(&mut self) {
        self.committed = self.params.initial_state();
        self.committed_t = 0.0;
        self.committed_d = 0.0;
        self.trial = None;
        self.envelope[0] = self.envelope_at_commit();
    }

    fn state_values(&self) -> Vec<f64> {
        let mut v: Vec<f64> = self.committed.iter().copied().collect();
        v.push(self.committed_t);
        v.push(self.committed_d);
        v
    }

    fn set_state_values(&mut self, v: &[f64]) -> Result<(), HydraulicError> {
        super::check_state_len("hydraulic circuit", v, NS + 2)?;
        self.committed = State::from_column_slice(&v[..NS]);
        self.committed_t = v[NS];
        self.committed_d = v[NS + 1];
        self.trial = None;
        // no sub-steps behind a restored state: its own values
        self.envelope[0] = self.envelope_at_commit();
        Ok(())
    }

    fn set_substep_envelope(&mut self, on: bool) {
        self.record_envelope = on;
        self.envelope[0] = self.envelope_at_commit();
    }
}

#[cfg(test)]
mod damper_rhs_tests {
    use super::*;
    use crate::hydraulics::extensions::{AnnularLeakage, Leakage};
    use crate::hydraulics::DamperDeck;

    fn damper() -> CircuitParams {
        let path = concat!(env!("CARGO_MANIFEST_DIR"), "/rotors/uh60a.toml");
        DamperDeck::from_file(std::path::Path::new(path))
            .unwrap()
            .physical
            .unwrap()
    }

    /// A reproducible uniform draw in [0, 1).
    fn draws(seed: u64) -> impl FnMut() -> f64 {
        let mut s = seed;
        move || {
            s = s
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (s >> 11) as f64 / (1u64 << 53) as f64
        }
    }

    /// The specialised right-hand side equals the general one bit for bit (every component,
    /// zero signs included) over states that visit every branch: pressure differences below,
    /// at and above the laminar transition of both signs, pressures below the supply (check
    /// valves open) and below zero (cavitation), seated and open poppets, both stroke rates.
    fn assert_bitwise(p: &CircuitParams, label: &str) {
        let fast = DamperRhs::new(p).unwrap_or_else(|| panic!("{label}: no fast path"));
        let mut u = draws(0x5eed);
        let dp_l = p.dp_laminar;
        for i in 0..20_000 {
            let mut y = State::zeros();
            let base = match i % 4 {
                0 => p.p_s * (2.0 * u() - 0.5),
                1 => 1e7 * u(),
                2 => -2e5 * u(),
                _ => p.p_s,
            };
            let dp = match i % 5 {
                0 => dp_l * (2.0 * u() - 1.0),
                1 => [dp_l, -dp_l, 0.0][i % 3],
                _ => 1e7 * (2.0 * u() - 1.0),
            };
            y[IP0] = base + dp;
            y[IP1] = base;
            for (ix, iv) in [(IX0, IV0), (IX1, IV1)] {
                y[ix] = match i % 3 {
                    0 => 0.0,
                    1 => 2e-3 * u(),
                    _ => 1e-3 * (2.0 * u() - 1.0),
                };
                y[iv] = if i % 7 == 0 { 0.0 } else { 2.0 * u() - 1.0 };
            }
            y[IIMP] = u();
            let d = 0.02 * (2.0 * u() - 1.0);
            let d_dot = if i % 11 == 0 {
                0.0
            } else {
                0.5 * (2.0 * u() - 1.0)
            };
            let t = u();
            let want = p.evaluate::<false>(t, d, d_dot, &y, None).unwrap().0;
            let got = fast.rhs(p, t, d, d_dot, &y).unwrap();
            for r in 0..NS {
                assert_eq!(
                    got[r].to_bits(),
                    want[r].to_bits(),
                    "{label}: f[{r}] {:e} vs {:e} at y = {y:?}, d = {d}, d_dot = {d_dot}",
                    got[r],
                    want[r]
                );
            }
        }
    }

    #[test]
    fn damper_rhs_is_the_general_rhs_bit_for_bit() {
        let full = damper();
        assert!(full.orifice.is_some() && full.check.is_some());
        assert!(full.relief.iter().all(Option::is_some));
        assert_bitwise(&full, "the example damper");
        let mut no_check = full.clone();
        no_check.check = None;
        assert_bitwise(&no_check, "no check valves");
        let mut no_orifice = full.clone();
        no_orifice.orifice = None;
        assert_bitwise(&no_orifice, "no orifice");
        let mut one_relief = full.clone();
        one_relief.relief[0] = None;
        assert_bitwise(&one_relief, "relief valve 1 alone");
        let mut no_relief = full.clone();
        no_relief.relief = [None, None];
        assert_bitwise(&no_relief, "no relief valves");
        let mut cavitating = full.clone();
        cavitating.fluid.p_cav = 1e5;
        assert_bitwise(&cavitating, "cavitation on");
        let mut viscous = full.clone();
        viscous.ext.orifice_viscosity = Some(crate::hydraulics::elements::OrificeViscosity {
            mu: 0.011,
            length: 3e-3,
        });
        assert_bitwise(&viscous, "viscous orifice");
    }

    #[test]
    fn extended_circuits_take_the_general_rhs() {
        let mut leaky = damper();
        leaky.ext.leakage = Some(AnnularLeakage::laminar(1e-12));
        assert!(DamperRhs::new(&leaky).is_none());
        let mut bleed = damper();
        bleed.ext.bleed = Some(Leakage { conductance: 1e-12 });
        assert!(DamperRhs::new(&bleed).is_none());
        let actuator = ActuatorParams::paper_table1().to_circuit();
        assert!(DamperRhs::new(&actuator).is_none());
    }
}
