//! Quasi-steady blade element: the airloads of one section from the air's velocity relative to
//! it (docs/aerodynamics.md).
//!
//! Section axes as the beam's: 1 along the span (outboard), 2 toward the leading edge, 3 up
//! (normal). The reference line is the quarter chord; the angle of attack is taken from the
//! velocity at the three-quarter chord (the pitch-rate term of thin-aerofoil theory: a section
//! pitching at `w1` sees `w1 c/2` more upwash there), the forces act at the quarter chord.
//!
//! Yawed flow: the independence principle. The spanwise component of the relative velocity
//! (along axis 1) carries no lift and does not enter the dynamic pressure, the angle of attack
//! or the Mach number; the section sees the velocity in its own plane (axes 2, 3).
use super::airfoil::{Airfoil, ClampCounts, Coefficients};

/// What one section sees and produces (per unit span).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct SectionAirloads {
    /// Angle of attack [rad] (positive: the air comes from below the chord).
    pub alpha_rad: f64,
    /// Mach number of the in-plane velocity.
    pub mach: f64,
    pub coefficients: Coefficients,
    /// Dynamic pressure of the in-plane velocity [Pa].
    pub q_pa: f64,
    /// Force per span in section axes [N/m] (axis 2 toward the leading edge, 3 up).
    pub force_n_per_m: [f64; 3],
    /// Pitching moment per span about axis 1 at the quarter chord [N m/m], nose up positive.
    pub moment_n_m_per_m: f64,
}

impl SectionAirloads {
    /// Normal force [N/m] (along axis 3), as the record's `normal_N_per_m`.
    pub fn normal_n_per_m(&self) -> f64 {
        self.force_n_per_m[2]
    }
    /// Chord force [N/m] (positive toward the trailing edge), as the record's `chord_N_per_m`.
    pub fn chord_n_per_m(&self) -> f64 {
        -self.force_n_per_m[1]
    }
}

/// Section properties the element needs.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Air {
    pub density_kg_m3: f64,
    pub speed_of_sound_m_s: f64,
}

/// The airloads of a section of chord `chord_m` whose three-quarter-chord point sees the air
/// moving at `u` relative to it (section axes) [m/s]; `lift_factor` scales the lift (tip
/// loss: 0 outboard of the effective tip). Drag acts along the in-plane relative velocity,
/// lift perpendicular to it.
pub fn blade_element(
    u: [f64; 3],
    chord_m: f64,
    air: &Air,
    airfoil: &Airfoil,
    clamps: &ClampCounts,
    lift_factor: f64,
) -> SectionAirloads {
    let (ut, up) = (-u[1], u[2]);
    let speed2 = ut * ut + up * up;
    if speed2 == 0.0 {
        return SectionAirloads::default();
    }
    let speed = speed2.sqrt();
    let alpha = up.atan2(ut);
    let mach = speed / air.speed_of_sound_m_s;
    let c = airfoil.coefficients(alpha, mach, clamps);
    let q = 0.5 * air.density_kg_m3 * speed2;
    let (cl, cd) = (lift_factor * c.cl, c.cd);
    // drag along (0, u2, u3)/|u|, lift along (0, u3, -u2)/|u| (up for air from ahead)
    let (d2, d3) = (u[1] / speed, u[2] / speed);
    let (l2, l3) = (d3, -d2);
    let k = q * chord_m;
    SectionAirloads {
        alpha_rad: alpha,
        mach,
        coefficients: Coefficients { cl, cd, cm: c.cm },
        q_pa: q,
        force_n_per_m: [0.0, k * (cl * l2 + cd * d2), k * (cl * l3 + cd * d3)],
        moment_n_m_per_m: k * chord_m * c.cm,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::aero::airfoil::ThinAirfoil;

    fn thin(cd0: f64) -> Airfoil {
        Airfoil::Thin(ThinAirfoil {
            cd0,
            ..Default::default()
        })
    }

    const AIR: Air = Air {
        density_kg_m3: 1.2,
        speed_of_sound_m_s: 340.0,
    };

    /// Air from ahead and below at alpha: lift 2 pi alpha q c normal to the flow, drag along it.
    #[test]
    fn lift_is_normal_to_the_flow_and_drag_along_it() {
        let (v, alpha, c) = (200.0_f64, 0.1_f64, 0.5);
        let u = [7.0, -v * alpha.cos(), v * alpha.sin()];
        let s = blade_element(u, c, &AIR, &thin(0.01), &ClampCounts::default(), 1.0);
        assert!((s.alpha_rad - alpha).abs() < 1e-15);
        assert!((s.mach - v / 340.0).abs() < 1e-15);
        let q = 0.5 * 1.2 * v * v;
        let (l, d) = (q * c * 2.0 * std::f64::consts::PI * alpha, q * c * 0.01);
        // lift tilted forward by alpha, drag backward along the flow
        let f2 = l * alpha.sin() - d * alpha.cos();
        let f3 = l * alpha.cos() + d * alpha.sin();
        assert!((s.force_n_per_m[1] - f2).abs() < 1e-9 * l);
        assert!((s.force_n_per_m[2] - f3).abs() < 1e-9 * l);
        assert_eq!(s.force_n_per_m[0], 0.0);
        // the spanwise component changes nothing
        let s0 = blade_element(
            [0.0, u[1], u[2]],
            c,
            &AIR,
            &thin(0.01),
            &ClampCounts::default(),
            1.0,
        );
        assert_eq!(s, s0);
    }

    #[test]
    fn tip_loss_removes_the_lift_not_the_drag() {
        let u = [0.0, -150.0, 10.0];
        let s = blade_element(u, 0.4, &AIR, &thin(0.02), &ClampCounts::default(), 0.0);
        let q = 0.5 * 1.2 * (150.0f64 * 150.0 + 100.0);
        let d = q * 0.4 * 0.02;
        assert!(((s.force_n_per_m[1].hypot(s.force_n_per_m[2])) - d).abs() < 1e-12 * d);
    }
}
