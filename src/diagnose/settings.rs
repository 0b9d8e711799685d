//! `rotorsim diagnose`'s options, defined once: [`DiagnoseSettings`] is read by the command line
//! (clap) and by the Python package (serde, its keyword arguments as one JSON object), and
//! turned into the pipeline's [`Config`] by [`DiagnoseSettings::job`].
use super::pipeline::Config;
use anyhow::anyhow;
use std::path::PathBuf;

/// Every option of `rotorsim diagnose` but its result folder, as given: each field's doc comment
/// is its `--help` text and its `#[arg]` its default.
#[derive(clap::Args, serde::Serialize, serde::Deserialize, Clone, Debug, PartialEq)]
#[serde(default, deny_unknown_fields)]
pub struct DiagnoseSettings {
    /// Damper deck of the baseline model (any TOML file with a [damper] table).
    #[arg(long, alias = "deck", value_name = "DECK")]
    pub damper_deck: Option<PathBuf>,
    /// Measured bench test(s) (bench CSV of docs/formats.md, with force).
    #[arg(long)]
    pub measured: Vec<PathBuf>,
    /// Rotor deck (flight-record diagnosis; its [damper] table is the baseline unless --damper-deck).
    #[arg(long)]
    pub rotor: Option<PathBuf>,
    /// Flight record (MCAP file or CSV stem, e.g. flightdata/c8534like).
    #[arg(long)]
    pub flight: Option<PathBuf>,
    /// Write the extended model as a damper deck.
    #[arg(long)]
    pub write_deck: Option<PathBuf>,
    /// Cycles simulated per fit test (the first settles the model).
    #[arg(long, default_value_t = 3)]
    pub fit_cycles: usize,
    /// Largest RK4 sub-step of the hydraulic model [s].
    #[arg(long, default_value_t = 3.0e-5)]
    pub max_substep: f64,
    /// Flight record without damper stroke: revolutions of the rotor run (physical damper,
    /// baseline deck) whose last, periodic revolution gives the simulated stroke.
    #[arg(long, default_value_t = 40)]
    pub revs: usize,
    /// Rotor runs (simulated stroke, --rotor-check): structural steps per revolution.
    #[arg(long, default_value_t = 256)]
    pub steps_per_rev: usize,
    /// Rotor runs (simulated stroke, --rotor-check): hydraulic RK4 sub-steps per structural step.
    #[arg(long, default_value_t = 25)]
    pub substeps: usize,
    /// Flight records: also run the rotor (--rotor must be a rotor deck) with the physical
    /// damper of the baseline deck and of the extended deck, in parallel, and compare both with
    /// the record's damper force (the rotor-level before/after; DIR/rotor_check/).
    #[arg(long)]
    pub rotor_check: bool,
    /// Revolutions of each rotor run of --rotor-check (as `rotorsim run --revs`).
    #[arg(long, default_value_t = 75)]
    pub check_revs: usize,
    /// Rotor model of the rotor runs: uh60a (the multibody model of the rotor deck) or rigid
    /// (its rigid-blade reduction, as `rotorsim run --model rigid`; seconds instead of minutes).
    #[arg(
        long,
        alias = "rotor-model",
        value_name = "ROTOR_MODEL",
        default_value = "uh60a"
    )]
    pub model: String,
}

impl Default for DiagnoseSettings {
    /// The command line's defaults: no option given, parsed (the `#[arg]`s are the only list).
    fn default() -> Self {
        use clap::{Args, FromArgMatches};
        let m = Self::augment_args(clap::Command::new("diagnose")).get_matches_from(["diagnose"]);
        Self::from_arg_matches(&m).unwrap_or_else(|e| unreachable!("diagnose without options: {e}"))
    }
}

impl DiagnoseSettings {
    /// The diagnosis these settings ask for into `out` (checked when it runs,
    /// [`Config::check`]).
    pub fn job(&self, out: impl Into<PathBuf>) -> Config {
        Config {
            deck: self.damper_deck.clone(),
            measured: self.measured.clone(),
            rotor: self.rotor.clone(),
            flight: self.flight.clone(),
            out: out.into(),
            write_deck: self.write_deck.clone(),
            fit_cycles: self.fit_cycles,
            max_substep: self.max_substep,
            revs: self.revs,
            steps_per_rev: self.steps_per_rev,
            substeps: self.substeps,
            rotor_check: self.rotor_check,
            check_revs: self.check_revs,
            rotor_model: self.model.clone(),
        }
    }

    /// Settings given as a JSON object of fields (the Python package's keyword arguments),
    /// every other the default; an unknown name or a wrong type is an error naming it.
    pub fn from_json(text: &str) -> anyhow::Result<Self> {
        serde_json::from_str(text).map_err(|e| anyhow!("diagnose options: {e}"))
    }

    /// [`DiagnoseSettings::defaults_map`] as JSON text.
    pub fn defaults_json() -> String {
        serde_json::Value::Object(Self::defaults_map()).to_string()
    }

    /// The settings' names with their default values (JSON).
    pub fn defaults_map() -> serde_json::Map<String, serde_json::Value> {
        serde_json::to_value(Self::default())
            .ok()
            .and_then(|v| v.as_object().cloned())
            .unwrap_or_default()
    }
}
