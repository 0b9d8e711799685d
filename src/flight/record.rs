//! The flight record: metadata, airloads on an (revolution, azimuth, station) grid, damper channel.
use super::motion::BladeMotion;
use super::FlightError;
use serde_json::{Map, Value};
use std::path::{Path, PathBuf};

/// Pilot controls [deg] of the record's metadata (`controls_deg`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ControlsDeg {
    pub collective: f64,
    pub lateral_cyclic: f64,
    pub longitudinal_cyclic: f64,
}

/// Metadata of a flight record (`NAME.meta.json` or the `/rotor/meta` MCAP message).
///
/// The known keys are typed; every key, known or not, is kept in [`FlightMeta::raw`] and written
/// back (docs/formats.md: extend, never break). On writing, the typed fields overwrite their raw keys.
#[derive(Debug, Clone, PartialEq)]
pub struct FlightMeta {
    pub counter: Option<String>,
    /// True when the record is not flight-test data; shown wherever the record is shown.
    pub synthetic: bool,
    pub description: Option<String>,
    pub rotor_speed_rad_s: f64,
    pub radius_m: f64,
    pub forward_speed_kt: Option<f64>,
    pub advance_ratio: Option<f64>,
    pub thrust_coefficient_over_solidity: Option<f64>,
    pub density_kg_m3: Option<f64>,
    pub speed_of_sound_m_s: Option<f64>,
    /// Blade chord (extension key `chord_m`), needed to convert M^2 C airloads.
    pub chord_m: Option<f64>,
    /// The damper's oil temperature during the record [K] (`damper_oil_temperature_K`): the
    /// diagnosis replays the damper at it where the deck has an oil law.
    pub damper_oil_temperature_k: Option<f64>,
    pub controls_deg: ControlsDeg,
    /// The whole metadata object as read, unknown keys included.
    pub raw: Map<String, Value>,
}

impl FlightMeta {
    /// Parses the metadata object; `path` names the file in errors.
    pub fn from_json(raw: Map<String, Value>, path: &Path) -> Result<Self, FlightError> {
        let err = |key: &str, msg: &str| FlightError::Meta {
            path: path.to_path_buf(),
            key: key.into(),
            msg: msg.into(),
        };
        let num = |key: &str, required: bool, positive: bool| -> Result<Option<f64>, FlightError> {
            match raw.get(key) {
                None | Some(Value::Null) if !required => Ok(None),
                None | Some(Value::Null) => Err(err(key, "missing; expected a number")),
                Some(v) => {
                    let x = v
                        .as_f64()
                        .ok_or_else(|| err(key, &format!("expected a number, found {v}")))?;
                    if !x.is_finite() || (positive && x <= 0.0) {
                        return Err(err(
                            key,
                            &format!(
                                "expected a finite{} number, found {x}",
                                if positive { " positive" } else { "" }
                            ),
                        ));
                    }
                    Ok(Some(x))
                }
            }
        };
        let string = |key: &str| -> Result<Option<String>, FlightError> {
            match raw.get(key) {
                None | Some(Value::Null) => Ok(None),
                Some(Value::String(s)) => Ok(Some(s.clone())),
                Some(v) => Err(err(key, &format!("expected a string, found {v}"))),
            }
        };
        let synthetic = match raw.get("synthetic") {
            Some(Value::Bool(b)) => *b,
            Some(v) => {
                return Err(err(
                    "synthetic",
                    &format!("expected true or false, found {v}"),
                ))
            }
            None => {
                return Err(err(
                    "synthetic",
                    "missing; expected true (synthetic data) or false (measured)",
                ))
            }
        };
        let controls = match raw.get("controls_deg") {
            Some(Value::Object(c)) => {
                let get = |k: &str| -> Result<f64, FlightError> {
                    let key = format!("controls_deg.{k}");
                    let v = c
                        .get(k)
                        .ok_or_else(|| err(&key, "missing; expected a number [deg]"))?;
                    v.as_f64()
                        .filter(|x| x.is_finite())
                        .ok_or_else(|| err(&key, &format!("expected a finite number, found {v}")))
                };
                ControlsDeg {
                    collective: get("collective")?,
                    lateral_cyclic: get("lateral_cyclic")?,
                    longitudinal_cyclic: get("longitudinal_cyclic")?,
                }
            }
            Some(v) => return Err(err("controls_deg", &format!("expected an object with collective, lateral_cyclic, longitudinal_cyclic, found {v}"))),
            None => return Err(err("controls_deg", "missing; expected an object with collective, lateral_cyclic, longitudinal_cyclic [deg]")),
        };
        Ok(Self {
            counter: string("counter")?,
            synthetic,
            description: string("description")?,
            rotor_speed_rad_s: num("rotor_speed_rad_s", true, true)?.unwrap_or_default(),
            radius_m: num("radius_m", true, true)?.unwrap_or_default(),
            forward_speed_kt: num("forward_speed_kt", false, false)?,
            advance_ratio: num("advance_ratio", false, false)?,
            thrust_coefficient_over_solidity: num(
                "thrust_coefficient_over_solidity",
                false,
                false,
            )?,
            density_kg_m3: num("density_kg_m3", false, true)?,
            speed_of_sound_m_s: num("speed_of_sound_m_s", false, true)?,
            chord_m: num("chord_m", false, true)?,
            damper_oil_temperature_k: {
                use crate::hydraulics::temperature as oil;
                let key = "damper_oil_temperature_K";
                match num(key, false, true)? {
                    Some(t) if !oil::is_oil_temperature_k(t) => {
                        return Err(err(
                            key,
                            &format!("expected {}, found {t}", oil::oil_temperature_expected()),
                        ))
                    }
                    t => t,
                }
            },
            controls_deg: controls,
            raw,
        })
    }

    /// Parses metadata JSON text.
    pub fn from_json_str(text: &str, path: &Path) -> Result<Self, FlightError> {
        let v: Value = serde_json::from_str(text).map_err(|e| FlightError::Line {
            path: path.to_path_buf(),
            line: e.line() as u64,
            msg: format!("invalid JSON: {e}"),
        })?;
        match v {
            Value::Object(m) => Self::from_json(m, path),
            _ => Err(FlightError::Invalid {
                path: path.to_path_buf(),
                msg: "expected a JSON object of metadata".into(),
            }),
        }
    }

    /// The metadata object to write: `raw` with the typed fields written over their keys.
    pub fn to_json(&self) -> Map<String, Value> {
        let mut m = self.raw.clone();
        let mut put_num = |k: &str, v: Option<f64>| {
            if let Some(x) = v {
                // Keep the raw number (and its integer/float form) when it is the same value.
                if m.get(k).and_then(Value::as_f64) != Some(x) {
                    m.insert(k.into(), Value::from(x));
                }
            }
        };
        put_num("rotor_speed_rad_s", Some(self.rotor_speed_rad_s));
        put_num("radius_m", Some(self.radius_m));
        put_num("forward_speed_kt", self.forward_speed_kt);
        put_num("advance_ratio", self.advance_ratio);
        put_num(
            "thrust_coefficient_over_solidity",
            self.thrust_coefficient_over_solidity,
        );
        put_num("density_kg_m3", self.density_kg_m3);
        put_num("speed_of_sound_m_s", self.speed_of_sound_m_s);
        put_num("chord_m", self.chord_m);
        put_num("damper_oil_temperature_K", self.damper_oil_temperature_k);
        m.insert("synthetic".into(), Value::Bool(self.synthetic));
        if let Some(c) = &self.counter {
            m.insert("counter".into(), Value::String(c.clone()));
        }
        if let Some(d) = &self.description {
            m.insert("description".into(), Value::String(d.clone()));
        }
        let mut c = match m.get("controls_deg") {
            Some(Value::Object(c)) => c.clone(),
            _ => Map::new(),
        };
        for (k, v) in [
            ("collective", self.controls_deg.collective),
            ("lateral_cyclic", self.controls_deg.lateral_cyclic),
            ("longitudinal_cyclic", self.controls_deg.longitudinal_cyclic),
        ] {
            if c.get(k).and_then(Value::as_f64) != Some(v) {
                c.insert(k.into(), Value::from(v));
            }
        }
        m.insert("controls_deg".into(), Value::Object(c));
        m
    }

    /// Rotor speed [deg/s].
    pub fn rotor_speed_deg_s(&self) -> f64 {
        self.rotor_speed_rad_s.to_degrees()
    }

    /// 1/2 rho a^2 c [N/m]: the scale of the M^2 C airloads; errors name the missing key.
    pub fn mach_squared_scale(&self, path: &Path) -> Result<(f64, f64), FlightError> {
        let need = |v: Option<f64>, key: &str| {
            v.ok_or_else(|| FlightError::Meta {
                path: path.to_path_buf(),
                key: key.into(),
                msg: "missing; needed to convert M^2 C airloads to SI".into(),
            })
        };
        let rho = need(self.density_kg_m3, "density_kg_m3")?;
        let a = need(self.speed_of_sound_m_s, "speed_of_sound_m_s")?;
        let c = need(self.chord_m, "chord_m")?;
        Ok((0.5 * rho * a * a * c, c))
    }
}

/// One sample of the measured damper channel.
#[derive(Debug, Clone, Copy, PartialEq)]
#[allow(non_snake_case)]
pub struct DamperSample {
    pub revolution: u32,
    pub azimuth_deg: f64,
    /// Damper force [N], docs/formats.md sign (positive pushes the end points apart).
    pub force_N: f64,
    /// Damper stroke [m], positive in extension, where the record has it.
    pub stroke_m: Option<f64>,
}

/// The damper channel over one azimuth grid (one revolution, or the revolution average).
#[derive(Debug, Clone, PartialEq)]
#[allow(non_snake_case)]
pub struct DamperTrace {
    pub azimuth_deg: Vec<f64>,
    pub force_N: Vec<f64>,
    pub stroke_m: Option<Vec<f64>>,
}

/// A flight record (docs/formats.md "Flight record"), values in SI.
///
/// Airloads are stored on a full grid: every listed revolution has the same azimuths, every
/// azimuth the same stations (checked on construction). Revolutions may have gaps (a record of
/// revolutions 0, 1, 3); [`FlightRecord::missing_revolutions`] reports them.
#[derive(Debug, Clone, PartialEq)]
pub struct FlightRecord {
    pub meta: FlightMeta,
    stations: Vec<f64>,
    revolutions: Vec<u32>,
    azimuths: Vec<f64>,
    normal: Vec<f64>,
    chord: Vec<f64>,
    moment: Vec<f64>,
    damper: Vec<DamperSample>,
    /// The measured rigid blade motion (optional `STEM.motion.csv` / MCAP channel
    /// `/rotor/motion`), on the airloads' azimuth grid. Set it with [`FlightRecord::with_motion`],
    /// which checks the grid (a motion assigned directly on another grid would not read back).
    pub motion: Option<BladeMotion>,
}

/// Where a row came from, for error messages.
#[derive(Debug, Clone, Copy)]
pub(crate) enum Loc {
    Line(u64),
    Message(u64),
}

impl std::fmt::Display for Loc {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Loc::Line(l) => write!(f, "line {l}"),
            Loc::Message(m) => write!(f, "message {m}"),
        }
    }
}

/// Airload rows as read (any order), SI, before assembly onto the grid.
#[derive(Debug, Default)]
pub(crate) struct AirloadRows {
    pub rev: Vec<u32>,
    pub psi: Vec<f64>,
    pub r: Vec<f64>,
    pub n: Vec<f64>,
    pub c: Vec<f64>,
    pub m: Vec<f64>,
    /// Line or message number of each row (see `lines`).
    pub loc: Vec<u64>,
    /// True when `loc` holds CSV lines, false for MCAP message indices.
    pub lines: bool,
}

impl AirloadRows {
    fn loc(&self, i: usize) -> Loc {
        if self.lines {
            Loc::Line(self.loc[i])
        } else {
            Loc::Message(self.loc[i])
        }
    }
    fn push(&mut self, rev: u32, psi: f64, r: f64, v: [f64; 3], loc: u64) {
        self.rev.push(rev);
        self.psi.push(psi);
        self.r.push(r);
        self.n.push(v[0]);
        self.c.push(v[1]);
        self.m.push(v[2]);
        self.loc.push(loc);
    }
}

/// Assembles airload rows onto the grid as they stream in. Rows in canonical order (revolution,
/// then azimuth, then station, as rotorsim writes them) go straight into the final arrays; the
/// first row out of that order moves everything to the general path (sort, then check), which
/// also produces the error messages for duplicates and gaps.
#[derive(Debug)]
pub(crate) struct AirloadAssembler {
    rows: Option<AirloadRows>,
    lines: bool,
    stations: Vec<f64>,
    stations_closed: bool,
    azimuths: Vec<f64>,
    azimuths_closed: bool,
    revolutions: Vec<u32>,
    i_az: usize,
    i_st: usize,
    n: Vec<f64>,
    c: Vec<f64>,
    m: Vec<f64>,
    loc: Vec<u64>,
}

impl AirloadAssembler {
    /// `lines`: locations are CSV lines (else MCAP message indices).
    pub fn new(lines: bool) -> Self {
        Self {
            rows: None,
            lines,
            stations: Vec::new(),
            stations_closed: false,
            azimuths: Vec::new(),
            azimuths_closed: false,
            revolutions: Vec::new(),
            i_az: 0,
            i_st: 0,
            n: Vec::new(),
            c: Vec::new(),
            m: Vec::new(),
            loc: Vec::new(),
        }
    }

    pub fn is_empty(&self) -> bool {
        self.loc.is_empty() && self.rows.as_ref().is_none_or(|r| r.rev.is_empty())
    }

    /// Adds one row (values in SI).
    pub fn push(&mut self, rev: u32, psi: f64, r: f64, v: [f64; 3], loc: u64) {
        if self.rows.is_none() && !self.fast(rev, psi, r) {
            self.spill();
        }
        match &mut self.rows {
            Some(rows) => rows.push(rev, psi, r, v, loc),
            None => {
                self.n.push(v[0]);
                self.c.push(v[1]);
                self.m.push(v[2]);
                self.loc.push(loc);
            }
        }
    }

    /// Advances the grid position for a row in canonical order; false if it is not.
    fn fast(&mut self, rev: u32, psi: f64, r: f64) -> bool {
        let Some(&cur_rev) = self.revolutions.last() else {
            self.revolutions.push(rev);
            self.azimuths.push(psi);
            self.stations.push(r);
            return true;
        };
        let cur_psi = self.azimuths[self.i_az];
        let at_last_station = |s: &Self| s.stations_closed && s.i_st + 1 == s.stations.len();
        if rev == cur_rev && psi == cur_psi {
            // Next station of the same azimuth.
            if !self.stations_closed {
                if r > self.stations[self.i_st] {
                    self.stations.push(r);
                    self.i_st += 1;
                    return true;
                }
                return false;
            }
            if self.i_st + 1 < self.stations.len() && self.stations[self.i_st + 1] == r {
                self.i_st += 1;
                return true;
            }
            return false;
        }
        // A new azimuth or revolution closes the station grid (first azimuth of all).
        if !self.stations_closed {
            self.stations_closed = true;
        }
        if !at_last_station(self) || r != self.stations[0] {
            return false;
        }
        if rev == cur_rev {
            if !self.azimuths_closed {
                if psi > cur_psi {
                    self.azimuths.push(psi);
                    self.i_az += 1;
                    self.i_st = 0;
                    return true;
                }
                return false;
            }
            if self.i_az + 1 < self.azimuths.len() && self.azimuths[self.i_az + 1] == psi {
                self.i_az += 1;
                self.i_st = 0;
                return true;
            }
            return false;
        }
        // A new revolution closes the azimuth grid (first revolution).
        self.azimuths_closed = true;
        if rev > cur_rev && self.i_az + 1 == self.azimuths.len() && psi == self.azimuths[0] {
            self.revolutions.push(rev);
            self.i_az = 0;
            self.i_st = 0;
            return true;
        }
        false
    }

    /// Moves the rows gathered so far to the general path.
    fn spill(&mut self) {
        let mut rows = AirloadRows {
            lines: self.lines,
            ..Default::default()
        };
        let (n_st, n_az) = (self.stations.len(), self.azimuths.len());
        for k in 0..self.loc.len() {
            let (i_st, i_az, i_rev) = (k % n_st, (k / n_st) % n_az, k / (n_st * n_az));
            rows.push(
                self.revolutions[i_rev],
                self.azimuths[i_az],
                self.stations[i_st],
                [self.n[k], self.c[k], self.m[k]],
                self.loc[k],
            );
        }
        *self = Self {
            rows: Some(rows),
            ..Self::new(self.lines)
        };
    }

    /// The grid (stations, revolutions, azimuths, normal, chord, moment), or the rows when the
    /// input was not in canonical order or ended inside a revolution.
    #[allow(clippy::type_complexity, clippy::result_large_err)] // internal, moved once
    fn finish(
        mut self,
    ) -> Result<(Vec<f64>, Vec<u32>, Vec<f64>, Vec<f64>, Vec<f64>, Vec<f64>), AirloadRows> {
        // The last revolution has every azimuth, the last azimuth every station.
        let complete = self.i_st + 1 == self.stations.len() && self.i_az + 1 == self.azimuths.len();
        if self.rows.is_none() && !complete {
            self.spill();
        }
        match self.rows {
            Some(rows) => Err(rows),
            None => Ok((
                self.stations,
                self.revolutions,
                self.azimuths,
                self.n,
                self.c,
                self.m,
            )),
        }
    }
}

/// Metadata keys that describe the data must agree with it: `azimuths_per_revolution` and
/// `revolutions` (extension keys of the shipped record), when present, are the airload grid's.
fn meta_agrees(meta: &FlightMeta, n_az: usize, n_rev: usize) -> Result<(), String> {
    for (key, n, what) in [
        ("azimuths_per_revolution", n_az, "azimuths per revolution"),
        ("revolutions", n_rev, "revolutions"),
    ] {
        if let Some(v) = meta.raw.get(key) {
            if v.as_u64() != Some(n as u64) {
                return Err(format!(
                    "meta key `{key}` = {v}, but the airloads have {n} {what}"
                ));
            }
        }
    }
    Ok(())
}

impl FlightRecord {
    /// Builds a record from full-grid arrays (index `(i_rev * n_az + i_az) * n_st + i_st`),
    /// checking grids, values and damper samples.
    #[allow(clippy::too_many_arguments)]
    pub fn new(
        meta: FlightMeta,
        stations_r_over_r: Vec<f64>,
        revolutions: Vec<u32>,
        azimuths_deg: Vec<f64>,
        normal_n_per_m: Vec<f64>,
        chord_n_per_m: Vec<f64>,
        moment_n_m_per_m: Vec<f64>,
        damper: Vec<DamperSample>,
    ) -> Result<Self, FlightError> {
        let inv = |msg: String| FlightError::Invalid {
            path: PathBuf::from("<flight record>"),
            msg,
        };
        let n = stations_r_over_r.len() * revolutions.len() * azimuths_deg.len();
        if n == 0 {
            return Err(inv(
                "no airloads (need stations, revolutions, azimuths)".into()
            ));
        }
        for (name, v) in [
            ("normal force", &normal_n_per_m),
            ("chord force", &chord_n_per_m),
            ("pitching moment", &moment_n_m_per_m),
        ] {
            if v.len() != n {
                return Err(inv(format!("{name}: {} values, expected {n}", v.len())));
            }
            if let Some(i) = v.iter().position(|x| !x.is_finite()) {
                return Err(inv(format!("{name}: non-finite value at index {i}")));
            }
        }
        if !stations_r_over_r.windows(2).all(|w| w[0] < w[1])
            || stations_r_over_r.iter().any(|&r| !(r > 0.0 && r <= 1.0))
        {
            return Err(inv(
                "stations r/R must increase strictly within (0, 1]".into()
            ));
        }
        if !azimuths_deg.windows(2).all(|w| w[0] < w[1])
            || azimuths_deg.iter().any(|&p| !(0.0..360.0).contains(&p))
        {
            return Err(inv("azimuths must increase strictly within [0, 360)".into()));
        }
        meta_agrees(&meta, azimuths_deg.len(), revolutions.len()).map_err(inv)?;
        if !revolutions.windows(2).all(|w| w[0] < w[1]) {
            return Err(inv("revolutions must increase strictly".into()));
        }
        let rec = Self {
            meta,
            stations: stations_r_over_r,
            revolutions,
            azimuths: azimuths_deg,
            normal: normal_n_per_m,
            chord: chord_n_per_m,
            moment: moment_n_m_per_m,
            damper: Vec::new(),
            motion: None,
        };
        let mut damper = damper;
        check_damper(&mut damper, &[], Path::new("<flight record>"))?;
        Ok(Self { damper, ..rec })
    }

    /// Assembles rows read from a file onto the full grid; errors name `path` and the row.
    pub(crate) fn from_rows(
        meta: FlightMeta,
        asm: AirloadAssembler,
        path: &Path,
        mut damper: Vec<DamperSample>,
        damper_locs: &[Loc],
        damper_path: &Path,
    ) -> Result<Self, FlightError> {
        let inv = |msg: String| FlightError::Invalid {
            path: path.to_path_buf(),
            msg,
        };
        let rows = match asm.finish() {
            Ok((stations, revolutions, azimuths, normal, chord, moment)) => {
                check_damper(&mut damper, damper_locs, damper_path)?;
                return Ok(Self {
                    meta,
                    stations,
                    revolutions,
                    azimuths,
                    normal,
                    chord,
                    moment,
                    damper,
                    motion: None,
                });
            }
            Err(rows) => rows,
        };
        let len = rows.rev.len();
        if len == 0 {
            return Err(inv("no airload rows".into()));
        }
        let key = |i: usize| (rows.rev[i], rows.psi[i], rows.r[i]);
        let cmp = |a: usize, b: usize| {
            let (ka, kb) = (key(a), key(b));
            ka.0.cmp(&kb.0)
                .then(ka.1.total_cmp(&kb.1))
                .then(ka.2.total_cmp(&kb.2))
        };
        let mut order: Vec<usize> = (0..len).collect();
        if !order.windows(2).all(|w| cmp(w[0], w[1]).is_le()) {
            order.sort_by(|&a, &b| cmp(a, b));
        }
        for w in order.windows(2) {
            if cmp(w[0], w[1]).is_eq() {
                let (rv, p, r) = key(w[1]);
                return Err(inv(format!(
                    "duplicate airload row: revolution {rv}, azimuth {p} deg, r/R {r} at {} and {}",
                    rows.loc(w[0]),
                    rows.loc(w[1])
                )));
            }
        }
        // Grids from the first revolution's first azimuth (stations) and first revolution (azimuths).
        let first = key(order[0]);
        let stations: Vec<f64> = order
            .iter()
            .map(|&i| key(i))
            .take_while(|k| k.0 == first.0 && k.1 == first.1)
            .map(|k| k.2)
            .collect();
        let n_st = stations.len();
        let azimuths: Vec<f64> = order
            .iter()
            .step_by(n_st)
            .map(|&i| key(i))
            .take_while(|k| k.0 == first.0)
            .map(|k| k.1)
            .collect();
        let n_az = azimuths.len();
        let block = n_st * n_az;
        let mut revolutions = Vec::new();
        let (mut normal, mut chord, mut moment) = (
            Vec::with_capacity(len),
            Vec::with_capacity(len),
            Vec::with_capacity(len),
        );
        let mut pos = 0;
        while pos < len {
            let rev = key(order[pos]).0;
            revolutions.push(rev);
            for (i_az, &psi) in azimuths.iter().enumerate() {
                for (i_st, &r) in stations.iter().enumerate() {
                    let p = pos + i_az * n_st + i_st;
                    let got = (p < len).then(|| key(order[p]));
                    match got {
                        Some(k) if k == (rev, psi, r) => {}
                        _ => {
                            return Err(inv(grid_gap_message(rev, psi, r, got, first.0, &stations)))
                        }
                    }
                    let i = order[p];
                    normal.push(rows.n[i]);
                    chord.push(rows.c[i]);
                    moment.push(rows.m[i]);
                }
            }
            pos += block;
            if pos < len && key(order[pos]).0 == rev {
                let (_, p, r) = key(order[pos]);
                return Err(inv(format!(
                    "revolution {rev}: azimuth {p} deg (r/R {r}, {}) is not on the azimuth grid of revolution {} ({n_az} azimuths)",
                    rows.loc(order[pos]), first.0
                )));
            }
        }
        check_damper(&mut damper, damper_locs, damper_path)?;
        Ok(Self {
            meta,
            stations,
            revolutions,
            azimuths,
            normal,
            chord,
            moment,
            damper,
            motion: None,
        })
    }

    /// The record with `motion` attached; errors unless the motion's azimuth grid is the
    /// airloads' (bit for bit).
    pub fn with_motion(mut self, motion: Option<BladeMotion>) -> Result<Self, FlightError> {
        if let Some(m) = &motion {
            if m.azimuths_deg() != self.azimuths.as_slice() {
                return Err(FlightError::Invalid {
                    path: PathBuf::from("<flight record>"),
                    msg: format!(
                        "the blade motion's azimuth grid ({} azimuths) is not the airloads' ({} azimuths)",
                        m.azimuths_deg().len(),
                        self.azimuths.len()
                    ),
                });
            }
        }
        self.motion = motion;
        Ok(self)
    }

    /// Stations r/R, strictly increasing.
    pub fn stations_r_over_r(&self) -> &[f64] {
        &self.stations
    }
    /// Revolution numbers present, strictly increasing.
    pub fn revolutions(&self) -> &[u32] {
        &self.revolutions
    }
    /// Azimuth grid [deg], the same for every revolution, strictly increasing in [0, 360).
    pub fn azimuths_deg(&self) -> &[f64] {
        &self.azimuths
    }
    /// Flat index of (revolution index, azimuth index, station index).
    pub fn index(&self, i_rev: usize, i_az: usize, i_st: usize) -> usize {
        (i_rev * self.azimuths.len() + i_az) * self.stations.len() + i_st
    }
    /// Normal force per span [N/m] (+z of the section frame), flat over [`Self::index`].
    pub fn normal_n_per_m(&self) -> &[f64] {
        &self.normal
    }
    /// Chord force per span [N/m] (along -y: positive = drag), flat over [`Self::index`].
    pub fn chord_n_per_m(&self) -> &[f64] {
        &self.chord
    }
    /// Pitching moment per span at the quarter chord [N m/m] (about +x: nose up).
    pub fn moment_n_m_per_m(&self) -> &[f64] {
        &self.moment
    }
    /// Measured damper samples, sorted by (revolution, azimuth).
    pub fn damper(&self) -> &[DamperSample] {
        &self.damper
    }
    /// True when the damper channel carries stroke.
    pub fn has_stroke(&self) -> bool {
        self.damper.first().is_some_and(|s| s.stroke_m.is_some())
    }

    /// Time [s] of (revolution, azimuth): (rev * 360 + psi) / Omega [deg/s] (docs/formats.md).
    pub fn time_s(&self, revolution: u32, azimuth_deg: f64) -> f64 {
        (revolution as f64 * 360.0 + azimuth_deg) / self.meta.rotor_speed_deg_s()
    }

    /// MCAP log time [ns] of (revolution, azimuth), rounded to the nearest nanosecond.
    pub fn log_time_ns(&self, revolution: u32, azimuth_deg: f64) -> u64 {
        (self.time_s(revolution, azimuth_deg) * 1e9).round() as u64
    }

    /// Revolutions missing between the first and the last one present.
    pub fn missing_revolutions(&self) -> Vec<u32> {
        missing(&self.revolutions)
    }

    /// Revolutions of the damper channel.
    pub fn damper_revolutions(&self) -> Vec<u32> {
        let mut v: Vec<u32> = self.damper.iter().map(|s| s.revolution).collect();
        v.dedup();
        v
    }

    /// The damper channel of one revolution.
    pub fn damper_revolution(&self, revolution: u32) -> Result<DamperTrace, FlightError> {
        let s: Vec<&DamperSample> = self
            .damper
            .iter()
            .filter(|s| s.revolution == revolution)
            .collect();
        if s.is_empty() {
            return Err(FlightError::Replay(format!(
                "damper channel has no revolution {revolution} (revolutions {:?})",
                self.damper_revolutions()
            )));
        }
        Ok(DamperTrace {
            azimuth_deg: s.iter().map(|s| s.azimuth_deg).collect(),
            force_N: s.iter().map(|s| s.force_N).collect(),
            stroke_m: s.iter().map(|s| s.stroke_m).collect(),
        })
    }

    /// The damper channel averaged over its revolutions, azimuth by azimuth.
    pub fn damper_average(&self) -> Result<DamperTrace, FlightError> {
        let revs = self.damper_revolutions();
        let mut acc = self.damper_revolution(revs[0])?;
        for &r in &revs[1..] {
            let t = self.damper_revolution(r)?;
            if t.azimuth_deg != acc.azimuth_deg {
                return Err(FlightError::Replay(format!(
                    "damper revolution {r} has a different azimuth grid from revolution {}",
                    revs[0]
                )));
            }
            for (a, b) in acc.force_N.iter_mut().zip(&t.force_N) {
                *a += b;
            }
            if let (Some(a), Some(b)) = (acc.stroke_m.as_mut(), t.stroke_m.as_ref()) {
                for (a, b) in a.iter_mut().zip(b) {
                    *a += b;
                }
            }
        }
        let k = revs.len() as f64;
        acc.force_N.iter_mut().for_each(|f| *f /= k);
        if let Some(s) = acc.stroke_m.as_mut() {
            s.iter_mut().for_each(|x| *x /= k);
        }
        Ok(acc)
    }

    /// Reads a record: an MCAP file, a CSV stem (`flightdata/c8534like`), or any one of the
    /// three CSV files of the triple (or the optional `STEM.motion.csv`). A CSV stem's
    /// `STEM.motion.csv` is read when it exists ([`FlightRecord::motion`]).
    pub fn read(path: &Path) -> Result<Self, FlightError> {
        let (rec, meta_file) = match resolve(path)? {
            Form::Mcap(p) => (super::mcap::read_mcap(&p)?, p),
            Form::Csv(stem) => {
                let m = PathBuf::from(format!("{}.meta.json", stem.display()));
                (super::csv::read_csv(&stem)?, m)
            }
        };
        meta_agrees(&rec.meta, rec.azimuths.len(), rec.revolutions.len()).map_err(|msg| {
            FlightError::Invalid {
                path: meta_file,
                msg,
            }
        })?;
        Ok(rec)
    }

    /// The files [`FlightRecord::read`] reads for `path`: the MCAP file, or the CSV triple of
    /// the stem (those that exist) and `STEM.motion.csv` when it exists.
    pub fn files(path: &Path) -> Result<Vec<PathBuf>, FlightError> {
        Ok(match resolve(path)? {
            Form::Mcap(p) => vec![p],
            Form::Csv(stem) => CSV_SUFFIXES
                .iter()
                .chain(&CSV_OPTIONAL_SUFFIXES)
                .map(|suf| PathBuf::from(format!("{}{suf}", stem.to_string_lossy())))
                .filter(|p| p.is_file())
                .collect(),
        })
    }

    /// Writes the CSV triple `STEM.meta.json`, `STEM.airloads.csv`, `STEM.damper.csv` (SI), and
    /// `STEM.motion.csv` when the record has a motion (a `STEM.motion.csv` already there is
    /// removed when it has none, so that the stem reads back as written).
    pub fn write_csv(&self, stem: &Path) -> Result<(), FlightError> {
        super::csv::write_csv(self, stem)
    }

    /// Writes one MCAP file.
    pub fn write_mcap(&self, path: &Path) -> Result<(), FlightError> {
        super::mcap::write_mcap(self, path)
    }
}

/// Revolutions missing between the first and the last of a strictly increasing list.
pub fn missing_revolutions_of(sorted: &[u32]) -> Vec<u32> {
    missing(sorted)
}

fn missing(sorted: &[u32]) -> Vec<u32> {
    match (sorted.first(), sorted.last()) {
        (Some(&a), Some(&b)) => (a..=b)
            .filter(|r| sorted.binary_search(r).is_err())
            .collect(),
        _ => Vec::new(),
    }
}

fn grid_gap_message(
    rev: u32,
    psi: f64,
    r: f64,
    got: Option<(u32, f64, f64)>,
    first_rev: u32,
    stations: &[f64],
) -> String {
    match got {
        Some((grev, gpsi, _)) if grev == rev && gpsi == psi => format!(
            "revolution {rev}, azimuth {psi} deg: station r/R {r} missing or a station off the grid {stations:?} of revolution {first_rev}"
        ),
        Some((grev, gpsi, _)) if grev == rev && gpsi > psi => {
            format!("revolution {rev}: azimuth {psi} deg missing (present in revolution {first_rev})")
        }
        Some((grev, gpsi, _)) if grev == rev => format!(
            "revolution {rev}: azimuth {gpsi} deg is not on the azimuth grid of revolution {first_rev}"
        ),
        _ => format!(
            "revolution {rev}: azimuth {psi} deg, r/R {r} missing (the grid of revolution {first_rev} has it)"
        ),
    }
}

/// Sorts damper samples and checks them: no duplicates, stroke everywhere or nowhere, the same
/// azimuth grid in every revolution.
fn check_damper(d: &mut [DamperSample], locs: &[Loc], path: &Path) -> Result<(), FlightError> {
    let inv = |msg: String| FlightError::Invalid {
        path: path.to_path_buf(),
        msg,
    };
    if d.is_empty() {
        return Err(inv("no damper samples".into()));
    }
    let loc = |i: usize| locs.get(i).map(|l| format!(" ({l})")).unwrap_or_default();
    for (i, s) in d.iter().enumerate() {
        if !s.force_N.is_finite()
            || !s.azimuth_deg.is_finite()
            || s.stroke_m.is_some_and(|x| !x.is_finite())
        {
            return Err(inv(format!(
                "damper sample {i}{}: non-finite value",
                loc(i)
            )));
        }
        if s.stroke_m.is_some() != d[0].stroke_m.is_some() {
            return Err(inv(format!(
                "damper sample {i}{}: stroke present in some samples only",
                loc(i)
            )));
        }
    }
    let cmp = |a: &DamperSample, b: &DamperSample| {
        a.revolution
            .cmp(&b.revolution)
            .then(a.azimuth_deg.total_cmp(&b.azimuth_deg))
    };
    if !d.windows(2).all(|w| cmp(&w[0], &w[1]).is_le()) {
        d.sort_by(cmp);
    }
    for w in d.windows(2) {
        if cmp(&w[0], &w[1]).is_eq() {
            return Err(inv(format!(
                "duplicate damper sample: revolution {}, azimuth {} deg",
                w[1].revolution, w[1].azimuth_deg
            )));
        }
    }
    let first_rev = d[0].revolution;
    let grid: Vec<f64> = d
        .iter()
        .take_while(|s| s.revolution == first_rev)
        .map(|s| s.azimuth_deg)
        .collect();
    for chunk in d.chunk_by(|a, b| a.revolution == b.revolution) {
        let rev = chunk[0].revolution;
        for (k, &psi) in grid.iter().enumerate() {
            match chunk.get(k) {
                Some(s) if s.azimuth_deg == psi => {}
                Some(s) if s.azimuth_deg < psi => {
                    return Err(inv(format!(
                        "damper revolution {rev}: azimuth {} deg is not on the grid of revolution {first_rev}",
                        s.azimuth_deg
                    )))
                }
                _ => {
                    return Err(inv(format!(
                        "damper revolution {rev}: azimuth {psi} deg missing (present in revolution {first_rev})"
                    )))
                }
            }
        }
        if let Some(s) = chunk.get(grid.len()) {
            return Err(inv(format!(
                "damper revolution {rev}: azimuth {} deg is not on the grid of revolution {first_rev}",
                s.azimuth_deg
            )));
        }
    }
    Ok(())
}

/// The two forms of a record on disk.
pub(crate) enum Form {
    Mcap(PathBuf),
    Csv(PathBuf),
}

/// Suffixes of the CSV triple.
pub const CSV_SUFFIXES: [&str; 3] = [".meta.json", ".airloads.csv", ".damper.csv"];
/// Suffixes of the optional CSV files of a record (read when they exist).
pub const CSV_OPTIONAL_SUFFIXES: [&str; 1] = [".motion.csv"];

/// Decides which form `path` names.
pub(crate) fn resolve(path: &Path) -> Result<Form, FlightError> {
    let s = path.to_string_lossy();
    if s.ends_with(".mcap") {
        return Ok(Form::Mcap(path.to_path_buf()));
    }
    for suf in CSV_SUFFIXES.iter().chain(&CSV_OPTIONAL_SUFFIXES) {
        if let Some(stem) = s.strip_suffix(suf) {
            return Ok(Form::Csv(PathBuf::from(stem)));
        }
    }
    let with = |suf: &str| PathBuf::from(format!("{s}{suf}"));
    if with(".meta.json").exists() {
        return Ok(Form::Csv(path.to_path_buf()));
    }
    if with(".mcap").exists() {
        return Ok(Form::Mcap(with(".mcap")));
    }
    if path.is_file() {
        // An MCAP file without the extension is recognised by its magic bytes.
        let mut magic = [0u8; 8];
        if let Ok(mut f) = std::fs::File::open(path) {
            use std::io::Read;
            if f.read_exact(&mut magic).is_ok() && magic == ::mcap::MAGIC[..] {
                return Ok(Form::Mcap(path.to_path_buf()));
            }
        }
    }
    let present: Vec<String> = [".airloads.csv", ".damper.csv"]
        .iter()
        .map(|suf| with(suf))
        .filter(|p| p.exists())
        .map(|p| p.display().to_string())
        .collect();
    let msg = if !present.is_empty() {
        format!(
            "{} is missing: a CSV record is the triple STEM.meta.json, STEM.airloads.csv, STEM.damper.csv, and only {} is there",
            with(".meta.json").display(),
            present.join(" and ")
        )
    } else if !path.exists() {
        format!(
            "no such file or record: neither {s}, {s}.meta.json nor {s}.mcap exists (expected an MCAP file, a CSV stem or one of its three files)"
        )
    } else {
        "expected an MCAP file (.mcap), a stem STEM with STEM.meta.json, STEM.airloads.csv, STEM.damper.csv, or one of those three files".into()
    };
    Err(FlightError::NotARecord {
        path: path.to_path_buf(),
        msg,
    })
}
