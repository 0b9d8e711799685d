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
    let _ = std::fs::remove_dir_all(out);
    let o = Command::new(env!("CARGO_BIN_EXE_rotorsim"))
        .current_dir(repo())
        .args(["run", "--model", "rigid", "--out"])
        .arg(out)
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
}

#[test]
fn the_report_opens_with_its_verdict_and_draws_every_model_alike() {
    let out = std::env::temp_dir().join(format!("rotorsim_layout_{}", std::process::id()));
    run_rigid(&out);
    let html = std::fs::read_to_string(out.join("report.html")).unwrap();

    // Banners and the verdict box before the first figure.
    let first_h2 = html.find("<h2>").unwrap();
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
        .map(|h| {
            html.find(&format!("<h2>{h}"))
                .unwrap_or_else(|| panic!("no section {h}"))
        })
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
            let ninety = x_axes
                .iter()
                .filter(|l| **l == ["0", "90", "180", "270", "360"])
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
    let _ = std::fs::remove_dir_all(&out);
}
