//! DIR/report.html: the periodic solution as in the paper (Figs. 16-22), periodicity
//! convergence, the metrics table and plain statements of which damper model comes closest and
//! what none of them reproduces. Self-contained (inline SVG).
use super::summary::{periodicity_statement, Measured, ModelFigures, Ranking, RunInfo, Stats};
use super::{ModelOutcome, ModelRun};
use crate::analysis::compare::PeriodicInterp;
use crate::report::html::{Banner, HtmlReport};
use crate::report::plot::{stacked_svg, Plot, SeriesKind};

const W: u32 = 900;
const H: u32 = 380;

/// Engineering units of a channel: (displayed unit, scale from SI).
fn unit_of(channel: &str) -> (&'static str, f64) {
    if channel.ends_with("_N") {
        ("kN", 1e-3)
    } else if channel.ends_with("_Nm") {
        ("kN m", 1e-3)
    } else if channel.ends_with("_Pa") {
        ("MPa", 1e-6)
    } else if channel.ends_with("_m3_s") {
        ("L/s", 1e3)
    } else if channel.ends_with("_m_s") {
        ("mm/s", 1e3)
    } else if channel.ends_with("_rad") {
        ("deg", 180.0 / std::f64::consts::PI)
    } else if channel.ends_with("_m") {
        ("mm", 1e3)
    } else {
        ("", 1.0)
    }
}

/// The measured stroke rate [m/s] from the averaged stroke (periodic central differences in
/// azimuth, at the rotor speed of the run).
fn measured_rate(m: &Measured, period_s: f64) -> Option<Vec<f64>> {
    let s = m.stroke_m.as_ref()?;
    let n = s.len();
    if n < 3 || m.azimuth_deg.len() != n || period_s.is_nan() || period_s <= 0.0 {
        return None;
    }
    let dpsi_dt = 360.0 / period_s;
    Some(
        (0..n)
            .map(|i| {
                let (a, b) = ((i + n - 1) % n, (i + 1) % n);
                let mut dpsi = m.azimuth_deg[b] - m.azimuth_deg[a];
                if dpsi <= 0.0 {
                    dpsi += 360.0;
                }
                (s[b] - s[a]) / dpsi * dpsi_dt
            })
            .collect(),
    )
}

/// Closes a loop (repeats the first sample at the end).
fn closed(v: &[f64]) -> Vec<f64> {
    let mut o = v.to_vec();
    if let Some(f) = v.first() {
        o.push(*f);
    }
    o
}

/// The verdict's split of the force error into the rotor's part (the stroke it gives the
/// damper) and the damper's (its 1/rev dynamic stiffness for that stroke), from the summary's
/// stroke checks; or why the split cannot be made.
pub fn rotor_damper_split(ok: &[(&ModelRun, &ModelFigures)], m: &Measured) -> Vec<String> {
    if m.stroke_m.is_none() {
        return vec!["Rotor or damper? The split cannot be made: the record has no damper stroke, so the force error cannot be divided between the stroke the rotor gives the damper and the damper's force for that stroke.".into()];
    }
    let checks: Vec<(&str, &super::summary::StrokeCheck)> = ok
        .iter()
        .filter_map(|(r, f)| f.stroke.as_ref().map(|s| (r.label.as_str(), s)))
        .collect();
    let Some(first) = checks.first() else {
        return vec!["Rotor or damper? The split cannot be made: no model has a damper stroke channel to compare with the record's.".into()];
    };
    let rec = first.1.rev1_measured.amplitude;
    let pct: Vec<f64> = checks
        .iter()
        .map(|(_, c)| 100.0 * (c.rev1_model.amplitude / rec - 1.0))
        .collect();
    let (lo, hi) = pct.iter().fold((f64::INFINITY, f64::NEG_INFINITY), |a, p| {
        (a.0.min(*p), a.1.max(*p))
    });
    let span = if (hi - lo).abs() < 0.05 {
        format!("{:.1}%", lo.abs())
    } else {
        format!(
            "{:.1}-{:.1}%",
            lo.abs().min(hi.abs()),
            lo.abs().max(hi.abs())
        )
    };
    let rotor = if hi < 0.0 {
        format!("Rotor: the model's 1/rev stroke is {span} below the record's {:.2} mm, so every damper model sees too small a stroke.", rec * 1e3)
    } else if lo > 0.0 {
        format!("Rotor: the model's 1/rev stroke is {span} above the record's {:.2} mm, so every damper model sees too large a stroke.", rec * 1e3)
    } else {
        let each: Vec<String> = checks
            .iter()
            .zip(&pct)
            .map(|((n, _), p)| format!("{n} {p:+.1}%"))
            .collect();
        format!(
            "Rotor: the model's 1/rev stroke against the record's {:.2} mm: {}.",
            rec * 1e3,
            each.join(", ")
        )
    };
    let kr = first.1.stiffness_1rev_measured;
    let each: Vec<String> = checks
        .iter()
        .map(|(n, c)| {
            let k = c.stiffness_1rev_model;
            format!(
                "{n} {:.0} / {:.0}",
                k.storage_N_per_m * 1e-3,
                k.loss_N_per_m * 1e-3,
            )
        })
        .collect();
    let loss: Vec<f64> = checks
        .iter()
        .map(|(_, c)| 100.0 * (c.stiffness_1rev_model.loss_N_per_m / kr.loss_N_per_m - 1.0))
        .collect();
    let (llo, lhi) = loss
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |a, p| {
            (a.0.min(*p), a.1.max(*p))
        });
    // one figure when the models agree to the printed digit (or one model ran)
    let span = |a: f64, b: f64| {
        if (a.round() - b.round()).abs() < 0.5 {
            format!("{:.0}%", a.abs())
        } else {
            format!("{:.0}-{:.0}%", a.abs().min(b.abs()), a.abs().max(b.abs()))
        }
    };
    let every = if checks.len() == 1 {
        "the model's"
    } else {
        "every model's"
    };
    let versus = if lhi < 0.0 {
        format!("{every} loss K'' is {} below the record's", span(lhi, llo))
    } else if llo > 0.0 {
        format!("{every} loss K'' is {} above the record's", span(llo, lhi))
    } else {
        format!("the models' loss K'' is {llo:+.0}% to {lhi:+.0}% of the record's")
    };
    let damper = format!(
        "Damper: for the stroke it gets, the 1/rev dynamic stiffness K' (storage) / K'' (loss) is {} kN/m against the record's {:.0} / {:.0} kN/m: {versus}.",
        each.join(", "),
        kr.storage_N_per_m * 1e-3,
        kr.loss_N_per_m * 1e-3
    );
    vec![rotor, damper]
}

/// Banners and the verdict box; returns nothing, writes to `rep`.
fn verdict(
    rep: &mut HtmlReport,
    info: &RunInfo,
    ok: &[(&ModelRun, &ModelFigures)],
    measured: &Result<Measured, String>,
    rank: Option<&Ranking>,
) {
    let runs: Vec<&ModelRun> = ok.iter().map(|x| x.0).collect();
    let runs = &runs[..];
    if info.synthetic {
        rep.banner(
            Banner::Synthetic,
            "SYNTHETIC flight record: the \"measured\" damper force is synthetic data (the record's metadata says synthetic), not a flight-test measurement.",
        );
    }
    let not_periodic: Vec<String> = runs
        .iter()
        .filter(|r| !r.periodic.converged)
        .map(|r| format!("{} (residual {:.1e})", r.label, r.periodic.residual))
        .collect();
    if runs.is_empty() {
        rep.banner(Banner::Bad, "No model completed.");
    } else if not_periodic.is_empty() {
        rep.banner(
            Banner::Ok,
            &format!(
                "periodic: every model's reported revolution repeats within the {:.0e} tolerance",
                runs[0].periodic.tolerance
            ),
        );
    } else {
        rep.banner(
            Banner::Bad,
            &format!(
                "NOT periodic: {} - the reported revolution is not a periodic solution; compare with care (--revs, or the rotor deck's transient damping)",
                not_periodic.join(", ")
            ),
        );
    }
    let syn = if info.synthetic { "SYNTHETIC " } else { "" };
    match (measured, rank) {
        (Ok(m), Some(r)) => {
            let best = &r.order[0];
            let headline = match r.order.get(1) {
                _ if !r.reproduces => {
                    let top = r.order.iter().max_by(|a, b| a.2.total_cmp(&b.2)).unwrap_or(best);
                    format!(
                        "No model reproduces the {syn}measured damper force: the best correlation is {:.3} ({}), where {} is asked; the smallest RMS error is {:.2} kN ({})",
                        top.2,
                        top.0,
                        super::summary::REPRODUCES_CORRELATION,
                        best.1 * 1e-3,
                        best.0
                    )
                }
                Some(next) => format!(
                    "Closest to the {syn}measured damper force: {} - RMS error {:.2} kN, {:.2} kN ({:.0}%) below the next, {} ({:.2} kN)",
                    best.0,
                    best.1 * 1e-3,
                    (next.1 - best.1) * 1e-3,
                    100.0 * (1.0 - best.1 / next.1),
                    next.0,
                    next.1 * 1e-3
                ),
                None => format!(
                    "Only {} was compared with the {syn}measured damper force: RMS error {:.2} kN",
                    best.0,
                    best.1 * 1e-3
                ),
            };
            let ptp = Stats::of(&m.force_n).peak_to_peak;
            let mut lines: Vec<String> = r
                .order
                .iter()
                .enumerate()
                .map(|(i, (name, rms, corr))| {
                    format!(
                        "{}. {name}: RMS error {:.2} kN ({:.0}% of the measured peak-to-peak {:.1} kN), correlation {corr:.3}",
                        i + 1,
                        rms * 1e-3,
                        100.0 * rms / ptp,
                        ptp * 1e-3
                    )
                })
                .collect();
            lines.extend(rotor_damper_split(ok, m));
            // a whole rotor whose blades differ: the record is blade 1's; say what the others do
            if !info.blade_differences.is_empty() {
                for (r, _) in ok.iter().filter(|(r, _)| !r.blade_runs.is_empty()) {
                    lines.push(format!(
                        "{}, blade by blade (the comparison above is blade 1's): {}.",
                        r.label,
                        super::summary::blade_force_lines(r).join("; ")
                    ));
                }
            }
            lines.push(format!(
                "Measurement: the record's damper force averaged over {} revolutions, compared at its own {} azimuths.",
                m.revolutions,
                m.azimuth_deg.len()
            ));
            rep.verdict(&headline, &lines);
        }
        (Err(note), _) => {
            rep.verdict(&format!("No comparison with a measurement: {note}."), &[]);
        }
        (Ok(_), None) => {
            rep.verdict("No model completed, so there is no comparison.", &[]);
        }
    }
}

/// The figures right after the verdict: models over the measurement, loops, stroke, harmonics,
/// periodicity, tip motion.
fn top_figures(
    rep: &mut HtmlReport,
    info: &RunInfo,
    runs: &[&ModelRun],
    measured: Option<&Measured>,
) {
    let syn = if info.synthetic { "SYNTHETIC " } else { "" };
    force_figures(rep, syn, runs, measured);
    loop_figures(rep, syn, runs, measured);
    stroke_figures(rep, syn, runs, measured);
    harmonics_figure(rep, syn, runs, measured);
    periodicity_figures(rep, runs);
    tip_figures(rep, runs);
}

/// The damper models over the measurement, and the residual.
fn force_figures(rep: &mut HtmlReport, syn: &str, runs: &[&ModelRun], measured: Option<&Measured>) {
    let mlabel = |_: &Measured| format!("{syn}measured");
    if let Some(m) = measured {
        rep.heading(2, "The damper models over the measurement (paper Fig. 22)");
        let mut p = Plot::new(
            &format!("Damper force: models and {syn}measurement"),
            "azimuth [deg]",
            "damper force [kN]",
        )
        .azimuth()
        .y_scale(1e-3);
        for r in runs {
            if let Some(f) = r.channel("damper_force_N") {
                p = p.line(&r.label, &r.azimuth_deg, f);
            }
        }
        p = p.points(&mlabel(m), &m.azimuth_deg, &m.force_n);
        // The relief-valve cracking forces here, so no second force figure is needed.
        let limits = runs.iter().find_map(|r| r.force_limits_n);
        if let Some((lo, hi)) = limits {
            p = p
                .dashed("valve 0 cracking force", &[0.0, 360.0], &[hi, hi])
                .colour(SIDE_COLOURS[0])
                .dashed("valve 1 cracking force", &[0.0, 360.0], &[lo, lo])
                .colour(SIDE_COLOURS[1]);
        }
        let mut pr = Plot::new(
            &format!("Residual: model - {syn}measured, at the measured azimuths"),
            "azimuth [deg]",
            "force error [kN]",
        )
        .azimuth()
        .y_scale(1e-3);
        for r in runs {
            if let Some(f) = r.channel("damper_force_N") {
                if let Ok(ip) = PeriodicInterp::new(crate::analysis::compare::Periodic {
                    psi_deg: &r.azimuth_deg,
                    value: f,
                }) {
                    let e: Vec<f64> = m
                        .azimuth_deg
                        .iter()
                        .zip(&m.force_n)
                        .map(|(p, y)| ip.at(*p) - y)
                        .collect();
                    pr = pr.line(&r.label, &m.azimuth_deg, &e);
                }
            }
        }
        svg(
            rep,
            &format!(
                "Damper force of the models over the {syn}measured force (top; {}); residual model - measured (bottom).",
                if limits.is_some() {
                    "dashed: the physical damper's relief-valve cracking forces, valve 0 limiting the positive force, valve 1 the negative"
                } else {
                    "no model has relief valves"
                }
            ),
            &[p, pr],
        );
    }
}

/// Force-stroke and force-velocity loops.
fn loop_figures(rep: &mut HtmlReport, syn: &str, runs: &[&ModelRun], measured: Option<&Measured>) {
    let mlabel = |_: &Measured| format!("{syn}measured");
    let mut fs = Plot::new("Force-stroke loops", "stroke [mm]", "damper force [kN]")
        .x_scale(1e3)
        .y_scale(1e-3);
    let mut fv = Plot::new(
        "Force-velocity loops",
        "stroke rate [mm/s]",
        "damper force [kN]",
    )
    .x_scale(1e3)
    .y_scale(1e-3);
    for r in runs {
        if let (Some(f), Some(s), Some(v)) = (
            r.channel("damper_force_N"),
            r.channel("damper_stroke_m"),
            r.channel("damper_stroke_rate_m_s"),
        ) {
            fs = fs.line(&r.label, &closed(s), &closed(f));
            fv = fv.line(&r.label, &closed(v), &closed(f));
        }
    }
    let mut loop_note = String::new();
    if let Some(m) = measured {
        if let Some(s) = &m.stroke_m {
            fs = fs.points(&mlabel(m), s, &m.force_n);
            if let Some(v) = runs.first().and_then(|r| measured_rate(m, r.period_s)) {
                fv = fv.points(&mlabel(m), &v, &m.force_n);
                loop_note = " The measured stroke rate is the record's averaged stroke differentiated in azimuth at the rotor speed.".into();
            }
        } else {
            loop_note =
                " The record has no damper stroke, so only the models' loops are shown.".into();
        }
    }
    if !fs.series.is_empty() {
        rep.heading(2, "Force-stroke and force-velocity loops");
        // Full width each: side by side left a loop under 200 px of data.
        svg(
            rep,
            &format!("Damper force against stroke (top; the area is the energy dissipated per revolution) and against stroke rate (bottom), last revolution.{loop_note}"),
            &[fs, fv],
        );
    }
}

/// Stroke: the record's over the models'.
fn stroke_figures(
    rep: &mut HtmlReport,
    syn: &str,
    runs: &[&ModelRun],
    measured: Option<&Measured>,
) {
    let mlabel = |_: &Measured| format!("{syn}measured");
    let mut ps = channel_plot(runs, "Damper stroke", &[("damper_stroke_m", "")]);
    let mut pv = channel_plot(
        runs,
        "Damper stroke rate",
        &[("damper_stroke_rate_m_s", "")],
    );
    if let Some(m) = measured {
        if let Some(s) = &m.stroke_m {
            ps = ps.points(&mlabel(m), &m.azimuth_deg, s);
            if let Some(v) = runs.first().and_then(|r| measured_rate(m, r.period_s)) {
                pv = pv.points(&mlabel(m), &m.azimuth_deg, &v);
            }
        }
    }
    rep.heading(2, "Damper stroke (paper Fig. 17)");
    svg(
        rep,
        "Damper stroke (top) and stroke rate (bottom), last revolution, with the record's where it has a stroke.",
        &[ps, pv],
    );
}

/// Harmonics bar chart.
fn harmonics_figure(
    rep: &mut HtmlReport,
    syn: &str,
    runs: &[&ModelRun],
    measured: Option<&Measured>,
) {
    let nh = super::N_HARMONICS;
    let ns: Vec<f64> = (0..=nh).map(|n| n as f64).collect();
    let mut ph = Plot::new(
        "Damper force harmonics",
        "harmonic [/rev]",
        "damper force amplitude [kN]",
    )
    .x_step(1.0)
    .y_scale(1e-3);
    if let Some(m) = measured {
        if let Ok(h) = crate::analysis::harmonics::harmonics(&m.azimuth_deg, &m.force_n, nh) {
            let a: Vec<f64> = h.iter().map(|h| h.amplitude).collect();
            ph = ph.bars(&format!("{syn}measured"), &ns, &a);
        }
    }
    for r in runs {
        if let Some(f) = r.channel("damper_force_N") {
            if let Ok(h) = crate::analysis::harmonics::harmonics(&r.azimuth_deg, f, nh) {
                let a: Vec<f64> = h.iter().map(|h| h.amplitude).collect();
                ph = ph.bars(&r.label, &ns, &a);
            }
        }
    }
    if !ph.series.is_empty() {
        rep.heading(2, "Harmonics");
        svg(
            rep,
            &format!("Amplitude of the damper force harmonics 0-{nh}/rev (0/rev: the mean, shown as its magnitude)."),
            &[ph],
        );
    }
}

/// Periodicity history.
fn periodicity_figures(rep: &mut HtmlReport, runs: &[&ModelRun]) {
    // 5. Periodicity history. A shooting iterate integrates several revolutions (the marched
    // ones before it, then one per subspace direction and trial), so the legend says how many.
    rep.heading(2, "Periodicity");
    let shooting = runs.iter().any(|r| r.periodic.iterations > 0);
    let mut pc = Plot::new(
        "Periodicity residual",
        if shooting {
            "shooting iterate (0: after the marched revolutions) [-]"
        } else {
            "revolution [-]"
        },
        "log10(periodicity residual) [-]",
    );
    let (mut longest, mut lo, mut hi) = (1usize, f64::INFINITY, f64::NEG_INFINITY);
    for r in runs {
        let h = r.measure_history();
        let p = &r.periodic;
        longest = longest.max(h.len());
        let (x, name): (Vec<f64>, String) = if shooting {
            let per = (p
                .revolutions_integrated
                .saturating_sub(p.marched_revolutions)) as f64
                / (h.len().saturating_sub(1)).max(1) as f64;
            (
                (0..h.len()).map(|k| k as f64).collect(),
                format!("{} ({per:.1} revs/iter)", r.label),
            )
        } else {
            ((1..=h.len()).map(|k| k as f64).collect(), r.label.clone())
        };
        let y: Vec<f64> = h.iter().map(|m| m.max(1e-16).log10()).collect();
        for v in y.iter().filter(|v| v.is_finite()) {
            lo = lo.min(*v);
            hi = hi.max(*v);
        }
        pc = pc.line(&name, &x, &y);
    }
    let x0 = if shooting { 0.0 } else { 1.0 };
    if let Some(r) = runs.first() {
        let t = r.periodic.tolerance.log10();
        lo = lo.min(t);
        hi = hi.max(t);
        pc = pc.dashed(
            &format!("tolerance {:.0e}", r.periodic.tolerance),
            &[x0, (longest as f64 - 1.0 + x0).max(x0 + 1.0)],
            &[t, t],
        );
    }
    if lo.is_finite() {
        // whole decades, at least two, so every decade has a labelled tick
        let (a, b) = (lo.floor(), hi.ceil().max(lo.floor() + 2.0));
        pc = pc.y_range(a, b);
    }
    if longest <= 12 {
        pc = pc.x_step(1.0);
    }
    svg(
        rep,
        &if shooting {
            format!("log10 of the periodicity residual after each accepted shooting iterate (0: after the marched revolutions, before the first Newton-Picard step). An iterate integrates several revolutions (one per subspace direction, plus trials); the legend gives the average revolutions per iterate of each model; in all: {}. The dashed line is the tolerance.", runs.iter().map(|r| format!("{} {} marched + {} in the iterates", r.label, r.periodic.marched_revolutions, r.periodic.revolutions_integrated.saturating_sub(r.periodic.marched_revolutions))).collect::<Vec<_>>().join(", "))
        } else {
            "log10 of the periodicity residual after each marched revolution (one revolution each); the dashed line is the tolerance.".to_string()
        },
        &[pc],
    );
    let per: Vec<String> = runs
        .iter()
        .map(|r| format!("{}: {}", r.label, periodicity_statement(r)))
        .collect();
    rep.paragraph("The periodicity residual of the reported revolution is the largest change of the damper force and the blade tip flap, lag and twist over the revolution, end against start, relative to their peak-to-peak:");
    rep.list(&per);
}

/// Tip motion.
fn tip_figures(rep: &mut HtmlReport, runs: &[&ModelRun]) {
    rep.heading(2, "Blade tip motion");
    svg(
        rep,
        "Blade tip flap (top), lag (middle) and elastic twist (bottom) over the last revolution.",
        &[
            channel_plot(runs, "Tip flap", &[("tip_flap_m", "")]),
            channel_plot(runs, "Tip lag", &[("tip_lag_m", "")]),
            channel_plot(runs, "Tip twist", &[("tip_twist_rad", "")]),
        ],
    );
}

/// Colours of chamber/valve 0 and 1 (a valve and its chamber alike).
const SIDE_COLOURS: [plotters::style::RGBColor; 2] = [
    crate::report::plot::OTHER_COLOURS[0],
    crate::report::plot::OTHER_COLOURS[1],
];

/// Chamber pressures with each relief valve's cracking pressure (dashed, same colour).
fn pressure_plot(phys: &[&ModelRun]) -> Plot {
    let mut p = Plot::new(
        "Chamber pressures",
        "azimuth [deg]",
        "chamber pressure [MPa]",
    )
    .azimuth()
    .y_scale(1e-6);
    let multi = phys.len() > 1;
    let names = ["p0: chamber 0 (compression)", "p1: chamber 1 (extension)"];
    for r in phys {
        let pre = if multi {
            format!("{} ", r.label)
        } else {
            String::new()
        };
        for (k, ch) in ["p0_Pa", "p1_Pa"].iter().enumerate() {
            if let Some(v) = r.channel(ch) {
                p = p
                    .line(&format!("{pre}{}", names[k]), &r.azimuth_deg, v)
                    .colour(SIDE_COLOURS[k]);
            }
        }
    }
    // The cracking pressure follows the other chamber's pressure (Eq. 5), so a line, not a level.
    for r in phys {
        let (Some(reg), Some(p0), Some(p1)) =
            (r.relief_regulation, r.channel("p0_Pa"), r.channel("p1_Pa"))
        else {
            continue;
        };
        let pre = if multi {
            format!("{} ", r.label)
        } else {
            String::new()
        };
        for (k, (g, other)) in reg.iter().zip([p1, p0]).enumerate() {
            let pc: Vec<f64> = other.iter().map(|po| g.cracking_pressure_pa(*po)).collect();
            p = p
                .dashed(&format!("{pre}valve {k} cracks at"), &r.azimuth_deg, &pc)
                .colour(SIDE_COLOURS[k]);
        }
    }
    p
}

/// The relief-valve figures: poppet displacement, velocity and flow of both valves, as their
/// envelope over the hydraulic sub-steps where the run has it, on an azimuth window that
/// does not cut a valve opening; and the caption's account of both.
fn valve_plots(phys: &[&ModelRun]) -> (Vec<Plot>, String) {
    let env = phys
        .iter()
        .all(|r| r.channel("x_valve0_substep_max_m").is_some());
    // Window start: of 0, -90, -180 deg the one farthest from any sample with a valve open.
    let mut open: Vec<f64> = vec![];
    for r in phys {
        for ch in ["x_valve0", "x_valve1"] {
            let name = if env {
                format!("{ch}_substep_max_m")
            } else {
                format!("{ch}_m")
            };
            if let Some(v) = r.channel(&name) {
                open.extend(
                    r.azimuth_deg
                        .iter()
                        .zip(v)
                        .filter(|(_, x)| **x > 1e-9)
                        .map(|(a, _)| *a),
                );
            }
        }
    }
    let gap = |s: f64| {
        open.iter()
            .map(|a| {
                let d = (a - s).rem_euclid(360.0);
                d.min(360.0 - d)
            })
            .fold(f64::INFINITY, f64::min)
    };
    let start = [0.0, -90.0, -180.0]
        .into_iter()
        .fold((0.0, gap(0.0)), |best, s| {
            let g = gap(s);
            if g > best.1 + 1e-9 {
                (s, g)
            } else {
                best
            }
        })
        .0;
    // One revolution from `start`, closed periodically at start + 360.
    let wrap = |az: &[f64], v: &[f64]| -> (Vec<f64>, Vec<f64>) {
        let mut pts: Vec<(f64, f64)> = az
            .iter()
            .zip(v)
            .map(|(a, y)| (start + (a - start).rem_euclid(360.0), *y))
            .collect();
        pts.sort_by(|a, b| a.0.total_cmp(&b.0));
        if let Some(&(a, y)) = pts.first() {
            pts.push((a + 360.0, y));
        }
        pts.into_iter().unzip()
    };
    let multi = phys.len() > 1;
    let panel = |title: &str, ylabel: &str, q: &str, unit: &str| -> Plot {
        let (_, scale) = unit_of(unit);
        let mut p = Plot::new(title, "azimuth [deg]", ylabel)
            .x_range(start, start + 360.0)
            .x_step(90.0)
            .y_scale(scale);
        for r in phys {
            let pre = if multi {
                format!("{} ", r.label)
            } else {
                String::new()
            };
            for (k, &colour) in SIDE_COLOURS.iter().enumerate() {
                let series: Vec<(String, SeriesKind)> = if env {
                    vec![
                        (format!("{q}{k}_substep_max{unit}"), SeriesKind::Line),
                        (format!("{q}{k}_substep_min{unit}"), SeriesKind::Dotted),
                    ]
                } else {
                    vec![(format!("{q}{k}{unit}"), SeriesKind::Line)]
                };
                for (ch, kind) in series {
                    let Some(v) = r.channel(&ch) else { continue };
                    let (x, y) = wrap(&r.azimuth_deg, v);
                    let what = match (env, kind) {
                        (false, _) => String::new(),
                        (true, SeriesKind::Line) => " max".into(),
                        _ => " min".into(),
                    };
                    p = p
                        .series(kind, &format!("{pre}valve {k}{what}"), &x, &y)
                        .colour(colour);
                }
            }
        }
        p
    };
    let plots = vec![
        panel(
            "Relief valve poppet displacements",
            "poppet displacement [mm]",
            "x_valve",
            "_m",
        ),
        panel(
            "Relief valve poppet velocities",
            "poppet velocity [mm/s]",
            "v_valve",
            "_m_s",
        ),
        panel(
            "Relief valve flows",
            "relief valve flow [L/s]",
            "q_valve",
            "_m3_s",
        ),
    ];
    let sampling = if env {
        "Each valve's minimum (dotted) and maximum (solid) over the hydraulic sub-steps of every structural step, drawn at the step's starting azimuth: the poppet moves within a step, and one sample per step would alias that motion into apparent chatter."
    } else {
        "One sample per structural step (this run has no sub-step envelope): motion within a step is not shown and may alias."
    };
    let window = if start == 0.0 {
        "Azimuth 0-360 deg (no valve opening there straddles 0 deg).".to_string()
    } else {
        format!(
            "Azimuth window {start:.0} to {:.0} deg (a negative azimuth is that plus 360 deg), chosen so that no valve opening is cut at the window's edge.",
            start + 360.0
        )
    };
    (plots, format!("{sampling} {window}"))
}

fn svg(rep: &mut HtmlReport, caption: &str, plots: &[Plot]) {
    match stacked_svg(plots, W, H) {
        Ok(s) => {
            rep.svg(caption, &s);
        }
        Err(e) => {
            rep.notice(&format!("figure '{caption}' could not be drawn: {e}"));
        }
    }
}

/// A plot of `channels` vs azimuth for every run that has them, in engineering units (from the
/// first channel's SI suffix). Colour: the model; line style: the channel (solid, dashed, dotted).
fn channel_plot(runs: &[&ModelRun], title: &str, channels: &[(&str, &str)]) -> Plot {
    let (unit, scale) = channels.first().map_or(("", 1.0), |c| unit_of(c.0));
    let ylabel = if unit.is_empty() {
        title.to_lowercase()
    } else {
        format!("{} [{unit}]", title.to_lowercase())
    };
    let mut p = Plot::new(title, "azimuth [deg]", &ylabel)
        .azimuth()
        .y_scale(scale);
    let multi = runs.len() > 1;
    for r in runs {
        for (k, (ch, name)) in channels.iter().enumerate() {
            if let Some(v) = r.channel(ch) {
                let label = match (multi, name.is_empty()) {
                    (true, true) => r.label.clone(),
                    (true, false) => format!("{} {name}", r.label),
                    (false, true) => r.label.clone(),
                    (false, false) => name.to_string(),
                };
                let kind = [SeriesKind::Line, SeriesKind::Dashed, SeriesKind::Dotted][k % 3];
                p = p.series(kind, &label, &r.azimuth_deg, v);
            }
        }
    }
    p
}

/// A channel name in words with its unit ("hub_fx_fixed_N" -> "hub force x, fixed frame [N]").
pub fn readable_channel(ch: &str) -> String {
    let (stem, unit) = [("_Nm", "N m"), ("_N", "N")]
        .iter()
        .find_map(|(suf, u)| ch.strip_suffix(suf).map(|s| (s, *u)))
        .unwrap_or((ch, ""));
    let mut words: Vec<String> = vec![];
    let mut fixed = false;
    for w in stem.split('_') {
        match w {
            "fixed" => fixed = true,
            "fx" | "fy" | "fz" => words.push(format!("force {}", &w[1..])),
            "mx" | "my" | "mz" => words.push(format!("moment {}", &w[1..])),
            _ => words.push(w.to_string()),
        }
    }
    let mut s = words.join(" ");
    if fixed {
        s.push_str(", fixed frame");
    }
    if unit.is_empty() {
        s
    } else {
        format!("{s} [{unit}]")
    }
}

fn fmt(x: f64, prec: usize) -> String {
    if x.is_finite() {
        format!("{x:.prec$}")
    } else {
        "n/a".into()
    }
}

/// What none of the models reproduces, read from the residuals (observations, not causes).
pub fn unreproduced(items: &[(&ModelRun, &ModelFigures)], measured: &Measured) -> Vec<String> {
    let res: Vec<(&str, &super::summary::Residual, f64)> = items
        .iter()
        .filter_map(|(r, f)| {
            Some((
                r.model.as_str(),
                f.residual.as_ref()?,
                f.metrics.as_ref()?.rms_error,
            ))
        })
        .collect();
    if res.is_empty() {
        return Vec::new();
    }
    let mut out = Vec::new();
    let ptp = {
        let lo = measured
            .force_n
            .iter()
            .cloned()
            .fold(f64::INFINITY, f64::min);
        let hi = measured
            .force_n
            .iter()
            .cloned()
            .fold(f64::NEG_INFINITY, f64::max);
        hi - lo
    };
    let best_rms = res.iter().map(|r| r.2).fold(f64::INFINITY, f64::min);
    out.push(format!(
        "Even the closest model leaves an RMS error of {best_rms:.0} N, {:.0}% of the measured peak-to-peak force ({ptp:.0} N).",
        100.0 * best_rms / ptp
    ));
    // Residual harmonics: those in every model's top three.
    let common: Vec<usize> = res[0]
        .1
        .dominant
        .iter()
        .map(|d| d.0)
        .filter(|n| res.iter().all(|r| r.1.dominant.iter().any(|d| d.0 == *n)))
        .collect();
    for n in &common {
        let amps: Vec<String> = res
            .iter()
            .map(|r| format!("{} {:.0} N", r.0, r.1.harmonics[*n].amplitude))
            .collect();
        out.push(format!(
            "Residual harmonic {n}/rev is among the three largest for every model (amplitude: {}); measured {n}/rev amplitude {:.0} N.",
            amps.join(", "),
            crate::analysis::harmonics::harmonics(&measured.azimuth_deg, &measured.force_n, *n)
                .map(|h| h[*n].amplitude)
                .unwrap_or(f64::NAN)
        ));
    }
    // Peak asymmetry.
    let am = res[0].1.asymmetry_measured;
    let (amin, amax) = res.iter().fold((f64::INFINITY, f64::NEG_INFINITY), |a, r| {
        (a.0.min(r.1.asymmetry_model), a.1.max(r.1.asymmetry_model))
    });
    if am < amin * 0.95 || am > amax * 1.05 {
        out.push(format!(
            "Peak asymmetry: the measured max/|min| force ratio is {am:.2}; the models give {amin:.2} to {amax:.2}."
        ));
    } else {
        out.push(format!(
            "Peak asymmetry is reproduced within the models' spread (measured max/|min| {am:.2}, models {amin:.2} to {amax:.2})."
        ));
    }
    // Dwell near zero: judged model by model (a model that dwells much longer than the record is
    // as much a finding as one that dwells much shorter).
    let dm = res[0].1.dwell_measured;
    let longer: Vec<String> = res
        .iter()
        .filter(|r| r.1.dwell_model > dm * 1.2 + 0.005)
        .map(|r| format!("{} {:.1}%", r.0, 100.0 * r.1.dwell_model))
        .collect();
    let shorter: Vec<String> = res
        .iter()
        .filter(|r| r.1.dwell_model * 1.2 + 0.005 < dm)
        .map(|r| format!("{} {:.1}%", r.0, 100.0 * r.1.dwell_model))
        .collect();
    let base = format!(
        "Dwell near zero: the measured force stays within 5% of its peak of zero over {:.1}% of the revolution",
        100.0 * dm
    );
    if longer.is_empty() && shorter.is_empty() {
        let all: Vec<String> = res
            .iter()
            .map(|r| format!("{} {:.1}%", r.0, 100.0 * r.1.dwell_model))
            .collect();
        out.push(format!(
            "{base}; every model dwells about as long ({}).",
            all.join(", ")
        ));
    } else {
        let mut parts = vec![];
        if !longer.is_empty() {
            parts.push(format!("much longer in {}", longer.join(", ")));
        }
        if !shorter.is_empty() {
            parts.push(format!("much shorter in {}", shorter.join(", ")));
        }
        out.push(format!(
            "{base}; the force dwells there {}.",
            parts.join("; ")
        ));
    }
    // Phase.
    let shifts: Vec<f64> = res.iter().map(|r| r.1.best_shift_deg).collect();
    let (smin, smax) = shifts
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |a, s| {
            (a.0.min(*s), a.1.max(*s))
        });
    if smin > 1.0 || smax < -1.0 {
        let dir = if smin > 0.0 { "lags" } else { "leads" };
        let gains: Vec<String> = res
            .iter()
            .map(|r| format!("{} {:.0} -> {:.0} N", r.0, r.2, r.1.rms_at_best_shift_n))
            .collect();
        out.push(format!(
            "Phase: the measurement {dir} every model, by {:.1} to {:.1} deg of azimuth (shift minimizing the RMS error; RMS error at that shift: {}).",
            smin.abs().min(smax.abs()),
            smin.abs().max(smax.abs()),
            gains.join(", ")
        ));
    } else {
        out.push(format!(
            "Phase: no consistent lag; the best azimuth shifts of the models are {:.1} to {:.1} deg.",
            smin, smax
        ));
    }
    out
}

/// The findings in words: the verdict against the measurement, what no model reproduces, the
/// relief-valve limits.
fn findings(
    rep: &mut HtmlReport,
    ok: &[(&ModelRun, &ModelFigures)],
    measured: &Result<Measured, String>,
    rank: Option<&Ranking>,
    syn: &str,
) {
    // The findings in words.
    rep.heading(2, "Findings");
    match (measured, rank) {
        (Ok(m), Some(r)) => {
            rep.paragraph(&format!(
                "Against the {syn}measured damper force (average of {} revolutions, compared on its own {} azimuths): {}.",
                m.revolutions,
                m.azimuth_deg.len(),
                r.statement
            ));
            rep.paragraph("What none of the models reproduces (observations on the residual model - measured; input to the diagnosis, `rotorsim diagnose`):");
            rep.list(&unreproduced(ok, m));
            let strokes: Vec<String> = ok
                .iter()
                .filter_map(|(r, f)| {
                    f.stroke
                        .as_ref()
                        .map(|s| format!("{}: {}", r.label, s.statement))
                })
                .collect();
            if !strokes.is_empty() {
                rep.paragraph(&format!("The record carries the damper stroke: the rotor's part of the force error (the stroke) and the damper's (its 1/rev dynamic stiffness K* = -F1/d1 for the stroke it gets; storage K' = Re K*, loss K'' = Im K*), against the {syn}record:"));
                rep.list(&strokes);
            }
        }
        (Err(note), _) => {
            rep.paragraph(&format!("No comparison with a measurement: {note}."));
        }
        (Ok(_), None) => {
            rep.paragraph("No model completed, so there is no comparison.");
        }
    }
    let lim: Vec<String> = ok
        .iter()
        .filter_map(|(r, f)| {
            f.limits.map(|c| {
                format!(
                    "{}: force {:.0} to {:.0} N, relief-valve cracking forces {:.0} to {:.0} N: {}",
                    r.label,
                    f.force.min,
                    f.force.max,
                    c.min_limit_n,
                    c.max_limit_n,
                    c.statement()
                )
            })
        })
        .collect();
    if !lim.is_empty() {
        rep.paragraph("Relief-valve limits (cracking forces; the dashpot models have none):");
        rep.list(&lim);
    }
}

/// The metrics table and the damper force's harmonics.
fn metrics_section(
    rep: &mut HtmlReport,
    ok: &[(&ModelRun, &ModelFigures)],
    measured: &Result<Measured, String>,
    syn: &str,
) {
    // Metrics table.
    rep.heading(2, "Metrics");
    let mut rows = Vec::new();
    if let Ok(m) = measured {
        let st = Stats::of(&m.force_n);
        let mut row = vec![
            format!("{syn}measured"),
            fmt(st.min, 0),
            fmt(st.max, 0),
            fmt(st.peak_to_peak, 0),
            fmt(st.rms, 0),
        ];
        row.extend(std::iter::repeat_n("-".to_string(), 7));
        rows.push(row);
    }
    for (r, f) in ok {
        let m = f.metrics.as_ref();
        let t = r.timing;
        rows.push(vec![
            r.label.clone(),
            fmt(f.force.min, 0),
            fmt(f.force.max, 0),
            fmt(f.force.peak_to_peak, 0),
            fmt(f.force.rms, 0),
            m.map_or("-".into(), |m| fmt(m.rms_error, 0)),
            m.map_or("-".into(), |m| fmt(m.peak_to_peak_error, 0)),
            m.map_or("-".into(), |m| fmt(m.correlation, 3)),
            super::fmt_measure(r.last_measure()),
            fmt(r.wall_s, 2),
            fmt(t.total_s - t.hydraulics_s, 2),
            fmt(t.hydraulics_s, 2),
        ]);
    }
    rep.table(
        &[
            "damper force of",
            "min [N]",
            "max [N]",
            "peak-to-peak [N]",
            "RMS [N]",
            "RMS error [N]",
            "peak-to-peak error [N]",
            "correlation [-]",
            "periodicity residual [-]",
            "wall time [s]",
            "structure time [s]",
            "hydraulics time [s]",
        ],
        &rows,
    );
    if let Ok(m) = measured {
        // Harmonics table: amplitude per harmonic, measured then models.
        let mut hrows = Vec::new();
        let hm =
            crate::analysis::harmonics::harmonics(&m.azimuth_deg, &m.force_n, super::N_HARMONICS)
                .unwrap_or_default();
        let mut row = vec![format!("{syn}measured")];
        row.extend(hm.iter().map(|h| fmt(h.amplitude, 0)));
        hrows.push(row);
        for (r, f) in ok {
            if let Some(mt) = &f.metrics {
                let mut row = vec![r.label.clone()];
                row.extend(mt.harmonics_model.iter().map(|h| fmt(h.amplitude, 0)));
                hrows.push(row);
            }
            if let Some(res) = &f.residual {
                let mut row = vec![format!("{} residual", r.label)];
                row.extend(res.harmonics.iter().map(|h| fmt(h.amplitude, 0)));
                hrows.push(row);
            }
        }
        let hdr: Vec<String> = (0..=super::N_HARMONICS)
            .map(|n| {
                if n == 0 {
                    "0/rev: |mean| [N]".to_string()
                } else {
                    format!("{n}/rev [N]")
                }
            })
            .collect();
        rep.paragraph("Damper force harmonics: the amplitude of each harmonic [N], of the measurement, of each model and of each model's residual (model - measured).");
        let mut h: Vec<&str> = vec!["damper force of"];
        h.extend(hdr.iter().map(|s| s.as_str()));
        rep.table(&h, &hrows);
    }
}

/// The damper force (without a measurement) and inside the physical damper.
fn damper_figures(rep: &mut HtmlReport, runs: &[&ModelRun], measured: &Result<Measured, String>) {
    // Figures.
    // With a measurement the first figure already shows the force and the cracking forces.
    if measured.is_err() {
        rep.heading(2, "Damper force (paper Fig. 16)");
        let mut pf = channel_plot(runs, "Damper force", &[("damper_force_N", "")]);
        if let Some((lo, hi)) = runs.iter().find_map(|r| r.force_limits_n) {
            pf = pf
                .dashed(
                    "relief-valve cracking force (max)",
                    &[0.0, 360.0],
                    &[hi, hi],
                )
                .dashed(
                    "relief-valve cracking force (min)",
                    &[0.0, 360.0],
                    &[lo, lo],
                );
        }
        svg(
            rep,
            "Damper force over the last revolution, with the relief-valve cracking forces.",
            &[pf],
        );
    }
    let phys: Vec<&ModelRun> = runs
        .iter()
        .copied()
        .filter(|r| r.channel("p0_Pa").is_some())
        .collect();
    if phys.is_empty() {
        rep.paragraph(
            "No physical damper run: no internal hydraulic channels to show (Figs. 18-21).",
        );
    } else {
        rep.heading(2, "Inside the physical damper (paper Figs. 18-21)");
        svg(
            rep,
            "Chamber pressures (cf. Fig. 18). Chamber 0 grows with the stroke, so it is compressed (and loaded) when the damper shortens; chamber 1 when it extends (docs/formats.md). Dashed, in the chamber's colour: the pressure at which the chamber's relief valve cracks, F_p / A_front + (A_back / A_front) p_other, which follows the other chamber's pressure p_other (Eq. 5); the valve opens where its chamber's pressure reaches that line.",
            &[pressure_plot(&phys)],
        );
        svg(
            rep,
            "Volumetric flow through the orifice, positive from chamber 0 to 1 (cf. Fig. 19).",
            &[channel_plot(
                &phys,
                "Orifice flow",
                &[("q_orifice_m3_s", "")],
            )],
        );
        let (valves, how) = valve_plots(&phys);
        svg(
            rep,
            &format!("Relief valve poppet displacement (top; cf. Fig. 20), velocity (middle) and flow (bottom; cf. Fig. 21). {how}"),
            &valves,
        );
    }
}

/// How each model reached its periodic solution, and its Floquet multipliers.
fn periodic_section(rep: &mut HtmlReport, runs: &[&ModelRun]) {
    rep.heading(2, "Periodic solution");
    let per: Vec<Vec<String>> = runs
        .iter()
        .map(|r| {
            let p = &r.periodic;
            vec![
                r.label.clone(),
                p.method_used.name().to_string(),
                if p.converged {
                    "yes".into()
                } else {
                    "NO".into()
                },
                super::fmt_measure(Some(p.residual)),
                p.error_estimate
                    .map_or("-".into(), |e| super::fmt_measure(Some(e))),
                p.revolutions_integrated.to_string(),
                p.iterations.to_string(),
                p.directions.to_string(),
            ]
        })
        .collect();
    rep.table(
        &[
            "model",
            "method",
            "converged",
            "residual",
            "error estimate",
            "revolutions integrated",
            "iterations",
            "subspace directions",
        ],
        &per,
    );
    let frows = floquet_rows(runs);
    if !frows.is_empty() {
        rep.paragraph("Floquet multipliers of the periodic solution (Ritz values of the shooting subspace, least damped first, the lag mode at the top). |mu| is the decay of the mode per revolution; for a complex pair the frequency is known modulo 1/rev (shown in 0..0.5 /rev) and the damping ratio is computed with that frequency. A real positive multiplier is a motion that decays without oscillating: it has no frequency and no damping ratio, only its decay per revolution; a real negative one changes sign every revolution (1/2 /rev). The mode label is the largest of tip lag, flap and twist in the mode. A multiplier is the eigenvalue of a subspace of the monodromy matrix; its residual ||M v - mu v|| / ||v|| says how far the subspace holds the mode, and a mode whose residual is above 1% of |mu| is shown as not resolved, with its residual and no value (the subspace does not hold it to 1%). After the periodic solution is found, shooting adds directions (one revolution each) to resolve the reported modes: under prescribed airloads up to 12 for the eight least damped modes of |mu| at least 0.1; with the lifting line acting (computed and hybrid airloads), whose damping brings the first flap mode to |mu| ~ 0.1, ten modes are reported and up to 20 directions resolve those of |mu| at least 0.05.");
        if runs.iter().all(|r| r.airloads.is_none()) {
            rep.paragraph("Why the flap modes are so lightly damped: the run replays prescribed airloads, so the flap motion gets no aerodynamic damping, only the structure's. In the words of docs/rotor_model.md: \"prescribed airloads carry no aerodynamic damping (in flight the flap mode has a damping ratio of order Lock number / 16 ~ 0.5; here only the bearing damper, ~0.2%)\".");
        }
        rep.table(
            &[
                "model",
                "mode",
                "kind",
                "multiplier",
                "decay per rev |mu|",
                "frequency [/rev, mod 1]",
                "damping ratio [-]",
                "residual ||M v - mu v|| / ||v||",
                "reliable",
            ],
            &frows,
        );
    }
}

/// The HTML report.
#[allow(clippy::too_many_arguments)]
pub fn report_html(
    info: &RunInfo,
    outcomes: &[ModelOutcome],
    figs: &[Option<Result<ModelFigures, String>>],
    measured: &Result<Measured, String>,
    rank: Option<&Ranking>,
) -> String {
    let mut rep = HtmlReport::new(&format!(
        "rotorsim run: {} with {}",
        info.rotor_model, info.flight
    ));
    let syn = if info.synthetic { "SYNTHETIC " } else { "" };
    let ok: Vec<(&ModelRun, &ModelFigures)> = outcomes
        .iter()
        .zip(figs)
        .filter_map(|(o, f)| match (&o.result, f) {
            (Ok(r), Some(Ok(f))) => Some((r, f)),
            _ => None,
        })
        .collect();
    verdict(&mut rep, info, &ok, measured, rank);
    rep.paragraph(&format!(
        "Rotor deck {}, damper deck {}, flight record {}{}; at most {} revolutions of {} steps (each model stops once periodic), hydraulics {} with {} sub-steps. Total wall time {:.1} s.",
        info.rotor,
        info.damper_deck,
        info.flight,
        info.counter.as_ref().map(|c| format!(" (counter {c})")).unwrap_or_default(),
        info.revs,
        info.steps_per_rev,
        info.scheme,
        info.substeps,
        info.wall_s
    ));
    for (o, f) in outcomes.iter().zip(figs) {
        match (&o.result, f) {
            (Err(e), _) | (Ok(_), Some(Err(e))) => {
                rep.notice(&format!("The {} model FAILED: {e}", o.model.name()));
            }
            _ => {}
        }
    }
    let runs: Vec<&ModelRun> = ok.iter().map(|x| x.0).collect();
    if info.rotor_model.contains("sdof") {
        rep.banner(Banner::Info, "Rotor model: the lag-hinge single-degree-of-freedom TEST DOUBLE (--model sdof), not the UH-60A multibody rotor model.");
    }
    if info.rotor_model.contains("rigid-blade") {
        rep.banner(Banner::Info, "Rotor model: the rigid-blade reduction of the rotor deck (--model rigid): the blade rigid on its lag hinge, no flap, no elastic bending or twist, airloads projected with the control pitch (docs/rotor_model.md). For damper comparisons on records of rigid-blade generators; blade loads need the multibody model.");
    }
    rep.contents();
    top_figures(&mut rep, info, &runs, measured.as_ref().ok());

    findings(&mut rep, &ok, measured, rank, syn);
    metrics_section(&mut rep, &ok, measured, syn);
    damper_figures(&mut rep, &runs, measured);
    periodic_section(&mut rep, &runs);
    blade_loads(&mut rep, &runs, info.synthetic);
    airloads(&mut rep, &runs);
    whole_rotor(&mut rep, info, &runs);
    rep.heading(2, "Conventions");
    rep.paragraph("Azimuth: docs/formats.md, 0 over the tail, increasing with rotation; model time 0 is azimuth 0 of the reference blade. Damper force positive when it pushes its end points apart (Eq. 8), stroke positive in extension. The model's last revolution is interpolated (periodic linear interpolation) at the measured azimuths; the measurement is the record's damper channel averaged over its revolutions, azimuth by azimuth, never resampled. No time shift is applied to the comparison; the best shift is reported as evidence only. Details: docs/run.md.");
    rep.finish()
}

/// Panels of `channels` grouped so that the components in one panel are within a factor 5 of
/// each other in peak magnitude (over all runs); largest first.
fn root_groups(
    runs: &[&ModelRun],
    title: &str,
    quantity: &str,
    channels: &[(&str, &str)],
) -> Vec<Plot> {
    let mut peak: Vec<(f64, (&str, &str))> = channels
        .iter()
        .filter_map(|c| {
            let m = runs
                .iter()
                .filter_map(|r| r.channel(c.0))
                .flat_map(|v| v.iter().map(|x| x.abs()))
                .fold(f64::NAN, f64::max);
            m.is_finite().then_some((m, *c))
        })
        .collect();
    peak.sort_by(|a, b| b.0.total_cmp(&a.0));
    let mut groups: Vec<Vec<(&str, &str)>> = vec![];
    let mut top = f64::NAN;
    for (m, c) in peak {
        match groups.last_mut() {
            Some(g) if m * 5.0 >= top => g.push(c),
            _ => {
                groups.push(vec![c]);
                top = m;
            }
        }
    }
    groups
        .iter_mut()
        .map(|g| {
            g.sort_by_key(|c| channels.iter().position(|x| x.0 == c.0));
            let names: Vec<&str> = g
                .iter()
                .map(|c| c.1.split(' ').next().unwrap_or(""))
                .collect();
            let plural = if g.len() > 1 { "s" } else { "" };
            let mut p = channel_plot(runs, &format!("{title}{plural} {}", names.join(", ")), g);
            let (unit, _) = unit_of(g[0].0);
            p.y_label = format!("{quantity} [{unit}]");
            p
        })
        .collect()
}

/// How a multiplier whose residual is above 1% of |mu| is shown instead of its value.
pub fn unresolved_text(m: &crate::periodic::Multiplier) -> String {
    format!(
        "not resolved (residual {:.0}% of |mu|)",
        100.0 * m.residual / m.magnitude
    )
}

/// Rows of the Floquet table: a multiplier not resolved to 1% shows no value; a real multiplier is named as such, with no damping ratio (the
/// formula's 1 for a real positive one is not a damping).
pub fn floquet_rows(runs: &[&ModelRun]) -> Vec<Vec<String>> {
    let mut rows = Vec::new();
    for r in runs {
        for m in &r.periodic.floquet_multipliers {
            let mode = if m.mode.is_empty() {
                "-".to_string()
            } else {
                m.mode.clone()
            };
            if !m.reliable {
                // no number for a mode the subspace does not hold to 1%
                rows.push(vec![
                    r.label.clone(),
                    mode,
                    "-".into(),
                    unresolved_text(m),
                    "-".into(),
                    "-".into(),
                    "-".into(),
                    format!("{:.1e}", m.residual),
                    "NO".into(),
                ]);
                continue;
            }
            let (kind, freq, zeta) = if m.im != 0.0 {
                (
                    "complex pair",
                    format!("{:.4}", m.frequency_per_rev),
                    format!("{:.4}", m.damping_ratio),
                )
            } else if m.re >= 0.0 {
                ("real (non-oscillatory)", "-".into(), "-".into())
            } else {
                (
                    "real negative (sign flips every rev)",
                    "0.5".into(),
                    format!("{:.4}", m.damping_ratio),
                )
            };
            rows.push(vec![
                r.label.clone(),
                mode,
                kind.into(),
                format!("{:.6} {:+.6}i", m.re, m.im),
                format!("{:.4}", m.magnitude),
                freq,
                zeta,
                format!("{:.1e}", m.residual),
                "yes".into(),
            ]);
        }
    }
    rows
}

/// Radial distributions of the section loads, pitch-link and root loads vs azimuth, and the
/// N/rev hub loads (docs/loads.md).
/// Lifting-line runs: the computed normal force against the record's over azimuth at three
/// stations and over radius at four azimuths, and the rotor's thrust.
fn airloads(rep: &mut HtmlReport, runs: &[&ModelRun]) {
    let with: Vec<&ModelRun> = runs
        .iter()
        .copied()
        .filter(|r| r.airloads.is_some())
        .collect();
    let Some(first) = with.first() else { return };
    let Some(a) = &first.airloads else { return };
    rep.heading(2, "Airloads");
    let ct = |r: &ModelRun| {
        r.channel("rotor_CT_over_sigma")
            .map(|v| v.iter().sum::<f64>() / v.len().max(1) as f64)
    };
    rep.paragraph(&format!(
        "Airloads {} with the lifting line ({} inflow; {}). Thrust coefficient over solidity {}{}. The measured normal force is the record's{} (docs/aerodynamics.md).",
        a.source_text(),
        a.inflow,
        a.airfoils.join(", "),
        with.iter()
            .map(|r| format!("{} {:.4}", r.label, ct(r).unwrap_or(f64::NAN)))
            .collect::<Vec<_>>()
            .join(", "),
        a.record_ct_over_sigma
            .map(|v| format!(" against the record's {v:.4} (a plausibility comparison)"))
            .unwrap_or_default(),
        if a.record_synthetic { ", SYNTHETIC" } else { "" },
    ));
    if a.clamped_queries > 0 {
        rep.paragraph(&format!("{}.", a.clamp_statement()));
    }
    // stations r/R of the normal-force channels
    let prefix = "aero_normal_N_per_m_r";
    let stations: Vec<(String, f64)> = first
        .channel_names
        .iter()
        .filter_map(|c| {
            let r = c.strip_prefix(prefix)?;
            Some((r.to_string(), r.parse().ok()?))
        })
        .collect();
    if stations.is_empty() {
        return;
    }
    let normal = |r: &ModelRun, st: &str| -> Option<(Vec<f64>, Vec<f64>)> {
        let c = r.channel(&format!("{prefix}{st}"))?;
        let d = r.channel(&format!("aero_normal_minus_measured_N_per_m_r{st}"))?;
        Some((c.to_vec(), c.iter().zip(d).map(|(c, d)| c - d).collect()))
    };
    let mut plots = vec![];
    let n = stations.len();
    for k in [n / 3, (2 * n) / 3, n.saturating_sub(2)] {
        let (st, x) = &stations[k.min(n - 1)];
        let mut p = Plot::new(
            &format!("normal force at r/R = {x:.3}"),
            "azimuth of blade 1 [deg]",
            "normal force [N/m]",
        )
        .azimuth();
        let mut measured_drawn = false;
        for r in &with {
            let Some((c, m)) = normal(r, st) else {
                continue;
            };
            if !measured_drawn {
                p = p.dashed("measured", &closed_x(&r.azimuth_deg), &closed(&m));
                measured_drawn = true;
            }
            p = p.line(
                &format!("{} ({})", r.label, a.source),
                &closed_x(&r.azimuth_deg),
                &closed(&c),
            );
        }
        plots.push(p);
    }
    svg(
        rep,
        "The lifting line's normal force against the record's over the revolution, at three stations (blade 1, section frame).",
        &plots,
    );
    let r = first;
    let nr = r.azimuth_deg.len();
    let xs: Vec<f64> = stations.iter().map(|s| s.1).collect();
    let mut p = Plot::new(
        &format!("{}: normal force over radius", r.label),
        "r/R",
        "normal force [N/m]",
    );
    for q in 0..4 {
        let j = q * nr / 4;
        let (mut c, mut m) = (vec![], vec![]);
        for (st, _) in &stations {
            if let Some((cv, mv)) = normal(r, st) {
                c.push(cv[j]);
                m.push(mv[j]);
            }
        }
        let psi = r.azimuth_deg[j];
        let colour = crate::report::plot::OTHER_COLOURS[q];
        p = p
            .line(&format!("computed, {psi:.0} deg"), &xs, &c)
            .colour(colour)
            .dashed(&format!("measured, {psi:.0} deg"), &xs, &m)
            .colour(colour);
    }
    svg(
        rep,
        "The normal force over radius at four azimuths: the lifting line's (solid) and the record's (dashed).",
        &[p],
    );
}

/// The pitch-link load's harmonics and its contributors' (docs/loads.md, "Pitch-link
/// contributors").
fn pitch_link_contributors(rep: &mut HtmlReport, runs: &[&ModelRun], synthetic: bool) {
    use super::loads::{pitch_link_breakdown, PITCH_LINK_HARMONICS};
    let mut rows = vec![];
    let mut checks = vec![];
    for r in runs {
        let Some(b) = pitch_link_breakdown(r) else {
            continue;
        };
        for c in &b.rows {
            let mut row = vec![r.label.clone(), c.name.clone(), format!("{:.0}", c.mean_n)];
            row.extend(c.amplitude_n.iter().map(|a| {
                if a.is_finite() {
                    format!("{a:.0}")
                } else {
                    "-".into()
                }
            }));
            rows.push(row);
        }
        let c = &b.balance_check;
        checks.push(format!(
            "{}: largest difference between the load and its contributors' sum {:.1e} of its magnitude ({}, tolerance {:.1e})",
            r.label,
            c.max_rel_error,
            if c.passed { "passed" } else { "FAILED" },
            c.tolerance
        ));
    }
    if rows.is_empty() {
        return;
    }
    let source = if synthetic {
        "the SYNTHETIC record's airloads"
    } else {
        "the airloads"
    };
    rep.paragraph(&format!(
        "Pitch-link load and its contributors [N]: the moment balance about the pitch axis of the blade outboard of the pitch bearing, each moment as the link tension that balances it (its moment over the horn's arm). The bearing's row is split per harmonic by phase against the pitch-bearing angle: in phase, its spring (storage); a quarter period ahead, its damping (loss); '-' where the blade does not pitch at that harmonic. Airloads: {source}, their pitching moments and their forces' moments about the pitch axis. The pitch link's own: its shear at the horn and its upper half's inertia, between the horn and the mid-length where the load is taken."
    ));
    let mut head = vec!["model".to_string(), "contributor".into(), "mean".into()];
    head.extend((1..=PITCH_LINK_HARMONICS).map(|n| format!("{n}/rev")));
    let head: Vec<&str> = head.iter().map(|s| s.as_str()).collect();
    rep.table(&head, &rows);
    rep.paragraph(&format!("Balance check: {}.", checks.join("; ")));
}

fn blade_loads(rep: &mut HtmlReport, runs: &[&ModelRun], synthetic: bool) {
    use crate::rotor::deck::SECTION_KINDS;
    let with: Vec<&ModelRun> = runs
        .iter()
        .copied()
        .filter(|r| r.channel("root_fx_N").is_some())
        .collect();
    if with.is_empty() {
        return;
    }
    rep.heading(2, "Blade loads");
    rep.paragraph("Section loads are what the outboard part of the blade exerts on the inboard part, in the deformed section frame: flap moment positive for tip-up bending, chord moment positive for bending toward the leading edge, torsion nose up, axial force in tension (docs/loads.md, sign conventions). Stations r/R below the blade root are the section just outboard of the bearing and of the pitch horn.");
    let multi = with.len() > 1;
    let mut plots = vec![];
    for (kind, unit) in SECTION_KINDS.iter().take(3) {
        let shown = if *unit == "Nm" { "kN m" } else { "kN" };
        let mut p = Plot::new(
            &format!(
                "{} along the blade: mean (solid), half peak-to-peak (dashed)",
                kind.replace('_', " ")
            ),
            "radial station r/R [-]",
            &format!("{} [{shown}]", kind.replace('_', " ")),
        )
        .y_scale(1e-3);
        for r in &with {
            let mut pts: Vec<(f64, f64, f64)> = vec![];
            for (name, v) in r.channel_names.iter().zip(&r.last_rev) {
                let Some(rest) = name.strip_prefix(&format!("{kind}_r")) else {
                    continue;
                };
                let Some(x) = rest.split('_').next().and_then(|x| x.parse::<f64>().ok()) else {
                    continue;
                };
                let st = super::summary::Stats::of(v);
                pts.push((x, st.mean, 0.5 * st.peak_to_peak));
            }
            pts.sort_by(|a, b| a.0.total_cmp(&b.0));
            let x: Vec<f64> = pts.iter().map(|p| p.0).collect();
            let m: Vec<f64> = pts.iter().map(|p| p.1).collect();
            let h: Vec<f64> = pts.iter().map(|p| p.2).collect();
            let lab = if multi {
                r.label.clone()
            } else {
                String::new()
            };
            p = p
                .line(&format!("{lab} mean"), &x, &m)
                .dashed(&format!("{lab} half p-p"), &x, &h);
        }
        plots.push(p);
    }
    svg(
        rep,
        "Section loads along the blade over the last revolution.",
        &plots,
    );
    svg(
        rep,
        "Pitch-link axial load (tension positive), last revolution.",
        &[channel_plot(
            runs,
            "Pitch-link load",
            &[("pitch_link_force_N", "")],
        )],
    );
    pitch_link_contributors(rep, &with, synthetic);
    // Grouped by magnitude: the centrifugal fx is ten times the shears and would flatten them.
    let mut root = root_groups(
        &with,
        "Root force",
        "root force",
        &[
            ("root_fx_N", "fx (radial)"),
            ("root_fy_N", "fy (lead)"),
            ("root_fz_N", "fz (up)"),
        ],
    );
    root.extend(root_groups(
        &with,
        "Root moment",
        "root moment",
        &[
            ("root_mx_Nm", "mx (about x)"),
            ("root_my_Nm", "my (about y)"),
            ("root_mz_Nm", "mz (about z)"),
        ],
    ));
    svg(
        rep,
        "Blade root loads at the hub centre, rotating hub frame (x outward, y toward the leading edge, z up): forces, then moments, each panel holding the components of like magnitude.",
        &root,
    );
    let mut rows = vec![];
    for r in &with {
        for ch in super::loads::HUB_CHANNELS {
            let Some(v) = r.channel(ch) else { continue };
            let Ok(h) =
                crate::analysis::harmonics::harmonics(&r.azimuth_deg, v, super::N_HARMONICS)
            else {
                continue;
            };
            let amp = |n: usize| h.get(n).map_or(f64::NAN, |x| x.amplitude);
            let nb = r.blades.unwrap_or(4);
            rows.push(vec![
                r.label.clone(),
                readable_channel(ch),
                format!("{:.1}", amp(0)),
                format!("{:.1} ({nb}/rev)", amp(nb)),
                format!("{:.1} ({}/rev)", amp(2 * nb), 2 * nb),
            ]);
        }
        if let Some(c) = &r.loads_check {
            rep.paragraph(&format!(
                "{}: equilibrium check, root loads against the resultant of the applied, inertial, damper and pitch-link loads: largest difference {:.1e} of {}'s peak-to-peak ({}, tolerance {:.1e}).",
                r.label,
                c.max_rel_error,
                c.channel,
                if c.passed { "passed" } else { "FAILED" },
                c.tolerance
            ));
        }
    }
    if !rows.is_empty() {
        if with.iter().any(|r| !r.blade_runs.is_empty()) {
            rep.paragraph("Hub loads in the non-rotating frame (x along blade 1 at azimuth 0, z up): every blade's own root loads summed, no symmetry assumed (the harmonics at other than multiples of N/rev are in the section Whole rotor). Amplitudes [N, N m]:");
        } else {
            rep.paragraph("Hub loads in the non-rotating frame (x along the reference blade at azimuth 0, z up): the rotor's identical blades' root loads summed, so only multiples of N/rev remain. Amplitudes [N, N m]:");
        }
        rep.table(
            &["model", "hub load", "mean (0/rev)", "N/rev", "2N/rev"],
            &rows,
        );
    }
}

/// Share of the largest hub-load harmonic above which a harmonic that is not a multiple of
/// N/rev is highlighted: numerical noise of a periodic solution sits orders below it.
const NON_NPREV_MARK: f64 = 1e-3;

/// The whole rotor: each blade's damper force on its own azimuth, the hub loads' harmonics
/// with the content at other than multiples of N/rev highlighted (it comes only from blades
/// that differ).
fn whole_rotor(rep: &mut HtmlReport, info: &RunInfo, runs: &[&ModelRun]) {
    let whole: Vec<&&ModelRun> = runs.iter().filter(|r| !r.blade_runs.is_empty()).collect();
    let Some(first) = whole.first() else { return };
    let n = first.blade_runs.len();
    rep.heading(2, "Whole rotor");
    if info.airframe.is_empty() {
        rep.paragraph(&format!(
            "All {n} blades on a driven hub, each its own model with its own deck values: blade k sits (k-1) x {:.1} deg ahead of blade 1 and sees the shared swashplate's controls and the record's airloads at its own azimuth. On a driven hub the blades are coupled only through prescribed motion, so each blade's periodic solution is the rotor's; the hub loads are the sum of the blades' actual root loads. Each blade's outputs are in <model>/blade<K>/ (docs/run.md).",
            360.0 / n as f64
        ));
    } else {
        rep.paragraph(&format!(
            "All {n} blades on a hub that moves with the airframe, in one model: blade k sits (k-1) x {:.1} deg ahead of blade 1 and sees the shared swashplate's controls and the record's airloads at its own azimuth; the blades are coupled through the hub, and the periodic solution and Floquet multipliers are those of the whole rotor with its airframe. The hub loads are the sum of the blades' actual root loads. Each blade's outputs are in <model>/blade<K>/ (docs/run.md).",
            360.0 / n as f64
        ));
    }
    if info.blade_differences.is_empty() {
        rep.paragraph("The blades are identical: every blade has the deck's values.");
    } else {
        rep.paragraph("Where the blades differ from the deck:");
        rep.list(&info.blade_differences);
    }
    let plots: Vec<Plot> = whole
        .iter()
        .map(|r| {
            let mut p = Plot::new(
                &format!(
                    "{}: damper force of every blade at its own azimuth",
                    r.label
                ),
                "blade azimuth [deg]",
                "damper force [kN]",
            )
            .azimuth()
            .y_scale(1e-3);
            for b in &r.blade_runs {
                let k = b.blade.unwrap_or(0);
                let Some(f) = b.channel("damper_force_N") else {
                    continue;
                };
                let ahead = super::rotor::blade_azimuth_deg(k, n);
                let mut pts: Vec<(f64, f64)> = b
                    .azimuth_deg
                    .iter()
                    .zip(f)
                    .map(|(a, v)| ((a + ahead).rem_euclid(360.0), *v))
                    .collect();
                pts.sort_by(|a, b| a.0.total_cmp(&b.0));
                let (x, y): (Vec<f64>, Vec<f64>) = pts.into_iter().unzip();
                p = p.line(&format!("blade {k}"), &closed_x(&x), &closed(&y));
            }
            p
        })
        .collect();
    svg(
        rep,
        "Damper force of each blade against its own azimuth: identical blades lie on one curve; a blade that differs stands apart.",
        &plots,
    );
    let top = 2 * n;
    let mut header: Vec<String> = vec!["model".into(), "hub load".into()];
    header.extend((0..=top).map(|k| format!("{k}/rev")));
    let mut rows = vec![];
    let mut marks: Vec<Vec<bool>> = vec![];
    for r in &whole {
        for ch in super::loads::HUB_CHANNELS {
            let Some(v) = r.channel(ch) else { continue };
            let Ok(h) = crate::analysis::harmonics::harmonics(&r.azimuth_deg, v, top) else {
                continue;
            };
            let amp: Vec<f64> = (0..=top)
                .map(|k| h.get(k).map_or(f64::NAN, |x| x.amplitude))
                .collect();
            // the mean (thrust, torque) would hide an oscillatory load's content
            let big = amp[1..].iter().cloned().fold(0.0, f64::max);
            let mut row = vec![r.label.clone(), readable_channel(ch)];
            row.extend(amp.iter().map(|a| format!("{a:.1}")));
            let mut m = vec![false, false];
            m.extend(
                amp.iter()
                    .enumerate()
                    .map(|(k, a)| k % n != 0 && *a > NON_NPREV_MARK * big),
            );
            rows.push(row);
            marks.push(m);
        }
    }
    if !rows.is_empty() {
        rep.paragraph(&format!(
            "Harmonics of the fixed-frame hub loads [N, N m]. Identical blades pass only multiples of {n}/rev to the hub; highlighted: a harmonic that is not, above {NON_NPREV_MARK:.0e} of the load's largest oscillatory harmonic, the signature of dissimilar blades (a leaking damper, a blade out of track)."
        ));
        let header: Vec<&str> = header.iter().map(|s| s.as_str()).collect();
        rep.marked_table(&header, &rows, |i, j| marks[i][j]);
    }
    airframe(rep, info, &whole);
}

/// The airframe under the hub: its directions, its motion over the revolution and the check
/// of its equation of motion against the rotor's loads on it.
fn airframe(rep: &mut HtmlReport, info: &RunInfo, whole: &[&&ModelRun]) {
    if info.airframe.is_empty() {
        return;
    }
    rep.heading(3, "Airframe");
    rep.paragraph("The airframe under the hub, from the deck's [airframe] (each direction alone, without the rotor):");
    rep.list(&info.airframe);
    let mut plots = vec![];
    for r in whole {
        for (unit, scale, ylabel) in [
            ("_m", 1e3, "airframe translation [mm]"),
            (
                "_rad",
                180.0 / std::f64::consts::PI,
                "airframe rotation [deg]",
            ),
        ] {
            let chans: Vec<(&String, &Vec<f64>)> = r
                .channel_names
                .iter()
                .zip(&r.last_rev)
                .filter(|(c, _)| {
                    c.starts_with("airframe_") && c.ends_with(unit) && !c.contains("accel")
                })
                .collect();
            if chans.is_empty() {
                continue;
            }
            let mut p = Plot::new(
                &format!("{}: airframe motion at the hub", r.label),
                "azimuth of blade 1 [deg]",
                ylabel,
            )
            .azimuth()
            .y_scale(scale);
            for (c, v) in chans {
                let dir = c
                    .strip_prefix("airframe_")
                    .and_then(|x| x.strip_suffix(unit))
                    .unwrap_or(c);
                p = p.line(dir, &closed_x(&r.azimuth_deg), &closed(v));
            }
            plots.push(p);
        }
    }
    svg(
        rep,
        "The airframe's displacement at the hub over the reported revolution (fixed frame), with its static deflection under the mean rotor loads.",
        &plots,
    );
    let mut rows = vec![];
    for r in whole {
        let Some(c) = &r.airframe_check else { continue };
        for d in &c.directions {
            let unit = if matches!(d.direction.as_str(), "roll" | "pitch") {
                "N m"
            } else {
                "N"
            };
            rows.push(vec![
                r.label.clone(),
                d.direction.clone(),
                format!("{:.3e} {unit}", d.max_imbalance),
                format!("{:.1} {unit}", d.max_hub_load),
                format!(
                    "{:.1e}",
                    d.max_imbalance / d.max_hub_load.max(f64::MIN_POSITIVE)
                ),
                format!("{:.2}", d.max_over_step_tolerance),
            ]);
        }
    }
    if !rows.is_empty() {
        rep.paragraph("Momentum check: the airframe's equation of motion (mass x acceleration + damper + spring) against the rotor's loads on it at the hub, summed from every blade's loads on the hub, at every sample of the reported revolution. The translations balance to the Newton tolerance of the step (the last column: the largest ratio of the imbalance to the residual tolerance of its step, at most 1); roll and pitch to second order in the airframe's rotation (their axes turn with it).");
        rep.table(
            &[
                "model",
                "direction",
                "largest imbalance",
                "largest rotor load",
                "relative",
                "of the step's tolerance",
            ],
            &rows,
        );
    }
}

/// Azimuths of one revolution closed at 360 (pairs with [`closed`]).
fn closed_x(x: &[f64]) -> Vec<f64> {
    let mut v = x.to_vec();
    if let Some(f) = x.first() {
        v.push(f + 360.0);
    }
    v
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn without_a_recorded_stroke_the_split_says_why_it_cannot_be_made() {
        let m = Measured {
            azimuth_deg: vec![0.0, 90.0, 180.0, 270.0],
            force_n: vec![1.0, 0.0, -1.0, 0.0],
            stroke_m: None,
            revolutions: 1,
            synthetic: false,
        };
        let s = rotor_damper_split(&[], &m);
        assert_eq!(s.len(), 1);
        assert!(s[0].contains("cannot be made") && s[0].contains("no damper stroke"));
    }

    #[test]
    fn hub_channels_read_as_words_with_units() {
        assert_eq!(
            readable_channel("hub_fx_fixed_N"),
            "hub force x, fixed frame [N]"
        );
        assert_eq!(
            readable_channel("hub_my_fixed_Nm"),
            "hub moment y, fixed frame [N m]"
        );
    }
}
