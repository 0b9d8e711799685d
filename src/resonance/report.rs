//! The stability outputs: stability.csv, summary.json and report.html.
use super::*;
use crate::io::OutDir;
use crate::report::html::{Banner, HtmlReport};
use crate::report::plot::Plot;
use crate::rotor::RotorDeck;
use crate::stability::{AirframeAxis, Mode};
use std::f64::consts::PI;

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
                m.name(),
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
        "verdicts": map.verdicts,
        "min_damping_ratio": min.as_ref().map(|m| m.0),
        "min_damping_mode": min.as_ref().map(|m| m.1.clone()),
        "min_damping_speed_rad_s": min.as_ref().map(|m| m.2),
        "condition": if map.hover.is_some() { "hover" } else { "ground" },
        "hover": map.hover,
        "notes": map.notes,
    })
}

/// Largest damping ratio the damping plot's axis is sized for (the modes a resonance is about).
pub const DAMPING_AXIS_MAX: f64 = 0.3;

/// "from A to B rad/s (growth rate up to G 1/s)", an end at the first or last speed of the map
/// said to be the scan's end (the range may go on beyond it).
pub fn range_text(map: &StabilityMap, u: &UnstableRange) -> String {
    let first = map.speeds.first().map_or(f64::NAN, |s| s.omega_rad_s);
    let last = map.speeds.last().map_or(f64::NAN, |s| s.omega_rad_s);
    let mut ends = vec![];
    if u.from_rad_s <= first {
        ends.push("from the scan's first speed: it may begin below");
    }
    if u.to_rad_s >= last {
        ends.push("to the scan's last speed: it may go on above");
    }
    let ends = if ends.is_empty() {
        String::new()
    } else {
        format!(" ({})", ends.join("; "))
    };
    format!(
        "from {:.3} to {:.3} rad/s{ends}, growth rate up to {:.4} 1/s",
        u.from_rad_s, u.to_rad_s, u.max_growth_rate_per_s
    )
}

/// stability.html: the Coleman diagram, damping versus speed with the unstable ranges shaded,
/// the reduced model and the ranges.
pub fn html(map: &StabilityMap, deck: &RotorDeck) -> anyhow::Result<String> {
    html_with(map, deck, None)
}

/// As [`html`], the amplitude check's outcome among the banners (unless a verdict carries it).
pub fn html_with(
    map: &StabilityMap,
    deck: &RotorDeck,
    amplitude: Option<&amplitude::AmplitudeCheck>,
) -> anyhow::Result<String> {
    let mut rep = HtmlReport::new(if map.hover.is_some() {
        "Air resonance in hover"
    } else {
        "Ground resonance"
    });
    html_intro(&mut rep, map, deck, amplitude);
    html_figures(&mut rep, map)?;
    html_model(&mut rep, map);
    rep.list(&map.notes);
    Ok(rep.finish())
}

/// The verdict banner and what was solved.
fn html_intro(
    rep: &mut HtmlReport,
    map: &StabilityMap,
    deck: &RotorDeck,
    amplitude: Option<&amplitude::AmplitudeCheck>,
) {
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
            .map(|u| format!("{} {}", u.mode, range_text(map, u)))
            .collect();
        rep.banner(
            Banner::Bad,
            &format!("Linear map: growing {}.", ranges.join("; ")),
        );
    }
    for v in &map.verdicts {
        let kind = match v.call {
            band::Call::Stable => Banner::Ok,
            _ => Banner::Bad,
        };
        rep.banner(kind, &format!("{}.", v.line()));
    }
    if let Some(a) = amplitude {
        if map.verdicts.iter().all(|v| v.amplitude_check.is_none()) {
            let kind = if a.benign() { Banner::Ok } else { Banner::Bad };
            rep.banner(kind, &format!("Amplitude check {}.", a.headline));
        }
    }
    if !map.verdicts.is_empty() {
        rep.paragraph(&format!(
            "A verdict's band: the map recomputed at the verdict's speed with each of the deck's ASSUMED values at x1/{a} and x{a} (and, for the physical damper, the flow laws' numerical floor dp_laminar_Pa at x1/{f} and x{f}), the changes of the growth rate combined in quadrature on each side. UNSTABLE only where the whole band grows, marginal where it crosses zero (docs/stability.md, \"Verdicts and their band\").",
            a = band::ASSUMED_FACTOR,
            f = band::FLOOR_FACTOR
        ));
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
}

/// The Coleman diagram, the damping and the unstable ranges.
fn html_figures(rep: &mut HtmlReport, map: &StabilityMap) -> anyhow::Result<()> {
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
    // the axis holds the lightly damped modes: overdamped ones (ratio above DAMPING_AXIS_MAX,
    // real roots at +-1) would squeeze an unstable -0.01 onto the zero line
    let (mut lo, mut hi) = (0.0f64, 0.0f64);
    for s in &map.speeds {
        for m in &s.modes {
            let z = m.damping_ratio;
            if z.abs() < 0.999 && z < DAMPING_AXIS_MAX {
                lo = lo.min(z);
                hi = hi.max(z);
            }
        }
    }
    let pad = 0.08 * (hi - lo).max(1e-3);
    let (lo, hi) = (lo - pad, hi + pad);
    let clipped = map
        .speeds
        .iter()
        .flat_map(|s| &s.modes)
        .any(|m| m.damping_ratio < lo || m.damping_ratio > hi);
    let mut damping = Plot::new(
        if clipped {
            "Damping ratio (unstable ranges shaded; axis clipped to the lightly damped modes)"
        } else {
            "Damping ratio (unstable ranges shaded)"
        },
        "rotor speed [rad/s]",
        "damping ratio [-]",
    )
    .y_range(lo, hi);
    for l in &label_order {
        let (x, f) = series(&|m| m.frequency_hz, l);
        coleman = coleman.points(l, &x, &f);
        let (x, z) = series(&|m| m.damping_ratio, l);
        damping = damping.points(l, &x, &z);
        if let Some(c) = crate::report::plot::mode_colour(l) {
            coleman = coleman.colour(c);
            damping = damping.colour(c);
        }
    }
    for u in &map.unstable {
        damping = damping.band(
            &format!("unstable: {}", u.mode),
            &[u.from_rad_s, u.to_rad_s],
            &[lo, hi],
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
    Ok(())
}

/// The reduced model: blades, airframe, and in hover the equilibrium.
fn html_model(rep: &mut HtmlReport, map: &StabilityMap) {
    let sp: Vec<f64> = map.speeds.iter().map(|s| s.omega_rad_s).collect();
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
    amplitude: Option<&amplitude::AmplitudeCheck>,
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
    let mut page = html_with(map, deck, amplitude)?;
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
        out.write("amplitude.csv", amplitude::csv(a).as_bytes())?;
        let section = amplitude::html_section(a)?;
        page = match page.find("<h2 id=\"the-reduced-model\"") {
            Some(i) => format!("{}{}{}", &page[..i], section, &page[i..]),
            None => page.replace("</body>", &format!("{section}</body>")),
        };
    }
    out.write("stability.html", page.as_bytes())?;
    let mut summary = summary_json(map, deck);
    if let Some(a) = amplitude {
        summary["amplitude_check"] = amplitude::json(a);
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
