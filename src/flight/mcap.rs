//! The MCAP form of a flight record (docs/formats.md): channels `/rotor/meta` (one message),
//! `/rotor/airloads` (one message per azimuth, arrays over stations), `/rotor/damper` (one message
//! per sample); JSON message encoding, one JSON schema (encoding `jsonschema`) per channel;
//! log time = (revolution * 360 + azimuth_deg) / Omega[deg/s], in nanoseconds. The optional
//! `/rotor/motion` channel (one message per sample) carries the measured blade motion
//! (`STEM.motion.csv` of the CSV form); it is written only for a record that has one.
//!
//! Streaming: the reader never holds the file. It feeds the sans-io linear reader of the `mcap`
//! crate from the open file as it asks for bytes (at most one chunk buffered, bounded by a record
//! length limit), and decodes each message as it comes, in file order, which for files written
//! here is log-time order. Only the decoded values are kept: they are the record.
use super::motion::MotionAssembler;
use super::record::{AirloadAssembler, DamperSample, FlightMeta, FlightRecord, Loc};
use super::FlightError;
use ::mcap::records::{MessageHeader, Record};
use ::mcap::sans_io::linear_reader::{LinearReadEvent, LinearReader, LinearReaderOptions};
use serde::{Deserialize, Serialize};
use std::collections::{BTreeMap, HashMap};
use std::io::Read;
use std::path::Path;

pub const TOPIC_META: &str = "/rotor/meta";
pub const TOPIC_AIRLOADS: &str = "/rotor/airloads";
pub const TOPIC_DAMPER: &str = "/rotor/damper";
pub const TOPIC_MOTION: &str = "/rotor/motion";
pub const SCHEMA_META: &str = "rotorsim.FlightMeta";
pub const SCHEMA_AIRLOADS: &str = "rotorsim.AirloadsAzimuth";
pub const SCHEMA_DAMPER: &str = "rotorsim.DamperSample";
pub const SCHEMA_MOTION: &str = "rotorsim.MotionSample";
/// Log times may differ from (rev * 360 + psi) / Omega by this much (writers round differently).
pub const LOG_TIME_TOLERANCE_NS: u64 = 1000;

/// JSON schema of `/rotor/meta`.
pub const META_SCHEMA_JSON: &str = r#"{
  "$schema": "https://json-schema.org/draft/2020-12/schema",
  "title": "rotorsim.FlightMeta",
  "description": "Flight record metadata (docs/formats.md). Unknown keys are kept.",
  "type": "object",
  "required": ["synthetic", "rotor_speed_rad_s", "radius_m", "controls_deg"],
  "properties": {
    "counter": {"type": "string"},
    "synthetic": {"type": "boolean"},
    "description": {"type": "string"},
    "rotor_speed_rad_s": {"type": "number"},
    "radius_m": {"type": "number"},
    "forward_speed_kt": {"type": "number"},
    "advance_ratio": {"type": "number"},
    "thrust_coefficient_over_solidity": {"type": "number"},
    "density_kg_m3": {"type": "number"},
    "speed_of_sound_m_s": {"type": "number"},
    "chord_m": {"type": "number"},
    "damper_oil_temperature_K": {"type": "number"},
    "controls_deg": {
      "type": "object",
      "required": ["collective", "lateral_cyclic", "longitudinal_cyclic"],
      "properties": {
        "collective": {"type": "number"},
        "lateral_cyclic": {"type": "number"},
        "longitudinal_cyclic": {"type": "number"}
      }
    }
  },
  "additionalProperties": true
}"#;

/// JSON schema of `/rotor/airloads`.
pub const AIRLOADS_SCHEMA_JSON: &str = r#"{
  "$schema": "https://json-schema.org/draft/2020-12/schema",
  "title": "rotorsim.AirloadsAzimuth",
  "description": "Airloads per unit span at one azimuth, arrays over radial stations; section frame: normal +z, chord force along -y (positive = drag), moment about +x at the quarter chord (nose up).",
  "type": "object",
  "required": ["revolution", "azimuth_deg", "r_over_R", "normal_force_N_per_m", "chord_force_N_per_m", "pitching_moment_N_m_per_m"],
  "properties": {
    "revolution": {"type": "integer", "minimum": 0},
    "azimuth_deg": {"type": "number", "minimum": 0, "exclusiveMaximum": 360},
    "r_over_R": {"type": "array", "items": {"type": "number"}},
    "normal_force_N_per_m": {"type": "array", "items": {"type": "number"}},
    "chord_force_N_per_m": {"type": "array", "items": {"type": "number"}},
    "pitching_moment_N_m_per_m": {"type": "array", "items": {"type": "number"}}
  }
}"#;

/// JSON schema of `/rotor/damper`.
pub const DAMPER_SCHEMA_JSON: &str = r#"{
  "$schema": "https://json-schema.org/draft/2020-12/schema",
  "title": "rotorsim.DamperSample",
  "description": "Measured damper force (positive pushes the end points apart) and, where present, stroke (positive in extension).",
  "type": "object",
  "required": ["revolution", "azimuth_deg", "damper_force_N"],
  "properties": {
    "revolution": {"type": "integer", "minimum": 0},
    "azimuth_deg": {"type": "number", "minimum": 0, "exclusiveMaximum": 360},
    "damper_force_N": {"type": "number"},
    "damper_stroke_m": {"type": "number"}
  }
}"#;

/// JSON schema of `/rotor/motion` (optional channel).
pub const MOTION_SCHEMA_JSON: &str = r#"{
  "$schema": "https://json-schema.org/draft/2020-12/schema",
  "title": "rotorsim.MotionSample",
  "description": "Measured rigid motion of blade 1 on the airloads' azimuth grid [deg]: flap up positive, lag aft (against the rotation) positive, root pitch nose up positive.",
  "type": "object",
  "required": ["revolution", "azimuth_deg", "flap_deg", "lag_deg", "pitch_deg"],
  "properties": {
    "revolution": {"type": "integer", "minimum": 0},
    "azimuth_deg": {"type": "number", "minimum": 0, "exclusiveMaximum": 360},
    "flap_deg": {"type": "number"},
    "lag_deg": {"type": "number"},
    "pitch_deg": {"type": "number"}
  }
}"#;

#[derive(Serialize, Deserialize)]
struct MotionMsg {
    revolution: u32,
    azimuth_deg: f64,
    flap_deg: f64,
    lag_deg: f64,
    pitch_deg: f64,
}

#[derive(Serialize)]
struct AirloadsOut<'a> {
    revolution: u32,
    azimuth_deg: f64,
    #[serde(rename = "r_over_R")]
    r_over_r: &'a [f64],
    #[serde(rename = "normal_force_N_per_m")]
    normal: &'a [f64],
    #[serde(rename = "chord_force_N_per_m")]
    chord: &'a [f64],
    #[serde(rename = "pitching_moment_N_m_per_m")]
    moment: &'a [f64],
}

#[derive(Deserialize)]
struct AirloadsIn {
    revolution: u32,
    azimuth_deg: f64,
    #[serde(rename = "r_over_R")]
    r_over_r: Vec<f64>,
    #[serde(rename = "normal_force_N_per_m")]
    normal: Vec<f64>,
    #[serde(rename = "chord_force_N_per_m")]
    chord: Vec<f64>,
    #[serde(rename = "pitching_moment_N_m_per_m")]
    moment: Vec<f64>,
}

#[derive(Serialize, Deserialize)]
struct DamperMsg {
    revolution: u32,
    azimuth_deg: f64,
    #[serde(rename = "damper_force_N")]
    force: f64,
    #[serde(
        rename = "damper_stroke_m",
        skip_serializing_if = "Option::is_none",
        default
    )]
    stroke: Option<f64>,
}

fn mcap_write_err(path: &Path, e: ::mcap::McapError) -> FlightError {
    FlightError::Invalid {
        path: path.to_path_buf(),
        msg: format!("cannot encode MCAP: {e}"),
    }
}

/// The MCAP bytes of a record: meta first, then airloads and damper messages merged in
/// log-time order (airloads first on ties).
pub fn mcap_bytes(rec: &FlightRecord, path: &Path) -> Result<Vec<u8>, FlightError> {
    let e = |err| mcap_write_err(path, err);
    let mut buf = std::io::Cursor::new(Vec::new());
    {
        let mut w = ::mcap::WriteOptions::new()
            .library(concat!("rotorsim/", env!("CARGO_PKG_VERSION")))
            .create(&mut buf)
            .map_err(e)?;
        let mut chan_meta = BTreeMap::new();
        chan_meta.insert(
            "synthetic".to_string(),
            rec.meta.synthetic.to_string(), // shown by MCAP viewers next to the channel
        );
        let mut add = |schema: &str, json: &str, topic: &str| -> Result<u16, FlightError> {
            let s = w
                .add_schema(schema, "jsonschema", json.as_bytes())
                .map_err(e)?;
            w.add_channel(s, topic, "json", &chan_meta).map_err(e)
        };
        let c_meta = add(SCHEMA_META, META_SCHEMA_JSON, TOPIC_META)?;
        let c_air = add(SCHEMA_AIRLOADS, AIRLOADS_SCHEMA_JSON, TOPIC_AIRLOADS)?;
        let c_damp = add(SCHEMA_DAMPER, DAMPER_SCHEMA_JSON, TOPIC_DAMPER)?;
        let c_motion = match rec.motion {
            Some(_) => add(SCHEMA_MOTION, MOTION_SCHEMA_JSON, TOPIC_MOTION)?,
            None => 0,
        };

        let n_st = rec.stations_r_over_r().len();
        let az = rec.azimuths_deg();
        let air_times = rec
            .revolutions()
            .iter()
            .flat_map(|&r| az.iter().map(move |&p| (r, p)));
        let t_first = air_times
            .clone()
            .next()
            .map(|(r, p)| rec.log_time_ns(r, p))
            .unwrap_or(0)
            .min(
                rec.damper()
                    .first()
                    .map_or(u64::MAX, |s| rec.log_time_ns(s.revolution, s.azimuth_deg)),
            );
        let meta_json = serde_json::to_vec(&serde_json::Value::Object(rec.meta.to_json()))
            .map_err(|err| FlightError::Invalid {
                path: path.to_path_buf(),
                msg: format!("cannot encode metadata: {err}"),
            })?;
        let header = |channel_id, sequence, t| MessageHeader {
            channel_id,
            sequence,
            log_time: t,
            publish_time: t,
        };
        w.write_to_known_channel(&header(c_meta, 0, t_first), &meta_json)
            .map_err(e)?;

        let mut damp = rec.damper().iter().enumerate().peekable();
        let mut data = Vec::new();
        let mut write_damper_until =
            |w: &mut ::mcap::Writer<_>, limit: u64| -> Result<(), FlightError> {
                while let Some(&(k, s)) = damp.peek() {
                    let t = rec.log_time_ns(s.revolution, s.azimuth_deg);
                    if t >= limit {
                        break;
                    }
                    let msg = DamperMsg {
                        revolution: s.revolution,
                        azimuth_deg: s.azimuth_deg,
                        force: s.force_N,
                        stroke: s.stroke_m,
                    };
                    let bytes = serde_json::to_vec(&msg).unwrap_or_default();
                    w.write_to_known_channel(&header(c_damp, k as u32, t), &bytes)
                        .map_err(e)?;
                    damp.next();
                }
                Ok(())
            };
        // Motion samples (revolution, azimuth index), in log-time order.
        let mut motion = rec
            .motion
            .iter()
            .flat_map(|m| {
                let n_az = m.azimuths_deg().len();
                (0..m.revolutions().len() * n_az).map(move |i| (m, i, i / n_az, i % n_az))
            })
            .peekable();
        let mut write_motion_until =
            |w: &mut ::mcap::Writer<_>, limit: u64| -> Result<(), FlightError> {
                while let Some(&(m, i, ir, ia)) = motion.peek() {
                    let (rev, psi) = (m.revolutions()[ir], m.azimuths_deg()[ia]);
                    let t = rec.log_time_ns(rev, psi);
                    if t >= limit {
                        break;
                    }
                    let msg = MotionMsg {
                        revolution: rev,
                        azimuth_deg: psi,
                        flap_deg: m.flap_deg()[i],
                        lag_deg: m.lag_deg()[i],
                        pitch_deg: m.pitch_deg()[i],
                    };
                    let bytes = serde_json::to_vec(&msg).unwrap_or_default();
                    w.write_to_known_channel(&header(c_motion, i as u32, t), &bytes)
                        .map_err(e)?;
                    motion.next();
                }
                Ok(())
            };
        for (k, (ir, ia)) in (0..rec.revolutions().len())
            .flat_map(|ir| (0..az.len()).map(move |ia| (ir, ia)))
            .enumerate()
        {
            let (rev, psi) = (rec.revolutions()[ir], az[ia]);
            let t = rec.log_time_ns(rev, psi);
            write_damper_until(&mut w, t)?;
            write_motion_until(&mut w, t)?;
            let i0 = rec.index(ir, ia, 0);
            let msg = AirloadsOut {
                revolution: rev,
                azimuth_deg: psi,
                r_over_r: rec.stations_r_over_r(),
                normal: &rec.normal_n_per_m()[i0..i0 + n_st],
                chord: &rec.chord_n_per_m()[i0..i0 + n_st],
                moment: &rec.moment_n_m_per_m()[i0..i0 + n_st],
            };
            data.clear();
            serde_json::to_writer(&mut data, &msg).map_err(|err| FlightError::Invalid {
                path: path.to_path_buf(),
                msg: format!("cannot encode airloads: {err}"),
            })?;
            w.write_to_known_channel(&header(c_air, k as u32, t), &data)
                .map_err(e)?;
        }
        write_damper_until(&mut w, u64::MAX)?;
        write_motion_until(&mut w, u64::MAX)?;
        w.finish().map_err(e)?;
    }
    Ok(buf.into_inner())
}

/// Writes the record as one MCAP file, atomically.
pub fn write_mcap(rec: &FlightRecord, path: &Path) -> Result<(), FlightError> {
    let bytes = mcap_bytes(rec, path)?;
    crate::io::write_atomic(path, &bytes)?;
    Ok(())
}

#[derive(Clone, Copy, PartialEq)]
enum Kind {
    Meta,
    Airloads,
    Damper,
    Motion,
}

impl Kind {
    fn of(topic: &str) -> Option<Self> {
        match topic {
            TOPIC_META => Some(Kind::Meta),
            TOPIC_AIRLOADS => Some(Kind::Airloads),
            TOPIC_DAMPER => Some(Kind::Damper),
            TOPIC_MOTION => Some(Kind::Motion),
            _ => None,
        }
    }
    fn topic(self) -> &'static str {
        match self {
            Kind::Meta => TOPIC_META,
            Kind::Airloads => TOPIC_AIRLOADS,
            Kind::Damper => TOPIC_DAMPER,
            Kind::Motion => TOPIC_MOTION,
        }
    }
    fn schema(self) -> (&'static str, &'static str) {
        match self {
            Kind::Meta => (SCHEMA_META, META_SCHEMA_JSON),
            Kind::Airloads => (SCHEMA_AIRLOADS, AIRLOADS_SCHEMA_JSON),
            Kind::Damper => (SCHEMA_DAMPER, DAMPER_SCHEMA_JSON),
            Kind::Motion => (SCHEMA_MOTION, MOTION_SCHEMA_JSON),
        }
    }
}

/// Checks that a channel's schema is ours: name, encoding, and a JSON schema that declares every
/// property our schema requires (a newer schema may add properties).
fn check_schema(
    kind: Kind,
    schema: Option<&(String, String, Vec<u8>)>,
    message_encoding: &str,
) -> Result<(), String> {
    let (name, ours) = kind.schema();
    let Some((sname, senc, data)) = schema else {
        return Err(format!(
            "has no schema; expected JSON schema `{name}` (encoding jsonschema)"
        ));
    };
    if sname != name || senc != "jsonschema" {
        return Err(format!(
            "schema `{sname}` (encoding `{senc}`); expected `{name}` (encoding jsonschema)"
        ));
    }
    if message_encoding != "json" {
        return Err(format!(
            "message encoding `{message_encoding}`; expected json"
        ));
    }
    let theirs: serde_json::Value = serde_json::from_slice(data)
        .map_err(|e| format!("schema `{sname}` is not valid JSON: {e}"))?;
    let ours: serde_json::Value = serde_json::from_str(ours).unwrap_or_default();
    let required = ours["required"].as_array().cloned().unwrap_or_default();
    for key in required.iter().filter_map(|k| k.as_str()) {
        if theirs["properties"].get(key).is_none() {
            return Err(format!(
                "schema `{sname}` does not declare property `{key}`"
            ));
        }
    }
    Ok(())
}

struct ChannelInfo {
    kind: Option<Kind>,
    count: u64,
}

/// Reads an MCAP flight record, streaming (see the module doc).
pub fn read_mcap(path: &Path) -> Result<FlightRecord, FlightError> {
    let mut file = std::fs::File::open(path).map_err(|source| FlightError::Io {
        path: path.to_path_buf(),
        source,
    })?;
    let len = file.metadata().map(|m| m.len()).unwrap_or(0);
    read_mcap_from(&mut file, len, path)
}

/// What the reader has collected from the records so far.
struct Collected {
    schemas: HashMap<u16, (String, String, Vec<u8>)>,
    channels: HashMap<u16, ChannelInfo>,
    meta: Option<FlightMeta>,
    rows: AirloadAssembler,
    damper: Vec<DamperSample>,
    damper_locs: Vec<Loc>,
    // (kind, message index, log time, revolution, azimuth), checked once Omega is known.
    times: Vec<(Kind, u64, u64, u32, f64)>,
    // Motion rows (revolution, azimuth, [flap, lag, pitch] deg, message index), placed on the
    // airloads' grid once that is known.
    motion_rows: Vec<(u32, f64, [f64; 3], u64)>,
    seen: [bool; 4],
}

/// Reads an MCAP flight record from any byte source of `len` bytes (used for files and tests);
/// `path` names the source in errors.
pub fn read_mcap_from(
    src: &mut dyn Read,
    len: u64,
    path: &Path,
) -> Result<FlightRecord, FlightError> {
    let corrupt = |msg: String| FlightError::McapCorrupt {
        path: path.to_path_buf(),
        msg,
    };
    // No record can be longer than the file, nor a chunk decompress to more than 100 times it:
    // bounds the buffers a corrupt length field could make the reader allocate.
    let limit = (len.saturating_mul(100)).clamp(1 << 20, 1 << 32) as usize;
    let mut reader = LinearReader::new_with_options(
        LinearReaderOptions::default()
            .with_prevalidate_chunk_crcs(true)
            .with_validate_data_section_crc(true)
            .with_record_length_limit(limit),
    );
    let mut c = Collected {
        schemas: HashMap::new(),
        channels: HashMap::new(),
        meta: None,
        rows: AirloadAssembler::new(false),
        damper: Vec::new(),
        damper_locs: Vec::new(),
        times: Vec::new(),
        motion_rows: Vec::new(),
        seen: [false; 4],
    };
    while let Some(event) = reader.next_event() {
        match event.map_err(|e| corrupt(e.to_string()))? {
            LinearReadEvent::ReadRequest(n) => {
                let buf = reader.insert(n);
                let got = src.read(buf).map_err(|source| FlightError::Io {
                    path: path.to_path_buf(),
                    source,
                })?;
                reader.notify_read(got);
            }
            LinearReadEvent::Record { data, opcode } => {
                let record = ::mcap::parse_record(opcode, data)
                    .map_err(|e| corrupt(format!("record with opcode {opcode:#04x}: {e}")))?;
                c.record(record, path)?;
            }
        }
    }
    c.finish(path)
}

fn channel_error(path: &Path, kind: Kind, msg: String) -> FlightError {
    FlightError::Channel {
        path: path.to_path_buf(),
        channel: kind.topic().into(),
        msg,
    }
}

impl Collected {
    /// Takes one record: schemas and channels are declared, messages read.
    fn record(&mut self, record: Record<'_>, path: &Path) -> Result<(), FlightError> {
        match record {
            Record::Schema { header, data } => {
                self.schemas
                    .insert(header.id, (header.name, header.encoding, data.into_owned()));
            }
            Record::Channel(ch) => {
                let kind = Kind::of(&ch.topic);
                if let Some(k) = kind {
                    let schema = (ch.schema_id != 0)
                        .then(|| self.schemas.get(&ch.schema_id))
                        .flatten();
                    check_schema(k, schema, &ch.message_encoding)
                        .map_err(|m| channel_error(path, k, m))?;
                    self.seen[k as usize] = true;
                }
                let count = self.channels.get(&ch.id).map_or(0, |c| c.count);
                self.channels.insert(ch.id, ChannelInfo { kind, count });
            }
            Record::Message { header, data } => {
                let Some(ch) = self.channels.get_mut(&header.channel_id) else {
                    return Err(FlightError::McapCorrupt {
                        path: path.to_path_buf(),
                        msg: format!(
                            "message on channel id {} that was never declared",
                            header.channel_id
                        ),
                    });
                };
                let index = ch.count;
                ch.count += 1;
                if let Some(kind) = ch.kind {
                    self.message(kind, index, header.log_time, &data, path)?;
                }
            }
            _ => {}
        }
        Ok(())
    }

    /// Reads message `index` of a channel of `kind`.
    fn message(
        &mut self,
        kind: Kind,
        index: u64,
        log_time: u64,
        data: &[u8],
        path: &Path,
    ) -> Result<(), FlightError> {
        let msg_err = |msg: String| FlightError::Message {
            path: path.to_path_buf(),
            channel: kind.topic().into(),
            index,
            msg,
        };
        let bad_json = |e: serde_json::Error| {
            msg_err(format!("does not match schema `{}`: {e}", kind.schema().0))
        };
        // a sample's azimuth, checked, and its time stamp (every sampled channel)
        let times = &mut self.times;
        let mut stamp = |revolution: u32, azimuth_deg: f64| {
            if !(0.0..360.0).contains(&azimuth_deg) {
                return Err(msg_err(format!(
                    "azimuth_deg {azimuth_deg} is outside [0, 360)"
                )));
            }
            times.push((kind, index, log_time, revolution, azimuth_deg));
            Ok(())
        };
        match kind {
            Kind::Meta => {
                if self.meta.is_some() {
                    return Err(msg_err(
                        "a second metadata message; expected exactly one".into(),
                    ));
                }
                let v: serde_json::Map<String, serde_json::Value> =
                    serde_json::from_slice(data).map_err(bad_json)?;
                self.meta = Some(FlightMeta::from_json(v, path)?);
            }
            Kind::Airloads => {
                let m: AirloadsIn = serde_json::from_slice(data).map_err(bad_json)?;
                let n = m.r_over_r.len();
                if n == 0 || m.normal.len() != n || m.chord.len() != n || m.moment.len() != n {
                    return Err(msg_err(format!(
                        "arrays of lengths r_over_R {}, normal {}, chord {}, moment {}; expected equal, non-zero lengths",
                        n,
                        m.normal.len(),
                        m.chord.len(),
                        m.moment.len()
                    )));
                }
                stamp(m.revolution, m.azimuth_deg)?;
                if let Some(r) = m.r_over_r.iter().find(|&&r| !(r > 0.0 && r <= 1.0)) {
                    return Err(msg_err(format!("r_over_R {r} is outside (0, 1]")));
                }
                for k in 0..n {
                    self.rows.push(
                        m.revolution,
                        m.azimuth_deg,
                        m.r_over_r[k],
                        [m.normal[k], m.chord[k], m.moment[k]],
                        index,
                    );
                }
            }
            Kind::Damper => {
                let m: DamperMsg = serde_json::from_slice(data).map_err(bad_json)?;
                stamp(m.revolution, m.azimuth_deg)?;
                self.damper.push(DamperSample {
                    revolution: m.revolution,
                    azimuth_deg: m.azimuth_deg,
                    force_N: m.force,
                    stroke_m: m.stroke,
                });
                self.damper_locs.push(Loc::Message(index));
            }
            Kind::Motion => {
                let m: MotionMsg = serde_json::from_slice(data).map_err(bad_json)?;
                stamp(m.revolution, m.azimuth_deg)?;
                self.motion_rows.push((
                    m.revolution,
                    m.azimuth_deg,
                    [m.flap_deg, m.lag_deg, m.pitch_deg],
                    index,
                ));
            }
        }
        Ok(())
    }

    /// The record from every message read: channels present, time stamps checked against
    /// the rotor speed, motion placed on the airloads' grid.
    fn finish(self, path: &Path) -> Result<FlightRecord, FlightError> {
        let chan_err = |kind: Kind, msg: String| channel_error(path, kind, msg);
        let Collected {
            meta,
            rows,
            damper,
            damper_locs,
            times,
            mut motion_rows,
            seen,
            ..
        } = self;
        for k in [Kind::Meta, Kind::Airloads, Kind::Damper] {
            if !seen[k as usize] {
                return Err(chan_err(
                    k,
                    format!(
                        "missing; expected channel {} with schema `{}`",
                        k.topic(),
                        k.schema().0
                    ),
                ));
            }
        }
        let Some(meta) = meta else {
            return Err(chan_err(
                Kind::Meta,
                "no message; expected exactly one".into(),
            ));
        };
        if rows.is_empty() {
            return Err(chan_err(Kind::Airloads, "no messages".into()));
        }
        if damper.is_empty() {
            return Err(chan_err(Kind::Damper, "no messages".into()));
        }
        let omega_deg_s = meta.rotor_speed_deg_s();
        for &(kind, index, t, rev, psi) in &times {
            let expect = ((rev as f64 * 360.0 + psi) / omega_deg_s * 1e9).round();
            if (t as f64 - expect).abs() > LOG_TIME_TOLERANCE_NS as f64 {
                return Err(FlightError::Message {
                    path: path.to_path_buf(),
                    channel: kind.topic().into(),
                    index,
                    msg: format!(
                        "log time {t} ns does not match revolution {rev}, azimuth {psi} deg at Omega = {} rad/s (expected {expect} ns)",
                        meta.rotor_speed_rad_s
                    ),
                });
            }
        }
        let mut rec = FlightRecord::from_rows(meta, rows, path, damper, &damper_locs, path)?;
        if seen[Kind::Motion as usize] {
            // Messages of a file not in log-time order are placed in order first.
            if !motion_rows
                .windows(2)
                .all(|w| (w[0].0, w[0].1) <= (w[1].0, w[1].1))
            {
                motion_rows.sort_by(|a, b| a.0.cmp(&b.0).then(a.1.total_cmp(&b.1)));
            }
            let mut asm = MotionAssembler::new(rec.azimuths_deg());
            for &(rev, psi, v, index) in &motion_rows {
                asm.push(rev, psi, v).map_err(|e| FlightError::Message {
                    path: path.to_path_buf(),
                    channel: TOPIC_MOTION.into(),
                    index,
                    msg: format!("field `{}`: {}", e.column, e.msg),
                })?;
            }
            let motion = asm.finish().map_err(|msg| chan_err(Kind::Motion, msg))?;
            rec.motion = Some(motion);
        }
        Ok(rec)
    }
}
