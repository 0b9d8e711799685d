//! Per-blade differences of a rotor deck (docs/rotor_deck.md, "Per-blade differences"): the
//! deck's `[blades.K.<deck path>]` tables and `--set blades.K.<deck path>=V` overrides. Blade K's
//! deck is the base deck (the deck without its `[blades]` table, what every single-blade command
//! reads) with these applied as overrides, the deck's entries first, then the `--set` ones: each
//! is validated exactly like a value written in the deck, and an error names the key as written.
use super::deck::{deck_error, RotorSpec};
use super::RotorDeck;
use crate::hydraulics::DamperDeck;
use crate::overrides::{self, Override};
use anyhow::{anyhow, bail};
use std::path::PathBuf;
use toml::{Table, Value};

/// The top-level key of per-blade differences.
pub const KEY: &str = "blades";

/// What a [`RotorDeck`] keeps of its per-blade differences.
#[derive(Clone, Debug, Default)]
pub(super) struct PerBlade {
    /// The deck's `[blades]` table (as read; checked by [`RotorDeck::check_blades`]).
    pub(super) table: Option<Value>,
    /// The `--set blades.*` overrides, keys as given.
    pub(super) sets: Vec<Override>,
}

/// Whether an override addresses a blade (`blades.K.<deck path>`) rather than the base deck.
pub fn is_blade_override(ov: &Override) -> bool {
    ov.key == KEY || ov.key.starts_with("blades.")
}

/// One difference of one blade: the override of its deck and where it was written.
#[derive(Clone, Debug)]
struct Entry {
    blade: usize,
    /// The override with the `blades.K.` prefix stripped.
    ov: Override,
    /// The `--set` it came from (None: the deck's `[blades.K]` table).
    set: Option<Override>,
}

impl Entry {
    /// The key as the user wrote it.
    fn full_key(&self) -> String {
        format!("{KEY}.{}.{}", self.blade, self.ov.key)
    }
    /// `err` (about blade `blade`'s deck) in the words of the user's input: the file and the
    /// full key, `--set KEY=VALUE:` first when it came from the command line.
    fn error(&self, file: &str, err: &anyhow::Error) -> anyhow::Error {
        located(file, self.set.as_ref(), &self.full_key(), &inner(file, err))
    }
}

/// `rotor deck F, KEY: MSG`, prefixed with `--set KEY=VALUE:` for an override.
fn located(file: &str, set: Option<&Override>, key: &str, msg: &str) -> anyhow::Error {
    match set {
        Some(o) => anyhow!("--set {o}: rotor deck {file}, {key}: {msg}"),
        None => deck_error(file, key, msg).into(),
    }
}

/// The deck's message without its leading file name (the caller names file and key).
fn inner(file: &str, err: &anyhow::Error) -> String {
    let msg = format!("{err:#}");
    for p in [
        format!("rotor deck {file}: "),
        format!("rotor deck {file}, "),
        format!("deck {file}: "),
    ] {
        if let Some(rest) = msg.strip_prefix(&p) {
            return rest.to_string();
        }
    }
    msg
}

/// Blade number of `k` (the text after `blades.`), 1 to `n`.
fn blade_number(k: &str, n: usize) -> Result<usize, String> {
    let range = format!("expected {KEY}.1 to {KEY}.{n}");
    let b = match k.parse::<usize>() {
        // one spelling per blade: `blades.03` would be a second name of blade 3
        Ok(b) if b.to_string() == k => b,
        _ => return Err(format!("`{k}` is not a blade number: {range}")),
    };
    if b == 0 || b > n {
        return Err(format!(
            "the rotor has {n} blades (rotor.blades = {n}): {range}"
        ));
    }
    Ok(b)
}

/// Refuses the deck paths a blade cannot change; `path` is the key after `blades.K.`.
fn check_path(path: &str) -> Result<(), String> {
    let first = path.split('.').next().unwrap_or("");
    if first == "rotor" {
        return Err(
            "the rotor's speed, radius and blade count are shared by all blades: set them in [rotor]"
                .into(),
        );
    }
    if first == "airframe" {
        return Err("the airframe is under the whole rotor: set it in [airframe]".into());
    }
    if first == KEY {
        return Err(format!(
            "per-blade tables do not nest: expected {KEY}.K.<deck key>"
        ));
    }
    Ok(())
}

/// The deck's `[blades]` table as entries, in blade order, each checked for its shape (blade
/// number, deck path); the values are checked when the blade's deck is built.
fn deck_entries(file: &str, table: &Value, base: &Table, n: usize) -> anyhow::Result<Vec<Entry>> {
    let Value::Table(t) = table else {
        return Err(deck_error(
            file,
            KEY,
            &format!(
                "expected per-blade tables [{KEY}.K.<deck path>] (K = 1 to {n}), found {table}"
            ),
        )
        .into());
    };
    let mut out = Vec::new();
    for (k, v) in t {
        let b = blade_number(k, n).map_err(|e| deck_error(file, &format!("{KEY}.{k}"), &e))?;
        let Value::Table(bt) = v else {
            return Err(deck_error(
                file,
                &format!("{KEY}.{k}"),
                &format!("expected a table of blade {b}'s deck values ([{KEY}.{k}.<deck path>]), found {v}"),
            )
            .into());
        };
        let mut leaves = Vec::new();
        flatten(bt, &mut Vec::new(), &mut leaves);
        for (parts, leaf) in leaves {
            let path = parts.join(".");
            let full = format!("{KEY}.{k}.{path}");
            let bad = |msg: String| anyhow::Error::from(deck_error(file, &full, &msg));
            if parts
                .iter()
                .any(|p| overrides::check_key(p).is_err() || p.contains('.'))
            {
                return Err(bad(
                    "expected a deck key of letters, digits, `_` and `-`".into()
                ));
            }
            check_path(&path).map_err(bad)?;
            match leaf {
                Some(value) => out.push(Entry {
                    blade: b,
                    ov: Override {
                        key: path,
                        value: value.clone(),
                    },
                    set: None,
                }),
                // an empty table changes nothing, but must still name a table of the deck
                None if lookup(base, &parts).is_some_and(Value::is_table) => {}
                None => return Err(bad(format!("unknown table: the deck has no [{path}]"))),
            }
        }
    }
    out.sort_by_key(|e| e.blade);
    Ok(out)
}

/// The leaves of `t` by key path (None: an empty table).
fn flatten<'t>(
    t: &'t Table,
    path: &mut Vec<&'t str>,
    out: &mut Vec<(Vec<&'t str>, Option<&'t Value>)>,
) {
    if t.is_empty() && !path.is_empty() {
        out.push((path.clone(), None));
    }
    for (k, v) in t {
        path.push(k);
        match v {
            Value::Table(sub) => flatten(sub, path, out),
            v => out.push((path.clone(), Some(v))),
        }
        path.pop();
    }
}

fn lookup<'t>(t: &'t Table, parts: &[&str]) -> Option<&'t Value> {
    let (first, rest) = parts.split_first()?;
    let v = t.get(*first)?;
    match (rest.is_empty(), v) {
        (true, v) => Some(v),
        (false, Value::Table(sub)) => lookup(sub, rest),
        _ => None,
    }
}

/// A `--set blades.K.<deck path>=V` as an entry, its shape checked.
fn set_entry(file: &str, ov: &Override, n: usize) -> anyhow::Result<Entry> {
    let mut parts = ov.key.splitn(3, '.');
    let (_, k, path) = (parts.next(), parts.next(), parts.next());
    let (Some(k), Some(path)) = (k, path) else {
        bail!(
            "--set {ov}: rotor deck {file}, {}: expected {KEY}.K.<deck key> (K = 1 to {n}, e.g. {KEY}.2.damper.physical.A_orf_m2)",
            ov.key
        );
    };
    let b =
        blade_number(k, n).map_err(|e| anyhow!("--set {ov}: rotor deck {file}, {KEY}.{k}: {e}"))?;
    check_path(path).map_err(|e| anyhow!("--set {ov}: rotor deck {file}, {}: {e}", ov.key))?;
    Ok(Entry {
        blade: b,
        ov: Override {
            key: path.to_string(),
            value: ov.value.clone(),
        },
        set: Some(ov.clone()),
    })
}

/// The rotor reader's verdict on the tables `root`; a schema error without the table's path
/// (the user wrote the value elsewhere: the caller names where).
fn check_rotor(root: &Table, file: &str) -> anyhow::Result<()> {
    if let Err(e) = RotorSpec::schema(root) {
        bail!("{}", e.message().trim_end());
    }
    RotorSpec::from_table(root, file)?;
    Ok(())
}

impl RotorDeck {
    fn file(&self) -> String {
        self.path.display().to_string()
    }

    /// Whether blades differ: the deck has a `[blades]` table or there are `--set blades.*`
    /// overrides.
    pub fn per_blade(&self) -> bool {
        self.blades.table.is_some() || !self.blades.sets.is_empty()
    }

    /// The blades that differ from the base deck (ascending; the others' decks equal it).
    /// Empty when the entries are bad ([`RotorDeck::check_blades`] refuses those on load).
    pub fn differing_blades(&self) -> Vec<usize> {
        let mut v: Vec<usize> = self
            .blade_entries()
            .unwrap_or_default()
            .iter()
            .map(|e| e.blade)
            .collect();
        v.sort_unstable();
        v.dedup();
        v
    }

    /// Every per-blade difference as `blades.K.<deck path> = value`, the deck's first (blade
    /// order), then the `--set` ones in order (for reports).
    pub fn blade_differences(&self) -> Vec<String> {
        self.blade_entries()
            .unwrap_or_default()
            .iter()
            .map(|e| {
                format!(
                    "blades.{}.{} = {}",
                    e.blade,
                    e.ov.key,
                    crate::overrides::display(&e.ov.value)
                )
            })
            .collect()
    }

    /// Every per-blade entry, the deck's first (blade order), then the `--set` ones in order.
    fn blade_entries(&self) -> anyhow::Result<Vec<Entry>> {
        let file = self.file();
        let n = self.spec.rotor.blades;
        let mut out = match &self.blades.table {
            Some(t) => deck_entries(&file, t, &self.base_table()?, n)?,
            None => Vec::new(),
        };
        for ov in &self.blades.sets {
            out.push(set_entry(&file, ov, n)?);
        }
        Ok(out)
    }

    /// The base deck's tables (the `[blades]` table removed).
    fn base_table(&self) -> anyhow::Result<Table> {
        let mut root = self.table.clone();
        root.remove(KEY);
        Ok(root)
    }

    /// Blade `k`'s deck (1-based): the base deck with blade `k`'s entries of the `[blades]`
    /// table, then its `--set blades.K.*` overrides, each validated like the deck (the `[damper]`
    /// table by the damper deck's rules). Without entries it equals the base deck. A deck
    /// without a `[damper]` table takes no `damper.*` entries: they are for the separate damper
    /// deck of the run ([`RotorDeck::blade_damper_overrides`]).
    pub fn blade(&self, k: usize) -> anyhow::Result<RotorDeck> {
        let file = self.file();
        let n = self.spec.rotor.blades;
        if k == 0 || k > n {
            bail!("rotor deck {file}: no blade {k}: the rotor has {n} blades (rotor.blades = {n})");
        }
        let mut root = self.base_table()?;
        let has_damper = root.contains_key("damper");
        let entries: Vec<Entry> = self
            .blade_entries()?
            .into_iter()
            .filter(|e| e.blade == k && (has_damper || !e.ov.is_damper()))
            .collect();
        for e in &entries {
            overrides::apply(&mut root, &e.ov).map_err(|err| e.error(&file, &err))?;
            check_rotor(&root, &file).map_err(|err| e.error(&file, &err))?;
            if e.ov.is_damper() {
                DamperDeck::from_toml_table(root.clone(), &file)
                    .map_err(|err| e.error(&file, &err.into()))?;
            }
        }
        Ok(RotorDeck {
            path: self.path.clone(),
            spec: RotorSpec::from_table(&root, &file)?,
            table: root,
            blades: PerBlade::default(),
            damper: Default::default(),
            assumed: self.assumed.clone(),
        })
    }

    /// Blade `k`'s `damper.*` overrides (prefix `blades.K.` stripped; the deck's first, then
    /// the `--set` ones), for a run whose damper deck is a separate file (`--damper-deck`):
    /// apply them to that file after its own `--set damper.*` ones (what
    /// [`RotorDeck::blade_damper_deck`] does, naming the key as written). Empty for a blade without
    /// any, or when the entries are bad ([`RotorDeck::check_blades`] refuses those on load).
    pub fn blade_damper_overrides(&self, k: usize) -> Vec<Override> {
        self.blade_entries()
            .unwrap_or_default()
            .into_iter()
            .filter(|e| e.blade == k && e.ov.is_damper())
            .map(|e| e.ov)
            .collect()
    }

    /// Blade `k`'s damper from the separate damper deck `damper_file` (`--damper-deck`): the
    /// file with its own `--set damper.*` overrides `damper_sets`, then blade `k`'s `damper.*`
    /// entries, each validated; an error names the rotor deck and the key as written.
    pub fn blade_damper_deck(
        &self,
        k: usize,
        damper_file: &std::path::Path,
        damper_sets: &[Override],
    ) -> anyhow::Result<DamperDeck> {
        let dfile = damper_file.display().to_string();
        let text = std::fs::read_to_string(damper_file)
            .map_err(|e| anyhow!("damper deck {dfile}: cannot read: {e}"))?;
        DamperDeck::from_toml_str(&text, &dfile)?;
        let root = overrides::parse_deck(&text, &dfile)?;
        let mut root = overrides::apply_all(root, &dfile, damper_sets, |t, _| {
            DamperDeck::from_toml_table(t.clone(), &dfile)?;
            Ok(())
        })?;
        let file = self.file();
        for e in self
            .blade_entries()?
            .into_iter()
            .filter(|e| e.blade == k && e.ov.is_damper())
        {
            let ctx = |err: &anyhow::Error| {
                located(
                    &file,
                    e.set.as_ref(),
                    &e.full_key(),
                    &format!("in damper deck {dfile}: {}", inner(&dfile, err)),
                )
            };
            overrides::apply(&mut root, &e.ov).map_err(|err| ctx(&err))?;
            DamperDeck::from_toml_table(root.clone(), &dfile).map_err(|err| ctx(&err.into()))?;
        }
        Ok(DamperDeck::from_toml_table(root, &dfile)?)
    }

    /// Refuses bad per-blade input before anything runs, naming the file and the key as
    /// written: a blade number that is not one of 1 to N, a `blades.K` that is not a table, a
    /// `rotor.*` key (shared by the rotor), and an unknown key or bad value in any blade's deck
    /// (every blade's deck is built and validated, a different section table read).
    pub fn check_blades(&self) -> anyhow::Result<()> {
        if !self.per_blade() {
            return Ok(());
        }
        let file = self.file();
        let entries = self.blade_entries()?;
        let dir = self.path.parent().unwrap_or(std::path::Path::new(""));
        // only the blades with entries: the others are the base deck, already checked
        for k in self.differing_blades() {
            let b = self.blade(k)?;
            if b.spec.blade.sections_csv != self.spec.blade.sections_csv {
                let csv = dir.join(&b.spec.blade.sections_csv);
                crate::structure::section::SectionTable::from_csv(&csv).map_err(|err| {
                    // the last entry that set it is the one in force
                    let e = entries
                        .iter()
                        .rev()
                        .find(|e| e.blade == k && e.ov.key == "blade.sections_csv");
                    let key = e.map_or(format!("{KEY}.{k}.blade.sections_csv"), Entry::full_key);
                    located(
                        &file,
                        e.and_then(|e| e.set.as_ref()),
                        &key,
                        &err.to_string(),
                    )
                })?;
            }
        }
        Ok(())
    }

    /// Every blade's section table that differs from the base deck's (deduplicated, in blade
    /// order); blades whose deck cannot be built are skipped ([`RotorDeck::check_blades`]
    /// refuses them on load).
    pub(super) fn blade_section_files(&self) -> Vec<PathBuf> {
        let dir = self.path.parent().unwrap_or(std::path::Path::new(""));
        let mut out: Vec<PathBuf> = Vec::new();
        for k in self.differing_blades() {
            if let Ok(b) = self.blade(k) {
                if b.spec.blade.sections_csv != self.spec.blade.sections_csv {
                    let p = dir.join(&b.spec.blade.sections_csv);
                    if !out.contains(&p) {
                        out.push(p);
                    }
                }
            }
        }
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn blade_numbers() {
        assert_eq!(blade_number("3", 4), Ok(3));
        for bad in ["0", "5", "03", "x", "-1", ""] {
            assert!(blade_number(bad, 4).is_err(), "{bad}");
        }
        assert!(blade_number("5", 4)
            .unwrap_err()
            .contains("rotor.blades = 4"));
    }

    #[test]
    fn paths_shared_by_the_rotor_are_refused() {
        assert!(check_path("rotor.omega_rad_s").is_err());
        assert!(check_path("blades.2.bearing.lag_stiffness_Nm_per_rad").is_err());
        assert!(check_path("rotor_x").is_ok());
        assert!(check_path("damper.physical.A_orf_m2").is_ok());
    }

    #[test]
    fn deck_tables_flatten_to_dotted_keys() {
        let t: Table = "[3.damper.physical]\nA_orf_m2 = 4.0e-6\n[2.bearing]\nlag_stiffness_Nm_per_rad = 1.0\n[2.pitch_control]\nlink_section = { EA_N = 1.0e8 }"
            .parse()
            .unwrap();
        let base: Table = "[bearing]\n[pitch_control]\n[damper]".parse().unwrap();
        let e = deck_entries("f", &Value::Table(t), &base, 4).unwrap();
        let keys: Vec<String> = e.iter().map(Entry::full_key).collect();
        assert_eq!(
            keys,
            [
                "blades.2.bearing.lag_stiffness_Nm_per_rad",
                "blades.2.pitch_control.link_section.EA_N",
                "blades.3.damper.physical.A_orf_m2"
            ]
        );
        let empty: Table = "[2.no_such]".parse().unwrap();
        let err = deck_entries("f", &Value::Table(empty), &base, 4).unwrap_err();
        assert!(err.to_string().contains("blades.2.no_such"), "{err}");
    }

    #[test]
    fn set_keys_are_checked() {
        let ov = |s: &str| Override::parse(s).unwrap();
        let e = set_entry("f", &ov("blades.2.damper.physical.A_orf_m2=1e-6"), 4).unwrap();
        assert_eq!(
            (e.blade, e.ov.key.as_str()),
            (2, "damper.physical.A_orf_m2")
        );
        for (bad, want) in [
            ("blades.2=1", "blades.K.<deck key>"),
            ("blades=1", "blades.K.<deck key>"),
            ("blades.9.bearing.x=1", "blades.9: the rotor has 4 blades"),
            ("blades.two.bearing.x=1", "blades.two"),
            ("blades.1.rotor.radius_m=1", "blades.1.rotor.radius_m"),
        ] {
            let err = set_entry("f", &ov(bad), 4).unwrap_err().to_string();
            assert!(err.starts_with(&format!("--set {}", ov(bad))), "{err}");
            assert!(err.contains(want), "{bad}: {err}");
        }
    }
}
