//! Types shared by both capture formats, and the bookkeeping both readers do the same way
//! (clock and encoder unwrapping, gap detection, outlier rejection, statistics).

use std::f64::consts::TAU;
use std::fmt;
use std::path::Path;

use serde::Serialize;

use crate::error::RigError;

/// Encoder counts per revolution when the header does not say (1024 lines, quadrature ×4).
pub const DEFAULT_ENCODER_CPR: u32 = 4096;
/// Accelerometer sensitivity when the header does not say (±4 g range).
pub const DEFAULT_ACCEL_LSB_PER_G: f64 = 8192.0;
/// Serial line rate when the header does not say.
pub const DEFAULT_SAMPLE_HZ: f64 = 200.0;
/// SD encoder frame rate when the header does not say.
pub const DEFAULT_ENCODER_HZ: f64 = 1000.0;
/// SD accelerometer frame rate when the header does not say.
pub const DEFAULT_ACCEL_HZ: f64 = 200.0;
/// How many [`Skip`]s are kept in full in [`IngestStats::skips`].
pub const MAX_SKIPS_KEPT: usize = 20;
/// How many [`Gap`]s are kept in full in [`IngestStats::gaps`].
pub const MAX_GAPS_KEPT: usize = 100;

/// The `key=value` header of a capture, every key in file order (unknown keys too: they are
/// metadata the experimenter may need later).
#[derive(Debug, Clone, Default, PartialEq, Eq, Serialize)]
pub struct Header {
    pub entries: Vec<(String, String)>,
}

impl Header {
    /// An empty header (every accessor then returns its default).
    pub fn new() -> Self {
        Self::default()
    }

    /// The header the `serial-v1` firmware writes (without `started`).
    pub fn serial_v1() -> Self {
        Self::new()
            .with("firmware", "serial-v1")
            .with("encoder_cpr", "4096")
            .with("accel_lsb_per_g", "8192")
            .with("sample_hz", "200")
    }

    /// The header the `sd-v2` firmware writes (without `started`).
    pub fn sd_v2() -> Self {
        Self::new()
            .with("firmware", "sd-v2")
            .with("encoder_cpr", "4096")
            .with("accel_lsb_per_g", "8192")
            .with("encoder_hz", "1000")
            .with("accel_hz", "200")
    }

    /// Builder form of [`Header::set`].
    pub fn with(mut self, key: impl Into<String>, value: impl Into<String>) -> Self {
        self.set(key, value);
        self
    }

    /// Replaces the first entry with this key, or appends one.
    pub fn set(&mut self, key: impl Into<String>, value: impl Into<String>) {
        let key = key.into();
        let value = value.into();
        match self.entries.iter_mut().find(|(k, _)| *k == key) {
            Some(e) => e.1 = value,
            None => self.entries.push((key, value)),
        }
    }

    /// The value of the first entry with this key.
    pub fn get(&self, key: &str) -> Option<&str> {
        self.entries
            .iter()
            .find(|(k, _)| k == key)
            .map(|(_, v)| v.as_str())
    }

    pub fn firmware(&self) -> Option<&str> {
        self.get("firmware")
    }

    /// When logging started, as written by the firmware (ISO 8601), if known.
    pub fn started(&self) -> Option<&str> {
        self.get("started")
    }

    /// Encoder counts per revolution (default 4096).
    pub fn encoder_cpr(&self) -> u32 {
        self.positive::<u32>("encoder_cpr")
            .unwrap_or(DEFAULT_ENCODER_CPR)
    }

    /// Accelerometer LSB per g (default 8192).
    pub fn accel_lsb_per_g(&self) -> f64 {
        self.positive_f64("accel_lsb_per_g")
            .unwrap_or(DEFAULT_ACCEL_LSB_PER_G)
    }

    /// Serial line rate in Hz (default 200).
    pub fn sample_hz(&self) -> f64 {
        self.positive_f64("sample_hz").unwrap_or(DEFAULT_SAMPLE_HZ)
    }

    /// SD encoder frame rate in Hz (default 1000).
    pub fn encoder_hz(&self) -> f64 {
        self.positive_f64("encoder_hz")
            .unwrap_or(DEFAULT_ENCODER_HZ)
    }

    /// SD accelerometer frame rate in Hz (default 200).
    pub fn accel_hz(&self) -> f64 {
        self.positive_f64("accel_hz").unwrap_or(DEFAULT_ACCEL_HZ)
    }

    fn positive<T: std::str::FromStr + PartialOrd + Default>(&self, key: &str) -> Option<T> {
        self.get(key)
            .and_then(|v| v.trim().parse::<T>().ok())
            .filter(|v| *v > T::default())
    }

    fn positive_f64(&self, key: &str) -> Option<f64> {
        self.positive::<f64>(key).filter(|v| v.is_finite())
    }

    /// Rejects a present-but-unusable numeric key: silently falling back to the default would
    /// turn a typo into wrong angles or accelerations.
    pub(crate) fn validate(&self, path: &Path) -> Result<(), RigError> {
        let bad = |key: &str, expected: &str| RigError::BadHeader {
            path: path.to_path_buf(),
            key: key.to_string(),
            value: self.get(key).unwrap_or_default().to_string(),
            expected: expected.to_string(),
        };
        if self.get("encoder_cpr").is_some() && self.positive::<u32>("encoder_cpr").is_none() {
            return Err(bad(
                "encoder_cpr",
                "a positive integer (counts per revolution)",
            ));
        }
        for key in ["accel_lsb_per_g", "sample_hz", "encoder_hz", "accel_hz"] {
            if self.get(key).is_some() && self.positive_f64(key).is_none() {
                return Err(bad(key, "a positive number"));
            }
        }
        // A tiny positive sensitivity (`1e-320`) turns every raw value into an infinite or
        // absurd acceleration, which used to surface only as an error about the output MCAP's
        // field. Any 16-bit accelerometer lies inside this range (±32768 g … ±0.03 g).
        if let Some(lsb) = self.positive_f64("accel_lsb_per_g") {
            if !(ACCEL_LSB_PER_G_RANGE.0..=ACCEL_LSB_PER_G_RANGE.1).contains(&lsb) {
                return Err(bad(
                    "accel_lsb_per_g",
                    "a sensitivity from 1 to 1e6 LSB per g (the rig's is 8192)",
                ));
            }
        }
        Ok(())
    }
}

/// Accepted `accel_lsb_per_g`, inclusive (see [`Header::validate`]).
pub const ACCEL_LSB_PER_G_RANGE: (f64, f64) = (1.0, 1e6);

/// One encoder reading.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct EncoderSample {
    /// The board's 32-bit microsecond clock as logged.
    pub t_us_raw: u32,
    /// The board clock unwrapped: `t_us_raw + 2^32 · wraps` since the capture's first sample.
    pub t_us: u64,
    /// The 16-bit count as logged.
    pub count_raw: i16,
    /// The count unwrapped (continuous across the ±32768 wrap), zero at power-on.
    pub count: i64,
    /// Angle from the hanging position, `(count + 0.5) · 2π / cpr`. The firmware's count is
    /// `floor(cpr · θ / 2π)`, so the true angle lies anywhere in `[count, count + 1)` counts: the
    /// bin centre is the unbiased estimate (using `count` itself would bias θ by half a count).
    pub theta_rad: f64,
}

/// One accelerometer reading.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct AccelSample {
    pub t_us_raw: u32,
    /// Unwrapped board clock, as in [`EncoderSample::t_us`].
    pub t_us: u64,
    /// Raw `[x, y, z]` as logged.
    pub raw: [i16; 3],
    /// `raw / lsb_per_g · g`: specific force, so z reads about +g at rest.
    pub si_m_s2: [f64; 3],
}

/// One sample of either sensor, in file order.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub enum Sample {
    Encoder(EncoderSample),
    Accel(AccelSample),
}

impl Sample {
    /// Unwrapped board time.
    pub fn t_us(&self) -> u64 {
        match self {
            Sample::Encoder(e) => e.t_us,
            Sample::Accel(a) => a.t_us,
        }
    }

    /// Board time as logged.
    pub fn t_us_raw(&self) -> u32 {
        match self {
            Sample::Encoder(e) => e.t_us_raw,
            Sample::Accel(a) => a.t_us_raw,
        }
    }
}

/// Where in a capture something happened.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Location {
    /// 1-based line number (serial captures).
    Line(u64),
    /// 0-based byte offset (SD captures).
    Byte(u64),
}

impl fmt::Display for Location {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Location::Line(n) => write!(f, "line {n}"),
            Location::Byte(n) => write!(f, "byte {n}"),
        }
    }
}

/// A damaged line or frame region that was dropped.
#[derive(Debug, Clone, PartialEq, Eq, Serialize)]
pub struct Skip {
    pub at: Location,
    pub reason: String,
}

/// A time step longer than `gap_factor ×` the nominal sample period.
#[derive(Debug, Clone, PartialEq, Eq, Serialize)]
pub struct Gap {
    /// Which stream: `"serial"`, `"encoder"` or `"accel"`.
    pub stream: &'static str,
    /// Unwrapped time of the last sample before the gap.
    pub after_t_us: u64,
    /// Unwrapped time of the first sample after the gap.
    pub before_t_us: u64,
    /// `round(step / period) − 1`.
    pub missing_samples_est: u64,
}

/// What a reader kept, dropped and noticed.
#[derive(Debug, Clone, Default, PartialEq, Eq, Serialize)]
pub struct IngestStats {
    pub encoder_samples: u64,
    pub accel_samples: u64,
    /// Serial: damaged lines. SD: damaged regions (one region may span several frames) and
    /// frames rejected for their content.
    pub skipped_lines_or_frames: u64,
    /// Serial: bytes of the skipped lines. SD: bytes dropped while resynchronising plus frames
    /// rejected for their content (with the kept frames, the header frame and the truncated
    /// tail, this accounts for every byte of the file).
    pub skipped_bytes: u64,
    /// The first [`MAX_SKIPS_KEPT`] skips, in file order.
    pub skips: Vec<Skip>,
    /// The first [`MAX_GAPS_KEPT`] gaps.
    pub gaps: Vec<Gap>,
    /// Every gap, including those not kept in `gaps`.
    pub gap_count: u64,
    pub clock_wraps: u64,
    pub encoder_wraps: u64,
    /// Bytes of a frame cut by the end of the file (power cut).
    pub truncated_tail_bytes: u64,
    /// Records dropped because their stamps left the timeline for a short run while the
    /// majority of the records carried on (stale or future-stamped blocks, duplicated chunks);
    /// each is also a skip.
    pub off_timeline: u64,
    /// Of `off_timeline`, the exact copies (stamp and values) of another record.
    pub duplicates: u64,
    /// Records dropped because a value moved faster than the pendulum or the shaker can
    /// ([`MAX_ENCODER_REV_PER_S`], [`MAX_SHAKER_JERK_M_S3`]); each is also a skip.
    pub implausible: u64,
    /// Places where the board clock restarted (a reset) or the stamps moved for good: the
    /// timeline was re-anchored there and a new segment started (also in `warnings`).
    pub new_segments: u64,
    /// Bytes of the records kept (serial lines, SD frames): with `skipped_bytes`, how much of
    /// the data was usable. 0 when the reader does not count them.
    pub kept_bytes: u64,
    /// The encoder sample period the reader used (µs): the header's, or the measured median
    /// step when the two disagree (see [`RATE_MISMATCH_FACTOR`]). 0 when unknown.
    pub encoder_period_us: u64,
    /// Unwrapped time of the first and last kept encoder samples.
    pub encoder_first_t_us: Option<u64>,
    pub encoder_last_t_us: Option<u64>,
    /// Things the reader noticed and acted on without dropping data (a header rate that the
    /// stamps contradict, a new segment); the first [`MAX_SKIPS_KEPT`].
    pub warnings: Vec<String>,
}

impl IngestStats {
    /// One line for logs and reports.
    pub fn summary(&self) -> String {
        format!(
            "{} encoder + {} accel samples; {} lines/frames skipped ({} bytes; {} off the \
             timeline, {} of them duplicates; {} implausible values); {} gaps; {} new segments; \
             {} clock wraps; {} encoder wraps; {} truncated tail bytes",
            self.encoder_samples,
            self.accel_samples,
            self.skipped_lines_or_frames,
            self.skipped_bytes,
            self.off_timeline,
            self.duplicates,
            self.implausible,
            self.gap_count,
            self.new_segments,
            self.clock_wraps,
            self.encoder_wraps,
            self.truncated_tail_bytes
        )
    }

    /// Records a skip, keeping the kept list in file order (a reader may decide on a line only
    /// after having looked at the next one).
    pub(crate) fn skip(&mut self, at: Location, reason: impl Into<String>, bytes: u64) {
        self.skipped_lines_or_frames += 1;
        self.skipped_bytes += bytes;
        if self.skips.len() < MAX_SKIPS_KEPT {
            let key = loc_key(at);
            let idx = self.skips.partition_point(|s| loc_key(s.at) <= key);
            self.skips.insert(
                idx,
                Skip {
                    at,
                    reason: reason.into(),
                },
            );
        }
    }

    /// Records a warning (the first [`MAX_SKIPS_KEPT`] are kept).
    pub(crate) fn warn(&mut self, w: String) {
        if self.warnings.len() < MAX_SKIPS_KEPT {
            self.warnings.push(w);
        }
    }

    /// Notes a kept encoder sample's time (for [`IngestStats::failure`]).
    pub(crate) fn kept_encoder(&mut self, t_us: u64) {
        self.encoder_samples += 1;
        self.encoder_first_t_us.get_or_insert(t_us);
        self.encoder_last_t_us = Some(t_us);
    }

    /// Why the capture is a failed run, or `None` if it kept enough to be one.
    ///
    /// A run holds tens of seconds to minutes of samples (rig.md), so one that keeps almost
    /// nothing is a failure to report, never an empty MCAP with exit 0. Failed when:
    /// - it kept fewer than 2 encoder samples (nothing to analyse);
    /// - it kept less than [`MIN_KEPT_FRACTION`] of its data bytes (the rest was damage); or
    /// - the kept encoder samples are fewer than [`MIN_KEPT_FRACTION`] of what their time span
    ///   implies at the sample rate used (the stream is mostly holes).
    ///
    /// The same rule for both rig readers; the fractions are skipped when a reader does not
    /// count bytes or knows no rate.
    /// The reasons carry the reader's warnings, which often say why so little was kept (a
    /// damaged header frame, a rate the stamps contradict).
    pub fn failure(&self) -> Option<String> {
        let why = self.failure_reason()?;
        Some(if self.warnings.is_empty() {
            why
        } else {
            format!(
                "{why} (the reader also warned: {})",
                self.warnings.join("; ")
            )
        })
    }

    fn failure_reason(&self) -> Option<String> {
        if self.encoder_samples < 2 {
            return Some(format!(
                "kept {} encoder samples: nothing left to analyse ({} lines/frames, {} bytes skipped as damaged)",
                self.encoder_samples, self.skipped_lines_or_frames, self.skipped_bytes
            ));
        }
        let data_bytes = self.kept_bytes + self.skipped_bytes;
        if self.kept_bytes > 0 && (self.kept_bytes as f64) < MIN_KEPT_FRACTION * data_bytes as f64 {
            return Some(format!(
                "kept {} of {data_bytes} data bytes ({:.1} %): the rest was damaged ({} lines/frames skipped)",
                self.kept_bytes,
                100.0 * self.kept_bytes as f64 / data_bytes as f64,
                self.skipped_lines_or_frames
            ));
        }
        if let (Some(a), Some(b)) = (self.encoder_first_t_us, self.encoder_last_t_us) {
            if let Some(steps) = b.saturating_sub(a).checked_div(self.encoder_period_us) {
                let implied = steps + 1;
                if (self.encoder_samples as f64) < MIN_KEPT_FRACTION * implied as f64 {
                    return Some(format!(
                        "kept {} encoder samples over {:.3} s, where a sample every {} µs implies {implied}: the stream is mostly holes",
                        self.encoder_samples,
                        (b - a) as f64 * 1e-6,
                        self.encoder_period_us
                    ));
                }
            }
        }
        None
    }

    fn gap(&mut self, gap: Gap) {
        self.gap_count += 1;
        if self.gaps.len() < MAX_GAPS_KEPT {
            self.gaps.push(gap);
        }
    }
}

fn loc_key(l: Location) -> u64 {
    match l {
        Location::Line(n) | Location::Byte(n) => n,
    }
}

/// Reading options.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct ReadOptions {
    /// Local gravity used to convert accelerometer LSB to m/s².
    pub g_m_s2: f64,
    /// A time step longer than `gap_factor ×` the nominal period is reported as a gap.
    pub gap_factor: f64,
}

impl Default for ReadOptions {
    fn default() -> Self {
        Self {
            g_m_s2: 9.81,
            gap_factor: 3.0,
        }
    }
}

/// Angle of an (unwrapped) count, at the centre of its quantisation bin.
pub(crate) fn theta_rad(count: i64, cpr: u32) -> f64 {
    (count as f64 + 0.5) * TAU / f64::from(cpr.max(1))
}

pub(crate) fn accel_si(raw: [i16; 3], lsb_per_g: f64, g_m_s2: f64) -> [f64; 3] {
    raw.map(|r| f64::from(r) / lsb_per_g * g_m_s2)
}

/// Step from `from` to `to` on the wrapping 32-bit clock: positive forward (also across a wrap),
/// negative backwards; a raw value smaller than the previous by more than 2^31 is a wrap.
pub(crate) fn signed_step(from: u32, to: u32) -> i64 {
    i64::from(to.wrapping_sub(from) as i32)
}

/// How [`check_order`] judges time steps, in µs.
#[derive(Debug, Clone, Copy)]
pub(crate) struct OrderRule {
    /// A step of at least this is "in order" (1 for one stream; negative when two streams with
    /// skewed stamps are interleaved).
    pub min_step_us: i64,
    /// The nominal step, used to decide which of two contradicting records to believe.
    pub period_us: i64,
    /// The largest step that needs no confirmation by the following records (at the end of
    /// the file nothing can confirm it).
    pub max_lone_step_us: i64,
}

/// How many following records must continue smoothly from a record that jumps ahead (or
/// starts the capture) before it is believed. Nearby lines share their leading digits, so two
/// or three neighbouring merged lines can agree with each other; a real gap is followed by a
/// steady stream.
pub(crate) const CONFIRM_RECORDS: usize = 3;

/// A run that keeps less than this fraction of its data (bytes, or samples its span implies)
/// failed ([`IngestStats::failure`]). Damage on a working link costs a few per cent; a capture
/// that lost 90 % is not a run to fit, whatever survived.
pub const MIN_KEPT_FRACTION: f64 = 0.1;

/// A header rate and the measured median step disagree when they differ by more than this
/// factor. The firmware's rates are crystal-timed (well under 1 %) and the stamps jitter by
/// tens of µs on 1–5 ms, so any real disagreement is the header being wrong (edited, or from
/// another build), never timing. 1.5 stays clear of that and of a lossy link (the median step
/// is still the period while fewer than half the steps span a gap), and catches a wrong rate
/// well before it breaks the order check, which accepts lone steps up to `gap_factor` (3)
/// periods.
pub const RATE_MISMATCH_FACTOR: f64 = 1.5;

/// Records read ahead at the start to measure the median step (0.6 s of serial lines, about
/// 0.1 s of SD frames with some 20 accelerometer ones).
pub(crate) const RATE_PROBE_RECORDS: usize = 128;

/// Fewer measured steps than this: the rate is not checked (a tiny or mostly broken capture).
const RATE_PROBE_MIN_STEPS: usize = 8;

/// How many records are read ahead to decide a jump of the clock (ahead or back): whether the
/// earlier timeline comes back within them (then the jump is a short minority, dropped) or not
/// (then the new timeline is the evidence). A bad SD sector is 512 B, at most 46 frames; a
/// terminal program's repeated buffer is a few KB, ~100 lines. 512 records cover ten of
/// either, in ~20 KB.
pub(crate) const TIMELINE_WINDOW: usize = 512;

/// A clock that jumps to below this after running (and holds there steadily) restarted: the
/// board was reset. The board counts µs from power-on and logs within a second or two of it.
pub const RESET_NEAR_ZERO_US: u32 = 10_000_000;

/// The fastest the pendulum can turn, in revolutions per second, for the plausibility of an
/// encoder step. From rig.md's rig, the shaker can drive at most a rotation at the crank's top
/// speed (2πΩ = 14.8 rad/s at Ω = 2.36 Hz) plus the speed gained falling over the top against
/// the largest base acceleration (r ω² (1 + λ) = 61 m/s² at r = 0.205 m, L = 0.575 m) on the
/// shortest arm (l = 0.17 m): sqrt(ω² + 4 (g + ÿ_max) / l) = 43 rad/s = 6.9 rev/s. The operator
/// may spin it faster by hand before the shaker starts: the twin's hand spin that wraps the
/// 16-bit count is 75 rad/s (11.9 rev/s). 25 rev/s (157 rad/s, 102 counts per ms, 512 per 5 ms)
/// is twice that; a garbled digit (8,000 counts in 5 ms: 390 rev/s) is far outside.
pub const MAX_ENCODER_REV_PER_S: f64 = 25.0;

/// Counts always allowed between two encoder samples on top of the speed bound: the
/// quantisation (±1) and a little stamp jitter.
const ENCODER_SLACK_COUNTS: f64 = 2.0;

/// The fastest the table's acceleration can change, m/s³, for the plausibility of an
/// accelerometer step: the crank-rod's largest jerk on rig.md's rig (r = 0.205 m, L = 0.575 m,
/// Ω = 2.36 Hz) is 1,036 m/s³ (0.53 g per 5 ms); doubled for the motor's ramp, the table's
/// own vibration and an `accel_gain` error.
pub const MAX_SHAKER_JERK_M_S3: f64 = 2000.0;

/// Accelerometer change always allowed between two samples, in g: the sensor noise (400 µg/√Hz
/// to 44 Hz is 3.3 mg rms) many times over.
const ACCEL_SLACK_G: f64 = 0.05;

/// Whether an encoder count can move by `d_counts` in `dt_us` (see [`MAX_ENCODER_REV_PER_S`]).
pub(crate) fn encoder_step_plausible(d_counts: i64, dt_us: i64, cpr: u32) -> bool {
    let dt_s = dt_us.max(0) as f64 * 1e-6;
    let max = MAX_ENCODER_REV_PER_S * f64::from(cpr.max(1)) * dt_s + ENCODER_SLACK_COUNTS;
    (d_counts.abs() as f64) <= max
}

/// Whether raw accelerometer values can move from `a` to `b` in `dt_us` (see
/// [`MAX_SHAKER_JERK_M_S3`]); `lsb_per_g` converts, `g_m_s2` is g.
pub(crate) fn accel_step_plausible(
    a: [i16; 3],
    b: [i16; 3],
    dt_us: i64,
    lsb_per_g: f64,
    g_m_s2: f64,
) -> bool {
    let dt_s = dt_us.max(0) as f64 * 1e-6;
    let max_g = MAX_SHAKER_JERK_M_S3 * dt_s / g_m_s2.max(1e-9) + ACCEL_SLACK_G;
    let max = max_g * lsb_per_g;
    (0..3).all(|i| (f64::from(b[i]) - f64::from(a[i])).abs() <= max)
}

/// Whether the value of `cand` is a glitch, given the last kept value of its stream (`prev`)
/// and the next ones (`next`, not yet judged), each `(raw t_us, value)`; `ok(x, y)` says
/// whether `y` can follow `x`.
///
/// The majority of the evidence decides, as for times: a candidate that `prev` cannot reach
/// is a glitch when the following values side with `prev` at least as often as with it (a lone
/// implausible value at the end of the file too); when they side with the candidate, the
/// stream really moved (or `prev` was the odd one) and it is kept. A first value is dropped
/// only when its followers agree with each other and not with it.
pub(crate) fn value_glitch<V: Copy>(
    prev: Option<(u32, V)>,
    cand: (u32, V),
    next: &[(u32, V)],
    ok: impl Fn((u32, V), (u32, V)) -> bool,
) -> bool {
    match prev {
        Some(p) => {
            if ok(p, cand) {
                return false;
            }
            let with_prev = next.iter().filter(|&&n| ok(p, n)).count();
            let with_cand = next.iter().filter(|&&n| ok(cand, n)).count();
            with_prev >= with_cand
        }
        None => match next {
            [a, b, ..] => !ok(cand, *a) && ok(*a, *b),
            _ => false,
        },
    }
}

/// The sample period one stream's stamps show, checked against the header's.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct RateCheck {
    /// The period to use, µs: the header's, or the measured one when they disagree.
    pub period_us: f64,
    /// Set when they disagree: what to tell the user.
    pub warning: Option<String>,
}

/// Compares a header's declared rate (`key` = `declared_hz`) with the median of the measured
/// positive steps of one stream (µs). Both readers use this rule, per stream.
pub(crate) fn check_rate(
    key: &str,
    declared_hz: f64,
    mut steps_us: Vec<i64>,
    what: &str,
) -> RateCheck {
    let declared_us = 1e6 / declared_hz;
    // Steps of a second or more are gaps or garbage, not the rate.
    steps_us.retain(|&s| s > 0 && s < 1_000_000);
    if steps_us.len() < RATE_PROBE_MIN_STEPS {
        return RateCheck {
            period_us: declared_us,
            warning: None,
        };
    }
    steps_us.sort_unstable();
    let median = steps_us[steps_us.len() / 2] as f64;
    let ratio = median / declared_us;
    if (1.0 / RATE_MISMATCH_FACTOR..=RATE_MISMATCH_FACTOR).contains(&ratio) {
        return RateCheck {
            period_us: declared_us,
            warning: None,
        };
    }
    RateCheck {
        period_us: median,
        warning: Some(format!(
            "header {key}={declared_hz} says a {what} sample every {declared_us:.0} µs, but the median step of the first {} is {median:.0} µs ({:.1} Hz), off by more than ×{RATE_MISMATCH_FACTOR}: the measured rate is used",
            steps_us.len() + 1,
            1e6 / median
        )),
    }
}

/// What [`Lookahead::pop_judged`] decided about a record's time.
#[derive(Debug, Clone, PartialEq)]
pub(crate) enum Timeline {
    /// It follows the timeline (or a believed gap).
    Keep,
    /// The stamps moved for good here: keep it as the first record of a new segment;
    /// `reset` when the clock restarted near zero (a board reset).
    NewSegment { reset: bool },
    /// Dropped: why, and whether it is off the timeline (a short minority run) and an exact
    /// copy of another record.
    Drop {
        reason: String,
        off_timeline: bool,
        duplicate: bool,
    },
}

impl Timeline {
    fn drop(reason: impl Into<String>) -> Self {
        Timeline::Drop {
            reason: reason.into(),
            off_timeline: false,
            duplicate: false,
        }
    }
}

/// A record as the timeline judgement sees it.
pub(crate) trait Record {
    /// Raw board time.
    fn t_raw(&self) -> u32;
    fn at(&self) -> Location;
    /// The record's values (not its time), to recognise exact copies.
    fn fingerprint(&self) -> u64;
}

/// How many kept (and dropped) records [`Recent`] remembers: 40 s of serial lines, 8 s of SD
/// frames, ~0.5 MB.
const RECENT_RECORDS: usize = 8192;

/// Records by stamp and values, forgetting the oldest beyond [`RECENT_RECORDS`].
#[derive(Debug, Default)]
struct Remembered {
    map: std::collections::HashMap<(u32, u64), Location>,
    order: std::collections::VecDeque<(u32, u64)>,
}

impl Remembered {
    fn insert(&mut self, key: (u32, u64), at: Location) {
        if self.order.len() == RECENT_RECORDS {
            if let Some(old) = self.order.pop_front() {
                self.map.remove(&old);
            }
        }
        if self.map.insert(key, at).is_none() {
            self.order.push_back(key);
        }
    }

    fn clear(&mut self) {
        self.map.clear();
        self.order.clear();
    }
}

/// The last records kept, to recognise a duplicated chunk that comes back after its original,
/// and the last ones dropped off the timeline, to recognise a copy that came before its
/// original once the original arrives.
#[derive(Debug, Default)]
pub(crate) struct Recent {
    kept: Remembered,
    dropped: Remembered,
}

impl Recent {
    /// Remembers a kept record; true if it is the original of a copy dropped earlier (then
    /// that copy is a duplicate).
    pub(crate) fn push_kept(&mut self, r: &impl Record) -> bool {
        let key = (r.t_raw(), r.fingerprint());
        self.kept.insert(key, r.at());
        self.dropped.map.remove(&key).is_some()
    }

    /// Remembers a record dropped off the timeline that was not recognised as a copy.
    pub(crate) fn push_dropped(&mut self, r: &impl Record) {
        self.dropped.insert((r.t_raw(), r.fingerprint()), r.at());
    }

    fn find(&self, r: &impl Record) -> Option<Location> {
        self.kept.map.get(&(r.t_raw(), r.fingerprint())).copied()
    }

    pub(crate) fn clear(&mut self) {
        self.kept.clear();
        self.dropped.clear();
    }
}

/// The records after a candidate that [`check_order`] looks at, read ahead from a capture's
/// record source (the serial and SD readers share it).
#[derive(Debug)]
pub(crate) struct Lookahead<T> {
    buf: std::collections::VecDeque<T>,
    /// The record source is exhausted.
    drained: bool,
}

impl<T> Default for Lookahead<T> {
    fn default() -> Self {
        Self {
            buf: std::collections::VecDeque::with_capacity(CONFIRM_RECORDS + 1),
            drained: false,
        }
    }
}

impl<T> Lookahead<T> {
    /// Reads records until the next candidate and [`CONFIRM_RECORDS`] followers are in (fewer
    /// at the end of the source).
    pub(crate) fn fill<E>(&mut self, read: impl FnMut() -> Result<Option<T>, E>) -> Result<(), E> {
        self.fill_to(CONFIRM_RECORDS + 1, read)
    }

    /// Reads records until `n` are buffered (fewer at the end of the source).
    pub(crate) fn fill_to<E>(
        &mut self,
        n: usize,
        mut read: impl FnMut() -> Result<Option<T>, E>,
    ) -> Result<(), E> {
        while self.buf.len() < n && !self.drained {
            match read()? {
                Some(x) => self.buf.push_back(x),
                None => self.drained = true,
            }
        }
        Ok(())
    }

    /// The records read ahead, the next candidate first.
    pub(crate) fn iter(&self) -> impl Iterator<Item = &T> {
        self.buf.iter()
    }
}

impl<T: Record> Lookahead<T> {
    /// Whether the next candidate jumps (ahead beyond a lone step, or back) from `prev`: then
    /// [`TIMELINE_WINDOW`] records must be read ahead before [`Lookahead::pop_judged`].
    pub(crate) fn front_jumps(&self, prev: Option<u32>, rule: OrderRule) -> bool {
        match (prev, self.buf.front()) {
            (Some(p), Some(c)) => {
                let s = signed_step(p, c.t_raw());
                s < rule.min_step_us || s > rule.max_lone_step_us
            }
            _ => false,
        }
    }

    /// The next candidate (None at the end) with the verdict on its time, given the last kept
    /// record's raw time `prev` and the records read ahead ([`Lookahead::front_jumps`] says
    /// when the whole window is needed), and the recently kept records.
    ///
    /// An ordinary step is judged by [`check_order`]. A jump, ahead or back, is judged by the
    /// majority of the evidence in the window:
    /// - a copy (stamp and values) of a recently kept record is a duplicated chunk: dropped;
    /// - if the earlier timeline comes back within the window (a record that continues from
    ///   `prev`, followed steadily), the jump is a short minority (a stale or future-stamped
    ///   block, a chunk repeated out of place): dropped, whatever its own consistency;
    /// - otherwise, if the candidate starts a steady run, the stamps really moved: a jump ahead
    ///   is a gap (kept), a jump back or a restart near zero a new segment;
    /// - otherwise the candidate is a lone damaged record: dropped.
    pub(crate) fn pop_judged(
        &mut self,
        prev: Option<u32>,
        rule: OrderRule,
        recent: &Recent,
    ) -> Option<(T, Timeline)> {
        let cand = self.buf.pop_front()?;
        let c = cand.t_raw();
        let mut next = [0u32; CONFIRM_RECORDS];
        let k = self.buf.len().min(CONFIRM_RECORDS);
        for (slot, x) in next.iter_mut().zip(&self.buf) {
            *slot = x.t_raw();
        }
        let verdict = match prev {
            Some(p)
                if {
                    let s = signed_step(p, c);
                    s < rule.min_step_us || s > rule.max_lone_step_us
                } =>
            {
                self.judge_jump(p, &cand, rule, recent)
            }
            _ => match check_order(prev, c, &next[..k], rule) {
                Ok(()) => Timeline::Keep,
                Err(why) => Timeline::drop(why),
            },
        };
        Some((cand, verdict))
    }

    fn judge_jump(&self, p: u32, cand: &T, rule: OrderRule, recent: &Recent) -> Timeline {
        let c = cand.t_raw();
        let step = signed_step(p, c);
        let behind = step < rule.min_step_us;
        let ordinary = |a: u32, b: u32| {
            let s = signed_step(a, b);
            s >= rule.min_step_us && s <= rule.max_lone_step_us
        };
        let off = |why: String, duplicate: bool| Timeline::Drop {
            reason: why,
            off_timeline: true,
            duplicate,
        };
        let shift = format!("{:+.6} s", step as f64 * 1e-6);
        if behind {
            if let Some(at) = recent.find(cand) {
                return off(
                    format!("repeats the record kept at {at} (a duplicated chunk; t_us={c})"),
                    true,
                );
            }
        }
        // Steady from index i of the window: its next records step ordinarily (fewer at the
        // end of the file; none needed for the last record of the file).
        let steady_from = |i: usize| {
            let mut last = self.buf[i].t_raw();
            for x in self.buf.iter().skip(i + 1).take(CONFIRM_RECORDS) {
                if !ordinary(last, x.t_raw()) {
                    return false;
                }
                last = x.t_raw();
            }
            self.drained || self.buf.len() > i + CONFIRM_RECORDS
        };
        for (i, x) in self.buf.iter().enumerate() {
            let s = signed_step(p, x.t_raw());
            // Records lost while the damage lasted widen how far on the earlier timeline may
            // resume; a record lying between `prev` and a jump ahead is on it.
            let on_earlier = if behind {
                s >= rule.min_step_us && s <= rule.max_lone_step_us.saturating_mul(i as i64 + 2)
            } else {
                s >= rule.min_step_us && signed_step(x.t_raw(), c) > rule.max_lone_step_us
            };
            if on_earlier && steady_from(i) {
                let copy = self
                    .buf
                    .iter()
                    .find(|y| y.t_raw() == c && y.fingerprint() == cand.fingerprint())
                    .map(|y| y.at());
                let what = if copy.is_some() {
                    " (a copy of a record further on: a duplicated chunk)"
                } else {
                    ""
                };
                return off(
                    format!(
                        "stamped {shift} off the timeline, which resumes at {}{what} (t_us={c})",
                        x.at()
                    ),
                    copy.is_some(),
                );
            }
        }
        let confirmed = !self.buf.is_empty() && {
            let mut last = c;
            self.buf.iter().take(CONFIRM_RECORDS).all(|x| {
                let ok = ordinary(last, x.t_raw());
                last = x.t_raw();
                ok
            })
        };
        if !confirmed {
            return Timeline::drop(if behind {
                "time goes backwards"
            } else {
                "time jumps ahead and the next records do not follow"
            });
        }
        // Far beyond a wrap's reach yet near zero: the clock restarted (a genuine wrap lands
        // near zero only from near the top, a short step).
        let restarted =
            c < RESET_NEAR_ZERO_US && (behind || step > 2 * i64::from(RESET_NEAR_ZERO_US));
        if behind || restarted {
            Timeline::NewSegment { reset: restarted }
        } else {
            Timeline::Keep
        }
    }
}

/// How many segments (runs of records between two jumps of the clock) a reader remembers for
/// [`TimelinePlan`]. A capture with more jumps than this is so broken that no majority can be
/// told: then no plan is made (the read-ahead window's verdicts stand).
const MAX_SEGMENTS: usize = 1024;

/// How many consecutive segments one block off the timeline may span (a stale block that is
/// itself broken by a jump).
const MAX_BLOCK_SEGMENTS: usize = 8;

/// How many times a capture is read at most: the first reading, and again while a reading
/// finds blocks off the timeline (each reading drops what the ones before found; a block
/// inside a block needs a third).
pub const MAX_READINGS: usize = 3;

/// A run of kept records whose steps are all ordinary, as a reader's first pass saw it.
#[derive(Debug, Clone, Copy)]
struct Segment {
    first_at: Location,
    last_at: Location,
    first_raw: u32,
    last_raw: u32,
    records: u64,
}

/// The segments of a reader's pass: where the clock jumped (ahead beyond a lone step, back,
/// or restarted) between kept records. Bounded by [`MAX_SEGMENTS`].
#[derive(Debug, Default)]
pub(crate) struct SegmentLog {
    segs: Vec<Segment>,
    overflow: bool,
}

impl SegmentLog {
    /// A record was kept; `jumped`: its step from the last kept record was not ordinary (a
    /// believed gap or a new segment).
    pub(crate) fn kept(&mut self, at: Location, raw: u32, jumped: bool) {
        if self.overflow {
            return;
        }
        if !jumped {
            if let Some(s) = self.segs.last_mut() {
                s.last_at = at;
                s.last_raw = raw;
                s.records += 1;
                return;
            }
        }
        if self.segs.len() == MAX_SEGMENTS {
            self.overflow = true;
            self.segs = Vec::new();
        } else {
            self.segs.push(Segment {
                first_at: at,
                last_at: at,
                first_raw: raw,
                last_raw: raw,
                records: 1,
            });
        }
    }

    /// The blocks this pass kept that the majority of the evidence says are off the timeline.
    ///
    /// A block (one or a few consecutive segments) is off the timeline when the segment after
    /// it continues the segment before it (the step between them is in order and no longer
    /// than the block could have covered: the block was inserted, or replaced as many records),
    /// the block's stamps do not lie between the two (records after real gaps do), and the two
    /// together hold more records than the block. The clock cannot leave its
    /// timeline and come back to it, so the side that does not fit is the damage: a stale or
    /// future-stamped block, or a chunk repeated out of place, whatever its length. A first or
    /// last segment has only one side: nothing says which of the two is right, so both stay
    /// (a new segment). Of several candidates the one with the smallest share of the records
    /// around it is decided first (a long stale block must not make a real gap before it look
    /// like the excursion).
    pub(crate) fn plan(&self, rule: OrderRule) -> Option<TimelinePlan> {
        if self.overflow {
            return None;
        }
        let mut segs = self.segs.clone();
        let mut blocks = Vec::new();
        loop {
            // (ratio, first index of the block, index of the segment resuming the timeline)
            let mut best: Option<(f64, usize, usize)> = None;
            for i in 1..segs.len() {
                let before = segs[i - 1];
                let mut inside = 0u64;
                for j in (i + 1)..segs.len().min(i + 1 + MAX_BLOCK_SEGMENTS) {
                    inside += segs[j - 1].records;
                    let after = segs[j];
                    let step = signed_step(before.last_raw, after.first_raw);
                    let reach = rule.max_lone_step_us.saturating_add(
                        2i64.saturating_mul(rule.period_us.max(1))
                            .saturating_mul(i64::try_from(inside).unwrap_or(i64::MAX)),
                    );
                    let around = before.records + after.records;
                    // Every segment of the block lies off the line from `before` to `after`
                    // (real data after real gaps lies between them in time).
                    let off = segs[i..j].iter().all(|s| {
                        signed_step(before.last_raw, s.first_raw) < rule.min_step_us
                            || signed_step(s.last_raw, after.first_raw) < rule.min_step_us
                    });
                    if off && step >= rule.min_step_us && step <= reach && inside < around {
                        let ratio = inside as f64 / around as f64;
                        if best.is_none_or(|b| ratio < b.0) {
                            best = Some((ratio, i, j));
                        }
                        break;
                    }
                }
            }
            let Some((_, i, j)) = best else { break };
            let (before, after) = (segs[i - 1], segs[j]);
            blocks.push(OffTimelineBlock {
                from: segs[i].first_at,
                to: segs[j - 1].last_at,
                records: segs[i..j].iter().map(|s| s.records).sum(),
                shift_us: signed_step(before.last_raw, segs[i].first_raw),
                resumes_at: after.first_at,
                around: before.records + after.records,
            });
            let merged = Segment {
                first_at: before.first_at,
                first_raw: before.first_raw,
                last_at: after.last_at,
                last_raw: after.last_raw,
                records: before.records + after.records,
            };
            segs.splice(i - 1..=j, [merged]);
        }
        if blocks.is_empty() {
            return None;
        }
        blocks.sort_by_key(|b| loc_key(b.from));
        Some(TimelinePlan { blocks })
    }
}

/// A block of records a first pass kept that is off the timeline (see [`TimelinePlan`]).
#[derive(Debug, Clone, PartialEq, Eq, Serialize)]
pub struct OffTimelineBlock {
    /// The block's first and last records.
    pub from: Location,
    pub to: Location,
    /// Records the first pass kept in it.
    pub records: u64,
    /// How far its first stamp is from the timeline before it, µs.
    pub shift_us: i64,
    /// The first record after it, where the timeline resumes.
    pub resumes_at: Location,
    /// Records of the timeline on either side of it that continue across it.
    pub around: u64,
}

/// What a capture's second reading drops: the blocks a first reading kept although the
/// timeline before and after them continues across them (stale or future-stamped blocks and
/// chunks repeated out of place longer than the [`TIMELINE_WINDOW`] read ahead).
///
/// A reader decides a jump of the clock on the records it reads ahead; a block longer than
/// that cannot be told from a real jump until it ends. So a reader records where its clock
/// jumped, and at the end of the capture says which blocks the majority of the evidence
/// rejects ([`crate::SdReader::timeline_plan`]); the capture is then read again with the plan
/// ([`crate::SdReader::set_timeline_plan`]), and those blocks are dropped as off the timeline
/// (in `off_timeline` and the skips, with a warning each). Captures without such a block are
/// read once.
#[derive(Debug, Clone, Default, PartialEq, Eq, Serialize)]
pub struct TimelinePlan {
    /// Sorted by position, not overlapping.
    pub blocks: Vec<OffTimelineBlock>,
}

impl TimelinePlan {
    pub fn is_empty(&self) -> bool {
        self.blocks.is_empty()
    }

    /// Adds the blocks of a later reading (made with this plan, so they do not overlap).
    pub fn merge(&mut self, other: TimelinePlan) {
        self.blocks.extend(other.blocks);
        self.blocks.sort_by_key(|b| loc_key(b.from));
    }

    /// The block that holds the record at `at`.
    pub(crate) fn covering(&self, at: Location) -> Option<&OffTimelineBlock> {
        let k = loc_key(at);
        let i = self.blocks.partition_point(|b| loc_key(b.from) <= k);
        let b = self.blocks.get(i.checked_sub(1)?)?;
        (loc_key(b.to) >= k).then_some(b)
    }

    /// The warning a reader gives for each block it drops.
    pub(crate) fn warnings(&self) -> impl Iterator<Item = String> + '_ {
        self.blocks.iter().map(|b| {
            format!(
                "{}–{}: {} records stamped {:+.6} s off the timeline dropped: the {} records \
                 before and after them continue across them (the timeline resumes at {})",
                b.from,
                b.to,
                b.records,
                b.shift_us as f64 * 1e-6,
                b.around,
                b.resumes_at
            )
        })
    }

    /// The skip reason of a record in `b`.
    pub(crate) fn reason(b: &OffTimelineBlock, t_raw: u32) -> String {
        format!(
            "stamped {:+.6} s off the timeline in a block of {} records ({}–{}), which resumes at \
             {}: the {} records around it agree (t_us={t_raw})",
            b.shift_us as f64 * 1e-6,
            b.records,
            b.from,
            b.to,
            b.resumes_at,
            b.around
        )
    }
}

/// Outlier rejection with a few records of lookahead, on the raw clock.
///
/// A damaged record that still parses (merged serial lines, a CRC collision) nearly always has a
/// time that does not fit between its neighbours. `prev` is the last kept record, `next` the
/// following candidates (up to [`CONFIRM_RECORDS`], fewer at the end of the file).
/// - A step longer than `max_lone_step_us` (a jump ahead, or the first record) is believed only
///   if the next records follow it with ordinary steps.
/// - When the candidate and the next record contradict each other but both follow `prev`, the
///   one whose step from `prev` is closer to the nominal period is believed.
///
/// Keeping a damaged record would invent a sample and make every later one look out of order,
/// so when unsure the candidate is the one dropped.
pub(crate) fn check_order(
    prev: Option<u32>,
    cand: u32,
    next: &[u32],
    rule: OrderRule,
) -> Result<(), &'static str> {
    let ok = |a: u32, b: u32| signed_step(a, b) >= rule.min_step_us;
    let ordinary = |a: u32, b: u32| ok(a, b) && signed_step(a, b) <= rule.max_lone_step_us;
    let confirmed = || {
        let mut last = cand;
        for &n in next {
            if !ordinary(last, n) {
                return false;
            }
            last = n;
        }
        true
    };
    let Some(p) = prev else {
        // A capture of one record has nothing to check it against: kept.
        return if confirmed() {
            Ok(())
        } else {
            Err("first record not followed by a steady stream")
        };
    };
    if !ok(p, cand) {
        return Err("time goes backwards");
    }
    if signed_step(p, cand) > rule.max_lone_step_us {
        return if !next.is_empty() && confirmed() {
            Ok(())
        } else {
            Err("time jumps ahead and the next records do not follow")
        };
    }
    let Some(&n) = next.first() else {
        return Ok(());
    };
    if ok(cand, n) || !ok(p, n) {
        return Ok(());
    }
    let off = |x: u32| (signed_step(p, x) - rule.period_us).abs();
    if off(cand) <= off(n) {
        Ok(())
    } else {
        Err("time jumps out of order with its neighbours")
    }
}

/// Unwraps the shared 32-bit board clock.
#[derive(Debug, Default)]
pub(crate) struct Clock {
    last_raw: Option<u32>,
    last_t: i64,
    max_t: i64,
}

impl Clock {
    pub(crate) fn last_raw(&self) -> Option<u32> {
        self.last_raw
    }

    /// The unwrapped time of `raw`, or `None` if it would fall before zero (a record stamped
    /// before the capture's first one, across a wrap).
    pub(crate) fn peek(&self, raw: u32) -> Option<u64> {
        match self.last_raw {
            None => Some(u64::from(raw)),
            Some(p) => u64::try_from(self.last_t + signed_step(p, raw)).ok(),
        }
    }

    /// Where a new segment starting at raw time `raw` goes on the unwrapped timeline: after
    /// the last record by the time since a reset (`raw` counts from the board's power-on, so
    /// the hole is at least that long), or by one `period_us` when the stamps merely moved.
    pub(crate) fn reanchor_t(&self, raw: u32, reset: bool, period_us: u64) -> u64 {
        let last = u64::try_from(self.last_t).unwrap_or(0);
        let after = if reset {
            u64::from(raw).max(period_us)
        } else {
            period_us
        };
        last.saturating_add(after.max(1))
    }

    /// Continues the timeline from a new segment's first record (no clock wrap is counted).
    pub(crate) fn reanchor(&mut self, raw: u32, t_us: u64) {
        let t = i64::try_from(t_us).unwrap_or(i64::MAX);
        self.last_raw = Some(raw);
        self.last_t = t;
        self.max_t = self.max_t.max(t);
    }

    pub(crate) fn commit(&mut self, raw: u32, t_us: u64, stats: &mut IngestStats) {
        let t = i64::try_from(t_us).unwrap_or(i64::MAX);
        if self.last_raw.is_none() {
            self.max_t = t;
        } else if t > self.max_t {
            let wraps = (t >> 32) - (self.max_t >> 32);
            stats.clock_wraps += u64::try_from(wraps).unwrap_or(0);
            self.max_t = t;
        }
        self.last_raw = Some(raw);
        self.last_t = t;
    }
}

/// Unwraps the 16-bit encoder count.
#[derive(Debug, Default)]
pub(crate) struct Counter {
    last_raw: Option<i16>,
    count: i64,
}

impl Counter {
    /// The board powered on again: its count restarted from zero where the pendulum was.
    pub(crate) fn restart(&mut self) {
        self.last_raw = None;
    }

    /// The difference is taken mod 2^16 into [−32768, 32767]: a jump of 2^15 counts between two
    /// samples (half of 8 revolutions in 1–5 ms) is physically impossible.
    pub(crate) fn step(&mut self, raw: i16, stats: &mut IngestStats) -> i64 {
        match self.last_raw {
            None => self.count = i64::from(raw),
            Some(p) => {
                let d = i64::from(raw.wrapping_sub(p));
                let sum = i64::from(p) + d;
                if sum > i64::from(i16::MAX) || sum < i64::from(i16::MIN) {
                    stats.encoder_wraps += 1;
                }
                self.count += d;
            }
        }
        self.last_raw = Some(raw);
        self.count
    }
}

/// Gap detection for one stream.
#[derive(Debug)]
pub(crate) struct GapTracker {
    stream: &'static str,
    period_us: f64,
    factor: f64,
    last_t: Option<u64>,
}

impl GapTracker {
    pub(crate) fn new(stream: &'static str, rate_hz: f64, factor: f64) -> Self {
        Self {
            stream,
            period_us: 1e6 / rate_hz,
            factor,
            last_t: None,
        }
    }

    pub(crate) fn last_t(&self) -> Option<u64> {
        self.last_t
    }

    pub(crate) fn set_period_us(&mut self, period_us: f64) {
        self.period_us = period_us;
    }

    pub(crate) fn step(&mut self, t_us: u64, stats: &mut IngestStats) {
        if let Some(prev) = self.last_t {
            let dt = t_us.saturating_sub(prev) as f64;
            if dt > self.factor * self.period_us {
                let missing = ((dt / self.period_us).round() - 1.0).max(0.0);
                stats.gap(Gap {
                    stream: self.stream,
                    after_t_us: prev,
                    before_t_us: t_us,
                    missing_samples_est: missing as u64,
                });
            }
        }
        self.last_t = Some(t_us);
    }
}

/// A short, printable excerpt of a damaged input for messages.
pub(crate) fn snippet(bytes: &[u8]) -> String {
    const MAX: usize = 40;
    let s = String::from_utf8_lossy(&bytes[..bytes.len().min(MAX)]);
    let mut out: String = s.escape_debug().collect();
    if bytes.len() > MAX {
        out.push('…');
    }
    format!("\"{out}\"")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn theta_is_bin_centre() {
        assert!((theta_rad(0, 4096) - 0.5 * TAU / 4096.0).abs() < 1e-15);
        assert!((theta_rad(-1, 4096) + 0.5 * TAU / 4096.0).abs() < 1e-15);
        assert!((theta_rad(4095, 4096) - (TAU - 0.5 * TAU / 4096.0)).abs() < 1e-12);
    }

    #[test]
    fn clock_unwraps_and_counts_wraps() {
        let mut stats = IngestStats::default();
        let mut c = Clock::default();
        let t0 = c.peek(u32::MAX - 10).unwrap();
        c.commit(u32::MAX - 10, t0, &mut stats);
        let t1 = c.peek(5).unwrap();
        assert_eq!(t1, (1u64 << 32) + 5);
        c.commit(5, t1, &mut stats);
        assert_eq!(stats.clock_wraps, 1);
        // slightly backwards across the wrap (another stream's stamp): no extra wrap
        let t2 = c.peek(u32::MAX - 2).unwrap();
        assert_eq!(t2, u64::from(u32::MAX - 2));
        c.commit(u32::MAX - 2, t2, &mut stats);
        let t3 = c.peek(100).unwrap();
        c.commit(100, t3, &mut stats);
        assert_eq!(stats.clock_wraps, 1);
    }

    #[test]
    fn counter_unwraps() {
        let mut stats = IngestStats::default();
        let mut c = Counter::default();
        assert_eq!(c.step(32760, &mut stats), 32760);
        assert_eq!(c.step(-32766, &mut stats), 32770);
        assert_eq!(c.step(32767, &mut stats), 32767);
        assert_eq!(stats.encoder_wraps, 2);
    }

    #[test]
    fn order_check() {
        let r = OrderRule {
            min_step_us: 1,
            period_us: 100,
            max_lone_step_us: 300,
        };
        assert!(check_order(Some(100), 200, &[300], r).is_ok());
        assert!(check_order(Some(100), 90, &[300], r).is_err());
        // outlier between good neighbours
        assert!(check_order(Some(100), 90_000, &[300], r).is_err());
        // the next one is the outlier: keep the candidate
        assert!(check_order(Some(100), 200, &[50], r).is_ok());
        assert!(check_order(Some(100), 200, &[120], r).is_ok());
        // wrap
        assert!(check_order(Some(u32::MAX - 5), 3, &[5000], r).is_ok());
        // the last record
        assert!(check_order(Some(100), 300, &[], r).is_ok());
        // a gap followed by a steady stream, and two merged lines agreeing with each other
        assert!(check_order(Some(100), 5_000, &[5_100, 5_200, 5_300], r).is_ok());
        assert!(check_order(Some(100), 5_000, &[5_100, 300, 400], r).is_err());
        assert!(check_order(Some(100), 90_000, &[], r).is_err());
        // the first record
        assert!(check_order(None, 100, &[200], r).is_ok());
        assert!(check_order(None, 100, &[90_000], r).is_err());
        assert!(check_order(None, 100, &[], r).is_ok());
    }

    #[test]
    fn header_defaults_and_validation() {
        let h = Header::new().with("x", "1");
        assert_eq!(h.encoder_cpr(), 4096);
        assert_eq!(h.accel_lsb_per_g(), 8192.0);
        assert_eq!(h.sample_hz(), 200.0);
        assert!(h.validate(Path::new("f")).is_ok());
        let bad = Header::new().with("encoder_cpr", "zero");
        let e = bad.validate(Path::new("f.csv")).unwrap_err().to_string();
        assert!(e.contains("f.csv") && e.contains("encoder_cpr"), "{e}");
    }

    /// Issue 13, item 10: a sensitivity that makes accelerations infinite or absurd is refused
    /// naming the capture's header key (it used to fail later naming the output MCAP's field).
    #[test]
    fn issue_13_implausible_accel_lsb_per_g_names_the_header_key() {
        for v in ["1e-320", "1e-300", "0.5", "2e6"] {
            let h = Header::new().with("accel_lsb_per_g", v);
            let e = h.validate(Path::new("r01.csv")).unwrap_err().to_string();
            assert!(
                e.contains("r01.csv")
                    && e.contains("header key `accel_lsb_per_g`")
                    && e.contains(v),
                "{e}"
            );
        }
        for v in ["1", "8192", "16384", "1e6"] {
            assert!(Header::new()
                .with("accel_lsb_per_g", v)
                .validate(Path::new("f"))
                .is_ok());
        }
    }
}
