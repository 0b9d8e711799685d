//! What every job's settings type shares: a job's options are one type (clap for the command
//! line, serde for sweep plans and the Python package's keywords), its defaults those of the
//! command line (docs/architecture.md, "Adding an option to a job").
use anyhow::anyhow;

/// A job's options but its result folder, as given. Implementors derive `clap::Args` and serde
/// (`#[serde(default, deny_unknown_fields)]`) and take `Default` from [`command_line_defaults`].
pub trait JobSettings:
    clap::Args + clap::FromArgMatches + serde::Serialize + serde::de::DeserializeOwned + Default
{
    /// The command's name, for messages (`stability options: ...`).
    const COMMAND: &'static str;

    /// Settings given as a JSON object of fields (the Python package's keyword arguments),
    /// every other the default; an unknown name or a wrong type is an error naming it.
    fn from_json(text: &str) -> anyhow::Result<Self> {
        serde_json::from_str(text).map_err(|e| anyhow!("{} options: {e}", Self::COMMAND))
    }

    /// The settings' names with their default values (JSON): what the command line, the
    /// Python package and (for some) a sweep plan accept.
    fn defaults_map() -> serde_json::Map<String, serde_json::Value> {
        serde_json::to_value(Self::default())
            .ok()
            .and_then(|v| v.as_object().cloned())
            .unwrap_or_default()
    }

    /// [`JobSettings::defaults_map`] as JSON text.
    fn defaults_json() -> String {
        serde_json::Value::Object(Self::defaults_map()).to_string()
    }
}

/// The command line's defaults of `T`: no option given, parsed (the `#[arg]`s are the only list).
/// Options the command requires have none: they stay unset (`None`) here.
pub fn command_line_defaults<T: clap::Args + clap::FromArgMatches>(name: &'static str) -> T {
    let cmd = T::augment_args(clap::Command::new(name))
        .mut_args(|a| a.required(false))
        // a required-unless or conflict rule cannot hold without options: not an error here
        .ignore_errors(true);
    cmd.try_get_matches_from([name])
        .and_then(|m| T::from_arg_matches(&m))
        .unwrap_or_else(|e| unreachable!("{name} without options: {e}"))
}

/// A required option's value, or an error naming it (a JSON or plan key left out).
pub fn required<'a, T>(value: &'a Option<T>, flag: &str, expected: &str) -> anyhow::Result<&'a T> {
    value
        .as_ref()
        .ok_or_else(|| anyhow!("{flag}: expected {expected} (the option is required)"))
}
