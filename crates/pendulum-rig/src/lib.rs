//! pendulum-rig: reads the rig's raw captures (serial text `serial-v1`, binary SD-card `sd-v2`)
//! and the campaign description `campaign.toml`, as specified in `shared/spec/rig.md`.
//!
//! Readers stream in constant memory, never panic on damaged input, and report what they
//! dropped (with line numbers or byte offsets) in [`IngestStats`].

pub mod bounce;
pub mod campaign;
pub mod capture;
pub mod crc8;
pub mod detect;
pub mod error;
mod lines;
pub mod names;
pub mod sd;
pub mod serial;

pub use campaign::{Campaign, Role, RunSpec};
pub use capture::{
    AccelSample, EncoderSample, Gap, Header, IngestStats, Location, OffTimelineBlock, ReadOptions,
    Sample, Skip, TimelinePlan,
};
pub use detect::CaptureReader;
pub use error::RigError;
pub use sd::{SdReader, SdWriter};
pub use serial::{SerialReader, SerialWriter};
pub mod timeseries;
pub mod twin;
