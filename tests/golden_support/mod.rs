//! Golden outputs: a result folder reduced to a listing that is stored under tests/golden/ and
//! compared on every test run (tests/golden.rs for the README's commands,
//! tests/shipped_examples.rs for every shipped deck).
//!
//! The listing holds, for every file of the folder, a sha256 of its normalised content (bit for
//! bit: the same hash means the same numbers to the last digit) and a numeric fingerprint:
//! - CSV: per column, the count, sum, sum of magnitudes, largest magnitude and 9 evenly spaced
//!   samples (text columns: a hash);
//! - JSON: the numbers grouped by their key path (array indices folded), per group the count,
//!   sum, sum of magnitudes, largest magnitude and a sum weighted by a hash of each full path,
//!   so a change of any single value moves it; strings and booleans hashed per group;
//! - other text (decks, printed output): numbers fingerprinted as one group, the rest hashed;
//! - HTML, SVG, PNG and MCAP: present (their numbers are the JSON's and CSV's);
//! - the case folders of a sweep or study (`cases/`): one weighted group a file, since the
//!   study's own tables summarise them.
//!
//! Normalised: the binary's, the result folder's, the work folder's and the repository's paths
//! become `<BIN>`, `<OUT>`, `<WORK>`, `<REPO>`; what differs from run to run or build to build
//! is left out (wall times, run ids, start and end times, the version and git commit, the
//! command line: how a result was asked for, not what it is; and the sha256 and size of
//! outputs in manifest.json).
//!
//! A file whose hash differs passes only if its fingerprint agrees within 1e-9 relative (each
//! line against its own largest magnitude) and the case is listed, with the reason, in
//! tests/golden/DIFFERENCES.md. `ROTORSIM_GOLDEN_UPDATE=1` writes the listings instead.
#![allow(dead_code)]
use sha2::{Digest, Sha256};
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

/// Relative agreement of a file whose arithmetic changed.
pub const RELATIVE: f64 = 1e-9;
/// Samples of a CSV column.
const SAMPLES: usize = 5;
/// JSON groups per file at most (deeper key paths fold into their parents beyond it).
const MAX_GROUPS: usize = 64;

/// Keys whose values differ from run to run (and any key ending in `_wall_time_s`).
const VOLATILE_KEYS: [&str; 9] = [
    "git_commit",
    "command_line",
    "wall_time_s",
    "cost_per_step_s",
    "start_time",
    "end_time",
    "run_id",
    "rotorsim_version",
    "elapsed_s",
];
/// CSV columns whose values differ from run to run.
const VOLATILE_COLUMNS: [&str; 1] = ["wall_time_s"];

/// The binary under test: this build's, or `ROTORSIM_GOLDEN_BIN` (a reference build, to write
/// the goldens from the code before a change).
pub fn bin() -> String {
    std::env::var("ROTORSIM_GOLDEN_BIN").unwrap_or_else(|_| env!("CARGO_BIN_EXE_rotorsim").into())
}

fn repo() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

fn sha(bytes: &[u8]) -> String {
    let h = Sha256::digest(bytes);
    h.iter().take(12).map(|b| format!("{b:02x}")).collect()
}

/// FNV-1a of a key path: the weight of its value in a group's weighted sum, in [0.5, 1.5).
fn weight(path: &str) -> f64 {
    let mut h: u64 = 0xcbf29ce484222325;
    for b in path.bytes() {
        h ^= b as u64;
        h = h.wrapping_mul(0x100000001b3);
    }
    0.5 + (h >> 11) as f64 / (1u64 << 53) as f64
}

/// Path substitutions, longest first.
pub struct Paths {
    subs: Vec<(String, &'static str)>,
}

impl Paths {
    pub fn new(out: &Path, work: &Path) -> Self {
        let mut subs = vec![
            (bin(), "<BIN>"),
            (out.display().to_string(), "<OUT>"),
            (work.display().to_string(), "<WORK>"),
            (repo().display().to_string(), "<REPO>"),
        ];
        subs.sort_by_key(|(s, _)| std::cmp::Reverse(s.len()));
        Paths { subs }
    }
    fn apply(&self, text: &str) -> String {
        let mut t = text.to_string();
        for (from, to) in &self.subs {
            if !from.is_empty() {
                t = t.replace(from.as_str(), to);
            }
        }
        t
    }
}

fn num(x: f64) -> String {
    format!("{x:e}")
}

/// Running statistics of one group of numbers.
#[derive(Default)]
struct Stats {
    n: usize,
    sum: f64,
    abs: f64,
    max: f64,
    wsum: f64,
}

impl Stats {
    fn add(&mut self, x: f64, w: f64) {
        self.n += 1;
        self.sum += x;
        self.abs += x.abs();
        self.max = self.max.max(x.abs());
        self.wsum += w * x;
    }
    fn line(&self, name: &str) -> String {
        format!(
            "num {name} n={} sum={} abs={} max={} wsum={}",
            self.n,
            num(self.sum),
            num(self.abs),
            num(self.max),
            num(self.wsum)
        )
    }
}

fn csv_listing(text: &str, whole: bool, lines: &mut Vec<String>) -> String {
    let mut r = csv::ReaderBuilder::new()
        .has_headers(false)
        .flexible(true)
        .from_reader(text.as_bytes());
    let records: Vec<csv::StringRecord> = match r.records().collect() {
        Ok(v) => v,
        Err(e) => {
            lines.push(format!("not CSV: {e}"));
            return sha(text.as_bytes());
        }
    };
    let Some(header) = records.first() else {
        return sha(b"");
    };
    let names: Vec<&str> = header.iter().collect();
    let keep: Vec<bool> = names
        .iter()
        .map(|n| !VOLATILE_COLUMNS.contains(n))
        .collect();
    let mut cols: Vec<Vec<&str>> = vec![vec![]; names.len()];
    let mut norm = String::new();
    for (row, rec) in records.iter().enumerate() {
        for (i, c) in rec.iter().enumerate() {
            if keep.get(i).copied().unwrap_or(true) {
                norm.push_str(c);
                norm.push('\u{1f}');
            }
            if row > 0 && i < cols.len() {
                cols[i].push(c);
            }
        }
        norm.push('\n');
    }
    if whole {
        let mut s = Stats::default();
        for (i, col) in cols.iter().enumerate().filter(|(i, _)| keep[*i]) {
            let w = weight(names[i]);
            for x in col.iter().filter_map(|c| c.parse::<f64>().ok()) {
                if x.is_finite() {
                    s.add(x, w);
                }
            }
        }
        lines.push(s.line("all"));
        return sha(norm.as_bytes());
    }
    for (i, name) in names.iter().enumerate() {
        if !keep[i] {
            continue;
        }
        let col = &cols[i];
        let values: Option<Vec<f64>> = col
            .iter()
            .map(|c| {
                if c.is_empty() {
                    Some(f64::NAN)
                } else {
                    c.parse::<f64>().ok()
                }
            })
            .collect();
        match values {
            Some(v) if v.iter().any(|x| x.is_finite()) => {
                let mut s = Stats::default();
                for x in v.iter().filter(|x| x.is_finite()) {
                    s.add(*x, 1.0);
                }
                lines.push(s.line(&format!("col:{name}")));
                let k = v.len();
                let picks: Vec<String> = (0..SAMPLES.min(k))
                    .map(|j| {
                        let idx = if SAMPLES >= k {
                            j
                        } else {
                            j * (k - 1) / (SAMPLES - 1)
                        };
                        num(v[idx])
                    })
                    .collect();
                lines.push(format!("smp col:{name} {}", picks.join(" ")));
            }
            _ => lines.push(format!("txt col:{name} {}", sha(col.join("\n").as_bytes()))),
        }
    }
    sha(norm.as_bytes())
}

/// Drops volatile keys, normalises paths; returns the cleaned value.
fn clean_json(v: &mut serde_json::Value, paths: &Paths, manifest: bool) {
    match v {
        serde_json::Value::Object(m) => {
            m.retain(|k, _| !VOLATILE_KEYS.contains(&k.as_str()) && !k.ends_with("_wall_time_s"));
            if manifest && m.contains_key("sha256") && m.contains_key("size") {
                // an output's entry: its content is checked where it is listed itself
                m.remove("sha256");
                m.remove("size");
            }
            for (_, x) in m.iter_mut() {
                clean_json(x, paths, manifest);
            }
        }
        serde_json::Value::Array(a) => a.iter_mut().for_each(|x| clean_json(x, paths, manifest)),
        serde_json::Value::String(s) => *s = paths.apply(s),
        _ => {}
    }
}

fn flatten(v: &serde_json::Value, path: &str, out: &mut Vec<(String, serde_json::Value)>) {
    match v {
        serde_json::Value::Object(m) => {
            for (k, x) in m {
                flatten(x, &format!("{path}.{k}"), out)
            }
        }
        serde_json::Value::Array(a) => {
            for (i, x) in a.iter().enumerate() {
                flatten(x, &format!("{path}[{i}]"), out)
            }
        }
        _ => out.push((path.to_string(), v.clone())),
    }
}

/// The key path with array indices folded, cut to `depth` components.
fn group_of(path: &str, depth: usize) -> String {
    let mut folded = String::new();
    let mut in_index = false;
    for ch in path.chars() {
        match ch {
            '[' => {
                in_index = true;
                folded.push_str("[*]");
            }
            ']' => in_index = false,
            _ if in_index => {}
            _ => folded.push(ch),
        }
    }
    // components split at '.' and '[': keep the first `depth`
    let mut n = 0;
    let mut end = folded.len();
    for (i, ch) in folded.char_indices() {
        if (ch == '.' || ch == '[') && i > 0 {
            n += 1;
            if n == depth {
                end = i;
                break;
            }
        }
    }
    folded[..end].to_string()
}

fn json_listing(
    text: &str,
    paths: &Paths,
    manifest: bool,
    max_groups: usize,
    lines: &mut Vec<String>,
) -> String {
    let Ok(mut v) = serde_json::from_str::<serde_json::Value>(text) else {
        lines.push("not JSON".into());
        return sha(paths.apply(text).as_bytes());
    };
    clean_json(&mut v, paths, manifest);
    let canonical = serde_json::to_string(&v).unwrap();
    let mut leaves = vec![];
    flatten(&v, "", &mut leaves);
    let mut depth = 64;
    let groups = loop {
        let mut g: BTreeMap<String, Vec<&(String, serde_json::Value)>> = BTreeMap::new();
        for leaf in &leaves {
            g.entry(group_of(&leaf.0, depth)).or_default().push(leaf);
        }
        if g.len() <= max_groups || depth == 1 {
            break g;
        }
        depth -= 1;
    };
    for (name, members) in &groups {
        let mut s = Stats::default();
        let mut text = String::new();
        for (p, x) in members {
            match x.as_f64() {
                Some(f) => s.add(f, weight(p)),
                None => {
                    text.push_str(p);
                    text.push('=');
                    text.push_str(&x.to_string());
                    text.push('\n');
                }
            }
        }
        if s.n > 0 {
            lines.push(s.line(name));
        }
        if !text.is_empty() {
            lines.push(format!("txt {name} {}", sha(text.as_bytes())));
        }
    }
    sha(canonical.as_bytes())
}

/// Numbers of a text (a deck, printed output): fingerprinted as one group, the rest hashed.
fn text_listing(text: &str, paths: &Paths, lines: &mut Vec<String>) -> String {
    let text = paths.apply(text);
    let mut s = Stats::default();
    let mut words = String::new();
    for (i, tok) in text
        .split(|c: char| c.is_whitespace() || ",=[](){}\"'".contains(c))
        .filter(|t| !t.is_empty())
        .enumerate()
    {
        match tok.parse::<f64>() {
            Ok(x) if x.is_finite() => s.add(x, weight(&i.to_string())),
            _ => {
                words.push_str(tok);
                words.push(' ');
            }
        }
    }
    if s.n > 0 {
        lines.push(s.line("numbers"));
    }
    lines.push(format!("txt words {}", sha(words.as_bytes())));
    sha(text.as_bytes())
}

/// The listing of every file under `out`, sorted by path.
pub fn listing(out: &Path, paths: &Paths) -> String {
    fn walk(dir: &Path, files: &mut Vec<PathBuf>) {
        let Ok(rd) = std::fs::read_dir(dir) else {
            return;
        };
        for e in rd {
            let p = e.unwrap().path();
            if p.is_dir() {
                walk(&p, files)
            } else {
                files.push(p)
            }
        }
    }
    let mut files = vec![];
    walk(out, &mut files);
    files.sort();
    let mut text = String::new();
    for f in files {
        let rel = f.strip_prefix(out).unwrap().display().to_string();
        let ext = f.extension().and_then(|e| e.to_str()).unwrap_or("");
        let mut lines = vec![];
        let head = match ext {
            "html" | "svg" | "png" | "mcap" => format!("== {rel} present"),
            _ => {
                let bytes = std::fs::read(&f).unwrap();
                let body = String::from_utf8_lossy(&bytes);
                let case = rel.starts_with("cases/");
                let hash = match ext {
                    "csv" => csv_listing(&body, case, &mut lines),
                    "json" => json_listing(
                        &body,
                        paths,
                        f.file_name().unwrap() == "manifest.json",
                        if case { 1 } else { MAX_GROUPS },
                        &mut lines,
                    ),
                    _ => text_listing(&body, paths, &mut lines),
                };
                format!("== {rel} sha={hash}")
            }
        };
        text.push_str(&head);
        text.push('\n');
        for l in lines {
            text.push_str(&l);
            text.push('\n');
        }
    }
    text
}

/// The numbers of a fingerprint line and its text with the numbers blanked (counts stay text).
fn numbers_of(line: &str) -> (String, Vec<f64>) {
    let mut shape = String::new();
    let mut nums = vec![];
    let numeric = line.starts_with("num ") || line.starts_with("smp ");
    for tok in line.split(' ') {
        let (key, val) = match tok.split_once('=') {
            Some((k, v)) => (format!("{k}="), v),
            None => (String::new(), tok),
        };
        match val.parse::<f64>() {
            Ok(x) if numeric && key != "n=" => {
                shape.push_str(&key);
                shape.push_str("# ");
                nums.push(x);
            }
            _ => {
                shape.push_str(tok);
                shape.push(' ');
            }
        }
    }
    (shape, nums)
}

/// Blocks of a listing by file.
fn blocks(listing: &str) -> BTreeMap<String, (String, Vec<String>)> {
    let mut out = BTreeMap::new();
    let mut cur: Option<(String, String, Vec<String>)> = None;
    for l in listing.lines() {
        if let Some(rest) = l.strip_prefix("== ") {
            if let Some((f, h, ls)) = cur.take() {
                out.insert(f, (h, ls));
            }
            let (f, h) = rest.rsplit_once(' ').unwrap_or((rest, ""));
            cur = Some((f.to_string(), h.to_string(), vec![]));
        } else if let Some((_, _, ls)) = cur.as_mut() {
            ls.push(l.to_string());
        }
    }
    if let Some((f, h, ls)) = cur.take() {
        out.insert(f, (h, ls));
    }
    out
}

/// How a listing compares with its golden.
pub struct Comparison {
    /// Files whose hash differs but whose fingerprint agrees within `RELATIVE`.
    pub within: Vec<String>,
    /// What disagrees (missing or extra files, a fingerprint out of tolerance).
    pub errors: Vec<String>,
}

pub fn compare(golden: &str, now: &str) -> Comparison {
    let g = blocks(golden);
    let n = blocks(now);
    let mut c = Comparison {
        within: vec![],
        errors: vec![],
    };
    for f in g.keys().filter(|f| !n.contains_key(*f)) {
        c.errors.push(format!("{f}: missing (the golden has it)"));
    }
    for f in n.keys().filter(|f| !g.contains_key(*f)) {
        c.errors.push(format!("{f}: new (not in the golden)"));
    }
    for (f, (gh, gl)) in &g {
        let Some((nh, nl)) = n.get(f) else { continue };
        if gh == nh && gl == nl {
            continue;
        }
        if gl.len() != nl.len() {
            c.errors.push(format!(
                "{f}: {} fingerprint lines, golden {}",
                nl.len(),
                gl.len()
            ));
            continue;
        }
        let mut ok = true;
        for (a, b) in gl.iter().zip(nl) {
            if a == b {
                continue;
            }
            let (sa, na) = numbers_of(a);
            let (sb, nb) = numbers_of(b);
            let scale = na.iter().fold(0.0f64, |m, x| m.max(x.abs()));
            let close = sa == sb
                && na.len() == nb.len()
                && na
                    .iter()
                    .zip(&nb)
                    .all(|(x, y)| (x.is_nan() && y.is_nan()) || (x - y).abs() <= RELATIVE * scale);
            if !close {
                ok = false;
                c.errors.push(format!("{f}:\n  golden {a}\n  now    {b}"));
            }
        }
        if ok {
            c.within.push(f.clone());
        }
    }
    c
}

/// Cases allowed to differ within `RELATIVE` (tests/golden/DIFFERENCES.md: a line `- case: reason`).
fn allowed(case: &str) -> bool {
    let text =
        std::fs::read_to_string(repo().join("tests/golden/DIFFERENCES.md")).unwrap_or_default();
    text.lines()
        .filter_map(|l| l.strip_prefix("- `"))
        .filter_map(|l| l.split_once('`'))
        .any(|(c, _)| c == case)
}

/// Checks the folder `out` against tests/golden/`case`.txt (or writes it under
/// `ROTORSIM_GOLDEN_UPDATE=1`); an error says what differs.
pub fn check(case: &str, out: &Path, paths: &Paths) -> Result<(), String> {
    let now = listing(out, paths);
    let file = repo().join("tests/golden").join(format!("{case}.txt"));
    if std::env::var("ROTORSIM_GOLDEN_UPDATE").as_deref() == Ok("1") {
        std::fs::create_dir_all(file.parent().unwrap()).unwrap();
        std::fs::write(&file, &now).unwrap();
        return Ok(());
    }
    let golden = std::fs::read_to_string(&file).map_err(|e| {
        format!(
            "golden {case}: {}: {e} (ROTORSIM_GOLDEN_UPDATE=1 writes it)",
            file.display()
        )
    })?;
    let c = compare(&golden, &now);
    let mut errors = c.errors;
    if !c.within.is_empty() && !allowed(case) {
        errors.push(format!(
            "not bit for bit, within {RELATIVE:e} relative, and tests/golden/DIFFERENCES.md gives no reason for `{case}`: {}",
            c.within.join(", ")
        ));
    }
    if errors.is_empty() {
        Ok(())
    } else {
        Err(format!("golden {case}: {}", errors.join("\n")))
    }
}
