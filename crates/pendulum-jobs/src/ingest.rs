//! `pendulum ingest CAMPAIGN_DIR --out OUT_DIR`: every run's raw capture → one `<run_id>.mcap`,
//! in parallel, streaming (constant memory in the capture's length), atomically.

use std::path::{Path, PathBuf};

use indicatif::{ProgressBar, ProgressStyle};
use pendulum_log::{
    parse_rfc3339_utc_ns, AccelMsg, EncoderMsg, RunLogOptions, METADATA_CAPTURE_HEADER,
    METADATA_RUN,
};
use pendulum_rig::{
    Campaign, CaptureReader, IngestStats, Location, ReadOptions, RunSpec, Sample, TimelinePlan,
};
use rayon::prelude::*;

use crate::inputs::Inputs;
use crate::runs::run_metadata;
use crate::JobError;

/// One run's ingest result.
#[derive(Debug, Clone)]
pub struct IngestRow {
    pub run_id: String,
    pub format: String,
    pub mcap: Option<PathBuf>,
    pub stats: Option<IngestStats>,
    /// Why the run could not be ingested at all.
    pub error: Option<String>,
    pub warnings: Vec<String>,
}

/// All runs' results.
#[derive(Debug, Clone)]
pub struct IngestSummary {
    pub campaign: String,
    pub rows: Vec<IngestRow>,
    /// The campaign's own warnings (a key that looks misspelt), each naming its run.
    pub warnings: Vec<String>,
}

impl IngestSummary {
    /// Runs that could not be ingested at all, or kept almost nothing
    /// ([`IngestStats::failure`]).
    pub fn failed(&self) -> usize {
        self.rows.iter().filter(|r| r.error.is_some()).count()
    }
}

impl std::fmt::Display for IngestSummary {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        // The name comes from campaign.toml: printed with any terminal code escaped.
        writeln!(
            f,
            "campaign {}: {} runs",
            pendulum_rig::names::printable(&self.campaign),
            self.rows.len()
        )?;
        for w in &self.warnings {
            writeln!(f, "warning: {w}")?;
        }
        writeln!(
            f,
            "{:<10} {:<10} {:>9} {:>8} {:>8} {:>8} {:>5} {:>6} {:>6} {:>6}",
            "run",
            "format",
            "encoder",
            "accel",
            "skipped",
            "bytes",
            "gaps",
            "clkwr",
            "encwr",
            "trunc"
        )?;
        for r in &self.rows {
            match (&r.stats, &r.error) {
                (Some(s), None) => writeln!(
                    f,
                    "{:<10} {:<10} {:>9} {:>8} {:>8} {:>8} {:>5} {:>6} {:>6} {:>6}",
                    r.run_id,
                    r.format,
                    s.encoder_samples,
                    s.accel_samples,
                    s.skipped_lines_or_frames,
                    s.skipped_bytes,
                    s.gap_count,
                    s.clock_wraps,
                    s.encoder_wraps,
                    s.truncated_tail_bytes
                )?,
                (_, Some(e)) => writeln!(f, "{:<10} FAILED: {e}", r.run_id)?,
                _ => {}
            }
        }
        for r in &self.rows {
            if let Some(s) = &r.stats {
                for skip in &s.skips {
                    writeln!(f, "  {}: skipped at {}: {}", r.run_id, skip.at, skip.reason)?;
                }
                let more = s
                    .skipped_lines_or_frames
                    .saturating_sub(s.skips.len() as u64);
                if more > 0 {
                    writeln!(f, "  {}: … and {more} more skipped", r.run_id)?;
                }
                for g in s.gaps.iter().take(3) {
                    writeln!(
                        f,
                        "  {}: gap in {} from t_us {} to {} (~{} samples missing)",
                        r.run_id, g.stream, g.after_t_us, g.before_t_us, g.missing_samples_est
                    )?;
                }
            }
            for w in &r.warnings {
                writeln!(f, "  {}: warning: {w}", r.run_id)?;
            }
        }
        Ok(())
    }
}

/// Smallest unwrapped clock value among the first samples (frames of the two SD streams may be
/// slightly out of order), so that every t_s is ≥ 0.
fn first_t_us(
    spec: &RunSpec,
    opts: ReadOptions,
    plan: Option<&TimelinePlan>,
) -> Result<Option<u64>, JobError> {
    let mut r = CaptureReader::open_run_planned(spec, opts, plan)?;
    let mut min: Option<u64> = None;
    for _ in 0..2000 {
        match r.next_sample()? {
            Some(s) => min = Some(min.map_or(s.t_us(), |m| m.min(s.t_us()))),
            None => break,
        }
    }
    Ok(min)
}

/// The `/ingest_stats` message as `schemas/ingest_stats.json` documents it: `skipped` and
/// `gaps` are counts, each skip's `at` is the line number or byte offset (`unit` says which);
/// the kept gaps themselves go in `gap_list`.
fn stats_json(stats: &IngestStats, format: &str) -> serde_json::Value {
    let skips: Vec<serde_json::Value> = stats
        .skips
        .iter()
        .map(|s| {
            let (unit, at) = match s.at {
                Location::Line(n) => ("line", n),
                Location::Byte(n) => ("byte", n),
            };
            serde_json::json!({"at": at, "unit": unit, "reason": s.reason})
        })
        .collect();
    serde_json::json!({
        "format": format,
        "encoder_samples": stats.encoder_samples,
        "accel_samples": stats.accel_samples,
        "skipped": stats.skipped_lines_or_frames,
        "skipped_bytes": stats.skipped_bytes,
        "gaps": stats.gap_count,
        "clock_wraps": stats.clock_wraps,
        "encoder_wraps": stats.encoder_wraps,
        "truncated_tail_bytes": stats.truncated_tail_bytes,
        "off_timeline": stats.off_timeline,
        "duplicates": stats.duplicates,
        "implausible": stats.implausible,
        "new_segments": stats.new_segments,
        "encoder_period_us": stats.encoder_period_us,
        "warnings": stats.warnings,
        "skips": skips,
        "gap_list": serde_json::to_value(&stats.gaps).unwrap_or_default(),
    })
}

/// Rig captures always carry the accelerometer; a generic time series only when the campaign
/// names an acceleration column (no channel at all otherwise, rather than an empty one).
fn has_accelerometer(spec: &RunSpec) -> bool {
    spec.format.as_deref() != Some("timeseries")
        || spec
            .extra
            .keys()
            .any(|k| k.starts_with("accel_") && k.ends_with("_column"))
}

fn ingest_run(c: &Campaign, spec: &RunSpec, out_dir: &Path) -> Result<IngestRow, JobError> {
    let mut plan: Option<TimelinePlan> = None;
    for reading in 1..=pendulum_rig::capture::MAX_READINGS {
        let last = reading == pendulum_rig::capture::MAX_READINGS;
        match ingest_reading(c, spec, out_dir, plan.as_ref(), last)? {
            Reading::Done(row) => return Ok(*row),
            Reading::Again(more) => match &mut plan {
                Some(p) => p.merge(more),
                None => plan = Some(more),
            },
        }
    }
    unreachable!("the last reading is always done")
}

/// One reading of a capture into its MCAP.
enum Reading {
    Done(Box<IngestRow>),
    /// The reading kept blocks off the timeline: its MCAP was discarded (never under the final
    /// name), to be read again dropping them.
    Again(TimelinePlan),
}

fn ingest_reading(
    c: &Campaign,
    spec: &RunSpec,
    out_dir: &Path,
    plan: Option<&TimelinePlan>,
    last: bool,
) -> Result<Reading, JobError> {
    let opts = ReadOptions {
        g_m_s2: c.g_m_s2,
        ..ReadOptions::default()
    };
    let t0 = first_t_us(spec, opts, plan)?.unwrap_or(0);
    let mut reader = CaptureReader::open_run_planned(spec, opts, plan)?;
    let mut warnings = Vec::new();
    // A time base the reader had to rebuild (bursty stamps) is news the user must see, not only
    // a header key in the MCAP.
    if let Some(tb) = reader.header().get("time_base") {
        warnings.push(format!("time base {tb}"));
    }
    let start_ns = match reader.header().started() {
        Some(s) => match parse_rfc3339_utc_ns(s) {
            Ok(ns) => Some(ns),
            Err(e) => {
                warnings.push(format!(
                    "header started={s:?} unreadable ({e}); log times use the board clock"
                ));
                None
            }
        },
        None => None,
    };
    let path = mcap_path(out_dir, spec);
    let mut w = RunLogOptions::new()
        .library(concat!("pendulum/", env!("CARGO_PKG_VERSION")))
        .start_ns(start_ns)
        .accel_channel(has_accelerometer(spec))
        .create(&path)?;
    w.write_metadata(METADATA_RUN, run_metadata(c, spec))?;
    w.write_metadata(
        METADATA_CAPTURE_HEADER,
        reader.header().entries.iter().cloned().collect(),
    )?;
    while let Some(s) = reader.next_sample()? {
        let t_us = s.t_us();
        if t_us < t0 {
            warnings.push(format!(
                "sample at t_us {t_us} precedes the capture's first sample: dropped"
            ));
            continue;
        }
        let t_s = (t_us - t0) as f64 * 1e-6;
        match s {
            Sample::Encoder(e) => w.write_encoder(&EncoderMsg {
                t_s,
                t_us,
                count: e.count,
                count_raw: e.count_raw,
                theta_rad: e.theta_rad,
            })?,
            Sample::Accel(a) => w.write_accel(&AccelMsg {
                t_s,
                t_us,
                ax_raw: a.raw[0],
                ay_raw: a.raw[1],
                az_raw: a.raw[2],
                ax_m_s2: a.si_m_s2[0],
                ay_m_s2: a.si_m_s2[1],
                az_m_s2: a.si_m_s2[2],
            })?,
        }
    }
    if !last {
        if let Some(more) = reader.timeline_plan() {
            // Unfinished: the writer removes its temporary file.
            drop(w);
            return Ok(Reading::Again(more));
        }
    }
    let stats = reader.stats().clone();
    warnings.extend(stats.warnings.iter().cloned());
    if let Some(why) = stats.failure() {
        // Dropped unfinished: the writer removes its temporary file, so no near-empty MCAP
        // takes the final name; the row keeps the stats so that the skips are listed.
        drop(w);
        return Ok(Reading::Done(Box::new(IngestRow {
            run_id: spec.id.clone(),
            format: reader.format().to_string(),
            mcap: None,
            stats: Some(stats),
            error: Some(format!("{}: failed run: {why}", spec.file.display())),
            warnings,
        })));
    }
    w.write_stats(&stats_json(&stats, reader.format()))?;
    let summary = w.finish()?;
    Ok(Reading::Done(Box::new(IngestRow {
        run_id: spec.id.clone(),
        format: reader.format().to_string(),
        mcap: Some(summary.path),
        stats: Some(stats),
        error: None,
        warnings,
    })))
}

/// Where a run's MCAP goes (the id is a safe file name: [`pendulum_rig::names`]).
fn mcap_path(out_dir: &Path, spec: &RunSpec) -> PathBuf {
    out_dir.join(format!("{}.mcap", spec.id))
}

/// Ingests every run of the campaign at `dir` into `out_dir`.
pub fn run(dir: &Path, out_dir: &Path, show_progress: bool) -> Result<IngestSummary, JobError> {
    let c = Campaign::load(dir)?;
    // OUT may be the campaign folder itself: no `<id>.mcap` may replace campaign.toml or a
    // capture. Checked for every run before anything is written.
    let mut inputs = Inputs::new();
    inputs.add_campaign(&c, dir);
    for spec in &c.runs {
        inputs.check_output(
            &format!("the output of run {}", spec.id),
            &mcap_path(out_dir, spec),
        )?;
    }
    crate::outputs::prepare_out_dir(out_dir)?;
    let bar = if show_progress {
        let b = ProgressBar::new(c.runs.len() as u64);
        b.set_style(
            ProgressStyle::with_template("ingest {bar:30} {pos}/{len} runs {msg}")
                .unwrap_or_else(|_| ProgressStyle::default_bar()),
        );
        b
    } else {
        ProgressBar::hidden()
    };
    let rows: Vec<IngestRow> = c
        .runs
        .par_iter()
        .map(|spec| {
            let mut row = if !spec.file.is_file() {
                IngestRow {
                    run_id: spec.id.clone(),
                    format: "-".into(),
                    mcap: None,
                    stats: None,
                    error: Some(format!("{}: capture file not found", spec.file.display())),
                    warnings: Vec::new(),
                }
            } else {
                ingest_run(&c, spec, out_dir).unwrap_or_else(|e| IngestRow {
                    run_id: spec.id.clone(),
                    format: "-".into(),
                    mcap: None,
                    stats: None,
                    error: Some(e.to_string()),
                    warnings: Vec::new(),
                })
            };
            // A failed run's own temporary file is gone (the writer removes it). An `<id>.mcap`
            // already in OUT is not this process's to delete: it may be an earlier ingest's, or
            // another ingest's finishing right now into the same folder. The failure says it is
            // there and stale instead.
            if let Some(e) = &mut row.error {
                let earlier = mcap_path(out_dir, spec);
                if earlier.exists() {
                    e.push_str(&format!(
                        "; {} is NOT from this ingest (left as it was)",
                        earlier.display()
                    ));
                }
            }
            bar.set_message(spec.id.clone());
            bar.inc(1);
            row
        })
        .collect();
    bar.finish_and_clear();
    // Every run in: the folder is complete (the marker is written last; `prepare_out_dir`
    // removed any earlier one). A failed run leaves it without one.
    if rows.iter().all(|r| r.error.is_none()) {
        let files: Vec<PathBuf> = rows.iter().filter_map(|r| r.mcap.clone()).collect();
        crate::outputs::mark_complete(out_dir, "pendulum ingest", &files)?;
    }
    Ok(IngestSummary {
        campaign: c.name.clone(),
        rows,
        warnings: c.warnings.clone(),
    })
}
