//! The binary SD-card capture (`*.bin`, firmware `sd-v2`): reader and writer.
//!
//! Frame: `A5 5A | type | n | t_us (u32 LE) | payload (n bytes) | CRC-8 over type..payload`.
//! The reader keeps a bounded buffer (one read chunk plus one frame), resynchronises after
//! damage on the next sync whose frame has a valid CRC, and reports what it dropped.

use std::io::{self, Read, Write};
use std::path::{Path, PathBuf};

use crate::capture::{
    accel_si, accel_step_plausible, check_rate, encoder_step_plausible, signed_step, theta_rad,
    value_glitch, AccelSample, Clock, Counter, EncoderSample, GapTracker, Header, IngestStats,
    Location, Lookahead, OrderRule, ReadOptions, Recent, Record, Sample, SegmentLog, Timeline,
    TimelinePlan, CONFIRM_RECORDS, RATE_PROBE_RECORDS, TIMELINE_WINDOW,
};
use crate::crc8::crc8;
use crate::error::RigError;

/// Frame start marker.
pub const SYNC: [u8; 2] = [0xA5, 0x5A];
pub const FRAME_ENCODER: u8 = 1;
pub const FRAME_ACCEL: u8 = 2;
pub const FRAME_HEADER: u8 = 3;
/// Sync, type, length, t_us and CRC: a frame is `FRAME_OVERHEAD + n` bytes.
pub const FRAME_OVERHEAD: usize = 9;

/// Accelerometer stamps are compensated for the filter delay, so an accel frame may be stamped
/// a few ms before the encoder frame written just before it: steps down to −50 ms between
/// frames of different streams are still "in order" for outlier rejection.
const MAX_CROSS_STREAM_SKEW_US: i64 = 50_000;
/// Records read ahead to find the next frames of a stream when a value looks implausible (the
/// accelerometer has one frame in six).
const VALUE_WINDOW: usize = 4 * (CONFIRM_RECORDS + 1);
const READ_CHUNK: usize = 16 * 1024;

/// Builds one frame. A payload longer than 255 bytes is cut to 255 (the length is one byte).
pub fn encode_frame(kind: u8, t_us: u32, payload: &[u8]) -> Vec<u8> {
    let payload = &payload[..payload.len().min(255)];
    let mut f = Vec::with_capacity(FRAME_OVERHEAD + payload.len());
    f.extend_from_slice(&SYNC);
    f.push(kind);
    f.push(payload.len() as u8);
    f.extend_from_slice(&t_us.to_le_bytes());
    f.extend_from_slice(payload);
    let crc = crc8(&f[2..]);
    f.push(crc);
    f
}

fn valid_kind_len(kind: u8, n: u8) -> bool {
    matches!(
        (kind, n),
        (FRAME_ENCODER, 2) | (FRAME_ACCEL, 6) | (FRAME_HEADER, _)
    )
}

/// A frame that passed sync, type/length and CRC checks.
struct Frame {
    offset: u64,
    kind: u8,
    len: u64,
    t_us: u32,
    payload: [u8; 6],
    suspect: Suspect,
}

/// Whether a frame that passed its CRC still needs a plausibility check.
///
/// A frame whose bytes were shifted by an insertion or deletion passes the 8-bit CRC by chance
/// 1 time in 256; it then mostly ends off the frame grid (not followed by a sync), so such
/// frames must also look plausible next to the last sample of their stream.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Suspect {
    /// Followed by a sync.
    No,
    /// The last frame of the file: checked if its stream has an earlier sample.
    AtEnd,
    /// Followed by something else: checked, and dropped if its stream has no earlier sample.
    OffGrid,
}

impl Frame {
    fn i16_at(&self, i: usize) -> i16 {
        i16::from_le_bytes([self.payload[2 * i], self.payload[2 * i + 1]])
    }

    fn accel(&self) -> [i16; 3] {
        [self.i16_at(0), self.i16_at(1), self.i16_at(2)]
    }
}

impl Record for Frame {
    fn t_raw(&self) -> u32 {
        self.t_us
    }

    fn at(&self) -> Location {
        Location::Byte(self.offset)
    }

    fn fingerprint(&self) -> u64 {
        self.payload
            .iter()
            .fold(u64::from(self.kind), |acc, &b| (acc << 8) | u64::from(b))
    }
}

/// Bytes being dropped since the last valid frame.
struct DropRun {
    start: u64,
    len: u64,
    reason: &'static str,
}

/// Streaming reader of an SD capture.
pub struct SdReader<R: Read> {
    inner: R,
    path: PathBuf,
    opts: ReadOptions,
    header: Header,
    cpr: u32,
    lsb_per_g: f64,
    order: OrderRule,
    buf: Vec<u8>,
    start: usize,
    buf_offset: u64,
    eof: bool,
    dropping: Option<DropRun>,
    tail_start: Option<u64>,
    finished: bool,
    lookahead: Lookahead<Frame>,
    /// The rates were checked against the first frames ([`SdReader::probe_rate`]).
    probed: bool,
    encoder_period_us: f64,
    recent: Recent,
    /// Where the clock jumped between kept frames, for [`SdReader::timeline_plan`].
    segments: SegmentLog,
    /// Blocks an earlier reading found off the timeline: dropped as they are read.
    plan: TimelinePlan,
    /// The last kept frame of each stream: raw time and value, for plausibility.
    last_enc_raw: Option<(u32, i16)>,
    last_acc_raw: Option<(u32, [i16; 3])>,
    clock: Clock,
    counter: Counter,
    enc_gaps: GapTracker,
    acc_gaps: GapTracker,
    last_enc: Option<(u64, i16)>,
    last_acc: Option<(u64, [i16; 3])>,
    stats: IngestStats,
}

impl<R: Read> SdReader<R> {
    /// Reads the header frame, which must start the file. `path` is only used in messages.
    pub fn new(inner: R, path: impl AsRef<Path>, opts: ReadOptions) -> Result<Self, RigError> {
        let mut me = Self {
            inner,
            path: path.as_ref().to_path_buf(),
            opts,
            header: Header::new(),
            cpr: 0,
            lsb_per_g: 0.0,
            order: OrderRule {
                min_step_us: -MAX_CROSS_STREAM_SKEW_US,
                period_us: 1000,
                max_lone_step_us: MAX_CROSS_STREAM_SKEW_US,
            },
            buf: Vec::with_capacity(READ_CHUNK + 512),
            start: 0,
            buf_offset: 0,
            eof: false,
            dropping: None,
            tail_start: None,
            finished: false,
            lookahead: Lookahead::default(),
            probed: false,
            encoder_period_us: 1000.0,
            recent: Recent::default(),
            segments: SegmentLog::default(),
            plan: TimelinePlan::default(),
            last_enc_raw: None,
            last_acc_raw: None,
            clock: Clock::default(),
            counter: Counter::default(),
            enc_gaps: GapTracker::new("encoder", 1.0, 1.0),
            acc_gaps: GapTracker::new("accel", 1.0, 1.0),
            last_enc: None,
            last_acc: None,
            stats: IngestStats::default(),
        };
        me.read_header()?;
        me.header.validate(&me.path)?;
        me.cpr = me.header.encoder_cpr();
        me.lsb_per_g = me.header.accel_lsb_per_g();
        me.enc_gaps = GapTracker::new("encoder", me.header.encoder_hz(), opts.gap_factor);
        me.acc_gaps = GapTracker::new("accel", me.header.accel_hz(), opts.gap_factor);
        me.set_periods(1e6 / me.header.encoder_hz(), 1e6 / me.header.accel_hz());
        Ok(me)
    }

    fn set_periods(&mut self, encoder_us: f64, accel_us: f64) {
        self.encoder_period_us = encoder_us;
        self.stats.encoder_period_us = encoder_us.round() as u64;
        self.enc_gaps.set_period_us(encoder_us);
        self.acc_gaps.set_period_us(accel_us);
        let slowest_period_us = encoder_us.max(accel_us);
        self.order = OrderRule {
            min_step_us: -MAX_CROSS_STREAM_SKEW_US,
            period_us: encoder_us.round() as i64,
            max_lone_step_us: (self.opts.gap_factor.max(1.0) * slowest_period_us).round() as i64
                + MAX_CROSS_STREAM_SKEW_US,
        };
    }

    /// Reads the first [`RATE_PROBE_RECORDS`] frames ahead and checks the header's
    /// `encoder_hz` and `accel_hz` against each stream's median step ([`check_rate`], the rule
    /// of the serial reader): when they disagree, the stamps win.
    fn probe_rate(&mut self) -> Result<(), RigError> {
        self.probed = true;
        let mut ahead = std::mem::take(&mut self.lookahead);
        let filled = ahead.fill_to(RATE_PROBE_RECORDS, || self.next_data_frame());
        self.lookahead = ahead;
        filled?;
        let steps = |kind: u8| -> Vec<i64> {
            let t: Vec<u32> = self
                .lookahead
                .iter()
                .filter(|f| f.kind == kind)
                .map(|f| f.t_us)
                .collect();
            t.windows(2).map(|w| signed_step(w[0], w[1])).collect()
        };
        let enc = check_rate(
            "encoder_hz",
            self.header.encoder_hz(),
            steps(FRAME_ENCODER),
            "encoder",
        );
        let acc = check_rate(
            "accel_hz",
            self.header.accel_hz(),
            steps(FRAME_ACCEL),
            "accelerometer",
        );
        if enc.warning.is_some() || acc.warning.is_some() {
            for w in [enc.warning, acc.warning].into_iter().flatten() {
                self.stats.warn(w);
            }
            self.set_periods(enc.period_us, acc.period_us);
        }
        Ok(())
    }

    pub fn header(&self) -> &Header {
        &self.header
    }

    pub fn stats(&self) -> &IngestStats {
        &self.stats
    }

    /// Drops the blocks of `plan` (from an earlier reading of the same capture) as they are
    /// read, each with a warning. Call before the first [`SdReader::next_sample`].
    pub fn set_timeline_plan(&mut self, plan: TimelinePlan) {
        for w in plan.warnings() {
            self.stats.warn(w);
        }
        self.plan = plan;
    }

    /// After the last sample: the blocks this reading kept that the majority of the evidence
    /// puts off the timeline (see [`TimelinePlan`]), or `None` when there are none. Read the
    /// capture again with [`SdReader::set_timeline_plan`] to drop them.
    pub fn timeline_plan(&self) -> Option<TimelinePlan> {
        self.segments.plan(self.order)
    }

    fn not_a_capture(&self, at: u64, reason: &str) -> RigError {
        RigError::NotACapture {
            path: self.path.clone(),
            at: Location::Byte(at),
            reason: reason.to_string(),
        }
    }

    fn read_header(&mut self) -> Result<(), RigError> {
        let avail = self.fill(4)?;
        let b = &self.buf[self.start..];
        if avail < 2 || b[..2] != SYNC {
            return Err(self.not_a_capture(0, "expected the sd-v2 sync bytes A5 5A"));
        }
        if avail < 4 {
            return Err(self.not_a_capture(2, "expected a header frame (type 3) first"));
        }
        if b[2] != FRAME_HEADER {
            // A data frame first: no header was written (not damage the reader can repair).
            if valid_kind_len(b[2], b[3]) {
                return Err(self.not_a_capture(2, "expected a header frame (type 3) first"));
            }
            self.header_lost(
                2,
                "its type byte is neither a header's nor a data frame's",
                None,
            );
            return Ok(());
        }
        let total = FRAME_OVERHEAD + usize::from(b[3]);
        if self.fill(total)? < total {
            return Err(self.not_a_capture(0, "header frame cut short by the end of the file"));
        }
        let f = &self.buf[self.start..self.start + total];
        if crc8(&f[2..total - 1]) != f[total - 1] {
            let text = String::from_utf8_lossy(&f[8..total - 1]).into_owned();
            self.header_lost((total - 1) as u64, "CRC mismatch", Some(&text));
            return Ok(());
        }
        let text = String::from_utf8_lossy(&f[8..total - 1]).into_owned();
        for line in text.lines() {
            if let Some((k, v)) = line.split_once('=') {
                let k = k.trim();
                if !k.is_empty() {
                    self.header
                        .entries
                        .push((k.to_string(), v.trim().to_string()));
                }
            }
        }
        self.start += total;
        Ok(())
    }

    /// A header frame that fails its checks. A bad card sector can corrupt bytes anywhere
    /// (rig.md), the header's among them, and one flipped bit there must not cost the run: the
    /// frame's keys cannot be trusted, so rig.md's defaults hold (as for a key absent from an
    /// old capture; the rates are checked against the stamps as always, [`SdReader::probe_rate`]),
    /// a warning says so, and the reader resynchronises from byte 0 on the next valid frame,
    /// counting the header's bytes among those it dropped. Where the damaged frame still reads a
    /// value other than the default for a key the reading depends on, the warning quotes it, for
    /// the experimenter to check against the rig.
    fn header_lost(&mut self, at: u64, why: &str, text: Option<&str>) {
        // The values an empty header falls back to: `Header`'s own accessors, the one source.
        let empty = Header::new();
        let defaults = [
            ("encoder_cpr", f64::from(empty.encoder_cpr())),
            ("accel_lsb_per_g", empty.accel_lsb_per_g()),
            ("encoder_hz", empty.encoder_hz()),
            ("accel_hz", empty.accel_hz()),
        ];
        let listed: Vec<String> = defaults.iter().map(|(k, v)| format!("{k} {v}")).collect();
        let mut msg = format!(
            "header frame damaged (byte {at}: {why}): its keys are not used and the defaults hold \
             ({}; the rates are checked against the stamps)",
            listed.join(", ")
        );
        for line in text.unwrap_or_default().lines() {
            let Some((k, v)) = line.split_once('=') else {
                continue;
            };
            let (k, v) = (k.trim(), v.trim());
            if let Some((_, d)) = defaults.iter().find(|(key, _)| *key == k) {
                if v.parse::<f64>().ok() != Some(*d) {
                    msg.push_str(&format!("; the damaged frame reads {k}={v}: check it"));
                }
            }
        }
        self.stats.warn(msg);
    }

    /// Makes at least `k` bytes available if the file has them; returns how many are.
    fn fill(&mut self, k: usize) -> Result<usize, RigError> {
        while self.buf.len() - self.start < k && !self.eof {
            if self.start > 0 {
                self.buf.drain(..self.start);
                self.buf_offset += self.start as u64;
                self.start = 0;
            }
            let old = self.buf.len();
            self.buf.resize(old + READ_CHUNK, 0);
            let got = self.inner.read(&mut self.buf[old..]);
            match got {
                Ok(0) => {
                    self.buf.truncate(old);
                    self.eof = true;
                }
                Ok(n) => self.buf.truncate(old + n),
                Err(e) if e.kind() == io::ErrorKind::Interrupted => self.buf.truncate(old),
                Err(e) => {
                    self.buf.truncate(old);
                    return Err(RigError::io(&self.path, e));
                }
            }
        }
        Ok(self.buf.len() - self.start)
    }

    fn pos(&self) -> u64 {
        self.buf_offset + self.start as u64
    }

    fn drop_bytes(&mut self, n: usize, reason: &'static str) {
        let pos = self.pos();
        let run = self.dropping.get_or_insert(DropRun {
            start: pos,
            len: 0,
            reason,
        });
        run.len += n as u64;
        self.start += n;
    }

    /// A frame cut by the end of the file may start here.
    fn mark_tail(&mut self) {
        if self.tail_start.is_none() {
            self.tail_start = Some(self.pos());
        }
    }

    fn flush_drop(&mut self) {
        if let Some(run) = self.dropping.take() {
            let reason = format!("{} bytes dropped ({})", run.len, run.reason);
            self.stats.skip(Location::Byte(run.start), reason, run.len);
        }
    }

    /// At the end of the file: bytes from a cut last frame are the truncated tail, anything
    /// dropped before them is a skip.
    fn finish_tail(&mut self) {
        if self.finished {
            return;
        }
        self.finished = true;
        let end = self.pos();
        if let Some(t) = self.tail_start.take() {
            self.stats.truncated_tail_bytes = end.saturating_sub(t);
            if let Some(run) = self.dropping.as_mut() {
                run.len = t.saturating_sub(run.start);
                if run.len == 0 {
                    self.dropping = None;
                }
            }
        }
        self.flush_drop();
    }

    /// The next frame that passes sync, type/length and CRC checks.
    fn next_frame(&mut self) -> Result<Option<Frame>, RigError> {
        loop {
            let avail = self.fill(2)?;
            if avail == 0 {
                self.finish_tail();
                return Ok(None);
            }
            let s = self.start;
            if self.buf[s] != SYNC[0] {
                let run = self.buf[s..]
                    .iter()
                    .position(|&b| b == SYNC[0])
                    .unwrap_or(avail);
                self.drop_bytes(run.max(1), "no sync");
                continue;
            }
            if avail < 2 {
                self.mark_tail();
                self.drop_bytes(1, "cut short");
                continue;
            }
            if self.buf[s + 1] != SYNC[1] {
                self.drop_bytes(1, "no sync");
                continue;
            }
            if self.fill(4)? < 4 {
                self.mark_tail();
                self.drop_bytes(1, "cut short");
                continue;
            }
            let s = self.start;
            let (kind, n) = (self.buf[s + 2], self.buf[s + 3]);
            if !valid_kind_len(kind, n) {
                self.drop_bytes(1, "bad frame type or length");
                continue;
            }
            let total = FRAME_OVERHEAD + usize::from(n);
            let avail = self.fill(total + 2)?;
            if avail < total {
                self.mark_tail();
                self.drop_bytes(1, "cut short");
                continue;
            }
            let s = self.start;
            let f = &self.buf[s..s + total];
            if crc8(&f[2..total - 1]) != f[total - 1] {
                self.drop_bytes(1, "bad CRC");
                continue;
            }
            let after = &self.buf[s + total..s + avail.min(total + 2)];
            let suspect = match after.len() {
                0 => Suspect::AtEnd,
                1 if after[0] != SYNC[0] => Suspect::OffGrid,
                n if n >= 2 && after[..2] != SYNC => Suspect::OffGrid,
                _ => Suspect::No,
            };
            let t_us = u32::from_le_bytes([f[4], f[5], f[6], f[7]]);
            let mut payload = [0u8; 6];
            if kind != FRAME_HEADER {
                payload[..usize::from(n)].copy_from_slice(&f[8..8 + usize::from(n)]);
            }
            self.tail_start = None;
            self.flush_drop();
            let frame = Frame {
                offset: self.pos(),
                kind,
                len: total as u64,
                t_us,
                payload,
                suspect,
            };
            self.start += total;
            return Ok(Some(frame));
        }
    }

    /// The next encoder or accelerometer frame; header frames after the first are skipped.
    fn next_data_frame(&mut self) -> Result<Option<Frame>, RigError> {
        loop {
            match self.next_frame()? {
                Some(f) if f.kind == FRAME_HEADER => {
                    self.stats.skip(
                        Location::Byte(f.offset),
                        "header frame after the start of the file ignored",
                        f.len,
                    );
                }
                Some(f) if self.plan.covering(Location::Byte(f.offset)).is_some() => {
                    let at = Location::Byte(f.offset);
                    let reason = self
                        .plan
                        .covering(at)
                        .map(|b| TimelinePlan::reason(b, f.t_us))
                        .unwrap_or_default();
                    self.stats.off_timeline += 1;
                    self.recent.push_dropped(&f);
                    self.stats
                        .skip(at, format!("frame with valid CRC dropped: {reason}"), f.len);
                }
                other => return Ok(other),
            }
        }
    }

    /// Plausibility of a suspect frame next to the last kept sample of its stream (the same
    /// bounds as [`SdReader::implausible`], without the followers' vote).
    fn plausible(&self, f: &Frame, t_us: u64) -> bool {
        if f.suspect == Suspect::No {
            return true;
        }
        let alone = f.suspect == Suspect::AtEnd;
        if f.kind == FRAME_ENCODER {
            match self.last_enc {
                None => alone,
                Some((t0, c0)) => encoder_step_plausible(
                    i64::from(f.i16_at(0).wrapping_sub(c0)),
                    i64::try_from(t_us.saturating_sub(t0)).unwrap_or(i64::MAX),
                    self.cpr,
                ),
            }
        } else {
            match self.last_acc {
                None => alone,
                Some((t0, a0)) => accel_step_plausible(
                    a0,
                    f.accel(),
                    i64::try_from(t_us.saturating_sub(t0)).unwrap_or(i64::MAX),
                    self.lsb_per_g,
                    self.opts.g_m_s2,
                ),
            }
        }
    }

    /// Why a frame whose time is accepted still cannot be believed: its value moved further
    /// than the pendulum (encoder) or the shaker (accelerometer) can since the last kept frame
    /// of its stream, while the stream's next frames side with that one ([`value_glitch`], the
    /// serial reader's rule). `fresh`: the frame starts a new segment.
    fn implausible(&mut self, cand: &Frame, fresh: bool) -> Result<Option<String>, RigError> {
        let (cpr, lsb, g) = (self.cpr, self.lsb_per_g, self.opts.g_m_s2);
        let enc_ok = |a: (u32, i16), b: (u32, i16)| {
            encoder_step_plausible(i64::from(b.1.wrapping_sub(a.1)), signed_step(a.0, b.0), cpr)
        };
        let acc_ok = |a: (u32, [i16; 3]), b: (u32, [i16; 3])| {
            accel_step_plausible(a.1, b.1, signed_step(a.0, b.0), lsb, g)
        };
        let direct_ok = if cand.kind == FRAME_ENCODER {
            self.last_enc_raw
                .is_none_or(|p| fresh || enc_ok(p, (cand.t_us, cand.i16_at(0))))
        } else {
            self.last_acc_raw
                .is_none_or(|p| fresh || acc_ok(p, (cand.t_us, cand.accel())))
        };
        if direct_ok {
            return Ok(None);
        }
        // The stream's next frames vote.
        let mut ahead = std::mem::take(&mut self.lookahead);
        let filled = ahead.fill_to(VALUE_WINDOW, || self.next_data_frame());
        self.lookahead = ahead;
        filled?;
        let same = self
            .lookahead
            .iter()
            .filter(|f| f.kind == cand.kind)
            .take(CONFIRM_RECORDS);
        if cand.kind == FRAME_ENCODER {
            let next: Vec<(u32, i16)> = same.map(|f| (f.t_us, f.i16_at(0))).collect();
            let c = (cand.t_us, cand.i16_at(0));
            if value_glitch(self.last_enc_raw, c, &next, enc_ok) {
                let p = self.last_enc_raw.unwrap_or(c);
                return Ok(Some(format!(
                    "encoder value {} moves faster than the pendulum can ({} counts in {} µs): a glitch",
                    c.1,
                    i64::from(c.1.wrapping_sub(p.1)),
                    signed_step(p.0, c.0)
                )));
            }
        } else {
            let next: Vec<(u32, [i16; 3])> = same.map(|f| (f.t_us, f.accel())).collect();
            let c = (cand.t_us, cand.accel());
            if value_glitch(self.last_acc_raw, c, &next, acc_ok) {
                return Ok(Some(format!(
                    "accelerometer values {:?} change faster than the shaker can: a glitch",
                    c.1
                )));
            }
        }
        Ok(None)
    }

    /// The next sample, in file order. Errors only on I/O failure; damage is skipped and
    /// counted in [`Self::stats`].
    pub fn next_sample(&mut self) -> Result<Option<Sample>, RigError> {
        if !self.probed {
            self.probe_rate()?;
        }
        loop {
            // Taken out while it reads, so that the reader can borrow itself.
            let mut ahead = std::mem::take(&mut self.lookahead);
            let mut filled = ahead.fill(|| self.next_data_frame());
            if filled.is_ok() && ahead.front_jumps(self.clock.last_raw(), self.order) {
                filled = ahead.fill_to(TIMELINE_WINDOW, || self.next_data_frame());
            }
            self.lookahead = ahead;
            filled?;
            let Some((cand, verdict)) =
                self.lookahead
                    .pop_judged(self.clock.last_raw(), self.order, &self.recent)
            else {
                return Ok(None);
            };
            let at = Location::Byte(cand.offset);
            let segment = match verdict {
                Timeline::Keep => None,
                Timeline::NewSegment { reset } => Some(reset),
                Timeline::Drop {
                    reason,
                    off_timeline,
                    duplicate,
                } => {
                    let reason = if off_timeline {
                        self.stats.off_timeline += 1;
                        self.stats.duplicates += u64::from(duplicate);
                        if !duplicate {
                            self.recent.push_dropped(&cand);
                        }
                        format!("frame with valid CRC dropped: {reason}")
                    } else {
                        format!(
                            "frame with valid CRC dropped: {reason} (t_us={})",
                            cand.t_us
                        )
                    };
                    self.stats.skip(at, reason, cand.len);
                    continue;
                }
            };
            let t_us = match segment {
                Some(reset) => {
                    self.clock
                        .reanchor_t(cand.t_us, reset, self.encoder_period_us.round() as u64)
                }
                None => match self.clock.peek(cand.t_us) {
                    Some(t) => t,
                    None => {
                        self.stats
                            .skip(at, "time before the capture start", cand.len);
                        continue;
                    }
                },
            };
            let (stream_last, name) = if cand.kind == FRAME_ENCODER {
                (self.enc_gaps.last_t(), "encoder")
            } else {
                (self.acc_gaps.last_t(), "accel")
            };
            if segment.is_none() && stream_last.is_some_and(|last| t_us <= last) {
                let reason = format!("time goes backwards in the {name} stream: garbled");
                self.stats.skip(at, reason, cand.len);
                continue;
            }
            if !self.plausible(&cand, t_us) {
                let reason = format!(
                    "frame with valid CRC but off the frame grid and implausible {name} value"
                );
                self.stats.skip(at, reason, cand.len);
                continue;
            }
            if let Some(why) = self.implausible(&cand, segment.is_some())? {
                self.stats.implausible += 1;
                self.stats
                    .skip(at, format!("frame with valid CRC dropped: {why}"), cand.len);
                continue;
            }
            let jumped = segment.is_some()
                || self.clock.last_raw().is_some_and(|p| {
                    let s = signed_step(p, cand.t_us);
                    s < self.order.min_step_us || s > self.order.max_lone_step_us
                });
            self.segments.kept(at, cand.t_us, jumped);
            match segment {
                Some(reset) => {
                    self.clock.reanchor(cand.t_us, t_us);
                    self.start_segment(at, cand.t_us, t_us, reset);
                }
                None => self.clock.commit(cand.t_us, t_us, &mut self.stats),
            }
            self.stats.kept_bytes += cand.len;
            if self.recent.push_kept(&cand) {
                // A copy seen before its original (dropped off the timeline) was a duplicate.
                self.stats.duplicates += 1;
            }
            if cand.kind == FRAME_ENCODER {
                let count_raw = cand.i16_at(0);
                self.enc_gaps.step(t_us, &mut self.stats);
                let count = self.counter.step(count_raw, &mut self.stats);
                self.last_enc = Some((t_us, count_raw));
                self.last_enc_raw = Some((cand.t_us, count_raw));
                self.stats.kept_encoder(t_us);
                return Ok(Some(Sample::Encoder(EncoderSample {
                    t_us_raw: cand.t_us,
                    t_us,
                    count_raw,
                    count,
                    theta_rad: theta_rad(count, self.cpr),
                })));
            }
            let raw = cand.accel();
            self.acc_gaps.step(t_us, &mut self.stats);
            self.last_acc = Some((t_us, raw));
            self.last_acc_raw = Some((cand.t_us, raw));
            self.stats.accel_samples += 1;
            return Ok(Some(Sample::Accel(AccelSample {
                t_us_raw: cand.t_us,
                t_us,
                raw,
                si_m_s2: accel_si(raw, self.lsb_per_g, self.opts.g_m_s2),
            })));
        }
    }

    /// Bookkeeping of a new segment (see [`Timeline::NewSegment`]): both streams start afresh.
    fn start_segment(&mut self, at: Location, raw: u32, t_us: u64, reset: bool) {
        self.stats.new_segments += 1;
        self.recent.clear();
        self.last_enc = None;
        self.last_acc = None;
        self.last_enc_raw = None;
        self.last_acc_raw = None;
        if reset {
            self.counter.restart();
            self.stats.warn(format!(
                "{at}: the board clock restarted (t_us={raw}; a board reset): new segment from unwrapped t_us {t_us}; the encoder count restarts at the board's power-on zero"
            ));
        } else {
            self.stats.warn(format!(
                "{at}: the clock moved back for good (t_us={raw}): new segment from unwrapped t_us {t_us}"
            ));
        }
    }
}

/// Writes an SD capture as the `sd-v2` firmware does (used by the twin and by tests).
pub struct SdWriter<W: Write> {
    w: W,
}

impl<W: Write> SdWriter<W> {
    /// Writes the header frame (`key=value\n` lines, stamped t_us = 0). Fails with
    /// `InvalidInput` if the header text does not fit in one frame (255 bytes).
    pub fn new(mut w: W, header: &Header) -> io::Result<Self> {
        let mut text = String::new();
        for (k, v) in &header.entries {
            let k: String = k
                .chars()
                .map(|c| if c == '=' || c.is_control() { '_' } else { c })
                .collect();
            let v: String = v
                .chars()
                .map(|c| if c.is_control() { ' ' } else { c })
                .collect();
            text.push_str(&format!("{k}={v}\n"));
        }
        if text.len() > 255 {
            return Err(io::Error::new(
                io::ErrorKind::InvalidInput,
                format!("sd-v2 header text is {} bytes, at most 255 fit", text.len()),
            ));
        }
        w.write_all(&encode_frame(FRAME_HEADER, 0, text.as_bytes()))?;
        Ok(Self { w })
    }

    pub fn write_encoder(&mut self, t_us_raw: u32, count_raw: i16) -> io::Result<()> {
        self.w.write_all(&encode_frame(
            FRAME_ENCODER,
            t_us_raw,
            &count_raw.to_le_bytes(),
        ))
    }

    pub fn write_accel(&mut self, t_us_raw: u32, raw: [i16; 3]) -> io::Result<()> {
        let mut p = [0u8; 6];
        for (i, v) in raw.iter().enumerate() {
            p[2 * i..2 * i + 2].copy_from_slice(&v.to_le_bytes());
        }
        self.w.write_all(&encode_frame(FRAME_ACCEL, t_us_raw, &p))
    }

    /// Writes bytes verbatim: for injecting damage.
    pub fn write_raw(&mut self, bytes: &[u8]) -> io::Result<()> {
        self.w.write_all(bytes)
    }

    /// Flushes and returns the inner writer.
    pub fn finish(mut self) -> io::Result<W> {
        self.w.flush()?;
        Ok(self.w)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn capture() -> Vec<u8> {
        let mut w = SdWriter::new(Vec::new(), &Header::sd_v2()).unwrap();
        for i in 0..20u32 {
            w.write_encoder(1000 * i, i as i16).unwrap();
            if i % 5 == 0 {
                w.write_accel(1000 * i, [1, 2, 8192]).unwrap();
            }
        }
        w.finish().unwrap()
    }

    fn read_all(bytes: &[u8]) -> (Vec<Sample>, IngestStats) {
        let mut r = SdReader::new(bytes, "t.bin", ReadOptions::default()).unwrap();
        let mut v = Vec::new();
        while let Some(s) = r.next_sample().unwrap() {
            v.push(s);
        }
        (v, r.stats().clone())
    }

    #[test]
    fn frame_layout() {
        let f = encode_frame(FRAME_ENCODER, 0x0403_0201, &[0xFF, 0x7F]);
        assert_eq!(&f[..8], &[0xA5, 0x5A, 1, 2, 1, 2, 3, 4]);
        assert_eq!(&f[8..10], &[0xFF, 0x7F]);
        assert_eq!(f[10], crc8(&f[2..10]));
    }

    #[test]
    fn reads_back() {
        let (v, st) = read_all(&capture());
        assert_eq!(v.len(), 24);
        assert_eq!(st.encoder_samples, 20);
        assert_eq!(st.accel_samples, 4);
        assert_eq!(st.skipped_lines_or_frames, 0);
        assert_eq!(st.gap_count, 0);
    }

    #[test]
    fn truncated_tail_is_counted() {
        let bytes = capture();
        let cut = &bytes[..bytes.len() - 4];
        let (v, st) = read_all(cut);
        assert_eq!(v.len(), 23);
        assert_eq!(st.truncated_tail_bytes, 11 - 4);
        assert_eq!(st.skipped_bytes, 0);
    }

    /// A bad card sector can corrupt bytes anywhere (rig.md), the header frame's among them: a
    /// bit flipped in its text, its length or its type costs the header (the defaults hold, a
    /// warning says so), never the run. A twin campaign's capture with one flipped bit in its
    /// 150-byte header frame (its `accel_hz=200` read 208) used to fail with "header frame CRC
    /// mismatch".
    #[test]
    fn a_damaged_header_frame_costs_its_keys_not_the_run() {
        let clean = capture();
        let header_len = FRAME_OVERHEAD + usize::from(clean[3]);
        for (at, bit) in [(12, 0), (header_len - 3, 5), (3, 0), (2, 2)] {
            let mut bytes = clean.clone();
            bytes[at] ^= 1 << bit;
            let (v, st) = read_all(&bytes);
            assert_eq!(v.len(), 24, "byte {at}: every data frame is kept");
            assert!(
                st.warnings
                    .iter()
                    .any(|w| w.contains("header frame damaged")),
                "byte {at}: {:?}",
                st.warnings
            );
            assert!(
                st.skipped_bytes >= header_len as u64 - 1,
                "byte {at}: the header's bytes are counted as dropped ({})",
                st.skipped_bytes
            );
        }
    }

    /// The warning quotes a key the reading depends on whose damaged value is not the default.
    #[test]
    fn a_damaged_header_that_reads_another_resolution_says_so() {
        let mut w =
            SdWriter::new(Vec::new(), &Header::sd_v2().with("encoder_cpr", "2048")).unwrap();
        w.write_encoder(0, 0).unwrap();
        w.write_encoder(1000, 1).unwrap();
        let mut bytes = w.finish().unwrap();
        let text_end = FRAME_OVERHEAD + usize::from(bytes[3]) - 1;
        bytes[text_end - 1] ^= 1;
        let (_, st) = read_all(&bytes);
        assert!(
            st.warnings.iter().any(|w| w.contains("encoder_cpr=2048")),
            "{:?}",
            st.warnings
        );
    }

    #[test]
    fn not_a_capture_names_path_and_offset() {
        let e = SdReader::new(&b"\xA5\x5A\x01\x02"[..], "z.bin", ReadOptions::default())
            .err()
            .unwrap()
            .to_string();
        assert!(e.contains("z.bin") && e.contains("byte 2"), "{e}");
    }
}
