//! The CSV triple: `STEM.meta.json`, `STEM.airloads.csv`, `STEM.damper.csv` (docs/formats.md),
//! and the optional `STEM.motion.csv` (the measured rigid blade motion).
//!
//! Reading converts alternate units to SI (units.rs); writing is always SI with shortest
//! round-trip number formatting, so CSV -> MCAP -> CSV gives back every value bit for bit.
use super::motion::{MotionAssembler, MOTION_COLUMNS};
use super::record::{AirloadAssembler, DamperSample, FlightMeta, FlightRecord, Loc};
use super::units::{self, Quantity, Unit};
use super::FlightError;
use std::path::{Path, PathBuf};

fn with_suffix(stem: &Path, suffix: &str) -> PathBuf {
    PathBuf::from(format!("{}{suffix}", stem.to_string_lossy()))
}

fn read_text(path: &Path) -> Result<String, FlightError> {
    std::fs::read_to_string(path).map_err(|source| FlightError::Io {
        path: path.to_path_buf(),
        source,
    })
}

/// Reads the CSV triple of `stem`.
pub fn read_csv(stem: &Path) -> Result<FlightRecord, FlightError> {
    let meta_path = with_suffix(stem, ".meta.json");
    let meta = FlightMeta::from_json_str(&read_text(&meta_path)?, &meta_path)?;
    let air_path = with_suffix(stem, ".airloads.csv");
    let rows = parse_airloads(open(&air_path)?, &air_path, &meta)?;
    let damp_path = with_suffix(stem, ".damper.csv");
    let (damper, locs) = parse_damper(open(&damp_path)?, &damp_path)?;
    let mut rec = FlightRecord::from_rows(meta, rows, &air_path, damper, &locs, &damp_path)?;
    let motion_path = with_suffix(stem, ".motion.csv");
    if motion_path.is_file() {
        rec.motion = Some(parse_motion(
            open(&motion_path)?,
            &motion_path,
            rec.azimuths_deg(),
        )?);
    }
    Ok(rec)
}

/// Parses `STEM.motion.csv` against the airloads' azimuth grid `grid` [deg]. Every error names
/// the file, the line and the column.
pub(crate) fn parse_motion(
    src: impl std::io::Read,
    path: &Path,
    grid: &[f64],
) -> Result<super::BladeMotion, FlightError> {
    let line_err = |line: u64, column: &str, msg: String| FlightError::Line {
        path: path.to_path_buf(),
        line,
        msg: format!("column `{column}`: {msg}"),
    };
    let expected = MOTION_COLUMNS.join(",");
    let mut rd = csv::ReaderBuilder::new()
        .has_headers(true)
        .trim(csv::Trim::All)
        .flexible(true)
        .from_reader(src);
    let header = rd.headers().map_err(|e| csv_err(path, e))?.clone();
    let mut idx = [usize::MAX; 5];
    for (col, name) in header.iter().enumerate() {
        let name = name.trim().trim_start_matches('\u{feff}');
        let Some(k) = MOTION_COLUMNS.iter().position(|c| *c == name) else {
            return Err(line_err(
                1,
                name,
                format!("unexpected column (column {}); expected the header {expected} (angles in degrees)", col + 1),
            ));
        };
        if idx[k] != usize::MAX {
            return Err(line_err(1, name, "given twice".into()));
        }
        idx[k] = col;
    }
    if let Some(k) = idx.iter().position(|&i| i == usize::MAX) {
        return Err(line_err(
            1,
            MOTION_COLUMNS[k],
            format!("missing; expected the header {expected}"),
        ));
    }
    let mut asm = MotionAssembler::new(grid);
    let mut rec = csv::ByteRecord::new();
    let mut last_line = 1;
    loop {
        match rd.read_byte_record(&mut rec) {
            Ok(true) => {}
            Ok(false) => break,
            Err(e) => return Err(csv_err(path, e)),
        }
        let line = rec.position().map_or(0, |p| p.line());
        last_line = line;
        if rec.len() != header.len() {
            // The first column the row lacks (or the one too many).
            let column = header
                .get(rec.len().min(header.len()))
                .map(|c| format!("`{c}` missing"))
                .unwrap_or_else(|| "an extra field beyond the header".into());
            return Err(FlightError::Line {
                path: path.to_path_buf(),
                line,
                msg: format!(
                    "{} fields, expected {} ({expected}): column {column}",
                    rec.len(),
                    header.len()
                ),
            });
        }
        let f = |k: usize| field(&rec, idx[k], path, line, MOTION_COLUMNS[k]);
        let rev = parse_rev(f(0)?, path, line)?;
        let psi = parse_azimuth(f(1)?, path, line)?;
        let v = [
            parse_f64(f(2)?, path, line, MOTION_COLUMNS[2])?,
            parse_f64(f(3)?, path, line, MOTION_COLUMNS[3])?,
            parse_f64(f(4)?, path, line, MOTION_COLUMNS[4])?,
        ];
        asm.push(rev, psi, v)
            .map_err(|e| line_err(line, e.column, e.msg))?;
    }
    asm.finish().map_err(|msg| FlightError::Line {
        path: path.to_path_buf(),
        line: last_line,
        msg: if msg == "no motion rows" {
            format!("no motion rows after the header; expected rows of {expected}")
        } else {
            format!("column `revolution`: {msg} (the last row)")
        },
    })
}

/// Column layout of a header: index of each required column and its unit.
struct Columns {
    idx: Vec<usize>,
    units: Vec<Option<Unit>>,
}

/// Maps header names to the wanted columns; `fixed` are unit-less columns, `quantities` carry a
/// unit; `optional` quantities may be absent.
fn map_header(
    header: &csv::StringRecord,
    path: &Path,
    fixed: &[&str],
    quantities: &[(Quantity, bool)],
) -> Result<Columns, FlightError> {
    let n = fixed.len() + quantities.len();
    let mut idx = vec![usize::MAX; n];
    let mut unit_of = vec![None; n];
    let expected = || {
        let mut v: Vec<String> = fixed.iter().map(|s| s.to_string()).collect();
        v.extend(quantities.iter().map(|(q, _)| q.si_column().to_string()));
        v.join(",")
    };
    for (col, name) in header.iter().enumerate() {
        let name = name.trim().trim_start_matches('\u{feff}'); // a UTF-8 byte-order mark
        let slot = if let Some(k) = fixed.iter().position(|f| *f == name) {
            k
        } else if let Some((q, suffix)) = units::split_column(name) {
            let Some(k) = quantities.iter().position(|(qq, _)| *qq == q) else {
                return Err(FlightError::Line {
                    path: path.to_path_buf(),
                    line: 1,
                    msg: format!(
                        "unexpected column `{name}` in this file; expected the header {}",
                        expected()
                    ),
                });
            };
            let unit = units::parse_unit(q, suffix).ok_or_else(|| FlightError::UnknownUnit {
                path: path.to_path_buf(),
                column: name.into(),
                unit: suffix.into(),
                expected: q
                    .units()
                    .iter()
                    .map(|u| format!("{}{u}", q.prefix()))
                    .collect::<Vec<_>>()
                    .join(", "),
            })?;
            unit_of[fixed.len() + k] = Some(unit);
            fixed.len() + k
        } else {
            return Err(FlightError::Line {
                path: path.to_path_buf(),
                line: 1,
                msg: format!(
                    "unexpected column `{name}`; expected the header {}",
                    expected()
                ),
            });
        };
        if idx[slot] != usize::MAX {
            return Err(FlightError::Line {
                path: path.to_path_buf(),
                line: 1,
                msg: format!("column `{name}` given twice (possibly in two units)"),
            });
        }
        idx[slot] = col;
    }
    for (k, &i) in idx.iter().enumerate() {
        let required = k < fixed.len() || quantities[k - fixed.len()].1;
        if i == usize::MAX && required {
            let name = if k < fixed.len() {
                fixed[k].to_string()
            } else {
                quantities[k - fixed.len()].0.si_column().to_string()
            };
            return Err(FlightError::Line {
                path: path.to_path_buf(),
                line: 1,
                msg: format!(
                    "missing column `{name}` (or an accepted unit variant); expected the header {}",
                    expected()
                ),
            });
        }
    }
    Ok(Columns {
        idx,
        units: unit_of,
    })
}

fn open(path: &Path) -> Result<std::fs::File, FlightError> {
    std::fs::File::open(path).map_err(|source| FlightError::Io {
        path: path.to_path_buf(),
        source,
    })
}

/// A CSV reader over any byte source (files are read as they are parsed, not loaded whole).
fn reader<R: std::io::Read>(src: R) -> csv::Reader<R> {
    csv::ReaderBuilder::new()
        .has_headers(true)
        .trim(csv::Trim::All)
        .flexible(false)
        .buffer_capacity(1 << 16)
        .from_reader(src)
}

fn csv_err(path: &Path, e: csv::Error) -> FlightError {
    let line = e.position().map_or(0, |p| p.line());
    FlightError::Line {
        path: path.to_path_buf(),
        line,
        msg: match e.kind() {
            csv::ErrorKind::UnequalLengths {
                expected_len, len, ..
            } => format!("{len} fields, expected {expected_len} (as in the header)"),
            _ => format!("{e}"),
        },
    }
}

fn field<'a>(
    rec: &'a csv::ByteRecord,
    i: usize,
    path: &Path,
    line: u64,
    name: &str,
) -> Result<&'a str, FlightError> {
    let b = rec.get(i).unwrap_or_default();
    std::str::from_utf8(b).map_err(|_| FlightError::Line {
        path: path.to_path_buf(),
        line,
        msg: format!("column `{name}`: not UTF-8 text"),
    })
}

fn parse_f64(s: &str, path: &Path, line: u64, name: &str) -> Result<f64, FlightError> {
    match s.parse::<f64>() {
        Ok(x) if x.is_finite() => Ok(x),
        Ok(x) => Err(FlightError::Line {
            path: path.to_path_buf(),
            line,
            msg: format!("column `{name}`: {x} is not a finite number"),
        }),
        Err(_) => Err(FlightError::Line {
            path: path.to_path_buf(),
            line,
            msg: format!("column `{name}`: expected a number, found `{s}`"),
        }),
    }
}

fn parse_rev(s: &str, path: &Path, line: u64) -> Result<u32, FlightError> {
    s.parse::<u32>().map_err(|_| FlightError::Line {
        path: path.to_path_buf(),
        line,
        msg: format!("column `revolution`: expected a whole number >= 0, found `{s}`"),
    })
}

fn parse_azimuth(s: &str, path: &Path, line: u64) -> Result<f64, FlightError> {
    let psi = parse_f64(s, path, line, "azimuth_deg")?;
    if !(0.0..360.0).contains(&psi) {
        return Err(FlightError::Line {
            path: path.to_path_buf(),
            line,
            msg: format!("column `azimuth_deg`: {psi} is outside [0, 360)"),
        });
    }
    Ok(psi)
}

const AIR_FIXED: [&str; 3] = ["revolution", "azimuth_deg", "r_over_R"];

/// Parses `STEM.airloads.csv` into SI rows.
pub(crate) fn parse_airloads(
    src: impl std::io::Read,
    path: &Path,
    meta: &FlightMeta,
) -> Result<AirloadAssembler, FlightError> {
    let mut rd = reader(src);
    let header = rd.headers().map_err(|e| csv_err(path, e))?.clone();
    let q = [
        (Quantity::NormalForce, true),
        (Quantity::ChordForce, true),
        (Quantity::PitchingMoment, true),
    ];
    let cols = map_header(&header, path, &AIR_FIXED, &q)?;
    let needs_mach = cols.units.contains(&Some(Unit::MachSquaredCoefficient));
    let (q_c, chord) = if needs_mach {
        meta.mach_squared_scale(path)?
    } else {
        (0.0, 0.0)
    };
    let factor: Vec<f64> = (0..3)
        .map(|k| cols.units[3 + k].map_or(1.0, |u| u.factor(q[k].0, q_c, chord)))
        .collect();
    let names: Vec<&str> = cols.idx.iter().map(|&i| &header[i]).collect();
    let mut rows = AirloadAssembler::new(true);
    let mut rec = csv::ByteRecord::new();
    loop {
        match rd.read_byte_record(&mut rec) {
            Ok(true) => {}
            Ok(false) => break,
            Err(e) => return Err(csv_err(path, e)),
        }
        let line = rec.position().map_or(0, |p| p.line());
        let f = |k: usize| field(&rec, cols.idx[k], path, line, names[k]);
        let rev = parse_rev(f(0)?, path, line)?;
        let psi = parse_azimuth(f(1)?, path, line)?;
        let r = parse_f64(f(2)?, path, line, "r_over_R")?;
        if !(r > 0.0 && r <= 1.0) {
            return Err(FlightError::Line {
                path: path.to_path_buf(),
                line,
                msg: format!("column `r_over_R`: {r} is outside (0, 1]"),
            });
        }
        // x * 1.0 == x exactly, so SI columns pass through bit for bit.
        let v = |k: usize| -> Result<f64, FlightError> {
            Ok(parse_f64(f(k)?, path, line, names[k])? * factor[k - 3])
        };
        rows.push(rev, psi, r, [v(3)?, v(4)?, v(5)?], line);
    }
    if rows.is_empty() {
        return Err(FlightError::Invalid {
            path: path.to_path_buf(),
            msg: "no airload rows after the header".into(),
        });
    }
    Ok(rows)
}

const DAMP_FIXED: [&str; 2] = ["revolution", "azimuth_deg"];

/// Parses `STEM.damper.csv` into SI samples, with the line of each.
pub(crate) fn parse_damper(
    src: impl std::io::Read,
    path: &Path,
) -> Result<(Vec<DamperSample>, Vec<Loc>), FlightError> {
    let mut rd = reader(src);
    let header = rd.headers().map_err(|e| csv_err(path, e))?.clone();
    let q = [
        (Quantity::DamperForce, true),
        (Quantity::DamperStroke, false),
    ];
    let cols = map_header(&header, path, &DAMP_FIXED, &q)?;
    let f_force = cols.units[2].map_or(1.0, |u| u.factor(Quantity::DamperForce, 0.0, 0.0));
    let f_stroke = cols.units[3].map_or(1.0, |u| u.factor(Quantity::DamperStroke, 0.0, 0.0));
    let has_stroke = cols.idx[3] != usize::MAX;
    let mut out = Vec::new();
    let mut locs = Vec::new();
    let mut rec = csv::ByteRecord::new();
    loop {
        match rd.read_byte_record(&mut rec) {
            Ok(true) => {}
            Ok(false) => break,
            Err(e) => return Err(csv_err(path, e)),
        }
        let line = rec.position().map_or(0, |p| p.line());
        let f = |k: usize| field(&rec, cols.idx[k], path, line, &header[cols.idx[k]]);
        let stroke = if has_stroke {
            Some(parse_f64(f(3)?, path, line, &header[cols.idx[3]])? * f_stroke)
        } else {
            None
        };
        out.push(DamperSample {
            revolution: parse_rev(f(0)?, path, line)?,
            azimuth_deg: parse_azimuth(f(1)?, path, line)?,
            force_N: parse_f64(f(2)?, path, line, &header[cols.idx[2]])? * f_force,
            stroke_m: stroke,
        });
        locs.push(Loc::Line(line));
    }
    if out.is_empty() {
        return Err(FlightError::Invalid {
            path: path.to_path_buf(),
            msg: "no damper samples after the header".into(),
        });
    }
    Ok((out, locs))
}

/// The metadata file text (pretty JSON, one key per line).
pub(crate) fn meta_text(rec: &FlightRecord) -> String {
    let mut s = serde_json::to_string_pretty(&serde_json::Value::Object(rec.meta.to_json()))
        .unwrap_or_default();
    s.push('\n');
    s
}

/// The airloads CSV text (SI).
pub(crate) fn airloads_text(rec: &FlightRecord) -> String {
    let header = [
        "revolution",
        "azimuth_deg",
        "r_over_R",
        Quantity::NormalForce.si_column(),
        Quantity::ChordForce.si_column(),
        Quantity::PitchingMoment.si_column(),
    ];
    let (st, az) = (rec.stations_r_over_r(), rec.azimuths_deg());
    let rows = rec
        .revolutions()
        .iter()
        .enumerate()
        .flat_map(move |(ir, &rev)| {
            az.iter().enumerate().flat_map(move |(ia, &psi)| {
                st.iter().enumerate().map(move |(is, &r)| {
                    let i = rec.index(ir, ia, is);
                    [
                        rev as f64,
                        psi,
                        r,
                        rec.normal_n_per_m()[i],
                        rec.chord_n_per_m()[i],
                        rec.moment_n_m_per_m()[i],
                    ]
                })
            })
        });
    crate::io::csv_string(&header, rows)
}

/// The damper CSV text (SI).
pub(crate) fn damper_text(rec: &FlightRecord) -> String {
    if rec.has_stroke() {
        crate::io::csv_string(
            &[
                "revolution",
                "azimuth_deg",
                "damper_force_N",
                "damper_stroke_m",
            ],
            rec.damper().iter().map(|s| {
                [
                    s.revolution as f64,
                    s.azimuth_deg,
                    s.force_N,
                    s.stroke_m.unwrap_or(f64::NAN),
                ]
            }),
        )
    } else {
        crate::io::csv_string(
            &["revolution", "azimuth_deg", "damper_force_N"],
            rec.damper()
                .iter()
                .map(|s| [s.revolution as f64, s.azimuth_deg, s.force_N]),
        )
    }
}

/// The motion CSV text [deg], or `None` for a record without motion.
pub(crate) fn motion_text(rec: &FlightRecord) -> Option<String> {
    let m = rec.motion.as_ref()?;
    let az = m.azimuths_deg();
    let rows = m
        .revolutions()
        .iter()
        .enumerate()
        .flat_map(move |(ir, &rev)| {
            az.iter().enumerate().map(move |(ia, &psi)| {
                let i = m.index(ir, ia);
                [
                    rev as f64,
                    psi,
                    m.flap_deg()[i],
                    m.lag_deg()[i],
                    m.pitch_deg()[i],
                ]
            })
        });
    Some(crate::io::csv_string(&MOTION_COLUMNS, rows))
}

/// Writes the triple atomically, file by file (each file is complete or absent), and
/// `STEM.motion.csv` when the record has a motion; without one, a `STEM.motion.csv` already
/// there is removed (else the stem would not read back as written).
pub fn write_csv(rec: &FlightRecord, stem: &Path) -> Result<(), FlightError> {
    let motion_path = with_suffix(stem, ".motion.csv");
    match motion_text(rec) {
        Some(text) => crate::io::write_atomic(&motion_path, text.as_bytes())?,
        None if motion_path.is_file() => {
            std::fs::remove_file(&motion_path).map_err(|source| FlightError::Io {
                path: motion_path.clone(),
                source,
            })?
        }
        None => {}
    }
    crate::io::write_atomic(
        &with_suffix(stem, ".airloads.csv"),
        airloads_text(rec).as_bytes(),
    )?;
    crate::io::write_atomic(
        &with_suffix(stem, ".damper.csv"),
        damper_text(rec).as_bytes(),
    )?;
    crate::io::write_atomic(&with_suffix(stem, ".meta.json"), meta_text(rec).as_bytes())?;
    Ok(())
}
