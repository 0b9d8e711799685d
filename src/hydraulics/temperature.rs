//! Oil temperature: the circuit's oil properties moved from the temperature at which a data
//! sheet gives them to another. Hydraulic oils thin, expand and soften as they warm; over the
//! range a damper sees (-40 to +90 C) each property follows an exponential in temperature well
//! enough (Walther/Reynolds for viscosity, a constant expansion coefficient for density, the
//! isothermal tangent modulus falling ~0.5%/K):
//! - density `rho(T) = rho_ref exp(-c_rho (T - T_ref))` (orifice, relief and check flows, Eq. 4);
//! - bulk modulus: alpha and beta of Eq. (3) scaled by g and g^2, `g = exp(c_B (T - T_ref))`,
//!   so that `B_T(p) = B_ref(g p) / g`: the zero-pressure modulus falls by the factor g;
//! - viscosity `mu(T) = mu_ref exp(-c_mu (T - T_ref))`: the laminar conductances (piston
//!   leakage, accumulator bleed) scale by 1/mu, the leakage's `mu L` by mu (its clearance stays),
//!   and the viscous orifice's `mu` (its laminar resistance) by mu.
//!
//! Exponentials compose: moving from T1 to T2 and on to T3 is moving from T1 to T3 (up to
//! rounding). The valves' numerical laminar transition (`dp_laminar_Pa`) is left as given.
use super::circuit::CircuitParams;

/// Oil temperatures that make sense [K]: from below any cold day to above any oil's flash point.
pub const OIL_TEMPERATURE_RANGE_K: (f64, f64) = (150.0, 600.0);
/// Whether `t_k` is an oil temperature that makes sense (within [`OIL_TEMPERATURE_RANGE_K`]).
pub fn is_oil_temperature_k(t_k: f64) -> bool {
    (OIL_TEMPERATURE_RANGE_K.0..=OIL_TEMPERATURE_RANGE_K.1).contains(&t_k)
}

/// What an oil temperature must be, as error messages say it.
pub fn oil_temperature_expected() -> String {
    let (lo, hi) = OIL_TEMPERATURE_RANGE_K;
    format!("an absolute temperature in K, {lo} to {hi}")
}

/// Largest temperature coefficient that makes sense [1/K] (a factor e per 10 K).
pub const OIL_COEFFICIENT_MAX_PER_K: f64 = 0.1;

/// The oil's temperature and its properties' temperature coefficients (`[damper.physical.oil]`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct OilTemperature {
    /// Temperature at which the circuit's properties hold [K].
    pub temperature_k: f64,
    /// c_rho [1/K]: the density's volumetric expansion coefficient (~7e-4 for mineral oils).
    pub density_per_k: f64,
    /// c_B [1/K]: the fractional fall of the bulk modulus per kelvin (~5e-3).
    pub bulk_modulus_per_k: f64,
    /// c_mu [1/K]: the fractional fall of the viscosity per kelvin (~0.02-0.04).
    pub viscosity_per_k: f64,
}

impl OilTemperature {
    /// The exponent `c (T - T_ref)` of the laws below at which a property has lost `fraction`
    /// of its value (`1 - exp(-c dT) = fraction`): a coefficient per K times a warming.
    pub fn loss_exponent(fraction: f64) -> f64 {
        -(1.0 - fraction).ln()
    }

    /// `c` with its oil properties moved from `self.temperature_k` to `t_k`; returns the law at
    /// its new temperature.
    pub fn move_to(&self, c: &mut CircuitParams, t_k: f64) -> OilTemperature {
        let dt = t_k - self.temperature_k;
        c.fluid.rho *= (-self.density_per_k * dt).exp();
        let g = (self.bulk_modulus_per_k * dt).exp();
        c.fluid.alpha *= g;
        c.fluid.beta *= g * g;
        // mu(T) / mu(T_ref)
        let mu = (-self.viscosity_per_k * dt).exp();
        if let Some(l) = c.ext.leakage.as_mut() {
            l.conductance /= mu;
            l.viscosity_length *= mu;
        }
        if let Some(b) = c.ext.bleed.as_mut() {
            b.conductance /= mu;
        }
        // the orifice's laminar resistance is proportional to mu
        if let Some(v) = c.ext.orifice_viscosity.as_mut() {
            v.mu *= mu;
        }
        OilTemperature {
            temperature_k: t_k,
            ..*self
        }
    }
}
