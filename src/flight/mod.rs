//! Flight records (CSV triple and MCAP), unit conversion at the edges, airload replay.
//!
//! A [`FlightRecord`] holds the metadata, the airloads per azimuth at radial stations (SI, section
//! frame of docs/formats.md), the measured damper channel and, optionally, the measured rigid blade
//! motion ([`BladeMotion`]). [`FlightRecord::read`] accepts either
//! form; [`FlightRecord::write_csv`] and [`FlightRecord::write_mcap`] write them atomically.
//! [`AirloadReplay`] turns a record into a load provider for the rotor run.
//! Format details, interpolation and root/tip treatment: docs/flight_records.md.
use std::path::PathBuf;

pub mod csv;
pub mod mcap;
pub mod motion;
pub mod record;
pub mod replay;
pub mod units;

pub use motion::{BladeMotion, MotionSample, PeriodicMotion};
pub use record::{ControlsDeg, DamperSample, DamperTrace, FlightMeta, FlightRecord};
pub use replay::{AirloadReplay, ReplayMode, ReplayOptions, SectionLoads};

/// Errors of flight-record reading, writing and replay. Each names the file and the line,
/// message or key involved, and what was expected.
#[derive(Debug, thiserror::Error)]
pub enum FlightError {
    #[error("cannot read {path}: {source}")]
    Io {
        path: PathBuf,
        #[source]
        source: std::io::Error,
    },
    #[error("{path}: not a flight record: {msg}")]
    NotARecord { path: PathBuf, msg: String },
    #[error("{path}, line {line}: {msg}")]
    Line {
        path: PathBuf,
        line: u64,
        msg: String,
    },
    #[error("{path}: {msg}")]
    Invalid { path: PathBuf, msg: String },
    #[error("{path}: metadata key `{key}`: {msg}")]
    Meta {
        path: PathBuf,
        key: String,
        msg: String,
    },
    #[error("{path}: column `{column}`: unknown unit `{unit}`; expected one of {expected}")]
    UnknownUnit {
        path: PathBuf,
        column: String,
        unit: String,
        expected: String,
    },
    #[error("{path}: truncated or corrupt MCAP: {msg}")]
    McapCorrupt { path: PathBuf, msg: String },
    #[error("{path}: channel {channel}: {msg}")]
    Channel {
        path: PathBuf,
        channel: String,
        msg: String,
    },
    #[error("{path}: channel {channel}, message {index}: {msg}")]
    Message {
        path: PathBuf,
        channel: String,
        index: u64,
        msg: String,
    },
    #[error("cannot write flight record: {0}")]
    Write(#[from] crate::io::OutputError),
    #[error("replay: {0}")]
    Replay(String),
}
