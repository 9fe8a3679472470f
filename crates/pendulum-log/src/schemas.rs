//! The JSON Schemas of the run file's channels, embedded from `schemas/*.json` at the workspace
//! root.
//!
//! They are embedded (not read at run time) so a run file is self-describing wherever the binary
//! runs; the files in `schemas/` stay the single source that reviewers and other tools read.

/// Schema of `/encoder` ([`crate::EncoderMsg`]).
pub const ENCODER: &str = include_str!("../../../schemas/encoder.json");
/// Schema of `/accel` ([`crate::AccelMsg`]).
pub const ACCEL: &str = include_str!("../../../schemas/accel.json");
/// Schema of `/ingest_stats` (a free-form JSON object with documented fields).
pub const INGEST_STATS: &str = include_str!("../../../schemas/ingest_stats.json");
/// Schema of `/sim/theta` ([`crate::SimulatedMsg`]).
pub const SIMULATED: &str = include_str!("../../../schemas/simulated.json");

/// MCAP schema name of `/encoder`; Foxglove shows it as the message type.
pub const ENCODER_NAME: &str = "pendulum.Encoder";
/// MCAP schema name of `/accel`.
pub const ACCEL_NAME: &str = "pendulum.Accel";
/// MCAP schema name of `/ingest_stats`.
pub const INGEST_STATS_NAME: &str = "pendulum.IngestStats";
/// MCAP schema name of `/sim/theta`.
pub const SIMULATED_NAME: &str = "pendulum.Simulated";
