//! Generic time-series captures (`format = "timeseries"` in `campaign.toml`): a CSV/TSV file of
//! columns (a time column or a fixed sample rate, an angle column, optional accelerometer
//! columns) from a rig that is not ours, read into the same [`Sample`]s as the rig's captures.
//!
//! The run entry describes the file (every key below also works in the `[rig]` table):
//!
//! ```toml
//! [[run]]
//! id = "small"
//! file = "single_small_amplitude_1khz.csv"
//! role = "identify"
//! format = "timeseries"
//! time_column = "t_s"        # seconds; or `sample_hz = 1000` when the file has no time column
//! angle_column = "theta_rad"
//! angle_unit = "rad"         # rad | deg | counts (then counts_per_rev = 40000)
//! hanging_angle = 3.14159265 # the angle's value at the hanging position, in angle_unit
//! # accel_z_column = "az"; accel_x_column = "ax"; accel_y_column = "ay"; accel_unit = "m/s2" | "g"
//! ```
//!
//! A column is named (`"t_s"`) or given by its 0-based index (`time_column = 0`, `angle_column
//! = 1`, the first column is 0): when every column the run uses is given by index, the file
//! needs no column-name line (a recording that starts with its first sample); a first line
//! that is all numbers is then data. An index also works when the file has a column-name line.
//!
//! Optional keys: `time_unit` (`s`, `ms`, `us`; default `s`), `delimiter` (`","`, `"\t"`, `";"`,
//! `" "` for runs of blanks; default: detected from the column line), `counts_per_rev` also with
//! `rad`/`deg` (then the encoder-equivalent count is filled in). Rig keys (`m_kg`, `l_m`, …) are
//! optional for such runs; no `omega_hz` means no shaker.
//!
//! The file: optional `# key=value` lines (kept in the header, like the rig's), then one
//! column-name line, then one line per sample. Same rules as the rig's readers: a damaged line
//! (wrong number of fields, a field that is not a finite number) is skipped and reported with its
//! line number; a time that does not increase is reported and its line skipped; a time that jumps
//! ahead is believed only if the following lines continue from it; gaps are counted.
//!
//! Bursty stamps: when a third or more of the rows repeat the previous row's stamp (a host that
//! reads the serial buffer every ~60 ms and stamps all it got with the time of the read), the
//! stamps are not the samples' times. The reader then measures the steady rate over the bursts
//! (rows of bursts 2..K / time from stamp 1 to stamp K, over the first 50,000 rows; the median
//! over bursts when the two disagree by more than 5 %, i.e. samples were lost), or takes
//! `sample_hz` when given, and times each row as `t0 + row index / rate` (re-anchored on the
//! stamps after lost samples). The header's `time_base` says so, with the rate. Too few bursts to
//! measure a rate and no `sample_hz`: the file is refused with a message naming the problem.
//!
//! What a sample becomes: `EncoderSample { t_us: time·1e6 (or index / sample_hz ·1e6),
//! theta_rad: (angle − hanging_angle) in rad, count: the count relative to hanging for
//! `counts`, floor(θ·cpr/2π) when `counts_per_rev` is given with another unit, else 0 }`, and,
//! when accelerometer columns are given, an `AccelSample` at the same time (axes without a column
//! read 0; `raw` is the equivalent at 8192 LSB/g, saturated, and the header says so).

use crate::lines::{read_bounded_line, LineInfo};
use std::collections::{BTreeMap, VecDeque};
use std::f64::consts::TAU;
use std::io::{self, BufRead};
use std::path::{Path, PathBuf};

use serde::Serialize;
use toml::Value;

use crate::campaign::RunSpec;
use crate::capture::{
    snippet, AccelSample, EncoderSample, GapTracker, Header, IngestStats, Location, ReadOptions,
    Sample, CONFIRM_RECORDS, DEFAULT_ACCEL_LSB_PER_G,
};
use crate::error::RigError;

/// The `format` value of such runs.
pub const FORMAT: &str = "timeseries";

/// The run keys this format reads (they stay in [`RunSpec::extra`]).
pub const TIMESERIES_KEYS: [&str; 12] = [
    "time_column",
    "time_unit",
    "sample_hz",
    "angle_column",
    "angle_unit",
    "counts_per_rev",
    "hanging_angle",
    "accel_x_column",
    "accel_y_column",
    "accel_z_column",
    "accel_unit",
    "delimiter",
];

/// A line longer than this is garbage (a real line is a few dozen bytes per column).
const MAX_LINE_BYTES: usize = 64 * 1024;
/// Rows looked at to estimate the nominal sample period when only a time column is given.
const RATE_PROBE_ROWS: usize = 33;
/// Stamps are bursty when at least this fraction of the probed rows repeat the previous row's
/// stamp (a file with an odd duplicated stamp is not bursty: that row is skipped as before).
const BURSTY_REPEAT_FRACTION: f64 = 1.0 / 3.0;
/// Rows read ahead to measure the steady rate of bursty stamps (or the whole file if shorter):
/// at ~260 Hz, over three minutes, so the rate's error (one burst's jitter over the span) is far
/// below 1 %.
const BURST_PROBE_ROWS: usize = 50_000;
/// Bursts needed to measure a rate.
const MIN_BURSTS: usize = 4;

/// The unit of the angle column.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum AngleUnit {
    Rad,
    Deg,
    /// Encoder counts, `counts_per_rev` per revolution.
    Counts,
}

impl AngleUnit {
    pub fn as_str(&self) -> &'static str {
        match self {
            AngleUnit::Rad => "rad",
            AngleUnit::Deg => "deg",
            AngleUnit::Counts => "counts",
        }
    }
}

/// The unit of the accelerometer columns.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub enum AccelUnit {
    /// m/s² (key value `"m/s2"`, also `"m/s^2"`, `"mps2"`).
    MS2,
    /// Multiples of the campaign's g.
    G,
}

/// The column separator.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
pub enum Delimiter {
    Byte(u8),
    /// Runs of blanks (spaces or tabs).
    Whitespace,
}

impl Delimiter {
    fn name(&self) -> String {
        match self {
            Delimiter::Byte(b'\t') => "\\t".into(),
            Delimiter::Byte(b) => char::from(*b).to_string(),
            Delimiter::Whitespace => "whitespace".into(),
        }
    }

    fn split<'a>(&self, line: &'a [u8]) -> Vec<&'a [u8]> {
        match self {
            Delimiter::Byte(d) => line.split(|b| b == d).collect(),
            Delimiter::Whitespace => line
                .split(|b| *b == b' ' || *b == b'\t')
                .filter(|f| !f.is_empty())
                .collect(),
        }
    }
}

/// A column of a time-series file: by its name in the column-name line, or by its 0-based
/// index (then the file needs no column-name line when every column is given so).
#[derive(Debug, Clone, PartialEq, Eq, Serialize)]
pub enum ColumnRef {
    Name(String),
    Index(usize),
}

impl std::fmt::Display for ColumnRef {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            ColumnRef::Name(n) => f.write_str(n),
            ColumnRef::Index(i) => write!(f, "#{i}"),
        }
    }
}

/// The largest column index a run may give (a file of more columns is no time series).
pub const MAX_COLUMN_INDEX: i64 = 9999;

/// A `format = "timeseries"` run's description of its file.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct TimeseriesSpec {
    /// The time column (in `time_unit`); `None` = times from `sample_hz`.
    pub time_column: Option<ColumnRef>,
    /// Seconds per unit of the time column (1, 1e-3 or 1e-6).
    pub time_scale_s: f64,
    /// The sample rate: the time base without a time column; with one, the nominal rate (for
    /// gap reports), and the time base when the stamps come in bursts (it overrides the rate
    /// measured over the bursts).
    pub sample_hz: Option<f64>,
    pub angle_column: ColumnRef,
    pub angle_unit: AngleUnit,
    pub counts_per_rev: Option<f64>,
    /// The angle's value at the hanging position, in `angle_unit`.
    pub hanging_angle: f64,
    /// `[x, y, z]` accelerometer columns.
    pub accel_columns: [Option<ColumnRef>; 3],
    pub accel_unit: AccelUnit,
    /// `None` = detected from the column line.
    pub delimiter: Option<Delimiter>,
}

impl TimeseriesSpec {
    /// Reads and checks the keys of a run (rig table merged in). `path` (campaign.toml) and
    /// `run` (its id) name the place in messages.
    pub fn from_keys(
        keys: &BTreeMap<String, Value>,
        path: &Path,
        run: &str,
    ) -> Result<Self, RigError> {
        let err = |key: &str, expected: &str| RigError::CampaignKey {
            path: path.to_path_buf(),
            run: Some(run.to_string()),
            key: key.to_string(),
            expected: expected.to_string(),
        };
        let column = |key: &str| -> Result<Option<ColumnRef>, RigError> {
            match keys.get(key) {
                None => Ok(None),
                Some(Value::String(s)) if !s.trim().is_empty() => {
                    Ok(Some(ColumnRef::Name(s.trim().to_string())))
                }
                Some(Value::Integer(i)) if (0..=MAX_COLUMN_INDEX).contains(i) => {
                    Ok(Some(ColumnRef::Index(*i as usize)))
                }
                Some(_) => Err(err(
                    key,
                    "a column name (a non-empty string) or a 0-based column index (0 to 9999)",
                )),
            }
        };
        let number = |key: &str, positive: bool| -> Result<Option<f64>, RigError> {
            let v = match keys.get(key) {
                None => return Ok(None),
                Some(Value::Float(f)) => *f,
                Some(Value::Integer(i)) => *i as f64,
                Some(_) => {
                    return Err(err(
                        key,
                        if positive {
                            "a positive number"
                        } else {
                            "a number"
                        },
                    ))
                }
            };
            if !v.is_finite() || (positive && v <= 0.0) {
                return Err(err(
                    key,
                    if positive {
                        "a positive number"
                    } else {
                        "a finite number"
                    },
                ));
            }
            Ok(Some(v))
        };
        let time_column = column("time_column")?;
        let sample_hz = number("sample_hz", true)?;
        if time_column.is_none() && sample_hz.is_none() {
            return Err(err(
                "time_column",
                "a column name (or `sample_hz` when the file has no time column)",
            ));
        }
        let time_scale_s = match keys.get("time_unit") {
            None => 1.0,
            Some(Value::String(s)) => match s.trim() {
                "s" => 1.0,
                "ms" => 1e-3,
                "us" | "µs" => 1e-6,
                _ => return Err(err("time_unit", "\"s\", \"ms\" or \"us\"")),
            },
            Some(_) => return Err(err("time_unit", "\"s\", \"ms\" or \"us\"")),
        };
        let angle_column =
            column("angle_column")?.ok_or_else(|| err("angle_column", "a column name or index"))?;
        let angle_unit = match keys.get("angle_unit") {
            Some(Value::String(s)) => match s.trim() {
                "rad" => AngleUnit::Rad,
                "deg" => AngleUnit::Deg,
                "counts" => AngleUnit::Counts,
                _ => return Err(err("angle_unit", "\"rad\", \"deg\" or \"counts\"")),
            },
            _ => return Err(err("angle_unit", "\"rad\", \"deg\" or \"counts\"")),
        };
        let counts_per_rev = number("counts_per_rev", true)?;
        if angle_unit == AngleUnit::Counts && counts_per_rev.is_none() {
            return Err(err(
                "counts_per_rev",
                "a positive number (angle_unit = \"counts\" needs it)",
            ));
        }
        let hanging_angle = number("hanging_angle", false)?.unwrap_or(0.0);
        let accel_columns = [
            column("accel_x_column")?,
            column("accel_y_column")?,
            column("accel_z_column")?,
        ];
        let accel_unit = match keys.get("accel_unit") {
            None => AccelUnit::MS2,
            Some(Value::String(s)) => match s.trim() {
                "m/s2" | "m/s^2" | "m/s²" | "mps2" => AccelUnit::MS2,
                "g" => AccelUnit::G,
                _ => return Err(err("accel_unit", "\"m/s2\" or \"g\"")),
            },
            Some(_) => return Err(err("accel_unit", "\"m/s2\" or \"g\"")),
        };
        let delimiter = match keys.get("delimiter") {
            None => None,
            Some(Value::String(s)) => Some(match s.as_str() {
                "," => Delimiter::Byte(b','),
                "\t" | "\\t" | "tab" => Delimiter::Byte(b'\t'),
                ";" => Delimiter::Byte(b';'),
                " " | "whitespace" => Delimiter::Whitespace,
                _ => {
                    return Err(err(
                        "delimiter",
                        "\",\", \"\\t\", \";\" or \" \" (runs of blanks)",
                    ))
                }
            }),
            Some(_) => {
                return Err(err(
                    "delimiter",
                    "\",\", \"\\t\", \";\" or \" \" (runs of blanks)",
                ))
            }
        };
        Ok(Self {
            time_column,
            time_scale_s,
            sample_hz,
            angle_column,
            angle_unit,
            counts_per_rev,
            hanging_angle,
            accel_columns,
            accel_unit,
            delimiter,
        })
    }

    /// The spec of a campaign run (its keys are in [`RunSpec::extra`]); messages name the
    /// capture file, since the run carries no campaign path.
    pub fn from_run(spec: &RunSpec) -> Result<Self, RigError> {
        Self::from_keys(&spec.extra, &spec.file, &spec.id)
    }

    /// Radians per unit of the angle column.
    pub fn rad_per_unit(&self) -> f64 {
        match self.angle_unit {
            AngleUnit::Rad => 1.0,
            AngleUnit::Deg => std::f64::consts::PI / 180.0,
            AngleUnit::Counts => TAU / self.counts_per_rev.unwrap_or(1.0),
        }
    }

    fn has_accel(&self) -> bool {
        self.accel_columns.iter().any(Option::is_some)
    }

    /// Every column the run uses is given by index: the file may have no column-name line.
    fn by_index_only(&self) -> bool {
        let cols = self
            .time_column
            .iter()
            .chain(std::iter::once(&self.angle_column))
            .chain(self.accel_columns.iter().flatten());
        cols.clone().all(|c| matches!(c, ColumnRef::Index(_)))
    }
}

/// A parsed data line, not yet accepted.
#[derive(Debug, Clone, Copy)]
struct Row {
    line: u64,
    bytes: u64,
    /// Data-line index (damaged lines count: they were samples too).
    index: u64,
    /// Seconds, as in the file (time column) or from the data-line index.
    t_s: f64,
    angle: f64,
    accel: [f64; 3],
}

/// Streaming reader of a time-series file.
pub struct TimeseriesReader<R: BufRead> {
    reader: R,
    path: PathBuf,
    spec: TimeseriesSpec,
    opts: ReadOptions,
    header: Header,
    delim: Delimiter,
    columns: Vec<String>,
    /// The line read as the column-name line (for a file without one, the first sample).
    column_line_info: Option<LineInfo>,
    /// A file without a column-name line: its first sample, read again as data.
    first_data: Option<(LineInfo, Vec<u8>)>,
    ncols: usize,
    idx_time: Option<usize>,
    idx_angle: usize,
    idx_accel: [Option<usize>; 3],
    rad_per_unit: f64,
    line_no: u64,
    /// Bytes read so far (where the next line starts).
    byte_pos: u64,
    /// Data lines seen so far (good or bad): the sample index when times come from `sample_hz`.
    data_lines: u64,
    line: Vec<u8>,
    lookahead: VecDeque<Row>,
    drained: bool,
    /// Nominal sample period, s (from `sample_hz` or estimated from the first rows).
    period_s: f64,
    /// Subtracted from every time so that none is negative (0 unless the first time is < 0).
    t_origin_s: Option<f64>,
    last_t_s: Option<f64>,
    gaps: GapTracker,
    pending_accel: Option<AccelSample>,
    stats: IngestStats,
    /// Bursty stamps: times come from the steady rate instead (see [`BurstClock`]). Boxed: the
    /// reader is one variant of `CaptureReader`, whose variants should stay alike in size.
    bursts: Option<Box<BurstClock>>,
}

/// The time base of a file whose stamps come in bursts (a host that reads the serial buffer
/// every few tens of ms and stamps every row it got with the time of the read, no sample lost):
/// a row's time is `t0 + index / rate_hz`, the rate measured over the bursts (or `sample_hz`).
#[derive(Debug, Clone, PartialEq)]
struct BurstClock {
    rate_hz: f64,
    t0_s: f64,
    /// Median of (stamp − reconstructed time) over the probe: how long a row waits for its read.
    lag_s: f64,
    /// Stamps ahead of the reconstructed time by more than this mean lost samples: the clock
    /// is re-anchored on the stamps.
    gap_s: f64,
    /// Whether lost samples re-anchor the clock on the stamps: not with a rate the campaign
    /// gives (`sample_hz`), which the stamps may contradict (its drift against them would look
    /// like gaps).
    reanchor: bool,
    last_stamp_s: Option<f64>,
}

/// What the probe found about bursty stamps.
#[derive(Debug, Clone, PartialEq)]
struct BurstStats {
    /// Rate = rows / elapsed time over the complete bursts (lost reads left out), Hz.
    rate_hz: f64,
    /// Median over bursts of (rows in the burst / time since the previous stamp), Hz.
    median_rate_hz: f64,
    bursts: usize,
    rows_per_stamp: f64,
    /// Median time between stamps, s.
    interval_s: f64,
}

/// Bursts of equal stamps among `rows` (file order): the measured rate, or why there is none.
/// Rows of burst k were sampled after stamp k−1 and up to stamp k, so the rate counts the rows
/// of bursts 2..K over the time from stamp 1 to stamp K (the first burst may be partial and the
/// last one cut by the probe), leaving out bursts after a read period longer than 1.5 times the
/// median (lost reads).
fn burst_stats(rows: &[Row]) -> Result<BurstStats, String> {
    // (stamp, index of the burst's first row)
    let mut starts: Vec<(f64, u64)> = Vec::new();
    for r in rows {
        match starts.last() {
            Some(&(s, _)) if r.t_s == s => {}
            Some(&(s, _)) if r.t_s < s => {}
            _ => starts.push((r.t_s, r.index)),
        }
    }
    // Complete bursts with the interval that ends at their stamp: 2..K (the K+1-th start
    // closes burst K).
    if starts.len() < MIN_BURSTS + 2 {
        return Err(format!(
            "only {} distinct stamps among the first {} rows: too few bursts to measure the rate",
            starts.len(),
            rows.len()
        ));
    }
    let k = starts.len() - 1; // starts[k] closes burst k−1 (0-based bursts 1..k−1 complete)
                              // (rows, time since the previous stamp) of each complete burst
    let bursts: Vec<(f64, f64)> = (1..k)
        .map(|j| {
            (
                (starts[j + 1].1 - starts[j].1) as f64,
                starts[j].0 - starts[j - 1].0,
            )
        })
        .collect();
    let mut iv: Vec<f64> = bursts.iter().map(|b| b.1).collect();
    iv.sort_by(f64::total_cmp);
    let interval_s = iv[iv.len() / 2];
    // Reads whose rows were lost leave a long interval before the next stamp with an ordinary
    // burst: rows / time over them would make the rate too low, so they are left out.
    let kept: Vec<&(f64, f64)> = bursts.iter().filter(|b| b.1 <= 1.5 * interval_s).collect();
    let rows_counted: f64 = kept.iter().map(|b| b.0).sum();
    let elapsed: f64 = kept.iter().map(|b| b.1).sum();
    if !(elapsed > 0.0 && rows_counted > 0.0) {
        return Err("the stamps do not advance".into());
    }
    let mut per: Vec<f64> = bursts
        .iter()
        .filter(|b| b.1 > 0.0)
        .map(|b| b.0 / b.1)
        .collect();
    per.sort_by(f64::total_cmp);
    Ok(BurstStats {
        rate_hz: rows_counted / elapsed,
        median_rate_hz: per[per.len() / 2],
        bursts: kept.len(),
        rows_per_stamp: rows_counted / kept.len() as f64,
        interval_s,
    })
}

impl BurstClock {
    /// The clock for the probed rows at `rate_hz`: t0 puts every probed row at or before its
    /// stamp (a row is read after it was sampled), the lag is the probe's median wait.
    fn new(rows: &[Row], rate_hz: f64, interval_s: f64, reanchor: bool) -> Self {
        let t0_s = rows
            .iter()
            .map(|r| r.t_s - r.index as f64 / rate_hz)
            .fold(f64::INFINITY, f64::min);
        let mut lags: Vec<f64> = rows
            .iter()
            .map(|r| r.t_s - (t0_s + r.index as f64 / rate_hz))
            .collect();
        lags.sort_by(f64::total_cmp);
        Self {
            rate_hz,
            t0_s,
            lag_s: lags.get(lags.len() / 2).copied().unwrap_or(0.0),
            gap_s: 4.0 * interval_s + 10.0 / rate_hz,
            reanchor,
            last_stamp_s: None,
        }
    }

    /// The time of a row, or why its stamp cannot be believed. `confirmed`: the next line's stamp
    /// is not earlier than this one's (a garbled stamp far ahead must not move the clock).
    fn place(&mut self, r: &Row, confirmed: bool) -> Result<f64, String> {
        if let Some(prev) = self.last_stamp_s {
            if r.t_s < prev {
                return Err(format!(
                    "time stamp goes backwards: {} s after {} s",
                    round_sig(r.t_s),
                    round_sig(prev)
                ));
            }
        }
        let mut t = self.t0_s + r.index as f64 / self.rate_hz;
        let lead = r.t_s - t;
        if self.reanchor && lead - self.lag_s > self.gap_s {
            if !confirmed {
                return Err(format!(
                    "time stamp jumps ahead ({} s, the rows' clock says {} s) and the next \
                     line does not follow",
                    round_sig(r.t_s),
                    round_sig(t)
                ));
            }
            // Samples were lost: the stamps, not the row count, say when this row was.
            self.t0_s += lead - self.lag_s;
            t = self.t0_s + r.index as f64 / self.rate_hz;
        }
        self.last_stamp_s = Some(r.t_s);
        Ok(t)
    }
}

impl TimeseriesReader<io::BufReader<std::fs::File>> {
    /// Opens `path` as described by `spec`.
    pub fn open(
        path: impl AsRef<Path>,
        spec: TimeseriesSpec,
        opts: ReadOptions,
    ) -> Result<Self, RigError> {
        let path = path.as_ref();
        let file = std::fs::File::open(path).map_err(|e| RigError::io(path, e))?;
        Self::new(
            io::BufReader::with_capacity(64 * 1024, file),
            path,
            spec,
            opts,
        )
    }
}

impl<R: BufRead> TimeseriesReader<R> {
    /// Reads the `#` header and the column line and finds the columns. `path` names the file in
    /// messages. A missing column is an error naming the file, the column and the columns
    /// present.
    pub fn new(
        reader: R,
        path: impl AsRef<Path>,
        spec: TimeseriesSpec,
        opts: ReadOptions,
    ) -> Result<Self, RigError> {
        let rad_per_unit = spec.rad_per_unit();
        let mut me = Self {
            reader,
            path: path.as_ref().to_path_buf(),
            delim: spec.delimiter.unwrap_or(Delimiter::Byte(b',')),
            spec,
            opts,
            header: Header::new(),
            columns: Vec::new(),
            column_line_info: None,
            first_data: None,
            ncols: 0,
            idx_time: None,
            idx_angle: 0,
            idx_accel: [None; 3],
            rad_per_unit,
            line_no: 0,
            byte_pos: 0,
            data_lines: 0,
            line: Vec::with_capacity(128),
            lookahead: VecDeque::new(),
            drained: false,
            period_s: 0.0,
            t_origin_s: None,
            last_t_s: None,
            gaps: GapTracker::new("timeseries", 1.0, 1.0),
            pending_accel: None,
            stats: IngestStats::default(),
            bursts: None,
        };
        let column_line = me.read_header()?;
        me.find_columns(column_line)?;
        me.fill_header();
        if me.idx_time.is_some() {
            me.fill_lookahead(RATE_PROBE_ROWS)?;
            me.detect_bursts(column_line)?;
        }
        // The nominal period: the burst clock's rate, the sample rate if given, else the median
        // step of the first rows.
        me.period_s = match (&me.bursts, me.spec.sample_hz) {
            (Some(b), _) => 1.0 / b.rate_hz,
            (None, Some(hz)) => 1.0 / hz,
            (None, None) => {
                let mut steps: Vec<f64> = me
                    .lookahead
                    .iter()
                    .zip(me.lookahead.iter().skip(1))
                    .map(|(a, b)| b.t_s - a.t_s)
                    .filter(|d| *d > 0.0)
                    .collect();
                steps.sort_by(f64::total_cmp);
                steps.get(steps.len() / 2).copied().unwrap_or(0.0)
            }
        };
        if me.period_s > 0.0 {
            me.gaps = GapTracker::new("timeseries", 1.0 / me.period_s, opts.gap_factor);
            me.header
                .set("sample_hz", format!("{}", round_sig(1.0 / me.period_s)));
        } else {
            me.gaps = GapTracker::new("timeseries", 1.0, f64::INFINITY);
        }
        Ok(me)
    }

    pub fn header(&self) -> &Header {
        &self.header
    }

    /// Reads ahead until `rows` parsed rows wait in the lookahead (or the file ends).
    fn fill_lookahead(&mut self, rows: usize) -> Result<(), RigError> {
        while self.lookahead.len() < rows && !self.drained {
            match self.next_row()? {
                Some(r) => self.lookahead.push_back(r),
                None => self.drained = true,
            }
        }
        Ok(())
    }

    /// Repeated stamps: when many rows share their stamp with the previous row, the stamps are
    /// the times a host read a buffer, not the samples' times. The time is then reconstructed
    /// from the steady rate (measured over the bursts, or `sample_hz` when given) and the header
    /// says so (`time_base`); without enough bursts to measure a rate and no `sample_hz`, the
    /// file is refused with a message naming the problem, rather than read as a handful of rows.
    fn detect_bursts(&mut self, column_line: u64) -> Result<(), RigError> {
        let steps = self.lookahead.len().saturating_sub(1);
        let repeats = self
            .lookahead
            .iter()
            .zip(self.lookahead.iter().skip(1))
            .filter(|(a, b)| b.t_s == a.t_s)
            .count();
        if steps < 2 || (repeats as f64) < BURSTY_REPEAT_FRACTION * steps as f64 {
            return Ok(());
        }
        self.fill_lookahead(BURST_PROBE_ROWS)?;
        let rows: Vec<Row> = self.lookahead.iter().copied().collect();
        let repeats = rows.windows(2).filter(|w| w[1].t_s == w[0].t_s).count();
        let col = self
            .spec
            .time_column
            .as_ref()
            .map(ToString::to_string)
            .unwrap_or_default();
        let measured = burst_stats(&rows);
        let (rate_hz, interval_s) = match (&measured, self.spec.sample_hz) {
            (_, Some(hz)) => (hz, measured.as_ref().map_or(0.0, |b| b.interval_s)),
            (Ok(b), None) => {
                // Lost samples inside the probe make rows/time too low; the median over bursts
                // does not see them.
                let rate = if (b.rate_hz / b.median_rate_hz - 1.0).abs() <= 0.05 {
                    b.rate_hz
                } else {
                    b.median_rate_hz
                };
                (rate, b.interval_s)
            }
            (Err(why), None) => {
                return Err(self.not_a_capture(
                    column_line,
                    format!(
                        "time column `{col}`: {repeats} of {} rows repeat the previous row's \
                         stamp (stamps in bursts: a host reading a buffer?) and {why}; give \
                         `sample_hz` (the rate the samples were taken at) to read the file",
                        rows.len()
                    ),
                ))
            }
        };
        let mut note = match &measured {
            Ok(b) => format!(
                "reconstructed from the sample rate: the `{col}` stamps come in bursts ({:.1} \
                 rows per stamp, one stamp every {:.1} ms; {repeats} of the first {} rows repeat \
                 the previous stamp), so t = row index / {} Hz; measured over {} bursts: {} Hz \
                 (rows / elapsed time), median over bursts {} Hz",
                b.rows_per_stamp,
                1e3 * b.interval_s,
                rows.len(),
                round_sig(rate_hz),
                b.bursts,
                round_sig(b.rate_hz),
                round_sig(b.median_rate_hz)
            ),
            Err(why) => format!(
                "reconstructed from the sample rate: the `{col}` stamps repeat ({repeats} of the \
                 first {} rows) and {why}, so t = row index / {} Hz",
                rows.len(),
                round_sig(rate_hz)
            ),
        };
        if let Some(hz) = self.spec.sample_hz {
            note.push_str(&format!("; the rate is the campaign's sample_hz = {hz}"));
            if let Ok(b) = &measured {
                let off = b.rate_hz / hz - 1.0;
                if off.abs() > 0.01 {
                    note.push_str(&format!(
                        ", {:+.1} % off the stamps' rate (check sample_hz)",
                        -100.0 * off / (1.0 + off)
                    ));
                }
            }
        }
        self.header.set("time_base", note);
        if let Ok(b) = &measured {
            self.header
                .set("sample_hz_measured", format!("{}", round_sig(b.rate_hz)));
        }
        // The anchor: the rows before the first lost read (a stamp interval over 1.5 times the
        // usual), at most 2,000: later rows would pull the typical wait up by the gap.
        let given = self.spec.sample_hz.is_some();
        let first_gap = rows
            .windows(2)
            .position(|w| interval_s > 0.0 && w[1].t_s - w[0].t_s > 1.5 * interval_s)
            .map_or(rows.len(), |i| i + 1);
        let anchor = &rows[..first_gap.clamp(1, 2000)];
        self.bursts = Some(Box::new(BurstClock::new(
            anchor, rate_hz, interval_s, !given,
        )));
        Ok(())
    }

    pub fn stats(&self) -> &IngestStats {
        &self.stats
    }

    /// The column names of the file, in order.
    pub fn columns(&self) -> &[String] {
        &self.columns
    }

    pub fn spec(&self) -> &TimeseriesSpec {
        &self.spec
    }

    fn not_a_capture(&self, line: u64, reason: String) -> RigError {
        RigError::NotACapture {
            path: self.path.clone(),
            at: Location::Line(line),
            reason,
        }
    }

    /// Reads `#` lines into the header; returns the line number of the column line (left in
    /// `self.line`).
    fn read_header(&mut self) -> Result<u64, RigError> {
        loop {
            if self.byte_pos > crate::serial::MAX_HEADER_BYTES {
                return Err(self.not_a_capture(
                    self.line_no,
                    format!(
                        "the `#` header runs past {} bytes (line {}, byte {}) without a \
                         column-name line",
                        crate::serial::MAX_HEADER_BYTES,
                        self.line_no,
                        self.byte_pos
                    ),
                ));
            }
            let Some(info) = self.read_line()? else {
                // No line at all: the file is empty, which is the message a user needs.
                let reason = if self.line_no == 0 {
                    "file is empty (0 bytes)"
                } else {
                    "the file ends before its column-name line"
                };
                return Err(self.not_a_capture(self.line_no.max(1), reason.into()));
            };
            if info.overlong {
                return Err(self.not_a_capture(
                    info.number,
                    format!(
                        "header line {} (from byte {}) is {} bytes, longer than {MAX_LINE_BYTES}",
                        info.number, info.start, info.bytes
                    ),
                ));
            }
            let mut content: &[u8] = &self.line;
            if info.number == 1 {
                content = content.strip_prefix(b"\xEF\xBB\xBF").unwrap_or(content);
            }
            let text = String::from_utf8_lossy(content).trim().to_string();
            if text.is_empty() {
                continue;
            }
            if let Some(rest) = text.strip_prefix('#') {
                if let Some((k, v)) = rest.split_once('=') {
                    let k = k.trim();
                    if !k.is_empty() {
                        self.header
                            .entries
                            .push((k.to_string(), v.trim().to_string()));
                    }
                }
                continue;
            }
            self.line = text.into_bytes();
            self.column_line_info = Some(info);
            return Ok(info.number);
        }
    }

    fn find_columns(&mut self, line_number: u64) -> Result<(), RigError> {
        if self.spec.delimiter.is_none() {
            self.delim = detect_delimiter(&self.line);
        }
        let names: Vec<String> = self
            .delim
            .split(&self.line)
            .iter()
            .map(|f| {
                let s = String::from_utf8_lossy(f);
                s.trim()
                    .trim_matches('"')
                    .trim_matches('\'')
                    .trim()
                    .to_string()
            })
            .collect();
        let headerless = names.iter().all(|n| n.parse::<f64>().is_ok());
        if headerless && !self.spec.by_index_only() {
            return Err(self.not_a_capture(
                line_number,
                format!(
                    "expected a column-name line (the file's columns must be named, or give \
                     every column by its 0-based index: `time_column = 0`, `angle_column = 1`), \
                     found {}",
                    snippet(&self.line)
                ),
            ));
        }
        if headerless {
            // No column-name line: this line is the first sample, read again as data.
            self.columns = (0..names.len()).map(|i| format!("#{i}")).collect();
            if let Some(info) = self.column_line_info {
                self.first_data = Some((info, std::mem::take(&mut self.line)));
            }
        } else {
            self.columns = names;
        }
        self.ncols = self.columns.len();
        let find = |me: &Self, key: &str, col: &ColumnRef| -> Result<usize, RigError> {
            let present = || {
                format!(
                    "{} (delimiter `{}`)",
                    me.columns
                        .iter()
                        .map(|c| format!("`{c}`"))
                        .collect::<Vec<_>>()
                        .join(", "),
                    me.delim.name()
                )
            };
            match col {
                ColumnRef::Name(name) => {
                    me.columns.iter().position(|c| c == name).ok_or_else(|| {
                        me.not_a_capture(
                            line_number,
                            format!(
                                "column `{name}` (key `{key}`) not found; the columns present \
                                 are: {}",
                                present()
                            ),
                        )
                    })
                }
                ColumnRef::Index(i) if *i < me.ncols => Ok(*i),
                ColumnRef::Index(i) => Err(me.not_a_capture(
                    line_number,
                    format!(
                        "column index {i} (key `{key}`, 0-based) is past the {} columns of the \
                         file: {}",
                        me.ncols,
                        present()
                    ),
                )),
            }
        };
        if let Some(tc) = self.spec.time_column.clone() {
            self.idx_time = Some(find(self, "time_column", &tc)?);
        }
        let ac = self.spec.angle_column.clone();
        self.idx_angle = find(self, "angle_column", &ac)?;
        for (i, key) in ["accel_x_column", "accel_y_column", "accel_z_column"]
            .iter()
            .enumerate()
        {
            if let Some(c) = self.spec.accel_columns[i].clone() {
                self.idx_accel[i] = Some(find(self, key, &c)?);
            }
        }
        Ok(())
    }

    /// What the MCAP's capture-header record should say about this file.
    fn fill_header(&mut self) {
        let s = self.spec.clone();
        let h = &mut self.header;
        h.set("format", FORMAT);
        h.set("columns", self.columns.join(","));
        h.set("delimiter", self.delim.name());
        match &s.time_column {
            Some(c) => h.set("time_column", c.to_string()),
            None => h.set("time_column", "none (sample index / sample_hz)"),
        }
        h.set("angle_column", s.angle_column.to_string());
        h.set("angle_unit", s.angle_unit.as_str());
        h.set("hanging_angle", format!("{}", s.hanging_angle));
        // With any angle unit: the analysis takes the angle's resolution from it (issue 16).
        if let Some(cpr) = s.counts_per_rev {
            h.set("encoder_cpr", format!("{cpr}"));
            h.set("angle_resolution_rad", format!("{}", round_sig(TAU / cpr)));
        }
        if s.has_accel() {
            let names = ["x", "y", "z"];
            for (i, c) in s.accel_columns.iter().enumerate() {
                h.set(
                    format!("accel_{}_column", names[i]),
                    c.as_ref()
                        .map_or_else(|| "none (reads 0)".into(), ToString::to_string),
                );
            }
            h.set(
                "accel_unit",
                match s.accel_unit {
                    AccelUnit::MS2 => "m/s2",
                    AccelUnit::G => "g",
                },
            );
            h.set("accel_lsb_per_g", format!("{DEFAULT_ACCEL_LSB_PER_G}"));
            h.set(
                "accel_raw",
                "synthesized from the SI values at accel_lsb_per_g (saturated)",
            );
        }
    }

    /// Reads one line into `self.line`, keeping at most [`MAX_LINE_BYTES`] of it.
    fn read_line(&mut self) -> Result<Option<LineInfo>, RigError> {
        read_bounded_line(
            &mut self.reader,
            &mut self.line,
            &mut self.line_no,
            &mut self.byte_pos,
            MAX_LINE_BYTES,
        )
        .map_err(|e| RigError::io(&self.path, e))
    }

    /// The next parsable data line; damaged ones are recorded and skipped.
    fn next_row(&mut self) -> Result<Option<Row>, RigError> {
        loop {
            let info = match self.first_data.take() {
                Some((info, line)) => {
                    self.line = line;
                    info
                }
                None => match self.read_line()? {
                    Some(info) => info,
                    None => return Ok(None),
                },
            };
            if self.line.iter().all(|b| b.is_ascii_whitespace()) && !info.overlong {
                continue;
            }
            if self.line.first() == Some(&b'#') {
                continue;
            }
            let index = self.data_lines;
            self.data_lines += 1;
            if info.overlong {
                self.stats.skip(
                    Location::Line(info.number),
                    format!(
                        "line of {} bytes from byte {}, longer than {MAX_LINE_BYTES} (garbage)",
                        info.bytes, info.start
                    ),
                    info.bytes,
                );
                continue;
            }
            match self.parse_row(index) {
                Ok((t_s, angle, accel)) => {
                    return Ok(Some(Row {
                        line: info.number,
                        bytes: info.bytes,
                        index,
                        t_s,
                        angle,
                        accel,
                    }))
                }
                Err(why) => {
                    let reason = format!("{why}: {}", snippet(&self.line));
                    self.stats
                        .skip(Location::Line(info.number), reason, info.bytes);
                }
            }
        }
    }

    fn parse_row(&self, index: u64) -> Result<(f64, f64, [f64; 3]), String> {
        let fields = self.delim.split(&self.line);
        if fields.len() != self.ncols {
            let hint = if fields.len() > self.ncols {
                "lines run together?"
            } else {
                "cut short?"
            };
            return Err(format!(
                "{} fields, expected {} ({hint})",
                fields.len(),
                self.ncols
            ));
        }
        let num = |i: usize| -> Result<f64, String> {
            let s = std::str::from_utf8(fields[i]).unwrap_or("").trim();
            let s = s.trim_matches('"');
            match s.parse::<f64>() {
                Ok(v) if v.is_finite() => Ok(v),
                _ => Err(format!(
                    "column `{}` is not a finite number",
                    self.columns[i]
                )),
            }
        };
        let t_s = match self.idx_time {
            Some(i) => num(i)? * self.spec.time_scale_s,
            None => index as f64 / self.spec.sample_hz.unwrap_or(1.0),
        };
        let angle = num(self.idx_angle)?;
        let mut accel = [0.0; 3];
        for (a, idx) in accel.iter_mut().zip(self.idx_accel) {
            if let Some(i) = idx {
                *a = num(i)?;
            }
        }
        Ok((t_s, angle, accel))
    }

    /// The next sample: each good line's encoder sample, then (with accelerometer columns) its
    /// accelerometer sample. Errors only on I/O failure; damaged lines are skipped and counted
    /// in [`Self::stats`].
    pub fn next_sample(&mut self) -> Result<Option<Sample>, RigError> {
        if let Some(a) = self.pending_accel.take() {
            return Ok(Some(Sample::Accel(a)));
        }
        loop {
            while self.lookahead.len() <= CONFIRM_RECORDS && !self.drained {
                match self.next_row()? {
                    Some(r) => self.lookahead.push_back(r),
                    None => self.drained = true,
                }
            }
            let Some(cand) = self.lookahead.pop_front() else {
                return Ok(None);
            };
            let placed = match self.bursts.as_mut() {
                Some(b) => {
                    let confirmed = self.lookahead.front().is_none_or(|r| r.t_s >= cand.t_s);
                    b.place(&cand, confirmed)
                }
                None => self.check_time(&cand).map(|()| cand.t_s),
            };
            let t_s = match placed {
                Ok(t) => t,
                Err(why) => {
                    self.stats.skip(Location::Line(cand.line), why, cand.bytes);
                    continue;
                }
            };
            self.last_t_s = Some(t_s);
            let origin = *self.t_origin_s.get_or_insert(t_s.min(0.0));
            let t_us = ((t_s - origin) * 1e6).round().max(0.0) as u64;
            self.gaps.step(t_us, &mut self.stats);
            let t_us_raw = (t_us & u64::from(u32::MAX)) as u32;
            let rel = cand.angle - self.spec.hanging_angle;
            let theta_rad = rel * self.rad_per_unit;
            let count: i64 = match (self.spec.angle_unit, self.spec.counts_per_rev) {
                (AngleUnit::Counts, _) => rel.round() as i64,
                (_, Some(cpr)) => {
                    // floor(θ·cpr/2π) as the rig's firmware counts; a value printed on the grid
                    // (k·360/cpr degrees) must give k, not k − 1 from the last bit.
                    let x = theta_rad * cpr / TAU;
                    if (x - x.round()).abs() < 1e-6 {
                        x.round() as i64
                    } else {
                        x.floor() as i64
                    }
                }
                (_, None) => 0,
            };
            self.stats.encoder_samples += 1;
            if self.spec.has_accel() {
                let g = self.opts.g_m_s2;
                let si = match self.spec.accel_unit {
                    AccelUnit::MS2 => cand.accel,
                    AccelUnit::G => cand.accel.map(|a| a * g),
                };
                let raw = si.map(|a| {
                    (a / g * DEFAULT_ACCEL_LSB_PER_G)
                        .round()
                        .clamp(f64::from(i16::MIN), f64::from(i16::MAX)) as i16
                });
                self.stats.accel_samples += 1;
                self.pending_accel = Some(AccelSample {
                    t_us_raw,
                    t_us,
                    raw,
                    si_m_s2: si,
                });
            }
            return Ok(Some(Sample::Encoder(EncoderSample {
                t_us_raw,
                t_us,
                count_raw: count as i16,
                count,
                theta_rad,
            })));
        }
    }

    /// Order check with a few lines of lookahead: a time that does not increase is reported;
    /// a time that jumps ahead by more than `gap_factor` periods is believed only when the next
    /// lines continue from it (a garbled time would otherwise make every later line look out
    /// of order).
    fn check_time(&self, cand: &Row) -> Result<(), String> {
        let Some(prev) = self.last_t_s else {
            return Ok(());
        };
        if cand.t_s <= prev {
            return Err(format!(
                "time does not increase: {} s after {} s",
                round_sig(cand.t_s),
                round_sig(prev)
            ));
        }
        let max_lone = self.opts.gap_factor.max(1.0) * self.period_s;
        if self.period_s > 0.0 && cand.t_s - prev > max_lone {
            let mut last = cand.t_s;
            let mut confirmed = !self.lookahead.is_empty();
            for r in self.lookahead.iter().take(CONFIRM_RECORDS) {
                if !(r.t_s > last && r.t_s - last <= max_lone) {
                    confirmed = false;
                    break;
                }
                last = r.t_s;
            }
            if !confirmed {
                return Err(format!(
                    "time jumps ahead ({} s after {} s) and the next lines do not follow",
                    round_sig(cand.t_s),
                    round_sig(prev)
                ));
            }
        }
        Ok(())
    }
}

/// The separator of a column line: the most frequent of tab, `;` and `,`; runs of blanks when
/// none appears (a single column has no separator at all).
fn detect_delimiter(line: &[u8]) -> Delimiter {
    let count = |d: u8| line.iter().filter(|&&b| b == d).count();
    let best = [b'\t', b';', b',']
        .into_iter()
        .map(|d| (count(d), d))
        .max_by_key(|(n, _)| *n);
    match best {
        Some((n, d)) if n > 0 => Delimiter::Byte(d),
        _ => Delimiter::Whitespace,
    }
}

/// 10 significant digits, for messages and header values.
fn round_sig(x: f64) -> f64 {
    if x == 0.0 || !x.is_finite() {
        return x;
    }
    let mag = 10f64.powi(9 - x.abs().log10().floor() as i32);
    (x * mag).round() / mag
}

#[cfg(test)]
mod tests {
    use super::*;

    fn keys(text: &str) -> BTreeMap<String, Value> {
        let t: toml::Table = toml::from_str(text).unwrap();
        t.into_iter().collect()
    }

    fn spec(text: &str) -> TimeseriesSpec {
        TimeseriesSpec::from_keys(&keys(text), Path::new("c/campaign.toml"), "r1").unwrap()
    }

    fn read_all(text: &str, s: TimeseriesSpec) -> (Vec<Sample>, IngestStats, Header) {
        let mut r =
            TimeseriesReader::new(text.as_bytes(), "x.csv", s, ReadOptions::default()).unwrap();
        let mut v = Vec::new();
        while let Some(x) = r.next_sample().unwrap() {
            v.push(x);
        }
        (v, r.stats().clone(), r.header().clone())
    }

    fn enc(s: &[Sample]) -> Vec<EncoderSample> {
        s.iter()
            .filter_map(|x| match x {
                Sample::Encoder(e) => Some(*e),
                _ => None,
            })
            .collect()
    }

    #[test]
    fn keys_are_checked() {
        let s = spec("time_column = \"t_s\"\nangle_column = \"theta\"\nangle_unit = \"rad\"\nhanging_angle = 3.25");
        assert_eq!(s.time_column, Some(ColumnRef::Name("t_s".into())));
        assert_eq!(s.angle_unit, AngleUnit::Rad);
        assert_eq!(s.hanging_angle, 3.25);
        let bad = |text: &str, key: &str| {
            let e = TimeseriesSpec::from_keys(&keys(text), Path::new("c/campaign.toml"), "r1")
                .unwrap_err()
                .to_string();
            assert!(
                e.contains("c/campaign.toml") && e.contains("r1") && e.contains(key),
                "{e}"
            );
        };
        bad("angle_column = \"a\"\nangle_unit = \"rad\"", "time_column");
        bad("time_column = \"t\"\nangle_unit = \"rad\"", "angle_column");
        bad("time_column = \"t\"\nangle_column = \"a\"", "angle_unit");
        bad(
            "time_column = \"t\"\nangle_column = \"a\"\nangle_unit = \"grad\"",
            "angle_unit",
        );
        bad(
            "time_column = \"t\"\nangle_column = \"a\"\nangle_unit = \"counts\"",
            "counts_per_rev",
        );
        bad(
            "sample_hz = -3\nangle_column = \"a\"\nangle_unit = \"rad\"",
            "sample_hz",
        );
        bad(
            "time_column = \"t\"\nangle_column = \"a\"\nangle_unit = \"rad\"\naccel_unit = \"furlong\"",
            "accel_unit",
        );
    }

    #[test]
    fn reads_csv_with_time_column_and_hanging_offset() {
        let s = spec("time_column = \"t_s\"\nangle_column = \"theta_rad\"\nangle_unit = \"rad\"\nhanging_angle = 3.0");
        let text = "t_s,theta_rad\n0.000,3.5\n0.001,3.25\n0.002,3.0\n";
        let (v, st, h) = read_all(text, s);
        let e = enc(&v);
        assert_eq!(e.len(), 3);
        assert_eq!(e[1].t_us, 1000);
        assert!((e[0].theta_rad - 0.5).abs() < 1e-12);
        assert!((e[2].theta_rad).abs() < 1e-12);
        assert_eq!(e[0].count, 0);
        assert_eq!(st.encoder_samples, 3);
        assert_eq!(st.accel_samples, 0);
        assert_eq!(h.get("format"), Some("timeseries"));
        assert_eq!(h.get("sample_hz"), Some("1000"));
    }

    #[test]
    fn tsv_degrees_sample_rate_and_accel_in_g() {
        let s = spec(
            "sample_hz = 100\nangle_column = \"angle\"\nangle_unit = \"deg\"\n\
             accel_z_column = \"az\"\naccel_unit = \"g\"",
        );
        let text = "# rig=other\nangle\taz\n90\t1.0\n-90\t0.5\n";
        let (v, st, h) = read_all(text, s);
        assert_eq!(h.get("rig"), Some("other"));
        assert_eq!(st.accel_samples, 2);
        let e = enc(&v);
        assert!((e[0].theta_rad - std::f64::consts::FRAC_PI_2).abs() < 1e-12);
        assert_eq!(e[1].t_us, 10_000);
        match v[1] {
            Sample::Accel(a) => {
                assert!((a.si_m_s2[2] - 9.81).abs() < 1e-12);
                assert_eq!(a.si_m_s2[0], 0.0);
                assert_eq!(a.raw[2], 8192);
            }
            _ => panic!("expected accel after encoder"),
        }
    }

    #[test]
    fn counts_with_counts_per_rev() {
        let s = spec(
            "time_column = \"ms\"\ntime_unit = \"ms\"\nangle_column = \"enc\"\n\
             angle_unit = \"counts\"\ncounts_per_rev = 4000\nhanging_angle = 2000",
        );
        let text = "ms;enc\n0;2000\n5;3000\n";
        let (v, _, _) = read_all(text, s);
        let e = enc(&v);
        assert_eq!(e[1].t_us, 5000);
        assert_eq!(e[1].count, 1000);
        assert!((e[1].theta_rad - std::f64::consts::FRAC_PI_2).abs() < 1e-12);
    }

    #[test]
    fn bad_lines_and_time_order_are_reported() {
        let s = spec("time_column = \"t\"\nangle_column = \"a\"\nangle_unit = \"rad\"");
        let mut text = String::from("t,a\n");
        for i in 0..40 {
            text.push_str(&format!("{},{}\n", i as f64 * 0.01, i));
        }
        text.push_str("0.39,7\n"); // line 42: time goes backwards
        text.push_str("0.40,x\n"); // 43: not a number
        text.push_str("0.41,1,2\n"); // 44: too many fields
        text.push_str("55.0,1\n"); // 45: a garbled jump ahead
        text.push_str("0.42,1\n0.43,1\n0.44,1\n0.45,1"); // no final newline: still read
        let (v, st, _) = read_all(&text, s);
        assert_eq!(enc(&v).len(), 44);
        assert_eq!(st.skipped_lines_or_frames, 4);
        let lines: Vec<Location> = st.skips.iter().map(|k| k.at).collect();
        assert_eq!(
            lines,
            vec![
                Location::Line(42),
                Location::Line(43),
                Location::Line(44),
                Location::Line(45)
            ]
        );
        assert!(
            st.skips[0].reason.contains("does not increase"),
            "{:?}",
            st.skips
        );
        assert!(st.skips[1].reason.contains("`a`"), "{:?}", st.skips);
        assert!(st.skips[3].reason.contains("jumps ahead"), "{:?}", st.skips);
    }

    #[test]
    fn gaps_are_counted() {
        let s = spec("time_column = \"t\"\nangle_column = \"a\"\nangle_unit = \"rad\"");
        let mut text = String::from("t,a\n");
        for i in (0..100).filter(|i| !(50..60).contains(i)) {
            text.push_str(&format!("{},{}\n", i as f64 * 0.01, 0.1));
        }
        let (_, st, _) = read_all(&text, s);
        assert_eq!(st.gap_count, 1);
        assert_eq!(st.gaps[0].missing_samples_est, 10);
    }

    #[test]
    fn missing_column_names_file_column_and_columns_present() {
        let s = spec("time_column = \"t_s\"\nangle_column = \"theta\"\nangle_unit = \"rad\"");
        let e = TimeseriesReader::new(
            &b"t_s,theta_rad\n0,1\n"[..],
            "data/run.csv",
            s,
            ReadOptions::default(),
        )
        .err()
        .unwrap()
        .to_string();
        assert!(
            e.contains("data/run.csv") && e.contains("`theta`") && e.contains("`t_s`, `theta_rad`"),
            "{e}"
        );
    }

    #[test]
    fn whitespace_and_no_header_line() {
        let s = spec("sample_hz = 10\nangle_column = \"a\"\nangle_unit = \"rad\"");
        let (v, _, _) = read_all("  a  \n 0.1 \n 0.2\n", s.clone());
        assert_eq!(enc(&v).len(), 2);
        let e = TimeseriesReader::new(&b"0.1,0.2\n"[..], "n.csv", s, ReadOptions::default())
            .err()
            .unwrap()
            .to_string();
        assert!(e.contains("n.csv") && e.contains("column-name"), "{e}");
    }

    /// A host that reads the serial buffer every ~62 ms and stamps every row it got with the
    /// time of the read: `rows` samples at `rate_hz`, stamps in ms; the reads numbered in `lost`
    /// lose their rows. Returns the text and each written row's true time, s.
    fn bursty_csv(
        rate_hz: f64,
        rows: usize,
        jitter_ms: f64,
        lost: std::ops::Range<usize>,
    ) -> (String, Vec<f64>) {
        let mut text = String::from("# host=laptop\nt_ms,angle_deg\n");
        let mut truth = Vec::new();
        let mut read_at = 62.0;
        let mut k = 0usize;
        let mut i = 0usize;
        while i < rows {
            // every sample taken by the read time goes out with that stamp
            while i < rows && (i as f64) * 1e3 / rate_hz <= read_at {
                let t = i as f64 / rate_hz;
                let deg = 20.0 * (-0.05 * t).exp() * (9.0 * t).cos();
                if !lost.contains(&k) {
                    text.push_str(&format!(
                        "{read_at:.0},{:.3}\n",
                        (deg / 0.088).round() * 0.088
                    ));
                    truth.push(t);
                }
                i += 1;
            }
            k += 1;
            // a reproducible ±jitter around the 62 ms period
            let u = ((k * 7919) % 101) as f64 / 100.0 - 0.5;
            read_at += 62.0 + 2.0 * jitter_ms * u;
        }
        (text, truth)
    }

    /// Issue 16 item 3: bursty stamps (15–16 rows share one, no sample lost) keep every row,
    /// times rebuilt from the rate measured over the bursts (within 1 %), and the header says so.
    #[test]
    fn regression_issue_16_bursty_stamps_keep_every_row() {
        let rate = 259.3;
        let (text, _) = bursty_csv(rate, 7625, 4.0, 0..0);
        let s = spec("time_column = \"t_ms\"\ntime_unit = \"ms\"\nangle_column = \"angle_deg\"\nangle_unit = \"deg\"");
        let (v, st, h) = read_all(&text, s);
        let e = enc(&v);
        assert_eq!(e.len(), 7625, "{:?}", st.skips);
        assert_eq!(st.skipped_lines_or_frames, 0, "{:?}", st.skips);
        assert_eq!(st.gap_count, 0, "{:?}", st.gaps);
        let measured: f64 = h.get("sample_hz_measured").unwrap().parse().unwrap();
        assert!(
            (measured / rate - 1.0).abs() < 0.01,
            "measured {measured} Hz"
        );
        let span_s = (e[e.len() - 1].t_us - e[0].t_us) as f64 * 1e-6;
        let recovered = (e.len() - 1) as f64 / span_s;
        assert!(
            (recovered / rate - 1.0).abs() < 0.01,
            "rows say {recovered} Hz"
        );
        assert!(e.windows(2).all(|w| w[1].t_us > w[0].t_us));
        let tb = h.get("time_base").unwrap();
        assert!(tb.contains("bursts") && tb.contains("Hz"), "{tb}");
        eprintln!("time_base = {tb}");

        // `sample_hz` overrides the measured rate.
        let s = spec("time_column = \"t_ms\"\ntime_unit = \"ms\"\nangle_column = \"angle_deg\"\nangle_unit = \"deg\"\nsample_hz = 250");
        let (v, _, h) = read_all(&text, s);
        let e = enc(&v);
        assert_eq!(e.len(), 7625);
        assert_eq!(e[250].t_us - e[0].t_us, 1_000_000);
        assert!(h.get("time_base").unwrap().contains("sample_hz = 250"));

        // Reads 300–304 lost (after the probe would be the same): a gap, the clock re-anchored
        // on the stamps, every later row within one read period of its true time.
        let (lossy, truth) = bursty_csv(rate, 30_000, 4.0, 300..305);
        let s = spec("time_column = \"t_ms\"\ntime_unit = \"ms\"\nangle_column = \"angle_deg\"\nangle_unit = \"deg\"");
        let (v, st, h) = read_all(&lossy, s);
        eprintln!("lossy: {:?}", h.get("time_base"));
        let e = enc(&v);
        assert_eq!(e.len(), truth.len(), "{:?}", st.skips);
        assert_eq!(st.gap_count, 1, "{:?}", st.gaps);
        let worst = e
            .iter()
            .zip(&truth)
            .map(|(x, t)| ((x.t_us - e[0].t_us) as f64 * 1e-6 - (t - truth[0])).abs())
            .fold(0.0, f64::max);
        assert!(worst < 0.062, "a row {worst} s off its time");

        // Too few bursts to measure a rate and no sample_hz: refused, naming the problem.
        let short: String = text.lines().take(40).map(|l| format!("{l}\n")).collect();
        let s = spec("time_column = \"t_ms\"\ntime_unit = \"ms\"\nangle_column = \"angle_deg\"\nangle_unit = \"deg\"");
        let err = TimeseriesReader::new(short.as_bytes(), "b.csv", s, ReadOptions::default())
            .err()
            .unwrap()
            .to_string();
        assert!(
            err.contains("b.csv") && err.contains("stamp") && err.contains("sample_hz"),
            "{err}"
        );
    }

    /// Issue 16 item 4: `counts_per_rev` with degrees is honoured (the count and the header's
    /// resolution), a value on the grid giving its own count.
    #[test]
    fn regression_issue_16_counts_per_rev_with_degrees() {
        let s = spec(
            "sample_hz = 100\nangle_column = \"a\"\nangle_unit = \"deg\"\ncounts_per_rev = 4096",
        );
        let step = 360.0 / 4096.0;
        let text = format!("a\n0\n{}\n{}\n", 3.0 * step, -5.0 * step);
        let (v, _, h) = read_all(&text, s);
        let e = enc(&v);
        assert_eq!(e.iter().map(|x| x.count).collect::<Vec<_>>(), [0, 3, -5]);
        assert_eq!(h.get("encoder_cpr"), Some("4096"));
        let q: f64 = h.get("angle_resolution_rad").unwrap().parse().unwrap();
        assert!((q - TAU / 4096.0).abs() < 1e-12);
    }

    const CAMPAIGN: &str = r#"
name = "multiarm"
[rig]
r_b_m = 0.01

[[run]]
id = "small"
file = "small.csv"
role = "identify"
format = "timeseries"
time_column = "t_s"
angle_column = "theta_rad"
angle_unit = "rad"
hanging_angle = 3.14159265358979
note = "kept"
"#;

    #[test]
    fn campaign_accepts_timeseries_runs_without_rig_keys() {
        use crate::campaign::Campaign;
        let c = Campaign::parse(CAMPAIGN, "/d/campaign.toml").unwrap();
        let r = &c.runs[0];
        assert_eq!(r.format.as_deref(), Some(FORMAT));
        assert!(r.m_kg.is_nan() && r.l_m.is_nan() && r.crank_r_m.is_nan());
        assert_eq!(r.r_b_m, 0.01);
        assert_eq!(r.omega_hz, None);
        assert_eq!(r.extra["angle_column"].as_str(), Some("theta_rad"));
        assert_eq!(r.extra["note"].as_str(), Some("kept"));
        let s = TimeseriesSpec::from_run(r).unwrap();
        assert_eq!(s.angle_column, ColumnRef::Name("theta_rad".into()));
        // Round trip: the unknown rig keys stay unknown.
        let text = c.to_toml_string().unwrap();
        let back = Campaign::parse(&text, "/d/campaign.toml").unwrap();
        assert!(back.runs[0].m_kg.is_nan(), "{text}");
        assert_eq!(back.runs[0].extra, r.extra);
        // A bad key names campaign.toml, the run and the key.
        let bad = CAMPAIGN.replace("angle_unit = \"rad\"", "angle_unit = \"radians\"");
        let e = Campaign::parse(&bad, "/d/campaign.toml")
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("/d/campaign.toml") && e.contains("small") && e.contains("angle_unit"),
            "{e}"
        );
        // Rig keys stay required for the rig's own formats.
        let rig = CAMPAIGN.replace("format = \"timeseries\"", "format = \"serial-v1\"");
        let e = Campaign::parse(&rig, "/d/campaign.toml")
            .unwrap_err()
            .to_string();
        assert!(e.contains("m_kg"), "{e}");
    }

    #[test]
    fn capture_reader_opens_a_timeseries_run() {
        use crate::campaign::Campaign;
        use crate::detect::CaptureReader;
        let dir = tempfile::tempdir().unwrap();
        std::fs::write(
            dir.path().join("small.csv"),
            "t_s,theta_rad\n0.0,3.2\n0.001,3.3\n",
        )
        .unwrap();
        std::fs::write(dir.path().join("campaign.toml"), CAMPAIGN).unwrap();
        let c = Campaign::load(dir.path()).unwrap();
        let mut r = CaptureReader::open_run(&c.runs[0], ReadOptions::default()).unwrap();
        assert_eq!(r.format(), FORMAT);
        let mut n = 0;
        while let Some(Sample::Encoder(e)) = r.next_sample().unwrap() {
            assert!((e.theta_rad - (3.2 + 0.1 * n as f64 - std::f64::consts::PI)).abs() < 1e-9);
            n += 1;
        }
        assert_eq!(n, 2);
        assert_eq!(r.stats().encoder_samples, 2);
    }
}
