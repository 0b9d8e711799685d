//! Overrides of deck values by dotted path (`rotorsim run --set damper.physical.A_orf_m2=2.0e-6`,
//! sweep plans). An override is applied to the parsed TOML of a deck before the deck is
//! validated, so an overridden value is checked exactly like one written in the deck: an unknown
//! key or an out-of-range value is refused by the deck's own validation, and the error is
//! prefixed with the override that caused it.
use anyhow::{anyhow, bail};
use toml::{Table, Value};

/// One `KEY=VALUE` override.
#[derive(Clone, Debug, PartialEq)]
pub struct Override {
    /// Dotted path of the deck value, unit in the name (`damper.physical.A_orf_m2`).
    pub key: String,
    pub value: Value,
}

impl Override {
    /// Parses `KEY=VALUE`; VALUE is a TOML value (`2.0e-6`, `3`, `true`, `[1, 2]`,
    /// `"physical"`), or else taken as a bare string (`physical`).
    pub fn parse(s: &str) -> anyhow::Result<Self> {
        let (key, text) = s.split_once('=').ok_or_else(|| {
            anyhow!("--set {s}: expected KEY=VALUE (e.g. damper.physical.A_orf_m2=2.0e-6)")
        })?;
        let key = key.trim();
        check_key(key).map_err(|e| anyhow!("--set {s}: {e}"))?;
        Ok(Override {
            key: key.to_string(),
            value: parse_value(text.trim()),
        })
    }

    /// The value as TOML text.
    pub fn value_text(&self) -> String {
        self.value.to_string()
    }

    /// Whether the override addresses the `[damper]` table.
    pub fn is_damper(&self) -> bool {
        self.key == "damper" || self.key.starts_with("damper.")
    }
}

impl std::fmt::Display for Override {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{}={}", self.key, self.value)
    }
}

/// A dotted key: non-empty parts of letters, digits, `_` and `-`.
pub fn check_key(key: &str) -> anyhow::Result<()> {
    if key.is_empty()
        || key.split('.').any(|p| {
            p.is_empty()
                || !p
                    .chars()
                    .all(|c| c.is_ascii_alphanumeric() || c == '_' || c == '-')
        })
    {
        bail!("`{key}` is not a dotted deck key (expected e.g. damper.physical.A_orf_m2)");
    }
    Ok(())
}

/// A TOML value, or the text itself as a string when it is not one.
pub fn parse_value(text: &str) -> Value {
    format!("v = {text}")
        .parse::<Table>()
        .ok()
        .and_then(|mut t| t.remove("v"))
        .unwrap_or_else(|| Value::String(text.to_string()))
}

/// A value as plain text for tables and messages (strings unquoted).
pub fn display(v: &Value) -> String {
    match v {
        Value::String(s) => s.clone(),
        // shortest text that reads back to the same number, in exponent form when small or large
        Value::Float(x) if *x != 0.0 && (x.abs() < 1e-3 || x.abs() >= 1e6) => format!("{x:e}"),
        Value::Float(x) => format!("{x:?}"),
        v => v.to_string(),
    }
}

fn type_name(v: &Value) -> &'static str {
    match v {
        Value::String(_) => "a string",
        Value::Integer(_) => "an integer",
        Value::Float(_) => "a number",
        Value::Boolean(_) => "a boolean",
        Value::Datetime(_) => "a date-time",
        Value::Array(_) => "an array",
        Value::Table(_) => "a table",
    }
}

/// Sets `ov` in `root`. A value already in the deck keeps its type (an integer where the deck has
/// a number is taken as that number); a key the deck does not hold is added and left to the
/// deck's validation, which refuses unknown keys.
pub fn apply(root: &mut Table, ov: &Override) -> anyhow::Result<()> {
    let parts: Vec<&str> = ov.key.split('.').collect();
    let (leaf, path) = parts.split_last().ok_or_else(|| anyhow!("empty key"))?;
    let mut t = root;
    for (i, p) in path.iter().enumerate() {
        let entry = t
            .entry(p.to_string())
            .or_insert_with(|| Value::Table(Table::new()));
        t = match entry {
            Value::Table(sub) => sub,
            other => bail!(
                "`{}` is {} in the deck, not a table",
                parts[..=i].join("."),
                type_name(other)
            ),
        };
    }
    let new = match (t.get(*leaf), &ov.value) {
        (None, v) => v.clone(),
        (Some(Value::Float(_)), Value::Integer(i)) => Value::Float(*i as f64),
        (Some(Value::Table(_)), _) => {
            bail!("is a table in the deck: set its keys one by one")
        }
        (Some(old), v) if std::mem::discriminant(old) == std::mem::discriminant(v) => v.clone(),
        (Some(old), v) => bail!(
            "expected {} (the deck has {old}), found {} `{v}`",
            type_name(old),
            type_name(v)
        ),
    };
    t.insert(leaf.to_string(), new);
    Ok(())
}

/// Applies `overrides` to the parsed deck `root` one after the other, validating the deck with
/// `validate` after each (after the last of consecutive keys of one table), and returns the
/// edited tables. An error names the override (`--set KEY=VALUE: ...`) followed by the deck's
/// own message, which names the file and the key.
pub fn apply_all(
    mut root: Table,
    file: &str,
    overrides: &[Override],
    validate: impl Fn(&Table, &Override) -> anyhow::Result<()>,
) -> anyhow::Result<Table> {
    let table = |k: &str| k.rsplit_once('.').map(|(t, _)| t.to_string());
    for (i, ov) in overrides.iter().enumerate() {
        apply(&mut root, ov).map_err(|e| anyhow!("--set {ov}: deck {file}, {}: {e}", ov.key))?;
        // a table built key by key (`--set airframe.x.mass_kg=... --set
        // airframe.x.stiffness_N_per_m=...`) is checked once its next key is set
        let completed_later = table(&ov.key).is_some_and(|t| {
            overrides[i + 1..]
                .iter()
                .any(|o| table(&o.key).as_deref() == Some(t.as_str()))
        });
        if let Err(e) = validate(&root, ov) {
            if !completed_later {
                return Err(anyhow!("--set {ov}: {e:#}"));
            }
        }
    }
    Ok(root)
}

/// The deck text `text` parsed, an error naming `file`.
pub fn parse_deck(text: &str, file: &str) -> anyhow::Result<Table> {
    text.parse()
        .map_err(|e: toml::de::Error| anyhow!("deck {file}: {}", e.to_string().trim_end()))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn values_and_types() {
        let ov = Override::parse("damper.physical.A_orf_m2=2.0e-6").unwrap();
        assert_eq!(ov.value, Value::Float(2.0e-6));
        assert_eq!(
            Override::parse("damper.model=physical").unwrap().value,
            Value::String("physical".into())
        );
        assert!(Override::parse("damper.physical.A_orf_m2").is_err());
        assert!(Override::parse("a..b=1").is_err());
        let mut t: Table = "[a]\nx = 1.5\nn = 2\ns = \"q\"".parse().unwrap();
        apply(&mut t, &Override::parse("a.x=3").unwrap()).unwrap();
        assert_eq!(t["a"]["x"], Value::Float(3.0));
        assert!(apply(&mut t, &Override::parse("a.n=2.5").unwrap()).is_err());
        assert!(apply(&mut t, &Override::parse("a.s=2.5").unwrap()).is_err());
        assert!(apply(&mut t, &Override::parse("a.x.y=1").unwrap()).is_err());
        assert!(apply(&mut t, &Override::parse("a=1").unwrap()).is_err());
        apply(&mut t, &Override::parse("a.new_m=1").unwrap()).unwrap();
    }
}
