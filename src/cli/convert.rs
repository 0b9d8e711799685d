//! `rotorsim convert IN OUT`: flight record CSV triple <-> MCAP, without loss.
use crate::flight::FlightRecord;
use clap::Args;
use std::path::PathBuf;

#[derive(Args, Debug)]
pub struct ConvertArgs {
    /// Input record: an .mcap file, a CSV stem (flightdata/c8534like) or one of its files.
    pub input: PathBuf,
    /// Output: a path ending in .mcap writes MCAP; anything else is the stem of a CSV triple
    /// (STEM.meta.json, STEM.airloads.csv, STEM.damper.csv, and STEM.motion.csv for a record
    /// with a measured blade motion).
    pub output: PathBuf,
}

pub fn run(args: ConvertArgs) -> anyhow::Result<()> {
    // The error names the file, line or channel already.
    let rec = FlightRecord::read(&args.input)?;
    let out = args.output.to_string_lossy().into_owned();
    let label = if rec.meta.synthetic {
        " [SYNTHETIC (not flight-test data)]"
    } else {
        ""
    };
    if out.ends_with(".mcap") {
        rec.write_mcap(&args.output)?;
        outln!("wrote {out}{label}");
    } else {
        let stem = crate::flight::record::CSV_SUFFIXES
            .iter()
            .chain(&crate::flight::record::CSV_OPTIONAL_SUFFIXES)
            .find_map(|s| out.strip_suffix(s))
            .unwrap_or(&out)
            .to_string();
        rec.write_csv(std::path::Path::new(&stem))?;
        let motion = if rec.motion.is_some() {
            format!(", {stem}.motion.csv")
        } else {
            String::new()
        };
        outln!("wrote {stem}.meta.json, {stem}.airloads.csv, {stem}.damper.csv{motion}{label}");
    }
    Ok(())
}
