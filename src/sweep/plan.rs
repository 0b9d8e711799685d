//! Sweep plans (docs/sweep.md): `[base]` run options and deck values, `[vary]` lists whose
//! product is swept, `[[case]]` explicit cases, `[sweep]` scheduling. Parsing checks the plan's
//! own structure and the types of run options; deck values and records are checked case by case
//! by the caller before any case runs.
use crate::overrides::{check_key, Override};
use crate::resonance::StabilitySettings;
use crate::run::job::RunSettings;
use crate::run::settings::JobSettings;
use anyhow::{anyhow, bail};
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;
use std::path::Path;
use toml::{Table, Value};

/// Run options a plan may not set: the sweep decides the folder and the warm start, and deck
/// values are the plan's dotted keys (not `set`).
pub const NOT_PLAN_OPTIONS: &[&str] = &["out", "initial_state", "set"];

/// A plan key that is no run option: a ground-resonance map instead of a run (`rotorsim
/// stability --speeds`).
pub const STABILITY_SPEEDS: &str = "stability_speeds";

/// The keys of a stability case: [`STABILITY_SPEEDS`], then every [`StabilitySettings`] field
/// but `speeds` (that key) and `set` (deck values are the plan's dotted keys).
pub fn stability_options() -> Vec<String> {
    let mut v = vec![STABILITY_SPEEDS.to_string()];
    v.extend(
        StabilitySettings::defaults_map()
            .into_iter()
            .map(|(k, _)| k)
            .filter(|k| k != "speeds" && k != "set"),
    );
    v
}

/// Options a plan may set (every [`RunSettings`] field but [`NOT_PLAN_OPTIONS`], then
/// [`STABILITY_SPEEDS`] and the other options of a stability case), with the type each takes,
/// read from the settings' defaults.
pub fn run_options() -> Vec<(String, OptionType)> {
    let mut v: Vec<(String, OptionType)> = RunSettings::defaults_map()
        .into_iter()
        .filter(|(k, _)| !NOT_PLAN_OPTIONS.contains(&k.as_str()))
        .map(|(k, d)| {
            let ty = match d {
                serde_json::Value::Bool(_) => OptionType::Flag,
                serde_json::Value::Number(n) if n.is_u64() => OptionType::Count,
                serde_json::Value::Number(_) => OptionType::Number,
                _ => OptionType::Text,
            };
            (k, ty)
        })
        .collect();
    v.push((STABILITY_SPEEDS.to_string(), OptionType::Text));
    for k in stability_options() {
        if !v.iter().any(|(n, _)| *n == k) {
            v.push((k, OptionType::Any));
        }
    }
    v
}

/// Cases a plan may hold. Each case is a run of seconds at least, its settings and its folder
/// kept for the whole sweep: beyond a million cases a plan is a typo (one list too many, a
/// range written out too finely), and expanding it would take the machine's memory.
pub const MAX_CASES: u64 = 1_000_000;

/// Options that decide the state vector of a case: a case starts from a neighbour's periodic
/// state only when all of these agree.
pub const STATE_OPTIONS: &[&str] = &[
    "rotor",
    "flight",
    "model",
    "damper",
    "damper_deck",
    "steps_per_rev",
];

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum OptionType {
    Text,
    Count,
    Number,
    Flag,
    /// A stability case's option: its type checked when the case is read.
    Any,
}

impl OptionType {
    fn expected(self) -> &'static str {
        match self {
            OptionType::Text => "a string",
            OptionType::Count => "a positive integer",
            OptionType::Number => "a positive number",
            OptionType::Flag => "true or false",
            OptionType::Any => "a value",
        }
    }
    fn check(self, v: &Value) -> bool {
        match (self, v) {
            (OptionType::Text, Value::String(_)) => true,
            (OptionType::Count, Value::Integer(i)) => *i > 0,
            (OptionType::Number, Value::Float(x)) => x.is_finite() && *x > 0.0,
            (OptionType::Number, Value::Integer(i)) => *i > 0,
            (OptionType::Flag, Value::Boolean(_)) => true,
            (OptionType::Any, v) => !matches!(v, Value::Table(_)),
            _ => false,
        }
    }
}

/// One case: its id (its folder under `DIR/cases/`) and every setting (base, varied and case
/// values merged; deck keys are dotted, run options plain).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Case {
    pub id: String,
    pub settings: BTreeMap<String, Value>,
}

impl Case {
    /// A run option's value as text (None: the run's default).
    pub fn option(&self, name: &str) -> Option<&Value> {
        self.settings.get(name)
    }
    /// The deck overrides of the case, in key order.
    pub fn overrides(&self) -> Vec<Override> {
        self.settings
            .iter()
            .filter(|(k, _)| k.contains('.'))
            .map(|(k, v)| Override {
                key: k.clone(),
                value: v.clone(),
            })
            .collect()
    }
    /// Whether a periodic state of `other` can start this case.
    pub fn state_compatible(&self, other: &Case) -> bool {
        STATE_OPTIONS
            .iter()
            .all(|k| self.settings.get(*k) == other.settings.get(*k))
    }
}

/// A parsed plan.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Plan {
    /// The plan file, for messages.
    pub file: String,
    /// Keys shown as columns of sweep.csv: the `[vary]` keys, then the keys `[[case]]` tables
    /// set, in order of appearance.
    pub keys: Vec<String>,
    pub cases: Vec<Case>,
    /// Warm starts (`[sweep] warm_start`, default true) and the cases per warm-start group
    /// (`[sweep] group_size`, default 4).
    pub warm_start: bool,
    pub group_size: usize,
}

/// A value as plain text for tables and messages (strings unquoted).
pub fn display(v: &Value) -> String {
    crate::overrides::display(v)
}

impl Plan {
    pub fn from_file(path: &Path) -> anyhow::Result<Self> {
        let file = path.display().to_string();
        let text = std::fs::read_to_string(path)
            .map_err(|e| anyhow!("sweep plan {file}: cannot read: {e}"))?;
        Self::parse(&text, &file)
    }

    pub fn parse(text: &str, file: &str) -> anyhow::Result<Self> {
        let root: Table = text.parse().map_err(|e: toml::de::Error| {
            anyhow!("sweep plan {file}: {}", e.to_string().trim_end())
        })?;
        let bad = |key: &str, msg: String| anyhow!("sweep plan {file}, {key}: {msg}");
        for k in root.keys() {
            if !["base", "vary", "case", "sweep"].contains(&k.as_str()) {
                return Err(bad(
                    k,
                    "unknown table, expected [base], [vary], [[case]] or [sweep]".into(),
                ));
            }
        }
        let table = |name: &str| -> anyhow::Result<Option<&Table>> {
            match root.get(name) {
                None => Ok(None),
                Some(Value::Table(t)) => Ok(Some(t)),
                Some(v) => Err(bad(name, format!("expected a table, found {v}"))),
            }
        };
        let options = run_options();
        let check_setting =
            |where_: &str, k: &str, v: &Value| check_setting(file, &options, where_, k, v);
        let mut base = BTreeMap::new();
        if let Some(t) = table("base")? {
            for (k, v) in t {
                check_setting("[base]", k, v)?;
                base.insert(k.clone(), v.clone());
            }
        }
        let mut keys: Vec<String> = Vec::new();
        let mut axes: Vec<(String, Vec<Value>)> = Vec::new();
        if let Some(t) = table("vary")? {
            if t.is_empty() {
                return Err(bad(
                    "[vary]",
                    "empty: expected at least one key with a list of values".into(),
                ));
            }
            for (k, v) in t {
                let list = match v {
                    Value::Array(a) if !a.is_empty() => a.clone(),
                    Value::Array(_) => {
                        return Err(bad(
                            &format!("[vary] \"{k}\""),
                            "empty list: expected at least one value".into(),
                        ))
                    }
                    v => {
                        return Err(bad(
                            &format!("[vary] \"{k}\""),
                            format!("expected a list of values, found {v}"),
                        ))
                    }
                };
                for x in &list {
                    check_setting("[vary]", k, x)?;
                }
                keys.push(k.clone());
                axes.push((k.clone(), list));
            }
        }
        // counted before anything is expanded: a product of a few lists grows beyond memory
        let n_explicit = match root.get("case") {
            Some(Value::Array(list)) => list.len() as u64,
            _ => 0,
        };
        let product = case_count(file, &axes, n_explicit)?;
        let mut cases = Vec::new();
        if !axes.is_empty() {
            let total = product as usize;
            for i in 0..total {
                let mut s = base.clone();
                let mut rem = i;
                for (k, list) in axes.iter().rev() {
                    s.insert(k.clone(), list[rem % list.len()].clone());
                    rem /= list.len();
                }
                cases.push((None, s));
            }
        }
        if let Some(v) = root.get("case") {
            explicit_cases(v, &base, &mut keys, &mut cases, &check_setting, &bad)?;
        }
        if cases.is_empty() {
            return Err(bad(
                "[vary]",
                "missing: expected a [vary] table or [[case]] tables (a plan sweeps at least one case)".into(),
            ));
        }
        let sweep = match table("sweep")? {
            Some(t) => sweep_options(t, file)?,
            None => (true, 4usize),
        };
        let width = cases.len().to_string().len().max(3);
        let cases: Vec<Case> = cases
            .into_iter()
            .enumerate()
            .map(|(i, (id, settings))| Case {
                id: id.unwrap_or_else(|| format!("c{:0width$}", i + 1)),
                settings,
            })
            .collect();
        let mut ids: Vec<&str> = cases.iter().map(|c| c.id.as_str()).collect();
        ids.sort_unstable();
        if let Some(w) = ids.windows(2).find(|w| w[0] == w[1]) {
            return Err(bad(
                "[[case]] \"id\"",
                format!("two cases share the id `{}`", w[0]),
            ));
        }
        Ok(Plan {
            file: file.to_string(),
            keys,
            cases,
            warm_start: sweep.0,
            group_size: sweep.1,
        })
    }

    /// The varied values of `case` as text, one per [`Plan::keys`] (empty: the deck's or the
    /// run's default).
    pub fn varied(&self, case: &Case) -> Vec<String> {
        self.keys
            .iter()
            .map(|k| case.settings.get(k).map(display).unwrap_or_default())
            .collect()
    }

    /// Warm-start groups: consecutive cases, `group_size` at a time; the middle case of each
    /// group (its seed) starts cold, the others from the seed's periodic state when their
    /// state options agree. Depends on the plan only, so a case's result does not depend on
    /// how the sweep is scheduled or sharded.
    pub fn groups(&self) -> Vec<Group> {
        let n = if self.warm_start { self.group_size } else { 1 };
        (0..self.cases.len())
            .collect::<Vec<_>>()
            .chunks(n)
            .map(|c| {
                let seed = c[c.len() / 2];
                Group {
                    seed,
                    members: c
                        .iter()
                        .copied()
                        .filter(|&i| i != seed)
                        .map(|i| {
                            let warm = self.cases[i].state_compatible(&self.cases[seed]);
                            (i, warm)
                        })
                        .collect(),
                }
            })
            .collect()
    }
}

/// A warm-start group: its seed case and the other members (index, whether it starts from the
/// seed's state).
#[derive(Clone, Debug, PartialEq)]
pub struct Group {
    pub seed: usize,
    pub members: Vec<(usize, bool)>,
}

fn valid_id(s: &str) -> bool {
    !s.is_empty()
        && s != "."
        && s != ".."
        && !s.starts_with('.')
        && s.chars()
            .all(|c| c.is_ascii_alphanumeric() || c == '-' || c == '_' || c == '.')
}

/// `K/N`: shard K (0-based) of N.
pub fn parse_shard(s: &str) -> anyhow::Result<(usize, usize)> {
    let (k, n) = s
        .split_once('/')
        .ok_or_else(|| anyhow!("--shard {s}: expected K/N (shard K of N, K from 0 to N-1)"))?;
    let k: usize = k
        .trim()
        .parse()
        .map_err(|_| anyhow!("--shard {s}: K is not a whole number"))?;
    let n: usize = n
        .trim()
        .parse()
        .map_err(|_| anyhow!("--shard {s}: N is not a whole number"))?;
    if n == 0 || k >= n {
        bail!("--shard {s}: expected 0 <= K < N");
    }
    Ok((k, n))
}

/// A plan's setting `k = v` (in `where_`): a run option of the right type or a dotted deck key.
fn check_setting(
    file: &str,
    options: &[(String, OptionType)],
    where_: &str,
    k: &str,
    v: &Value,
) -> anyhow::Result<()> {
    let bad = |key: &str, msg: String| anyhow!("sweep plan {file}, {key}: {msg}");
    let key = format!("{where_} \"{k}\"");
    if k.contains('.') {
        check_key(k).map_err(|e| bad(&key, format!("{e}")))?;
        if matches!(v, Value::Table(_)) {
            return Err(bad(&key, "expected a deck value, found a table".into()));
        }
        return Ok(());
    }
    match options.iter().find(|(n, _)| n == k) {
        Some((_, ty)) if ty.check(v) => Ok(()),
        Some((_, ty)) => Err(bad(&key, format!("expected {}, found {v}", ty.expected()))),
        None if k == "out" || k == "initial_state" => Err(bad(
            &key,
            "set by the sweep (each case's folder, the warm start), not by the plan"
                .into(),
        )),
        None if k == "set" => Err(bad(
            &key,
            "a plan sets deck values by their dotted keys (e.g. \"damper.physical.A_orf_m2\" = 2.0e-6), not by `set`".into(),
        )),
        None => Err(bad(
            &key,
            format!(
                "unknown key: expected a run option ({}) or a dotted deck key with its unit (e.g. damper.physical.A_orf_m2)",
                options.iter().map(|o| o.0.as_str()).collect::<Vec<_>>().join(", ")
            ),
        )),
    }
}

/// The `[[case]]` tables, each `base` with its own settings; their keys join `keys`.
#[allow(clippy::type_complexity)]
fn explicit_cases(
    v: &Value,
    base: &BTreeMap<String, Value>,
    keys: &mut Vec<String>,
    cases: &mut Vec<(Option<String>, BTreeMap<String, Value>)>,
    check_setting: &dyn Fn(&str, &str, &Value) -> anyhow::Result<()>,
    bad: &dyn Fn(&str, String) -> anyhow::Error,
) -> anyhow::Result<()> {
    let Value::Array(list) = v else {
        return Err(bad("case", format!("expected [[case]] tables, found {v}")));
    };
    for (n, c) in list.iter().enumerate() {
        let where_ = format!("[[case]] {}", n + 1);
        let Value::Table(t) = c else {
            return Err(bad(&where_, "expected a table".into()));
        };
        let mut s = base.clone();
        let mut id = None;
        for (k, v) in t {
            if k == "id" {
                match v {
                    Value::String(x) if valid_id(x) => id = Some(x.clone()),
                    v => {
                        return Err(bad(
                            &format!("{where_} \"id\""),
                            format!("expected a folder name of letters, digits, '-', '_' and '.', found {v}"),
                        ))
                    }
                }
                continue;
            }
            check_setting(&where_, k, v)?;
            if !keys.contains(k) {
                keys.push(k.clone());
            }
            s.insert(k.clone(), v.clone());
        }
        cases.push((id, s));
    }
    Ok(())
}

/// The number of cases the product of the `[vary]` lists gives, refused beyond [`MAX_CASES`]
/// with the `[[case]]` tables counted.
fn case_count(file: &str, axes: &[(String, Vec<Value>)], n_explicit: u64) -> anyhow::Result<u64> {
    let product = if axes.is_empty() {
        0
    } else {
        axes.iter()
            .fold(1u64, |n, a| n.saturating_mul(a.1.len() as u64))
    };
    let count = product.saturating_add(n_explicit);
    if count > MAX_CASES {
        let shown = if count == u64::MAX {
            "more than 1.8e19".to_string()
        } else {
            count.to_string()
        };
        return Err(anyhow!(
            "sweep plan {file}: {shown} cases ([vary] {} = {product}{}), beyond the {MAX_CASES} a sweep may hold; vary fewer keys or fewer values per key, or split the plan into several plans",
            axes.iter()
                .map(|(k, l)| format!("\"{k}\" {}", l.len()))
                .collect::<Vec<_>>()
                .join(" x "),
            if n_explicit > 0 {
                format!(", plus {n_explicit} [[case]] tables")
            } else {
                String::new()
            }
        ));
    }
    Ok(product)
}

/// The `[sweep]` table: (warm_start, group_size).
fn sweep_options(t: &Table, file: &str) -> anyhow::Result<(bool, usize)> {
    let bad = |key: &str, msg: String| anyhow!("sweep plan {file}, {key}: {msg}");
    let mut sweep = (true, 4usize);
    for (k, v) in t {
        match (k.as_str(), v) {
            ("warm_start", Value::Boolean(b)) => sweep.0 = *b,
            ("group_size", Value::Integer(n)) if *n >= 1 => sweep.1 = *n as usize,
            ("warm_start", v) => {
                return Err(bad(
                    "[sweep] warm_start",
                    format!("expected true or false, found {v}"),
                ))
            }
            ("group_size", v) => {
                return Err(bad(
                    "[sweep] group_size",
                    format!("expected a positive integer, found {v}"),
                ))
            }
            (k, _) => {
                return Err(bad(
                    &format!("[sweep] {k}"),
                    "unknown key, expected warm_start or group_size".into(),
                ))
            }
        }
    }
    Ok(sweep)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn product_and_cases() {
        let p = Plan::parse(
            "[base]\nmodel = \"rigid\"\n[vary]\n\"damper.physical.A_orf_m2\" = [1.6e-6, 2.0e-6]\nrevs = [10, 20, 30]\n[[case]]\nid = \"extra\"\nsubsteps = 5\n",
            "p.toml",
        )
        .unwrap();
        assert_eq!(p.cases.len(), 7);
        assert_eq!(p.cases[0].id, "c001");
        assert_eq!(p.cases[1].settings["revs"], Value::Integer(20));
        assert_eq!(
            p.cases[3].settings["damper.physical.A_orf_m2"],
            Value::Float(2.0e-6)
        );
        assert_eq!(p.cases[6].id, "extra");
        assert_eq!(p.keys, ["damper.physical.A_orf_m2", "revs", "substeps"]);
        let g = p.groups();
        assert_eq!(g.len(), 2);
        assert_eq!(g[0].seed, 2);
        for bad in [
            "[vary]\n",
            "[vary]\nrevs = []\n",
            "[vary]\nrevs = [\"x\"]\n",
            "[vary]\nbogus = [1]\n",
            "[base]\nout = \"x\"\n[vary]\nrevs = [1]\n",
            "[base]\nmodel = \"rigid\"\n",
        ] {
            let e = Plan::parse(bad, "p.toml").unwrap_err().to_string();
            assert!(e.contains("p.toml"), "{e}");
        }
        // counted before expansion: 10^12 cases refused at once with the count and the axes
        let ten = "[0, 1, 2, 3, 4, 5, 6, 7, 8, 9]";
        let big: String = (0..12).map(|i| format!("\"k.a{i}\" = {ten}\n")).collect();
        let e = Plan::parse(&format!("[vary]\n{big}"), "big.toml")
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("big.toml") && e.contains("1000000000000 cases"),
            "{e}"
        );
        assert!(e.contains("\"k.a0\" 10 x"), "{e}");
        assert_eq!(parse_shard("1/4").unwrap(), (1, 4));
        assert!(parse_shard("4/4").is_err());
    }
}
