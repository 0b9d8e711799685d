//! Ground resonance of a rotor deck on its airframe (docs/stability.md): the deck's blades
//! reduced to rigid blades on their lag hinges ([`crate::stability`]), each blade's damper
//! linearised at the operating point, the airframe's in-plane directions under the hub, over a
//! range of rotor speeds. Isotropic rotors: eigenvalues of the constant-coefficient equations
//! in multi-blade (Coleman) coordinates; rotors whose blades differ: Floquet exponents of the
//! periodic equations over one revolution.
use super::rigid_blade::{blade_decks, same_damper, RigidLagBlade};
use crate::hydraulics::bench::harmonic_run;
use crate::hydraulics::{DamperDeck, DamperModel, IntegratorOptions};
use crate::io::OutDir;
use crate::report::html::{Banner, HtmlReport};
use crate::report::plot::Plot;
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
    /// Air resonance in hover ([`super::air_resonance`]); `None` on the ground.
    pub hover: Option<super::air_resonance::HoverReport>,
}

impl StabilityMap {
    /// Least damping ratio over the map, its mode and speed.
    pub fn min_damping(&self) -> Option<(f64, String, f64)> {
        self.speeds
            .iter()
            .flat_map(|s| {
                s.modes
                    .iter()
                    .map(move |m| (m.damping_ratio, m.label.to_string(), s.omega_rad_s))
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
    let dev = damper.build(model, integrator)?;
    let r = harmonic_run(
        dev.as_ref(),
        w,
        w * amplitude_m,
        BENCH_CYCLES,
        BENCH_STEPS_PER_CYCLE,
        false,
    )?;
    Ok((
        a2 * r.storage_stiffness_n_per_m,
        a2 * r.loss_stiffness_n_per_m / w,
    ))
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
    let v = super::ranges::parse_range(name, s, EXPECTED, MAX_SPEEDS, "a map may have")?;
    check_speeds(name, &v).map_err(|e| anyhow!("{e:#} ({EXPECTED})"))?;
    Ok(v)
}

/// Refuses speeds `name` [rad/s] that look like fractions of `deck`'s nominal speed.
pub fn check_rad_s(name: &str, speeds: &[f64], deck: &RotorDeck) -> anyhow::Result<()> {
    let nominal = deck.spec.rotor.omega_rad_s;
    super::ranges::check_not_fractions(name, speeds, nominal, &deck.path, "rotor.omega_rad_s")
}

/// Speeds `name` in rad/s: finite, positive, strictly increasing.
pub fn check_speeds(name: &str, s: &[f64]) -> anyhow::Result<()> {
    super::ranges::check_increasing(name, s, "rad/s", "rotor speed")
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

/// stability.csv: one row per speed and mode.
pub fn csv(map: &StabilityMap) -> String {
    let mut s = String::from(
        "rotor_speed_rad_s,mode,frequency_Hz,damping_ratio,growth_rate_per_s,method\n",
    );
    for sp in &map.speeds {
        for m in &sp.modes {
            s.push_str(&format!(
                "{},{},{},{},{},{}\n",
                sp.omega_rad_s,
                m.label,
                m.frequency_hz,
                m.damping_ratio,
                m.growth_rate_per_s,
                sp.method.name()
            ));
        }
    }
    s
}

/// summary.json: the reduced model, the unstable ranges and the least damping.
pub fn summary_json(map: &StabilityMap, deck: &RotorDeck) -> serde_json::Value {
    let blades: Vec<_> = map
        .blades
        .iter()
        .map(|b| {
            serde_json::json!({
                "mass_kg": b.mass_kg,
                "first_moment_kg_m": b.first_moment_kg_m,
                "inertia_kg_m2": b.inertia_kg_m2,
                "hinge_offset_m": b.hinge_offset_m,
                "lag_stiffness_Nm_per_rad": b.stiffness_nm_per_rad,
                "lag_damping_Nms_per_rad": b.damping_nms_per_rad,
            })
        })
        .collect();
    let axis = |a: &Option<AirframeAxis>| {
        a.as_ref().map(|a| {
            serde_json::json!({
                "mass_kg": a.mass_kg,
                "stiffness_N_per_m": a.stiffness_n_per_m,
                "damping_Ns_per_m": a.damping_ns_per_m,
            })
        })
    };
    let min = map.min_damping();
    serde_json::json!({
        "rotor_deck": deck.path.display().to_string(),
        "rotor": deck.path.display().to_string(),
        "options": {
            "overrides": map.overrides.iter().map(|(k, v)| serde_json::json!({"key": k, "value": v})).collect::<Vec<_>>(),
        },
        "damper_model": map.damper.name(),
        "linearisation_amplitude_m": LINEARISATION_AMPLITUDE_M,
        "method": map.speeds.first().map(|s| s.method.name()),
        "speeds_rad_s": map.speeds.iter().map(|s| s.omega_rad_s).collect::<Vec<_>>(),
        "blades_at_last_speed": blades,
        "airframe_x": axis(&map.x),
        "airframe_y": axis(&map.y),
        "stable": map.unstable.is_empty(),
        "unstable": map.unstable,
        "min_damping_ratio": min.as_ref().map(|m| m.0),
        "min_damping_mode": min.as_ref().map(|m| m.1.clone()),
        "min_damping_speed_rad_s": min.as_ref().map(|m| m.2),
        "condition": if map.hover.is_some() { "hover" } else { "ground" },
        "hover": map.hover,
        "notes": map.notes,
    })
}

/// stability.html: the Coleman diagram, damping versus speed with the unstable ranges shaded,
/// the reduced model and the ranges.
pub fn html(map: &StabilityMap, deck: &RotorDeck) -> anyhow::Result<String> {
    let mut rep = HtmlReport::new(if map.hover.is_some() {
        "Air resonance in hover"
    } else {
        "Ground resonance"
    });
    let method = map
        .speeds
        .first()
        .map_or("", |s| s.method.name())
        .to_string();
    if map.unstable.is_empty() {
        rep.banner(
            Banner::Ok,
            &format!(
                "Stable over {:.3} to {:.3} rad/s ({} damper, {method}).",
                map.speeds.first().map_or(f64::NAN, |s| s.omega_rad_s),
                map.speeds.last().map_or(f64::NAN, |s| s.omega_rad_s),
                map.damper.name()
            ),
        );
    } else {
        let ranges: Vec<String> = map
            .unstable
            .iter()
            .map(|u| {
                format!(
                    "{} from {:.3} to {:.3} rad/s (growth rate up to {:.4} 1/s)",
                    u.mode, u.from_rad_s, u.to_rad_s, u.max_growth_rate_per_s
                )
            })
            .collect();
        rep.banner(Banner::Bad, &format!("UNSTABLE: {}.", ranges.join("; ")));
    }
    let how = if method == "coleman" {
        "identical blades: constant-coefficient equations in multi-blade coordinates"
    } else {
        "blades differ: Floquet exponents of the periodic equations over one revolution"
    };
    let _ = match &map.hover {
        None => rep.paragraph(&format!(
            "Rotor deck {}: {} blades reduced to rigid blades on their lag hinges, each damper ({}) linearised at the regressing lag's rotating-frame frequency and a stroke amplitude of {} mm, on the airframe's in-plane directions (docs/stability.md). Method: {method} ({how}).",
            deck.path.display(),
            map.blades.len(),
            map.damper.name(),
            LINEARISATION_AMPLITUDE_M * 1e3,
        )),
        Some(h) => rep.paragraph(&format!(
            "Rotor deck {}: {} blades reduced to rigid blades on coincident lag and flap hinges ({} strips each), quasi-steady aerodynamics in hover at a collective of {} deg at 0.75 R, air density {} kg/m^3 (Lock number {:.2}), each damper ({}) linearised at the regressing lag's rotating-frame frequency and a stroke amplitude of {} mm, on the airframe's directions under the hub (docs/stability.md). Method: {method} ({how}).",
            deck.path.display(),
            map.blades.len(),
            h.options.strips,
            h.options.collective_deg,
            h.options.density_kg_m3,
            h.lock_number,
            map.damper.name(),
            LINEARISATION_AMPLITUDE_M * 1e3,
        )),
    };
    let label_order: Vec<String> = {
        let mut v: Vec<String> = vec![];
        for s in &map.speeds {
            for m in &s.modes {
                let l = m.label.to_string();
                if !v.contains(&l) {
                    v.push(l);
                }
            }
        }
        v
    };
    let series = |f: &dyn Fn(&Mode) -> f64, l: &str| -> (Vec<f64>, Vec<f64>) {
        let mut xs = vec![];
        let mut ys = vec![];
        for s in &map.speeds {
            for m in s.modes.iter().filter(|m| m.label.to_string() == l) {
                xs.push(s.omega_rad_s);
                ys.push(f(m));
            }
        }
        (xs, ys)
    };
    let mut coleman = Plot::new(
        "Frequencies in the fixed frame (Coleman diagram)",
        "rotor speed [rad/s]",
        "frequency [Hz]",
    );
    let mut damping = Plot::new(
        "Damping ratio (unstable ranges shaded)",
        "rotor speed [rad/s]",
        "damping ratio [-]",
    );
    let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
    for l in &label_order {
        let (x, f) = series(&|m| m.frequency_hz, l);
        coleman = coleman.points(l, &x, &f);
        let (x, z) = series(&|m| m.damping_ratio, l);
        for v in &z {
            lo = lo.min(*v);
            hi = hi.max(*v);
        }
        damping = damping.points(l, &x, &z);
    }
    for u in &map.unstable {
        damping = damping.band(
            &format!("unstable: {}", u.mode),
            &[u.from_rad_s, u.to_rad_s],
            &[lo.min(0.0), hi],
        );
    }
    let sp: Vec<f64> = map.speeds.iter().map(|s| s.omega_rad_s).collect();
    let per_rev: Vec<f64> = sp.iter().map(|w| w / (2.0 * PI)).collect();
    coleman = coleman.dashed("1/rev", &sp, &per_rev);
    rep.heading(2, "Coleman diagram");
    rep.svg(
        "Frequencies of the coupled modes in the fixed frame against rotor speed.",
        &coleman.to_svg(900, 500)?,
    );
    rep.heading(2, "Damping");
    rep.svg(
        "Damping ratio of each mode against rotor speed; negative is unstable.",
        &damping.to_svg(900, 500)?,
    );
    if !map.unstable.is_empty() {
        let rows: Vec<Vec<String>> = map
            .unstable
            .iter()
            .map(|u| {
                vec![
                    u.mode.clone(),
                    format!("{:.4}", u.from_rad_s),
                    format!("{:.4}", u.to_rad_s),
                    format!("{:.5}", u.max_growth_rate_per_s),
                ]
            })
            .collect();
        rep.table(
            &[
                "mode",
                "from [rad/s]",
                "to [rad/s]",
                "largest growth rate [1/s]",
            ],
            &rows,
        );
    }
    rep.heading(2, "The reduced model");
    let rows: Vec<Vec<String>> = map
        .blades
        .iter()
        .enumerate()
        .map(|(k, b)| {
            vec![
                format!("{}", k + 1),
                format!("{:.2}", b.mass_kg),
                format!("{:.2}", b.first_moment_kg_m),
                format!("{:.2}", b.inertia_kg_m2),
                format!("{:.4}", b.hinge_offset_m),
                format!("{:.1}", b.stiffness_nm_per_rad),
                format!("{:.1}", b.damping_nms_per_rad),
            ]
        })
        .collect();
    rep.paragraph(&format!(
        "Blades at {:.3} rad/s (the damper's values depend on the frequency it is linearised at):",
        sp.last().copied().unwrap_or(f64::NAN)
    ));
    rep.table(
        &[
            "blade",
            "mass [kg]",
            "first moment [kg m]",
            "inertia [kg m^2]",
            "hinge offset [m]",
            "lag stiffness [N m/rad]",
            "lag damping [N m s/rad]",
        ],
        &rows,
    );
    let axis = |n: &str, a: &Option<AirframeAxis>| {
        a.as_ref().map(|a| {
            vec![
                n.to_string(),
                format!("{:.1}", a.mass_kg),
                format!("{:.1}", a.stiffness_n_per_m),
                format!("{:.1}", a.damping_ns_per_m),
            ]
        })
    };
    let rows: Vec<Vec<String>> = [axis("x", &map.x), axis("y", &map.y)]
        .into_iter()
        .flatten()
        .collect();
    if !rows.is_empty() {
        rep.table(
            &[
                "airframe",
                "mass [kg]",
                "stiffness [N/m]",
                "damping [N s/m]",
            ],
            &rows,
        );
    }
    if let Some(h) = &map.hover {
        let rows: Vec<Vec<String>> = h
            .airframe
            .iter()
            .map(|(n, m, k, c, z)| {
                vec![
                    n.clone(),
                    format!("{m:.1}"),
                    format!("{k:.1}"),
                    format!("{c:.1}"),
                    format!("{z:.3}"),
                ]
            })
            .collect();
        rep.table(
            &[
                "airframe",
                "mass [kg] or inertia [kg m^2]",
                "stiffness [N/m or N m/rad]",
                "damping [N s/m or N m s/rad]",
                "centre above the hub [m]",
            ],
            &rows,
        );
        rep.heading(2, "Hover equilibrium");
        let rows: Vec<Vec<String>> = h
            .states
            .iter()
            .map(|s| {
                vec![
                    format!("{:.3}", s.omega_rad_s),
                    format!("{:.0}", s.thrust_n),
                    format!("{:.3}", s.induced_velocity_m_s),
                    format!("{:.3}", s.coning_deg),
                    format!("{:.3}", s.lag_deg),
                ]
            })
            .collect();
        rep.table(
            &[
                "rotor speed [rad/s]",
                "thrust [N]",
                "induced velocity [m/s]",
                "coning [deg]",
                "lag [deg]",
            ],
            &rows,
        );
    }
    rep.list(&map.notes);
    Ok(rep.finish())
}

/// Writes stability.csv, stability.html and summary.json into `out`.
pub fn write(map: &StabilityMap, deck: &RotorDeck, out: &OutDir) -> anyhow::Result<()> {
    write_with_time(map, &[], deck, out)
}

/// As [`write`], with the time-domain checks: rows of method `time` (mode `whole rotor`), a
/// table and figure in the report, `time_checks` in summary.json.
pub fn write_with_time(
    map: &StabilityMap,
    time: &[TimeCheck],
    deck: &RotorDeck,
    out: &OutDir,
) -> anyhow::Result<()> {
    write_all(map, time, None, deck, out)
}

/// As [`write_with_time`], with the nonlinear amplitude check: amplitude.csv, its section in
/// the report, `amplitude_check` in summary.json.
pub fn write_all(
    map: &StabilityMap,
    time: &[TimeCheck],
    amplitude: Option<&super::amplitude::AmplitudeCheck>,
    deck: &RotorDeck,
    out: &OutDir,
) -> anyhow::Result<()> {
    let mut text = csv(map);
    for c in time {
        let w = 2.0 * PI * c.frequency_hz;
        let zeta = -c.growth_rate_per_s / c.growth_rate_per_s.hypot(w);
        text.push_str(&format!(
            "{},whole rotor,{},{},{},time\n",
            c.omega_rad_s, c.frequency_hz, zeta, c.growth_rate_per_s
        ));
    }
    out.write("stability.csv", text.as_bytes())?;
    let mut page = html(map, deck)?;
    if !time.is_empty() {
        let mut rep = HtmlReport::new("");
        rep.heading(2, "Time domain: the whole rotor");
        rep.paragraph(&format!(
            "The whole multibody rotor on its airframe (every blade, its damper, the hub on the airframe's chain), in rotating equilibrium without airloads, kicked along x by {} m/s and marched {} s; the growth rate is the slope of ln|x| at the peaks of the airframe's x motion from {} s on, beside the {} analysis's least stable growth rate at the same speed.",
            time[0].kick_m_s,
            time[0].time_s.last().copied().unwrap_or(f64::NAN),
            time[0].fit_from_s,
            map.speeds.first().map_or("linear", |s| s.method.name())
        ));
        let mut rows = vec![];
        let mut plot = Plot::new("Airframe x after the kick", "time [s]", "airframe x [m]");
        for c in time {
            let linear = map
                .speeds
                .iter()
                .find(|s| s.omega_rad_s == c.omega_rad_s)
                .and_then(|s| {
                    s.modes
                        .iter()
                        .map(|m| m.growth_rate_per_s)
                        .max_by(f64::total_cmp)
                });
            rows.push(vec![
                format!("{}", c.omega_rad_s),
                format!("{:+.5}", c.growth_rate_per_s),
                format!("{:.4}", c.frequency_hz),
                linear.map_or("-".into(), |g| format!("{g:+.5}")),
                linear.map_or("-".into(), |g| {
                    format!("{:.2}%", 100.0 * (c.growth_rate_per_s / g - 1.0).abs())
                }),
            ]);
            plot = plot.line(
                &format!("{} rad/s", c.omega_rad_s),
                &c.time_s,
                &c.airframe_x_m,
            );
        }
        rep.table(
            &[
                "rotor speed [rad/s]",
                "whole rotor growth rate [1/s]",
                "frequency [Hz]",
                "linear analysis [1/s]",
                "difference",
            ],
            &rows,
        );
        rep.svg(
            "The airframe's x motion after the kick.",
            &plot.to_svg(900, 450)?,
        );
        // the section goes before the reduced model
        let body = rep.finish();
        let section = body
            .split_once("<body>")
            .map(|(_, b)| b)
            .and_then(|b| b.rsplit_once("</body>").map(|(b, _)| b))
            .unwrap_or("")
            .to_string();
        page = match page.find("<h2 id=\"the-reduced-model\"") {
            Some(i) => format!("{}{}{}", &page[..i], section, &page[i..]),
            None => page.replace("</body>", &format!("{section}</body>")),
        };
    }
    if let Some(a) = amplitude {
        out.write("amplitude.csv", super::amplitude::csv(a).as_bytes())?;
        let section = super::amplitude::html_section(a)?;
        page = match page.find("<h2 id=\"the-reduced-model\"") {
            Some(i) => format!("{}{}{}", &page[..i], section, &page[i..]),
            None => page.replace("</body>", &format!("{section}</body>")),
        };
    }
    out.write("stability.html", page.as_bytes())?;
    let mut summary = summary_json(map, deck);
    if let Some(a) = amplitude {
        summary["amplitude_check"] = super::amplitude::json(a);
    }
    summary["time_checks"] = serde_json::Value::Array(
        time.iter()
            .map(|c| {
                serde_json::json!({
                    "rotor_speed_rad_s": c.omega_rad_s,
                    "kick_m_s": c.kick_m_s,
                    "duration_s": c.time_s.last(),
                    "fit_from_s": c.fit_from_s,
                    "growth_rate_per_s": c.growth_rate_per_s,
                    "frequency_Hz": c.frequency_hz,
                })
            })
            .collect(),
    );
    out.write(
        "summary.json",
        serde_json::to_string_pretty(&summary)?.as_bytes(),
    )?;
    Ok(())
}

/// The whole multibody rotor on its airframe at one speed, kicked along the hub's x axis:
/// its airframe x motion and the growth rate and frequency fitted to it.
#[derive(Clone, Debug)]
pub struct TimeCheck {
    pub omega_rad_s: f64,
    /// Velocity of the kick [m/s].
    pub kick_m_s: f64,
    pub time_s: Vec<f64>,
    pub airframe_x_m: Vec<f64>,
    /// Slope of ln|x| at its peaks over the fitted window [1/s].
    pub growth_rate_per_s: f64,
    /// From the spacing of the peaks of |x| in the window [Hz].
    pub frequency_hz: f64,
    /// Start of the fitted window [s] (the kick's faster modes have died out before it).
    pub fit_from_s: f64,
}

/// A flight record of no airloads and no controls at `omega` for the rotor of `spec`: a
/// rotor on the ground.
fn ground_record(spec: &RotorSpec, omega: f64) -> anyhow::Result<crate::flight::FlightRecord> {
    use crate::flight::record::FlightMeta;
    let meta = serde_json::json!({
        "synthetic": true,
        "description": "no airloads: a rotor on the ground (rotorsim stability)",
        "rotor_speed_rad_s": omega,
        "radius_m": spec.rotor.radius_m,
        "controls_deg": {"collective": 0.0, "lateral_cyclic": 0.0, "longitudinal_cyclic": 0.0},
    });
    let serde_json::Value::Object(raw) = meta else {
        bail!("ground record metadata");
    };
    let meta = FlightMeta::from_json(raw, std::path::Path::new("<ground record>"))?;
    let az = vec![0.0, 90.0, 180.0, 270.0];
    let n = 2 * az.len();
    // a record holds a damper channel: none was measured, zeros stand in (never compared)
    let damper = az
        .iter()
        .map(|&a| crate::flight::record::DamperSample {
            revolution: 0,
            azimuth_deg: a,
            force_N: 0.0,
            stroke_m: None,
        })
        .collect();
    Ok(crate::flight::FlightRecord::new(
        meta,
        vec![0.5, 1.0],
        vec![0],
        az,
        vec![0.0; n],
        vec![0.0; n],
        vec![0.0; n],
        damper,
    )?)
}

/// Airframe motion up to which a kicked response is fitted [m]: small against the rotor, so
/// that the lag angles stay small and the linear analysis applies (a growing response is
/// stopped there).
pub const TIME_FIT_MAX_M: f64 = 0.01;

/// Growth rate and frequency of `x(t)` after `from_s` and before `|x|` first exceeds
/// [`TIME_FIT_MAX_M`]. The frequency from the mean spacing of the peaks of `|x|`; the growth
/// rate as the least-squares slope of `ln E / 2` against time over every sample, `E = x^2 +
/// (x'/omega)^2` (x' by central differences): for a growing oscillation `E` grows smoothly,
/// without the peaks' sampling of the cycle.
pub fn fit_growth(t: &[f64], x: &[f64], from_s: f64) -> Option<(f64, f64)> {
    let end = x
        .iter()
        .position(|v| v.abs() > TIME_FIT_MAX_M)
        .unwrap_or(x.len());
    // a decaying response ends where it meets the solver's noise: 1e-4 of its largest value
    let top = x
        .iter()
        .zip(t)
        .filter(|(_, ti)| **ti >= from_s)
        .fold(0.0f64, |m, (v, _)| m.max(v.abs()));
    let end = match x
        .iter()
        .zip(t)
        .rposition(|(v, ti)| *ti >= from_s && v.abs() > 1e-4 * top)
    {
        Some(i) => end.min(i + 1),
        None => end,
    };
    let (t, x) = (&t[..end], &x[..end]);
    let peaks: Vec<f64> = (1..x.len().saturating_sub(1))
        .filter(|&i| t[i] >= from_s && x[i].abs() > x[i - 1].abs() && x[i].abs() >= x[i + 1].abs())
        .map(|i| t[i])
        .collect();
    if peaks.len() < 6 {
        return None;
    }
    let f = 0.5 * (peaks.len() - 1) as f64 / (peaks[peaks.len() - 1] - peaks[0]);
    let w = 2.0 * std::f64::consts::PI * f;
    // whole cycles of the window, so that what is left of the cycle in E averages out
    let (a, b) = (peaks[0], peaks[peaks.len() - 1]);
    let pts: Vec<(f64, f64)> = (1..x.len() - 1)
        .filter(|&i| t[i] >= a && t[i] <= b)
        .map(|i| {
            let v = (x[i + 1] - x[i - 1]) / (t[i + 1] - t[i - 1]);
            (t[i], 0.5 * (x[i] * x[i] + (v / w) * (v / w)).ln())
        })
        .collect();
    Some((crate::analysis::compare::slope(&pts), f))
}

/// Most steps per revolution of a time-domain check.
pub const MAX_TIME_STEPS_PER_REV: usize = 16384;
/// Most structural steps of one time-domain check (about an hour of the whole rotor).
pub const MAX_TIME_STEPS: f64 = 5e6;

/// How the time-domain check runs.
#[derive(Clone, Copy, Debug)]
pub struct TimeOptions {
    /// Velocity of the kick along x [m/s].
    pub kick_m_s: f64,
    /// Simulated time [s] (a growing response stops at [`TIME_FIT_MAX_M`]).
    pub duration_s: f64,
    /// Start of the fitted window [s].
    pub fit_from_s: f64,
    /// Structural steps per revolution.
    pub steps_per_rev: usize,
}

impl TimeOptions {
    /// The options at rotor speed `omega` [rad/s], sizes checked before anything is built or
    /// allocated.
    pub fn check(&self, omega: f64) -> anyhow::Result<()> {
        let TimeOptions {
            kick_m_s,
            duration_s,
            steps_per_rev,
            ..
        } = *self;
        if !(kick_m_s.is_finite() && kick_m_s > 0.0) {
            bail!("--kick-m-s {kick_m_s}: expected a positive velocity in m/s");
        }
        if !(duration_s.is_finite() && duration_s > 0.0) {
            bail!("--time-duration-s {duration_s}: expected a positive time in s");
        }
        if !(8..=MAX_TIME_STEPS_PER_REV).contains(&steps_per_rev) {
            bail!("--steps-per-rev {steps_per_rev}: expected 8 to {MAX_TIME_STEPS_PER_REV}");
        }
        let steps = duration_s * omega / (2.0 * PI) * steps_per_rev as f64;
        if steps > MAX_TIME_STEPS {
            bail!(
                "--time-duration-s {duration_s} at {omega} rad/s and {steps_per_rev} steps per revolution is {steps:.3e} steps, beyond the {MAX_TIME_STEPS:.0e} a time-domain check may take; shorten it"
            );
        }
        Ok(())
    }
}

impl Default for TimeOptions {
    fn default() -> Self {
        TimeOptions {
            kick_m_s: 1e-4,
            duration_s: 20.0,
            fit_from_s: 7.0,
            // 256 puts the Hammond rotor's growth rates up to 4.5% off near the coalescence,
            // 512 within 1%, 1024 within 0.04% (docs/stability.md)
            steps_per_rev: 512,
        }
    }
}

/// The time-domain check at `omega`: the deck at that speed (`sets` applied, e.g. a blade's
/// damper), the whole multibody rotor on its airframe with damper model `model`, in rotating
/// equilibrium without airloads, kicked along x and marched ([`TimeOptions`]).
pub fn time_check(
    path: &std::path::Path,
    sets: &[crate::overrides::Override],
    model: DamperModel,
    omega: f64,
    o: &TimeOptions,
) -> anyhow::Result<TimeCheck> {
    let TimeOptions {
        kick_m_s,
        duration_s,
        fit_from_s,
        steps_per_rev,
    } = *o;
    o.check(omega)?;
    let mut all = sets.to_vec();
    all.push(crate::overrides::Override::parse(&format!(
        "rotor.omega_rad_s={omega}"
    ))?);
    let deck = RotorDeck::from_file_with(path, &all)?;
    if deck.spec.airframe.is_none() {
        bail!(
            "rotor deck {} has no [airframe]: nothing to kick",
            path.display()
        );
    }
    let n = deck.spec.rotor.blades;
    let mut blades = Vec::with_capacity(n);
    for k in 1..=n {
        let b = deck.blade(k)?;
        let d = b.damper()?;
        blades.push((b, d));
    }
    let parts: Vec<(&RotorSpec, &DamperDeck)> = blades.iter().map(|(b, d)| (&b.spec, d)).collect();
    let record = ground_record(&deck.spec, omega)?;
    let opts = crate::rotor::RunOptions {
        perturbation_damping: false,
        steps_per_rev,
        ..Default::default()
    };
    let mut sim = crate::rotor::sim::build_rotor_sim(&parts, path, model, &record, &opts)?;
    use crate::rotor::ForcedResponse;
    sim.set_output_channels(false);
    let names = sim.channel_names();
    let ix = names
        .iter()
        .position(|c| c == "airframe_x_m")
        .ok_or_else(|| anyhow!("the rotor has no airframe x channel"))?;
    sim.kick_airframe(0, kick_m_s)?;
    let steps = (duration_s / sim.time_step_s()).ceil() as usize;
    let mut buf = vec![0.0; names.len()];
    let (mut t, mut x) = (Vec::with_capacity(steps), Vec::with_capacity(steps));
    let t0 = sim.time_s();
    for _ in 0..steps {
        sim.step()?;
        sim.channels(&mut buf);
        t.push(sim.time_s() - t0);
        x.push(buf[ix]);
        if buf[ix].abs() > TIME_FIT_MAX_M {
            break; // beyond what the fit uses
        }
    }
    let (g, f) = fit_growth(&t, &x, fit_from_s).ok_or_else(|| {
        anyhow!("the airframe x motion has too few peaks after {fit_from_s} s to fit a growth rate")
    })?;
    Ok(TimeCheck {
        omega_rad_s: omega,
        kick_m_s,
        time_s: t,
        airframe_x_m: x,
        growth_rate_per_s: g,
        frequency_hz: f,
        fit_from_s,
    })
}

/// Every option of `rotorsim stability` but its result folder, as given: the command's flags
/// (clap), a sweep plan's stability keys and the Python package's keyword arguments (serde,
/// through JSON) are this one type; [`StabilitySettings::job`] reads it into a
/// [`StabilityJob`]. [`StabilitySettings::default`] gives the command line's defaults (the
/// required `rotor` and `speeds` unset).
#[derive(clap::Args, serde::Serialize, serde::Deserialize, Clone, Debug, PartialEq)]
#[serde(default, deny_unknown_fields)]
pub struct StabilitySettings {
    /// Rotor deck with an `[airframe]` (docs/rotor_deck.md); per-blade differences
    /// (`[blades.K...]`, `--set blades.K...`) make the rotor anisotropic.
    #[arg(long, required = true)]
    pub rotor: Option<std::path::PathBuf>,
    /// Rotor speeds [rad/s]: START:STOP:STEP (inclusive) or a comma-separated list, increasing.
    #[arg(long, required = true)]
    pub speeds: Option<String>,
    /// Damper model linearised at each speed: linear, nonlinear or physical (default: the
    /// deck's `damper.model`).
    #[arg(long)]
    pub damper: Option<String>,
    /// Also march the whole multibody rotor on its airframe at these speeds [rad/s] (a list):
    /// kicked along x, its growth rate fitted (method `time` in stability.csv).
    #[arg(long)]
    pub time: Option<String>,
    /// Velocity of the time-domain kick along x [m/s].
    #[arg(long, default_value_t = 1e-4)]
    pub kick_m_s: f64,
    /// Simulated time of each time-domain run [s] (a growing one stops when the airframe
    /// moves 10 mm); the fit starts at 7/20 of it.
    #[arg(long, default_value_t = 20.0)]
    pub time_duration_s: f64,
    /// Structural steps per revolution of the time-domain runs (256 is up to 4.5% off in the
    /// growth rate near a coalescence, 512 within 1%).
    #[arg(long, default_value_t = 512)]
    pub steps_per_rev: usize,
    /// Nonlinear amplitude check: start the reduced rotor on its regressing lag mode at these
    /// damper stroke amplitudes [m] (an increasing list; `default` for 0.1 to 30 mm), each
    /// blade's damper a device with its valves live; growth rate against amplitude and the
    /// limit cycles (amplitude.csv).
    #[arg(long)]
    pub amplitudes_m: Option<String>,
    /// Rotor speed of the amplitude check [rad/s] (default: the deck's rotor.omega_rad_s).
    #[arg(long)]
    pub amplitude_at_rad_s: Option<f64>,
    /// Air resonance in hover instead of ground resonance: rigid blades that lag and flap,
    /// quasi-steady aerodynamics (the deck's `[aero]`), on the airframe's x, y, roll and pitch.
    #[arg(long)]
    pub hover: bool,
    /// Hover: blade pitch at 0.75 R [deg] (the deck's twist about it).
    #[arg(long, default_value_t = 8.0)]
    pub collective_deg: f64,
    /// Hover: air density [kg/m^3] (sea-level standard by default).
    #[arg(long, default_value_t = 1.225)]
    pub density_kg_m3: f64,
    /// Hover: speed of sound [m/s] (the aerofoil tables' Mach number).
    #[arg(long, default_value_t = 340.3)]
    pub speed_of_sound_m_s: f64,
    /// Hover: strips per blade from the hinge to the tip (mass and aerodynamics).
    #[arg(long, default_value_t = crate::run::air_resonance::DEFAULT_STRIPS)]
    pub strips: usize,
    /// Override a deck value by its dotted path before validation (repeatable), as for run.
    #[arg(long = "set", value_name = "KEY=VALUE", value_parser = crate::run::job::parse_set)]
    #[serde(with = "crate::run::job::set_texts")]
    pub set: Vec<crate::overrides::Override>,
}

impl Default for StabilitySettings {
    fn default() -> Self {
        super::settings::command_line_defaults("stability")
    }
}

impl super::settings::JobSettings for StabilitySettings {
    const COMMAND: &'static str = "stability";
}

impl StabilitySettings {
    /// The stability run these settings ask for into `out` (its options checked when it runs).
    pub fn job(&self, out: impl Into<std::path::PathBuf>) -> anyhow::Result<StabilityJob> {
        use super::settings::required;
        let rotor = required(&self.rotor, "--rotor", "a rotor deck with an [airframe]")?;
        let speeds = required(&self.speeds, "--speeds", "rotor speeds in rad/s")?;
        Ok(StabilityJob {
            rotor: rotor.clone(),
            speeds: speeds.clone(),
            damper: self.damper.clone(),
            time_speeds: self.time.clone(),
            time: TimeOptions {
                kick_m_s: self.kick_m_s,
                duration_s: self.time_duration_s,
                fit_from_s: self.time_duration_s * 7.0 / 20.0,
                steps_per_rev: self.steps_per_rev,
            },
            amplitudes_m: self.amplitudes_m.clone(),
            amplitude_at_rad_s: self.amplitude_at_rad_s,
            hover: self.hover,
            hover_options: super::air_resonance::HoverOptions {
                collective_deg: self.collective_deg,
                density_kg_m3: self.density_kg_m3,
                speed_of_sound_m_s: self.speed_of_sound_m_s,
                strips: self.strips,
            },
            set: self.set.clone(),
            out: out.into(),
        })
    }
}

/// `rotorsim stability` as a library call: the command's options, typed ([`StabilityJob::new`]
/// gives its defaults), checked and run by [`StabilityJob::execute`] into its result folder.
/// The command line and the Python package both run through it.
#[derive(Clone, Debug)]
pub struct StabilityJob {
    /// Rotor deck with an `[airframe]`.
    pub rotor: std::path::PathBuf,
    /// Rotor speeds [rad/s]: START:STOP:STEP (inclusive) or a comma-separated list.
    pub speeds: String,
    /// Damper model linearised at each speed (None: the deck's `damper.model`).
    pub damper: Option<String>,
    /// Speeds [rad/s] of the whole multibody rotor's time-domain runs (a list).
    pub time_speeds: Option<String>,
    /// The time-domain runs (`fit_from_s` is 7/20 of `duration_s`, set by `execute`).
    pub time: TimeOptions,
    /// Stroke amplitudes [m] of the nonlinear amplitude check (a list, or `default`).
    pub amplitudes_m: Option<String>,
    /// Rotor speed of the amplitude check [rad/s] (None: the deck's).
    pub amplitude_at_rad_s: Option<f64>,
    /// Air resonance in hover instead of ground resonance, and its condition.
    pub hover: bool,
    pub hover_options: super::air_resonance::HoverOptions,
    /// Deck values overridden by dotted path before validation.
    pub set: Vec<crate::overrides::Override>,
    pub out: std::path::PathBuf,
}

/// What a stability run found, its folder published.
#[derive(Clone, Debug)]
pub struct StabilityOutcome {
    pub map: StabilityMap,
    /// The damper model linearised, and the speeds of the map [rad/s].
    pub model: DamperModel,
    pub speeds: Vec<f64>,
    /// The whole rotor's time-domain runs.
    pub time: Vec<TimeCheck>,
    pub amplitude: Option<super::amplitude::AmplitudeCheck>,
}

impl StabilityJob {
    /// The map of `rotor` over `speeds` into `out` with the defaults of `rotorsim stability`.
    pub fn new(
        rotor: impl Into<std::path::PathBuf>,
        speeds: &str,
        out: impl Into<std::path::PathBuf>,
    ) -> Self {
        StabilityJob {
            rotor: rotor.into(),
            speeds: speeds.to_string(),
            damper: None,
            time_speeds: None,
            time: TimeOptions::default(),
            amplitudes_m: None,
            amplitude_at_rad_s: None,
            hover: false,
            hover_options: Default::default(),
            set: vec![],
            out: out.into(),
        }
    }

    /// Checks the options and the deck (before the result folder exists), then computes the
    /// map, the time-domain runs and the amplitude check and writes them. `say` gets a line as
    /// each slow part starts. A failure after the folder exists leaves it marked incomplete.
    pub fn execute(&self, say: &mut dyn FnMut(&str)) -> anyhow::Result<StabilityOutcome> {
        let speeds = parse_speeds("--speeds", &self.speeds)?;
        let deck = RotorDeck::from_file_with(&self.rotor, &self.set)?;
        check_rad_s("--speeds", &speeds, &deck)?;
        let model = match &self.damper {
            Some(d) => d
                .parse::<DamperModel>()
                .map_err(|e| anyhow!("--damper {d}: {e}"))?,
            None => deck.damper()?.model,
        };
        // the time-domain runs: read and sized before the result folder exists
        let time_opts = TimeOptions {
            fit_from_s: self.time.duration_s * 7.0 / 20.0,
            ..self.time
        };
        let mut time_speeds: Vec<f64> = vec![];
        if let Some(t) = &self.time_speeds {
            time_speeds = parse_speeds("--time", t)?;
            check_rad_s("--time", &time_speeds, &deck)?;
            for &w in &time_speeds {
                time_opts.check(w)?;
            }
        }
        // the amplitude check: read and checked before the result folder exists
        let amplitude = match &self.amplitudes_m {
            None => {
                if self.amplitude_at_rad_s.is_some() {
                    bail!("--amplitude-at-rad-s needs --amplitudes-m (the amplitudes to start from, or `default`)");
                }
                None
            }
            Some(a) => {
                let amplitudes_m = if a.trim() == "default" {
                    super::amplitude::DEFAULT_AMPLITUDES_M.to_vec()
                } else {
                    super::ranges::parse_range(
                        "--amplitudes-m",
                        a,
                        "expected stroke amplitudes in m, e.g. 1e-4,1e-3,1e-2, or `default`",
                        super::amplitude::MAX_AMPLITUDES,
                        "an amplitude check may have",
                    )?
                };
                let w = self
                    .amplitude_at_rad_s
                    .unwrap_or(deck.spec.rotor.omega_rad_s);
                if !(w.is_finite() && w > 0.0) {
                    bail!("--amplitude-at-rad-s {w}: expected a positive rotor speed in rad/s");
                }
                super::amplitude::check_amplitudes(
                    &amplitudes_m,
                    deck.spec.damper_attachment.arm_m,
                )?;
                Some((w, amplitudes_m))
            }
        };
        let hover = self.hover_options;
        if self.hover {
            hover.check()?;
            if self.time_speeds.is_some() {
                bail!("--hover: the whole rotor's time domain (--time) is for ground resonance; run it without --hover (the amplitude check, --amplitudes-m, runs in hover)");
            }
        }
        let out = OutDir::create(&self.out, &deck.input_files())?;
        let result = if self.hover {
            super::air_resonance::air_resonance_map(&deck, model, &speeds, &hover)
        } else {
            stability_map(&deck, model, &speeds)
        };
        let map = match result {
            Ok(mut m) => {
                m.overrides = self
                    .set
                    .iter()
                    .map(|o| (o.key.clone(), o.value_text()))
                    .collect();
                m
            }
            Err(e) => {
                out.mark_incomplete(&format!("{e:#}"))?;
                return Err(e);
            }
        };
        let mut time = vec![];
        for &w in &time_speeds {
            say(&format!(
                "time domain at {w} rad/s ({} s of motion)...",
                self.time.duration_s
            ));
            match time_check(&self.rotor, &self.set, model, w, &time_opts) {
                Ok(c) => time.push(c),
                Err(e) => {
                    out.mark_incomplete(&format!("{e:#}"))?;
                    return Err(e.context(format!("time domain at {w} rad/s")));
                }
            }
        }
        let amp = match amplitude {
            None => None,
            Some((w, amplitudes_m)) => {
                say(&format!(
                    "amplitude check at {w} rad/s ({} starts, {} damper)...",
                    amplitudes_m.len(),
                    model.name()
                ));
                let opts = super::amplitude::AmplitudeOptions {
                    amplitudes_m,
                    hover: self.hover.then_some(hover),
                    ..Default::default()
                };
                match super::amplitude::amplitude_check(&deck, model, w, &opts) {
                    Ok(c) => Some(c),
                    Err(e) => {
                        out.mark_incomplete(&format!("{e:#}"))?;
                        return Err(e.context(format!("amplitude check at {w} rad/s")));
                    }
                }
            }
        };
        write_all(&map, &time, amp.as_ref(), &deck, &out)?;
        out.finish()?;
        Ok(StabilityOutcome {
            map,
            model,
            speeds,
            time,
            amplitude: amp,
        })
    }
}
