//! Reading a run file back, with every CRC checked.

use std::collections::{BTreeMap, HashMap};
use std::fs::File;
use std::io::{BufReader, ErrorKind, Read};
use std::ops::ControlFlow;
use std::path::{Path, PathBuf};

use mcap::records::Record;
use mcap::sans_io::{LinearReadEvent, LinearReader, LinearReaderOptions};
use mcap::McapError;

use crate::write::{json_kind, Topic};
use crate::{AccelMsg, EncoderMsg, LogError, SimulatedMsg, MESSAGE_ENCODING, SCHEMA_ENCODING};

/// A whole run file in memory. Messages are in file order, which the writer guarantees is
/// non-decreasing log time per channel.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct RunLog {
    /// The file read.
    pub path: PathBuf,
    /// The MCAP header's `library` (which program wrote the file).
    pub library: String,
    /// `/encoder` messages.
    pub encoder: Vec<EncoderMsg>,
    /// Log time of each `/encoder` message, ns (same index as `encoder`).
    pub encoder_log_time_ns: Vec<u64>,
    /// `/accel` messages.
    pub accel: Vec<AccelMsg>,
    /// Log time of each `/accel` message, ns.
    pub accel_log_time_ns: Vec<u64>,
    /// `/sim/theta` messages (empty if the run has no replay).
    pub simulated: Vec<SimulatedMsg>,
    /// Log time of each `/sim/theta` message, ns.
    pub simulated_log_time_ns: Vec<u64>,
    /// Metadata records by name (e.g. "run", "capture_header").
    pub metadata: BTreeMap<String, BTreeMap<String, String>>,
    /// The `/ingest_stats` message, if any.
    pub stats: Option<serde_json::Value>,
    /// Message counts on topics this crate does not know (kept, not failed, so files written by
    /// later versions still read).
    pub other_topics: BTreeMap<String, u64>,
}

/// One message of a run file, as passed to [`for_each_message`].
#[derive(Debug, Clone, PartialEq)]
pub enum RunMessage {
    Encoder {
        log_time_ns: u64,
        msg: EncoderMsg,
    },
    Accel {
        log_time_ns: u64,
        msg: AccelMsg,
    },
    Simulated {
        log_time_ns: u64,
        msg: SimulatedMsg,
    },
    Stats {
        log_time_ns: u64,
        stats: serde_json::Value,
    },
}

/// Reads a whole run file, checking chunk, data-section and summary CRCs, the end magic, the
/// channels' encodings and the message counts recorded in the file's statistics. A corrupt or
/// truncated file is an error naming the file, never partial or garbled data.
pub fn read_run(path: &Path) -> Result<RunLog, LogError> {
    let mut run = RunLog {
        path: path.to_path_buf(),
        ..RunLog::default()
    };
    let mut stats_count = 0u64;
    visit(path, &mut |item| {
        match item {
            Item::Library(library) => run.library = library,
            Item::Metadata(name, map) => {
                run.metadata.insert(name, map);
            }
            Item::Message(RunMessage::Encoder { log_time_ns, msg }) => {
                run.encoder.push(msg);
                run.encoder_log_time_ns.push(log_time_ns);
            }
            Item::Message(RunMessage::Accel { log_time_ns, msg }) => {
                run.accel.push(msg);
                run.accel_log_time_ns.push(log_time_ns);
            }
            Item::Message(RunMessage::Simulated { log_time_ns, msg }) => {
                run.simulated.push(msg);
                run.simulated_log_time_ns.push(log_time_ns);
            }
            Item::Message(RunMessage::Stats { stats, .. }) => {
                stats_count += 1;
                if run.stats.is_none() {
                    run.stats = Some(stats);
                }
            }
            Item::Other(topic) => *run.other_topics.entry(topic).or_insert(0) += 1,
        }
        ControlFlow::Continue(())
    })?;
    if stats_count > 1 {
        return Err(LogError::Unexpected {
            path: path.to_path_buf(),
            topic: Topic::Stats.name().to_string(),
            expected: "one message",
            found: format!("{stats_count} messages"),
        });
    }
    Ok(run)
}

/// Streams a run file's messages in file order with memory bounded by one chunk, with the same
/// checks as [`read_run`]. Return `ControlFlow::Break(())` from `f` to stop early (the rest of the
/// file is then not checked).
///
/// Each chunk's CRC is checked before any of its messages reach `f`, so `f` never sees garbled
/// data; a file truncated or corrupted further on still gives an error after the earlier
/// messages were delivered.
pub fn for_each_message(
    path: &Path,
    mut f: impl FnMut(RunMessage) -> ControlFlow<()>,
) -> Result<(), LogError> {
    visit(path, &mut |item| match item {
        Item::Message(m) => f(m),
        _ => ControlFlow::Continue(()),
    })
}

enum Item {
    Library(String),
    Metadata(String, BTreeMap<String, String>),
    Message(RunMessage),
    Other(String),
}

struct ChannelInfo {
    topic: String,
    known: Option<Topic>,
    messages: u64,
}

/// Largest record (or decompressed chunk) the reader accepts, so a corrupt length field cannot
/// make it allocate gigabytes. Far above the writer's 1 MiB default chunks.
const MIN_RECORD_LIMIT_BYTES: u64 = 256 * 1024 * 1024;

fn visit(path: &Path, f: &mut dyn FnMut(Item) -> ControlFlow<()>) -> Result<(), LogError> {
    let file = File::open(path).map_err(|source| LogError::Io {
        path: path.to_path_buf(),
        op: "open the run file",
        source,
    })?;
    let size_bytes = file
        .metadata()
        .map_err(|source| LogError::Io {
            path: path.to_path_buf(),
            op: "stat the run file",
            source,
        })?
        .len();
    let limit = usize::try_from(size_bytes.max(MIN_RECORD_LIMIT_BYTES)).unwrap_or(usize::MAX);
    let mut source = BufReader::with_capacity(64 * 1024, file);
    let mut reader = LinearReader::new_with_options(
        LinearReaderOptions::default()
            // Check each chunk's CRC before yielding its records (the default checks none).
            .with_prevalidate_chunk_crcs(true)
            .with_validate_chunk_crcs(true)
            .with_validate_data_section_crc(true)
            .with_validate_summary_section_crc(true)
            .with_check_finishes_after_end_magic(true)
            .with_record_length_limit(limit),
    );
    let classify = |e: McapError| classify_error(path, size_bytes, e);

    let mut schema_encodings: HashMap<u16, String> = HashMap::new();
    let mut channels: HashMap<u16, ChannelInfo> = HashMap::new();
    let mut after_data_end = false;

    while let Some(event) = reader.next_event() {
        let (opcode, data) = match event.map_err(classify)? {
            LinearReadEvent::ReadRequest(need) => {
                let buf = reader.insert(need);
                let read = loop {
                    match source.read(buf) {
                        Ok(n) => break n,
                        Err(e) if e.kind() == ErrorKind::Interrupted => continue,
                        Err(source) => {
                            return Err(LogError::Io {
                                path: path.to_path_buf(),
                                op: "read the run file",
                                source,
                            })
                        }
                    }
                };
                reader.notify_read(read);
                continue;
            }
            LinearReadEvent::Record { opcode, data } => (opcode, data),
        };
        let record = mcap::parse_record(opcode, data).map_err(classify)?;
        let flow = match record {
            Record::Header(header) => f(Item::Library(header.library)),
            Record::Schema { header, .. } => {
                // The summary section repeats schemas and channels; they must match.
                schema_encodings.insert(header.id, header.encoding);
                ControlFlow::Continue(())
            }
            Record::Channel(channel) => {
                let known = Topic::from_name(&channel.topic);
                if known.is_some() {
                    let schema_encoding = schema_encodings
                        .get(&channel.schema_id)
                        .map(String::as_str)
                        .unwrap_or("no schema");
                    if schema_encoding != SCHEMA_ENCODING
                        || channel.message_encoding != MESSAGE_ENCODING
                    {
                        return Err(LogError::Unexpected {
                            path: path.to_path_buf(),
                            topic: channel.topic,
                            expected: "schema encoding jsonschema and message encoding json",
                            found: format!(
                                "schema encoding {schema_encoding:?}, message encoding {:?}",
                                channel.message_encoding
                            ),
                        });
                    }
                }
                if !after_data_end || !channels.contains_key(&channel.id) {
                    let messages = channels.get(&channel.id).map_or(0, |c| c.messages);
                    channels.insert(
                        channel.id,
                        ChannelInfo {
                            topic: channel.topic,
                            known,
                            messages,
                        },
                    );
                }
                ControlFlow::Continue(())
            }
            Record::Message { header, data } => {
                let Some(channel) = channels.get_mut(&header.channel_id) else {
                    return Err(classify(McapError::UnknownChannel(
                        header.sequence,
                        header.channel_id,
                    )));
                };
                let index = channel.messages;
                channel.messages += 1;
                let log_time_ns = header.log_time;
                let item = match channel.known {
                    None => Item::Other(channel.topic.clone()),
                    Some(topic) => {
                        let bad = |expected: &'static str| {
                            move |source| LogError::BadMessage {
                                path: path.to_path_buf(),
                                topic: topic.name(),
                                index,
                                expected,
                                source,
                            }
                        };
                        Item::Message(match topic {
                            Topic::Encoder => RunMessage::Encoder {
                                log_time_ns,
                                msg: serde_json::from_slice(&data).map_err(bad("EncoderMsg"))?,
                            },
                            Topic::Accel => RunMessage::Accel {
                                log_time_ns,
                                msg: serde_json::from_slice(&data).map_err(bad("AccelMsg"))?,
                            },
                            Topic::Simulated => RunMessage::Simulated {
                                log_time_ns,
                                msg: serde_json::from_slice(&data).map_err(bad("SimulatedMsg"))?,
                            },
                            Topic::Stats => {
                                let stats: serde_json::Value =
                                    serde_json::from_slice(&data).map_err(bad("JSON object"))?;
                                if !stats.is_object() {
                                    return Err(LogError::Unexpected {
                                        path: path.to_path_buf(),
                                        topic: topic.name().to_string(),
                                        expected: "a JSON object",
                                        found: json_kind(&stats).to_string(),
                                    });
                                }
                                RunMessage::Stats { log_time_ns, stats }
                            }
                        })
                    }
                };
                f(item)
            }
            Record::Metadata(m) => f(Item::Metadata(m.name, m.metadata)),
            Record::DataEnd(_) => {
                after_data_end = true;
                ControlFlow::Continue(())
            }
            Record::Statistics(stats) => {
                // A second, independent count: catches a summary that disagrees with the data.
                for (id, &expected) in &stats.channel_message_counts {
                    let found = channels.get(id).map_or(0, |c| c.messages);
                    if found != expected {
                        return Err(LogError::Unexpected {
                            path: path.to_path_buf(),
                            topic: channels
                                .get(id)
                                .map_or_else(|| format!("channel {id}"), |c| c.topic.clone()),
                            expected: "as many messages as the file's statistics record",
                            found: format!("{found} messages, statistics say {expected}"),
                        });
                    }
                }
                ControlFlow::Continue(())
            }
            _ => ControlFlow::Continue(()),
        };
        if flow.is_break() {
            return Ok(());
        }
    }
    Ok(())
}

fn classify_error(path: &Path, size_bytes: u64, e: McapError) -> LogError {
    let path = path.to_path_buf();
    let crc = |section, stored, computed| LogError::CrcMismatch {
        path: path.clone(),
        section,
        stored,
        computed,
    };
    match e {
        McapError::UnexpectedEof => LogError::Truncated { path, size_bytes },
        McapError::BadChunkCrc { saved, calculated } => crc("chunk", saved, calculated),
        McapError::BadDataCrc { saved, calculated } => crc("data section", saved, calculated),
        McapError::BadSummaryCrc { saved, calculated } => crc("summary section", saved, calculated),
        source => LogError::Corrupt { path, source },
    }
}
