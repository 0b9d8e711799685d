//! The nonlinear amplitude check of ground or air resonance (docs/stability.md): the reduced
//! rotor of the stability map on its airframe at one speed (in hover, the air-resonance
//! model linearised about its hover equilibrium), each blade's damper a device (relief and
//! check valves live), started on the regressing lag mode at a series of stroke amplitudes.
//! Each start gives a growth rate in the time domain; beside it the growth rate the damper's
//! equivalent stiffness and damping at that amplitude predict (the bench's first harmonic),
//! and the linearised map's at 0.1 mm. Where the time-domain growth rate changes sign between
//! two amplitudes there is a limit cycle.
use super::air::HoverOptions;
use super::rigid_blade::RigidLagBlade;
use super::tracking::{fit_log, settle, track, Follow, Settled, TrackedMode, Whirl};
use super::{in_plane, linearise_at, LINEARISATION_AMPLITUDE_M};
use crate::hydraulics::{DamperDeck, DamperModel, IntegratorOptions};
use crate::rotor::RotorDeck;
use crate::stability::{
    cyclic_amplitude, free_response_with_dampers, AirRotor, AirframeAxis, BladeDamper, BodyDof,
    Hover, LagRotor, Mode, ModeLabel,
};
use anyhow::{anyhow, bail};
use faer::c64;
use rayon::prelude::*;
use std::f64::consts::PI;

/// Stroke amplitudes tried when none are given [m]: from the linearisation's 0.1 mm to
/// beyond the relief valves' opening and short of the end of travel (37.5 mm) on the shipped
/// deck.
pub const DEFAULT_AMPLITUDES_M: [f64; 8] = [1e-4, 3e-4, 1e-3, 3e-3, 1e-2, 2e-2, 2.5e-2, 3e-2];
/// The devices' integrator, in the time domain and on the bench alike (the map's, see
/// [`super::BENCH_INTEGRATOR`]): at tens of millimetres of stroke at the lag
/// frequency the flows make the chambers too stiff for RK4's sub-steps.
pub const INTEGRATOR: IntegratorOptions = super::BENCH_INTEGRATOR;
/// Most starts of one amplitude check (each a time-domain run of four live dampers).
pub const MAX_AMPLITUDES: usize = 200;
/// Largest lag angle of a start [rad]: the reduced model is linear in the lag angle.
pub const MAX_LAG_RAD: f64 = 0.35;
/// A start's free response stops once a blade's stroke reaches this fraction of the damper's
/// travel (the physical damper's `V/A`, its shortest chamber's): the start has grown to the
/// end of travel, a result (no limit cycle below the stroke limit), not a failure. The margin
/// keeps the devices' trial strokes inside the chambers.
pub const END_OF_TRAVEL_FRACTION: f64 = 0.95;

/// A start that grew to the damper's end of travel.
#[derive(Clone, Copy, Debug, serde::Serialize)]
pub struct EndOfTravel {
    /// The stroke where the response stopped (the largest blade's) [m].
    pub stroke_m: f64,
    /// The damper's travel [m] (the response stops at [`END_OF_TRAVEL_FRACTION`] of it).
    pub travel_m: f64,
    /// Time from the start [s].
    pub time_s: f64,
    /// The blade whose stroke reached it (1-based).
    pub blade: usize,
}

impl EndOfTravel {
    /// "grows to the end of travel (35.6 of 37.5 mm) within 0.84 s"
    pub fn text(&self) -> String {
        format!(
            "grows to the end of travel ({:.1} of {:.1} mm) within {:.2} s",
            self.stroke_m * 1e3,
            self.travel_m * 1e3,
            self.time_s
        )
    }
}

/// How the amplitude check runs.
#[derive(Clone, Debug)]
pub struct AmplitudeOptions {
    /// Stroke amplitudes of the starts [m], increasing.
    pub amplitudes_m: Vec<f64>,
    /// Damper cycles (the tracked mode's rotating-frame period) fitted from each start, after
    /// [`SKIP_CYCLES`] left out; the devices are pressurised on the mode's stroke before it.
    pub cycles: usize,
    /// Steps per revolution (RK4 on the blades, the devices sub-stepped inside each).
    pub steps_per_rev: usize,
    /// In hover (the air-resonance model, [`super::air`]) rather than on the ground.
    pub hover: Option<super::air::HoverOptions>,
}

impl Default for AmplitudeOptions {
    fn default() -> Self {
        AmplitudeOptions {
            amplitudes_m: DEFAULT_AMPLITUDES_M.to_vec(),
            cycles: 4,
            steps_per_rev: 256,
            hover: None,
        }
    }
}

/// One start.
#[derive(Clone, Debug)]
pub struct AmplitudePoint {
    /// Stroke amplitude of the start [m].
    pub start_m: f64,
    /// Stroke amplitude over the fitted window (geometric mean) [m].
    pub stroke_amplitude_m: f64,
    /// Time domain, the devices live: slope of the log of the cyclic lag amplitude [1/s].
    pub growth_rate_per_s: f64,
    /// From the damper's equivalent stiffness and damping at `stroke_amplitude_m` [1/s].
    pub equivalent_growth_rate_per_s: f64,
    /// The equivalent damping at the lag hinge (blade 1) [N m s/rad].
    pub equivalent_damping_nms_per_rad: f64,
    /// The equivalent regressing lag's fixed-frame frequency [Hz].
    pub frequency_hz: f64,
    /// Largest damper force of the run, any blade [N].
    pub max_force_n: f64,
    /// Coupling iterations of the hardest step.
    pub max_iterations: usize,
    /// Stroke amplitude envelope over the run: (time [s], amplitude [m]), thinned.
    pub envelope: Vec<(f64, f64)>,
    /// MAC of the start's mode with the mode at the amplitude before it (the linearisation's
    /// for the first start, the bracket's lower end for a refinement).
    pub mac: f64,
    /// The next best MAC among the other modes.
    pub runner_up_mac: f64,
    /// The tracked mode's label at this amplitude (for the record: it is followed by MAC).
    pub label: ModeLabel,
    /// The fitted window of the free response [s] (first and last revolution sampled).
    pub fit_from_s: f64,
    pub fit_to_s: f64,
    /// Revolutions sampled in the window.
    pub fitted_revolutions: usize,
    /// How the devices were pressurised before the start.
    pub settled: Settled,
    /// A start of the neutral amplitude's refinement (not one of the given amplitudes).
    pub bisection: bool,
    /// The start grew to the damper's end of travel (its response stopped there). The growth
    /// rate is then fitted over the revolutions it ran (from the start when fewer than four
    /// follow the skipped damper cycle).
    pub end_of_travel: Option<EndOfTravel>,
}

/// A limit cycle between two starts.
#[derive(Clone, Debug, serde::Serialize)]
pub struct LimitCycle {
    /// Stroke amplitude where the growth rate crosses zero [m]: log-linear interpolation
    /// inside the refined bracket.
    pub stroke_amplitude_m: f64,
    /// The refined bracket: the window amplitudes of its two starts [m].
    pub bracket_m: [f64; 2],
    /// Its start amplitudes [m] (within [`BRACKET_RATIO`]).
    pub start_bracket_m: [f64; 2],
    /// Their growth rates [1/s].
    pub bracket_growth_rates_per_s: [f64; 2],
    /// The interpolation between the two given starts, before the refinement [m].
    pub coarse_m: f64,
    /// Stable (smaller motions grow to it, larger decay to it) or a threshold (larger motions
    /// grow without bound, smaller decay).
    pub stable: bool,
}

/// The amplitude check at one speed.
#[derive(Clone, Debug)]
pub struct AmplitudeCheck {
    pub omega_rad_s: f64,
    pub damper: DamperModel,
    /// The linearised map's regressing lag at 0.1 mm.
    pub linearised: Mode,
    pub points: Vec<AmplitudePoint>,
    /// The starts of the neutral amplitudes' refinement, by amplitude.
    pub refinements: Vec<AmplitudePoint>,
    pub limit_cycles: Vec<LimitCycle>,
    /// The relief valves' force limits of blade 1's damper, where it has them [N].
    pub relief_limits_n: Option<(f64, f64)>,
    pub steps_per_rev: usize,
    /// Damper cycles fitted per start.
    pub fit_cycles: usize,
    /// The damper's travel [m] (physical damper), where the starts stop.
    pub travel_m: Option<f64>,
    /// The outcome in a short line (the command's, the report banner's and the verdict's).
    pub headline: String,
    /// The outcome in a sentence.
    pub statement: String,
}

impl AmplitudeCheck {
    /// Whether the outcome is good news: a stable limit cycle (no unstable one) or decay at
    /// every amplitude.
    pub fn benign(&self) -> bool {
        if self.limit_cycles.is_empty() {
            self.points.iter().all(|p| p.growth_rate_per_s < 0.0)
        } else {
            self.limit_cycles.iter().all(|c| c.stable)
                && self.points.iter().all(|p| p.end_of_travel.is_none())
        }
    }
}

/// Amplitudes: finite, positive, increasing, and a lag angle the reduced model holds.
pub fn check_amplitudes(a: &[f64], arm_m: f64) -> anyhow::Result<()> {
    crate::run::ranges::check_increasing("--amplitudes-m", a, "m", "stroke amplitude")?;
    let top = a[a.len() - 1];
    if top / arm_m > MAX_LAG_RAD {
        bail!(
            "--amplitudes-m: {top} m of stroke is {:.1} deg of lag on the {arm_m} m damper arm, beyond the {:.0} deg the reduced lag model holds",
            (top / arm_m).to_degrees(),
            MAX_LAG_RAD.to_degrees()
        );
    }
    Ok(())
}

/// A rotor with its dampers' equivalent values, its regressing lag mode, and each blade's
/// (stiffness, damping) at the hinge.
type Equivalent = (Reduced, Mode, Vec<(f64, f64)>);
/// A rotor with its dampers' equivalent values, the mode tracked on it, and each blade's
/// (stiffness, damping) at the hinge.
type Tracked = (Reduced, TrackedMode, Vec<(f64, f64)>);

/// The reduced rotor of the check: on the ground (lag only) or in hover (lag, flap, air).
#[derive(Clone, Debug)]
enum Reduced {
    Lag(LagRotor),
    Air(Box<AirRotor>, Box<Hover>),
}

impl Reduced {
    fn blades(&self) -> usize {
        match self {
            Reduced::Lag(r) => r.blades.len(),
            Reduced::Air(r, _) => r.blades.len(),
        }
    }
    fn modes(&self, om: f64) -> anyhow::Result<Vec<Mode>> {
        let fl = super::FLOQUET_STEPS_PER_REV;
        Ok(match self {
            Reduced::Lag(r) if r.is_isotropic() && r.blades.len() >= 3 => {
                r.coleman_eigenvalues(om)?
            }
            Reduced::Lag(r) => r.floquet(om, fl)?,
            Reduced::Air(r, _) if r.is_isotropic() => r.coleman_eigenvalues(om)?.1,
            Reduced::Air(r, _) => r.floquet(om, fl)?.1,
        })
    }
    /// The mode of this rotor that `follow` picks (its Floquet basis at zero time).
    fn tracked(&self, om: f64, follow: Follow) -> anyhow::Result<TrackedMode> {
        let fl = super::FLOQUET_STEPS_PER_REV;
        let modes = self.modes(om)?;
        let phi = match self {
            Reduced::Lag(r) => r.monodromy(om, fl)?,
            Reduced::Air(r, h) => r.monodromy(h, fl)?,
        };
        let m = (phi.len() as f64).sqrt().round() as usize;
        track(&phi, m, &modes, om, self.blades(), follow)
    }
    fn respond(
        &self,
        om: f64,
        dampers: &mut [BladeDamper],
        z: &[f64],
        t_end: f64,
        dt: f64,
        stop_lag_rad: f64,
    ) -> anyhow::Result<crate::stability::DeviceResponse> {
        Ok(match self {
            Reduced::Lag(r) => {
                free_response_with_dampers(r, om, dampers, z, t_end, dt, stop_lag_rad)?
            }
            Reduced::Air(r, h) => {
                let steps_per_rev = (2.0 * PI / om / dt).round() as usize;
                r.response_with_dampers(h, dampers, z, t_end, steps_per_rev, stop_lag_rad)?
            }
        })
    }
}

struct Blades {
    decks: Vec<(RotorDeck, DamperDeck)>,
    x: Option<AirframeAxis>,
    y: Option<AirframeAxis>,
    /// In hover: the options, the airframe's coordinates and the rotor's radius.
    hover: Option<(HoverOptions, Vec<BodyDof>, f64)>,
}

impl Blades {
    fn of(
        deck: &RotorDeck,
        model: DamperModel,
        hover: Option<HoverOptions>,
    ) -> anyhow::Result<Self> {
        let file = deck.path.display().to_string();
        let decks = super::rigid_blade::blade_decks(deck, model)?;
        if let Some(h) = hover {
            h.check()?;
            let (body, _) = super::air::body(deck)?;
            return Ok(Blades {
                decks,
                x: None,
                y: None,
                hover: Some((h, body, deck.spec.rotor.radius_m)),
            });
        }
        let Some(af) = &deck.spec.airframe else {
            bail!("rotor deck {file} has no [airframe]: ground resonance is the rotor's lag modes coupled with the airframe under the hub; add [airframe] with x and y (mass_kg, stiffness_N_per_m, damping_Ns_per_m) (docs/rotor_deck.md, \"The airframe under the hub\")");
        };
        let (x, y, _) = in_plane(&af.dofs(), &file)?;
        Ok(Blades {
            decks,
            x,
            y,
            hover: None,
        })
    }

    /// The physical damper's travel [m]: its shortest chamber's `V0 / A`, over the blades
    /// (None for the other models).
    fn travel_m(&self, model: DamperModel) -> Option<f64> {
        if model != DamperModel::Physical {
            return None;
        }
        self.decks
            .iter()
            .filter_map(|(_, d)| d.physical.as_ref())
            .flat_map(|c| c.chambers.iter().map(|ch| ch.volume0 / ch.area))
            .filter(|t| t.is_finite() && *t > 0.0)
            .min_by(f64::total_cmp)
    }

    /// The rotor with each blade's damper replaced by `kc(blade)` (stiffness, damping at the
    /// hinge) on top of its lag bearing; in hover, about its hover equilibrium at `om`.
    fn rotor(&self, kc: &[(f64, f64)], om: f64) -> anyhow::Result<Reduced> {
        if let Some((opts, body, radius)) = &self.hover {
            let mut blades = Vec::with_capacity(self.decks.len());
            let mut airfoils = vec![];
            for ((b, _), &kc) in self.decks.iter().zip(kc) {
                let (ab, foils) = super::air::air_blade(&b.spec, &b.path, opts, kc)?;
                blades.push(ab);
                airfoils = foils;
            }
            let r = AirRotor {
                blades,
                body: body.clone(),
                air: crate::aero::section::Air {
                    density_kg_m3: opts.density_kg_m3,
                    speed_of_sound_m_s: opts.speed_of_sound_m_s,
                },
                airfoils,
                radius_m: *radius,
            };
            r.validate()?;
            let h = r.hover(om)?;
            return Ok(Reduced::Air(Box::new(r), Box::new(h)));
        }
        let mut blades = Vec::with_capacity(self.decks.len());
        for ((b, _), &kc) in self.decks.iter().zip(kc) {
            blades.push(RigidLagBlade::of(&b.spec, &b.path)?.lag_blade(kc));
        }
        Ok(Reduced::Lag(LagRotor {
            blades,
            x: self.x.clone(),
            y: self.y.clone(),
        }))
    }

    /// Each blade's damper linearised at stroke amplitude `a` and rotating-frame frequency `w`
    /// (hinge stiffness and damping; a blade whose damper equals an earlier one's shares it).
    fn dampers_at(
        &self,
        model: DamperModel,
        om: f64,
        a: f64,
        w: f64,
    ) -> anyhow::Result<Vec<(f64, f64)>> {
        let w_lin = w.max(0.05 * om).max(0.1);
        let mut kc: Vec<(f64, f64)> = Vec::with_capacity(self.decks.len());
        for (k, (b, d)) in self.decks.iter().enumerate() {
            let same = (0..k).find(|&j| super::rigid_blade::same_damper(&self.decks, j, k));
            kc.push(match same {
                Some(j) => kc[j],
                None => linearise_at(
                    d,
                    model,
                    b.spec.damper_attachment.arm_m,
                    w_lin,
                    a,
                    INTEGRATOR,
                )
                .map_err(|e| anyhow!("blade {}: {e:#}", k + 1))?,
            });
        }
        Ok(kc)
    }

    /// The rotor with its dampers' equivalent values at stroke amplitude `a`, linearised at
    /// the rotating-frame frequency `w` [rad/s], and its mode of largest MAC with `previous`
    /// (a right eigenvector of [`TrackedMode`]).
    fn tracked(
        &self,
        model: DamperModel,
        om: f64,
        a: f64,
        w: f64,
        previous: &[c64],
    ) -> anyhow::Result<Tracked> {
        let kc = self.dampers_at(model, om, a, w)?;
        let rotor = self.rotor(&kc, om)?;
        let t = rotor
            .tracked(om, Follow::Vector(previous))
            .map_err(|e| anyhow!("the reduced model at {om} rad/s: {e:#}"))?;
        Ok((rotor, t, kc))
    }

    /// The rotor with its dampers' equivalent values at stroke amplitude `a`, linearised at
    /// the regressing lag's rotating-frame frequency (found in two passes, as the map does,
    /// or taken from `w_guess`: it moves little with the amplitude), and that mode.
    fn equivalent(
        &self,
        model: DamperModel,
        om: f64,
        a: f64,
        w_guess: Option<f64>,
    ) -> anyhow::Result<Equivalent> {
        let (b0, _) = &self.decks[0];
        let mut w = RigidLagBlade::of(&b0.spec, &b0.path)?.lag_frequency_rad_s(om);
        let passes = match w_guess {
            Some(g) => {
                w = g;
                1
            }
            None => 2,
        };
        let mut out = None;
        for _ in 0..passes {
            let kc = self.dampers_at(model, om, a, w)?;
            let rotor = self.rotor(&kc, om)?;
            let modes = rotor
                .modes(om)
                .map_err(|e| anyhow!("the reduced model at {om} rad/s: {e:#}"))?;
            let ground = matches!(rotor, Reduced::Lag(_));
            let mode = modes
                .into_iter()
                .filter(|m| ground_resonance_mode(m.label, ground))
                .max_by(|p, q| p.growth_rate_per_s.total_cmp(&q.growth_rate_per_s))
                .ok_or_else(|| anyhow!("no regressing lag mode at {om} rad/s"))?;
            w = (om - 2.0 * PI * mode.frequency_hz).abs();
            out = Some((rotor, mode, kc));
        }
        out.ok_or_else(|| anyhow!("no equivalent rotor"))
    }
}

/// The modes the amplitude check may start on: the regressing lag, and on the ground the
/// airframe modes it meets. Each label names one mode, so where the regressing lag and the
/// airframe coalesce the least damped of them (the ground resonance) may carry an airframe
/// label; in hover the airframe's slow modes are the aircraft's flight dynamics, not the
/// damper's.
fn ground_resonance_mode(label: ModeLabel, ground: bool) -> bool {
    label == ModeLabel::RegressingLag
        || (ground && matches!(label, ModeLabel::AirframeX | ModeLabel::AirframeY))
}

/// Damper cycles of the free response left out of the fit: the coupled system's adjustment
/// from the prescribed start (the other modes the start excites, the devices' change from a
/// prescribed to a free stroke).
pub const SKIP_CYCLES: usize = 1;
/// The neutral amplitude's bracket is refined until its ends are within this ratio.
pub const BRACKET_RATIO: f64 = 1.01;
/// Most refinement rounds of one bracket (each splits it in three; 1.2 of log amplitude
/// needs five).
pub const MAX_REFINEMENTS: usize = 12;

/// The amplitude check of `deck` (per-blade differences applied) with damper model `model`
/// at rotor speed `omega` [rad/s].
pub fn amplitude_check(
    deck: &RotorDeck,
    model: DamperModel,
    omega: f64,
    o: &AmplitudeOptions,
) -> anyhow::Result<AmplitudeCheck> {
    if !(omega.is_finite() && omega > 0.0) {
        bail!("the amplitude check's rotor speed {omega} rad/s is not a positive finite speed");
    }
    if !(16..=super::MAX_TIME_STEPS_PER_REV).contains(&o.steps_per_rev) {
        bail!(
            "--steps-per-rev {}: expected 16 to {}",
            o.steps_per_rev,
            super::MAX_TIME_STEPS_PER_REV
        );
    }
    if !(1..=MAX_FIT_CYCLES).contains(&o.cycles) {
        bail!(
            "the amplitude check's fitted damper cycles {}: expected 1 to {MAX_FIT_CYCLES}",
            o.cycles
        );
    }
    let blades = Blades::of(deck, model, o.hover)?;
    let arm = blades.decks[0].0.spec.damper_attachment.arm_m;
    check_amplitudes(&o.amplitudes_m, arm)?;
    let travel_m = blades.travel_m(model);
    let max_arm = blades
        .decks
        .iter()
        .map(|(b, _)| b.spec.damper_attachment.arm_m)
        .fold(arm, f64::max);
    let mut stop_lag_rad = 2.0 * MAX_LAG_RAD;
    if let Some(t) = travel_m {
        let stop = END_OF_TRAVEL_FRACTION * t;
        let top = o.amplitudes_m[o.amplitudes_m.len() - 1];
        if top >= stop {
            bail!(
                "--amplitudes-m: {top} m of stroke is at the damper's end of travel ({t:.4e} m, its chambers' V/A; the starts stop at {:.0}% of it): start below {stop:.4e} m",
                100.0 * END_OF_TRAVEL_FRACTION
            );
        }
        stop_lag_rad = stop_lag_rad.min(stop / max_arm);
    }
    let (lin_rotor, linearised, _) =
        blades.equivalent(model, omega, LINEARISATION_AMPLITUDE_M, None)?;
    let first = lin_rotor
        .tracked(omega, Follow::Eigenvalue(linearised.eigenvalue))
        .map_err(|e| anyhow!("the regressing lag mode at {omega} rad/s: {e:#}"))?;
    let bare = blades.rotor(&vec![(0.0, 0.0); blades.decks.len()], omega)?;
    let ctx = Ctx {
        blades: &blades,
        bare: &bare,
        model,
        omega,
        arm,
        opts: o,
        stop_lag_rad,
        travel_m,
    };
    // the mode continued from 0.1 mm through the starts, by MAC (in order: cheap)
    let mut chain: Vec<(Reduced, TrackedMode)> = Vec::with_capacity(o.amplitudes_m.len());
    let mut prev = first.clone();
    for &a in &o.amplitudes_m {
        let (r, t, _) = blades
            .tracked(model, omega, a, w_rot(omega, &prev.mode), &prev.right)
            .map_err(|e| anyhow!("the damper's equivalent values at {a} m of stroke: {e:#}"))?;
        chain.push((r, t.clone()));
        prev = t;
    }
    // the starts are independent: side by side on the cores
    let points = o
        .amplitudes_m
        .par_iter()
        .zip(chain.par_iter())
        .map(|(&a, (r, t))| ctx.start(a, r, t, false))
        .collect::<anyhow::Result<Vec<_>>>()?;
    let mut limit_cycles = Vec::new();
    let mut refinements = Vec::new();
    for (k, w) in points.windows(2).enumerate() {
        if (w[0].growth_rate_per_s > 0.0) == (w[1].growth_rate_per_s > 0.0) {
            continue;
        }
        let coarse = interpolate(&w[0], &w[1]);
        let (lo, hi, extra) = ctx.bisect(
            w[0].clone(),
            chain[k].1.clone(),
            w[1].clone(),
            chain[k + 1].1.clone(),
        )?;
        refinements.extend(extra);
        limit_cycles.push(LimitCycle {
            stroke_amplitude_m: interpolate(&lo, &hi),
            stable: w[0].growth_rate_per_s > 0.0,
            bracket_m: [lo.stroke_amplitude_m, hi.stroke_amplitude_m],
            start_bracket_m: [lo.start_m, hi.start_m],
            bracket_growth_rates_per_s: [lo.growth_rate_per_s, hi.growth_rate_per_s],
            coarse_m: coarse,
        });
    }
    refinements.sort_by(|p: &AmplitudePoint, q| p.start_m.total_cmp(&q.start_m));
    let relief_limits_n = (model == DamperModel::Physical)
        .then(|| crate::rotor::sim::relief_limits(&blades.decks[0].1))
        .flatten();
    let mut all: Vec<&AmplitudePoint> = points.iter().chain(&refinements).collect();
    all.sort_by(|p, q| p.start_m.total_cmp(&q.start_m));
    let headline = headline(
        omega,
        model,
        linearised.label.as_str(),
        &points,
        &all,
        &limit_cycles,
    );
    let statement = statement(
        omega,
        &linearised,
        &points,
        &all,
        &limit_cycles,
        relief_limits_n,
        o.cycles,
    );
    Ok(AmplitudeCheck {
        omega_rad_s: omega,
        damper: model,
        linearised,
        points,
        refinements,
        limit_cycles,
        relief_limits_n,
        steps_per_rev: o.steps_per_rev,
        fit_cycles: o.cycles,
        travel_m,
        headline,
        statement,
    })
}

/// Most damper cycles a start may fit.
pub const MAX_FIT_CYCLES: usize = 50;

/// The mode's rotating-frame frequency at `omega` [rad/s] (what the damper strokes at).
fn w_rot(omega: f64, m: &Mode) -> f64 {
    (omega - m.eigenvalue.im.abs()).abs()
}

/// Log-linear interpolation of the zero of the growth rate between two points.
fn interpolate(p: &AmplitudePoint, q: &AmplitudePoint) -> f64 {
    let (g0, g1) = (p.growth_rate_per_s, q.growth_rate_per_s);
    let (l0, l1) = (p.stroke_amplitude_m.ln(), q.stroke_amplitude_m.ln());
    (l0 + (l1 - l0) * g0 / (g0 - g1)).exp()
}

/// What every start shares.
struct Ctx<'a> {
    blades: &'a Blades,
    bare: &'a Reduced,
    model: DamperModel,
    omega: f64,
    arm: f64,
    opts: &'a AmplitudeOptions,
    /// A response stops once a blade's lag angle exceeds this [rad] (the end of travel's, or
    /// the reduced model's range).
    stop_lag_rad: f64,
    travel_m: Option<f64>,
}

impl Ctx<'_> {
    /// One start at stroke amplitude `a` on the mode `tm` of the equivalent rotor `eq`: the
    /// devices pressurised on the mode's stroke, then the free response, its modal
    /// coordinate sampled once a revolution and fitted after [`SKIP_CYCLES`] damper cycles.
    fn start(
        &self,
        a: f64,
        _eq: &Reduced,
        tm: &TrackedMode,
        bisection: bool,
    ) -> anyhow::Result<AmplitudePoint> {
        let (om, arm, o) = (self.omega, self.arm, self.opts);
        let nb = self.bare.blades();
        let dt = 2.0 * PI / om / o.steps_per_rev as f64;
        let z: Vec<f64> = tm.unit_state().iter().map(|v| v * a / arm).collect();
        let mut dampers = Vec::with_capacity(nb);
        for (b, d) in &self.blades.decks {
            dampers.push(BladeDamper {
                device: d.build(self.model, INTEGRATOR)?,
                arm_m: b.spec.damper_attachment.arm_m,
            });
        }
        let wr = w_rot(om, &tm.mode).max(1e-3 * om);
        let period = 2.0 * PI / wr;
        let whirl = Whirl::of(tm, nb, om, a / arm);
        let settled = settle(&mut dampers, &whirl, period, dt)
            .map_err(|e| anyhow!("the amplitude check at {a} m of stroke, {om} rad/s: {e:#}"))?;
        let rev = 2.0 * PI / om;
        let fit_from = SKIP_CYCLES as f64 * period;
        let revs = (((SKIP_CYCLES + o.cycles) as f64 * period) / rev).ceil() + 1.0;
        let t_end = revs * rev;
        let r = self
            .bare
            .respond(om, &mut dampers, &z, t_end, dt, self.stop_lag_rad)
            .map_err(|e| anyhow!("the amplitude check at {a} m of stroke, {om} rad/s: {e}"))?;
        let resp = &r.response;
        // a response that stopped at the end of travel: a result
        let end_of_travel = self.travel_m.and_then(|travel| {
            let n = resp.time_s.len();
            let last = resp.state(n - 1);
            let (blade, stroke) = dampers
                .iter()
                .enumerate()
                .map(|(k, d)| (k, (d.arm_m * last[k]).abs()))
                .max_by(|p, q| p.1.total_cmp(&q.1))?;
            (stroke >= END_OF_TRAVEL_FRACTION * travel * (1.0 - 1e-12)).then_some(EndOfTravel {
                stroke_m: stroke,
                travel_m: travel,
                time_s: resp.time_s[n - 1],
                blade: blade + 1,
            })
        });
        let wf = tm.mode.eigenvalue.im.abs().max(1e-6);
        let env: Vec<(f64, f64)> = resp
            .time_s
            .iter()
            .enumerate()
            .map(|(i, &t)| (t, arm * cyclic_amplitude(resp.state(i), nb, om, t, wf)))
            .collect();
        // the modal coordinate at the start of each revolution (where the left eigenvector
        // of the monodromy applies)
        let sampled = |from: f64| -> Vec<(f64, f64)> {
            resp.time_s
                .iter()
                .enumerate()
                .filter(|(_, &t)| {
                    let k = (t / rev).round();
                    (t - k * rev).abs() < 0.25 * dt && t >= from - 0.25 * dt
                })
                .map(|(i, &t)| (t, 2.0 * arm * tm.coordinate(resp.state(i)).norm()))
                .filter(|&(_, v)| v > 0.0 && v.is_finite())
                .collect()
        };
        let mut samples = sampled(fit_from);
        if samples.len() < 4 && end_of_travel.is_some() {
            // it reached the end of travel before a window: the revolutions from the start
            samples = sampled(0.0);
            if samples.len() < 2 {
                // under a revolution: from the start to the stop
                samples = [env.first(), env.last()]
                    .into_iter()
                    .flatten()
                    .copied()
                    .collect();
            }
        }
        if samples.len() < 2 || (samples.len() < 4 && end_of_travel.is_none()) {
            bail!(
                "the amplitude check at {a} m of stroke, {om} rad/s: {} revolutions of the response after {fit_from:.3} s (at least 4 are fitted); the response {}",
                samples.len(),
                if resp.time_s.last().copied().unwrap_or(0.0) < t_end - dt {
                    format!("left the reduced model's range (lag beyond {:.0} deg)", 2.0 * MAX_LAG_RAD.to_degrees())
                } else {
                    "is too short: fit more damper cycles".to_string()
                }
            );
        }
        let (g, amp) = fit_log(&samples);
        let fit_to = samples.last().map_or(fit_from, |s| s.0);
        let equivalent = self
            .blades
            .tracked(self.model, om, amp, wr, &tm.right)
            .map_err(|e| anyhow!("the damper's equivalent values at {amp} m of stroke: {e:#}"));
        let (eq_growth, eq_damping) = match equivalent {
            Ok((_, at, kc)) => (at.mode.growth_rate_per_s, kc[0].1),
            // near the end of travel the bench may not run: the start's own result stands
            Err(_) if end_of_travel.is_some() => (f64::NAN, f64::NAN),
            Err(e) => return Err(e),
        };
        let thin = (env.len() / 400).max(1);
        Ok(AmplitudePoint {
            start_m: a,
            stroke_amplitude_m: amp,
            growth_rate_per_s: g,
            equivalent_growth_rate_per_s: eq_growth,
            equivalent_damping_nms_per_rad: eq_damping,
            frequency_hz: tm.mode.frequency_hz,
            max_force_n: r.force_n.iter().fold(0.0f64, |m, f| m.max(f.abs())),
            max_iterations: r.max_iterations,
            envelope: env.iter().step_by(thin).copied().collect(),
            mac: tm.mac,
            runner_up_mac: tm.runner_up_mac,
            label: tm.mode.label,
            fit_from_s: samples[0].0,
            fit_to_s: fit_to,
            fitted_revolutions: samples.len(),
            settled,
            bisection,
            end_of_travel,
        })
    }

    /// The bracket `(lo, hi)` of a sign change of the growth rate refined in log amplitude:
    /// each round two starts side by side, either side of the zero interpolated in log
    /// amplitude 0.8 of [`BRACKET_RATIO`] apart (after a round that did not straddle the
    /// zero, at the bracket's thirds), until its start amplitudes are within
    /// [`BRACKET_RATIO`]. Returns the final bracket and the refinement starts.
    fn bisect(
        &self,
        mut lo: AmplitudePoint,
        mut tlo: TrackedMode,
        mut hi: AmplitudePoint,
        mut thi: TrackedMode,
    ) -> anyhow::Result<(AmplitudePoint, AmplitudePoint, Vec<AmplitudePoint>)> {
        let mut extra = Vec::new();
        let mut round = 0;
        let mut secant = true;
        while hi.start_m / lo.start_m > BRACKET_RATIO {
            round += 1;
            if round > MAX_REFINEMENTS {
                bail!(
                    "the neutral amplitude at {} rad/s: after {MAX_REFINEMENTS} rounds the bracket is {:.6e} to {:.6e} m of stroke (ratio {:.4}, {BRACKET_RATIO} sought)",
                    self.omega, lo.start_m, hi.start_m, hi.start_m / lo.start_m
                );
            }
            let r = (hi.start_m / lo.start_m).ln();
            // the zero of the growth rate interpolated in log amplitude, tried just either
            // side of it (the bracket's width apart); after a round that did not straddle
            // it, the bracket's thirds
            let (g0, g1) = (lo.growth_rate_per_s, hi.growth_rate_per_s);
            let x = (g0 / (g0 - g1)).clamp(0.05, 0.95);
            let half = 0.4 * BRACKET_RATIO.ln();
            let amps = if secant && 2.0 * half < 0.9 * r {
                let c = lo.start_m.ln() + x * r;
                let (p, q) = (
                    (c - half).max(lo.start_m.ln() + 0.02 * r),
                    (c + half).min(hi.start_m.ln() - 0.02 * r),
                );
                [p.exp(), q.exp()]
            } else {
                [
                    lo.start_m * (r / 3.0).exp(),
                    lo.start_m * (2.0 * r / 3.0).exp(),
                ]
            };
            let new = amps
                .par_iter()
                .map(|&a| -> anyhow::Result<(AmplitudePoint, TrackedMode)> {
                    let (eq, t, _) = self
                        .blades
                        .tracked(
                            self.model,
                            self.omega,
                            a,
                            w_rot(self.omega, &tlo.mode),
                            &tlo.right,
                        )
                        .map_err(|e| {
                            anyhow!("the damper's equivalent values at {a} m of stroke: {e:#}")
                        })?;
                    let p = self.start(a, &eq, &t, true)?;
                    Ok((p, t))
                })
                .collect::<anyhow::Result<Vec<_>>>()?;
            let mut seq = vec![(lo.clone(), tlo.clone())];
            seq.extend(new.iter().cloned());
            seq.push((hi.clone(), thi.clone()));
            extra.extend(new.into_iter().map(|p| p.0));
            let pos = lo.growth_rate_per_s > 0.0;
            let k = (0..3)
                .find(|&k| (seq[k + 1].0.growth_rate_per_s > 0.0) != pos)
                .unwrap_or(2);
            // a round that straddled the zero with its two starts leaves their bracket
            secant = k == 1 || !secant;
            (lo, tlo) = seq[k].clone();
            (hi, thi) = seq[k + 1].clone();
            if (lo.growth_rate_per_s > 0.0) == (hi.growth_rate_per_s > 0.0) {
                // the first sign change from the low end is the one continued
                bail!("the neutral amplitude at {} rad/s: no sign change left in the bracket {:.6e} to {:.6e} m", self.omega, lo.start_m, hi.start_m);
            }
        }
        Ok((lo, hi, extra))
    }
}

/// The outcome in a line (`all`: the given and the refinement starts, by amplitude):
/// "limit cycle at 0.691 mm of stroke (stable; neutral amplitude bracketed 0.688-0.692 mm)",
/// "decays at every amplitude 0.1-30 mm: no limit cycle", or "grows to the end of travel
/// ... : no limit cycle below the stroke limit".
fn headline(
    omega: f64,
    model: DamperModel,
    mode: &str,
    points: &[AmplitudePoint],
    all: &[&AmplitudePoint],
    cycles: &[LimitCycle],
) -> String {
    // millimetres, three decimals at most, trailing zeros dropped
    let n = |v: f64| {
        let t = format!("{:.3}", v * 1e3);
        t.trim_end_matches('0').trim_end_matches('.').to_string()
    };
    let (lo, hi) = (
        points.first().map_or(0.0, |p| p.start_m),
        points.last().map_or(0.0, |p| p.start_m),
    );
    let travel = all.iter().find_map(|p| p.end_of_travel.map(|e| (p, e)));
    let mut parts: Vec<String> = cycles
        .iter()
        .map(|c| {
            format!(
                "{} at {} mm stroke (neutral amplitude bracketed {}-{} mm)",
                if c.stable {
                    "limit cycle"
                } else {
                    "unstable limit cycle (larger motions grow)"
                },
                n(c.stroke_amplitude_m),
                n(c.bracket_m[0]),
                n(c.bracket_m[1]),
            )
        })
        .collect();
    if cycles.is_empty() {
        let all_decay = points.iter().all(|p| p.growth_rate_per_s < 0.0);
        let range = format!("{}-{} mm", n(lo), n(hi));
        parts.push(match (all_decay, travel) {
            (true, _) => format!("decays at every amplitude {range}: no limit cycle"),
            (false, Some((p, e))) if p.start_m <= lo => format!(
                "{} from the {} mm start: no limit cycle below the stroke limit",
                e.text(),
                n(p.start_m)
            ),
            (false, Some((p, e))) => format!(
                "grows at every amplitude {range}, the {} mm start {}: no limit cycle below the stroke limit",
                n(p.start_m),
                e.text()
            ),
            (false, None) => {
                format!("grows at every amplitude {range}: no limit cycle in that range")
            }
        });
    } else if let Some((p, e)) = travel {
        parts.push(format!("the {} mm start {}", n(p.start_m), e.text()));
    }
    format!(
        "at {omega:.3} rad/s ({} damper), {mode}: {}",
        model.name(),
        parts.join("; ")
    )
}

fn statement(
    omega: f64,
    lin: &Mode,
    points: &[AmplitudePoint],
    all: &[&AmplitudePoint],
    cycles: &[LimitCycle],
    relief: Option<(f64, f64)>,
    fit_cycles: usize,
) -> String {
    let mm = |v: f64| format!("{:.3} mm", v * 1e3);
    let (lo, hi) = (
        points.first().map_or(0.0, |p| p.start_m),
        points.last().map_or(0.0, |p| p.start_m),
    );
    let linear = if lin.growth_rate_per_s < 0.0 {
        "stable"
    } else {
        "UNSTABLE"
    };
    let mut s = format!(
        "at {omega:.3} rad/s the linearised analysis (0.1 mm) says {linear} (growth rate {:.4} /s); ",
        lin.growth_rate_per_s
    );
    if cycles.is_empty() {
        let all_decay = points.iter().all(|p| p.growth_rate_per_s < 0.0);
        s += &format!(
            "the time domain finds no limit cycle between {} and {} of stroke: the {} {} at every amplitude tried",
            mm(lo),
            mm(hi),
            lin.label.as_str(),
            if all_decay { "decays" } else { "grows" }
        );
    } else {
        let list: Vec<String> = cycles
            .iter()
            .map(|c| {
                format!(
                    "{} at {} of stroke (bracketed by starts growing at {:+.5} and {:+.5} /s at {} and {})",
                    if c.stable {
                        "a stable limit cycle"
                    } else {
                        "an unstable limit cycle (larger motions grow)"
                    },
                    mm(c.stroke_amplitude_m),
                    c.bracket_growth_rates_per_s[0],
                    c.bracket_growth_rates_per_s[1],
                    mm(c.bracket_m[0]),
                    mm(c.bracket_m[1])
                )
            })
            .collect();
        s += &format!("the time domain finds {}", list.join(" and "));
    }
    let travel: Vec<String> = all
        .iter()
        .filter_map(|p| {
            p.end_of_travel
                .map(|e| format!("the {} start {}", mm(p.start_m), e.text()))
        })
        .collect();
    if !travel.is_empty() {
        s += &format!(
            "; {} (its response stopped there, its growth rate fitted over what it ran){}",
            travel.join(", "),
            if cycles.iter().all(|c| c.stable) {
                ": no limit cycle below the stroke limit"
            } else {
                ""
            }
        );
    }
    s += &format!(
        "; each start's dampers pressurised on the mode's stroke first, the growth rate fitted to the mode's coordinate once a revolution over {fit_cycles} damper cycles after the first"
    );
    let odd: Vec<String> = points
        .iter()
        .filter(|p| p.mac < super::tracking::AMBIGUOUS_MAC)
        .map(|p| format!("{} (MAC {:.2})", mm(p.start_m), p.mac))
        .collect();
    if !odd.is_empty() {
        s += &format!(
            "; the mode's continuation is AMBIGUOUS at the starts {} (MAC below {})",
            odd.join(", "),
            super::tracking::AMBIGUOUS_MAC
        );
    }
    if let Some((l, h)) = relief {
        let cap = h.min(-l);
        match points.iter().find(|p| p.max_force_n >= 0.99 * cap) {
            Some(p) => {
                s += &format!(
                    "; the relief valves open (the force reaches their ±{cap:.0} N) from the start at {}",
                    mm(p.start_m)
                )
            }
            None => {
                s += &format!(
                    "; the relief valves (±{cap:.0} N) did not open at the amplitudes tried"
                )
            }
        }
    }
    s
}

/// amplitude.csv: one row per start.
pub fn csv(c: &AmplitudeCheck) -> String {
    let mut s = String::from("rotor_speed_rad_s,start_stroke_amplitude_m,stroke_amplitude_m,growth_rate_per_s,equivalent_growth_rate_per_s,linearised_growth_rate_per_s,equivalent_damping_Nms_per_rad,frequency_Hz,max_damper_force_N,mac,runner_up_mac,fit_from_s,fit_to_s,fitted_revolutions,settle_cycles,settle_change,bisection,end_of_travel_stroke_m,end_of_travel_s\n");
    let mut all: Vec<&AmplitudePoint> = c.points.iter().chain(&c.refinements).collect();
    all.sort_by(|p, q| p.start_m.total_cmp(&q.start_m));
    for p in all {
        s.push_str(&format!(
            "{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{}\n",
            c.omega_rad_s,
            p.start_m,
            p.stroke_amplitude_m,
            p.growth_rate_per_s,
            p.equivalent_growth_rate_per_s,
            c.linearised.growth_rate_per_s,
            p.equivalent_damping_nms_per_rad,
            p.frequency_hz,
            p.max_force_n,
            p.mac,
            p.runner_up_mac,
            p.fit_from_s,
            p.fit_to_s,
            p.fitted_revolutions,
            p.settled.cycles,
            p.settled.change,
            u8::from(p.bisection),
            p.end_of_travel
                .map_or(String::new(), |e| e.stroke_m.to_string()),
            p.end_of_travel
                .map_or(String::new(), |e| e.time_s.to_string()),
        ));
    }
    s
}

/// The check in summary.json.
pub fn json(c: &AmplitudeCheck) -> serde_json::Value {
    serde_json::json!({
        "rotor_speed_rad_s": c.omega_rad_s,
        "damper_model": c.damper.name(),
        "steps_per_rev": c.steps_per_rev,
        "linearised_growth_rate_per_s": c.linearised.growth_rate_per_s,
        "linearisation_amplitude_m": LINEARISATION_AMPLITUDE_M,
        "fit_damper_cycles": c.fit_cycles,
        "points": c.points.iter().chain(&c.refinements).map(|p| serde_json::json!({
            "start_stroke_amplitude_m": p.start_m,
            "stroke_amplitude_m": p.stroke_amplitude_m,
            "growth_rate_per_s": p.growth_rate_per_s,
            "equivalent_growth_rate_per_s": p.equivalent_growth_rate_per_s,
            "equivalent_damping_Nms_per_rad": p.equivalent_damping_nms_per_rad,
            "frequency_Hz": p.frequency_hz,
            "max_damper_force_N": p.max_force_n,
            "mac": p.mac,
            "runner_up_mac": p.runner_up_mac,
            "mode_label": p.label.as_str(),
            "fit_from_s": p.fit_from_s,
            "fit_to_s": p.fit_to_s,
            "fitted_revolutions": p.fitted_revolutions,
            "settle_cycles": p.settled.cycles,
            "settle_change": p.settled.change,
            "bisection": p.bisection,
            "end_of_travel": p.end_of_travel,
        })).collect::<Vec<_>>(),
        "limit_cycles": c.limit_cycles,
        "relief_limits_N": c.relief_limits_n.map(|(l, h)| [l, h]),
        "travel_m": c.travel_m,
        "headline": c.headline,
        "statement": c.statement,
    })
}

/// The report's section (an HTML fragment): growth rate against amplitude, the envelopes,
/// the table.
pub fn html_section(c: &AmplitudeCheck) -> anyhow::Result<String> {
    use crate::report::html::HtmlReport;
    use crate::report::plot::Plot;
    let mut rep = HtmlReport::new("");
    rep.heading(2, "Amplitude: where the linear analysis stops being true");
    rep.paragraph(&format!(
        "The reduced rotor at {} rad/s with each blade's {} damper as a device (its valves live), started on the {} mode (the least damped of the regressing lag and, on the ground, the airframe modes it meets) at each stroke amplitude and integrated {} steps per revolution. The mode is continued from the linearised map's {} at {} mm through the amplitudes by the modal assurance criterion (MAC) of its Floquet eigenvector. Before each start the dampers run on the mode's stroke until their cycle-mean and RMS forces settle (the check valves' ratcheting); the growth rate is the slope of the log of the mode's coordinate (its left eigenvector on the state, once a revolution) over {} damper cycles after the first, at the window's mean amplitude. A sign change is refined in log amplitude until its starts are within {:.0}%. Beside each: the growth rate from the damper's equivalent stiffness and damping at that amplitude (the bench's first harmonic), and the linearised map's.",
        c.omega_rad_s,
        c.damper.name(),
        c.linearised.label.as_str(),
        c.steps_per_rev,
        c.linearised.label.as_str(),
        LINEARISATION_AMPLITUDE_M * 1e3,
        c.fit_cycles,
        (BRACKET_RATIO - 1.0) * 100.0
    ));
    rep.paragraph(&format!("Amplitude check {}.", c.headline));
    rep.paragraph(&c.statement);
    let lx: Vec<f64> = c
        .points
        .iter()
        .map(|p| (p.stroke_amplitude_m * 1e3).log10())
        .collect();
    let g: Vec<f64> = c.points.iter().map(|p| p.growth_rate_per_s).collect();
    let ge: Vec<f64> = c
        .points
        .iter()
        .map(|p| p.equivalent_growth_rate_per_s)
        .collect();
    let lin = vec![c.linearised.growth_rate_per_s; lx.len()];
    let zero = vec![0.0; lx.len()];
    let title = format!(
        "Growth rate of the {} against stroke amplitude",
        c.linearised.label.as_str()
    );
    let plot = Plot::new(
        &title,
        "log10 of the stroke amplitude [mm]",
        "growth rate [1/s]",
    )
    .points("time domain, damper live", &lx, &g)
    .line("equivalent damper at the amplitude (bench)", &lx, &ge)
    .dashed("linearised at 0.1 mm (the map)", &lx, &lin)
    .dotted("neutral", &lx, &zero);
    rep.svg(
        "Above zero the motion grows; a sign change between two amplitudes is a limit cycle.",
        &plot.to_svg(900, 420)?,
    );
    let mut env = Plot::new(
        "Stroke amplitude envelopes",
        "time [s]",
        "log10 of the stroke amplitude [mm]",
    );
    for p in &c.points {
        let t: Vec<f64> = p.envelope.iter().map(|e| e.0).collect();
        let a: Vec<f64> = p.envelope.iter().map(|e| (e.1 * 1e3).log10()).collect();
        env = env.line(&format!("start {:.2} mm", p.start_m * 1e3), &t, &a);
    }
    rep.svg(
        "Each start's cyclic lag amplitude times the damper arm.",
        &env.to_svg(900, 420)?,
    );
    let mut all: Vec<&AmplitudePoint> = c.points.iter().chain(&c.refinements).collect();
    all.sort_by(|p, q| p.start_m.total_cmp(&q.start_m));
    let rows: Vec<Vec<String>> = all
        .iter()
        .map(|p| {
            vec![
                format!("{:.3}", p.start_m * 1e3),
                format!("{:.3}", p.stroke_amplitude_m * 1e3),
                format!("{:+.5}", p.growth_rate_per_s),
                format!("{:+.5}", p.equivalent_growth_rate_per_s),
                format!("{:.1}", p.equivalent_damping_nms_per_rad),
                format!("{:.0}", p.max_force_n),
                format!("{:.3}", p.mac),
                format!("{:.2} to {:.2}", p.fit_from_s, p.fit_to_s),
                if p.bisection { "refinement" } else { "given" }.to_string(),
                p.end_of_travel.map_or(String::new(), |e| e.text()),
            ]
        })
        .collect();
    rep.table(
        &[
            "start [mm]",
            "amplitude [mm]",
            "growth rate, time domain [1/s]",
            "equivalent damper [1/s]",
            "equivalent damping [N m s/rad]",
            "largest damper force [N]",
            "MAC with the previous amplitude's mode",
            "fitted window [s]",
            "start",
            "end of travel",
        ],
        &rows,
    );
    let body = rep.finish();
    Ok(body
        .split_once("<body>")
        .map(|(_, b)| b)
        .and_then(|b| b.rsplit_once("</body>").map(|(b, _)| b))
        .unwrap_or("")
        .to_string())
}
