//! The rigid-lag-blade reduction of a rotor deck: the blade taken rigid on its lag hinge,
//! with the mass moments about the hinge ([`RotorSpec::lag_moments`]), the bearing's lag
//! spring and dashpot at the nominal speed, and the damper's arm. The ground-resonance map,
//! its amplitude check, the air-resonance map (for the frequency at which it linearises the
//! dampers) and the rigid run (`run --model rigid`) all reduce a blade through it.
use crate::hydraulics::{DamperDeck, DamperModel};
use crate::rotor::deck::RotorSpec;
use crate::rotor::RotorDeck;
use crate::stability::LagBlade;

/// Each blade's own deck (the rotor's per-blade differences applied) with its damper deck,
/// which must have `model`.
pub fn blade_decks(
    deck: &RotorDeck,
    model: DamperModel,
) -> anyhow::Result<Vec<(RotorDeck, DamperDeck)>> {
    let n = deck.spec.rotor.blades;
    let mut out = Vec::with_capacity(n);
    for k in 1..=n {
        let b = deck.blade(k)?;
        let damper = b.damper()?;
        damper.require(model)?;
        out.push((b, damper));
    }
    Ok(out)
}

/// Whether blades `j` and `k` of `decks` carry the same damper on the same arm (so that one
/// linearisation serves both).
pub fn same_damper(decks: &[(RotorDeck, DamperDeck)], j: usize, k: usize) -> bool {
    decks[j].1 == decks[k].1
        && decks[j].0.spec.damper_attachment.arm_m == decks[k].0.spec.damper_attachment.arm_m
}

/// One blade reduced to a rigid body on its lag hinge.
#[derive(Clone, Debug, PartialEq)]
pub struct RigidLagBlade {
    pub mass_kg: f64,
    /// First moment of mass about the lag hinge [kg m].
    pub first_moment_kg_m: f64,
    /// Second moment of mass about the lag hinge [kg m^2].
    pub inertia_kg_m2: f64,
    /// Lag hinge distance from the shaft [m].
    pub hinge_offset_m: f64,
    /// The lag bearing's spring and dashpot (equivalent values at the nominal speed).
    pub lag_stiffness_nm_per_rad: f64,
    pub lag_damping_nms_per_rad: f64,
    /// Damper arm [m]: stroke = arm x lag angle.
    pub damper_arm_m: f64,
}

impl RigidLagBlade {
    /// The reduction of the blade of `spec` (the deck at `deck_path`, against which the
    /// section table's path is resolved).
    pub fn of(spec: &RotorSpec, deck_path: &std::path::Path) -> anyhow::Result<Self> {
        let m = spec.lag_moments(deck_path)?;
        let (k, c) = spec.bearing_lag();
        Ok(RigidLagBlade {
            mass_kg: m.mass_kg,
            first_moment_kg_m: m.first_moment_kg_m,
            inertia_kg_m2: m.inertia_kg_m2,
            hinge_offset_m: spec.retention.hinge_r_m,
            lag_stiffness_nm_per_rad: k,
            lag_damping_nms_per_rad: c,
            damper_arm_m: spec.damper_attachment.arm_m,
        })
    }

    /// The blade's own lag frequency in the rotating frame at `omega_rad_s`, without the
    /// damper: `sqrt((e S Omega^2 + k) / I)` [rad/s].
    pub fn lag_frequency_rad_s(&self, omega_rad_s: f64) -> f64 {
        ((self.hinge_offset_m * self.first_moment_kg_m * omega_rad_s * omega_rad_s
            + self.lag_stiffness_nm_per_rad)
            / self.inertia_kg_m2)
            .sqrt()
    }

    /// The blade of the ground-resonance model with the damper's equivalent stiffness and
    /// damping at the hinge `(k, c)` added to the bearing's.
    pub fn lag_blade(&self, (k, c): (f64, f64)) -> LagBlade {
        LagBlade {
            mass_kg: self.mass_kg,
            first_moment_kg_m: self.first_moment_kg_m,
            inertia_kg_m2: self.inertia_kg_m2,
            hinge_offset_m: self.hinge_offset_m,
            stiffness_nm_per_rad: self.lag_stiffness_nm_per_rad + k,
            damping_nms_per_rad: self.lag_damping_nms_per_rad + c,
        }
    }
}
