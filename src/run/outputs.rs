//! The outputs of a rotor run, as `rotorsim run` writes them (summary.json, each model's
//! last_rev.csv, report.html, result.mcap); also those of the diagnosis' rotor-level runs.
use crate::io::OutDir;
use crate::run::summary::{self, Measured, ModelFigures, RunInfo};
use crate::run::{self, ModelOutcome};

/// What [`write_outputs`] reports back.
pub struct Written {
    /// The failures ("model: error").
    pub failed: Vec<String>,
    /// Which model comes closest to the measured force, and by how much (None without one).
    pub verdict: Option<String>,
}

/// Writes every output.
pub fn write_outputs(
    out: &OutDir,
    info: &RunInfo,
    outcomes: &[ModelOutcome],
    measured: &Result<Measured, String>,
) -> anyhow::Result<Written> {
    let meas = measured.as_ref().ok();
    let figs: Vec<Option<Result<ModelFigures, String>>> = outcomes
        .iter()
        .map(|o| {
            o.result
                .as_ref()
                .ok()
                .map(|r| summary::figures(r, meas).map_err(|e| format!("{e:#}")))
        })
        .collect();
    let mut failed = Vec::new();
    for (o, f) in outcomes.iter().zip(&figs) {
        match (&o.result, f) {
            (Err(e), _) | (Ok(_), Some(Err(e))) => failed.push(format!("{}: {e}", o.model.name())),
            (Ok(r), _) => {
                summary::write_last_rev(out, r, meas)?;
                if !r.all_revs.is_empty() {
                    summary::write_all_revs(out, r)?;
                }
                summary::write_periodic_state(out, r, info)?;
                // a whole rotor: every blade's folder (the record's damper is blade 1's)
                for b in &r.blade_runs {
                    let m = if b.blade == Some(1) { meas } else { None };
                    summary::write_last_rev(out, b, m)?;
                    if !b.all_revs.is_empty() {
                        summary::write_all_revs(out, b)?;
                    }
                    summary::write_periodic_state(out, b, info)?;
                }
            }
        }
    }
    let metrics: Vec<(String, &crate::analysis::compare::Metrics)> = outcomes
        .iter()
        .zip(&figs)
        .filter_map(|(o, f)| {
            let m = f.as_ref()?.as_ref().ok()?.metrics.as_ref()?;
            Some((o.model.name().to_string(), m))
        })
        .collect();
    let rank = summary::ranking(&metrics);
    let mut json = summary::summary_json(info, outcomes, &figs, measured, rank.as_ref());
    if let (Some(j), serde_json::Value::Object(p)) = (json.as_object_mut(), out.provenance()) {
        j.extend(p);
    }
    out.write(
        "summary.json",
        serde_json::to_string_pretty(&json)?.as_bytes(),
    )?;
    let html = run::report::report_html(info, outcomes, &figs, measured, rank.as_ref());
    out.write("report.html", html.as_bytes())?;
    let ok: Vec<&run::ModelRun> = outcomes
        .iter()
        .filter_map(|o| o.result.as_ref().ok())
        .collect();
    let mcap = run::mcap_out::mcap_bytes(&ok, meas, info.synthetic)?;
    out.write("result.mcap", &mcap)?;
    Ok(Written {
        failed,
        verdict: rank.map(|r| r.statement),
    })
}
