//! The ground-resonance map: each blade's damper linearised, the rotor's modes over the speeds.
use super::rigid_blade::{blade_decks, same_damper, RigidLagBlade};
use super::*;
use crate::hydraulics::bench::harmonic_run;
use crate::hydraulics::{DamperDeck, DamperModel, IntegratorOptions};
use crate::rotor::deck::{AirframeDof, RotorSpec};
use crate::rotor::RotorDeck;
use crate::stability::{AirframeAxis, LagBlade, LagRotor, Mode};
use anyhow::{anyhow, bail};
use std::f64::consts::PI;

/// Stroke amplitude at which a damper is linearised [m]: a small perturbation about the
/// operating point (zero mean stroke rate on the ground), 0.1 mm or about 0.03 deg of lag on
/// a 0.175 m arm.
pub const LINEARISATION_AMPLITUDE_M: f64 = 1e-4;

/// The devices' integrator on the linearisation bench: the L-stable SDIRK with the rotor
/// run's 25 sub-steps. At the lag frequency a bench cycle of 256 steps makes RK4's sub-step
/// (1.4e-4 s at 7 rad/s) so long against the chambers' rates that its own numerical damping
/// shows: the physical damper's small-amplitude damping came out 222 N m s/rad where a
/// converged integration (RK4 at 1.8e-5 s, or this) gives 39.
pub const BENCH_INTEGRATOR: IntegratorOptions = IntegratorOptions {
    scheme: crate::hydraulics::Scheme::Implicit,
    substeps: 25,
};

/// Cycles of the linearisation's harmonic run (the first harmonic of the last one) and steps
/// per cycle.
pub const BENCH_CYCLES: usize = 3;
pub const BENCH_STEPS_PER_CYCLE: usize = 128;

/// Revolution steps of the Floquet integration (RK4; the multipliers converge as h^4).
pub const FLOQUET_STEPS_PER_REV: usize = 512;

/// How a speed's modes were found.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Method {
    Coleman,
    Floquet,
}

impl Method {
    pub fn name(self) -> &'static str {
        match self {
            Method::Coleman => "coleman",
            Method::Floquet => "floquet",
        }
    }
}

/// A blade's damper linearised at one speed, moved to the lag hinge (`arm^2` times the
/// stroke's values).
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct LinearisedDamper {
    /// Blade (1-based).
    pub blade: usize,
    /// Lag frequency in the rotating frame it was linearised at [rad/s].
    pub frequency_rad_s: f64,
    pub stiffness_nm_per_rad: f64,
    pub damping_nms_per_rad: f64,
}

/// The modes at one rotor speed.
#[derive(Clone, Debug)]
pub struct SpeedModes {
    pub omega_rad_s: f64,
    pub method: Method,
    pub modes: Vec<Mode>,
    pub dampers: Vec<LinearisedDamper>,
}

/// A speed range where a mode grows (ends by linear interpolation of the growth rate between
/// the speeds of the map; open ends at the map's first or last speed).
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct UnstableRange {
    pub mode: String,
    pub from_rad_s: f64,
    pub to_rad_s: f64,
    pub max_growth_rate_per_s: f64,
}

/// A stability map over rotor speeds.
#[derive(Clone, Debug)]
pub struct StabilityMap {
    pub damper: DamperModel,
    pub blades: Vec<LagBlade>,
    pub x: Option<AirframeAxis>,
    pub y: Option<AirframeAxis>,
    pub speeds: Vec<SpeedModes>,
    pub unstable: Vec<UnstableRange>,
    /// What the reduced model leaves out, in words.
    pub notes: Vec<String>,
    /// The deck values overridden (`--set`, a sweep case's), as (key, value) for summary.json.
    pub overrides: Vec<(String, String)>,
    /// Air resonance in hover ([`air`]); `None` on the ground.
    pub hover: Option<air::HoverReport>,
    /// The verdicts with their bands ([`super::band`]; empty until the job computes them).
    pub verdicts: Vec<super::band::Verdict>,
}

impl StabilityMap {
    /// Least damping ratio over the map, its mode and speed.
    pub fn min_damping(&self) -> Option<(f64, String, f64)> {
        self.speeds
            .iter()
            .flat_map(|s| {
                s.modes
                    .iter()
                    .map(move |m| (m.damping_ratio, m.name(), s.omega_rad_s))
            })
            .min_by(|a, b| a.0.total_cmp(&b.0))
    }
}

/// The airframe's in-plane directions at the hub: x and y translations, and a roll or pitch
/// about a centre off the hub plane as the hub translation it carries (`y = c theta`: mass
/// `I / c^2`, and so the spring and damper). Returns (x, y, notes on what is left out).
pub(crate) fn in_plane(
    dofs: &[AirframeDof],
    file: &str,
) -> anyhow::Result<(Option<AirframeAxis>, Option<AirframeAxis>, Vec<String>)> {
    let (mut x, mut y, mut notes) = (None, None, vec![]);
    for d in dofs {
        let axis = |s: f64| AirframeAxis {
            mass_kg: d.mass * s,
            stiffness_n_per_m: d.stiffness * s,
            damping_ns_per_m: d.damping * s,
        };
        let (slot, a) = match (d.rotation, d.axis) {
            (false, 0) => (&mut x, axis(1.0)),
            (false, 1) => (&mut y, axis(1.0)),
            (true, _) if d.center_z_m != 0.0 => {
                let c2 = 1.0 / (d.center_z_m * d.center_z_m);
                (if d.axis == 0 { &mut y } else { &mut x }, axis(c2))
            }
            _ => {
                notes.push(format!(
                    "airframe {} is not in the in-plane model (ground resonance couples the lag modes with the hub's in-plane motion)",
                    d.name
                ));
                continue;
            }
        };
        if slot.is_some() {
            notes.push(format!(
                "airframe {}: a second in-plane direction on the same hub axis, left out",
                d.name
            ));
        } else {
            *slot = Some(a);
        }
    }
    if x.is_none() && y.is_none() {
        bail!("rotor deck {file}: [airframe] has no in-plane direction: ground resonance needs the hub to move in x or y (add airframe.x and airframe.y with mass_kg, stiffness_N_per_m, damping_Ns_per_m, docs/rotor_deck.md)");
    }
    Ok((x, y, notes))
}

/// The damper of `deck` as `model` linearised at the rotating-frame frequency `w` [rad/s]
/// and moved to the lag hinge: the linear dashpot exactly, the other models by their first
/// harmonic at [`LINEARISATION_AMPLITUDE_M`] (the bench's K' and K''/w).
pub(crate) fn linearise(
    damper: &DamperDeck,
    model: DamperModel,
    arm_m: f64,
    w: f64,
) -> anyhow::Result<(f64, f64)> {
    linearise_at(
        damper,
        model,
        arm_m,
        w,
        LINEARISATION_AMPLITUDE_M,
        BENCH_INTEGRATOR,
    )
}

/// As [`linearise`], at the stroke amplitude `amplitude_m`: the damper's equivalent stiffness
/// and damping at that amplitude (the bench's first harmonic), moved to the lag hinge.
pub(crate) fn linearise_at(
    damper: &DamperDeck,
    model: DamperModel,
    arm_m: f64,
    w: f64,
    amplitude_m: f64,
    integrator: IntegratorOptions,
) -> anyhow::Result<(f64, f64)> {
    let a2 = arm_m * arm_m;
    if model == DamperModel::Linear {
        let c = damper
            .linear_c_n_s_per_m
            .ok_or_else(|| anyhow!("{}: no [damper.linear] table", damper.source))?;
        return Ok((0.0, a2 * c));
    }
    let (storage, loss) =
        bench_cache::stiffnesses(damper, model, w, amplitude_m, integrator, || {
            let dev = damper.build(model, integrator)?;
            let r = harmonic_run(
                dev.as_ref(),
                w,
                w * amplitude_m,
                BENCH_CYCLES,
                BENCH_STEPS_PER_CYCLE,
                false,
            )?;
            Ok((r.storage_stiffness_n_per_m, r.loss_stiffness_n_per_m))
        })?;
    Ok((a2 * storage, a2 * loss / w))
}

/// The bench runs of [`linearise_at`] already made in this process, by everything that decides
/// them: the damper deck's values (all of them, as `Debug` prints them: every `f64` in its
/// shortest round-trip form, so two keys are equal exactly when the values are bit for bit,
/// -0 and 0 apart), the model, the frequency and amplitude (bits) and the integrator. A hit
/// returns what the run returned, so a map is bit for bit the one computed without it. The
/// verdicts' bands recompute the map once per moved value and end: the values that do not
/// touch the damper (the airframe's, the blade's) find their dampers' runs at the frequencies
/// the nominal map met (docs/performance.md). Only successes are kept; a caller finding a run
/// under way waits for it instead of repeating it.
mod bench_cache {
    use super::{DamperDeck, DamperModel, IntegratorOptions};
    use std::collections::HashMap;
    use std::sync::{Arc, Mutex, PoisonError};

    /// Entries kept before the cache starts over (a few kB each).
    const MAX_ENTRIES: usize = 4096;

    type Slot = Arc<Mutex<Option<(f64, f64)>>>;
    static RUNS: Mutex<Option<HashMap<String, Slot>>> = Mutex::new(None);

    /// The bench's storage and loss stiffnesses [N/m] of `damper` as `model` at `w` [rad/s]
    /// and stroke amplitude `amplitude_m`: from the cache, or `run` (kept when it succeeds).
    pub(super) fn stiffnesses(
        damper: &DamperDeck,
        model: DamperModel,
        w: f64,
        amplitude_m: f64,
        integrator: IntegratorOptions,
        run: impl FnOnce() -> anyhow::Result<(f64, f64)>,
    ) -> anyhow::Result<(f64, f64)> {
        let key = format!(
            "{model:?} {:016x} {:016x} {integrator:?} {damper:?}",
            w.to_bits(),
            amplitude_m.to_bits()
        );
        let slot = {
            let mut runs = RUNS.lock().unwrap_or_else(PoisonError::into_inner);
            let runs = runs.get_or_insert_with(HashMap::new);
            if runs.len() >= MAX_ENTRIES && !runs.contains_key(&key) {
                runs.clear();
            }
            runs.entry(key).or_default().clone()
        };
        let mut done = slot.lock().unwrap_or_else(PoisonError::into_inner);
        if let Some(kc) = *done {
            return Ok(kc);
        }
        let kc = run()?;
        *done = Some(kc);
        Ok(kc)
    }
}

/// One blade of `spec` with its damper linearised at `w`.
fn blade(
    spec: &RotorSpec,
    deck_path: &std::path::Path,
    damper: &DamperDeck,
    model: DamperModel,
    w: f64,
) -> anyhow::Result<(LagBlade, (f64, f64))> {
    let r = RigidLagBlade::of(spec, deck_path)?;
    let kc = linearise(damper, model, r.damper_arm_m, w)?;
    Ok((r.lag_blade(kc), kc))
}

/// The stability map of `deck` (its blades' own decks, per-blade differences applied) with
/// damper model `model` at the rotor speeds `speeds_rad_s`.
pub fn stability_map(
    deck: &RotorDeck,
    model: DamperModel,
    speeds_rad_s: &[f64],
) -> anyhow::Result<StabilityMap> {
    let file = deck.path.display().to_string();
    check_speeds("speeds", speeds_rad_s)?;
    let Some(af) = &deck.spec.airframe else {
        bail!("rotor deck {file} has no [airframe]: ground resonance is the rotor's lag modes coupled with the airframe under the hub; add [airframe] with x and y (mass_kg, stiffness_N_per_m, damping_Ns_per_m) or [[airframe.mode]] tables (docs/rotor_deck.md, \"The airframe under the hub\")");
    };
    let (x, y, mut notes) = in_plane(&af.dofs(), &file)?;
    let n = deck.spec.rotor.blades;
    let specs = blade_decks(deck, model)?;
    notes.push("blades rigid on their lag hinges: no flap, no elastic bending; no aerodynamics (a rotor on the ground)".into());
    let mut speeds = Vec::with_capacity(speeds_rad_s.len());
    let mut nominal_blades = vec![];
    for &om in speeds_rad_s {
        // the damper linearised at the regressing lag's rotating-frame frequency: first the
        // blade's own lag frequency, then (once) the coupled mode's
        let mut w = RigidLagBlade::of(&specs[0].0.spec, &specs[0].0.path)?.lag_frequency_rad_s(om);
        let mut result = None;
        for _ in 0..2 {
            let w_lin = w.max(0.05 * om).max(0.1);
            let mut blades = Vec::with_capacity(n);
            let mut dampers = Vec::with_capacity(n);
            // identical dampers are linearised once
            let mut done: Vec<(usize, (f64, f64))> = vec![];
            for (k, (b, d)) in specs.iter().enumerate() {
                let same = done.iter().find(|(j, _)| same_damper(&specs, *j, k));
                let (lb, kc) = match same {
                    Some(&(_, kc)) => (RigidLagBlade::of(&b.spec, &b.path)?.lag_blade(kc), kc),
                    None => {
                        let r = blade(&b.spec, &b.path, d, model, w_lin)
                            .map_err(|e| anyhow!("blade {}: {e:#}", k + 1))?;
                        done.push((k, r.1));
                        r
                    }
                };
                dampers.push(LinearisedDamper {
                    blade: k + 1,
                    frequency_rad_s: w_lin,
                    stiffness_nm_per_rad: kc.0,
                    damping_nms_per_rad: kc.1,
                });
                blades.push(lb);
            }
            let rotor = LagRotor {
                blades,
                x: x.clone(),
                y: y.clone(),
            };
            rotor
                .validate()
                .map_err(|e| anyhow!("rotor deck {file}: the reduced lag model: {e}"))?;
            let (method, modes) = if rotor.is_isotropic() && n >= 3 {
                (Method::Coleman, rotor.coleman_eigenvalues(om))
            } else {
                (Method::Floquet, rotor.floquet(om, FLOQUET_STEPS_PER_REV))
            };
            let modes = modes
                .map_err(|e| anyhow!("rotor deck {file}: {} at {om} rad/s: {e}", method.name()))?;
            if let Some(r) = modes
                .iter()
                .find(|m| m.label == crate::stability::ModeLabel::RegressingLag)
            {
                w = (om - 2.0 * PI * r.frequency_hz).abs();
            }
            nominal_blades = rotor.blades.clone();
            result = Some(SpeedModes {
                omega_rad_s: om,
                method,
                modes,
                dampers,
            });
            if model == DamperModel::Linear {
                break; // frequency-independent
            }
        }
        speeds.extend(result);
    }
    let unstable = unstable_ranges(&speeds);
    Ok(StabilityMap {
        damper: model,
        blades: nominal_blades,
        x,
        y,
        speeds,
        unstable,
        notes,
        overrides: Vec::new(),
        verdicts: Vec::new(),
        hover: None,
    })
}

/// Most speeds of one map (each is an eigen-analysis or a Floquet integration).
pub const MAX_SPEEDS: usize = 2000;

/// Rotor speeds of a map given as `name` (an option or a plan key): `START:STOP:STEP`
/// (inclusive) or `a,b,c`, in rad/s, increasing.
pub fn parse_speeds(name: &str, s: &str) -> anyhow::Result<Vec<f64>> {
    const EXPECTED: &str =
        "expected START:STOP:STEP in rad/s, e.g. 5:40:0.5, or an increasing list 10,20,30";
    let v = crate::run::ranges::parse_range(name, s, EXPECTED, MAX_SPEEDS, "a map may have")?;
    check_speeds(name, &v).map_err(|e| anyhow!("{e:#} ({EXPECTED})"))?;
    Ok(v)
}

/// Refuses speeds `name` [rad/s] that look like fractions of `deck`'s nominal speed.
pub fn check_rad_s(name: &str, speeds: &[f64], deck: &RotorDeck) -> anyhow::Result<()> {
    let nominal = deck.spec.rotor.omega_rad_s;
    crate::run::ranges::check_not_fractions(name, speeds, nominal, &deck.path, "rotor.omega_rad_s")
}

/// Speeds `name` in rad/s: finite, positive, strictly increasing.
pub fn check_speeds(name: &str, s: &[f64]) -> anyhow::Result<()> {
    crate::run::ranges::check_increasing(name, s, "rad/s", "rotor speed")
}

/// Contiguous speeds where a mode's growth rate is positive.
pub(crate) fn unstable_ranges(speeds: &[SpeedModes]) -> Vec<UnstableRange> {
    let mut labels: Vec<String> = vec![];
    for s in speeds {
        for m in &s.modes {
            let l = m.label.to_string();
            if !labels.contains(&l) {
                labels.push(l);
            }
        }
    }
    let mut out = vec![];
    for l in labels {
        let g: Vec<(f64, f64)> = speeds
            .iter()
            .filter_map(|s| {
                s.modes
                    .iter()
                    .filter(|m| m.label.to_string() == l)
                    .map(|m| m.growth_rate_per_s)
                    .max_by(f64::total_cmp)
                    .map(|g| (s.omega_rad_s, g))
            })
            .collect();
        let cross = |a: (f64, f64), b: (f64, f64)| a.0 + (b.0 - a.0) * a.1 / (a.1 - b.1);
        let mut i = 0;
        while i < g.len() {
            if g[i].1 <= 0.0 {
                i += 1;
                continue;
            }
            let start = i;
            while i + 1 < g.len() && g[i + 1].1 > 0.0 {
                i += 1;
            }
            let from = if start > 0 {
                cross(g[start - 1], g[start])
            } else {
                g[start].0
            };
            let to = if i + 1 < g.len() {
                cross(g[i], g[i + 1])
            } else {
                g[i].0
            };
            out.push(UnstableRange {
                mode: l.clone(),
                from_rad_s: from,
                to_rad_s: to,
                max_growth_rate_per_s: g[start..=i].iter().map(|p| p.1).fold(0.0, f64::max),
            });
            i += 1;
        }
    }
    out
}
