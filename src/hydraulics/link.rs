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
//! balance holds to round-off while the link stays in one regime; a sub-step that crosses into or
//! out of contact is put back on it by a projection (contact) or relaxes to it over a few
//! sub-steps (inside the gap, `F_dot = -F/tau`).
use super::circuit::{CircuitDevice, CircuitParams, State, IIMP, IP0, IP1, IV0, IV1, IX0, IX1, NS};
use super::integrators::{integrate, IntegratorOptions, OdeSystem};
use super::{check_step, Device, HydraulicError, StepForce};
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

/// The circuit and link over one step, the end's stroke linear in time from `d_i` at `t_i`.
struct LinkSystem<'a> {
    params: &'a CircuitParams,
    link: Link,
    t_i: f64,
    d_i: f64,
    d_dot: f64,
    tau: f64,
}

#[inline]
fn circuit_part(y: &LState) -> State {
    State::from_fn(|i, _| y[i])
}

/// Eq. (1) of both chambers at one state as affine functions of the piston velocity `v`:
/// `p_dot_k = g_k(net_k) net_k`, `net_k = qn_k - A_k lambda_k v`, with `g_k = B/V` on an inflow and
/// `B s(p)/V` on an outflow (the cavitation factor).
struct Rates {
    qn: [f64; 2],
    a_lambda: [f64; 2],
    area: [f64; 2],
    g_in: [f64; 2],
    g_out: [f64; 2],
}

impl Rates {
    /// `h(v) = A0 p0_dot - A1 p1_dot - k_c (v - d_dot) + relax`, its slope, and the two rates.
    #[inline]
    fn balance(&self, k_c: f64, d_dot: f64, relax: f64, v: f64) -> (f64, f64, [f64; 2]) {
        let mut rate = [0.0; 2];
        let mut slope = [0.0; 2];
        for k in 0..2 {
            let net = self.qn[k] - self.a_lambda[k] * v;
            let g = if net < 0.0 {
                self.g_out[k]
            } else {
                self.g_in[k]
            };
            rate[k] = g * net;
            slope[k] = -g * self.a_lambda[k];
        }
        (
            self.area[0] * rate[0] - self.area[1] * rate[1] - k_c * (v - d_dot) + relax,
            self.area[0] * slope[0] - self.area[1] * slope[1] - k_c,
            rate,
        )
    }
}

impl OdeSystem<NL> for LinkSystem<'_> {
    fn rhs(&self, t: f64, y: &LState) -> Result<LState, HydraulicError> {
        let d = self.d_i + self.d_dot * (t - self.t_i);
        let e = y[IE];
        let yc = circuit_part(y);
        let part = self.params.flow_part::<false>(t, d + e, &yc, None)?;
        let (f_link, contact) = self.link.force(e);
        let k_c = if contact { self.link.k } else { 0.0 };
        // Inside the gap the force relaxes to zero; in contact the projection keeps the balance.
        let relax = if contact {
            0.0
        } else {
            (self.params.force(&yc) - f_link) / self.tau
        };
        let mut rt = Rates {
            qn: part.qn,
            a_lambda: [0.0; 2],
            area: [0.0; 2],
            g_in: [0.0; 2],
            g_out: [0.0; 2],
        };
        // h is continuous, decreasing and affine between the velocities where a chamber's net
        // inflow changes sign with a cavitation factor below one: the root lies between the
        // kinks that bracket it, where one affine solve finds it.
        let mut kinks = [f64::NAN; 2];
        for k in 0..2 {
            let c = &self.params.chambers[k];
            let p = yc[if k == 0 { IP0 } else { IP1 }];
            let (b, _) = self.params.bulk(k, p);
            let s = self.params.fluid.cavitation_factor(p).0;
            rt.a_lambda[k] = c.area * c.lambda;
            rt.area[k] = c.area;
            rt.g_in[k] = b / part.vol[k];
            rt.g_out[k] = b * s / part.vol[k];
            if s != 1.0 {
                kinks[k] = part.qn[k] / rt.a_lambda[k];
            }
        }
        if kinks[0] > kinks[1] || kinks[0].is_nan() {
            kinks.swap(0, 1);
        }
        let d_dot = self.d_dot;
        let (mut lo, mut hi) = (f64::NEG_INFINITY, f64::INFINITY);
        for &v in kinks.iter().filter(|v| v.is_finite()) {
            if rt.balance(k_c, d_dot, relax, v).0 > 0.0 {
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
        let (h, slope, _) = rt.balance(k_c, d_dot, relax, probe);
        // A slope of zero: nothing resists the piston (both chambers emptied inside the gap);
        // it then moves with the end.
        let v = if slope < 0.0 {
            (probe - h / slope).clamp(lo, hi)
        } else {
            d_dot
        };
        let (_, _, rates) = rt.balance(k_c, d_dot, relax, v);
        let mut f = LState::zeros();
        for i in 0..NS {
            f[i] = part.f[i];
        }
        f[IP0] = rates[0];
        f[IP1] = rates[1];
        f[IE] = v - self.d_dot;
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

/// The physical damper behind a massless link (compliant free play or series mount), integrated
/// as one ODE with the link deflection (module docs). Same model, force, tangent and state
/// layout as [`CompliantFreePlay`](super::CompliantFreePlay) or
/// [`SeriesMount`](super::SeriesMount) around a [`CircuitDevice`], at one integration per step.
#[derive(Debug, Clone)]
pub struct LinkedCircuit {
    /// The circuit at the committed state (its stroke the piston's `d_h`).
    inner: CircuitDevice,
    link: Link,
    d_h: f64,
    fresh: bool,
    trial: Option<(State, f64, f64)>,
}

impl LinkedCircuit {
    /// A compliant free play (`gap_m > 0`) or a series mount (`gap_m = 0`) of stiffness
    /// `k_n_per_m` around `inner`, integrated with its options (explicit schemes only).
    pub fn new(inner: CircuitDevice, gap_m: f64, k_n_per_m: f64) -> Self {
        Self {
            inner,
            link: Link {
                half_gap: 0.5 * gap_m,
                k: k_n_per_m,
            },
            d_h: 0.0,
            fresh: true,
            trial: None,
        }
    }

    /// Piston stroke behind the link at the committed state [m].
    pub fn device_stroke(&self) -> f64 {
        self.d_h
    }

    /// The link (gap and contact stiffness).
    pub fn link(&self) -> Link {
        self.link
    }
}

impl Device for LinkedCircuit {
    fn trial_step(
        &mut self,
        t_i: f64,
        dt: f64,
        d_i: f64,
        d_f: f64,
    ) -> Result<StepForce, HydraulicError> {
        check_step(t_i, dt, d_i, d_f)?;
        if self.fresh {
            self.d_h = d_i + self.link.deflection_of(self.inner.committed_force());
        }
        let opts: IntegratorOptions = self.inner.options();
        let params = self.inner.params();
        let n = opts.substeps.max(1);
        let mut sys = LinkSystem {
            params,
            link: self.link,
            t_i,
            d_i,
            d_dot: (d_f - d_i) / dt,
            tau: RELAX_SUBSTEPS * dt / n as f64,
        };
        let mut y0 = LState::zeros();
        for (i, v) in self.inner.state().iter().enumerate() {
            y0[i] = *v;
        }
        y0[IIMP] = 0.0;
        y0[IE] = self.d_h - d_i;
        let y = integrate(&opts, &mut sys, t_i, dt, &y0)?;
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
        let out = StepForce {
            force_mean: y[IIMP] / dt,
            dforce_dstroke,
            force_end: params.force(&yc),
        };
        self.trial = Some((yc, t_i + dt, d_h));
        Ok(out)
    }

    fn commit(&mut self) {
        if let Some((y, t, d_h)) = self.trial.take() {
            let mut v = [0.0; NS + 2];
            v[..NS].copy_from_slice(y.as_slice());
            v[NS] = t;
            v[NS + 1] = d_h;
            // Finite by construction (the integrator refuses a non-finite state).
            let _ = self.inner.set_state_values(&v);
            self.d_h = d_h;
            self.fresh = false;
        }
    }

    series_link_state_methods!("linked circuit");
}
