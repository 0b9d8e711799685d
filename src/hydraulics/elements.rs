//! Basic hydraulic elements: chamber (Eqs. 1-2), orifice (Eq. 4), pressure relief valve
//! (Eqs. 5-7) and check valve. Each returns its contribution and the partial derivatives that
//! the implicit integrator's analytic Jacobian needs.
use super::fluid::Fluid;

/// Hydraulic chamber, Eqs. (1)-(2).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Chamber {
    /// Piston area A [m^2].
    pub area: f64,
    /// Volume V_0 at d = 0 [m^3].
    pub volume0: f64,
    /// lambda: +1 when a positive stroke grows the chamber, -1 otherwise.
    pub lambda: f64,
}

impl Chamber {
    /// Eq. (2): `V = V_0 + A lambda d`.
    #[inline]
    pub fn volume(&self, d: f64) -> f64 {
        self.volume0 + self.area * self.lambda * d
    }

    /// Eq. (1): `p_dot = B/V (Q - A lambda d_dot)`, with B of Eq. (3), and its partials
    /// (dp_dot/dp, dp_dot/dQ). Cavitation: when the net volume rate is an outflow the rate is
    /// scaled by the fluid's cavitation factor `s(p)`, so the pressure cannot be driven below
    /// zero; an inflow always raises the pressure at the full rate (refilling).
    #[inline]
    pub fn pressure_rate(
        &self,
        fluid: &Fluid,
        p: f64,
        v: f64,
        q: f64,
        d_dot: f64,
    ) -> (f64, f64, f64) {
        self.pressure_rate_with_bulk(fluid, fluid.bulk(p), p, v, q, d_dot)
    }

    /// [`Chamber::pressure_rate`] with the bulk modulus `(B, dB/dp)` given (e.g. the effective
    /// modulus of oil with entrained air).
    #[inline]
    pub fn pressure_rate_with_bulk(
        &self,
        fluid: &Fluid,
        (b, db): (f64, f64),
        p: f64,
        v: f64,
        q: f64,
        d_dot: f64,
    ) -> (f64, f64, f64) {
        let net = q - self.area * self.lambda * d_dot;
        Self::pressure_rate_of_net(fluid, (b, db), p, v, net)
    }

    /// Eq. (1) from the net volume rate into the chamber (inflows less `A lambda d_dot`):
    /// `(p_dot, dp_dot/dp, dp_dot/dQ)`. `1/V` multiplies: a division would lengthen the
    /// pressure's dependency chain, the cost of an explicit sub-step (docs/performance.md).
    #[inline(always)]
    pub fn pressure_rate_of_net(
        fluid: &Fluid,
        (b, db): (f64, f64),
        p: f64,
        v: f64,
        net: f64,
    ) -> (f64, f64, f64) {
        let iv = 1.0 / v;
        if net < 0.0 {
            let (s, ds) = fluid.cavitation_factor(p);
            (b * s * iv * net, (db * s + b * ds) * iv * net, b * s * iv)
        } else {
            (b * iv * net, db * iv * net, b * iv)
        }
    }
}

/// Eq. (1)'s factor of a chamber at one pressure and volume, for many net inflows (the linked
/// circuit's force balance): `B s(p)/V` where the net volume rate is an outflow, `B/V` otherwise.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RateFactors {
    pub outflow: f64,
    pub inflow: f64,
}

impl Chamber {
    /// The factors of [`Chamber::pressure_rate_with_bulk`] at bulk modulus `b`, cavitation factor
    /// `s` (of `p`) and volume `v`.
    #[inline(always)]
    pub fn rate_factors(b: f64, s: f64, v: f64) -> RateFactors {
        let iv = 1.0 / v;
        RateFactors {
            outflow: b * s * iv,
            inflow: b * iv,
        }
    }

    /// `(p_dot, dp_dot/dQ)` of [`Chamber::pressure_rate_with_bulk`] from its factors: the same
    /// operations in the same order, so the same bits.
    #[inline(always)]
    pub fn rate_with(&self, f: &RateFactors, q: f64, d_dot: f64) -> (f64, f64) {
        let net = q - self.area * self.lambda * d_dot;
        if net < 0.0 {
            (f.outflow * net, f.outflow)
        } else {
            (f.inflow * net, f.inflow)
        }
    }
}

/// Turbulent orifice law with a laminar transition: the "unit" flow `u(dp)` such that
/// `Q = C_d A u(dp)`. For |dp| >= dp_l, `u = sign(dp) sqrt(2|dp|/rho)` (Eq. 4); below, the odd
/// cubic `u = sqrt(2 dp_l/rho) (5 r - r^3)/4`, r = dp/dp_l, which matches value and slope at
/// |dp| = dp_l (C1) and keeps the law Lipschitz. dp_l -> 0 recovers Eq. (4).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FlowLaw {
    pub rho: f64,
    pub dp_laminar: f64,
}

impl FlowLaw {
    /// One-sided law of a check valve that opens progressively: 0 for dp <= 0,
    /// `u_l (5 r^2 - 3 r^3)/2` on (0, dp_l), Eq. (4) beyond; C1 everywhere (also at dp = 0, where
    /// a plain `max(dp, 0)` would kink and stall Newton).
    #[inline]
    pub fn one_sided_flow(&self, dp: f64) -> (f64, f64) {
        if dp <= 0.0 {
            (0.0, 0.0)
        } else if dp >= self.dp_laminar {
            self.unit_flow(dp)
        } else {
            let u_l = (2.0 * self.dp_laminar / self.rho).sqrt();
            let r = dp / self.dp_laminar;
            (
                u_l * (5.0 * r * r - 3.0 * r * r * r) * 0.5,
                u_l * (10.0 * r - 9.0 * r * r) * 0.5 / self.dp_laminar,
            )
        }
    }

    /// u(dp) and du/d(dp).
    #[inline]
    pub fn unit_flow(&self, dp: f64) -> (f64, f64) {
        let a = dp.abs();
        if a >= self.dp_laminar {
            let u = (a * (2.0 / self.rho)).sqrt();
            (u.copysign(dp), u / (2.0 * a))
        } else {
            let u_l = (2.0 * self.dp_laminar / self.rho).sqrt();
            let r = dp / self.dp_laminar;
            (
                u_l * (5.0 * r - r * r * r) * 0.25,
                u_l * (5.0 - 3.0 * r * r) * 0.25 / self.dp_laminar,
            )
        }
    }
}

/// Fixed orifice, Eq. (4): flow from the node at `p_from` to the node at `p_to`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Orifice {
    /// Sectional area A_orf [m^2].
    pub area: f64,
    /// Discharge coefficient C_d.
    pub cd: f64,
}

impl Orifice {
    /// Q (positive from `from` to `to`) and dQ/d(p_from - p_to).
    #[inline]
    pub fn flow(&self, law: &FlowLaw, dp: f64) -> (f64, f64) {
        let (u, du) = law.unit_flow(dp);
        (self.cd * self.area * u, self.cd * self.area * du)
    }
}

/// Discharge constant delta of a sharp-edged circular orifice at low Reynolds number, where
/// `C_d = delta sqrt(Re)` (Merritt, Hydraulic Control Systems, 1967, Sec. 3.2, after Wuest).
pub const ORIFICE_LAMINAR_DELTA: f64 = 0.2;

/// What the viscous orifice law needs beyond Eq. (4): the oil's dynamic viscosity and the length
/// of the orifice's bore (deck keys `mu_Pa_s`, `orifice_length_m`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct OrificeViscosity {
    /// Dynamic viscosity mu [Pa s] (follows the oil temperature, `temperature.rs`).
    pub mu: f64,
    /// Bore length L [m] (>= 0; 0: a sharp edge only).
    pub length: f64,
}

impl OrificeViscosity {
    /// Laminar resistance `R_lam = mu/(2 delta^2 d A) + 128 mu L/(pi d^4)` [Pa s/m^3] of an
    /// orifice of area `area`, `d = sqrt(4 A/pi)`: the sharp edge's low-Reynolds discharge law
    /// (`C_d = delta sqrt(Re)`, `Re = d Q/(A nu)`, in Eq. 4 gives `Q = 2 delta^2 d A dp/mu`) in
    /// series with Hagen-Poiseuille flow through the bore.
    pub fn laminar_resistance(&self, area: f64) -> f64 {
        use std::f64::consts::PI;
        let d = (4.0 * area / PI).sqrt();
        let edge = self.mu / (2.0 * ORIFICE_LAMINAR_DELTA * ORIFICE_LAMINAR_DELTA * d * area);
        let bore = 128.0 * self.mu * self.length / (PI * d.powi(4));
        edge + bore
    }

    /// The law `dp = R Q + k Q|Q|` of `orifice` in oil of density `rho`.
    pub fn law(&self, orifice: &Orifice, rho: f64) -> ViscousOrificeLaw {
        let cda = orifice.cd * orifice.area;
        ViscousOrificeLaw {
            r: self.laminar_resistance(orifice.area),
            k: rho / (2.0 * cda * cda),
        }
    }
}

/// Laminar-to-turbulent orifice: `dp = R Q + k Q|Q|`, with `k = rho/(2 C_d^2 A^2)` (Eq. 4's
/// turbulent limit) and R the laminar resistance ([`OrificeViscosity::laminar_resistance`]).
/// Smooth (C-infinity but at dp = 0, where it is C1) with the finite slope `1/R` at zero: no
/// regularisation.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ViscousOrificeLaw {
    /// Laminar resistance R [Pa s/m^3].
    pub r: f64,
    /// Turbulent coefficient k [Pa s^2/m^6].
    pub k: f64,
}

impl ViscousOrificeLaw {
    /// Q and dQ/d(dp): the root `Q = sign(dp) (-R + S)/(2k)`, `S = sqrt(R^2 + 4 k |dp|)`,
    /// written `2 dp/(R + S)` (no cancellation at small dp); `dQ/d(dp) = 1/S` (1/R at 0).
    #[inline(always)]
    pub fn flow(&self, dp: f64) -> (f64, f64) {
        let s = (self.r * self.r + 4.0 * self.k * dp.abs()).sqrt();
        (2.0 * dp / (self.r + s), 1.0 / s)
    }
}

/// Pressure relief valve, Eqs. (5)-(7). The poppet state is (x, x_dot); `x >= 0` (the seat).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ReliefValve {
    /// Poppet mass m [kg].
    pub m: f64,
    /// Poppet dashpot c [N s/m].
    pub c: f64,
    /// Spring constant k [N/m].
    pub k: f64,
    /// Spring preload F_p [N].
    pub f_p: f64,
    /// Area under the relieved chamber's pressure (A_0 of Eq. 5) [m^2].
    pub a_front: f64,
    /// Area under the other chamber's pressure (A_1 of Eq. 5) [m^2].
    pub a_back: f64,
    /// Flow area coefficients of Eq. (7): `A_prvl = a x + b x^2` [m], [-].
    pub a: f64,
    pub b: f64,
    /// Discharge coefficient.
    pub cd: f64,
}

/// Poppet rates of a relief valve and whether the seat holds it closed.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PoppetRate {
    pub x_dot: f64,
    pub v_dot: f64,
    /// The seat holds the poppet: x = x_dot = 0 and the opening force does not exceed F_p.
    pub held: bool,
}

impl ReliefValve {
    /// Net opening force `p_front A_0 - p_back A_1 - F_p` (Eq. 5 right-hand side).
    #[inline]
    pub fn opening_force(&self, p_front: f64, p_back: f64) -> f64 {
        p_front * self.a_front - p_back * self.a_back - self.f_p
    }

    /// Eq. (5) with the seat: a poppet at (or, numerically, below) the seat that is not moving
    /// away from it stays closed while the opening force is not positive.
    #[inline]
    pub fn poppet_rate(&self, p_front: f64, p_back: f64, x: f64, v: f64) -> PoppetRate {
        let f = self.opening_force(p_front, p_back);
        if x <= 0.0 && v <= 0.0 && f <= 0.0 {
            return PoppetRate {
                x_dot: 0.0,
                v_dot: 0.0,
                held: true,
            };
        }
        PoppetRate {
            x_dot: v,
            v_dot: (f - self.k * x - self.c * v) * (1.0 / self.m),
            held: false,
        }
    }

    /// Eq. (5) with the contact decided by the caller: `held` keeps the poppet still on its
    /// seat; otherwise the free Eq. (5) applies (also slightly below the seat; the integrator
    /// projects back after the sub-step).
    #[inline]
    pub fn poppet_rate_with(
        &self,
        p_front: f64,
        p_back: f64,
        x: f64,
        v: f64,
        held: bool,
    ) -> PoppetRate {
        if held {
            return PoppetRate {
                x_dot: 0.0,
                v_dot: 0.0,
                held: true,
            };
        }
        let f = self.opening_force(p_front, p_back);
        PoppetRate {
            x_dot: v,
            v_dot: (f - self.k * x - self.c * v) * (1.0 / self.m),
            held: false,
        }
    }

    /// Eq. (7): flow area and its derivative in x; zero for x <= 0.
    #[inline]
    pub fn flow_area(&self, x: f64) -> (f64, f64) {
        if x > 0.0 {
            (self.a * x + self.b * x * x, self.a + 2.0 * self.b * x)
        } else {
            (0.0, 0.0)
        }
    }

    /// Eq. (6): flow from the relieved chamber to the other one, with dQ/d(dp) and dQ/dx.
    #[inline]
    pub fn flow(&self, law: &FlowLaw, dp: f64, x: f64) -> (f64, f64, f64) {
        let (area, darea) = self.flow_area(x);
        if area == 0.0 {
            return (0.0, 0.0, 0.0);
        }
        let (u, du) = law.unit_flow(dp);
        (self.cd * area * u, self.cd * area * du, self.cd * darea * u)
    }

    /// Poppet lift at static equilibrium under a given opening force (for tests and design).
    pub fn static_lift(&self, p_front: f64, p_back: f64) -> f64 {
        (self.opening_force(p_front, p_back) / self.k).max(0.0)
    }
}

/// Check valve from the background (plenum) pressure p_s into a chamber: it conducts only when
/// the chamber pressure is below p_s, with the orifice law of Eq. (4) beyond `dp_l` and a
/// progressive C1 opening below ([`FlowLaw::one_sided_flow`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CheckValve {
    /// Open flow area [m^2].
    pub area: f64,
    /// Discharge coefficient.
    pub cd: f64,
}

impl CheckValve {
    /// Inflow from the plenum at `p_s` into a chamber at `p`, and dQ/dp.
    #[inline]
    pub fn inflow(&self, law: &FlowLaw, p_s: f64, p: f64) -> (f64, f64) {
        let (u, du) = law.one_sided_flow(p_s - p);
        (self.cd * self.area * u, -self.cd * self.area * du)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The shipped orifice (1.8e-6 m^2, Cd 0.611) in oil of mu = 0.011 Pa s with a 3 mm bore.
    fn shipped_law() -> ViscousOrificeLaw {
        let o = Orifice {
            area: 1.8e-6,
            cd: 0.611,
        };
        OrificeViscosity {
            mu: 0.011,
            length: 3.0e-3,
        }
        .law(&o, 850.0)
    }

    #[test]
    fn viscous_orifice_inverts_its_pressure_law() {
        let law = shipped_law();
        for dp in [0.0f64, 1e-3, 1.0, 1e3, 1e5, 3e6, 2e7] {
            for dp in [dp, -dp] {
                let (q, _) = law.flow(dp);
                // dp = R Q + k Q|Q| written out
                let back = law.r * q + law.k * q * q.abs();
                assert!(
                    (back - dp).abs() <= 1e-12 * dp.abs().max(1.0),
                    "{dp} -> {q} -> {back}"
                );
                assert_eq!(law.flow(-dp).0, -q);
            }
        }
        // laminar and turbulent limits
        let (q, dq) = law.flow(1e-6);
        // Q = (dp/R)(1 - k dp/R^2 + ...), dQ/d(dp) = (1/R)(1 - 2 k dp/R^2 + ...)
        let e = law.k * 1e-6 / (law.r * law.r);
        assert!((q / (1e-6 / law.r) - 1.0).abs() < 1.01 * e);
        assert!((dq * law.r - 1.0).abs() < 2.01 * e);
        let dp = 2e7;
        let q_t = (dp / law.k).sqrt();
        let (q, _) = law.flow(dp);
        // Q = Q_t (1 - R/(2 sqrt(k dp)) + ...)
        let expect = q_t - law.r / (2.0 * law.k);
        assert!((q - expect).abs() < 1e-3 * (q_t - expect), "{q} {expect}");
    }

    #[test]
    fn viscous_orifice_slope_is_the_finite_difference() {
        let law = shipped_law();
        for dp in [0.0f64, 0.5, 30.0, 1e3, 4e4, 1e6, 1e7] {
            for dp in [dp, -dp] {
                let h = 1e-6 * dp.abs().max(1.0);
                let fd = (law.flow(dp + h).0 - law.flow(dp - h).0) / (2.0 * h);
                let (_, dq) = law.flow(dp);
                assert!((fd - dq).abs() < 1e-6 * dq, "dp {dp}: {dq} vs {fd}");
            }
        }
        assert_eq!(law.flow(0.0).1, 1.0 / law.r);
    }

    #[test]
    fn laminar_resistance_is_merritt_plus_poiseuille() {
        // written out for A = 1.8e-6 m^2: d = 1.51388 mm
        let a: f64 = 1.8e-6;
        let d = (4.0 * a / std::f64::consts::PI).sqrt();
        let (mu, l) = (0.011, 3.0e-3);
        let edge = mu / (2.0 * 0.04 * d * a);
        let bore = 128.0 * mu * l / (std::f64::consts::PI * d * d * d * d);
        let r = OrificeViscosity { mu, length: l }.laminar_resistance(a);
        assert!((r - (edge + bore)).abs() < 1e-12 * r);
        // the edge term from Cd = delta sqrt(Re) in Eq. (4) at a small flow
        let q = 1e-8;
        let re = d * q / (a * mu / 850.0);
        let cd = 0.2 * re.sqrt();
        let dp_edge = 850.0 / 2.0 * (q / (cd * a)).powi(2);
        assert!((dp_edge - edge * q).abs() < 1e-9 * dp_edge);
    }

    #[test]
    fn unit_flow_is_odd_and_c1_at_transition() {
        let law = FlowLaw {
            rho: 850.0,
            dp_laminar: 1.0e3,
        };
        for dp in [1.0, 10.0, 999.0, 1.0e3, 5.0e4, 1.0e7] {
            let (a, da) = law.unit_flow(dp);
            let (b, db) = law.unit_flow(-dp);
            assert_eq!(a, -b);
            assert_eq!(da, db);
        }
        let e = 1.0e-9 * law.dp_laminar;
        let (lo, dlo) = law.unit_flow(law.dp_laminar - e);
        let (hi, dhi) = law.unit_flow(law.dp_laminar + e);
        assert!((lo - hi).abs() < 1e-9 * hi, "value jump {lo} {hi}");
        assert!((dlo - dhi).abs() < 1e-6 * dhi, "slope jump {dlo} {dhi}");
        let (lo, dlo) = law.one_sided_flow(law.dp_laminar - e);
        assert!((lo - hi).abs() < 1e-9 * hi && (dlo - dhi).abs() < 1e-6 * dhi);
        assert_eq!(law.one_sided_flow(0.0), (0.0, 0.0));
        assert_eq!(law.one_sided_flow(-5.0), (0.0, 0.0));
        // Beyond the transition it is Eq. (4) exactly.
        let (u, _) = law.unit_flow(2.0e6);
        assert_eq!(u, (2.0 * 2.0e6 / 850.0f64).sqrt());
    }
}
