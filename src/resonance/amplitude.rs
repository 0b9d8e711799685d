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
use super::{in_plane, linearise_at, LINEARISATION_AMPLITUDE_M};
use crate::hydraulics::{DamperDeck, DamperModel, IntegratorOptions};
use crate::rotor::RotorDeck;
use crate::stability::{
    cyclic_amplitude, free_response_with_dampers, AirRotor, AirframeAxis, BladeDamper, BodyDof,
    Hover, LagRotor, Mode, ModeLabel,
};
use anyhow::{anyhow, bail};
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

/// How the amplitude check runs.
#[derive(Clone, Debug)]
pub struct AmplitudeOptions {
    /// Stroke amplitudes of the starts [m], increasing.
    pub amplitudes_m: Vec<f64>,
    /// Fixed-frame cycles of the regressing lag mode integrated from each start; the first is
    /// left out of the fit (the devices start at rest while the blades move).
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
}

/// A limit cycle between two starts.
#[derive(Clone, Debug, serde::Serialize)]
pub struct LimitCycle {
    /// Stroke amplitude where the growth rate crosses zero (log-linear interpolation) [m].
    pub stroke_amplitude_m: f64,
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
    pub limit_cycles: Vec<LimitCycle>,
    /// The relief valves' force limits of blade 1's damper, where it has them [N].
    pub relief_limits_n: Option<(f64, f64)>,
    pub steps_per_rev: usize,
    /// The outcome in a sentence.
    pub statement: String,
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
    /// The regressing lag mode's state of this rotor (the mean rotor's when blades differ).
    fn mode_state(&self, om: f64) -> anyhow::Result<Vec<f64>> {
        let l = ModeLabel::RegressingLag;
        Ok(match self {
            Reduced::Lag(r) if r.is_isotropic() => r.mode_state(om, l)?,
            Reduced::Lag(r) => r.mean_rotor().mode_state(om, l)?,
            Reduced::Air(r, h) if r.is_isotropic() => r.mode_state(h, l)?,
            Reduced::Air(r, _) => {
                let m = r.blend_to_mean(0.0);
                m.mode_state(&m.hover(om)?, l)?
            }
        })
    }
    fn respond(
        &self,
        om: f64,
        dampers: &mut [BladeDamper],
        z: &[f64],
        t_end: f64,
        dt: f64,
    ) -> anyhow::Result<crate::stability::DeviceResponse> {
        Ok(match self {
            Reduced::Lag(r) => {
                free_response_with_dampers(r, om, dampers, z, t_end, dt, 2.0 * MAX_LAG_RAD)?
            }
            Reduced::Air(r, h) => {
                let steps_per_rev = (2.0 * PI / om / dt).round() as usize;
                r.response_with_dampers(h, dampers, z, t_end, steps_per_rev, 2.0 * MAX_LAG_RAD)?
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
            let rotor = self.rotor(&kc, om)?;
            let modes = rotor
                .modes(om)
                .map_err(|e| anyhow!("the reduced model at {om} rad/s: {e:#}"))?;
            let mode = modes
                .into_iter()
                .filter(|m| m.label == ModeLabel::RegressingLag)
                .max_by(|p, q| p.growth_rate_per_s.total_cmp(&q.growth_rate_per_s))
                .ok_or_else(|| anyhow!("no regressing lag mode at {om} rad/s"))?;
            w = (om - 2.0 * PI * mode.frequency_hz).abs();
            out = Some((rotor, mode, kc));
        }
        out.ok_or_else(|| anyhow!("no equivalent rotor"))
    }
}

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
    let blades = Blades::of(deck, model, o.hover)?;
    let arm = blades.decks[0].0.spec.damper_attachment.arm_m;
    check_amplitudes(&o.amplitudes_m, arm)?;
    let (_, linearised, _) = blades.equivalent(model, omega, LINEARISATION_AMPLITUDE_M, None)?;
    let w_rot = |m: &Mode| (omega - 2.0 * PI * m.frequency_hz).abs();
    let w_lin = w_rot(&linearised);
    let bare = blades.rotor(&vec![(0.0, 0.0); blades.decks.len()], omega)?;
    let nb = bare.blades();
    let dt = 2.0 * PI / omega / o.steps_per_rev as f64;
    // the starts are independent: side by side on the cores
    let start = |a: f64| -> anyhow::Result<AmplitudePoint> {
        let (eq, mode, _) = blades
            .equivalent(model, omega, a, Some(w_lin))
            .map_err(|e| anyhow!("the damper's equivalent values at {a} m of stroke: {e:#}"))?;
        let mut z = eq
            .mode_state(omega)
            .map_err(|e| anyhow!("the regressing lag mode at {omega} rad/s: {e:#}"))?;
        for v in &mut z {
            *v *= a / arm;
        }
        let mut dampers = Vec::with_capacity(nb);
        for (b, d) in &blades.decks {
            dampers.push(BladeDamper {
                device: d.build(model, INTEGRATOR)?,
                arm_m: b.spec.damper_attachment.arm_m,
            });
        }
        let wf = (2.0 * PI * mode.frequency_hz).max(1e-6);
        let period = 2.0 * PI / wf;
        let t_end = o.cycles.max(2) as f64 * period;
        let r = bare
            .respond(omega, &mut dampers, &z, t_end, dt)
            .map_err(|e| anyhow!("the amplitude check at {a} m of stroke, {omega} rad/s: {e}"))?;
        let resp = &r.response;
        let env: Vec<(f64, f64)> = resp
            .time_s
            .iter()
            .enumerate()
            .map(|(i, &t)| (t, arm * cyclic_amplitude(resp.state(i), nb, omega, t, wf)))
            .collect();
        let fit: Vec<(f64, f64)> = env
            .iter()
            .filter(|(t, v)| *t >= period && *v > 0.0)
            .map(|&(t, v)| (t, v.ln()))
            .collect();
        if fit.len() < 16 {
            bail!("the amplitude check at {a} m of stroke, {omega} rad/s: the response left the reduced model's range (lag beyond {:.0} deg) before a cycle was fitted", 2.0 * MAX_LAG_RAD.to_degrees());
        }
        let g = crate::analysis::compare::slope(&fit);
        let mean_ln = fit.iter().map(|p| p.1).sum::<f64>() / fit.len() as f64;
        let amp = mean_ln.exp();
        let (_, at, kc) = blades.equivalent(model, omega, amp, Some(w_rot(&mode)))?;
        let thin = (env.len() / 400).max(1);
        Ok(AmplitudePoint {
            start_m: a,
            stroke_amplitude_m: amp,
            growth_rate_per_s: g,
            equivalent_growth_rate_per_s: at.growth_rate_per_s,
            equivalent_damping_nms_per_rad: kc[0].1,
            frequency_hz: at.frequency_hz,
            max_force_n: r.force_n.iter().fold(0.0f64, |m, f| m.max(f.abs())),
            max_iterations: r.max_iterations,
            envelope: env.iter().step_by(thin).copied().collect(),
        })
    };
    let points = o
        .amplitudes_m
        .par_iter()
        .map(|&a| start(a))
        .collect::<anyhow::Result<Vec<_>>>()?;
    let limit_cycles: Vec<LimitCycle> = points
        .windows(2)
        .filter(|w| (w[0].growth_rate_per_s > 0.0) != (w[1].growth_rate_per_s > 0.0))
        .map(|w| {
            let (g0, g1) = (w[0].growth_rate_per_s, w[1].growth_rate_per_s);
            let (l0, l1) = (w[0].stroke_amplitude_m.ln(), w[1].stroke_amplitude_m.ln());
            LimitCycle {
                stroke_amplitude_m: (l0 + (l1 - l0) * g0 / (g0 - g1)).exp(),
                stable: g0 > 0.0,
            }
        })
        .collect();
    let relief_limits_n = (model == DamperModel::Physical)
        .then(|| crate::rotor::sim::relief_limits(&blades.decks[0].1))
        .flatten();
    let statement = statement(omega, &linearised, &points, &limit_cycles, relief_limits_n);
    Ok(AmplitudeCheck {
        omega_rad_s: omega,
        damper: model,
        linearised,
        points,
        limit_cycles,
        relief_limits_n,
        steps_per_rev: o.steps_per_rev,
        statement,
    })
}

fn statement(
    omega: f64,
    lin: &Mode,
    points: &[AmplitudePoint],
    cycles: &[LimitCycle],
    relief: Option<(f64, f64)>,
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
            "the time domain finds no limit cycle between {} and {} of stroke: the regressing lag {} at every amplitude tried",
            mm(lo),
            mm(hi),
            if all_decay { "decays" } else { "grows" }
        );
    } else {
        let list: Vec<String> = cycles
            .iter()
            .map(|c| {
                format!(
                    "{} at {} of stroke",
                    if c.stable {
                        "a stable limit cycle"
                    } else {
                        "an unstable limit cycle (larger motions grow)"
                    },
                    mm(c.stroke_amplitude_m)
                )
            })
            .collect();
        s += &format!("the time domain finds {}", list.join(" and "));
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
    let mut s = String::from("rotor_speed_rad_s,start_stroke_amplitude_m,stroke_amplitude_m,growth_rate_per_s,equivalent_growth_rate_per_s,linearised_growth_rate_per_s,equivalent_damping_Nms_per_rad,frequency_Hz,max_damper_force_N\n");
    for p in &c.points {
        s.push_str(&format!(
            "{},{},{},{},{},{},{},{},{}\n",
            c.omega_rad_s,
            p.start_m,
            p.stroke_amplitude_m,
            p.growth_rate_per_s,
            p.equivalent_growth_rate_per_s,
            c.linearised.growth_rate_per_s,
            p.equivalent_damping_nms_per_rad,
            p.frequency_hz,
            p.max_force_n
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
        "points": c.points.iter().map(|p| serde_json::json!({
            "start_stroke_amplitude_m": p.start_m,
            "stroke_amplitude_m": p.stroke_amplitude_m,
            "growth_rate_per_s": p.growth_rate_per_s,
            "equivalent_growth_rate_per_s": p.equivalent_growth_rate_per_s,
            "equivalent_damping_Nms_per_rad": p.equivalent_damping_nms_per_rad,
            "frequency_Hz": p.frequency_hz,
            "max_damper_force_N": p.max_force_n,
        })).collect::<Vec<_>>(),
        "limit_cycles": c.limit_cycles,
        "relief_limits_N": c.relief_limits_n.map(|(l, h)| [l, h]),
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
        "The reduced rotor at {} rad/s with each blade's {} damper as a device (its valves live), started on the regressing lag mode at each stroke amplitude and integrated {} steps per revolution; the growth rate is the slope of the log of the cyclic lag amplitude after the first cycle, at the window's mean amplitude. Beside it: the growth rate from the damper's equivalent stiffness and damping at that amplitude (the bench's first harmonic), and the linearised map's at {} mm.",
        c.omega_rad_s,
        c.damper.name(),
        c.steps_per_rev,
        LINEARISATION_AMPLITUDE_M * 1e3
    ));
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
    let plot = Plot::new(
        "Growth rate of the regressing lag against stroke amplitude",
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
    let rows: Vec<Vec<String>> = c
        .points
        .iter()
        .map(|p| {
            vec![
                format!("{:.3}", p.start_m * 1e3),
                format!("{:.3}", p.stroke_amplitude_m * 1e3),
                format!("{:+.5}", p.growth_rate_per_s),
                format!("{:+.5}", p.equivalent_growth_rate_per_s),
                format!("{:.1}", p.equivalent_damping_nms_per_rad),
                format!("{:.0}", p.max_force_n),
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
