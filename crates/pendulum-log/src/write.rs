//! Writing a run file: [`RunLogOptions`] → [`RunLogWriter`] → [`RunLogSummary`].

use std::collections::BTreeMap;
use std::fs::{self, File};
use std::io::BufWriter;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicU64, Ordering};

use mcap::records::{MessageHeader, Metadata};
use serde::Serialize;

use crate::{
    schemas, AccelMsg, EncoderMsg, LogError, SimulatedMsg, MESSAGE_ENCODING, SCHEMA_ENCODING,
    TOPIC_ACCEL, TOPIC_ENCODER, TOPIC_INGEST_STATS, TOPIC_SIMULATED,
};

/// The channels a run file can hold. The index is the slot in [`RunLogWriter::channels`].
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Topic {
    Encoder = 0,
    Accel = 1,
    Stats = 2,
    Simulated = 3,
}

impl Topic {
    pub(crate) const ALL: [Topic; 4] =
        [Topic::Encoder, Topic::Accel, Topic::Stats, Topic::Simulated];

    pub(crate) fn name(self) -> &'static str {
        match self {
            Topic::Encoder => TOPIC_ENCODER,
            Topic::Accel => TOPIC_ACCEL,
            Topic::Stats => TOPIC_INGEST_STATS,
            Topic::Simulated => TOPIC_SIMULATED,
        }
    }

    pub(crate) fn from_name(topic: &str) -> Option<Topic> {
        Topic::ALL.into_iter().find(|t| t.name() == topic)
    }

    fn schema(self) -> (&'static str, &'static str) {
        match self {
            Topic::Encoder => (schemas::ENCODER_NAME, schemas::ENCODER),
            Topic::Accel => (schemas::ACCEL_NAME, schemas::ACCEL),
            Topic::Stats => (schemas::INGEST_STATS_NAME, schemas::INGEST_STATS),
            Topic::Simulated => (schemas::SIMULATED_NAME, schemas::SIMULATED),
        }
    }
}

/// Options for a run file, builder style. Defaults: library `pendulum-log/<version>`, 1 MiB
/// chunks, zstd compression, no wall-clock start.
#[derive(Debug, Clone)]
pub struct RunLogOptions {
    library: String,
    chunk_size_bytes: u64,
    compression_zstd: bool,
    start_ns: Option<u64>,
    accel_channel: bool,
}

impl Default for RunLogOptions {
    fn default() -> Self {
        Self {
            library: concat!("pendulum-log/", env!("CARGO_PKG_VERSION")).to_string(),
            chunk_size_bytes: mcap::WriteOptions::DEFAULT_CHUNK_SIZE,
            compression_zstd: true,
            start_ns: None,
            accel_channel: true,
        }
    }
}

impl RunLogOptions {
    /// The defaults (see [`RunLogOptions`]).
    pub fn new() -> Self {
        Self::default()
    }

    /// The MCAP header's `library` string, so a file says which program wrote it.
    pub fn library(mut self, library: impl Into<String>) -> Self {
        self.library = library.into();
        self
    }

    /// Target uncompressed chunk size in bytes. Chunks are the unit of compression, CRC and
    /// random access; 1 MiB (the default) is a few seconds of a run.
    pub fn chunk_size(mut self, chunk_size_bytes: u64) -> Self {
        self.chunk_size_bytes = chunk_size_bytes.max(1);
        self
    }

    /// zstd-compress chunks (default true). JSON samples compress about tenfold.
    pub fn compression_zstd(mut self, on: bool) -> Self {
        self.compression_zstd = on;
        self
    }

    /// Wall-clock time of the run's first sample, ns since the Unix epoch (see
    /// [`RunLogWriter::set_start_ns`]); the same as calling that before the first message.
    pub fn start_ns(mut self, start_ns: Option<u64>) -> Self {
        self.start_ns = start_ns;
        self
    }

    /// Create the `/accel` channel even before (or without) any message (default true). A
    /// recording with no accelerometer passes false and gets no `/accel` channel at all.
    pub fn accel_channel(mut self, on: bool) -> Self {
        self.accel_channel = on;
        self
    }

    /// Starts writing a run whose file will be `final_path`.
    ///
    /// The data goes to a temporary `.NAME.<pid>-<n>.tmp` in the same folder (same file system,
    /// so the final rename is atomic; dot-prefixed, so dataset globs skip it). `final_path`
    /// appears only when [`RunLogWriter::finish`] succeeds, replacing any previous file of that
    /// name.
    ///
    /// The temporary name is unique to this process and writer, and created only if it does not
    /// exist yet: two processes writing the same run into one folder must not share (truncate,
    /// rename away or delete) each other's temporary file (issue 13).
    pub fn create(&self, final_path: &Path) -> Result<RunLogWriter, LogError> {
        static COUNTER: AtomicU64 = AtomicU64::new(0);
        let file_name = final_path
            .file_name()
            .ok_or_else(|| LogError::InvalidPath {
                path: final_path.to_path_buf(),
            })?;
        let mut tmp_name = std::ffi::OsString::from(".");
        tmp_name.push(file_name);
        tmp_name.push(format!(
            ".{}-{}.tmp",
            std::process::id(),
            COUNTER.fetch_add(1, Ordering::Relaxed)
        ));
        let tmp_path = final_path.with_file_name(tmp_name);

        let file = File::create_new(&tmp_path).map_err(|source| LogError::Io {
            path: tmp_path.clone(),
            op: "create the temporary file",
            source,
        })?;
        let write_options = mcap::WriteOptions::new()
            .library(self.library.clone())
            .chunk_size(Some(self.chunk_size_bytes))
            .compression(if self.compression_zstd {
                Some(mcap::Compression::Zstd)
            } else {
                None
            })
            // Single-threaded zstd: 1 MiB chunks gain nothing from worker threads, and several
            // runs are written in parallel already.
            .compression_threads(0);
        // From here on the temporary file exists: build the writer struct first so that its
        // Drop removes the file whatever fails next.
        let mut writer = RunLogWriter {
            final_path: final_path.to_path_buf(),
            tmp_path,
            mcap: None,
            channels: [None; 4],
            start_ns: self.start_ns,
            first_t_us: None,
            metadata_names: Vec::new(),
            stats: None,
            finished: false,
        };
        let mcap = write_options
            .create(BufWriter::new(file))
            .map_err(|source| writer.write_err("start the file", source))?;
        writer.mcap = Some(mcap);
        writer.ensure_channel(Topic::Encoder)?;
        if self.accel_channel {
            writer.ensure_channel(Topic::Accel)?;
        }
        Ok(writer)
    }
}

#[derive(Debug, Clone, Copy)]
struct ChannelState {
    id: u16,
    messages: u64,
    first_log_time_ns: Option<u64>,
    last_log_time_ns: Option<u64>,
}

/// Writes one run file. Create it with [`RunLogOptions::create`], write messages in time order
/// per channel, then call [`finish`](Self::finish). Dropping it unfinished deletes the temporary
/// file, so an error half-way never leaves a partial run behind.
///
/// Log time (and publish time, equal to it) of a sample is `start_ns + (t_us − first t_us)·1000`
/// when the capture's wall-clock start is known ([`set_start_ns`](Self::set_start_ns)), else the
/// unwrapped board clock `t_us·1000`. "First t_us" is derived from each message as
/// `t_us − round(t_s·1e6)`, so the result does not depend on which channel is written first.
pub struct RunLogWriter {
    final_path: PathBuf,
    tmp_path: PathBuf,
    mcap: Option<mcap::Writer<BufWriter<File>>>,
    channels: [Option<ChannelState>; 4],
    start_ns: Option<u64>,
    first_t_us: Option<i128>,
    metadata_names: Vec<String>,
    stats: Option<serde_json::Value>,
    finished: bool,
}

/// What [`RunLogWriter::finish`] wrote.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct RunLogSummary {
    /// The final file.
    pub path: PathBuf,
    /// Message count per topic, for every channel in the file (including empty ones).
    pub messages: BTreeMap<String, u64>,
    /// File size in bytes.
    pub bytes: u64,
}

impl RunLogWriter {
    /// The path the file will have after [`finish`](Self::finish).
    pub fn final_path(&self) -> &Path {
        &self.final_path
    }

    /// The temporary file being written.
    pub fn tmp_path(&self) -> &Path {
        &self.tmp_path
    }

    /// Anchors log times to wall-clock time: `start_ns` is the capture header's `started`
    /// ([`crate::parse_rfc3339_utc_ns`]) as ns since the Unix epoch, taken as the time of the
    /// run's first sample. `None` keeps log time on the board clock. Must be called before the
    /// first message, since it changes every message's time.
    pub fn set_start_ns(&mut self, start_ns: Option<u64>) -> Result<(), LogError> {
        if self
            .channels
            .iter()
            .flatten()
            .any(|c| c.messages > 0 && start_ns != self.start_ns)
        {
            return Err(LogError::StartAfterFirstMessage {
                path: self.final_path.clone(),
            });
        }
        self.start_ns = start_ns;
        Ok(())
    }

    /// Writes one encoder sample on `/encoder`.
    pub fn write_encoder(&mut self, msg: &EncoderMsg) -> Result<(), LogError> {
        self.check_finite(Topic::Encoder, &msg.floats())?;
        let log_time_ns = self.sample_log_time(Topic::Encoder, msg.t_us, msg.t_s)?;
        self.write_json(Topic::Encoder, log_time_ns, msg)
    }

    /// Writes one accelerometer sample on `/accel`.
    pub fn write_accel(&mut self, msg: &AccelMsg) -> Result<(), LogError> {
        self.check_finite(Topic::Accel, &msg.floats())?;
        let log_time_ns = self.sample_log_time(Topic::Accel, msg.t_us, msg.t_s)?;
        self.write_json(Topic::Accel, log_time_ns, msg)
    }

    /// Writes one model-replay sample on `/sim/theta` (the channel is created on first use).
    ///
    /// Its log time is the same time axis as the samples' at nanosecond resolution: `start_ns +
    /// t_s·1e9` with a start time, else `(first t_us)·1000 + t_s·1e9` (first t_us taken from the
    /// samples written so far, or 0 if none).
    pub fn write_simulated(&mut self, msg: &SimulatedMsg) -> Result<(), LogError> {
        let topic = Topic::Simulated;
        self.check_finite(topic, &msg.floats())?;
        let base_ns: i128 = match (self.start_ns, self.first_t_us) {
            (Some(start), _) => i128::from(start),
            (None, Some(first)) => first * 1000,
            (None, None) => 0,
        };
        let out_of_range = || LogError::TimeOutOfRange {
            path: self.final_path.clone(),
            topic: topic.name(),
            t_s: msg.t_s,
            t_us: None,
        };
        let offset_ns = (msg.t_s * 1e9).round();
        if offset_ns.abs() > 1e19 {
            return Err(out_of_range());
        }
        // `as` saturates and the bound above keeps the value exact enough for a range check.
        let log_time_ns = u64::try_from(base_ns + offset_ns as i128).map_err(|_| out_of_range())?;
        self.write_json(topic, log_time_ns, msg)
    }

    /// Writes a metadata record (e.g. [`crate::METADATA_RUN`], [`crate::METADATA_CAPTURE_HEADER`]).
    /// Each name may be written once, because readers key metadata by name.
    pub fn write_metadata(
        &mut self,
        name: &str,
        map: BTreeMap<String, String>,
    ) -> Result<(), LogError> {
        if self.metadata_names.iter().any(|n| n == name) {
            return Err(LogError::DuplicateMetadata {
                path: self.final_path.clone(),
                name: name.to_string(),
            });
        }
        let record = Metadata {
            name: name.to_string(),
            metadata: map,
        };
        let result = self.mcap_mut().write_metadata(&record);
        result.map_err(|source| self.write_err("write metadata", source))?;
        self.metadata_names.push(name.to_string());
        Ok(())
    }

    /// Sets the run's ingest statistics (a JSON object, see `schemas/ingest_stats.json`).
    ///
    /// It is written as the one message on `/ingest_stats` by [`finish`](Self::finish), stamped
    /// with the run's earliest log time, so it can be called before or after the samples and
    /// shows from the start of the run in Foxglove.
    pub fn write_stats(&mut self, stats: &serde_json::Value) -> Result<(), LogError> {
        let topic = Topic::Stats;
        if self.stats.is_some() {
            return Err(LogError::DuplicateStats {
                path: self.final_path.clone(),
                topic: topic.name(),
            });
        }
        if !stats.is_object() {
            return Err(LogError::Unexpected {
                path: self.final_path.clone(),
                topic: topic.name().to_string(),
                expected: "a JSON object",
                found: json_kind(stats).to_string(),
            });
        }
        self.stats = Some(stats.clone());
        Ok(())
    }

    /// Finishes the MCAP (summary, indexes, CRCs), syncs it to disk and renames the temporary
    /// file to the final name. Only after this does the final file exist.
    pub fn finish(mut self) -> Result<RunLogSummary, LogError> {
        if let Some(stats) = self.stats.take() {
            let log_time_ns = self
                .channels
                .iter()
                .flatten()
                .filter_map(|c| c.first_log_time_ns)
                .min()
                .or(self.start_ns)
                .unwrap_or(0);
            self.write_json(Topic::Stats, log_time_ns, &stats)?;
        }
        let mut mcap = self.mcap.take().ok_or_else(|| LogError::Io {
            path: self.tmp_path.clone(),
            op: "finish a writer that has no file",
            source: std::io::ErrorKind::Other.into(),
        })?;
        let finished = mcap.finish();
        // `into_inner` even on error, so that the file is closed before Drop removes it.
        let buffered = mcap.into_inner();
        finished.map_err(|source| self.write_err("finish the file", source))?;
        let file = buffered.into_inner().map_err(|e| LogError::Io {
            path: self.tmp_path.clone(),
            op: "flush the temporary file",
            source: e.into_error(),
        })?;
        file.sync_all().map_err(|source| LogError::Io {
            path: self.tmp_path.clone(),
            op: "sync the temporary file",
            source,
        })?;
        let bytes = file
            .metadata()
            .map_err(|source| LogError::Io {
                path: self.tmp_path.clone(),
                op: "stat the temporary file",
                source,
            })?
            .len();
        drop(file);
        fs::rename(&self.tmp_path, &self.final_path).map_err(|source| LogError::Io {
            path: self.final_path.clone(),
            op: "rename the temporary file to the final name",
            source,
        })?;
        self.finished = true;
        sync_parent_dir(&self.final_path)?;

        let messages = Topic::ALL
            .into_iter()
            .filter_map(|t| self.channels[t as usize].map(|c| (t.name().to_string(), c.messages)))
            .collect();
        Ok(RunLogSummary {
            path: self.final_path.clone(),
            messages,
            bytes,
        })
    }

    fn mcap_mut(&mut self) -> &mut mcap::Writer<BufWriter<File>> {
        // `mcap` is Some from `create` until `finish` (which consumes self) or Drop.
        self.mcap
            .as_mut()
            .unwrap_or_else(|| unreachable!("writer used after finish"))
    }

    fn write_err(&self, op: &'static str, source: mcap::McapError) -> LogError {
        LogError::Write {
            path: self.tmp_path.clone(),
            op,
            source,
        }
    }

    fn check_finite(&self, topic: Topic, floats: &[(&'static str, f64)]) -> Result<(), LogError> {
        match floats.iter().find(|(_, v)| !v.is_finite()) {
            Some(&(field, value)) => Err(LogError::NonFinite {
                path: self.final_path.clone(),
                topic: topic.name(),
                field,
                value,
            }),
            None => Ok(()),
        }
    }

    /// Log time of an encoder or accelerometer sample; see [`RunLogWriter`].
    fn sample_log_time(&mut self, topic: Topic, t_us: u64, t_s: f64) -> Result<u64, LogError> {
        let out_of_range = || LogError::TimeOutOfRange {
            path: self.final_path.clone(),
            topic: topic.name(),
            t_s,
            t_us: Some(t_us),
        };
        let since_first_us = (t_s * 1e6).round();
        if since_first_us.abs() > 1e19 {
            return Err(out_of_range());
        }
        let implied_first = i128::from(t_us) - since_first_us as i128;
        let first = match self.first_t_us {
            None => implied_first,
            // One microsecond of slack for t_s computed in floating point.
            Some(first) if (first - implied_first).abs() <= 1 => first,
            Some(first) => {
                return Err(LogError::InconsistentTime {
                    path: self.final_path.clone(),
                    topic: topic.name(),
                    t_us,
                    t_s,
                    implied_first_t_us: implied_first,
                    expected_first_t_us: first,
                })
            }
        };
        let log_time_ns: i128 = match self.start_ns {
            Some(start) => i128::from(start) + (i128::from(t_us) - first) * 1000,
            None => i128::from(t_us) * 1000,
        };
        let log_time_ns = u64::try_from(log_time_ns).map_err(|_| out_of_range())?;
        self.first_t_us = Some(first);
        Ok(log_time_ns)
    }

    fn ensure_channel(&mut self, topic: Topic) -> Result<u16, LogError> {
        if let Some(c) = self.channels[topic as usize] {
            return Ok(c.id);
        }
        let (schema_name, schema) = topic.schema();
        let mcap = self.mcap_mut();
        let result = mcap
            .add_schema(schema_name, SCHEMA_ENCODING, schema.as_bytes())
            .and_then(|schema_id| {
                mcap.add_channel(schema_id, topic.name(), MESSAGE_ENCODING, &BTreeMap::new())
            });
        let id = result.map_err(|source| self.write_err("add a channel", source))?;
        self.channels[topic as usize] = Some(ChannelState {
            id,
            messages: 0,
            first_log_time_ns: None,
            last_log_time_ns: None,
        });
        Ok(id)
    }

    fn write_json<T: Serialize>(
        &mut self,
        topic: Topic,
        log_time_ns: u64,
        msg: &T,
    ) -> Result<(), LogError> {
        let id = self.ensure_channel(topic)?;
        let state = self.channels[topic as usize].unwrap_or(ChannelState {
            id,
            messages: 0,
            first_log_time_ns: None,
            last_log_time_ns: None,
        });
        if let Some(previous_ns) = state.last_log_time_ns {
            if log_time_ns < previous_ns {
                return Err(LogError::OutOfOrder {
                    path: self.final_path.clone(),
                    topic: topic.name(),
                    index: state.messages,
                    log_time_ns,
                    previous_ns,
                });
            }
        }
        let data = serde_json::to_vec(msg).map_err(|source| LogError::Serialize {
            path: self.final_path.clone(),
            topic: topic.name(),
            source,
        })?;
        let header = MessageHeader {
            channel_id: id,
            // MCAP sequence numbers are u32 and may wrap; 1-based per channel.
            sequence: (state.messages.wrapping_add(1) & u64::from(u32::MAX)) as u32,
            log_time: log_time_ns,
            publish_time: log_time_ns,
        };
        let result = self.mcap_mut().write_to_known_channel(&header, &data);
        result.map_err(|source| self.write_err("write a message", source))?;
        self.channels[topic as usize] = Some(ChannelState {
            id,
            messages: state.messages + 1,
            first_log_time_ns: state.first_log_time_ns.or(Some(log_time_ns)),
            last_log_time_ns: Some(log_time_ns),
        });
        Ok(())
    }
}

impl Drop for RunLogWriter {
    /// An unfinished run must not survive: close the temporary file without completing the MCAP
    /// (`into_inner` skips the summary that `mcap::Writer`'s own Drop would write) and delete it.
    fn drop(&mut self) {
        if self.finished {
            return;
        }
        if let Some(mcap) = self.mcap.take() {
            drop(mcap.into_inner());
        }
        let _ = fs::remove_file(&self.tmp_path);
    }
}

/// Makes the rename durable: on Unix a rename is only on disk once its directory is synced.
fn sync_parent_dir(path: &Path) -> Result<(), LogError> {
    #[cfg(unix)]
    {
        let parent = match path.parent() {
            Some(p) if !p.as_os_str().is_empty() => p,
            _ => Path::new("."),
        };
        File::open(parent)
            .and_then(|dir| dir.sync_all())
            .map_err(|source| LogError::Io {
                path: parent.to_path_buf(),
                op: "sync the folder after the rename",
                source,
            })?;
    }
    #[cfg(not(unix))]
    let _ = path;
    Ok(())
}

pub(crate) fn json_kind(v: &serde_json::Value) -> &'static str {
    match v {
        serde_json::Value::Null => "null",
        serde_json::Value::Bool(_) => "a boolean",
        serde_json::Value::Number(_) => "a number",
        serde_json::Value::String(_) => "a string",
        serde_json::Value::Array(_) => "an array",
        serde_json::Value::Object(_) => "an object",
    }
}
