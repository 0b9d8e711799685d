//! DIR/sweep.csv and DIR/sweep.html from the case folders (whoever ran them: this process or
//! the shards of a cluster job).
use super::{case_dir, state_of, CaseState, Plan};
use crate::report::html::HtmlReport;
use crate::report::plot::Plot;
use rayon::prelude::*;
use serde_json::Value;
use std::path::Path;

/// Metric columns after the case id, the varied keys, `damper_model` and `status`.
pub const METRICS: &[&str] = &[
    "warm_start_from",
    "rms_error_N",
    "rms_error_rel",
    "correlation",
    "damper_force_min_N",
    "damper_force_max_N",
    "damper_force_peak_to_peak_N",
    "periodic_residual",
    "revolutions",
    "wall_time_s",
    "pitch_link_force_half_p2p_N",
    "root_mx_half_p2p_Nm",
    "root_my_half_p2p_Nm",
    "root_mz_half_p2p_Nm",
    // stability cases (a ground-resonance map each)
    "min_damping_ratio",
    "min_damping_mode",
    "min_damping_speed_rad_s",
    "stable",
];

/// Metrics plotted in sweep.html (numeric ones): axis label (engineering units) and the scale
/// from the CSV's SI value to it.
const PLOTTED: &[(&str, &str, f64)] = &[
    ("rms_error_N", "RMS error vs measured [kN]", 1e-3),
    ("correlation", "correlation with measured [-]", 1.0),
    (
        "damper_force_peak_to_peak_N",
        "damper force peak-to-peak [kN]",
        1e-3,
    ),
    ("periodic_residual", "periodicity residual [-]", 1.0),
    ("revolutions", "revolutions integrated", 1.0),
    ("wall_time_s", "wall time [s]", 1.0),
    (
        "pitch_link_force_half_p2p_N",
        "pitch-link force half peak-to-peak [kN]",
        1e-3,
    ),
    (
        "root_mx_half_p2p_Nm",
        "root moment mx half peak-to-peak [kN m]",
        1e-3,
    ),
    (
        "root_my_half_p2p_Nm",
        "root moment my half peak-to-peak [kN m]",
        1e-3,
    ),
    (
        "root_mz_half_p2p_Nm",
        "root moment mz half peak-to-peak [kN m]",
        1e-3,
    ),
    (
        "min_damping_ratio",
        "least damping ratio over the speeds [-]",
        1.0,
    ),
];

/// One row of sweep.csv.
#[derive(Clone, Debug, PartialEq)]
pub struct Row {
    pub case_id: String,
    pub varied: Vec<String>,
    pub model: String,
    pub status: String,
    /// One per [`METRICS`], empty when not available.
    pub metrics: Vec<String>,
}

fn num(v: &Value) -> String {
    match v {
        Value::Number(n) => n.to_string(),
        Value::Bool(b) => b.to_string(),
        _ => String::new(),
    }
}

fn read_json(p: &Path) -> Option<Value> {
    serde_json::from_str(&std::fs::read_to_string(p).ok()?).ok()
}

/// State of every case folder of the plan, in plan order, each checked against its manifest
/// (in parallel: checking hashes every file).
pub fn states(plan: &Plan, dir: &Path) -> Vec<CaseState> {
    plan.cases.par_iter().map(|c| state_of(dir, c)).collect()
}

/// Rows of every case of the plan, in plan order, one per case and damper model, from the
/// case folders in `states` ([`states`]). A damaged folder gives one `failed` row and nothing
/// of it is read.
pub fn rows(plan: &Plan, dir: &Path, states: &[CaseState]) -> Vec<Row> {
    let mut out = Vec::new();
    for (c, state) in plan.cases.iter().zip(states) {
        let varied = plan.varied(c);
        let cd = case_dir(dir, &c.id);
        let summary = match state {
            CaseState::Pending | CaseState::Damaged(_) => None,
            _ => read_json(&cd.join("summary.json")),
        };
        let empty = |status: &str| Row {
            case_id: c.id.clone(),
            varied: varied.clone(),
            model: String::new(),
            status: status.into(),
            metrics: vec![String::new(); METRICS.len()],
        };
        let Some(s) = summary else {
            out.push(empty(match state {
                CaseState::Pending => "not_run",
                _ => "failed",
            }));
            continue;
        };
        let warm = s["options"]["initial_state"]
            .as_str()
            .and_then(|p| {
                Path::new(p)
                    .file_name()
                    .map(|f| f.to_string_lossy().into_owned())
            })
            .unwrap_or_default();
        if s["min_damping_ratio"].is_number() {
            // a stability case: its map's least damping ratio, where, and whether stable
            let mut metrics = vec![String::new(); METRICS.len()];
            let n = METRICS.len();
            metrics[n - 4] = num(&s["min_damping_ratio"]);
            metrics[n - 3] = s["min_damping_mode"].as_str().unwrap_or("").to_string();
            metrics[n - 2] = num(&s["min_damping_speed_rad_s"]);
            metrics[n - 1] = num(&s["stable"]);
            out.push(Row {
                case_id: c.id.clone(),
                varied: varied.clone(),
                model: s["damper_model"].as_str().unwrap_or("").to_string(),
                status: if matches!(state, CaseState::Done) {
                    "ok"
                } else {
                    "failed"
                }
                .into(),
                metrics,
            });
            continue;
        }
        let Some(models) = s["models"].as_object() else {
            out.push(empty("failed"));
            continue;
        };
        for (name, m) in models {
            let status = if m["status"] != "ok" {
                "failed"
            } else if m["periodicity"]["converged"] == Value::Bool(true) {
                "ok"
            } else {
                "not_periodic"
            };
            let loads = &m["loads"]["channels"];
            let hp = |ch: &str| num(&loads[ch]["half_peak_to_peak"]);
            let metrics = vec![
                warm.clone(),
                num(&m["metrics"]["rms_error_N"]),
                num(&m["metrics"]["rms_error_rel"]),
                num(&m["metrics"]["correlation"]),
                num(&m["damper_force_N"]["min"]),
                num(&m["damper_force_N"]["max"]),
                num(&m["damper_force_N"]["peak_to_peak"]),
                num(&m["periodicity"]["last"]),
                num(&m["periodic"]["revolutions_integrated"]),
                num(&m["wall_time_s"]["total"]),
                hp("pitch_link_force_N"),
                hp("root_mx_Nm"),
                hp("root_my_Nm"),
                hp("root_mz_Nm"),
                // the stability columns
                String::new(),
                String::new(),
                String::new(),
                String::new(),
            ];
            out.push(Row {
                case_id: c.id.clone(),
                varied: varied.clone(),
                model: name.clone(),
                status: status.into(),
                metrics,
            });
        }
    }
    out
}

/// sweep.csv text.
pub fn csv(plan: &Plan, rows: &[Row]) -> anyhow::Result<String> {
    let mut w = csv::Writer::from_writer(Vec::new());
    let mut header = vec!["case_id".to_string()];
    header.extend(plan.keys.iter().cloned());
    header.push("damper_model".into());
    header.push("status".into());
    header.extend(METRICS.iter().map(|s| s.to_string()));
    w.write_record(&header)?;
    for r in rows {
        let mut rec = vec![r.case_id.clone()];
        rec.extend(r.varied.iter().cloned());
        rec.push(r.model.clone());
        rec.push(r.status.clone());
        rec.extend(r.metrics.iter().cloned());
        w.write_record(&rec)?;
    }
    Ok(String::from_utf8(
        w.into_inner().map_err(|e| anyhow::anyhow!("{e}"))?,
    )?)
}

/// Counts of rows by status, for messages: (ok, not periodic, failed, not run).
pub fn counts(rows: &[Row]) -> (usize, usize, usize, usize) {
    let n = |s: &str| rows.iter().filter(|r| r.status == s).count();
    (n("ok"), n("not_periodic"), n("failed"), n("not_run"))
}

/// sweep.html: each plotted metric against each numeric varied key, one series per damper
/// model, and the table.
pub fn html(plan: &Plan, rows: &[Row]) -> String {
    let mut h = HtmlReport::new("rotorsim sweep");
    let (ok, np, failed, not_run) = counts(rows);
    h.paragraph(&format!(
        "{} cases of {}; rows (case x damper model): {ok} periodic, {np} NOT periodic, {failed} failed, {not_run} not run.",
        plan.cases.len(),
        plan.file
    ));
    if failed + not_run > 0 {
        h.notice("This sweep is NOT complete: some cases failed or have not run (status column).");
    }
    let mut models: Vec<&str> = rows
        .iter()
        .map(|r| r.model.as_str())
        .filter(|m| !m.is_empty())
        .collect();
    models.sort_unstable();
    models.dedup();
    for (ki, key) in plan.keys.iter().enumerate() {
        let xs: Vec<Option<f64>> = rows.iter().map(|r| r.varied[ki].parse().ok()).collect();
        if xs.iter().all(|x| x.is_none()) {
            h.paragraph(&format!("{key}: not numeric, not plotted (see the table)."));
            continue;
        }
        h.heading(2, &format!("against {key}"));
        for (metric, label, scale) in PLOTTED {
            let mi = METRICS.iter().position(|m| m == metric).unwrap_or(0);
            let mut p = Plot::new(&format!("{label} vs {key}"), key, label).y_scale(*scale);
            let mut any = false;
            for m in &models {
                let (x, y): (Vec<f64>, Vec<f64>) = rows
                    .iter()
                    .zip(&xs)
                    .filter(|(r, _)| r.model == *m)
                    .filter_map(|(r, x)| Some(((*x)?, r.metrics[mi].parse::<f64>().ok()?)))
                    .unzip();
                if !x.is_empty() {
                    any = true;
                    p = p.points(m, &x, &y);
                }
            }
            if !any {
                continue;
            }
            match p.to_svg(720, 300) {
                Ok(svg) => h.svg(&format!("{label} against {key}"), &svg),
                Err(e) => h.paragraph(&format!("{label}: not plotted ({e})")),
            };
        }
    }
    let mut header: Vec<&str> = vec!["case_id"];
    header.extend(plan.keys.iter().map(|s| s.as_str()));
    header.extend(["damper_model", "status"]);
    header.extend(METRICS);
    let table: Vec<Vec<String>> = rows
        .iter()
        .map(|r| {
            let mut v = vec![r.case_id.clone()];
            v.extend(r.varied.iter().cloned());
            v.push(r.model.clone());
            v.push(r.status.clone());
            v.extend(r.metrics.iter().cloned());
            v
        })
        .collect();
    h.heading(2, "cases");
    h.table(&header, &table);
    h.finish()
}

/// What [`write`] wrote: the rows, and the failed cases with the reason (published
/// incomplete, or a folder that does not match its manifest).
#[derive(Clone, Debug, Default)]
pub struct Merged {
    pub rows: Vec<Row>,
    pub failed: Vec<(String, String)>,
}

/// Writes DIR/sweep.csv and DIR/sweep.html (each atomically) from the case folders, each
/// checked against its manifest first.
pub fn write(plan: &Plan, dir: &Path) -> anyhow::Result<Merged> {
    let states = states(plan, dir);
    let rows = rows(plan, dir, &states);
    crate::io::write_atomic(&dir.join("sweep.csv"), csv(plan, &rows)?.as_bytes())?;
    crate::io::write_atomic(&dir.join("sweep.html"), html(plan, &rows).as_bytes())?;
    let failed = plan
        .cases
        .iter()
        .zip(&states)
        .filter_map(|(c, s)| Some((c.id.clone(), s.failure()?.to_string())))
        .collect();
    Ok(Merged { rows, failed })
}
