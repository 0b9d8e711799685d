//! The sensitivity table from the case folders: per parameter, each output at the low, nominal
//! and high value and the swing (high minus low); DIR/sensitivity.csv, DIR/sensitivity.html
//! (a tornado chart and a ranking per output) and DIR/summary.json.
use super::{Param, SensitivityOptions, Setup, NOMINAL};
use crate::report::html::{Banner, HtmlReport};
use crate::report::plot::Plot;
use crate::sweep::{case_dir, state_of, CaseState, Plan};
use plotters::style::RGBColor;
use serde_json::{json, Value};
use std::path::Path;

/// One output of the table: the stem of its columns, its unit (empty: dimensionless) and what
/// it is.
#[derive(Clone, Copy, Debug)]
pub struct OutputDef {
    pub name: &'static str,
    pub unit: &'static str,
    pub title: &'static str,
    /// Only the multibody model (`uh60a`) gives it.
    pub multibody_only: bool,
}

/// The outputs, in the order of the columns.
pub const OUTPUTS: [OutputDef; 7] = [
    OutputDef {
        name: "damper_force_peak_to_peak",
        unit: "N",
        title: "damper force peak-to-peak",
        multibody_only: false,
    },
    OutputDef {
        name: "damper_force_rms_error",
        unit: "N",
        title: "damper force RMS error against the record",
        multibody_only: false,
    },
    OutputDef {
        name: "pitch_link_force_half_p2p",
        unit: "N",
        title: "pitch-link force half peak-to-peak",
        multibody_only: true,
    },
    OutputDef {
        name: "pitch_link_force_1rev",
        unit: "N",
        title: "pitch-link force 1/rev amplitude",
        multibody_only: true,
    },
    OutputDef {
        name: "root_chord_moment_half_p2p",
        unit: "Nm",
        title: "root chord (lag) moment root_mz half peak-to-peak",
        multibody_only: true,
    },
    OutputDef {
        name: "root_flap_moment_half_p2p",
        unit: "Nm",
        title: "root flap moment root_my half peak-to-peak",
        multibody_only: true,
    },
    OutputDef {
        name: "lag_damping_ratio",
        unit: "",
        title: "lag damping ratio (Floquet, least-damped lag mode)",
        multibody_only: false,
    },
];

impl OutputDef {
    /// Column name of `which` (`low`, `nominal`, `high`, `swing`), unit last.
    pub fn column(&self, which: &str) -> String {
        if self.unit.is_empty() {
            format!("{}_{which}", self.name)
        } else {
            format!("{}_{which}_{}", self.name, self.unit)
        }
    }
}

/// The outputs of one damper model's entry of a run's summary.json, in [`OUTPUTS`] order
/// (None: not in the summary, e.g. loads of the rigid model), and whether its lag multiplier
/// is reliable (None: no lag multiplier).
pub fn extract(m: &Value) -> (Vec<Option<f64>>, Option<bool>) {
    let loads = &m["loads"]["channels"];
    let hp = |ch: &str| loads[ch]["half_peak_to_peak"].as_f64();
    let one_rev = loads["pitch_link_force_N"]["harmonics"]
        .as_array()
        .and_then(|h| {
            h.iter()
                .find(|x| x["n_per_rev"].as_u64() == Some(1))
                .and_then(|x| x["amplitude"].as_f64())
        });
    // the run puts the oscillating lag mode first (least damped first otherwise)
    let lag = m["periodic"]["floquet_multipliers"]
        .as_array()
        .and_then(|a| a.first())
        .filter(|x| x["mode"] == "lag");
    (
        vec![
            m["damper_force_N"]["peak_to_peak"].as_f64(),
            m["metrics"]["rms_error_N"].as_f64(),
            hp("pitch_link_force_N"),
            one_rev,
            hp("root_mz_Nm"),
            hp("root_my_Nm"),
            // only a resolved multiplier (residual at most 1% of |mu|) has a damping ratio
            lag.filter(|x| x["reliable"].as_bool() == Some(true))
                .and_then(|x| x["damping_ratio"].as_f64()),
        ],
        lag.and_then(|x| x["reliable"].as_bool()),
    )
}

/// The result of one case: `ok`, `not_periodic`, `failed` (with the reason), `not_run`, or
/// `range_refused` for a side the deck's validation refused at every default factor (its
/// values are the nominal case's).
#[derive(Clone, Debug, PartialEq)]
pub struct CaseResult {
    pub id: String,
    pub status: String,
    pub reason: Option<String>,
    pub values: Vec<Option<f64>>,
    pub lag_reliable: Option<bool>,
}

/// Reads case `id` of the plan from its folder (checked against its manifest).
pub fn read_case(plan: &Plan, dir: &Path, id: &str, damper: &str) -> CaseResult {
    let none = |status: &str, reason: Option<String>| CaseResult {
        id: id.to_string(),
        status: status.into(),
        reason,
        values: vec![None; OUTPUTS.len()],
        lag_reliable: None,
    };
    let Some(case) = plan.cases.iter().find(|c| c.id == id) else {
        return none("not_run", Some("not in the plan".into()));
    };
    let state = state_of(dir, case);
    match &state {
        CaseState::Pending => return none("not_run", None),
        CaseState::Damaged(why) => return none("failed", Some(why.clone())),
        _ => {}
    }
    let s: Option<Value> = std::fs::read_to_string(case_dir(dir, id).join("summary.json"))
        .ok()
        .and_then(|t| serde_json::from_str(&t).ok());
    let Some(m) = s
        .as_ref()
        .map(|s| &s["models"][damper])
        .filter(|m| m.is_object())
    else {
        return none(
            "failed",
            Some(state.failure().unwrap_or("no result").to_string()),
        );
    };
    if m["status"] != "ok" {
        return none(
            "failed",
            Some(state.failure().unwrap_or("model failed").to_string()),
        );
    }
    let (values, lag_reliable) = extract(m);
    let status = if m["periodicity"]["converged"] == Value::Bool(true) {
        "ok"
    } else {
        "not_periodic"
    };
    CaseResult {
        id: id.to_string(),
        status: status.into(),
        reason: None,
        values,
        lag_reliable,
    }
}

/// One parameter's row: its low and high cases.
#[derive(Clone, Debug)]
pub struct Row {
    pub param: Param,
    pub low: CaseResult,
    pub high: CaseResult,
}

impl Row {
    /// Output `k` at low, nominal and high.
    pub fn triple(&self, nominal: &CaseResult, k: usize) -> [Option<f64>; 3] {
        [self.low.values[k], nominal.values[k], self.high.values[k]]
    }
    /// High minus low of output `k`.
    pub fn swing(&self, k: usize) -> Option<f64> {
        Some(self.high.values[k]? - self.low.values[k]?)
    }
    /// Largest minus least of output `k` over low, nominal and high (the length of the
    /// tornado's bars; the magnitude of the swing when the output is monotonic).
    pub fn spread(&self, nominal: &CaseResult, k: usize) -> Option<f64> {
        let v: Vec<f64> = self.triple(nominal, k).iter().flatten().copied().collect();
        if v.len() < 2 {
            return None;
        }
        let (lo, hi) = v
            .iter()
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &x| {
                (a.min(x), b.max(x))
            });
        Some(hi - lo)
    }
}

/// The whole table.
#[derive(Clone, Debug)]
pub struct Sensitivity {
    pub rotor: String,
    pub flight: String,
    pub model: String,
    pub damper: String,
    pub synthetic: bool,
    pub nominal: CaseResult,
    pub rows: Vec<Row>,
    pub skipped: Vec<super::scan::Skipped>,
    pub cases: usize,
    pub wall_s: f64,
}

impl Sensitivity {
    /// Row indices ranked by the spread of output `k`, largest first (rows without it last).
    pub fn ranking(&self, k: usize) -> Vec<usize> {
        let mut idx: Vec<usize> = (0..self.rows.len()).collect();
        let key = |i: &usize| self.rows[*i].spread(&self.nominal, k).unwrap_or(-1.0);
        idx.sort_by(|a, b| key(b).total_cmp(&key(a)).then(a.cmp(b)));
        idx
    }
    /// The three rows output `k` is most sensitive to (by [`Sensitivity::ranking`]), each with
    /// its name and spread (rows without one left out).
    pub fn top3(&self, k: usize) -> Vec<(&Row, f64)> {
        self.ranking(k)
            .iter()
            .take(3)
            .filter_map(|&i| {
                let r = &self.rows[i];
                Some((r, r.spread(&self.nominal, k)?))
            })
            .collect()
    }
    /// Cases that failed or did not run, with the reason.
    pub fn failures(&self) -> Vec<(String, String)> {
        std::iter::once(&self.nominal)
            .chain(self.rows.iter().flat_map(|r| [&r.low, &r.high]))
            .filter(|c| c.status == "failed" || c.status == "not_run")
            .map(|c| {
                (
                    c.id.clone(),
                    format!(
                        "{}{}",
                        c.status,
                        c.reason
                            .as_ref()
                            .map(|r| format!(": {r}"))
                            .unwrap_or_default()
                    ),
                )
            })
            .collect()
    }
    /// Cases that ran but did not reach the periodicity tolerance.
    pub fn not_periodic(&self) -> Vec<String> {
        std::iter::once(&self.nominal)
            .chain(self.rows.iter().flat_map(|r| [&r.low, &r.high]))
            .filter(|c| c.status == "not_periodic")
            .map(|c| c.id.clone())
            .collect()
    }
}

/// Reads every case of the plan into the table.
/// Reads every case of the plans (the output folder's, then the fallback rounds') into the
/// table, each side of a parameter from the round that ran it last.
pub fn collect(
    o: &SensitivityOptions,
    setup: &Setup,
    plans: &[Plan],
    wall_s: f64,
) -> anyhow::Result<Sensitivity> {
    let dir = &o.out;
    let damper = setup.damper.as_str();
    let nominal = read_case(&plans[0], dir, NOMINAL, damper);
    let synthetic = std::fs::read_to_string(case_dir(dir, NOMINAL).join("summary.json"))
        .ok()
        .and_then(|t| serde_json::from_str::<Value>(&t).ok())
        .is_some_and(|s| s["synthetic"] == Value::Bool(true));
    let side = |runs: bool, id: String, round: usize| {
        if runs {
            let k = round.min(plans.len() - 1);
            read_case(&plans[k], &super::round_dir(dir, k), &id, damper)
        } else {
            CaseResult {
                id,
                status: "range_refused".into(),
                reason: Some("no default factor accepted by the deck: the nominal value".into()),
                ..nominal.clone()
            }
        }
    };
    let rows = setup
        .params
        .iter()
        .map(|p| {
            let (lo, hi) = p.case_ids();
            Row {
                param: p.clone(),
                low: side(p.low_runs, lo, p.low_round),
                high: side(p.high_runs, hi, p.high_round),
            }
        })
        .collect();
    Ok(Sensitivity {
        rotor: o.rotor.display().to_string(),
        flight: o.flight.display().to_string(),
        model: o.model.clone(),
        damper: setup.damper.clone(),
        synthetic,
        nominal,
        rows,
        skipped: setup.skipped.clone(),
        cases: plans.iter().map(|p| p.cases.len()).sum(),
        wall_s,
    })
}

/// Shortest text that reads back to the same double (empty: none).
fn num(x: Option<f64>) -> String {
    x.map(|v| format!("{v:?}")).unwrap_or_default()
}

/// sensitivity.csv: one row per parameter.
pub fn csv(t: &Sensitivity) -> anyhow::Result<String> {
    let mut w = csv::Writer::from_writer(Vec::new());
    let mut header: Vec<String> = [
        "key",
        "unit",
        "source",
        "range",
        "nominal_value",
        "low_value",
        "high_value",
        "low_case_status",
        "high_case_status",
    ]
    .iter()
    .map(|s| s.to_string())
    .collect();
    for o in &OUTPUTS {
        for w in ["low", "nominal", "high", "swing"] {
            header.push(o.column(w));
        }
    }
    w.write_record(&header)?;
    for r in &t.rows {
        let p = &r.param;
        let mut rec = vec![
            p.name(),
            p.unit(),
            p.source.clone(),
            p.range.clone(),
            num(Some(p.target.nominal)),
            num(Some(p.low)),
            num(Some(p.high)),
            r.low.status.clone(),
            r.high.status.clone(),
        ];
        for k in 0..OUTPUTS.len() {
            let [lo, nom, hi] = r.triple(&t.nominal, k);
            rec.extend([num(lo), num(nom), num(hi), num(r.swing(k))]);
        }
        w.write_record(&rec)?;
    }
    Ok(String::from_utf8(
        w.into_inner().map_err(|e| anyhow::anyhow!("{e}"))?,
    )?)
}

/// summary.json: the setup, the nominal outputs, each output's ranking and every parameter.
pub fn summary(t: &Sensitivity) -> Value {
    let outputs: Vec<Value> = OUTPUTS
        .iter()
        .enumerate()
        .map(|(k, o)| {
            json!({
                "name": o.name,
                "unit": o.unit,
                "title": o.title,
                "nominal": t.nominal.values[k],
                "ranking": t.ranking(k).iter().map(|&i| {
                    let r = &t.rows[i];
                    json!({
                        "key": r.param.name(),
                        "low": r.low.values[k],
                        "high": r.high.values[k],
                        "swing": r.swing(k),
                        "spread": r.spread(&t.nominal, k),
                    })
                }).collect::<Vec<_>>(),
            })
        })
        .collect();
    let params: Vec<Value> = t
        .rows
        .iter()
        .map(|r| {
            let p = &r.param;
            let mut outs = serde_json::Map::new();
            for (k, o) in OUTPUTS.iter().enumerate() {
                let [lo, nom, hi] = r.triple(&t.nominal, k);
                outs.insert(
                    o.name.into(),
                    json!({"low": lo, "nominal": nom, "high": hi, "swing": r.swing(k)}),
                );
            }
            json!({
                "key": p.name(),
                "unit": p.unit(),
                "source": p.source,
                "range": p.range,
                "nominal_value": p.target.nominal,
                "low_value": p.low,
                "high_value": p.high,
                "low_case": {"id": r.low.id, "status": r.low.status, "reason": r.low.reason},
                "high_case": {"id": r.high.id, "status": r.high.status, "reason": r.high.reason},
                "outputs": outs,
            })
        })
        .collect();
    json!({
        "format": "rotorsim sensitivity 1",
        "rotor": t.rotor,
        "flight_record": t.flight,
        "rotor_model": t.model,
        "damper_model": t.damper,
        "synthetic": t.synthetic,
        "cases": t.cases,
        "wall_time_s": t.wall_s,
        "nominal": {
            "status": t.nominal.status,
            "lag_mode_reliable": t.nominal.lag_reliable,
            "outputs": OUTPUTS.iter().zip(&t.nominal.values)
                .map(|(o, v)| (o.name.to_string(), json!(v)))
                .collect::<serde_json::Map<_, _>>(),
        },
        "outputs": outputs,
        "parameters": params,
        "skipped": t.skipped.iter().map(|s| json!({
            "line": s.line, "key": s.key, "text": s.text, "reason": s.reason,
        })).collect::<Vec<_>>(),
        "failed": t.failures().iter().map(|(id, why)| json!({"case": id, "reason": why})).collect::<Vec<_>>(),
        "not_periodic": t.not_periodic(),
    })
}

/// Engineering display of a value of output `o`.
fn show(o: &OutputDef, v: Option<f64>) -> String {
    match v {
        None => "-".into(),
        Some(x) if o.unit.is_empty() => format!("{x:.4}"),
        Some(x) => format!("{x:.0}"),
    }
}

/// Change of `v` from `nom`, in % of |nom| (absolute when the nominal is zero).
fn change(v: Option<f64>, nom: Option<f64>) -> Option<f64> {
    let (v, n) = (v?, nom?);
    if n == 0.0 {
        return None;
    }
    Some(100.0 * (v - n) / n.abs())
}

fn pct(x: Option<f64>) -> String {
    x.map(|v| format!("{v:+.1}%")).unwrap_or_else(|| "-".into())
}

/// The tornado chart of output `k`: per parameter (ranked), the change of the output at the
/// low and at the high value, in % of the nominal output.
fn tornado(t: &Sensitivity, k: usize) -> Option<Result<String, String>> {
    let o = &OUTPUTS[k];
    let nom = t.nominal.values[k];
    let order = t.ranking(k);
    let shown: Vec<usize> = order
        .into_iter()
        .filter(|&i| t.rows[i].spread(&t.nominal, k).is_some())
        .collect();
    if shown.is_empty() || nom.is_none_or(|n| n == 0.0) {
        return None;
    }
    let names: Vec<String> = shown.iter().map(|&i| t.rows[i].param.name()).collect();
    let (mut yl, mut xl, mut yh, mut xh) = (vec![], vec![], vec![], vec![]);
    for (row, &i) in shown.iter().enumerate() {
        let r = &t.rows[i];
        if let Some(x) = change(r.low.values[k], nom) {
            yl.push(row as f64);
            xl.push(x);
        }
        if let Some(x) = change(r.high.values[k], nom) {
            yh.push(row as f64);
            xh.push(x);
        }
    }
    let p = Plot::new(
        &format!("{} (nominal {})", o.title, show(o, nom)),
        &format!("change from the nominal {} [% of nominal]", o.name),
        "",
    )
    .y_categories(&names)
    .hbars("at the low value", &xl, &yl)
    .colour(RGBColor(31, 119, 180))
    .hbars("at the high value", &xh, &yh)
    .colour(RGBColor(230, 120, 20));
    let height = (26 * names.len() as u32 + 120).max(220);
    Some(p.to_svg(1000, height).map_err(|e| e.to_string()))
}

/// sensitivity.html: the verdict lines, a tornado chart and a ranking per output, the
/// parameters and the skipped labels.
pub fn html(t: &Sensitivity) -> String {
    let mut h = HtmlReport::new("rotorsim sensitivity");
    if t.synthetic {
        h.banner(
            Banner::Synthetic,
            "SYNTHETIC flight record: the \"measured\" damper force is synthetic data (the record's metadata says synthetic), not a flight-test measurement; the RMS error is against it.",
        );
    }
    status_banners(&mut h, t);
    h.paragraph(&format!(
        "Rotor deck {}, flight record {}, rotor model {}, damper model {}: {} parameter(s), each moved to a low and a high value with the others at their nominal value ({} cases, {:.0} s). Default range of a value the deck labels ASSUMED: x0.5 to x2 of its nominal value (a side the deck's validation refuses falls back to x0.8 or x1.25, then x0.95 or x1.05); --vary KEY=LOW:HIGH states its own.",
        t.rotor, t.flight, t.model, t.damper, t.rows.len(), t.cases, t.wall_s
    ));
    let mut lines = Vec::new();
    for (k, o) in OUTPUTS.iter().enumerate() {
        let top: Vec<String> = t
            .top3(k)
            .iter()
            .map(|(r, s)| format!("{} ({})", r.param.name(), show(o, Some(*s))))
            .collect();
        if !top.is_empty() {
            let unit = if o.unit.is_empty() {
                String::new()
            } else {
                format!(" {}", o.unit)
            };
            lines.push(format!(
                "{}: nominal {}{unit}; most sensitive to {} (spread of the output over the low, nominal and high value)",
                o.title,
                show(o, t.nominal.values[k]),
                top.join(", ")
            ));
        }
    }
    h.verdict("Outputs and the parameters that move them most", &lines);
    if t.nominal.lag_reliable == Some(false) {
        h.notice("The nominal case's Floquet lag mode is not resolved by the run (its residual is above 1% of its magnitude: the shooting subspace does not hold it to 1%); its lag damping ratio is not shown (report.html of the case, Floquet table).");
    }
    h.contents();
    for (k, o) in OUTPUTS.iter().enumerate() {
        output_section(&mut h, t, k, o);
    }
    parameter_tables(&mut h, t);
    h.paragraph(&format!(
        "Every case is a complete run folder under cases/ (cases/{NOMINAL}/ the nominal one); sweep.csv has one row per case, sensitivity.csv one per parameter (docs/formats.md)."
    ));
    h.finish()
}

/// The banner: failed cases, cases not periodic, or all well.
fn status_banners(h: &mut HtmlReport, t: &Sensitivity) {
    let failures = t.failures();
    let np = t.not_periodic();
    if !failures.is_empty() {
        h.banner(
            Banner::Bad,
            &format!(
                "NOT complete: {} case(s) failed or have not run: {} (their outputs are empty below; the reasons are under \"failed cases\")",
                failures.len(),
                failures
                    .iter()
                    .map(|(id, _)| id.as_str())
                    .collect::<Vec<_>>()
                    .join(", ")
            ),
        );
    } else if !np.is_empty() {
        h.banner(
            Banner::Bad,
            &format!(
                "NOT periodic: {} - their reported revolution is the best one, not a periodic solution",
                np.join(", ")
            ),
        );
    } else {
        h.banner(
            Banner::Ok,
            &format!("every case ran and is periodic ({} cases)", t.cases),
        );
    }
}

/// One output's tornado and ranking table.
fn output_section(h: &mut HtmlReport, t: &Sensitivity, k: usize, o: &OutputDef) {
    h.heading(2, o.title);
    match tornado(t, k) {
        None if o.multibody_only && t.model != "uh60a" => {
            h.paragraph(&format!(
                "Not available: the {} model does not give blade loads (the multibody model does: --model uh60a).",
                t.model
            ));
            return;
        }
        None => {
            h.paragraph("Not available from these runs (no nominal value, or no parameter case with a value).");
            return;
        }
        Some(Ok(svg)) => {
            h.svg(
                &format!(
                    "tornado: {} at the low and high value of each parameter, in % of the nominal value, largest spread at the top",
                    o.title
                ),
                &svg,
            );
        }
        Some(Err(e)) => {
            h.paragraph(&format!("not plotted: {e}"));
        }
    }
    let unit = if o.unit.is_empty() { "-" } else { o.unit };
    let rows: Vec<Vec<String>> = t
        .ranking(k)
        .iter()
        .enumerate()
        .map(|(n, &i)| {
            let r = &t.rows[i];
            let nom = t.nominal.values[k];
            vec![
                (n + 1).to_string(),
                r.param.name(),
                format!("{} .. {}", short(r.param.low), short(r.param.high)),
                show(o, r.low.values[k]),
                show(o, r.high.values[k]),
                pct(change(r.low.values[k], nom)),
                pct(change(r.high.values[k], nom)),
                match o.unit.is_empty() {
                    true => r.swing(k).map_or("-".into(), |s| format!("{s:+.4}")),
                    false => r.swing(k).map_or("-".into(), |s| format!("{s:+.0}")),
                },
            ]
        })
        .collect();
    let h_low = format!("output at low [{unit}]");
    let h_high = format!("output at high [{unit}]");
    let h_swing = format!("swing high - low [{unit}]");
    h.table(
        &[
            "rank",
            "parameter",
            "low .. high value",
            &h_low,
            &h_high,
            "change at low",
            "change at high",
            &h_swing,
        ],
        &rows,
    );
}

/// The parameters, the failed cases and the ASSUMED labels not varied.
fn parameter_tables(h: &mut HtmlReport, t: &Sensitivity) {
    let failures = t.failures();
    h.heading(2, "parameters");
    let rows: Vec<Vec<String>> = t
        .rows
        .iter()
        .map(|r| {
            let p = &r.param;
            vec![
                format!("{} [{}]", p.name(), p.unit()),
                short(p.target.nominal),
                short(p.low),
                short(p.high),
                p.range.clone(),
                p.source.clone(),
                format!("{} / {}", r.low.status, r.high.status),
            ]
        })
        .collect();
    h.table(
        &[
            "key [unit]",
            "nominal",
            "low",
            "high",
            "range",
            "source",
            "low / high case",
        ],
        &rows,
    );
    if !failures.is_empty() {
        h.heading(2, "failed cases");
        h.paragraph("A case that fails to run leaves its side of the parameter empty. Give the parameter a narrower range with --vary KEY=LOW:HIGH (into another output folder), or run the case alone with rotorsim run --set to see why.");
        let rows: Vec<Vec<String>> = failures
            .iter()
            .map(|(id, why)| vec![id.clone(), why.clone()])
            .collect();
        h.table(&["case", "why"], &rows);
    }
    h.heading(2, "ASSUMED labels not varied");
    if t.skipped.is_empty() {
        h.paragraph("None: every ASSUMED label of the deck gave a parameter.");
    } else {
        let rows: Vec<Vec<String>> = t
            .skipped
            .iter()
            .map(|s| {
                vec![
                    s.line.to_string(),
                    s.key.clone().unwrap_or_default(),
                    s.text.clone(),
                    s.reason.clone(),
                ]
            })
            .collect();
        h.table(&["deck line", "key", "text", "why not varied"], &rows);
    }
}

/// A parameter value in short form (6 significant digits; sensitivity.csv has every digit).
fn short(x: f64) -> String {
    let r: f64 = format!("{x:.5e}").parse().unwrap_or(x);
    crate::overrides::display(&toml::Value::Float(r))
}

/// Writes DIR/sensitivity.csv, DIR/sensitivity.html and DIR/summary.json, each atomically.
pub fn write(dir: &Path, t: &Sensitivity) -> anyhow::Result<()> {
    crate::io::write_atomic(&dir.join("sensitivity.csv"), csv(t)?.as_bytes())?;
    crate::io::write_atomic(&dir.join("sensitivity.html"), html(t).as_bytes())?;
    let s = serde_json::to_string_pretty(&summary(t))? + "\n";
    crate::io::write_atomic(&dir.join("summary.json"), s.as_bytes())?;
    Ok(())
}
