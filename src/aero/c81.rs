//! C81 aerofoil coefficient tables: lift, drag and pitching-moment coefficients tabulated
//! against angle of attack (degrees) and Mach number, as read by comprehensive rotor codes
//! (CAMRAD, RCAS, MBDyn's `c81` aerodynamic data).
//!
//! # Fixed layout (the standard one)
//!
//! Columns are 1-based character positions; fields are 7 characters wide (Fortran `F7.0`).
//!
//! ```text
//! line 1         name (columns 1-30), then ML NL MD ND MM NM as six 2-column integers
//!                (columns 31-32, 33-34, ..., 41-42)                           A30,6I2
//! Mach row       columns 1-7 ignored, up to 9 Mach numbers in columns 8-70;
//!                more on continuation lines, 9 a line after 7 ignored columns  7X,9F7.0
//! alpha rows     NL rows: alpha (deg) in columns 1-7, the first 9 coefficients in
//!                columns 8-70; more on continuation lines as above       10F7.0/(7X,9F7.0)
//! ```
//!
//! The lift table (ML Mach numbers, NL angles of attack) comes first, then the drag table
//! (MD, ND) and the moment table (MM, NM), each with its own Mach row. This is the layout of
//! MBDyn's `read_c81_data` (its c81data.cc), `A30,6I2 / 7X,9F7.0 /
//! 10F7.0/(7X,9F7.0)`.
//!
//! Two leniencies, both needed by real tables:
//! - a row that needs more values than columns 1-70 hold may carry them after column 70 on the
//!   same line, whitespace separated (continuation lines joined onto the row, as in the public
//!   NACA 0012 table data/airfoils/naca0012.c81); continuation lines are read only when
//!   everything after column 70 is blank;
//! - numbers may use `E` or `D` exponents and may sit anywhere inside their 7 columns.
//!
//! Stricter than Fortran: a blank field where a number is due is an error (Fortran reads it
//! as 0), and so is anything non-blank after a row's last value or after the moment table, so
//! that a header whose counts do not match the table is caught.
//!
//! # Free layout
//!
//! MBDyn's free-format variant (`read_c81_data_free_format`), detected when the first line
//! starts with `# FREE FORMAT` (then skipped) or the header line contains `;`:
//!
//! ```text
//! name; ML NL MD ND MM NM
//! ML Mach numbers, then NL rows of alpha followed by ML coefficients,
//! MD Mach numbers, then ND rows of alpha and MD coefficients, then the moment table likewise
//! ```
//!
//! All numbers after the header are whitespace-separated and may be split over lines freely
//! (data/airfoils/ThinAirfoil2.c81 puts one row a line).
//!
//! In both layouts the angles of attack and the Mach numbers of each table must increase
//! strictly. Errors name the file, the 1-based line and the 1-based columns (fixed layout) or
//! field number on the line (free layout), and what was expected.
use std::path::Path;

/// Which edges of a [`Table2`] a query was clamped to.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Clamp {
    /// Angle of attack below the table's first one.
    pub alpha_low: bool,
    /// Angle of attack above the table's last one.
    pub alpha_high: bool,
    /// Mach number below the table's first one.
    pub mach_low: bool,
    /// Mach number above the table's last one.
    pub mach_high: bool,
}

impl Clamp {
    /// Whether any edge clamped.
    pub fn any(self) -> bool {
        self.alpha_low || self.alpha_high || self.mach_low || self.mach_high
    }

    /// The edges clamped in either.
    pub fn or(self, other: Clamp) -> Clamp {
        Clamp {
            alpha_low: self.alpha_low || other.alpha_low,
            alpha_high: self.alpha_high || other.alpha_high,
            mach_low: self.mach_low || other.mach_low,
            mach_high: self.mach_high || other.mach_high,
        }
    }
}

/// One coefficient tabulated on an (angle of attack, Mach) grid.
#[derive(Clone, Debug, PartialEq)]
pub struct Table2 {
    /// Mach numbers, strictly increasing.
    pub mach: Vec<f64>,
    /// Angles of attack (deg), strictly increasing.
    pub alpha_deg: Vec<f64>,
    /// Alpha-major: `values[i_alpha * mach.len() + i_mach]`.
    pub values: Vec<f64>,
}

/// Where `x` falls on `grid`: the lower index, the fraction towards the next point (0 when
/// the grid has one point) and -1/0/1 for below/inside/above the grid.
fn locate(grid: &[f64], x: f64) -> (usize, f64, i8) {
    let n = grid.len();
    if x < grid[0] {
        return (0, 0.0, -1);
    }
    if x > grid[n - 1] {
        return if n == 1 { (0, 0.0, 1) } else { (n - 2, 1.0, 1) };
    }
    if n == 1 {
        // x equals the only point (or is NaN).
        return (0, if x.is_nan() { x } else { 0.0 }, 0);
    }
    if x.is_nan() {
        return (0, x, 0);
    }
    let k = grid.partition_point(|&g| g <= x);
    let i = k.saturating_sub(1).min(n - 2);
    (i, (x - grid[i]) / (grid[i + 1] - grid[i]), 0)
}

#[inline]
fn lerp(a: f64, b: f64, t: f64) -> f64 {
    // Exact at t = 0 and t = 1.
    (1.0 - t) * a + t * b
}

impl Table2 {
    /// Bilinear interpolation in (alpha, Mach); outside the grid the edge value is used (never
    /// extrapolated) and the returned [`Clamp`] says which edges clamped. Does not allocate.
    pub fn eval(&self, alpha_deg: f64, mach: f64) -> (f64, Clamp) {
        let nm = self.mach.len();
        let (i, ta, ca) = locate(&self.alpha_deg, alpha_deg);
        let (j, tm, cm) = locate(&self.mach, mach);
        let i1 = if self.alpha_deg.len() > 1 { i + 1 } else { i };
        let j1 = if nm > 1 { j + 1 } else { j };
        let v = |a: usize, m: usize| self.values[a * nm + m];
        let lo = lerp(v(i, j), v(i, j1), tm);
        let hi = lerp(v(i1, j), v(i1, j1), tm);
        let clamp = Clamp {
            alpha_low: ca < 0,
            alpha_high: ca > 0,
            mach_low: cm < 0,
            mach_high: cm > 0,
        };
        (lerp(lo, hi, ta), clamp)
    }

    /// The value at grid point (i_alpha, i_mach).
    pub fn at(&self, i_alpha: usize, i_mach: usize) -> f64 {
        self.values[i_alpha * self.mach.len() + i_mach]
    }
}

/// A C81 aerofoil table: lift, drag and moment coefficients.
#[derive(Clone, Debug, PartialEq)]
pub struct C81Table {
    /// The name in the header (columns 1-30, or before `;`), trailing blanks removed.
    pub name: String,
    /// Lift coefficient.
    pub cl: Table2,
    /// Drag coefficient.
    pub cd: Table2,
    /// Pitching-moment coefficient.
    pub cm: Table2,
    /// The file it was read from (as given to [`C81Table::parse`]).
    pub source: String,
}

/// A C81 table that cannot be read.
#[derive(Debug, thiserror::Error)]
pub enum C81Error {
    /// The file cannot be read.
    #[error("aerofoil table {file}: cannot read: {reason}")]
    Read {
        /// The file.
        file: String,
        /// The operating system's reason.
        reason: String,
    },
    /// A field holds something else than expected.
    #[error("{file} line {line}, {at}: expected {expected}, found {found}")]
    Field {
        /// The file.
        file: String,
        /// 1-based line.
        line: usize,
        /// Where on the line: `columns 31-37` or `field 3 (columns 12-19)`.
        at: String,
        /// What was expected.
        expected: String,
        /// What was found, quoted in backticks, or `a blank field`.
        found: String,
    },
    /// The file ends before the table does.
    #[error("{file} line {line}: expected {expected}, found the end of the file")]
    Truncated {
        /// The file.
        file: String,
        /// 1-based line where the missing data should be (one past the last line).
        line: usize,
        /// What was expected.
        expected: String,
    },
}

/// The fixed layout's field width.
const W: usize = 7;

/// The `k`-th (0-based) 7-column field of a line, with its 1-based first column.
fn fixed_field(chars: &[char], k: usize) -> (String, usize) {
    let a = (k * W).min(chars.len());
    let b = ((k + 1) * W).min(chars.len());
    (chars[a..b].iter().collect(), k * W + 1)
}

fn quote(s: &str) -> String {
    if s.trim().is_empty() {
        "a blank field".to_string()
    } else {
        format!("`{}`", s.trim())
    }
}

/// Parses a Fortran-style real: `1.`, `.5`, `-1.2E-3`, `1.2D-3`; finite only.
fn parse_real(s: &str) -> Option<f64> {
    let t = s.trim();
    if t.is_empty() {
        return None;
    }
    let ok = t
        .chars()
        .all(|c| c.is_ascii_digit() || matches!(c, '.' | '+' | '-' | 'e' | 'E' | 'd' | 'D'));
    if !ok {
        return None;
    }
    t.replace(['d', 'D'], "E")
        .parse::<f64>()
        .ok()
        .filter(|v| v.is_finite())
}

/// The three tables' names, for messages.
const TABLES: [&str; 3] = ["lift", "drag", "moment"];

struct Counts {
    /// (Mach count, alpha count) per table.
    n: [(usize, usize); 3],
}

/// A number read from the file with its position, for the ordering checks.
struct Num {
    value: f64,
    line: usize,
    at: String,
    text: String,
}

/// The fixed-layout reader: a cursor over the lines.
struct Fixed<'a> {
    file: &'a str,
    lines: Vec<&'a str>,
    next: usize,
}

impl<'a> Fixed<'a> {
    fn next_line(&mut self, expected: &str) -> Result<(usize, Vec<char>), C81Error> {
        match self.lines.get(self.next) {
            Some(l) => {
                self.next += 1;
                Ok((self.next, l.chars().collect()))
            }
            None => Err(C81Error::Truncated {
                file: self.file.to_string(),
                line: self.lines.len() + 1,
                expected: expected.to_string(),
            }),
        }
    }

    fn field_error(&self, line: usize, at: String, expected: &str, found: &str) -> C81Error {
        C81Error::Field {
            file: self.file.to_string(),
            line,
            at,
            expected: expected.to_string(),
            found: quote(found),
        }
    }

    /// Reads one record of `need` numbers: a Mach row (`skip_first`: columns 1-7 ignored) or
    /// an alpha row. `what` names the record for messages; `value_name(k)` names value k.
    fn record(
        &mut self,
        need: usize,
        skip_first: bool,
        what: &str,
        value_name: &dyn Fn(usize) -> String,
    ) -> Result<Vec<Num>, C81Error> {
        let mut out: Vec<Num> = Vec::with_capacity(need);
        let (mut line, mut chars) = self.next_line(what)?;
        let mut first_line = true;
        loop {
            let k0 = if first_line && !skip_first { 0 } else { 1 };
            let mut last_col = k0 * W;
            for k in k0..10 {
                if out.len() == need {
                    break;
                }
                let (text, col) = fixed_field(&chars, k);
                let at = format!("columns {}-{}", col, col + W - 1);
                let expected = format!("a number ({})", value_name(out.len()));
                let value = parse_real(&text)
                    .ok_or_else(|| self.field_error(line, at.clone(), &expected, &text))?;
                out.push(Num {
                    value,
                    line,
                    at,
                    text: text.trim().to_string(),
                });
                last_col = (k + 1) * W;
            }
            let rest: String = chars.iter().skip(last_col).collect();
            if out.len() == need {
                if !rest.trim().is_empty() {
                    let lead = rest.len() - rest.trim_start().len();
                    let col = last_col + lead + 1;
                    let tok = rest.split_whitespace().next().unwrap_or("");
                    return Err(self.field_error(
                        line,
                        format!("column {col}"),
                        &format!("the end of the {what} after its {need} values"),
                        tok,
                    ));
                }
                return Ok(out);
            }
            if last_col == 10 * W && !rest.trim().is_empty() {
                // Continuation joined onto the row after column 70: whitespace-separated.
                let mut col = 10 * W;
                let mut s = rest.as_str();
                while !s.trim().is_empty() {
                    let lead = s.len() - s.trim_start().len();
                    s = &s[lead..];
                    let len = s.find(char::is_whitespace).unwrap_or(s.len());
                    let tok = &s[..len];
                    let start = col + lead + 1;
                    let at = format!("columns {}-{}", start, start + tok.chars().count() - 1);
                    if out.len() == need {
                        return Err(self.field_error(
                            line,
                            at,
                            &format!("the end of the {what} after its {need} values"),
                            tok,
                        ));
                    }
                    let expected = format!("a number ({})", value_name(out.len()));
                    let value = parse_real(tok)
                        .ok_or_else(|| self.field_error(line, at.clone(), &expected, tok))?;
                    out.push(Num {
                        value,
                        line,
                        at,
                        text: tok.to_string(),
                    });
                    col = start - 1 + tok.chars().count();
                    s = &s[len..];
                }
                if out.len() < need {
                    return Err(self.field_error(
                        line,
                        format!("column {}", col + 1),
                        &format!(
                            "{} more values of the {what} ({} of {need})",
                            need - out.len(),
                            value_name(out.len())
                        ),
                        "",
                    ));
                }
                return Ok(out);
            }
            // Continuation line.
            let (l, c) = self.next_line(&format!(
                "a continuation line of the {what} ({})",
                value_name(out.len())
            ))?;
            line = l;
            chars = c;
            first_line = false;
        }
    }
}

/// The free-layout reader: a stream of whitespace-separated tokens.
struct Free<'a> {
    file: &'a str,
    /// (1-based line, 1-based field on the line, 1-based first column, text)
    tokens: Vec<(usize, usize, usize, &'a str)>,
    next: usize,
    last_line: usize,
}

impl<'a> Free<'a> {
    fn new(file: &'a str, lines: &[&'a str], first: usize) -> Self {
        let mut tokens = Vec::new();
        for (n, l) in lines.iter().enumerate().skip(first) {
            let mut field = 0;
            let mut col = 0;
            let mut s = *l;
            while !s.trim().is_empty() {
                let lead = s.len() - s.trim_start().len();
                col += s[..lead].chars().count();
                s = &s[lead..];
                let len = s.find(char::is_whitespace).unwrap_or(s.len());
                field += 1;
                tokens.push((n + 1, field, col + 1, &s[..len]));
                col += s[..len].chars().count();
                s = &s[len..];
            }
        }
        Free {
            file,
            tokens,
            next: 0,
            last_line: lines.len(),
        }
    }

    fn number(&mut self, expected: &str) -> Result<Num, C81Error> {
        let Some(&(line, field, col, text)) = self.tokens.get(self.next) else {
            return Err(C81Error::Truncated {
                file: self.file.to_string(),
                line: self.last_line + 1,
                expected: expected.to_string(),
            });
        };
        self.next += 1;
        let at = format!(
            "field {field} (columns {col}-{})",
            col + text.chars().count() - 1
        );
        match parse_real(text) {
            Some(value) => Ok(Num {
                value,
                line,
                at,
                text: text.to_string(),
            }),
            None => Err(C81Error::Field {
                file: self.file.to_string(),
                line,
                at,
                expected: expected.to_string(),
                found: quote(text),
            }),
        }
    }
}

/// Checks that `nums` increase strictly.
fn check_increasing(file: &str, nums: &[Num], what: &str, unit: &str) -> Result<(), C81Error> {
    for w in nums.windows(2) {
        if w[1].value <= w[0].value {
            return Err(C81Error::Field {
                file: file.to_string(),
                line: w[1].line,
                at: w[1].at.clone(),
                expected: format!(
                    "{what} above the previous one, {}{unit} (line {}), as they must increase",
                    w[0].text, w[0].line
                ),
                found: format!("`{}`", w[1].text),
            });
        }
    }
    Ok(())
}

/// Builds a table from its Mach row and its alpha rows (each alpha then the coefficients).
fn build(file: &str, table: &str, mach: Vec<Num>, rows: Vec<Vec<Num>>) -> Result<Table2, C81Error> {
    check_increasing(file, &mach, &format!("a {table} table Mach number"), "")?;
    let mut alphas = Vec::with_capacity(rows.len());
    let mut values = Vec::with_capacity(rows.len() * mach.len());
    for mut r in rows {
        let rest = r.split_off(1);
        alphas.push(r.pop().expect("a row has its angle of attack"));
        values.extend(rest.iter().map(|n| n.value));
    }
    check_increasing(
        file,
        &alphas,
        &format!("a {table} table angle of attack"),
        " deg",
    )?;
    Ok(Table2 {
        mach: mach.iter().map(|n| n.value).collect(),
        alpha_deg: alphas.iter().map(|n| n.value).collect(),
        values,
    })
}

/// The aerofoil's name, the six counts ML NL MD ND MM NM, whether the file is free-format and
/// the header's line number, from the header line.
fn header_counts(
    file: &str,
    header: &str,
    first: usize,
) -> Result<(String, [usize; 6], bool, usize), C81Error> {
    let header_line = first + 1;
    let count_names = ["ML", "NL", "MD", "ND", "MM", "NM"];
    let count_error = |at: String, k: usize, found: &str| C81Error::Field {
        file: file.to_string(),
        line: header_line,
        at,
        expected: format!(
            "the count {} ({} of the {} table), a whole number of at least 1",
            count_names[k],
            if k.is_multiple_of(2) {
                "Mach numbers"
            } else {
                "angles of attack"
            },
            TABLES[k / 2]
        ),
        found: quote(found),
    };
    let mut n = [0usize; 6];
    let free = first == 1 || header.contains(';');
    let name;
    if free {
        let Some((nm, rest)) = header.split_once(';') else {
            return Err(C81Error::Field {
                file: file.to_string(),
                line: header_line,
                at: "column 1".to_string(),
                expected: "a free-format header `name; ML NL MD ND MM NM`".to_string(),
                found: quote(header),
            });
        };
        name = nm.trim().to_string();
        let toks = Free::new(file, &[rest], 0).tokens;
        let offset = nm.chars().count() + 1;
        for (k, slot) in n.iter_mut().enumerate() {
            let Some(&(_, _, col, text)) = toks.get(k) else {
                let c = header.chars().count() + 1;
                return Err(count_error(format!("column {c}"), k, ""));
            };
            let at = format!(
                "columns {}-{}",
                col + offset,
                col + offset + text.chars().count() - 1
            );
            *slot = text
                .parse::<usize>()
                .ok()
                .filter(|&v| v >= 1)
                .ok_or_else(|| count_error(at, k, text))?;
        }
        if let Some(&(_, _, col, text)) = toks.get(6) {
            return Err(C81Error::Field {
                file: file.to_string(),
                line: header_line,
                at: format!(
                    "columns {}-{}",
                    col + offset,
                    col + offset + text.chars().count() - 1
                ),
                expected: "the end of the header after its six counts".to_string(),
                found: quote(text),
            });
        }
    } else {
        let chars: Vec<char> = header.chars().collect();
        name = chars.iter().take(30).collect::<String>().trim().to_string();
        for (k, slot) in n.iter_mut().enumerate() {
            let a = (30 + 2 * k).min(chars.len());
            let b = (32 + 2 * k).min(chars.len());
            let text: String = chars[a..b].iter().collect();
            let at = format!("columns {}-{}", 31 + 2 * k, 32 + 2 * k);
            *slot = text
                .trim()
                .parse::<usize>()
                .ok()
                .filter(|&v| v >= 1)
                .ok_or_else(|| count_error(at, k, &text))?;
        }
    }
    Ok((name, n, free, header_line))
}

/// The three tables of a free-format file, after its header.
fn free_tables(
    file: &str,
    lines: &[&str],
    header_line: usize,
    counts: &Counts,
) -> Result<Vec<Table2>, C81Error> {
    let mut tables = Vec::with_capacity(3);
    let mut rd = Free::new(file, lines, header_line);
    for (t, &(nm, na)) in counts.n.iter().enumerate() {
        let table = TABLES[t];
        let mut mach = Vec::with_capacity(nm);
        for j in 0..nm {
            mach.push(rd.number(&format!(
                "a number (the {table} table's Mach number {} of {nm})",
                j + 1
            ))?);
        }
        let mut rows = Vec::with_capacity(na);
        for i in 0..na {
            let mut row = Vec::with_capacity(nm + 1);
            row.push(rd.number(&format!(
                "a number (the {table} table's angle of attack of row {} of {na})",
                i + 1
            ))?);
            for j in 0..nm {
                row.push(rd.number(&format!(
                    "a number (the {table} table's row {} of {na}, coefficient {} of {nm})",
                    i + 1,
                    j + 1
                ))?);
            }
            rows.push(row);
        }
        tables.push(build(file, table, mach, rows)?);
    }
    if let Some(&(line, field, col, text)) = rd.tokens.get(rd.next) {
        return Err(C81Error::Field {
            file: file.to_string(),
            line,
            at: format!(
                "field {field} (columns {col}-{})",
                col + text.chars().count() - 1
            ),
            expected: "the end of the file after the moment table".to_string(),
            found: quote(text),
        });
    }
    Ok(tables)
}

/// The three tables of a fixed-format (C81 columns) file, after its header.
fn fixed_tables(
    file: &str,
    lines: &[&str],
    header_line: usize,
    counts: &Counts,
) -> Result<Vec<Table2>, C81Error> {
    let mut tables = Vec::with_capacity(3);
    let mut rd = Fixed {
        file,
        lines: lines.to_vec(),
        next: header_line,
    };
    for (t, &(nm, na)) in counts.n.iter().enumerate() {
        let table = TABLES[t];
        let mach = rd.record(nm, true, &format!("{table} table's Mach row"), &|j| {
            format!("Mach number {} of {nm}", j + 1)
        })?;
        let mut rows = Vec::with_capacity(na);
        for i in 0..na {
            let row = rd.record(
                nm + 1,
                false,
                &format!("{table} table's row {} of {na}", i + 1),
                &|k| {
                    if k == 0 {
                        "the angle of attack".to_string()
                    } else {
                        format!("coefficient {k} of {nm}")
                    }
                },
            )?;
            rows.push(row);
        }
        tables.push(build(file, table, mach, rows)?);
    }
    for (k, l) in lines.iter().enumerate().skip(rd.next) {
        if !l.trim().is_empty() {
            let lead = l.len() - l.trim_start().len();
            return Err(C81Error::Field {
                file: file.to_string(),
                line: k + 1,
                at: format!("column {}", l[..lead].chars().count() + 1),
                expected: "the end of the file after the moment table".to_string(),
                found: quote(l.split_whitespace().next().unwrap_or("")),
            });
        }
    }
    Ok(tables)
}

impl C81Table {
    /// Reads a C81 table from its text; `file` names it in messages and in `source`.
    pub fn parse(text: &str, file: &str) -> Result<Self, C81Error> {
        let lines: Vec<&str> = text
            .split('\n')
            .map(|l| l.strip_suffix('\r').unwrap_or(l))
            .collect();
        // A final newline leaves an empty last piece, not a line.
        let lines: Vec<&str> = match lines.split_last() {
            Some((&"", init)) => init.to_vec(),
            _ => lines,
        };
        let mut first = 0;
        if lines.first().is_some_and(|l| {
            l.trim_start()
                .to_ascii_uppercase()
                .starts_with("# FREE FORMAT")
        }) {
            first = 1;
        }
        let Some(header) = lines.get(first) else {
            return Err(C81Error::Truncated {
                file: file.to_string(),
                line: first + 1,
                expected: "the header (aerofoil name and the six counts ML NL MD ND MM NM)"
                    .to_string(),
            });
        };
        let (name, n, free, header_line) = header_counts(file, header, first)?;
        let counts = Counts {
            n: [(n[0], n[1]), (n[2], n[3]), (n[4], n[5])],
        };

        let mut tables = if free {
            free_tables(file, &lines, header_line, &counts)?
        } else {
            fixed_tables(file, &lines, header_line, &counts)?
        };
        let cm = tables.pop().expect("three tables");
        let cd = tables.pop().expect("three tables");
        let cl = tables.pop().expect("three tables");
        Ok(C81Table {
            name,
            cl,
            cd,
            cm,
            source: file.to_string(),
        })
    }

    /// Reads a C81 table from a file; messages name the file as given.
    pub fn from_file(path: &Path) -> Result<Self, C81Error> {
        let file = path.display().to_string();
        let text = std::fs::read_to_string(path).map_err(|e| {
            let reason = e.to_string();
            let reason = match reason.find(" (os error") {
                Some(i) => reason[..i].to_string(),
                None => reason,
            };
            C81Error::Read {
                file: file.clone(),
                reason,
            }
        })?;
        Self::parse(&text, &file)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn locate_inside_and_at_edges() {
        let g = [0.0, 1.0, 3.0];
        assert_eq!(locate(&g, 0.0), (0, 0.0, 0));
        assert_eq!(locate(&g, 1.0), (1, 0.0, 0));
        assert_eq!(locate(&g, 2.0), (1, 0.5, 0));
        assert_eq!(locate(&g, 3.0), (1, 1.0, 0));
        assert_eq!(locate(&g, -1.0), (0, 0.0, -1));
        assert_eq!(locate(&g, 4.0), (1, 1.0, 1));
        assert_eq!(locate(&[2.0], 2.0), (0, 0.0, 0));
        assert_eq!(locate(&[2.0], 5.0), (0, 0.0, 1));
    }

    #[test]
    fn fortran_reals() {
        assert_eq!(parse_real("  .20  "), Some(0.2));
        assert_eq!(parse_real("-1.    "), Some(-1.0));
        assert_eq!(parse_real("1.5D-2"), Some(0.015));
        assert_eq!(parse_real("       "), None);
        assert_eq!(parse_real("0.1x3"), None);
        assert_eq!(parse_real("inf"), None);
    }

    #[test]
    fn single_mach_column() {
        let t = Table2 {
            mach: vec![0.3],
            alpha_deg: vec![0.0, 10.0],
            values: vec![0.0, 1.0],
        };
        let (v, c) = t.eval(5.0, 0.3);
        assert_eq!(v, 0.5);
        assert!(!c.any());
        let (v, c) = t.eval(5.0, 0.5);
        assert_eq!(v, 0.5);
        assert!(c.mach_high && !c.mach_low && !c.alpha_low && !c.alpha_high);
    }
}
