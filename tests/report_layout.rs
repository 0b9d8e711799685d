//! The run report reads at a glance: banners and the verdict box before any figure, the figures
//! in the order an engineer reads them, azimuth ticks every 90 deg, tick labels never repeated on
//! an axis, legends to the right of the data, and one colour per damper model in every figure.
use std::path::{Path, PathBuf};
use std::process::Command;

fn repo() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// One `<text>` of an SVG: its anchor, position, content and the colour of the element drawn
/// just before it (a legend's line or marker).
#[derive(Debug)]
struct Text {
    anchor: String,
    x: f64,
    y: f64,
    text: String,
    colour_before: Option<String>,
    /// Rotated (a y axis title).
    rotated: bool,
    font_size: f64,
}

fn attr(tag: &str, name: &str) -> Option<String> {
    let key = format!(" {name}=\"");
    let i = tag.find(&key)? + key.len();
    let j = tag[i..].find('"')?;
    Some(tag[i..i + j].to_string())
}

/// The texts of one SVG, in document order.
fn texts(svg: &str) -> Vec<Text> {
    let mut out = Vec::new();
    let mut rest = svg;
    let mut offset = 0;
    while let Some(i) = rest.find("<text ") {
        let open_end = i + rest[i..].find('>').unwrap();
        let close = open_end + rest[open_end..].find("</text>").unwrap();
        let tag = &rest[i..open_end];
        let before = &svg[..offset + i];
        // the colour of the previous drawn element (polyline stroke or circle/rect fill)
        let prev = before
            .rfind("<polyline")
            .into_iter()
            .chain(before.rfind("<circle"))
            .chain(before.rfind("<rect"))
            .max()
            .map(|p| &before[p..]);
        let colour_before = prev.and_then(|p| {
            let tag = &p[..p.find('>').unwrap_or(p.len())];
            attr(tag, "stroke")
                .filter(|s| s != "none")
                .or_else(|| attr(tag, "fill"))
        });
        out.push(Text {
            anchor: attr(tag, "text-anchor").unwrap_or_default(),
            x: attr(tag, "x").unwrap().parse().unwrap(),
            y: attr(tag, "y").unwrap().parse().unwrap(),
            text: rest[open_end + 1..close].trim().to_string(),
            colour_before,
            rotated: attr(tag, "transform").is_some_and(|t| t.starts_with("rotate")),
            font_size: attr(tag, "font-size")
                .and_then(|f| f.parse().ok())
                .unwrap_or(0.0),
        });
        offset += close;
        rest = &svg[offset..];
    }
    out
}

fn svgs(html: &str) -> Vec<&str> {
    let mut v = Vec::new();
    let mut rest = html;
    while let Some(i) = rest.find("<svg") {
        let j = i + rest[i..].find("</svg>").unwrap() + 6;
        v.push(&rest[i..j]);
        rest = &rest[j..];
    }
    v
}

/// The model a legend label names, and its fixed colour (src/report/plot.rs MODEL_COLOURS).
fn model_colour(label: &str) -> Option<&'static str> {
    let l = label.to_lowercase();
    if l.contains("measured") {
        Some("#000000")
    } else if l.starts_with("nonlinear") {
        Some("#FF7F0E")
    } else if l.starts_with("linear") {
        Some("#1F77B4")
    } else if l.starts_with("physical") {
        Some("#2CA02C")
    } else {
        None
    }
}

fn run_rigid(out: &Path) {
    run(out, &["--model", "rigid"]);
}

fn run(out: &Path, args: &[&str]) {
    let _ = std::fs::remove_dir_all(out);
    let o = Command::new(env!("CARGO_BIN_EXE_rotorsim"))
        .current_dir(repo())
        .arg("run")
        .args(args)
        .arg("--out")
        .arg(out)
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
}

/// Where the h2 with text `h` (or starting so) opens.
fn h2_at(html: &str, h: &str) -> Option<usize> {
    let mut from = 0;
    while let Some(i) = html[from..].find("<h2") {
        let at = from + i;
        let gt = at + html[at..].find('>')?;
        if html[gt + 1..].starts_with(h) {
            return Some(at);
        }
        from = gt;
    }
    None
}

/// Values of `attr="..."` of every `<tag ` in `html`.
fn attrs_of(html: &str, tag: &str, name: &str) -> Vec<String> {
    html.match_indices(&format!("<{tag} "))
        .filter_map(|(i, _)| {
            let end = i + html[i..].find('>')?;
            attr(&html[i..end], name)
        })
        .collect()
}

/// The cells of every row of every table: (header cells, rows of cells).
fn tables(html: &str) -> Vec<(Vec<String>, Vec<Vec<String>>)> {
    let cells = |row: &str, tag: &str| -> Vec<String> {
        row.split(&format!("<{tag}>"))
            .skip(1)
            .map(|c| c[..c.find(&format!("</{tag}>")).unwrap()].to_string())
            .collect()
    };
    html.split("<table>")
        .skip(1)
        .map(|t| {
            let t = &t[..t.find("</table>").unwrap()];
            let rows: Vec<&str> = t.split("<tr>").skip(1).collect();
            let head = rows.first().map(|r| cells(r, "th")).unwrap_or_default();
            let body = rows.iter().skip(1).map(|r| cells(r, "td")).collect();
            (head, body)
        })
        .collect()
}

/// A raw channel name such as `hub_fx_fixed_N` or `p0_Pa` in `s`.
fn raw_channel(s: &str) -> Option<&str> {
    const UNITS: [&str; 7] = ["N", "Nm", "Pa", "m", "m_s", "rad", "m3_s"];
    s.split(|c: char| !(c.is_ascii_alphanumeric() || c == '_'))
        .find(|w| {
            UNITS.iter().any(|u| {
                w.strip_suffix(u)
                    .and_then(|p| p.strip_suffix('_'))
                    .is_some_and(|p| {
                        !p.is_empty()
                            && p.chars()
                                .all(|c| c.is_ascii_lowercase() || c.is_ascii_digit() || c == '_')
                    })
            })
        })
}

/// What every run report holds for a newcomer, whatever the rotor model: a table of contents
/// of every section, the verdict's rotor/damper split, no figure twice, a readable periodicity
/// axis, a quantity and a unit on every axis, real Floquet multipliers named as such, the
/// measurement in the metrics table, no raw channel names, loops wide enough to read.
fn check_newcomer_points(html: &str) {
    // Contents: after the verdict, before the first section, one link per h2 and back.
    let ids = attrs_of(html, "h2", "id");
    assert!(ids.len() >= 8, "{ids:?}");
    let toc = html.find("<nav class=\"toc\"").expect("table of contents");
    let toc_end = toc + html[toc..].find("</nav>").unwrap();
    assert!(html.find("class=\"verdict\"").unwrap() < toc);
    assert!(toc < html.find("<h2").unwrap());
    let links: Vec<String> = attrs_of(&html[toc..toc_end], "a", "href");
    let want: Vec<String> = ids.iter().map(|i| format!("#{i}")).collect();
    assert_eq!(links, want, "contents against sections");
    let mut uniq = ids.clone();
    uniq.sort();
    uniq.dedup();
    assert_eq!(uniq.len(), ids.len(), "unique section ids");

    // The verdict splits the error into the rotor's and the damper's part (the record has a
    // stroke), with the numbers of the stroke check.
    let v = html.find("class=\"verdict\"").unwrap();
    let verdict = &html[v..v + html[v..].find("</div>").unwrap()];
    let rotor = verdict
        .find("<li>Rotor: the model&#39;s 1/rev stroke is")
        .expect("rotor split");
    let damper = verdict.find("<li>Damper: ").expect("damper split");
    assert!(rotor < damper);
    assert!(verdict[damper..].contains("K&#39; (storage) / K&#39;&#39; (loss)"));
    assert!(verdict[damper..].contains("the record&#39;s"));

    let all = svgs(html);
    let mut sigs: Vec<Vec<String>> = vec![];
    let mut force_over_azimuth = 0;
    for (k, svg) in all.iter().enumerate() {
        let t = texts(svg);
        let num = |s: &str| s.parse::<f64>().is_ok();
        let words: Vec<&Text> = t.iter().filter(|x| !num(&x.text)).collect();
        let label = words
            .iter()
            .map(|x| x.font_size)
            .fold(f64::INFINITY, f64::min);
        // Axis titles: rotated (y) or centred at the label size (x); a quantity, then a unit.
        for x in words
            .iter()
            .filter(|x| x.rotated || (x.anchor == "middle" && x.font_size <= label + 1e-9))
        {
            let (q, u) = x
                .text
                .split_once(" [")
                .unwrap_or_else(|| panic!("figure {k}: axis title '{}' has no unit", x.text));
            assert!(
                q.chars().any(|c| c.is_alphabetic()) && u.ends_with(']') && u.len() > 1,
                "figure {k}: axis title '{}'",
                x.text
            );
        }
        // Legends: no raw channel names.
        for x in words.iter().filter(|x| x.anchor == "start") {
            assert!(
                raw_channel(&x.text).is_none(),
                "figure {k}: legend '{}'",
                x.text
            );
        }
        let mut sig: Vec<String> = words.iter().map(|x| x.text.clone()).collect();
        sig.sort();
        assert!(
            !sigs.contains(&sig),
            "figure {k} repeats an earlier one: {sig:?}"
        );
        sigs.push(sig);
        let has = |s: &str| t.iter().any(|x| x.text == s);
        if has("damper force [kN]") && has("azimuth [deg]") {
            force_over_azimuth += 1;
        }
        // Periodicity: at least three labelled decades, and what an iterate stands for.
        if has("Periodicity residual") {
            let y: Vec<&Text> = t
                .iter()
                .filter(|x| x.anchor == "end" && num(&x.text))
                .collect();
            assert!(y.len() >= 3, "periodicity y ticks {y:?}");
            if t.iter().any(|x| x.text.starts_with("shooting iterate")) {
                assert!(t.iter().any(|x| x.text.contains("revs/iter)")), "{t:?}");
            }
        }
        // Loops: each at least 400 px of data wide.
        if has("Force-stroke loops") {
            assert!(has("Force-velocity loops"));
            let mut rows: std::collections::BTreeMap<i64, Vec<f64>> = Default::default();
            for x in t.iter().filter(|x| x.anchor == "middle" && num(&x.text)) {
                rows.entry(x.y.round() as i64).or_default().push(x.x);
            }
            assert_eq!(rows.len(), 2, "two loops, one above the other");
            for xs in rows.values() {
                let lo = xs.iter().cloned().fold(f64::INFINITY, f64::min);
                let hi = xs.iter().cloned().fold(f64::NEG_INFINITY, f64::max);
                assert!(hi - lo >= 400.0, "loop {lo}..{hi} px wide");
            }
        }
    }
    assert_eq!(
        force_over_azimuth, 1,
        "one figure of the force over azimuth"
    );

    // Tables: readable headers; the measurement in the metrics; real multipliers undamped by
    // name only.
    let tabs = tables(html);
    for (head, _) in &tabs {
        for h in head {
            assert!(raw_channel(h).is_none(), "table header '{h}'");
        }
    }
    for (_, rows) in &tabs {
        for r in rows {
            if let Some(c) = r.first() {
                assert!(raw_channel(c).is_none(), "table cell '{c}'");
            }
        }
    }
    let metrics = tabs
        .iter()
        .find(|(h, _)| h.iter().any(|c| c == "RMS error [N]"))
        .expect("metrics table");
    let meas = metrics
        .1
        .iter()
        .find(|r| r[0].contains("measured"))
        .expect("measurement row");
    assert!(
        meas[1..5].iter().all(|c| c.parse::<f64>().is_ok()),
        "{meas:?}"
    );
    let floquet = tabs
        .iter()
        .find(|(h, _)| h.iter().any(|c| c == "multiplier"))
        .expect("Floquet table");
    let col = |name: &str| floquet.0.iter().position(|c| c.starts_with(name)).unwrap();
    let (cm, cz, ck) = (col("multiplier"), col("damping ratio"), col("kind"));
    for r in &floquet.1 {
        if r[cm].ends_with("+0.000000i") && !r[cm].starts_with('-') {
            assert_eq!(r[ck], "real (non-oscillatory)");
            assert_eq!(r[cz], "-", "real multiplier given a damping ratio: {r:?}");
        }
        assert_ne!(r[cz], "1.0000", "{r:?}");
    }
    assert!(html.contains("no aerodynamic damping"));
    // Chambers named, each with its relief valve's cracking pressure.
    if html.contains("Inside the physical damper") {
        for want in [
            "p0: chamber 0 (compression)",
            "p1: chamber 1 (extension)",
            "valve 0 cracks at",
            "valve 1 cracks at",
        ] {
            assert!(html.contains(want), "{want}");
        }
    }
}

#[test]
fn the_report_opens_with_its_verdict_and_draws_every_model_alike() {
    let out = std::env::temp_dir().join(format!("rotorsim_layout_{}", std::process::id()));
    run_rigid(&out);
    let html = std::fs::read_to_string(out.join("report.html")).unwrap();

    // Banners and the verdict box before the first figure.
    let first_h2 = html.find("<h2").unwrap();
    let synthetic = html.find("class=\"banner").expect("SYNTHETIC banner");
    let verdict = html.find("Closest to").expect("verdict box");
    assert!(synthetic < verdict && verdict < first_h2);
    assert!(html[synthetic..verdict].contains("SYNTHETIC"));

    // The figures in reading order.
    let order = [
        "The damper models over the measurement",
        "Force-stroke and force-velocity loops",
        "Damper stroke",
        "Harmonics",
        "Periodicity",
        "Blade tip motion",
    ];
    let at: Vec<usize> = order
        .iter()
        .map(|h| h2_at(&html, h).unwrap_or_else(|| panic!("no section {h}")))
        .collect();
    assert!(at.windows(2).all(|w| w[0] < w[1]), "{order:?} at {at:?}");
    // The models over the measurement come first of all figures.
    assert!(html[..at[0]].find("<svg").is_none());

    let all = svgs(&html);
    assert!(all.len() >= 8, "{} figures", all.len());
    let (mut azimuth_axes, mut legends) = (0, 0);
    for (k, svg) in all.iter().enumerate() {
        let t = texts(svg);
        // Tick labels: numbers, written axis by axis: a run of consecutive numeric texts with one
        // anchor is one axis (x ticks centred under it, y ticks end-anchored left of it).
        let num = |s: &str| s.parse::<f64>().is_ok();
        let mut axes: std::collections::BTreeMap<(String, usize), Vec<&Text>> = Default::default();
        let mut run = 0;
        let mut prev: Option<&Text> = None;
        for x in &t {
            if !num(&x.text) {
                prev = None;
                continue;
            }
            if prev.is_none_or(|p| p.anchor != x.anchor) {
                run += 1;
            }
            let kind = if x.anchor == "middle" { "x" } else { "y" };
            axes.entry((kind.to_string(), run)).or_default().push(x);
            prev = Some(x);
        }
        for ((kind, _), ticks) in &axes {
            let labels: Vec<&str> = ticks.iter().map(|x| x.text.as_str()).collect();
            let mut uniq = labels.clone();
            uniq.sort();
            uniq.dedup();
            assert_eq!(
                uniq.len(),
                labels.len(),
                "figure {k}: repeated {kind} ticks {labels:?}"
            );
        }
        // Every azimuth axis is ticked every 90 deg.
        let azimuth_titles = t.iter().filter(|x| x.text == "azimuth [deg]").count();
        if azimuth_titles > 0 {
            let x_axes: Vec<Vec<&str>> = axes
                .iter()
                .filter(|((kind, _), _)| kind == "x")
                .map(|(_, v)| v.iter().map(|x| x.text.as_str()).collect())
                .collect();
            // 0-360, or a window shifted by a multiple of 90 deg (relief valves: no opening cut)
            let ninety = x_axes
                .iter()
                .filter(|l| {
                    let v: Vec<f64> = l.iter().filter_map(|x| x.parse().ok()).collect();
                    v.len() == 5 && v[0] % 90.0 == 0.0 && v.windows(2).all(|w| w[1] - w[0] == 90.0)
                })
                .count();
            assert!(
                ninety >= azimuth_titles,
                "figure {k}: azimuth ticks {x_axes:?}"
            );
            azimuth_axes += ninety;
        }
        // Legends (start-anchored labels of a model) right of every tick label of their panel
        // row, and drawn in the model's colour.
        for l in t.iter().filter(|x| x.anchor == "start") {
            let Some(want) = model_colour(&l.text) else {
                continue;
            };
            legends += 1;
            assert_eq!(
                l.colour_before.as_deref(),
                Some(want),
                "figure {k}: legend '{}'",
                l.text
            );
            // Over the data would put it between the first and last tick of an x axis below it.
            for ((kind, _), ticks) in &axes {
                let y = ticks[0].y;
                if kind != "x" || y < l.y || y - l.y > 400.0 {
                    continue;
                }
                let lo = ticks.iter().map(|x| x.x).fold(f64::INFINITY, f64::min);
                let hi = ticks.iter().map(|x| x.x).fold(f64::NEG_INFINITY, f64::max);
                assert!(
                    !(lo < l.x && l.x < hi),
                    "figure {k}: legend '{}' at x {} over the data ({lo}..{hi})",
                    l.text,
                    l.x
                );
            }
        }
    }
    assert!(azimuth_axes >= 4, "{azimuth_axes} azimuth axes");
    assert!(legends >= 12, "{legends} model legends");
    check_newcomer_points(&html);
    let _ = std::fs::remove_dir_all(&out);
}

/// The elastic run's report: blade loads readable (root loads split by magnitude, span loads
/// with quantity and unit), the relief valves drawn from their sub-step envelope (which holds
/// the step's own sample).
#[test]
fn the_elastic_report_reads_for_a_newcomer() {
    let out = std::env::temp_dir().join(format!("rotorsim_layout_el_{}", std::process::id()));
    run(&out, &[]);
    let html = std::fs::read_to_string(out.join("report.html")).unwrap();
    check_newcomer_points(&html);
    assert!(html.contains("flap moment [kN m]"));
    // The centrifugal fx alone; the shears together.
    let titles: Vec<String> = svgs(&html)
        .iter()
        .flat_map(|s| texts(s))
        .map(|t| t.text)
        .collect();
    assert!(titles.iter().any(|t| t == "Root force fx"), "fx alone");
    assert!(titles.iter().any(|t| t == "Root forces fy, fz"));
    assert!(html.contains("over the hydraulic sub-steps"));

    let csv = std::fs::read_to_string(out.join("physical/last_rev.csv")).unwrap();
    let mut lines = csv.lines();
    let head: Vec<&str> = lines.next().unwrap().split(',').collect();
    let at = |n: &str| head.iter().position(|h| *h == n).unwrap();
    // the envelope after every column written before it
    assert!(at("hub_mz_fixed_Nm") < at("x_valve0_substep_min_m"));
    let rows: Vec<Vec<f64>> = lines
        .map(|l| l.split(',').map(|v| v.parse().unwrap()).collect())
        .collect();
    let mut moving = 0;
    for q in ["x_valve0", "v_valve0", "q_valve0", "x_valve1"] {
        let unit = match q.chars().next() {
            Some('x') => "m",
            Some('v') => "m_s",
            _ => "m3_s",
        };
        let (p, lo, hi) = (
            at(&format!("{q}_{unit}")),
            at(&format!("{q}_substep_min_{unit}")),
            at(&format!("{q}_substep_max_{unit}")),
        );
        for r in &rows {
            let tol = 1e-12 + 1e-9 * r[p].abs();
            assert!(r[lo] <= r[p] + tol && r[p] <= r[hi] + tol, "{q}: {r:?}");
            moving += usize::from(r[hi] > r[lo]);
        }
    }
    assert!(moving > 0, "a relief valve moves within a step");
    // The valve figures' azimuth window cuts no opening: both valves shut across its edge.
    let start: f64 = match html.find("Azimuth window ") {
        Some(i) => html[i + 15..].split(' ').next().unwrap().parse().unwrap(),
        None => 0.0,
    };
    let edge = start.rem_euclid(360.0);
    let az = at("azimuth_deg");
    let k = rows
        .iter()
        .position(|r| r[az] == edge)
        .expect("a row at the edge");
    let before = (k + rows.len() - 1) % rows.len();
    for v in ["x_valve0_substep_max_m", "x_valve1_substep_max_m"] {
        assert_eq!(rows[k][at(v)], 0.0, "{v} open at the window edge {edge}");
        assert_eq!(rows[before][at(v)], 0.0, "{v} open just before {edge}");
    }
    let opens = rows
        .iter()
        .any(|r| r[at("x_valve0_substep_max_m")] > 0.0 && r[az] > 300.0)
        && rows
            .iter()
            .any(|r| r[at("x_valve0_substep_max_m")] > 0.0 && r[az] < 10.0);
    if opens {
        assert_ne!(start, 0.0, "an opening across 0 deg needs a shifted window");
    }
    let _ = std::fs::remove_dir_all(&out);
}
