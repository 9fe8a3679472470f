//! The crate's one error type. Every variant names the file, and the topic where one applies,
//! because a campaign writes and reads many run files and "CRC mismatch" alone says nothing.

use std::path::PathBuf;

/// Everything that can go wrong writing or reading a run file.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum LogError {
    /// A file-system operation failed.
    #[error("{path}: cannot {op}: {source}")]
    Io {
        path: PathBuf,
        /// What was being done, e.g. "create the temporary file".
        op: &'static str,
        source: std::io::Error,
    },

    /// The final path has no file name to derive the temporary name from.
    #[error("{path}: not a file path (expected something like runs/r01.mcap)")]
    InvalidPath { path: PathBuf },

    /// The `mcap` writer failed.
    #[error("{path}: MCAP writer failed to {op}: {source}")]
    Write {
        path: PathBuf,
        op: &'static str,
        source: mcap::McapError,
    },

    /// A message could not be serialized to JSON.
    #[error("{path}: topic {topic}: cannot serialize message: {source}")]
    Serialize {
        path: PathBuf,
        topic: &'static str,
        source: serde_json::Error,
    },

    /// A float field is NaN or infinite, which JSON cannot carry.
    #[error("{path}: topic {topic}: field {field} is {value}; expected a finite number (JSON has no NaN or infinity)")]
    NonFinite {
        path: PathBuf,
        topic: &'static str,
        field: &'static str,
        value: f64,
    },

    /// A message's `t_s` and `t_us` disagree with the run's first sample as implied by earlier
    /// messages.
    #[error("{path}: topic {topic}: t_us {t_us} with t_s {t_s} implies the run's first sample at t_us {implied_first_t_us}, but earlier messages put it at {expected_first_t_us}; expected t_s = (t_us − first t_us) / 1e6")]
    InconsistentTime {
        path: PathBuf,
        topic: &'static str,
        t_us: u64,
        t_s: f64,
        implied_first_t_us: i128,
        expected_first_t_us: i128,
    },

    /// A message's time cannot be expressed as MCAP log time (u64 nanoseconds since the epoch).
    #[error("{path}: topic {topic}: t_s {t_s} / t_us {t_us:?} gives a log time outside 0..=u64::MAX ns; expected a time at or after the run's start")]
    TimeOutOfRange {
        path: PathBuf,
        topic: &'static str,
        t_s: f64,
        t_us: Option<u64>,
    },

    /// A message is earlier than the previous one on its channel. Callers sort first.
    #[error("{path}: topic {topic}: message {index} has log time {log_time_ns} ns, earlier than the previous message's {previous_ns} ns; expected non-decreasing times (sort before writing)")]
    OutOfOrder {
        path: PathBuf,
        topic: &'static str,
        /// 0-based index of the offending message on its channel.
        index: u64,
        log_time_ns: u64,
        previous_ns: u64,
    },

    /// `set_start_ns` was called after messages were written with another time base.
    #[error("{path}: the start time must be set before the first message is written")]
    StartAfterFirstMessage { path: PathBuf },

    /// The same metadata name was written twice; readers would keep only one.
    #[error("{path}: metadata {name:?} written twice; expected each name once")]
    DuplicateMetadata { path: PathBuf, name: String },

    /// `write_stats` was called twice; the run holds one ingest statistics message.
    #[error("{path}: topic {topic}: statistics written twice; expected one message")]
    DuplicateStats { path: PathBuf, topic: &'static str },

    /// Content is well-formed MCAP but not what a run file holds.
    #[error("{path}: topic {topic}: expected {expected}, found {found}")]
    Unexpected {
        path: PathBuf,
        topic: String,
        expected: &'static str,
        found: String,
    },

    /// A start time string is not RFC 3339.
    #[error("start time {value:?}: {why}; expected RFC 3339 like 2026-03-14T10:22:05Z")]
    BadTimestamp { value: String, why: &'static str },

    /// The file ends in the middle of a record: an interrupted write or a cut copy.
    #[error("{path}: truncated MCAP file ({size_bytes} bytes): it ends in the middle of a record or before its end magic")]
    Truncated { path: PathBuf, size_bytes: u64 },

    /// A CRC stored in the file does not match its content: the file is corrupt.
    #[error("{path}: corrupt MCAP file: {section} CRC mismatch (stored {stored:08x}, computed {computed:08x})")]
    CrcMismatch {
        path: PathBuf,
        /// "chunk", "data section" or "summary section".
        section: &'static str,
        stored: u32,
        computed: u32,
    },

    /// The file is not readable MCAP for another reason (bad magic, bad record, bad compression).
    #[error("{path}: corrupt MCAP file: {source}")]
    Corrupt {
        path: PathBuf,
        source: mcap::McapError,
    },

    /// A message on a known topic is not the JSON its schema describes.
    #[error("{path}: topic {topic}: message {index} is not a valid {expected}: {source}")]
    BadMessage {
        path: PathBuf,
        topic: &'static str,
        index: u64,
        expected: &'static str,
        source: serde_json::Error,
    },
}
