//! The serial text capture (`*.csv`, firmware `serial-v1`): reader and writer.
//!
//! The reader streams line by line with a bounded line buffer, so memory does not grow with the
//! file (nor with a "line" of binary garbage that never ends).

use crate::lines::{read_bounded_line, LineInfo};
use std::io::{self, BufRead, Write};
use std::path::{Path, PathBuf};

use crate::capture::{
    accel_si, accel_step_plausible, check_rate, encoder_step_plausible, signed_step, snippet,
    theta_rad, value_glitch, AccelSample, Clock, Counter, EncoderSample, GapTracker, Header,
    IngestStats, Location, Lookahead, OrderRule, ReadOptions, Recent, Record, Sample, SegmentLog,
    Timeline, TimelinePlan, CONFIRM_RECORDS, RATE_PROBE_RECORDS, TIMELINE_WINDOW,
};
use crate::error::RigError;

/// The column line that ends the header.
pub const COLUMN_LINE: &str = "t_us,enc,ax,ay,az";

/// Longer lines are garbage: a real sample line is at most ~40 bytes.
const MAX_LINE_BYTES: usize = 1024;

/// A header (the `#` lines before the column line) longer than this is refused: the firmware's
/// is about 150 bytes; 64 KiB leaves room for any notes and keeps a damaged or hostile file
/// (19 MB of `#` lines used to be read into memory, 94 MB) from growing memory.
pub const MAX_HEADER_BYTES: u64 = 64 * 1024;

/// A syntactically valid data line, not yet accepted.
struct Row {
    line: u64,
    bytes: u64,
    t_us: u32,
    enc: i16,
    accel: [i16; 3],
}

impl Record for Row {
    fn t_raw(&self) -> u32 {
        self.t_us
    }

    fn at(&self) -> Location {
        Location::Line(self.line)
    }

    fn fingerprint(&self) -> u64 {
        let v = [self.enc, self.accel[0], self.accel[1], self.accel[2]];
        v.iter()
            .fold(0u64, |acc, &x| (acc << 16) | u64::from(x as u16))
    }
}

/// Streaming reader of a serial capture.
pub struct SerialReader<R: BufRead> {
    reader: R,
    path: PathBuf,
    opts: ReadOptions,
    header: Header,
    cpr: u32,
    lsb_per_g: f64,
    order: OrderRule,
    line_no: u64,
    /// Bytes read so far (where the next line starts).
    byte_pos: u64,
    line: Vec<u8>,
    lookahead: Lookahead<Row>,
    /// The rate was checked against the first records ([`SerialReader::probe_rate`]).
    probed: bool,
    period_us: f64,
    recent: Recent,
    /// Where the clock jumped between kept lines, for [`SerialReader::timeline_plan`].
    segments: SegmentLog,
    /// Blocks an earlier reading found off the timeline: dropped as they are read.
    plan: TimelinePlan,
    /// The last kept line's raw time and values, for the plausibility of the next.
    last_row: Option<(u32, i16, [i16; 3])>,
    pending_accel: Option<AccelSample>,
    clock: Clock,
    counter: Counter,
    gaps: GapTracker,
    stats: IngestStats,
}

impl<R: BufRead> SerialReader<R> {
    /// Reads the `#` header and the column line. `path` is only used in messages.
    pub fn new(reader: R, path: impl AsRef<Path>, opts: ReadOptions) -> Result<Self, RigError> {
        let path = path.as_ref().to_path_buf();
        let mut me = Self {
            reader,
            path,
            opts,
            header: Header::new(),
            cpr: 0,
            lsb_per_g: 0.0,
            order: OrderRule {
                min_step_us: 1,
                period_us: 5000,
                max_lone_step_us: 15_000,
            },
            line_no: 0,
            byte_pos: 0,
            line: Vec::with_capacity(128),
            lookahead: Lookahead::default(),
            probed: false,
            period_us: 5000.0,
            recent: Recent::default(),
            segments: SegmentLog::default(),
            plan: TimelinePlan::default(),
            last_row: None,
            pending_accel: None,
            clock: Clock::default(),
            counter: Counter::default(),
            gaps: GapTracker::new("serial", 1.0, 1.0),
            stats: IngestStats::default(),
        };
        me.read_header()?;
        me.header.validate(&me.path)?;
        me.cpr = me.header.encoder_cpr();
        me.lsb_per_g = me.header.accel_lsb_per_g();
        me.gaps = GapTracker::new("serial", me.header.sample_hz(), opts.gap_factor);
        me.set_period(1e6 / me.header.sample_hz());
        Ok(me)
    }

    fn set_period(&mut self, period_us: f64) {
        self.period_us = period_us;
        self.gaps.set_period_us(period_us);
        self.stats.encoder_period_us = period_us.round() as u64;
        self.order = OrderRule {
            min_step_us: 1,
            period_us: period_us.round() as i64,
            max_lone_step_us: (self.opts.gap_factor.max(1.0) * period_us).round() as i64,
        };
    }

    /// Reads the first [`RATE_PROBE_RECORDS`] lines ahead and checks the header's `sample_hz`
    /// against their median step ([`check_rate`]): when they disagree, the stamps win (a wrong
    /// header rate used to make every step look like a jump and drop the whole run).
    fn probe_rate(&mut self) -> Result<(), RigError> {
        self.probed = true;
        let mut ahead = std::mem::take(&mut self.lookahead);
        let filled = ahead.fill_to(RATE_PROBE_RECORDS, || self.next_row());
        self.lookahead = ahead;
        filled?;
        let t: Vec<u32> = self.lookahead.iter().map(|r| r.t_us).collect();
        let steps = t.windows(2).map(|w| signed_step(w[0], w[1])).collect();
        let rc = check_rate("sample_hz", self.header.sample_hz(), steps, "line");
        if let Some(w) = rc.warning {
            self.stats.warn(w);
            self.set_period(rc.period_us);
        }
        Ok(())
    }

    /// Why a line whose time is accepted still cannot be believed: an encoder or accelerometer
    /// value that moved further than the pendulum or the shaker can since the last kept line,
    /// while the next lines side with that one ([`value_glitch`]). `fresh`: the line starts a
    /// new segment (nothing to compare with).
    fn implausible(&self, cand: &Row, fresh: bool) -> Option<String> {
        let prev = if fresh { None } else { self.last_row };
        let next: Vec<&Row> = self.lookahead.iter().take(CONFIRM_RECORDS).collect();
        let cpr = self.cpr;
        let enc_ok = |a: (u32, i16), b: (u32, i16)| {
            encoder_step_plausible(i64::from(b.1.wrapping_sub(a.1)), signed_step(a.0, b.0), cpr)
        };
        let enc_next: Vec<(u32, i16)> = next.iter().map(|r| (r.t_us, r.enc)).collect();
        if value_glitch(
            prev.map(|p| (p.0, p.1)),
            (cand.t_us, cand.enc),
            &enc_next,
            enc_ok,
        ) {
            let from = prev.map_or(String::new(), |p| {
                format!(
                    " ({} counts in {} µs)",
                    i64::from(cand.enc.wrapping_sub(p.1)),
                    signed_step(p.0, cand.t_us)
                )
            });
            return Some(format!(
                "encoder value {} moves faster than the pendulum can{from}: a glitch",
                cand.enc
            ));
        }
        let (lsb, g) = (self.lsb_per_g, self.opts.g_m_s2);
        let acc_ok = |a: (u32, [i16; 3]), b: (u32, [i16; 3])| {
            accel_step_plausible(a.1, b.1, signed_step(a.0, b.0), lsb, g)
        };
        let acc_next: Vec<(u32, [i16; 3])> = next.iter().map(|r| (r.t_us, r.accel)).collect();
        if value_glitch(
            prev.map(|p| (p.0, p.2)),
            (cand.t_us, cand.accel),
            &acc_next,
            acc_ok,
        ) {
            return Some(format!(
                "accelerometer values {:?} change faster than the shaker can: a glitch",
                cand.accel
            ));
        }
        None
    }

    pub fn header(&self) -> &Header {
        &self.header
    }

    pub fn stats(&self) -> &IngestStats {
        &self.stats
    }

    /// Drops the blocks of `plan` (from an earlier reading of the same capture) as they are
    /// read, each with a warning. Call before the first [`SerialReader::next_sample`].
    pub fn set_timeline_plan(&mut self, plan: TimelinePlan) {
        for w in plan.warnings() {
            self.stats.warn(w);
        }
        self.plan = plan;
    }

    /// After the last sample: the blocks this reading kept that the majority of the evidence
    /// puts off the timeline (see [`TimelinePlan`]), or `None` when there are none. Read the
    /// capture again with [`SerialReader::set_timeline_plan`] to drop them.
    pub fn timeline_plan(&self) -> Option<TimelinePlan> {
        self.segments.plan(self.order)
    }

    fn not_a_capture(&self, line: u64, reason: String) -> RigError {
        RigError::NotACapture {
            path: self.path.clone(),
            at: Location::Line(line),
            reason,
        }
    }

    fn read_header(&mut self) -> Result<(), RigError> {
        let mut seen_header = false;
        loop {
            if self.byte_pos > MAX_HEADER_BYTES {
                return Err(self.not_a_capture(
                    self.line_no,
                    format!(
                        "the header runs past {MAX_HEADER_BYTES} bytes (line {}, byte {}) without \
                         the column line `{COLUMN_LINE}`: a capture's header is a few hundred bytes",
                        self.line_no, self.byte_pos
                    ),
                ));
            }
            let Some(info) = self.read_line()? else {
                let reason = if seen_header {
                    format!("the file ends before the column line `{COLUMN_LINE}`")
                } else {
                    "the file is empty".to_string()
                };
                return Err(self.not_a_capture(self.line_no.max(1), reason));
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
            let text = String::from_utf8_lossy(content);
            let text = text.trim();
            if text.is_empty() {
                continue;
            }
            if let Some(rest) = text.strip_prefix('#') {
                seen_header = true;
                // A `#` line without `=` is a comment.
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
            let columns: String = text.chars().filter(|c| !c.is_whitespace()).collect();
            if columns == COLUMN_LINE {
                return Ok(());
            }
            let reason = if seen_header {
                format!(
                    "expected the column line `{COLUMN_LINE}` after the header, found {}",
                    snippet(text.as_bytes())
                )
            } else {
                format!(
                    "expected a `#` header line or the column line `{COLUMN_LINE}`, found {}",
                    snippet(text.as_bytes())
                )
            };
            return Err(self.not_a_capture(info.number, reason));
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

    /// The next syntactically valid data line; damaged ones are recorded and skipped.
    fn next_row(&mut self) -> Result<Option<Row>, RigError> {
        loop {
            let Some(info) = self.read_line()? else {
                return Ok(None);
            };
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
            // Blank lines (a terminal program's doing) carry nothing: ignored, not counted.
            if self.line.iter().all(|b| b.is_ascii_whitespace()) {
                continue;
            }
            if !info.terminated {
                // Every line the firmware sends ends with `\n`: without it the line may have
                // been cut inside its last field, which would still parse.
                let reason = format!(
                    "last line has no line end (cut short): {}",
                    snippet(&self.line)
                );
                self.stats
                    .skip(Location::Line(info.number), reason, info.bytes);
                continue;
            }
            match parse_row(&self.line) {
                Ok((t_us, enc, accel)) => {
                    let row = Row {
                        line: info.number,
                        bytes: info.bytes,
                        t_us,
                        enc,
                        accel,
                    };
                    let at = Location::Line(info.number);
                    if let Some(b) = self.plan.covering(at) {
                        let reason = format!("{}: dropped", TimelinePlan::reason(b, t_us));
                        self.stats.off_timeline += 1;
                        self.recent.push_dropped(&row);
                        self.stats.skip(at, reason, info.bytes);
                        continue;
                    }
                    return Ok(Some(row));
                }
                Err(why) => {
                    let reason = format!("{why}: {}", snippet(&self.line));
                    self.stats
                        .skip(Location::Line(info.number), reason, info.bytes);
                }
            }
        }
    }

    /// The next sample: for each good line its encoder sample, then its accelerometer sample.
    /// Errors only on I/O failure; damaged lines are skipped and counted in [`Self::stats`].
    pub fn next_sample(&mut self) -> Result<Option<Sample>, RigError> {
        if let Some(a) = self.pending_accel.take() {
            return Ok(Some(Sample::Accel(a)));
        }
        if !self.probed {
            self.probe_rate()?;
        }
        loop {
            // Taken out while it reads, so that the reader can borrow itself.
            let mut ahead = std::mem::take(&mut self.lookahead);
            let mut filled = ahead.fill(|| self.next_row());
            if filled.is_ok() && ahead.front_jumps(self.clock.last_raw(), self.order) {
                filled = ahead.fill_to(TIMELINE_WINDOW, || self.next_row());
            }
            self.lookahead = ahead;
            filled?;
            let Some((cand, verdict)) =
                self.lookahead
                    .pop_judged(self.clock.last_raw(), self.order, &self.recent)
            else {
                return Ok(None);
            };
            let at = Location::Line(cand.line);
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
                        format!("{reason}: dropped")
                    } else {
                        format!("{reason} (t_us={}): garbled", cand.t_us)
                    };
                    self.stats.skip(at, reason, cand.bytes);
                    continue;
                }
            };
            let t_us = match segment {
                Some(reset) => {
                    self.clock
                        .reanchor_t(cand.t_us, reset, self.period_us.round() as u64)
                }
                None => match self.clock.peek(cand.t_us) {
                    Some(t) => t,
                    None => {
                        self.stats
                            .skip(at, "time before the capture start", cand.bytes);
                        continue;
                    }
                },
            };
            if let Some(why) = self.implausible(&cand, segment.is_some()) {
                self.stats.implausible += 1;
                self.stats.skip(at, format!("{why}: dropped"), cand.bytes);
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
            self.gaps.step(t_us, &mut self.stats);
            let count = self.counter.step(cand.enc, &mut self.stats);
            self.stats.kept_encoder(t_us);
            self.stats.accel_samples += 1;
            self.stats.kept_bytes += cand.bytes;
            if self.recent.push_kept(&cand) {
                // A copy seen before its original (dropped off the timeline) was a duplicate.
                self.stats.duplicates += 1;
            }
            self.last_row = Some((cand.t_us, cand.enc, cand.accel));
            self.pending_accel = Some(AccelSample {
                t_us_raw: cand.t_us,
                t_us,
                raw: cand.accel,
                si_m_s2: accel_si(cand.accel, self.lsb_per_g, self.opts.g_m_s2),
            });
            return Ok(Some(Sample::Encoder(EncoderSample {
                t_us_raw: cand.t_us,
                t_us,
                count_raw: cand.enc,
                count,
                theta_rad: theta_rad(count, self.cpr),
            })));
        }
    }

    /// Bookkeeping of a new segment (see [`Timeline::NewSegment`]).
    fn start_segment(&mut self, at: Location, raw: u32, t_us: u64, reset: bool) {
        self.stats.new_segments += 1;
        self.recent.clear();
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

/// Parses `t_us,enc,ax,ay,az`. Strict on purpose: anything the firmware would not have written
/// (signs on t, `+`, digits run together beyond the type's range, extra fields) is damage.
fn parse_row(line: &[u8]) -> Result<(u32, i16, [i16; 3]), String> {
    let fields: Vec<&[u8]> = line.split(|&b| b == b',').collect();
    if fields.len() != 5 {
        let hint = if fields.len() > 5 {
            "lines run together?"
        } else {
            "cut short?"
        };
        return Err(format!("{} fields, expected 5 ({hint})", fields.len()));
    }
    let t = parse_int(fields[0], false)
        .filter(|v| *v <= i64::from(u32::MAX))
        .ok_or_else(|| field_error("t_us", "an integer in 0..=4294967295"))?;
    let mut vals = [0i16; 4];
    for (i, name) in ["enc", "ax", "ay", "az"].iter().enumerate() {
        vals[i] = parse_int(fields[i + 1], true)
            .and_then(|v| i16::try_from(v).ok())
            .ok_or_else(|| field_error(name, "an integer in -32768..=32767"))?;
    }
    // `t` was range-checked above.
    let t = u32::try_from(t).map_err(|_| field_error("t_us", "a u32"))?;
    Ok((t, vals[0], [vals[1], vals[2], vals[3]]))
}

fn field_error(name: &str, expected: &str) -> String {
    format!("field `{name}` is not {expected}")
}

/// A decimal integer of at most 10 digits (enough for u32), optional `-` when `signed`.
/// No blanks allowed: the firmware writes none, and a sign garbled into a blank would
/// otherwise turn −12 into 12.
fn parse_int(f: &[u8], signed: bool) -> Option<i64> {
    let (neg, digits) = match f.strip_prefix(b"-") {
        Some(d) if signed => (true, d),
        _ => (false, f),
    };
    if digits.is_empty() || digits.len() > 10 || !digits.iter().all(u8::is_ascii_digit) {
        return None;
    }
    let v = digits
        .iter()
        .fold(0i64, |acc, d| acc * 10 + i64::from(d - b'0'));
    Some(if neg { -v } else { v })
}

/// Writes a serial capture as the `serial-v1` firmware does (used by the twin and by tests).
pub struct SerialWriter<W: Write> {
    w: W,
}

impl<W: Write> SerialWriter<W> {
    /// Writes `# key=value` lines for every header entry, then the column line.
    pub fn new(mut w: W, header: &Header) -> io::Result<Self> {
        for (k, v) in &header.entries {
            let k: String = k
                .chars()
                .map(|c| if c == '=' || c.is_control() { '_' } else { c })
                .collect();
            let v: String = v
                .chars()
                .map(|c| if c.is_control() { ' ' } else { c })
                .collect();
            writeln!(w, "# {k}={v}")?;
        }
        writeln!(w, "{COLUMN_LINE}")?;
        Ok(Self { w })
    }

    pub fn write_sample(&mut self, t_us_raw: u32, enc_raw: i16, raw: [i16; 3]) -> io::Result<()> {
        writeln!(
            self.w,
            "{t_us_raw},{enc_raw},{},{},{}",
            raw[0], raw[1], raw[2]
        )
    }

    /// Writes `s` verbatim (no line end added): for injecting damaged lines.
    pub fn write_raw(&mut self, s: &str) -> io::Result<()> {
        self.w.write_all(s.as_bytes())
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

    #[test]
    fn parses_rows_strictly() {
        assert_eq!(
            parse_row(b"3954112736,-3,41,-12,8237"),
            Ok((3954112736, -3, [41, -12, 8237]))
        );
        assert!(parse_row(b"4294967296,0,0,0,0").is_err());
        assert!(parse_row(b"1,32768,0,0,0").is_err());
        assert!(parse_row(b"-1,0,0,0,0").is_err());
        assert!(parse_row(b"1,0,0,0").is_err());
        assert!(parse_row(b"1,0,0,0,0,2,0,0,0,0").is_err());
        assert!(parse_row(b"1,0,0,x0,0").is_err());
        assert!(parse_row(b"1,0,0,,0").is_err());
        assert!(parse_row(b"1,-,0,0,0").is_err());
        assert!(parse_row(b"1,0,0, 12,0").is_err());
    }

    #[test]
    fn reads_the_spec_example() {
        let text = "# firmware=serial-v1\n# encoder_cpr=4096\n# accel_lsb_per_g=8192\n\
                    # sample_hz=200\n# started=2026-03-14T10:22:05Z\n# operator=ann\n\
                    t_us,enc,ax,ay,az\n3954112736,-3,41,-12,8237\n3954117741,-3,39,-15,8240\n";
        let mut r = SerialReader::new(text.as_bytes(), "x.csv", ReadOptions::default()).unwrap();
        assert_eq!(r.header().get("operator"), Some("ann"));
        assert_eq!(r.header().started(), Some("2026-03-14T10:22:05Z"));
        let mut n = 0;
        while let Some(s) = r.next_sample().unwrap() {
            if let Sample::Accel(a) = s {
                assert!((a.si_m_s2[2] - 9.81).abs() < 0.1);
            }
            n += 1;
        }
        assert_eq!(n, 4);
        assert_eq!(r.stats().encoder_samples, 2);
    }

    #[test]
    fn rejects_non_captures() {
        let e = SerialReader::new(&b"hello\n"[..], "a.txt", ReadOptions::default())
            .err()
            .unwrap()
            .to_string();
        assert!(e.contains("a.txt") && e.contains("line 1"), "{e}");
        let e = SerialReader::new(&b"# a=b\n\nfoo\n"[..], "b.txt", ReadOptions::default())
            .err()
            .unwrap()
            .to_string();
        assert!(e.contains("line 3") && e.contains(COLUMN_LINE), "{e}");
        assert!(SerialReader::new(&b""[..], "c", ReadOptions::default()).is_err());
        // Old captures without a header are fine.
        assert!(
            SerialReader::new(&b"t_us,enc,ax,ay,az\n"[..], "d", ReadOptions::default()).is_ok()
        );
    }
}
