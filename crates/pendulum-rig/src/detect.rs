//! Opening a capture whose format is told by its content, not its name.

use std::fs::File;
use std::io::{BufRead, BufReader};
use std::path::Path;

use crate::campaign::RunSpec;
use crate::capture::{Header, IngestStats, Location, ReadOptions, Sample, TimelinePlan};
use crate::error::RigError;
use crate::sd::{SdReader, SYNC};
use crate::serial::{SerialReader, COLUMN_LINE};
use crate::timeseries::{TimeseriesReader, TimeseriesSpec, FORMAT as TIMESERIES};

/// A capture of any format, opened from a file.
pub enum CaptureReader {
    Serial(SerialReader<BufReader<File>>),
    Sd(SdReader<BufReader<File>>),
    /// A generic CSV/TSV time series described by its campaign run (`format = "timeseries"`).
    Timeseries(TimeseriesReader<BufReader<File>>),
}

impl CaptureReader {
    /// Opens a campaign run's capture: a `format = "timeseries"` run as the time series its
    /// keys describe, any other run by [`CaptureReader::open`] (format told by the content).
    pub fn open_run(spec: &RunSpec, opts: ReadOptions) -> Result<Self, RigError> {
        if spec.format.as_deref() == Some(TIMESERIES) {
            let ts = TimeseriesSpec::from_run(spec)?;
            return Ok(CaptureReader::Timeseries(TimeseriesReader::open(
                &spec.file, ts, opts,
            )?));
        }
        Self::open(&spec.file, opts)
    }

    /// Opens `path` and detects its format: `A5 5A` first → `sd-v2`; text starting (after
    /// blank space) with `#` or the column line → `serial-v1`; anything else is
    /// [`RigError::NotACapture`].
    pub fn open(path: impl AsRef<Path>, opts: ReadOptions) -> Result<Self, RigError> {
        let path = path.as_ref();
        let file = File::open(path).map_err(|e| RigError::io(path, e))?;
        let mut reader = BufReader::with_capacity(64 * 1024, file);
        let head = loop {
            match reader.fill_buf() {
                Ok(b) => break b,
                Err(e) if e.kind() == std::io::ErrorKind::Interrupted => continue,
                Err(e) => return Err(RigError::io(path, e)),
            }
        };
        if head.is_empty() {
            // `fill_buf` returns nothing only at the end of the file: say so plainly rather
            // than list the formats it does not match.
            return Err(RigError::NotACapture {
                path: path.to_path_buf(),
                at: Location::Byte(0),
                reason: "file is empty (0 bytes)".into(),
            });
        }
        if head.starts_with(&SYNC) {
            return Ok(CaptureReader::Sd(SdReader::new(reader, path, opts)?));
        }
        let text = head.strip_prefix(b"\xEF\xBB\xBF").unwrap_or(head);
        let first = text
            .iter()
            .position(|b| !b.is_ascii_whitespace())
            .map(|i| &text[i..]);
        let serial = match first {
            Some(t) => t.starts_with(b"#") || t.starts_with(b"t_us"),
            // Only blank space so far: let the serial reader say what is wrong.
            None => !head.is_empty(),
        };
        if serial {
            return Ok(CaptureReader::Serial(SerialReader::new(
                reader, path, opts,
            )?));
        }
        Err(RigError::NotACapture {
            path: path.to_path_buf(),
            at: Location::Byte(0),
            reason: format!(
                "expected an sd-v2 capture (bytes A5 5A) or a serial-v1 capture (a `#` header \
                 line or the column line `{COLUMN_LINE}`)"
            ),
        })
    }

    /// `"serial-v1"`, `"sd-v2"` or `"timeseries"`.
    pub fn format(&self) -> &'static str {
        match self {
            CaptureReader::Serial(_) => "serial-v1",
            CaptureReader::Sd(_) => "sd-v2",
            CaptureReader::Timeseries(_) => TIMESERIES,
        }
    }

    /// See [`SerialReader::next_sample`] and [`SdReader::next_sample`].
    pub fn next_sample(&mut self) -> Result<Option<Sample>, RigError> {
        match self {
            CaptureReader::Serial(r) => r.next_sample(),
            CaptureReader::Sd(r) => r.next_sample(),
            CaptureReader::Timeseries(r) => r.next_sample(),
        }
    }

    /// See [`SdReader::set_timeline_plan`] (a generic time series has no board clock to
    /// judge: ignored).
    pub fn set_timeline_plan(&mut self, plan: TimelinePlan) {
        match self {
            CaptureReader::Serial(r) => r.set_timeline_plan(plan),
            CaptureReader::Sd(r) => r.set_timeline_plan(plan),
            CaptureReader::Timeseries(_) => {}
        }
    }

    /// See [`SdReader::timeline_plan`]: after the last sample, the blocks to drop on a second
    /// reading, if any.
    pub fn timeline_plan(&self) -> Option<TimelinePlan> {
        match self {
            CaptureReader::Serial(r) => r.timeline_plan(),
            CaptureReader::Sd(r) => r.timeline_plan(),
            CaptureReader::Timeseries(_) => None,
        }
    }

    /// Opens a run's capture ([`CaptureReader::open_run`]) with the plan of an earlier reading
    /// (none on the first).
    pub fn open_run_planned(
        spec: &RunSpec,
        opts: ReadOptions,
        plan: Option<&TimelinePlan>,
    ) -> Result<Self, RigError> {
        let mut r = Self::open_run(spec, opts)?;
        if let Some(p) = plan {
            r.set_timeline_plan(p.clone());
        }
        Ok(r)
    }

    pub fn header(&self) -> &Header {
        match self {
            CaptureReader::Serial(r) => r.header(),
            CaptureReader::Sd(r) => r.header(),
            CaptureReader::Timeseries(r) => r.header(),
        }
    }

    pub fn stats(&self) -> &IngestStats {
        match self {
            CaptureReader::Serial(r) => r.stats(),
            CaptureReader::Sd(r) => r.stats(),
            CaptureReader::Timeseries(r) => r.stats(),
        }
    }
}
