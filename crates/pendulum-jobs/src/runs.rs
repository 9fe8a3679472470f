//! Loading runs for the stages: from a campaign folder (raw captures, read on the fly) or from a
//! folder of MCAP files written by `pendulum ingest` (metadata record `run` holds the campaign's
//! description). Either way the stages get the same [`RunData`].

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use pendulum_log::{read_run, RunLog, METADATA_CAPTURE_HEADER, METADATA_RUN};
use pendulum_process::{RigParams, Role, RunData};
use pendulum_rig::{Campaign, CaptureReader, IngestStats, ReadOptions, RunSpec, Sample};

use crate::JobError;

/// A capture read into memory, with what the reader found.
pub struct ReadCapture {
    pub format: &'static str,
    pub header: Vec<(String, String)>,
    pub stats: IngestStats,
    pub samples: Vec<Sample>,
}

/// Reads every sample of a run's capture (streaming reader; the samples are kept).
pub fn read_capture(spec: &RunSpec, g_m_s2: f64) -> Result<ReadCapture, JobError> {
    let opts = ReadOptions {
        g_m_s2,
        ..ReadOptions::default()
    };
    // Read again while a reading finds blocks off the timeline longer than the reader's
    // read-ahead (as `pendulum ingest` does).
    let mut plan: Option<pendulum_rig::TimelinePlan> = None;
    let mut reading = 0;
    let (reader, samples) = loop {
        reading += 1;
        let mut reader = CaptureReader::open_run_planned(spec, opts, plan.as_ref())?;
        let mut samples = Vec::new();
        while let Some(s) = reader.next_sample()? {
            samples.push(s);
        }
        let more = match reader.timeline_plan() {
            Some(more) if reading < pendulum_rig::capture::MAX_READINGS => more,
            _ => break (reader, samples),
        };
        match &mut plan {
            Some(p) => p.merge(more),
            None => plan = Some(more),
        }
    };
    // The rule `pendulum ingest` applies: a run that kept almost nothing is no run to fit.
    if let Some(why) = reader.stats().failure() {
        return Err(JobError::Invalid(format!(
            "{}: run `{}`: failed run: {why}",
            spec.file.display(),
            spec.id
        )));
    }
    for w in &reader.stats().warnings {
        eprintln!("warning: run `{}`: {w}", spec.id);
    }
    Ok(ReadCapture {
        format: reader.format(),
        header: reader.header().entries.clone(),
        stats: reader.stats().clone(),
        samples,
    })
}

/// The campaign's description of a run as flat strings (the MCAP metadata record `run`).
pub fn run_metadata(c: &Campaign, spec: &RunSpec) -> BTreeMap<String, String> {
    let mut m = BTreeMap::new();
    m.insert("campaign".into(), c.name.clone());
    m.insert("id".into(), spec.id.clone());
    m.insert(
        "file".into(),
        spec.file
            .file_name()
            .map(|f| f.to_string_lossy().into_owned())
            .unwrap_or_default(),
    );
    m.insert("role".into(), spec.role.as_str().into());
    m.insert("m_kg".into(), spec.m_kg.to_string());
    m.insert("l_m".into(), spec.l_m.to_string());
    m.insert("crank_r_m".into(), spec.crank_r_m.to_string());
    m.insert("rod_L_m".into(), spec.rod_l_m.to_string());
    m.insert("r_b_m".into(), spec.r_b_m.to_string());
    m.insert("g_m_s2".into(), c.g_m_s2.to_string());
    if let Some(w) = spec.omega_hz {
        m.insert("omega_hz".into(), w.to_string());
    }
    if let Some(f) = &spec.format {
        m.insert("format".into(), f.clone());
    }
    for (k, v) in &spec.extra {
        let text = match v {
            toml::Value::String(s) => s.clone(),
            other => other.to_string(),
        };
        m.insert(k.clone(), text);
    }
    m
}

fn role_of(r: pendulum_rig::Role) -> Role {
    match r {
        pendulum_rig::Role::Identify => Role::Identify,
        pendulum_rig::Role::Validate => Role::Validate,
    }
}

/// Converts a read capture into the stages' run data (times in s from the first sample).
pub fn run_data(c: &Campaign, spec: &RunSpec, cap: &ReadCapture) -> RunData {
    let t_first = cap.samples.iter().map(|s| s.t_us()).min().unwrap_or(0);
    let mut rd = RunData {
        id: spec.id.clone(),
        role: role_of(spec.role),
        rig: RigParams {
            m_kg: spec.m_kg,
            l_m: spec.l_m,
            crank_r_m: spec.crank_r_m,
            rod_l_m: spec.rod_l_m,
            r_b_m: spec.r_b_m,
            omega_hz: spec.omega_hz,
            g_m_s2: c.g_m_s2,
        },
        enc_t_s: Vec::new(),
        theta_rad: Vec::new(),
        acc_t_s: Vec::new(),
        az_m_s2: Vec::new(),
        ax_m_s2: Vec::new(),
    };
    for s in &cap.samples {
        match s {
            Sample::Encoder(e) => {
                rd.enc_t_s.push((e.t_us - t_first) as f64 * 1e-6);
                rd.theta_rad.push(e.theta_rad);
            }
            Sample::Accel(a) => {
                rd.acc_t_s.push((a.t_us - t_first) as f64 * 1e-6);
                rd.ax_m_s2.push(a.si_m_s2[0]);
                rd.az_m_s2.push(a.si_m_s2[2]);
            }
        }
    }
    rd
}

fn meta_f64(m: &BTreeMap<String, String>, key: &str, path: &Path) -> Result<f64, JobError> {
    let v = m.get(key).ok_or_else(|| {
        JobError::Invalid(format!(
            "{}: metadata record `run` lacks key {key}",
            path.display()
        ))
    })?;
    v.parse().map_err(|_| {
        JobError::Invalid(format!(
            "{}: metadata `run.{key}` = {v:?} is not a number",
            path.display()
        ))
    })
}

/// Converts an MCAP run log (written by `pendulum ingest`) into the stages' run data.
pub fn run_data_from_log(log: &RunLog) -> Result<RunData, JobError> {
    let path = &log.path;
    let m = log.metadata.get(METADATA_RUN).ok_or_else(|| {
        JobError::Invalid(format!(
            "{}: no metadata record `run`: not written by pendulum ingest?",
            path.display()
        ))
    })?;
    let role = match m.get("role").map(String::as_str) {
        Some("identify") => Role::Identify,
        Some("validate") => Role::Validate,
        other => {
            return Err(JobError::Invalid(format!(
                "{}: metadata `run.role` = {other:?}: expected identify or validate",
                path.display()
            )))
        }
    };
    // The id names output files (`history_<model>_<id>.png`) and an MCAP may come from anyone:
    // the same rule as a campaign's ids. Without an id, the file's stem (already a name).
    let id = match m.get("id") {
        Some(id) => id.clone(),
        None => path
            .file_stem()
            .map(|s| s.to_string_lossy().into_owned())
            .unwrap_or_default(),
    };
    pendulum_rig::names::check_run_id(&id).map_err(|problem| {
        JobError::Invalid(format!(
            "{}: metadata `run.id` = {id:?} {problem}: expected {}",
            path.display(),
            pendulum_rig::names::ID_EXPECTED
        ))
    })?;
    Ok(RunData {
        id,
        role,
        rig: RigParams {
            m_kg: meta_f64(m, "m_kg", path)?,
            l_m: meta_f64(m, "l_m", path)?,
            crank_r_m: meta_f64(m, "crank_r_m", path)?,
            rod_l_m: meta_f64(m, "rod_L_m", path)?,
            r_b_m: meta_f64(m, "r_b_m", path)?,
            omega_hz: m
                .get("omega_hz")
                .map(|_| meta_f64(m, "omega_hz", path))
                .transpose()?,
            g_m_s2: meta_f64(m, "g_m_s2", path)?,
        },
        enc_t_s: log.encoder.iter().map(|e| e.t_s).collect(),
        theta_rad: log.encoder.iter().map(|e| e.theta_rad).collect(),
        acc_t_s: log.accel.iter().map(|a| a.t_s).collect(),
        az_m_s2: log.accel.iter().map(|a| a.az_m_s2).collect(),
        ax_m_s2: log.accel.iter().map(|a| a.ax_m_s2).collect(),
    })
}

/// Where runs come from.
pub enum Source {
    Campaign(Campaign),
    Mcap(Vec<PathBuf>),
}

/// Decides whether `dir` is a campaign (has campaign.toml) or a folder of MCAP files.
pub fn source(dir: &Path) -> Result<Source, JobError> {
    if dir.join("campaign.toml").is_file() || dir.extension().is_some_and(|e| e == "toml") {
        let c = Campaign::load(dir)?;
        c.check_files()?;
        return Ok(Source::Campaign(c));
    }
    let rd = std::fs::read_dir(dir).map_err(|source| JobError::Io {
        path: dir.to_path_buf(),
        source,
    })?;
    let mut files: Vec<PathBuf> = rd
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.extension().is_some_and(|e| e == "mcap"))
        .filter(|p| {
            !p.file_name()
                .is_some_and(|n| n.to_string_lossy().starts_with('.'))
        })
        .collect();
    files.sort();
    if files.is_empty() {
        return Err(JobError::Invalid(format!(
            "{}: neither a campaign (no campaign.toml) nor a folder of .mcap run logs",
            dir.display()
        )));
    }
    Ok(Source::Mcap(files))
}

/// Loads every run of a campaign or MCAP folder (in parallel). MCAP files of different
/// campaigns are refused ([`load_runs_mixing`]).
pub fn load_runs(dir: &Path) -> Result<Vec<RunData>, JobError> {
    load_runs_mixing(dir, false)
}

/// [`load_runs`]; `mix_campaigns`: MCAP files of different campaigns may be fitted together
/// (asked for with `--mix-campaigns`), else refused naming the campaigns.
pub fn load_runs_mixing(dir: &Path, mix_campaigns: bool) -> Result<Vec<RunData>, JobError> {
    Ok(load_runs_resolved_mixing(dir, mix_campaigns)?
        .into_iter()
        .map(|(rd, _)| rd)
        .collect())
}

/// [`load_runs`] with each run's angle resolution, rad, when its capture states it (see
/// [`angle_step_rad`]).
pub fn load_runs_resolved(dir: &Path) -> Result<Vec<(RunData, Option<f64>)>, JobError> {
    load_runs_resolved_mixing(dir, false)
}

/// Refuses MCAP files of more than one campaign (their metadata `run.campaign`), unless
/// `mix_campaigns`: runs of two campaigns (another rig, another day, another pendulum) fitted
/// as one used to give one set of damping parameters for both without a word. Files without a
/// campaign name are not counted.
fn check_one_campaign(
    dir: &Path,
    files: &[(PathBuf, Option<String>)],
    mix_campaigns: bool,
) -> Result<(), JobError> {
    let mut by: BTreeMap<&str, Vec<String>> = BTreeMap::new();
    for (p, c) in files {
        if let Some(c) = c {
            by.entry(c.as_str()).or_default().push(
                p.file_name()
                    .map(|n| n.to_string_lossy().into_owned())
                    .unwrap_or_default(),
            );
        }
    }
    if mix_campaigns || by.len() < 2 {
        return Ok(());
    }
    let list: Vec<String> = by
        .iter()
        .map(|(c, f)| {
            format!(
                "`{}` ({})",
                pendulum_rig::names::printable(c),
                f.iter()
                    .map(|n| pendulum_rig::names::printable(n))
                    .collect::<Vec<_>>()
                    .join(", ")
            )
        })
        .collect();
    Err(JobError::Invalid(format!(
        "{}: the MCAP files hold runs of {} campaigns: {}: refusing to fit them together (one \
         set of parameters for different rigs or days); `identify` and `validate` take \
         --mix-campaigns to do it on purpose",
        dir.display(),
        by.len(),
        list.join(" and ")
    )))
}

/// [`load_runs_resolved`]; `mix_campaigns` as in [`load_runs_mixing`].
pub fn load_runs_resolved_mixing(
    dir: &Path,
    mix_campaigns: bool,
) -> Result<Vec<(RunData, Option<f64>)>, JobError> {
    use rayon::prelude::*;
    match source(dir)? {
        Source::Campaign(c) => {
            // Before any work: a misspelt key changes what a run is taken for.
            for w in &c.warnings {
                eprintln!("warning: {w}");
            }
            c.runs
                .par_iter()
                .map(|spec| {
                    read_capture(spec, c.g_m_s2).map(|cap| {
                        let step = angle_step_rad(spec.format.as_deref(), &cap.header);
                        (run_data(&c, spec, &cap), step)
                    })
                })
                .collect()
        }
        Source::Mcap(files) => {
            let loaded: Vec<(RunData, Option<f64>, Option<String>)> = files
                .par_iter()
                .map(|p| {
                    let log = read_run(p)?;
                    let campaign = log
                        .metadata
                        .get(METADATA_RUN)
                        .and_then(|m| m.get("campaign").cloned());
                    let (rd, step) = run_of_log(&log)?;
                    Ok((rd, step, campaign))
                })
                .collect::<Result<_, JobError>>()?;
            let named: Vec<(PathBuf, Option<String>)> = files
                .iter()
                .cloned()
                .zip(loaded.iter().map(|l| l.2.clone()))
                .collect();
            check_one_campaign(dir, &named, mix_campaigns)?;
            Ok(loaded.into_iter().map(|(rd, step, _)| (rd, step)).collect())
        }
    }
}

/// An MCAP run log's run data and angle step.
fn run_of_log(log: &RunLog) -> Result<(RunData, Option<f64>), JobError> {
    let header: Vec<(String, String)> = log
        .metadata
        .get(METADATA_CAPTURE_HEADER)
        .map(|m| m.clone().into_iter().collect())
        .unwrap_or_default();
    let format = log
        .metadata
        .get(METADATA_RUN)
        .and_then(|m| m.get("format").cloned());
    let step = angle_step_rad(format.as_deref(), &header);
    Ok((run_data_from_log(log)?, step))
}

/// One step of a run's angle, rad (2π / counts per revolution), when its capture states it: the
/// header's `encoder_cpr` (a time series' `counts_per_rev`, whatever its angle unit), else the
/// rig's default for the rig's own formats; a time series without `counts_per_rev` states none
/// (the analysis then takes the smallest step in the data).
pub fn angle_step_rad(format: Option<&str>, header: &[(String, String)]) -> Option<f64> {
    let get = |k: &str| header.iter().find(|(key, _)| key == k).map(|(_, v)| v);
    if let Some(cpr) = get("encoder_cpr").and_then(|v| v.trim().parse::<f64>().ok()) {
        return (cpr.is_finite() && cpr > 0.0).then(|| std::f64::consts::TAU / cpr);
    }
    let timeseries = format == Some(pendulum_rig::timeseries::FORMAT)
        || get("format").map(String::as_str) == Some(pendulum_rig::timeseries::FORMAT);
    (!timeseries)
        .then(|| std::f64::consts::TAU / f64::from(pendulum_rig::capture::DEFAULT_ENCODER_CPR))
}
