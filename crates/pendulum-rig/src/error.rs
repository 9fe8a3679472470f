//! The crate's single error type.
//!
//! Every variant names the file it concerns and where in it (line, byte offset or campaign key),
//! so a message read weeks later still tells which capture to open and where to look.

use std::path::PathBuf;

use crate::capture::Location;

/// Everything that can go wrong while reading captures or campaigns.
///
/// Damage *inside* a capture (cut lines, bad CRCs) is not an error: it is skipped and reported in
/// [`crate::IngestStats`]. Errors are reserved for I/O failures and for inputs that cannot be
/// read at all.
#[derive(Debug, thiserror::Error)]
pub enum RigError {
    /// Reading or writing a file failed.
    #[error("{}: I/O error: {source}", .path.display())]
    Io {
        path: PathBuf,
        #[source]
        source: std::io::Error,
    },

    /// The file is not a capture in any known format (or its header is unreadable).
    #[error("{}: not a rig capture ({at}): {reason}", .path.display())]
    NotACapture {
        path: PathBuf,
        at: Location,
        reason: String,
    },

    /// A header key is present but its value cannot be used.
    #[error("{}: header key `{key}` = {value:?}: expected {expected}", .path.display())]
    BadHeader {
        path: PathBuf,
        key: String,
        value: String,
        expected: String,
    },

    /// `campaign.toml` is not valid TOML.
    #[error("{}:{line}:{column}: TOML syntax error: {message}", .path.display())]
    CampaignSyntax {
        path: PathBuf,
        /// 1-based.
        line: usize,
        /// 1-based, in characters.
        column: usize,
        message: String,
    },

    /// An input longer than such a file can sensibly be (a campaign description of megabytes,
    /// a line of one): refused before it is read into memory. `at` says where (`line 3,
    /// byte 120`, or the size).
    #[error("{}: {at}: {what}", .path.display())]
    TooLarge {
        path: PathBuf,
        at: String,
        what: String,
    },

    /// A campaign key is missing or has the wrong type or value.
    #[error("{}: {}key `{key}`: expected {expected}", .path.display(), run_label(.run))]
    CampaignKey {
        path: PathBuf,
        /// The run's id, or `run #N` (1-based) when the id itself is missing; `None` for
        /// top-level keys.
        run: Option<String>,
        key: String,
        expected: String,
    },

    /// A run id or `file` key that cannot safely become a file name or a path (see
    /// [`crate::names`]): the program refuses it rather than read outside the campaign folder
    /// or write outside the output folder. `value` is printed escaped (`{:?}`), so no control
    /// character reaches the terminal.
    #[error("{}: run `{run}`: key `{key}` = {value:?} {problem}: expected {}", .path.display(), crate::names::expected(.key))]
    UnsafeName {
        /// The campaign file (or twin case) that holds the value.
        path: PathBuf,
        /// The run's id, or `run #N` (1-based) when the id itself is refused.
        run: String,
        /// `id` or `file`.
        key: &'static str,
        value: String,
        /// What is wrong with it ("contains a path separator").
        problem: String,
    },

    /// A run's `role` is neither `identify` nor `validate`.
    #[error("{}: run `{run}`: key `role` = {value:?}: expected \"identify\" or \"validate\"", .path.display())]
    BadRole {
        path: PathBuf,
        run: String,
        value: String,
    },

    /// Two runs share an id.
    #[error("{}: duplicate run id `{run_id}`", .path.display())]
    DuplicateRunId { path: PathBuf, run_id: String },

    /// A run's capture file does not exist (`path` is the capture's resolved path).
    #[error("{}: capture file of run `{run_id}` not found", .path.display())]
    MissingRunFile { path: PathBuf, run_id: String },

    /// A campaign could not be turned into TOML.
    #[error("{}: cannot write campaign: {message}", .path.display())]
    CampaignWrite { path: PathBuf, message: String },
}

fn run_label(run: &Option<String>) -> String {
    match run {
        Some(r) => format!("run `{r}`: "),
        None => String::new(),
    }
}

impl RigError {
    /// Wraps an I/O error with the path it concerns.
    pub fn io(path: impl Into<PathBuf>, source: std::io::Error) -> Self {
        RigError::Io {
            path: path.into(),
            source,
        }
    }
}
