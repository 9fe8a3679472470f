//! One MCAP file per run.
//!
//! A run's cleaned samples go into one [MCAP](https://mcap.dev) file so that anyone can open it in
//! Foxglove (or read it with the official `mcap` libraries) without this project's code:
//!
//! | topic           | message          | what                                             |
//! |-----------------|------------------|--------------------------------------------------|
//! | `/encoder`      | [`EncoderMsg`]   | every encoder sample                             |
//! | `/accel`        | [`AccelMsg`]     | every accelerometer sample                       |
//! | `/ingest_stats` | JSON object      | one message: what the ingest found and dropped   |
//! | `/sim/theta`    | [`SimulatedMsg`] | optional: a model replay next to the measurement |
//!
//! Every channel uses schema encoding `jsonschema` and message encoding `json` with flat numeric
//! fields, because that is what Foxglove's Plot panel plots by message path
//! (`/encoder.theta_rad`, `/accel.az_m_s2`). The schemas live in `schemas/*.json` at the
//! workspace root and are embedded here ([`schemas`]).
//!
//! Metadata records hold the run's campaign description ([`METADATA_RUN`]) and the raw capture's
//! header ([`METADATA_CAPTURE_HEADER`]).
//!
//! Writing is atomic: [`RunLogWriter`] writes a dot-prefixed temporary file next to the final one
//! and renames it only in [`RunLogWriter::finish`], so a crash or an early `?` never leaves a
//! valid-looking but partial run file. Reading ([`read_run`], [`for_each_message`]) checks every
//! CRC the file carries, because the `mcap` crate does not check chunk CRCs by default and a
//! flipped bit would otherwise come back as plausible numbers.

#![forbid(unsafe_code)]

mod error;
mod msg;
mod read;
pub mod schemas;
mod time;
mod write;

pub use error::LogError;
pub use msg::{AccelMsg, EncoderMsg, SimulatedMsg};
pub use read::{for_each_message, read_run, RunLog, RunMessage};
pub use time::parse_rfc3339_utc_ns;
pub use write::{RunLogOptions, RunLogSummary, RunLogWriter};

/// Topic of the encoder samples ([`EncoderMsg`]).
pub const TOPIC_ENCODER: &str = "/encoder";
/// Topic of the accelerometer samples ([`AccelMsg`]).
pub const TOPIC_ACCEL: &str = "/accel";
/// Topic of the single ingest statistics message (a JSON object).
pub const TOPIC_INGEST_STATS: &str = "/ingest_stats";
/// Topic of a model replay ([`SimulatedMsg`]).
pub const TOPIC_SIMULATED: &str = "/sim/theta";

/// Metadata record holding the run's description from `campaign.toml` (id, file, m_kg, …).
pub const METADATA_RUN: &str = "run";
/// Metadata record holding the raw capture's header lines (firmware, started, unknown keys, …).
pub const METADATA_CAPTURE_HEADER: &str = "capture_header";

/// Schema encoding of every channel (MCAP well-known value).
pub const SCHEMA_ENCODING: &str = "jsonschema";
/// Message encoding of every channel (MCAP well-known value).
pub const MESSAGE_ENCODING: &str = "json";
