//! Hydraulic fluid: density and the pressure-dependent bulk modulus of Eq. (3).

/// Fluid properties.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Fluid {
    /// Mass density rho [kg/m^3].
    pub rho: f64,
    /// alpha of Eq. (3) [1/Pa]; with beta = 0 the bulk modulus is 1/alpha + p.
    pub alpha: f64,
    /// beta of Eq. (3) [1/Pa^2].
    pub beta: f64,
    /// Cavitation band [Pa]: a chamber losing volume has its pressure rate scaled by
    /// `1 - exp(-p/p_cav)`, so its pressure cannot be driven below zero (0 disables; see
    /// docs/hydraulics.md).
    pub p_cav: f64,
}

impl Fluid {
    /// Fluid with a constant bulk modulus `b` [Pa] (alpha = 1/B, beta = 0).
    pub fn constant_bulk(rho: f64, b: f64) -> Self {
        Self {
            rho,
            alpha: 1.0 / b,
            beta: 0.0,
            p_cav: 0.0,
        }
    }

    /// Bulk modulus of Eq. (3), `B = (1 + alpha p + beta p^2) / (alpha + 2 beta p)`, and dB/dp.
    #[inline]
    pub fn bulk(&self, p: f64) -> (f64, f64) {
        if self.beta == 0.0 {
            // B = (1 + alpha p)/alpha as a product: no division on the pressure's chain
            return ((1.0 + self.alpha * p) * (1.0 / self.alpha), 1.0);
        }
        let num = 1.0 + self.alpha * p + self.beta * p * p;
        let den = self.alpha + 2.0 * self.beta * p;
        let b = num / den;
        // d/dp (num/den) = 1 - 2 beta num / den^2
        (b, 1.0 - 2.0 * self.beta * num / (den * den))
    }

    /// `s(p) = 1 - exp(-p/p_cav)` for p >= 0, continued linearly (C1) below zero.
    #[inline]
    pub fn cavitation_factor(&self, p: f64) -> (f64, f64) {
        if self.p_cav <= 0.0 || p > 40.0 * self.p_cav {
            return (1.0, 0.0);
        }
        if p >= 0.0 {
            let e = (-p / self.p_cav).exp();
            (1.0 - e, e / self.p_cav)
        } else {
            (p / self.p_cav, 1.0 / self.p_cav)
        }
    }

    /// Pressure of a sealed chamber after its volume goes from `v0` to `v` starting at `p0`:
    /// the integral of Eq. (1) with Q = 0 and Eq. (3), `(1 + alpha p + beta p^2) V = const`
    /// (no cavitation factor).
    pub fn sealed_pressure(&self, p0: f64, v0: f64, v: f64) -> f64 {
        let c = (1.0 + self.alpha * p0 + self.beta * p0 * p0) * v0 / v;
        if self.beta == 0.0 {
            (c - 1.0) / self.alpha
        } else {
            // beta p^2 + alpha p + (1 - c) = 0, the root continuous with p0.
            let disc = self.alpha * self.alpha - 4.0 * self.beta * (1.0 - c);
            (-self.alpha + disc.sqrt()) / (2.0 * self.beta)
        }
    }
}
