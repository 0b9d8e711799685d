//! DIR/result.mcap: the last revolution of each model, one JSON message per structural step on
//! topic `/run/<model>` (azimuth_deg and every channel, units in the key names), and the measured
//! damper force (revolution average) on `/run/measured`. All share one time axis:
//! log time = ((revs - 1) * 360 + azimuth_deg) / Omega[deg/s], in nanoseconds, so a viewer
//! overlays them. Channel metadata carries `synthetic` (the record's flag) and the model label.
use super::summary::Measured;
use super::ModelRun;
use ::mcap::records::MessageHeader;
use std::collections::BTreeMap;
use std::fmt::Write as _;

fn schema_json(title: &str, names: &[&str]) -> String {
    let mut props = String::new();
    for (i, n) in names.iter().enumerate() {
        if i > 0 {
            props.push_str(",\n    ");
        }
        let _ = write!(props, "\"{n}\": {{\"type\": \"number\"}}");
    }
    format!(
        "{{\n  \"$schema\": \"https://json-schema.org/draft/2020-12/schema\",\n  \"title\": \"{title}\",\n  \"description\": \"One sample of the last revolution of a rotorsim run; units in the key names; docs/formats.md sign conventions.\",\n  \"type\": \"object\",\n  \"properties\": {{\n    {props}\n  }}\n}}"
    )
}

fn message(names: &[&str], values: &[f64]) -> Vec<u8> {
    let mut m = serde_json::Map::new();
    for (n, v) in names.iter().zip(values) {
        // JSON has no NaN: a non-finite value is written as null.
        m.insert((*n).to_string(), serde_json::Value::from(*v));
    }
    serde_json::to_vec(&serde_json::Value::Object(m)).unwrap_or_default()
}

/// MCAP bytes of the runs' last revolutions (and the measurement, when there is one).
pub fn mcap_bytes(
    runs: &[&ModelRun],
    measured: Option<&Measured>,
    synthetic: bool,
) -> anyhow::Result<Vec<u8>> {
    let mut buf = std::io::Cursor::new(Vec::new());
    {
        let mut w = ::mcap::WriteOptions::new()
            .library(concat!("rotorsim/", env!("CARGO_PKG_VERSION")))
            .create(&mut buf)?;
        // (log time, channel, sequence, bytes), sorted by time before writing.
        let mut msgs: Vec<(u64, u16, u32, Vec<u8>)> = Vec::new();
        let mut rev_base_s = 0.0;
        let mut period_s = 0.0;
        for r in runs {
            let mut names: Vec<&str> = vec!["azimuth_deg"];
            names.extend(r.channel_names.iter().map(|s| s.as_str()));
            let title = format!("rotorsim.Run.{}", r.model);
            let s = w.add_schema(&title, "jsonschema", schema_json(&title, &names).as_bytes())?;
            let mut meta = BTreeMap::new();
            meta.insert("synthetic".to_string(), synthetic.to_string());
            meta.insert("label".to_string(), r.label.clone());
            let c = w.add_channel(s, &format!("/run/{}", r.model), "json", &meta)?;
            rev_base_s = (r.revolutions - 1) as f64 * r.period_s;
            period_s = r.period_s;
            let mut row = vec![0.0; names.len()];
            for (i, psi) in r.azimuth_deg.iter().enumerate() {
                row[0] = *psi;
                for (k, ch) in r.last_rev.iter().enumerate() {
                    row[k + 1] = ch[i];
                }
                let t = ((rev_base_s + psi / 360.0 * r.period_s) * 1e9).round() as u64;
                msgs.push((t, c, i as u32, message(&names, &row)));
            }
        }
        if let (Some(m), true) = (measured, period_s > 0.0) {
            let names = ["azimuth_deg", "damper_force_N"];
            let title = "rotorsim.Run.measured";
            let s = w.add_schema(title, "jsonschema", schema_json(title, &names).as_bytes())?;
            let mut meta = BTreeMap::new();
            meta.insert("synthetic".to_string(), m.synthetic.to_string());
            meta.insert(
                "label".to_string(),
                format!("measured, average of {} revolutions", m.revolutions),
            );
            let c = w.add_channel(s, "/run/measured", "json", &meta)?;
            for (i, (psi, f)) in m.azimuth_deg.iter().zip(&m.force_n).enumerate() {
                let t = ((rev_base_s + psi / 360.0 * period_s) * 1e9).round() as u64;
                msgs.push((t, c, i as u32, message(&names, &[*psi, *f])));
            }
        }
        msgs.sort_by_key(|m| (m.0, m.1));
        for (t, c, seq, bytes) in msgs {
            w.write_to_known_channel(
                &MessageHeader {
                    channel_id: c,
                    sequence: seq,
                    log_time: t,
                    publish_time: t,
                },
                &bytes,
            )?;
        }
        w.finish()?;
    }
    Ok(buf.into_inner())
}
