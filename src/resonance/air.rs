//! Air resonance of a rotor deck in hover (docs/stability.md): the deck's blades reduced to
//! rigid blades on coincident lag and flap hinges with their mass and aerodynamics in spanwise
//! strips ([`crate::stability::air_rotor`]), each blade's damper linearised at the operating
//! point, on the airframe's directions under the hub (x, y, roll, pitch), over rotor speeds.
use super::{
    check_speeds, linearise, unstable_ranges, LinearisedDamper, Method, SpeedModes, StabilityMap,
    FLOQUET_STEPS_PER_REV,
};
use crate::aero::section::Air;
use crate::hydraulics::DamperModel;
use crate::rotor::deck::RotorSpec;
use crate::rotor::RotorDeck;
use crate::stability::{AirBlade, AirRotor, BodyAxis, BodyDof, LagBlade, ModeLabel, Strip};
use anyhow::{anyhow, bail};
use std::f64::consts::PI;

/// Strips of a blade from the hinge to the tip (midpoints; the integrals converge as
/// `1/strips^2`).
pub const DEFAULT_STRIPS: usize = 60;
/// Mass sampling points per strip (the section table is piecewise linear with jumps).
const MASS_SAMPLES: usize = 16;

/// The hover condition of an air-resonance map.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct HoverOptions {
    /// Blade pitch at 0.75 R [deg] (collective; the twist is the deck's `blade.twist_deg`).
    pub collective_deg: f64,
    pub density_kg_m3: f64,
    pub speed_of_sound_m_s: f64,
    pub strips: usize,
}

impl Default for HoverOptions {
    fn default() -> Self {
        HoverOptions {
            collective_deg: 8.0,
            density_kg_m3: 1.225,
            speed_of_sound_m_s: 340.3,
            strips: DEFAULT_STRIPS,
        }
    }
}

impl HoverOptions {
    /// Each value in its range, the message naming the option.
    pub fn check(&self) -> anyhow::Result<()> {
        if !(self.collective_deg.is_finite() && self.collective_deg.abs() <= 30.0) {
            bail!(
                "--collective-deg {}: expected a blade pitch at 0.75 R between -30 and 30 deg",
                self.collective_deg
            );
        }
        if !(self.density_kg_m3.is_finite() && self.density_kg_m3 > 0.0 && self.density_kg_m3 < 5.0)
        {
            bail!(
                "--density-kg-m3 {}: expected an air density between 0 and 5 kg/m^3",
                self.density_kg_m3
            );
        }
        if !(self.speed_of_sound_m_s.is_finite() && self.speed_of_sound_m_s > 100.0) {
            bail!(
                "--speed-of-sound-m-s {}: expected a speed of sound above 100 m/s",
                self.speed_of_sound_m_s
            );
        }
        if !(8..=2000).contains(&self.strips) {
            bail!(
                "--strips {}: expected 8 to 2000 strips per blade",
                self.strips
            );
        }
        Ok(())
    }
}

/// The hover state at one speed, for the report.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct HoverState {
    pub omega_rad_s: f64,
    pub thrust_n: f64,
    pub induced_velocity_m_s: f64,
    pub coning_deg: f64,
    pub lag_deg: f64,
}

/// What an air-resonance map adds to a stability map.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct HoverReport {
    pub options: HoverOptions,
    /// The airframe's directions in the model: (name, mass or inertia, spring, damper, centre
    /// height above the hub).
    pub airframe: Vec<(String, f64, f64, f64, f64)>,
    pub states: Vec<HoverState>,
    /// Blade flap inertia about the hinge [kg m^2] and Lock number `rho a c R^4 / I` (a = 2 pi).
    pub flap_inertia_kg_m2: f64,
    pub lock_number: f64,
}

fn interp(points: &[[f64; 2]], x: f64) -> f64 {
    match points {
        [] => 0.0,
        [p] => p[1],
        _ => {
            if x <= points[0][0] {
                return points[0][1];
            }
            for w in points.windows(2) {
                if x <= w[1][0] {
                    let t = (x - w[0][0]) / (w[1][0] - w[0][0]);
                    return w[0][1] + t * (w[1][1] - w[0][1]);
                }
            }
            points[points.len() - 1][1]
        }
    }
}

/// Mass per length of `spec`'s blade at radius `r` [kg/m]: the retention's segments 2 and 3
/// between the hinge and the blade root, the section table outboard.
fn mass_per_m(spec: &RotorSpec, table: &crate::structure::section::SectionTable, r: f64) -> f64 {
    let ret = &spec.retention;
    if r < ret.horn_r_m {
        ret.segment2.section.m
    } else if r < spec.blade.root_r_m {
        ret.segment3.section.m
    } else {
        table.at(r - spec.blade.root_r_m).m
    }
}

/// One blade of the air-resonance model from `spec` (the deck at `deck_path`): mass and
/// aerodynamics in `opts.strips` strips, the bearing's lag and flap springs and dampers plus
/// the damper's linearised values at the hinge `(k, c)`.
pub fn air_blade(
    spec: &RotorSpec,
    deck_path: &std::path::Path,
    opts: &HoverOptions,
    damper_kc: (f64, f64),
) -> anyhow::Result<(AirBlade, Vec<crate::aero::airfoil::Airfoil>)> {
    use crate::structure::section::SectionTable;
    let file = deck_path.display();
    let (geo, _) = crate::rotor::aero::blade_geometry(spec, deck_path)?;
    let csv = deck_path
        .parent()
        .unwrap_or(std::path::Path::new(""))
        .join(&spec.blade.sections_csv);
    let table = SectionTable::from_csv(&csv)?;
    let e = spec.retention.hinge_r_m;
    let radius = spec.rotor.radius_m;
    if e >= radius || e.is_nan() {
        bail!(
            "rotor deck {file}: retention.hinge_r_m = {e} is not inside the rotor radius {radius}"
        );
    }
    let n = opts.strips;
    let d = (radius - e) / n as f64;
    let twist = &spec.blade.twist_deg;
    let pitch = |r: f64| {
        (opts.collective_deg + interp(twist, r) - interp(twist, 0.75 * radius)).to_radians()
    };
    let tip = geo.tip_loss_factor * radius;
    let strips = (0..n)
        .map(|j| {
            let (r0, r1) = (e + j as f64 * d, e + (j + 1) as f64 * d);
            let rm = 0.5 * (r0 + r1);
            let mass: f64 = (0..MASS_SAMPLES)
                .map(|q| {
                    let r = r0 + (q as f64 + 0.5) * d / MASS_SAMPLES as f64;
                    mass_per_m(spec, &table, r) * d / MASS_SAMPLES as f64
                })
                .sum();
            let width = (r1.min(radius) - r0.max(geo.cutout_r_m)).max(0.0);
            let airfoil = geo
                .airfoils
                .iter()
                .position(|(r_end, _)| rm <= *r_end)
                .unwrap_or(geo.airfoils.len() - 1);
            Strip {
                rho_m: rm - e,
                mass_kg: mass,
                width_m: width,
                chord_m: geo.chord_m.first().map_or(0.0, |c| c.1),
                pitch_rad: pitch(rm),
                lift_factor: if rm <= tip { 1.0 } else { 0.0 },
                airfoil,
            }
        })
        .collect();
    let (lag, flap) = (spec.bearing_lag(), spec.bearing_flap());
    Ok((
        AirBlade {
            hinge_offset_m: e,
            strips,
            lag_stiffness_nm_per_rad: lag.0 + damper_kc.0,
            lag_damping_nms_per_rad: lag.1 + damper_kc.1,
            flap_stiffness_nm_per_rad: flap.0,
            flap_damping_nms_per_rad: flap.1,
        },
        geo.airfoils.into_iter().map(|(_, a)| a).collect(),
    ))
}

/// The airframe's directions under the hub as the air-resonance model's coordinates (x, y,
/// roll, pitch; a vertical direction is left out, with a note).
pub(crate) fn body(deck: &RotorDeck) -> anyhow::Result<(Vec<BodyDof>, Vec<String>)> {
    let file = deck.path.display();
    let Some(af) = &deck.spec.airframe else {
        bail!("rotor deck {file} has no [airframe]: air resonance is the rotor's lag and flap modes coupled with the airframe's roll and pitch under the hub; add [airframe] with roll and pitch (inertia_kg_m2, stiffness_Nm_per_rad, damping_Nms_per_rad) or [[airframe.mode]] tables (docs/rotor_deck.md, \"The airframe under the hub\")");
    };
    let (mut out, mut notes) = (vec![], vec![]);
    for d in af.dofs() {
        let axis = match (d.rotation, d.axis) {
            (false, 0) => BodyAxis::X,
            (false, 1) => BodyAxis::Y,
            (true, 0) => BodyAxis::Roll,
            (true, 1) => BodyAxis::Pitch,
            _ => {
                notes.push(format!(
                    "airframe {} is not in the air-resonance model (it couples with the collective modes only)",
                    d.name
                ));
                continue;
            }
        };
        if out.iter().any(|b: &BodyDof| b.axis == axis) {
            notes.push(format!(
                "airframe {}: a second direction on the same hub axis, left out",
                d.name
            ));
            continue;
        }
        out.push(BodyDof {
            axis,
            mass: d.mass,
            stiffness: d.stiffness,
            damping: d.damping,
            center_z_m: d.center_z_m,
        });
    }
    if out.is_empty() {
        bail!("rotor deck {file}: [airframe] has no direction the air-resonance model takes (x, y, roll or pitch)");
    }
    Ok((out, notes))
}

/// The air-resonance map of `deck` in hover with damper model `model` at `speeds_rad_s`.
pub fn air_resonance_map(
    deck: &RotorDeck,
    model: DamperModel,
    speeds_rad_s: &[f64],
    opts: &HoverOptions,
) -> anyhow::Result<StabilityMap> {
    let file = deck.path.display().to_string();
    check_speeds("speeds", speeds_rad_s)?;
    opts.check()?;
    let (body, mut notes) = body(deck)?;
    let n = deck.spec.rotor.blades;
    let specs = super::rigid_blade::blade_decks(deck, model)?;
    notes.push("blades rigid on coincident lag and flap hinges (lag inboard), no elastic bending or torsion, no pitch-flap coupling; quasi-steady strip aerodynamics with the uniform induced velocity of momentum theory frozen at the hover equilibrium (no dynamic inflow); no gravity".into());
    let air = Air {
        density_kg_m3: opts.density_kg_m3,
        speed_of_sound_m_s: opts.speed_of_sound_m_s,
    };
    let mut speeds = Vec::with_capacity(speeds_rad_s.len());
    let mut states = Vec::with_capacity(speeds_rad_s.len());
    let mut nominal = vec![];
    let mut inertia = 0.0;
    for &om in speeds_rad_s {
        let mut w = super::rigid_blade::RigidLagBlade::of(&specs[0].0.spec, &specs[0].0.path)?
            .lag_frequency_rad_s(om);
        let mut result = None;
        for _ in 0..2 {
            let w_lin = w.max(0.05 * om).max(0.1);
            let mut blades = Vec::with_capacity(n);
            let mut dampers = Vec::with_capacity(n);
            let mut airfoils = vec![];
            let mut done: Vec<(usize, (f64, f64))> = vec![];
            for (k, (b, d)) in specs.iter().enumerate() {
                let same = done
                    .iter()
                    .find(|(j, _)| super::rigid_blade::same_damper(&specs, *j, k));
                let kc = match same {
                    Some(&(_, kc)) => kc,
                    None => {
                        let kc = linearise(d, model, b.spec.damper_attachment.arm_m, w_lin)
                            .map_err(|e| anyhow!("blade {}: {e:#}", k + 1))?;
                        done.push((k, kc));
                        kc
                    }
                };
                let (ab, foils) = air_blade(&b.spec, &b.path, opts, kc)
                    .map_err(|e| anyhow!("blade {}: {e:#}", k + 1))?;
                if airfoils.is_empty() {
                    airfoils = foils;
                }
                dampers.push(LinearisedDamper {
                    blade: k + 1,
                    frequency_rad_s: w_lin,
                    stiffness_nm_per_rad: kc.0,
                    damping_nms_per_rad: kc.1,
                });
                blades.push(ab);
            }
            let rotor = AirRotor {
                blades,
                body: body.clone(),
                air,
                airfoils,
                radius_m: deck.spec.rotor.radius_m,
            };
            rotor
                .validate()
                .map_err(|e| anyhow!("rotor deck {file}: the air-resonance model: {e}"))?;
            let (method, res) = if rotor.is_isotropic() && n >= 3 {
                (Method::Coleman, rotor.coleman_eigenvalues(om))
            } else {
                (Method::Floquet, rotor.floquet(om, FLOQUET_STEPS_PER_REV))
            };
            let (hover, modes) = res
                .map_err(|e| anyhow!("rotor deck {file}: {} at {om} rad/s: {e}", method.name()))?;
            if let Some(r) = modes.iter().find(|m| m.label == ModeLabel::RegressingLag) {
                w = (om - 2.0 * PI * r.frequency_hz).abs();
            }
            inertia = rotor.blades[0].inertia_kg_m2();
            nominal = rotor
                .blades
                .iter()
                .map(|b| LagBlade {
                    mass_kg: b.mass_kg(),
                    first_moment_kg_m: b.first_moment_kg_m(),
                    inertia_kg_m2: b.inertia_kg_m2(),
                    hinge_offset_m: b.hinge_offset_m,
                    stiffness_nm_per_rad: b.lag_stiffness_nm_per_rad,
                    damping_nms_per_rad: b.lag_damping_nms_per_rad,
                })
                .collect();
            let state = HoverState {
                omega_rad_s: om,
                thrust_n: hover.thrust_n,
                induced_velocity_m_s: hover.inflow_m_s,
                coning_deg: hover.flap_rad[0].to_degrees(),
                lag_deg: hover.lag_rad[0].to_degrees(),
            };
            result = Some((
                SpeedModes {
                    omega_rad_s: om,
                    method,
                    modes,
                    dampers,
                },
                state,
            ));
            if model == DamperModel::Linear {
                break;
            }
        }
        if let Some((s, st)) = result {
            speeds.push(s);
            states.push(st);
        }
    }
    let unstable = unstable_ranges(&speeds);
    let chord = deck.spec.aero.as_ref().map_or(0.0, |a| a.chord_m);
    let report = HoverReport {
        options: *opts,
        airframe: body
            .iter()
            .map(|b| {
                (
                    format!("{:?}", b.axis).to_lowercase(),
                    b.mass,
                    b.stiffness,
                    b.damping,
                    b.center_z_m,
                )
            })
            .collect(),
        states,
        flap_inertia_kg_m2: inertia,
        lock_number: opts.density_kg_m3 * 2.0 * PI * chord * deck.spec.rotor.radius_m.powi(4)
            / inertia,
    };
    Ok(StabilityMap {
        damper: model,
        blades: nominal,
        x: None,
        y: None,
        speeds,
        unstable,
        notes,
        overrides: Vec::new(),
        verdicts: Vec::new(),
        hover: Some(report),
    })
}
