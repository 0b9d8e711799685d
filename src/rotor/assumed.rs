//! The deck's own labels of its assumed values, read with the deck: every key whose line
//! carries a `# ASSUMED` comment (docs/sensitivity.md, "Parameters"). The mark is the user's
//! way to label a value; the reader turns it into data on the deck ([`crate::rotor::RotorDeck::assumed`])
//! so that no later stage reads comments out of text.
//!
//! The scan follows the TOML text line by line: `[table]` headers give the dotted prefix of
//! the keys below them, a value spread over several lines (an array) is followed to its end,
//! and a `#` inside a string is not a comment. What the scan cannot turn into a parameter is
//! reported with the reason: an `ASSUMED` comment on a line of its own (it labels no single
//! value), a key inside an array of tables (`[[aero.airfoil]]`: an override cannot address
//! it), an inline table, a string or boolean, an integer count, a zero.
use toml::{Table, Value};

/// The word that marks an assumed value in a comment.
pub const MARK: &str = "ASSUMED";

/// A labelled value the scan found: its dotted key (as `rotorsim run --set` takes it), the
/// 1-based line, the value in the deck and the comment's text after the `#`.
#[derive(Clone, Debug, PartialEq)]
pub struct Labelled {
    pub key: String,
    pub line: usize,
    pub value: Value,
    pub comment: String,
}

/// An `ASSUMED` line that gives no parameter, and why.
#[derive(Clone, Debug, PartialEq)]
pub struct Skipped {
    pub line: usize,
    /// The dotted key of the line (None: a comment on its own line).
    pub key: Option<String>,
    /// The line's text, trimmed.
    pub text: String,
    pub reason: String,
}

/// What the scan of one deck found.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Scan {
    pub labelled: Vec<Labelled>,
    pub skipped: Vec<Skipped>,
}

/// Splits a line into its code and its comment (the text after a `#` outside strings).
fn split_comment(line: &str) -> (&str, Option<&str>) {
    let mut quote: Option<char> = None;
    let mut escaped = false;
    for (i, c) in line.char_indices() {
        match quote {
            Some(q) => {
                if escaped {
                    escaped = false;
                } else if c == '\\' && q == '"' {
                    escaped = true;
                } else if c == q {
                    quote = None;
                }
            }
            None if c == '"' || c == '\'' => quote = Some(c),
            None if c == '#' => return (&line[..i], Some(&line[i + 1..])),
            None => {}
        }
    }
    (line, None)
}

/// `[` minus `]` outside strings (a value continues on the next line while positive).
fn bracket_depth(code: &str) -> i64 {
    let mut quote: Option<char> = None;
    let mut d = 0i64;
    for c in code.chars() {
        match quote {
            Some(q) if c == q => quote = None,
            Some(_) => {}
            None if c == '"' || c == '\'' => quote = Some(c),
            None if c == '[' || c == '{' => d += 1,
            None if c == ']' || c == '}' => d -= 1,
            None => {}
        }
    }
    d
}

/// A dotted key as written (`a.b`, `"a.b"`, `a."b c"`) to its parts.
fn key_parts(text: &str) -> Vec<String> {
    let mut parts = Vec::new();
    let mut cur = String::new();
    let mut quote: Option<char> = None;
    for c in text.trim().chars() {
        match quote {
            Some(q) if c == q => quote = None,
            Some(_) => cur.push(c),
            None if c == '"' || c == '\'' => quote = Some(c),
            None if c == '.' => parts.push(std::mem::take(&mut cur).trim().to_string()),
            None => cur.push(c),
        }
    }
    parts.push(cur.trim().to_string());
    parts
}

/// The value at a dotted key of a parsed deck (through inline tables too).
pub fn lookup<'a>(root: &'a Table, key: &str) -> Option<&'a Value> {
    let mut parts = key.split('.');
    let mut v = root.get(parts.next()?)?;
    for p in parts {
        v = v.as_table()?.get(p)?;
    }
    Some(v)
}

/// Scans the deck text `text` (parsed as `root`) for values labelled `# ASSUMED`.
pub fn scan(text: &str, root: &Table) -> Scan {
    let mut out = Scan::default();
    let mut prefix: Vec<String> = Vec::new();
    let mut in_array_table = false;
    let mut depth = 0i64;
    for (n, line) in text.lines().enumerate() {
        let n = n + 1;
        let (code, comment) = split_comment(line);
        let marked = comment.is_some_and(|c| c.contains(MARK));
        let code_t = code.trim();
        if depth > 0 {
            // the continuation of a value spread over lines
            depth += bracket_depth(code);
            if marked {
                out.skipped.push(Skipped {
                    line: n,
                    key: None,
                    text: line.trim().to_string(),
                    reason: "on a continuation line of a value spread over lines: put the label on the key's own line".into(),
                });
            }
            continue;
        }
        if code_t.starts_with("[[") {
            let inner = code_t.trim_start_matches("[[").trim_end_matches("]]");
            prefix = key_parts(inner);
            in_array_table = true;
            if marked {
                out.skipped.push(Skipped {
                    line: n,
                    key: Some(prefix.join(".")),
                    text: line.trim().to_string(),
                    reason: "labels an array of tables, which an override cannot address".into(),
                });
            }
            continue;
        }
        if code_t.starts_with('[') {
            let inner = code_t.trim_start_matches('[').trim_end_matches(']');
            prefix = key_parts(inner);
            in_array_table = false;
            if marked {
                out.skipped.push(Skipped {
                    line: n,
                    key: Some(prefix.join(".")),
                    text: line.trim().to_string(),
                    reason: "labels a whole table: label its values one by one".into(),
                });
            }
            continue;
        }
        let Some((k, v)) = code_t.split_once('=') else {
            if marked {
                out.skipped.push(Skipped {
                    line: n,
                    key: None,
                    text: line.trim().to_string(),
                    reason: "a comment on a line of its own labels no single value: vary what it describes with --vary KEY=LOW:HIGH".into(),
                });
            }
            continue;
        };
        depth = bracket_depth(v).max(0);
        if !marked {
            continue;
        }
        let mut parts = prefix.clone();
        parts.extend(key_parts(k));
        let key = parts.join(".");
        let skip = |reason: &str| Skipped {
            line: n,
            key: Some(key.clone()),
            text: line.trim().to_string(),
            reason: reason.to_string(),
        };
        if in_array_table {
            out.skipped.push(skip(
                "inside an array of tables, which an override cannot address",
            ));
            continue;
        }
        match lookup(root, &key) {
            Some(value) => out.labelled.push(Labelled {
                key,
                line: n,
                value: value.clone(),
                comment: comment.unwrap_or_default().trim().to_string(),
            }),
            None => out
                .skipped
                .push(skip("the parsed deck holds no value at this key")),
        }
    }
    out
}

/// One number of the deck moved by a sensitivity study or a verdict's band: a scalar at `key`, or component `index`
/// of the number array at `key`.
#[derive(Clone, Debug, PartialEq)]
pub struct Target {
    pub key: String,
    pub index: Option<usize>,
    /// The deck's value there.
    pub nominal: f64,
    /// The whole array (for a component), to be written back with one component changed.
    pub array: Option<Vec<f64>>,
    /// Whether the deck holds an integer (a `--vary` value must then be whole).
    pub integer: bool,
    pub line: Option<usize>,
}

impl Target {
    /// The name shown in tables: `key`, or `key[i]` for a component.
    pub fn name(&self) -> String {
        match self.index {
            Some(i) => format!("{}[{i}]", self.key),
            None => self.key.clone(),
        }
    }

    /// The deck value (for an override of `key`) with this number set to `x`.
    pub fn value_at(&self, x: f64) -> Value {
        match (&self.array, self.index) {
            (Some(a), Some(i)) => Value::Array(
                a.iter()
                    .enumerate()
                    .map(|(k, v)| Value::Float(if k == i { x } else { *v }))
                    .collect(),
            ),
            _ if self.integer => Value::Integer(x.round() as i64),
            _ => Value::Float(x),
        }
    }
}

/// The numbers of a labelled value that the sensitivity moves by default, and the skipped
/// ones with the reason: a nonzero number; each nonzero component of an array of numbers.
pub fn targets(l: &Labelled) -> (Vec<Target>, Vec<Skipped>) {
    let skip = |key: String, reason: String| Skipped {
        line: l.line,
        key: Some(key),
        text: format!("{} = {}  # {}", l.key, l.value, l.comment),
        reason,
    };
    let zero = "zero: x0.5 and x2 of 0 are 0, so there is no relative range; give one with --vary KEY=LOW:HIGH";
    match &l.value {
        Value::Float(x) if *x != 0.0 && x.is_finite() => (
            vec![Target {
                key: l.key.clone(),
                index: None,
                nominal: *x,
                array: None,
                integer: false,
                line: Some(l.line),
            }],
            vec![],
        ),
        Value::Float(_) => (vec![], vec![skip(l.key.clone(), zero.into())]),
        Value::Integer(_) => (
            vec![],
            vec![skip(
                l.key.clone(),
                "an integer count: halving or doubling a count is not a stated range; give one with --vary KEY=LOW:HIGH".into(),
            )],
        ),
        Value::Array(a) => {
            let nums: Option<Vec<f64>> = a
                .iter()
                .map(|v| match v {
                    Value::Float(x) => Some(*x),
                    Value::Integer(i) => Some(*i as f64),
                    _ => None,
                })
                .collect();
            let Some(nums) = nums else {
                return (
                    vec![],
                    vec![skip(
                        l.key.clone(),
                        "an array of other than numbers (a table of rows): not varied".into(),
                    )],
                );
            };
            let mut t = Vec::new();
            let mut s = Vec::new();
            for (i, x) in nums.iter().enumerate() {
                let name = format!("{}[{i}]", l.key);
                if *x == 0.0 || !x.is_finite() {
                    s.push(skip(name, zero.into()));
                } else {
                    t.push(Target {
                        key: l.key.clone(),
                        index: Some(i),
                        nominal: *x,
                        array: Some(nums.clone()),
                        integer: false,
                        line: Some(l.line),
                    });
                }
            }
            (t, s)
        }
        Value::Table(_) => (
            vec![],
            vec![skip(
                l.key.clone(),
                "an inline table of several values: name one with --vary KEY.MEMBER=LOW:HIGH".into(),
            )],
        ),
        Value::String(_) | Value::Boolean(_) | Value::Datetime(_) => (
            vec![],
            vec![skip(l.key.clone(), "not a number: not varied".into())],
        ),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn comments_strings_and_keys() {
        assert_eq!(
            split_comment("a = \"x#y\" # c"),
            ("a = \"x#y\" ", Some(" c"))
        );
        assert_eq!(bracket_depth("x = [[1, 2], [3"), 2);
        assert_eq!(key_parts("a.\"b.c\""), vec!["a", "b.c"]);
    }

    #[test]
    fn marks_become_keys() {
        let text = "[bearing]\nlag_stiffness_Nm_per_rad = 2.0  # ASSUMED from a paper\nx = 1.0\n";
        let root: Table = text.parse().unwrap();
        let s = scan(text, &root);
        assert_eq!(s.labelled.len(), 1);
        assert_eq!(s.labelled[0].key, "bearing.lag_stiffness_Nm_per_rad");
        assert_eq!(s.labelled[0].line, 2);
        assert!(s.skipped.is_empty());
    }

    #[test]
    fn the_deck_carries_its_marks() {
        let p = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("rotors/uh60a.toml");
        let deck = crate::rotor::RotorDeck::from_file(&p).unwrap();
        let text = std::fs::read_to_string(&p).unwrap();
        assert_eq!(deck.assumed(), &scan(&text, &text.parse().unwrap()));
        assert!(!deck.assumed().labelled.is_empty());
    }
}
