//! `pendulum identify` and `pendulum validate`: runs a pipeline over a campaign (raw or MCAP) and
//! writes Parquet tables and plots into one folder per invocation.

use std::path::{Path, PathBuf};
use std::sync::Arc;
use std::time::Instant;

use indicatif::{ProgressBar, ProgressStyle};
use pendulum_fit::StopRule;
use pendulum_process::identify::{
    residual_series, FitOutcome, ResidualSeries, RunFit, MAX_NP, MIN_NP,
};
use pendulum_process::pipeline::{Context, PipelineConfig, StageConfig};
use pendulum_process::{Role, RunData};

use crate::inputs::Inputs;
use crate::outputs::{prepare_out_dir, removed_note, write_outputs_checked, OutputSummary, TABLES};
use crate::runs::{load_runs_mixing, load_runs_resolved_mixing};
use crate::JobError;

/// The built-in pipelines (the same text as `pipelines/*.toml`).
pub const IDENTIFY_PIPELINE: &str = include_str!("../../../pipelines/identify.toml");
pub const VALIDATE_PIPELINE: &str = include_str!("../../../pipelines/validate.toml");

/// Command-line overrides of the fit stage.
#[derive(Debug, Clone, Default)]
pub struct FitOverrides {
    pub model: Option<String>,
    pub np: Option<usize>,
    pub generations: Option<u64>,
    pub tol: Option<f64>,
    pub relative_tol: bool,
    pub seed: Option<u64>,
    pub threads: Option<usize>,
    pub window_s: Option<f64>,
    pub no_early_abandon: bool,
    /// Fit MCAP files of different campaigns together (refused otherwise, naming them).
    pub mix_campaigns: bool,
}

/// What to identify.
#[derive(Debug, Clone)]
pub struct IdentifyJob {
    pub input: PathBuf,
    pub out: PathBuf,
    pub pipeline: Option<PathBuf>,
    pub overrides: FitOverrides,
    pub progress: bool,
    /// Also fit the free-motion segments before the shakers start, as free decays (excitation
    /// off, identifiable terms), into `OUT/free_segments/`.
    pub free_segments: bool,
}

/// Shortest free-motion segment fitted as a free decay, s (about three swings of the study's
/// pendulum: the fit's restart segments span two).
pub const FREE_SEGMENT_MIN_S: f64 = 2.5;

/// The free-motion segment before each run's shaker start, as a run of its own with no shaker
/// (`<id>-free`, same role): it goes through the same stages as a free-decay recording.
pub fn free_segment_runs(ctx: &Context) -> Vec<RunData> {
    let mut out = Vec::new();
    for run in &ctx.runs {
        let Some(al) = ctx.alignments.get(&run.id).filter(|a| !a.is_free()) else {
            continue;
        };
        let Some(seg) = al.free_segment_samples(run, FREE_SEGMENT_MIN_S) else {
            continue;
        };
        let mut rig = run.rig.clone();
        rig.omega_hz = None;
        out.push(RunData {
            id: pendulum_process::run::free_segment_id(&run.id),
            role: run.role,
            rig,
            enc_t_s: run.enc_t_s[seg.clone()].to_vec(),
            theta_rad: run.theta_rad[seg].to_vec(),
            acc_t_s: Vec::new(),
            az_m_s2: Vec::new(),
            ax_m_s2: Vec::new(),
        });
    }
    out
}

/// Each free segment through `stages` before the fit (and validation), one segment at a time:
/// a segment that cannot be read as a free decay is left out with the reason, not every other
/// segment with it. A bob hanging still until its shaker starts has no swing to align on ("only
/// 0 turning points"); on a drawn design one such segment took the other four identify runs'
/// segments out of discover's refits, whose damping then wandered to another basin.
/// Returns each kept segment's own context, and a note per segment left out.
pub fn prepared_free_segments(
    free: Vec<RunData>,
    stages: &PipelineConfig,
) -> (Vec<Context>, Vec<String>) {
    let pre = PipelineConfig {
        name: stages.name.clone(),
        stages: stages
            .stages
            .iter()
            .filter(|s| !matches!(s, StageConfig::Fit(_) | StageConfig::Validate(_)))
            .cloned()
            .collect(),
    };
    let mut kept = Vec::new();
    let mut left_out = Vec::new();
    for run in free {
        let id = run.id.clone();
        let mut ctx = Context::new(vec![run]);
        match pre.run(&mut ctx) {
            Ok(()) => kept.push(ctx),
            Err(e) => left_out.push(format!("free segment {id} left out: {e}")),
        }
    }
    (kept, left_out)
}

/// Loads a pipeline file or the built-in one.
pub fn load_pipeline(
    path: Option<&Path>,
    builtin: &str,
    name: &str,
) -> Result<(PipelineConfig, String), JobError> {
    match path {
        Some(p) => {
            let text = std::fs::read_to_string(p).map_err(|source| JobError::Io {
                path: p.to_path_buf(),
                source,
            })?;
            Ok((PipelineConfig::from_toml(&text, p)?, text))
        }
        None => Ok((
            PipelineConfig::from_toml(builtin, Path::new(&format!("<built-in {name}>")))?,
            builtin.to_string(),
        )),
    }
}

fn apply_overrides(p: &mut PipelineConfig, o: &FitOverrides) {
    if let Some(fit) = p.fit_mut() {
        if let Some(m) = &o.model {
            fit.model = m.clone();
        }
        if let Some(v) = o.np {
            fit.np = Some(v);
        }
        if let Some(v) = o.generations {
            fit.max_generations = v;
        }
        if let Some(v) = o.tol {
            fit.tol = v;
        }
        if o.relative_tol {
            fit.stop_rule = StopRule::Relative;
        }
        if let Some(v) = o.seed {
            fit.seed = v;
        }
        if o.threads.is_some() {
            fit.threads = o.threads;
        }
        if let Some(w) = o.window_s {
            fit.window.window_s = w;
            fit.window.free_window_s = Some(w);
        }
        if o.no_early_abandon {
            fit.early_abandon = false;
        }
    }
    if let Some(w) = o.window_s {
        for s in &mut p.stages {
            if let StageConfig::Validate(v) = s {
                v.window.window_s = w;
                v.window.free_window_s = Some(w);
            }
        }
    }
}

/// A progress bar over DE generations showing the current best.
pub fn generation_bar(
    max_generations: u64,
) -> (ProgressBar, pendulum_process::identify::ProgressFn) {
    let bar = ProgressBar::new(max_generations);
    bar.set_style(
        ProgressStyle::with_template(
            "{prefix:>18} {bar:30} gen {pos}/{len} {msg} [{elapsed_precise}]",
        )
        .unwrap_or_else(|_| ProgressStyle::default_bar()),
    );
    let b = bar.clone();
    let f: pendulum_process::identify::ProgressFn = Arc::new(move |label: &str, g| {
        b.set_prefix(label.to_string());
        b.set_position(g.generation);
        b.set_message(format!("best {:.4} worst {:.4}", g.best, g.worst));
    });
    (bar, f)
}

/// Every run a fitted model saw (identify runs from the fit, validate runs from the
/// validation) with its data and alignment: a model fitted on re-aligned runs (speed_drift) is
/// replayed on its own alignment. Runs missing from the context are skipped.
fn fitted_runs<'a>(
    ctx: &'a Context,
    fit: &'a FitOutcome,
    validation: Option<&'a [RunFit]>,
) -> impl Iterator<Item = (&'a RunFit, &'a RunData, &'a pendulum_process::Alignment)> {
    fit.runs
        .iter()
        .chain(validation.unwrap_or(&[]))
        .filter_map(move |rf| {
            let run = ctx.runs.iter().find(|r| r.id == rf.id)?;
            let al = fit
                .alignments
                .get(&rf.id)
                .or_else(|| ctx.alignments.get(&rf.id))?;
            Some((rf, run, al))
        })
}

/// Residual histories of every fitted model on every run it saw (identify runs from the fit,
/// validate runs from the validation).
pub fn residuals_of(
    ctx: &Context,
    fit: &FitOutcome,
    validation: Option<&[RunFit]>,
    span_s: f64,
) -> Result<Vec<(String, Role, ResidualSeries)>, JobError> {
    let window = pendulum_process::identify::Window::default();
    let mut out = Vec::new();
    for (rf, run, al) in fitted_runs(ctx, fit, validation) {
        let series = residual_series(run, al, &fit.spec, &fit.params, rf.ic_fit, &window, span_s)?;
        out.push((rf.id.clone(), rf.role, series));
    }
    Ok(out)
}

/// One run's fit residual: run id, role, the series, and each sample's segment number.
pub type SegmentResiduals = (String, Role, ResidualSeries, Vec<usize>);

/// The residual each fitted model's fit minimised on every run it saw (identify runs from the
/// fit, validate runs from the validation): multiple-shooting segments restarted from the
/// measured state over the fit window, with each sample's segment number.
pub fn segment_residuals_of(
    ctx: &Context,
    fit: &FitOutcome,
    validation: Option<&[RunFit]>,
) -> Result<Vec<SegmentResiduals>, JobError> {
    let mut out = Vec::new();
    for (rf, run, al) in fitted_runs(ctx, fit, validation) {
        // The window the run was fitted or validated with.
        let window = match rf.role {
            Role::Identify => ctx.fit_window,
            _ => ctx.validate_window,
        }
        .unwrap_or_default();
        let (Some(ic), Some(steady)) = (ctx.initial.get(&rf.id), ctx.steady.get(&rf.id)) else {
            continue;
        };
        let (series, segments) = pendulum_process::identify::segment_residual_series(
            run,
            al,
            ic,
            steady,
            &ctx.steady_cfg,
            &fit.spec,
            &fit.params,
            rf.ic_fit,
            &window,
        )?;
        out.push((rf.id.clone(), rf.role, series, segments));
    }
    Ok(out)
}

/// Runs the identify pipeline and writes the outputs.
pub fn run(job: &IdentifyJob) -> Result<OutputSummary, JobError> {
    let started = Instant::now();
    let (mut pipeline, _) = load_pipeline(job.pipeline.as_deref(), IDENTIFY_PIPELINE, "identify")?;
    apply_overrides(&mut pipeline, &job.overrides);
    check_np(&mut pipeline, job)?;
    let pipeline_text = serde_json::to_string(&pipeline).unwrap_or_default();
    let mut inputs = Inputs::new();
    if let Some(p) = &job.pipeline {
        inputs.add("--pipeline", p);
    }
    let inputs = checked_inputs(inputs, &job.input, &job.out)?;
    let removed = prepare_out_dir(&job.out)?;
    let (runs, steps): (Vec<RunData>, Vec<Option<f64>>) =
        load_runs_resolved_mixing(&job.input, job.overrides.mix_campaigns)?
            .into_iter()
            .unzip();
    if !runs.iter().any(|r| r.role == Role::Identify) {
        return Err(JobError::Invalid(format!(
            "{}: no run has role = \"identify\"",
            job.input.display()
        )));
    }
    // The stated resolutions (counts_per_rev) bound the free-decay envelope the fit is checked
    // against, as in discover.
    let resolutions = runs
        .iter()
        .zip(&steps)
        .filter_map(|(r, s)| Some((r.id.clone(), (*s)?)))
        .collect();
    let mut ctx = Context::new(runs);
    ctx.resolutions = resolutions;
    ctx.notes.extend(removed_note(&removed));
    // The fit silently runs with at least MIN_NP members: say so, naming where np came from.
    if let Some(np) = pipeline
        .fit_mut()
        .and_then(|f| f.np)
        .filter(|&n| n < MIN_NP)
    {
        let from = if job.overrides.np.is_some() {
            format!("--np {np}")
        } else {
            format!("the pipeline's np = {np}")
        };
        ctx.notes.push(format!(
            "{from} raised to {MIN_NP}: differential evolution needs at least {MIN_NP} members"
        ));
    }
    let max_gen = pipeline.fit_mut().map_or(0, |f| f.max_generations);
    let bar = if job.progress {
        let (bar, f) = generation_bar(max_gen);
        ctx.progress = Some(f);
        Some(bar)
    } else {
        None
    };
    let res = pipeline.run(&mut ctx);
    if let Some(b) = bar {
        b.finish_and_clear();
    }
    res?;
    let mut summary = write_outputs_checked(
        &ctx,
        &job.out,
        &pipeline_text,
        "pendulum identify",
        started.elapsed().as_secs_f64(),
        &inputs,
    )?;
    if job.free_segments {
        let (kept, left_out) = prepared_free_segments(free_segment_runs(&ctx), &pipeline);
        for note in &left_out {
            summary.text += &format!("\n{note}");
        }
        let free: Vec<RunData> = kept.into_iter().flat_map(|c| c.runs).collect();
        if !free.iter().any(|r| r.role == Role::Identify) {
            summary.text += &format!(
                "\nfree segments: none of at least {FREE_SEGMENT_MIN_S} s before a shaker start in an identify run that reads as a free decay; not fitted\n"
            );
            return completed(&job.out, "pendulum identify", summary);
        }
        let n = free.len();
        let mut fctx = Context::new(free);
        pipeline.run(&mut fctx)?;
        let fs = write_outputs_checked(
            &fctx,
            &job.out.join("free_segments"),
            &pipeline_text,
            "pendulum identify --free-segments",
            started.elapsed().as_secs_f64(),
            &inputs,
        )?;
        summary.text += &format!(
            "\nfree segments before the shaker starts ({n} runs), fitted as free decays:\n{fs}"
        );
        summary.tables.extend(fs.tables);
        summary.plots.extend(fs.plots);
    }
    completed(&job.out, "pendulum identify", summary)
}

/// Marks OUT complete (the last write: [`crate::outputs::mark_complete`]) naming the tables
/// and plots of `summary`.
fn completed(out: &Path, command: &str, summary: OutputSummary) -> Result<OutputSummary, JobError> {
    let files: Vec<_> = summary
        .tables
        .iter()
        .chain(&summary.plots)
        .cloned()
        .collect();
    crate::outputs::mark_complete(out, command, &files)?;
    Ok(summary)
}

/// Refuses a population the machine cannot hold before the runs are loaded (see [`MAX_NP`]),
/// naming where it came from: `--np 100000000` used to abort on allocation (exit 134).
fn check_np(pipeline: &mut PipelineConfig, job: &IdentifyJob) -> Result<(), JobError> {
    let Some(np) = pipeline
        .fit_mut()
        .and_then(|f| f.np)
        .filter(|&n| n > MAX_NP)
    else {
        return Ok(());
    };
    let given = match (&job.overrides.np, &job.pipeline) {
        (Some(_), _) => format!("--np {np}"),
        (None, Some(p)) => format!("{}: np = {np}", p.display()),
        (None, None) => format!("the built-in pipeline's np = {np}"),
    };
    Err(JobError::TooLarge {
        given,
        what: "as many DE population members".into(),
        limit: MAX_NP.to_string(),
        why: "DE holds the population and a generation of trials, each a vector of 3 + 2·runs \
              numbers (8 bytes each): 1.6 GB at the limit with 500 runs, and every member \
              simulates every run each generation; the default is 10 · (3 + 2·runs)"
            .into(),
    })
}

/// What to validate: fixed parameters from a params.parquet.
#[derive(Debug, Clone)]
pub struct ValidateJob {
    pub input: PathBuf,
    pub params: PathBuf,
    pub model: Option<String>,
    pub out: PathBuf,
    pub pipeline: Option<PathBuf>,
    /// Validate on MCAP files of different campaigns together (refused otherwise).
    pub mix_campaigns: bool,
}

/// Runs the validate pipeline with a given model.
pub fn validate(job: &ValidateJob) -> Result<OutputSummary, JobError> {
    let started = Instant::now();
    let (pipeline, _) = load_pipeline(job.pipeline.as_deref(), VALIDATE_PIPELINE, "validate")?;
    let pipeline_text = serde_json::to_string(&pipeline).unwrap_or_default();
    let given = crate::outputs::read_params(&job.params, job.model.as_deref())?;
    let mut inputs = Inputs::new();
    inputs.add("--params", &job.params);
    if let Some(p) = &job.pipeline {
        inputs.add("--pipeline", p);
    }
    let inputs = checked_inputs(inputs, &job.input, &job.out)?;
    let removed = prepare_out_dir(&job.out)?;
    let runs = load_runs_mixing(&job.input, job.mix_campaigns)?;
    if !runs.iter().any(|r| r.role == Role::Validate) {
        return Err(JobError::Invalid(format!(
            "{}: no run has role = \"validate\"",
            job.input.display()
        )));
    }
    let mut ctx = Context::new(runs);
    ctx.notes.extend(removed_note(&removed));
    ctx.given = Some(given);
    pipeline.run(&mut ctx)?;
    let summary = write_outputs_checked(
        &ctx,
        &job.out,
        &pipeline_text,
        "pendulum validate",
        started.elapsed().as_secs_f64(),
        &inputs,
    )?;
    completed(&job.out, "pendulum validate", summary)
}

/// `inputs` plus the files of the run source `input`, after checking that none of the tables
/// `out` will receive is one of them: refused before the fit rather than after it. (Plots are
/// named after models and runs and checked as they are written.)
fn checked_inputs(mut inputs: Inputs, input: &Path, out: &Path) -> Result<Inputs, JobError> {
    inputs.add_run_source(input)?;
    for t in TABLES {
        inputs.check_output("the output", &out.join(t))?;
    }
    Ok(inputs)
}
