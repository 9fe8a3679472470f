//! `pendulum discover`: fit the base model, show what it gets wrong, name the cause, extend the
//! model and measure the gain on held-out runs; tables, plots and `report.md`.

use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use std::time::Instant;

use pendulum_discover::envelope::{
    envelope_fits, free_segment_envelopes, pooled_envelope, PooledTerm, SegmentEnvelope,
};
use pendulum_discover::{discover, Base, DiscoverConfig, Discovery};
use pendulum_plot::{Figure, Panel, Series, SeriesStyle};
use pendulum_process::pipeline::{Context, PipelineConfig, StageConfig};
use pendulum_process::Role;
use pendulum_report::{Column, ColumnData};
use serde::{Deserialize, Serialize};

use crate::outputs::write_outputs_checked;
use crate::runs::load_runs_resolved;
use crate::JobError;

/// The built-in discover pipeline (`pipelines/discover.toml`).
pub const DISCOVER_PIPELINE: &str = include_str!("../../../pipelines/discover.toml");

/// A discover pipeline file: the identify stages plus a `[discover]` table.
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct DiscoverPipeline {
    pub name: String,
    #[serde(rename = "stage")]
    pub stages: Vec<StageConfig>,
    #[serde(default)]
    pub discover: DiscoverConfig,
}

/// What to discover.
#[derive(Debug, Clone)]
pub struct DiscoverJob {
    pub input: PathBuf,
    pub out: PathBuf,
    pub base: Base,
    pub pipeline: Option<PathBuf>,
    pub generations: Option<u64>,
    pub seed: Option<u64>,
    pub progress: bool,
}

/// What discover wrote and found.
#[derive(Debug, Clone)]
pub struct DiscoverSummary {
    pub out_dir: PathBuf,
    pub report: PathBuf,
    /// The forced-run discovery (empty rows for free-decay campaigns).
    pub discovery: Discovery,
    /// Per-run free-decay diagnoses (campaigns without a shaker).
    pub decays: Vec<(String, pendulum_explain::DecayDiagnosis)>,
    /// Per run of a shaker campaign, the envelope of its free segment before the shaker starts
    /// (or why it could not be read).
    pub envelopes: Vec<(String, Result<pendulum_explain::EnvelopeFit, String>)>,
    /// The free segments' envelopes pooled over the runs ([`pooled_envelope`]), SI.
    pub pooled: Vec<PooledTerm>,
    pub text: String,
}

impl std::fmt::Display for DiscoverSummary {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(&self.text)
    }
}

fn load(path: Option<&Path>) -> Result<DiscoverPipeline, JobError> {
    let (text, src) = match path {
        Some(p) => (
            std::fs::read_to_string(p).map_err(|source| JobError::Io {
                path: p.to_path_buf(),
                source,
            })?,
            p.display().to_string(),
        ),
        None => (DISCOVER_PIPELINE.to_string(), "<built-in discover>".into()),
    };
    toml::from_str(&text)
        .map_err(|e| JobError::Invalid(format!("{src}: pipeline: {}", e.message())))
}

/// A gain (a fraction: 1 − after/before) as a percentage, `-` when not measured (NaN), for the
/// diagnosis table's 8-wide columns. A
/// candidate far outside anything physical can make a model billions of times worse (a
/// generator screened at c_g 1e6 N·m·s/rad printed an equation-error "gain" of −3.7e12 %); the
/// table says only that it is below −999 % (`diagnosis.parquet` keeps the value).
fn pct(v: f64) -> String {
    if v.is_nan() {
        "-".into()
    } else if v < -9.99 {
        "<-999%".into()
    } else {
        format!("{:.1}%", 100.0 * v)
    }
}

/// The diagnosis as a short table.
pub fn diagnosis_table(d: &Discovery) -> String {
    let mut t = String::new();
    let _ = writeln!(
        t,
        "{:<24} {:>8} {:>12} {:>24} {:>11} {:<6} {:>9} {:>16} {:>8}",
        "effect",
        "accepted",
        "estimate",
        "95 % interval",
        "refit",
        "unit",
        "ΔBIC",
        "E_θ gain ± noise",
        "eq gain"
    );
    for r in &d.rows {
        let _ = writeln!(
            t,
            "{:<24} {:>8} {:>12.4e} [{:>10.3e}, {:>10.3e}] {:>11} {:<6} {:>9.1} {:>8} ±{:>6} {:>8}",
            r.effect,
            if r.accepted { "YES" } else { "no" },
            r.estimate,
            r.ci_low,
            r.ci_high,
            if r.refit_estimate.is_finite() {
                format!("{:.3e}", r.refit_estimate)
            } else {
                "-".into()
            },
            r.unit,
            r.delta_bic,
            pct(r.heldout_gain),
            pct(r.heldout_noise),
            pct(r.heldout_eq_gain)
        );
    }
    // What the rows without a number say (a candidate the identify runs cannot estimate): "NaN"
    // alone would read as a failure of the tool, not of the runs' design.
    for r in d
        .rows
        .iter()
        .filter(|r| !r.accepted && r.estimate.is_nan() && r.effect != "unexplained")
    {
        let _ = writeln!(t, "{}: {}", r.effect, r.note);
    }
    // A value named from the trajectories, with their own range (the interval above is the
    // screen's, or theirs where they tell it from its absence).
    for r in d.rows.iter().filter(|r| r.refit_ci_low.is_finite()) {
        let _ = writeln!(
            t,
            "{}: named at {:.4e} {} (its trajectory refit on every run; the identify runs' own {:.4e}); the identify runs' trajectories hold it within [{:.3e}, {:.3e}]{}",
            r.effect,
            r.estimate,
            r.unit,
            r.identify_estimate,
            r.refit_ci_low,
            r.refit_ci_high,
            if r.refit_ci_low == 0.0 {
                " (down to 0: they cannot tell its size from its absence)"
            } else {
                ""
            }
        );
    }
    t
}

/// What `discover` writes besides identify's tables ([`crate::outputs::TABLES`]) and plots
/// named after models and runs; checked against the inputs before any work.
pub const OUTPUTS: [&str; 7] = [
    "diagnosis.parquet",
    "signatures.parquet",
    "envelopes.parquet",
    "damping_check.parquet",
    "report.md",
    "signatures.png",
    "envelopes.png",
];

pub fn run(job: &DiscoverJob) -> Result<DiscoverSummary, JobError> {
    let began = std::time::SystemTime::now();
    let summary = run_unmarked(job)?;
    // The folder is one unit: marked complete last, naming the files this invocation wrote
    // (`prepare_out_dir` removed any earlier marker before the work began).
    let mut files: Vec<PathBuf> = std::fs::read_dir(&summary.out_dir)
        .map_err(|source| JobError::Io {
            path: summary.out_dir.clone(),
            source,
        })?
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| {
            // Only what this invocation wrote (not a user's file, nor an earlier run's plot).
            p.metadata()
                .and_then(|m| m.modified())
                .is_ok_and(|t| t >= began)
                && p.file_name()
                    .and_then(|n| n.to_str())
                    .is_some_and(|n| !n.starts_with('.') && n != "complete.json")
        })
        .collect();
    files.sort();
    crate::outputs::mark_complete(&summary.out_dir, "pendulum discover", &files)?;
    Ok(summary)
}

fn run_unmarked(job: &DiscoverJob) -> Result<DiscoverSummary, JobError> {
    let started = Instant::now();
    let mut pipe = load(job.pipeline.as_deref())?;
    for s in &mut pipe.stages {
        if let StageConfig::Fit(f) = s {
            f.model = job.base.name().into();
            f.effects.clear();
            if let Some(g) = job.generations {
                f.max_generations = g;
            }
            if let Some(seed) = job.seed {
                f.seed = seed;
            }
        }
    }
    let pipeline_json = serde_json::to_string(&pipe).unwrap_or_default();
    let stages = PipelineConfig {
        name: pipe.name.clone(),
        stages: pipe
            .stages
            .iter()
            .filter(|s| !matches!(s, StageConfig::Validate(_)))
            .cloned()
            .collect(),
    };
    // OUT checked writable (and swept of stale temporary files) before the fits, not after.
    let removed = crate::outputs::prepare_out_dir(&job.out)?;
    // No output may replace an input (a capture or MCAP in OUT under an output's name).
    let mut inputs = crate::inputs::Inputs::new();
    inputs.add_run_source(&job.input)?;
    if let Some(p) = &job.pipeline {
        inputs.add("the pipeline file", p);
    }
    for name in crate::outputs::TABLES.iter().chain(&OUTPUTS) {
        inputs.check_output("the output", &job.out.join(name))?;
    }
    let (runs, steps): (Vec<_>, Vec<_>) = load_runs_resolved(&job.input)?.into_iter().unzip();
    if !runs.is_empty() && runs.iter().all(|r| r.rig.omega_hz.is_none()) {
        return free_decays(job, &runs, &steps, &pipeline_json);
    }
    for role in [Role::Identify, Role::Validate] {
        if !runs.iter().any(|r| r.role == role) {
            return Err(JobError::Invalid(format!(
                "{}: no run has role = \"{}\": discover fits on identify runs and measures the gain on validate runs",
                job.input.display(),
                role.as_str()
            )));
        }
    }
    let mut ctx = Context::new(runs);
    ctx.notes.extend(crate::outputs::removed_note(&removed));
    let max_gen = stages.stages.iter().find_map(|s| match s {
        StageConfig::Fit(f) => Some(f.max_generations),
        _ => None,
    });
    let bar = if job.progress {
        let (bar, f) = crate::identify::generation_bar(max_gen.unwrap_or(0));
        ctx.progress = Some(f);
        Some(bar)
    } else {
        None
    };
    let res = stages.run(&mut ctx);
    if let Some(b) = bar {
        b.finish_and_clear();
    }
    res?;
    let (free, left_out) = free_segments(&ctx, &stages, &pipe.discover);
    ctx.notes.extend(left_out);
    let n_id = free.iter().filter(|r| r.role == Role::Identify).count();
    if n_id > 0 {
        ctx.notes.push(format!(
            "the trajectory refits also follow the free segment before the shaker starts of {n_id} identify run(s) (one at rest adds nothing)"
        ));
    }
    let n_val = free.len() - n_id;
    if n_val > 0 {
        ctx.notes.push(format!(
            "the held-out E_θ also follows the free segment before the shaker starts of {n_val} validate run(s), and a named effect's value refitted on every run follows them too (one at rest adds nothing)"
        ));
    }
    // The free-decay segment before each shaker start: its envelope (the report's, and a view
    // of a loss's size for discovery).
    let envs = free_segment_envelopes(&ctx);
    let d = discover(&ctx, job.base, &pipe.discover, &free, &envs)?;
    if let Some(note) = d
        .damping_check
        .as_ref()
        .and_then(|c| c.note(&d.base.spec, &d.base.params))
    {
        ctx.notes
            .push(format!("{}: {}", note.0.to_lowercase(), note.1));
    }

    // Tables shared with identify: params/residuals/... for the base and the extended model.
    ctx.validations
        .push((d.base.spec.name.clone(), d.validation_base.clone()));
    if let Some(ext) = &d.extended {
        ctx.fits.push(ext.clone());
        ctx.validations
            .push((ext.spec.name.clone(), d.validation_final.clone()));
    }
    let out = &job.out;
    let mut summary = write_outputs_checked(
        &ctx,
        out,
        &pipeline_json,
        "pendulum discover",
        started.elapsed().as_secs_f64(),
        &inputs,
    )?;
    let opts = pendulum_report::TableOptions::new()
        .meta("command", "pendulum discover")
        .meta("pipeline", pipeline_json.clone())
        .meta("base", job.base.name());

    // diagnosis.parquet
    let f = |v: Vec<f64>, name: &str, unit: &str| Column::f64(name, unit, v);
    let rows = &d.rows;
    opts.write(
        &out.join("diagnosis.parquet"),
        &[
            Column::new(
                "effect",
                ColumnData::Str(rows.iter().map(|r| r.effect.clone()).collect()),
            ),
            Column::new(
                "accepted",
                ColumnData::Bool(rows.iter().map(|r| r.accepted).collect()),
            ),
            f(
                rows.iter().map(|r| r.estimate).collect(),
                "estimate",
                "see column unit (a named effect's value on every run, identify and validate, by the view that named it; otherwise the identify runs')",
            ),
            f(
                rows.iter().map(|r| r.identify_estimate).collect(),
                "identify_estimate",
                "see column unit (the identify runs' own value, by the view that named it: the value the held-out figures judged; estimate is a named effect's on every run)",
            ),
            f(
                rows.iter().map(|r| r.ci_low).collect(),
                "ci_low",
                "see column unit",
            ),
            f(
                rows.iter().map(|r| r.ci_high).collect(),
                "ci_high",
                "see column unit",
            ),
            Column::new(
                "unit",
                ColumnData::Str(rows.iter().map(|r| r.unit.clone()).collect()),
            ),
            f(rows.iter().map(|r| r.delta_bic).collect(), "delta_bic", "1"),
            f(
                rows.iter().map(|r| r.heldout_gain).collect(),
                "heldout_gain",
                "1 (fraction)",
            ),
            f(
                rows.iter().map(|r| r.heldout_noise).collect(),
                "heldout_noise",
                "1 (fraction; 1.96 × the standard error of heldout_gain)",
            ),
            f(
                rows.iter().map(|r| r.heldout_eq_gain).collect(),
                "heldout_eq_gain",
                "1 (fraction)",
            ),
            f(
                rows.iter().map(|r| r.screen_estimate).collect(),
                "screen_estimate",
                "see column unit",
            ),
            f(
                rows.iter().map(|r| r.refit_estimate).collect(),
                "refit_estimate",
                "see column unit (NaN: not refitted)",
            ),
            f(
                rows.iter().map(|r| r.refit_ci_low).collect(),
                "refit_ci_low",
                "see column unit (the trajectories' 95 % range for refit_estimate where it is the value named; NaN otherwise)",
            ),
            f(
                rows.iter().map(|r| r.refit_ci_high).collect(),
                "refit_ci_high",
                "see column unit (as refit_ci_low)",
            ),
            f(
                rows.iter().map(|r| r.e_validate_before).collect(),
                "e_validate_before",
                "rad",
            ),
            f(
                rows.iter().map(|r| r.e_validate_after).collect(),
                "e_validate_after",
                "rad",
            ),
            Column::new(
                "note",
                ColumnData::Str(rows.iter().map(|r| r.note.clone()).collect()),
            ),
        ],
    )?;
    // signatures.parquet: one row per equation-error window.
    let w = &d.weak;
    opts.write(
        &out.join("signatures.parquet"),
        &[
            Column::new(
                "run_id",
                ColumnData::Str(w.iter().map(|r| d.weak_runs[r.run].0.clone()).collect()),
            ),
            Column::new(
                "role",
                ColumnData::Str(
                    w.iter()
                        .map(|r| d.weak_runs[r.run].1.as_str().to_string())
                        .collect(),
                ),
            ),
            Column::new(
                "segment",
                ColumnData::Str(
                    w.iter()
                        .map(|r| {
                            if r.phase.is_nan() {
                                "free".to_string()
                            } else {
                                "forced".to_string()
                            }
                        })
                        .collect(),
                ),
            ),
            f(w.iter().map(|r| r.tau_s).collect(), "tau_s", "s"),
            f(w.iter().map(|r| r.theta).collect(), "theta", "rad"),
            f(
                w.iter().map(|r| r.theta_dot_rad_s).collect(),
                "theta_dot",
                "rad/s",
            ),
            f(w.iter().map(|r| r.phase).collect(), "forcing_phase", "rad"),
            f(
                w.iter().map(|r| r.a_y_meas).collect(),
                "a_vertical_meas",
                "m/s²",
            ),
            f(
                w.iter().map(|r| r.a_x_meas).collect(),
                "a_horizontal_meas",
                "m/s²",
            ),
            f(
                d.residual_base.clone(),
                "torque_unexplained_base",
                "1 (per m·g·l, test-function weighted)",
            ),
            f(
                d.residual_final.clone(),
                "torque_unexplained_final",
                "1 (per m·g·l, test-function weighted)",
            ),
        ],
    )?;
    summary.tables.push(out.join("diagnosis.parquet"));
    summary.tables.push(out.join("signatures.parquet"));
    // damping_check.parquet: the base fit's damping beside the free segments' and the joint one
    // (one row; where any identify run's free segment moves).
    if let Some(c) = &d.damping_check {
        let spec = &d.base.spec;
        let mut cols = vec![
            Column::new(
                "verdict",
                ColumnData::Str(vec![match c.verdict() {
                    pendulum_discover::DampingVerdict::Agrees => "agrees",
                    pendulum_discover::DampingVerdict::NotPinned => "not_pinned",
                    pendulum_discover::DampingVerdict::Disagrees => "disagrees",
                }
                .to_string()]),
            ),
            f(vec![c.n_segments as f64], "free_segments", "runs"),
        ];
        for (label, x) in [
            ("base", &d.base.params),
            ("free", &c.free_params),
            ("joint", &c.joint_params),
        ] {
            for (p, v) in spec.params.iter().zip(x) {
                cols.push(f(vec![*v], &format!("{label}.{}", p.name()), p.unit()));
            }
        }
        let fall = "1 (fractional fall of E_θ over 0.5 s segments; negative: a rise)";
        for (name, (g, n)) in [
            ("free_fall_from_base", c.free_gain),
            ("joint_fall_on_free_from_free", c.joint_on_free),
            ("joint_fall_on_forced_from_base", c.joint_on_forced),
        ] {
            cols.push(f(vec![g], name, fall));
            cols.push(f(vec![n], &format!("{name}_noise"), fall));
        }
        opts.write(&out.join("damping_check.parquet"), &cols)?;
        summary.tables.push(out.join("damping_check.parquet"));
    }
    let sig_png = out.join("signatures.png");
    signature_plot(&sig_png, &d)?;
    summary.plots.push(sig_png.clone());

    // The free-decay segments' envelopes (read before discovery).
    if !envs.is_empty() {
        write_envelopes(&out.join("envelopes.parquet"), &opts, &envs)?;
        summary.tables.push(out.join("envelopes.parquet"));
        let env_png = out.join("envelopes.png");
        envelope_plot(
            &env_png,
            &envs,
            "Free-decay segments before the shaker starts",
        )?;
        summary.plots.push(env_png);
    }

    let table = diagnosis_table(&d);
    let report = out.join("report.md");
    write_report(&report, job, &d, &table, &summary.plots, &ctx, &envs)?;
    let mut text = summary.text.clone();
    let _ = writeln!(text, "\nDiagnosis (base model: {}):", job.base.name());
    text.push_str(&table);
    if let Some(u) = &d.unexplained {
        let _ = writeln!(text, "unexplained: {u}");
    }
    for (id, res, noise) in &d.forcing_not_understood {
        let _ = writeln!(
            text,
            "forcing not understood in run {id}: the crank-rod model leaves {res:.3} m/s² RMS on the accelerometer (its noise: {noise:.3} m/s²); its forced segment and crank fit were left out"
        );
    }
    let fits = envelope_fits(&envs, &ctx);
    let pooled = pooled_envelope(&fits);
    if !pooled.is_empty() {
        let terms: Vec<String> = pooled
            .iter()
            .map(|t| format!("{} {:.3e} {}", t.name, t.estimate, t.unit))
            .collect();
        let _ = writeln!(
            text,
            "free segments before the shakers start ({} runs, envelopes pooled): {}",
            fits.len(),
            terms.join(", ")
        );
    }
    let (b, a) = (e(&d.validation_base), e(&d.validation_final));
    let _ = writeln!(
        text,
        "held-out E_θ (validate runs): base {b:.4} → final {a:.4} ({:+.1} %); report: {}",
        -100.0 * (1.0 - a / b.max(1e-12)),
        report.display()
    );
    Ok(DiscoverSummary {
        out_dir: out.clone(),
        report,
        discovery: d,
        decays: Vec::new(),
        envelopes: envs.into_iter().map(|e| (e.run, e.env)).collect(),
        pooled,
        text,
    })
}

/// Campaigns without a shaker: every run is a free decay, analysed in identifiable ratios
/// (`pendulum_explain::decay`), each fitted on its first half and scored on its second.
fn free_decays(
    job: &DiscoverJob,
    runs: &[pendulum_process::RunData],
    steps: &[Option<f64>],
    pipeline_json: &str,
) -> Result<DiscoverSummary, JobError> {
    use pendulum_explain::{diagnose_decay, DecayOptions, KnownRig};
    let out = &job.out;
    std::fs::create_dir_all(out).map_err(|source| JobError::Io {
        path: out.clone(),
        source,
    })?;
    let mut decays = Vec::new();
    let mut text = String::new();
    let mut report = format!(
        "# Free decays: what the {} model misses\n\nCampaign `{}`: {} free-decay runs (no shaker). Each run is fitted on its first half of swings and scored on the second (E_θ = Σ|θ_meas − θ_sim|, restarting at measured turning points).\n\n",
        job.base.name(),
        job.input.display(),
        runs.len()
    );
    let (mut c_run, mut c_eff, mut c_acc, mut c_unit, mut c_note) =
        (Vec::new(), Vec::new(), Vec::new(), Vec::new(), Vec::new());
    let mut nums: Vec<Vec<f64>> = vec![Vec::new(); 5];
    for (rd, step) in runs.iter().zip(steps) {
        let rig = (rd.rig.m_kg.is_finite() && rd.rig.l_m.is_finite()).then_some(KnownRig {
            m_kg: rd.rig.m_kg,
            a_m: rd.rig.l_m,
            g_m_s2: rd.rig.g_m_s2,
            r_b_m: rd.rig.r_b_m.is_finite().then_some(rd.rig.r_b_m),
        });
        let (base, candidates) = decay_terms(job.base);
        let opts = DecayOptions {
            rig,
            base,
            candidates,
            resolution_rad: *step,
            ..DecayOptions::default()
        };
        let d = diagnose_decay(&rd.enc_t_s, &rd.theta_rad, &opts)
            .map_err(|e| JobError::Invalid(format!("run {}: free-decay analysis: {e}", rd.id)))?;
        let _ = writeln!(text, "=== run {} (free decay) ===\n{d}", rd.id);
        let _ = writeln!(report, "## Run `{}`\n\n```\n{d}```\n", rd.id);
        for c in &d.candidates {
            c_run.push(rd.id.clone());
            c_eff.push(c.term.clone());
            c_acc.push(c.accepted);
            c_unit.push(c.unit.clone());
            c_note.push(c.verdict.clone());
            for (col, v) in
                nums.iter_mut()
                    .zip([c.estimate, c.ci_low, c.ci_high, c.delta_bic, c.heldout_gain])
            {
                col.push(v);
            }
        }
        for u in &d.unexplained {
            c_run.push(rd.id.clone());
            c_eff.push("unexplained".into());
            c_acc.push(false);
            c_unit.push(u.unit.clone());
            c_note.push(format!("{}: {} ({})", u.what, u.detail, u.location));
            for (col, v) in
                nums.iter_mut()
                    .zip([u.magnitude, f64::NAN, f64::NAN, f64::NAN, f64::NAN])
            {
                col.push(v);
            }
        }
        decays.push((rd.id.clone(), d));
    }
    let envs: Vec<SegmentEnvelope> = runs
        .iter()
        .zip(&decays)
        .map(|(rd, (_, d))| SegmentEnvelope {
            run: rd.id.clone(),
            role: rd.role,
            env: Ok(d.envelope.clone()),
        })
        .collect();
    // The whole record's envelope pooled over runs with a known rig (SI, each run's own scale).
    let rigs: Vec<(&pendulum_explain::EnvelopeFit, &pendulum_process::RigParams)> = runs
        .iter()
        .zip(&decays)
        .filter(|(rd, _)| rd.rig.m_kg.is_finite() && rd.rig.l_m.is_finite())
        .map(|(rd, (_, d))| (&d.envelope, &rd.rig))
        .collect();
    let pooled = if rigs.len() == runs.len() {
        pooled_envelope(&rigs)
    } else {
        Vec::new()
    };
    let f = |name: &str, unit: &str, v: Vec<f64>| Column::f64(name, unit, v);
    let [est, lo, hi, bic, gain]: [Vec<f64>; 5] = nums.try_into().unwrap_or_default();
    pendulum_report::TableOptions::new()
        .meta("command", "pendulum discover")
        .meta("pipeline", pipeline_json.to_string())
        .meta("base", job.base.name())
        .meta(
            "analysis",
            "free decay (identifiable ratios: estimates are dimensionless, see unit)",
        )
        .write(
            &out.join("diagnosis.parquet"),
            &[
                Column::new("run_id", ColumnData::Str(c_run)),
                Column::new("effect", ColumnData::Str(c_eff)),
                Column::new("accepted", ColumnData::Bool(c_acc)),
                f("estimate", "see column unit", est),
                f("ci_low", "see column unit", lo),
                f("ci_high", "see column unit", hi),
                Column::new("unit", ColumnData::Str(c_unit)),
                f("delta_bic", "1", bic),
                f("heldout_gain", "1 (fraction)", gain),
                Column::new("note", ColumnData::Str(c_note)),
            ],
        )?;
    let topts = pendulum_report::TableOptions::new()
        .meta("command", "pendulum discover")
        .meta("pipeline", pipeline_json.to_string())
        .meta("base", job.base.name())
        .meta("analysis", "free decay");
    write_decay_tables(out, &topts, runs, &decays)?;
    write_envelopes(&out.join("envelopes.parquet"), &topts, &envs)?;
    envelope_plot(
        &out.join("envelopes.png"),
        &envs,
        "Free decays: amplitude and loss per cycle",
    )?;
    loss_plot(&out.join("signatures.png"), &decays, job.base.name())?;
    if !pooled.is_empty() {
        let _ = writeln!(
            report,
            "## Pooled over the runs\n\nThe loss per cycle of every run, each with its own bob, pooled as a non-negative sum of the catalogue's exact pendulum loss curves (lowest BIC, every interval excluding zero; a coarse view beside the per-run trajectory fits above):\n"
        );
        let mut line = Vec::new();
        for t in &pooled {
            let _ = writeln!(
                report,
                "- `{}`: {:.4e} {} (95 % interval {:.4e} to {:.4e})",
                t.name, t.estimate, t.unit, t.ci_low, t.ci_high
            );
            line.push(format!("{} {:.3e} {}", t.name, t.estimate, t.unit));
        }
        let _ = writeln!(
            text,
            "envelopes pooled over the {} runs: {}",
            runs.len(),
            line.join(", ")
        );
    }
    let _ = writeln!(
        report,
        "\n## Tables and figures\n\n- `diagnosis.parquet`: every candidate per run, with its verdict\n- `params.parquet`: each run's base and best model, parameters with 95 % intervals\n- `runs.parquet`: per run, samples, turning points, held-out E_θ of each model\n- `signatures.parquet`: loss per cycle by amplitude band, measured and as each model predicts it\n- `envelopes.parquet`: every turning point's amplitude and loss per cycle\n\n![signatures.png](signatures.png)\n\n![envelopes.png](envelopes.png)\n"
    );
    let report_path = out.join("report.md");
    std::fs::write(&report_path, report).map_err(|source| JobError::Io {
        path: report_path.clone(),
        source,
    })?;
    let _ = writeln!(text, "report: {}", report_path.display());
    Ok(DiscoverSummary {
        out_dir: out.clone(),
        report: report_path,
        discovery: Discovery {
            damping_check: None,
            base: pendulum_process::identify::FitOutcome {
                spec: pendulum_process::fit::ModelSpec::linear(),
                params: Vec::new(),
                f_obj: f64::NAN,
                e_theta: f64::NAN,
                generations: 0,
                evaluations: 0,
                abandoned: 0,
                stop_reason: "free decay".into(),
                wall_s: 0.0,
                seed: 0,
                np: 0,
                convergence: Vec::new(),
                runs: Vec::new(),
                polished: None,
                alignments: Default::default(),
            },
            extended: None,
            rows: Vec::new(),
            weak: Vec::new(),
            weak_runs: Vec::new(),
            residual_base: Vec::new(),
            residual_final: Vec::new(),
            unexplained_description: None,
            validation_base: Vec::new(),
            validation_final: Vec::new(),
            unexplained: None,
            forcing_not_understood: Vec::new(),
        },
        decays,
        envelopes: envs.into_iter().map(|e| (e.run, e.env)).collect(),
        pooled,
        text,
    })
}

/// A free decay's base terms and the candidates screened against them, for each `--base`:
/// the same three models as a shaker campaign's (reference = a, b, μ; linear = b; dry = μ), each
/// candidate being a catalogue loss the base lacks.
fn decay_terms(base: Base) -> (Vec<pendulum_explain::Term>, Vec<pendulum_explain::Term>) {
    use pendulum_explain::Term;
    let base_terms = match base {
        Base::Reference => vec![
            Term::ViscousLinear,
            Term::ViscousQuadratic,
            Term::CoulombBearing,
        ],
        Base::Linear => vec![Term::ViscousLinear],
        Base::Dry => vec![Term::CoulombBearing],
    };
    // Catalogue order puts the simpler, commoner losses first (the screen prefers earlier ones
    // within noise of the best).
    let candidates = [
        Term::CoulombConstant,
        Term::ViscousLinear,
        Term::ViscousQuadratic,
        Term::CoulombBearing,
        // Tried only where the period does not follow the gravity law (issue 16 item 5).
        Term::Stiffness,
    ]
    .into_iter()
    .filter(|t| !base_terms.contains(t))
    .collect();
    (base_terms, candidates)
}

/// params.parquet, runs.parquet and signatures.parquet of a free-decay campaign: each run's base
/// and best model (parameters and their physical ratios, 95 % intervals), each run's held-out
/// scores, and the loss per cycle by amplitude band, measured and as each model predicts it.
fn write_decay_tables(
    out: &Path,
    opts: &pendulum_report::TableOptions,
    runs: &[pendulum_process::RunData],
    decays: &[(String, pendulum_explain::DecayDiagnosis)],
) -> Result<(), JobError> {
    let (mut p_run, mut p_model, mut p_terms, mut p_name, mut p_unit, mut p_kind) = (
        Vec::new(),
        Vec::new(),
        Vec::new(),
        Vec::new(),
        Vec::new(),
        Vec::new(),
    );
    let (mut p_est, mut p_lo, mut p_hi) = (Vec::new(), Vec::new(), Vec::new());
    for (id, d) in decays {
        for (model, fit) in [("base", &d.base), ("best", &d.best)] {
            for (kind, list) in [("fitted", &fit.params), ("physical", &fit.physical)] {
                for e in list {
                    p_run.push(id.clone());
                    p_model.push(model.to_string());
                    p_terms.push(fit.terms.join("+"));
                    p_kind.push(kind.to_string());
                    p_name.push(e.name.clone());
                    p_unit.push(e.unit.clone());
                    p_est.push(e.estimate);
                    p_lo.push(e.ci_low);
                    p_hi.push(e.ci_high);
                }
            }
        }
    }
    opts.write(
        &out.join("params.parquet"),
        &[
            Column::new("run_id", ColumnData::Str(p_run)),
            Column::new("model", ColumnData::Str(p_model)),
            Column::new("terms", ColumnData::Str(p_terms)),
            Column::new("kind", ColumnData::Str(p_kind)),
            Column::new("param", ColumnData::Str(p_name)),
            Column::f64("estimate", "see column unit", p_est),
            Column::f64("ci_low", "see column unit", p_lo),
            Column::f64("ci_high", "see column unit", p_hi),
            Column::new("unit", ColumnData::Str(p_unit)),
        ],
    )?;

    let score = |d: &pendulum_explain::DecayDiagnosis, prefix: &str| {
        d.heldout
            .iter()
            .find(|h| h.model.starts_with(prefix))
            .map_or(f64::NAN, |h| h.e_theta_rad)
    };
    let role = |id: &str| {
        runs.iter()
            .find(|r| r.id == id)
            .map_or(String::new(), |r| r.role.as_str().to_string())
    };
    let col = |f: &dyn Fn(&pendulum_explain::DecayDiagnosis) -> f64| -> Vec<f64> {
        decays.iter().map(|(_, d)| f(d)).collect()
    };
    opts.write(
        &out.join("runs.parquet"),
        &[
            Column::new(
                "run_id",
                ColumnData::Str(decays.iter().map(|(id, _)| id.clone()).collect()),
            ),
            Column::new(
                "role",
                ColumnData::Str(decays.iter().map(|(id, _)| role(id)).collect()),
            ),
            Column::new(
                "alignment",
                ColumnData::Str(decays.iter().map(|_| "free_decay".to_string()).collect()),
            ),
            Column::f64("samples", "1", col(&|d| d.samples as f64)),
            Column::f64("duration_s", "s", col(&|d| d.duration_s)),
            Column::f64("turning_points", "1", col(&|d| d.turning_points as f64)),
            Column::f64("t_motion_from_s", "s", col(&|d| d.t_motion_from_s)),
            Column::f64("t_motion_to_s", "s", col(&|d| d.t_motion_to_s)),
            Column::f64(
                "t_split_s",
                "s (fitted before, scored after)",
                col(&|d| d.t_split_s),
            ),
            Column::f64("noise_rad", "rad", col(&|d| d.envelope.noise_rad)),
            Column::f64("e_theta_heldout_base", "rad", col(&|d| score(d, "base"))),
            Column::f64(
                "e_theta_heldout_best",
                "rad (NaN: nothing added)",
                col(&|d| score(d, "best")),
            ),
            Column::new(
                "accepted",
                ColumnData::Str(decays.iter().map(|(_, d)| d.accepted.join("+")).collect()),
            ),
        ],
    )?;

    let (mut s_run, mut from, mut to, mut mean, mut cycles) =
        (Vec::new(), Vec::new(), Vec::new(), Vec::new(), Vec::new());
    let (mut meas, mut se, mut base, mut best) = (Vec::new(), Vec::new(), Vec::new(), Vec::new());
    for (id, d) in decays {
        for b in &d.loss_bands {
            s_run.push(id.clone());
            from.push(b.amplitude_from_rad);
            to.push(b.amplitude_to_rad);
            mean.push(b.amplitude_mean_rad);
            cycles.push(b.cycles as f64);
            meas.push(b.measured_rad);
            se.push(b.measured_se_rad);
            base.push(b.base_model_rad);
            best.push(b.best_model_rad);
        }
    }
    opts.write(
        &out.join("signatures.parquet"),
        &[
            Column::new("run_id", ColumnData::Str(s_run)),
            Column::f64("amplitude_from", "rad", from),
            Column::f64("amplitude_to", "rad", to),
            Column::f64("amplitude_mean", "rad", mean),
            Column::f64("cycles", "1", cycles),
            Column::f64("loss_per_cycle_measured", "rad", meas),
            Column::f64("loss_per_cycle_measured_se", "rad", se),
            Column::f64("loss_per_cycle_base", "rad (full-record fit)", base),
            Column::f64("loss_per_cycle_best", "rad (full-record fit)", best),
        ],
    )?;
    Ok(())
}

/// What a free decay's models get wrong, against amplitude: each run's measured loss per cycle
/// (points, by amplitude band) beside the base model's (line) and the
/// best model's prediction, in one panel per run (at most six).
fn loss_plot(
    path: &Path,
    decays: &[(String, pendulum_explain::DecayDiagnosis)],
    base: &str,
) -> Result<(), JobError> {
    let panels: Vec<Panel> = decays
        .iter()
        .take(6)
        .map(|(id, d)| {
            let pick = |f: &dyn Fn(&pendulum_explain::LossBand) -> f64| -> Vec<f64> {
                d.loss_bands.iter().map(f).collect()
            };
            let x = pick(&|b| b.amplitude_mean_rad);
            Panel {
                title: format!("run {id}: best = {}", d.best.terms.join(" + ")),
                x_label: "amplitude (rad)".into(),
                y_label: "loss per cycle (rad)".into(),
                series: vec![
                    Series {
                        label: "measured".into(),
                        x: x.clone(),
                        y: pick(&|b| b.measured_rad),
                        style: SeriesStyle::Points,
                        color: Some(0),
                    },
                    Series {
                        label: format!("base ({base})"),
                        x: x.clone(),
                        y: pick(&|b| b.base_model_rad),
                        style: SeriesStyle::Line,
                        color: Some(1),
                    },
                    Series {
                        label: "best".into(),
                        x,
                        y: pick(&|b| b.best_model_rad),
                        style: SeriesStyle::LinePoints,
                        color: Some(2),
                    },
                ],
                ..Panel::default()
            }
        })
        .collect();
    let fig = Figure {
        title: "Free decays: loss per cycle against amplitude, measured and modelled".into(),
        height: 400 * panels.len().max(1) as u32,
        panels,
        width: 1200,
    };
    fig.save_png(path)?;
    Ok(())
}

fn e(v: &[pendulum_process::identify::RunFit]) -> f64 {
    v.iter().map(|r| r.e_theta).sum()
}

/// envelopes.parquet: one row per turning point of each run's free segment.
fn write_envelopes(
    path: &Path,
    opts: &pendulum_report::TableOptions,
    envs: &[SegmentEnvelope],
) -> Result<(), JobError> {
    let (mut run, mut role, mut shape) = (Vec::new(), Vec::new(), Vec::new());
    let (mut n, mut t, mut amp, mut mid, mut loss) =
        (Vec::new(), Vec::new(), Vec::new(), Vec::new(), Vec::new());
    for e in envs {
        let Ok(env) = &e.env else { continue };
        for r in &env.rows {
            run.push(e.run.clone());
            role.push(e.role.as_str().to_string());
            shape.push(env.shape.clone());
            n.push(r.n as f64);
            t.push(r.t_s);
            amp.push(r.amplitude_rad);
            mid.push(r.mid_amplitude_rad.unwrap_or(f64::NAN));
            loss.push(r.loss_per_cycle_rad.unwrap_or(f64::NAN));
        }
    }
    opts.write(
        path,
        &[
            Column::new("run_id", ColumnData::Str(run)),
            Column::new("role", ColumnData::Str(role)),
            Column::f64("turning_point", "1 (half swing number)", n),
            Column::f64("t_s", "s (capture clock)", t),
            Column::f64("amplitude", "rad (from the swing's centre)", amp),
            Column::f64("mid_amplitude", "rad", mid),
            Column::f64("loss_per_cycle", "rad", loss),
            Column::new("shape", ColumnData::Str(shape)),
        ],
    )?;
    Ok(())
}

/// Amplitude against time and loss per cycle against amplitude, one colour per run.
fn envelope_plot(path: &Path, envs: &[SegmentEnvelope], title: &str) -> Result<(), JobError> {
    let ok: Vec<(&str, &pendulum_explain::EnvelopeFit)> = envs
        .iter()
        .filter_map(|e| e.env.as_ref().ok().map(|f| (e.run.as_str(), f)))
        .collect();
    let series = |f: &dyn Fn(&pendulum_explain::EnvelopeRow) -> (f64, f64), style: SeriesStyle| {
        ok.iter()
            .enumerate()
            .map(|(i, (id, env))| {
                let (x, y): (Vec<f64>, Vec<f64>) = env
                    .rows
                    .iter()
                    .map(f)
                    .filter(|(x, y)| x.is_finite() && y.is_finite())
                    .unzip();
                Series {
                    label: id.to_string(),
                    x,
                    y,
                    style,
                    color: Some(i),
                }
            })
            .collect::<Vec<_>>()
    };
    let fig = Figure {
        title: title.into(),
        panels: vec![
            Panel {
                title: "amplitude at each turning point".into(),
                x_label: "t (s, capture clock)".into(),
                y_label: "amplitude (rad)".into(),
                series: series(&|r| (r.t_s, r.amplitude_rad), SeriesStyle::Line),
                ..Panel::default()
            },
            Panel {
                title: "loss per cycle against amplitude (flat: dry friction; rising straight: viscous; parabola: quadratic)".into(),
                x_label: "amplitude (rad)".into(),
                y_label: "loss per cycle (rad)".into(),
                series: series(
                    &|r| {
                        (
                            r.mid_amplitude_rad.unwrap_or(f64::NAN),
                            r.loss_per_cycle_rad.unwrap_or(f64::NAN),
                        )
                    },
                    SeriesStyle::Points,
                ),
                ..Panel::default()
            },
        ],
        width: 1200,
        height: 900,
    };
    fig.save_png(path)?;
    Ok(())
}

fn signature_plot(path: &Path, d: &Discovery) -> Result<(), JobError> {
    let idm: Vec<usize> = (0..d.weak.len())
        .filter(|&i| d.weak_runs[d.weak[i].run].1 == Role::Identify)
        .collect();
    let pts = |key: &dyn Fn(usize) -> f64, res: &[f64], label: &str, color: usize| Series {
        label: label.into(),
        x: idm.iter().map(|&i| key(i)).collect(),
        y: idm.iter().map(|&i| res[i]).collect(),
        style: SeriesStyle::Points,
        color: Some(color),
    };
    let panel = |title: &str, xl: &str, key: &dyn Fn(usize) -> f64| Panel {
        title: title.into(),
        x_label: xl.into(),
        y_label: "unexplained torque / (m·g·l)".into(),
        series: vec![
            pts(key, &d.residual_base, "base model", 1),
            pts(key, &d.residual_final, "final model", 0),
        ],
        ..Panel::default()
    };
    let fig = Figure {
        title: "Unexplained torque (weak-form equation error), identify runs".into(),
        panels: vec![
            panel(
                "against angular velocity (dry friction: a step at dθ/dt = 0)",
                "dθ/dt (rad/s)",
                &|i| d.weak[i].theta_dot_rad_s,
            ),
            panel(
                "against angle (position torque: a sinusoid in θ)",
                "θ mod 2π (rad)",
                &|i| d.weak[i].theta.rem_euclid(2.0 * std::f64::consts::PI),
            ),
            panel(
                "against forcing phase (excitation errors)",
                "crank phase (rad)",
                &|i| d.weak[i].phase,
            ),
        ],
        width: 1200,
        height: 1200,
    };
    fig.save_png(path)?;
    Ok(())
}

fn write_report(
    path: &Path,
    job: &DiscoverJob,
    d: &Discovery,
    table: &str,
    plots: &[PathBuf],
    ctx: &Context,
    envs: &[SegmentEnvelope],
) -> Result<(), JobError> {
    let mut r = String::new();
    let _ = writeln!(r, "# What the {} model gets wrong\n", job.base.name());
    let _ = writeln!(
        r,
        "Campaign: `{}` ({} runs: {} identify, {} validate).\n",
        job.input.display(),
        ctx.runs.len(),
        ctx.runs.iter().filter(|x| x.role == Role::Identify).count(),
        ctx.runs.iter().filter(|x| x.role == Role::Validate).count()
    );
    let _ = writeln!(r, "## Base model\n");
    for (p, v) in d.base.spec.params.iter().zip(&d.base.params) {
        let _ = writeln!(r, "- {} = {:.5} {}", p.name(), v, p.unit());
    }
    if let Some(note) = d
        .damping_check
        .as_ref()
        .and_then(|c| c.note(&d.base.spec, &d.base.params))
    {
        let _ = writeln!(r, "\n**{}.** {}.", note.0, note.1);
    }
    let _ = writeln!(r, "\n## Diagnosis\n\nOne row per catalogue candidate screened (ΔBIC of the weak-form equation error on the identify runs); the best are refitted on the trajectories and accepted only if their 95 % interval excludes zero and the error on the validate runs, which neither the screen nor the refit saw, falls by more than chance explains: E_θ by more than max(2 %, its noise), or the equation error by more than max(5 %, its noise) while E_θ does not rise by more than its noise. Where the validate runs' equation error could see the candidate (the fall it would show were the candidate true at the screen's size clears its bar) but does not confirm it, E_θ's fall must be twice its bar, and any rise of that equation error refuses it; where it could not, it neither confirms nor contradicts. A fall's noise is 1.96 × its standard error from the paired differences of the validate runs' 0.5 s shooting segments (E_θ) or weak-form windows (equation error); `gain ± noise` and `eq gain` in the table. Two more conditions: the estimate is physically possible (no negative damping, dry torque or inertia), and the trajectory refit (`refit`) agrees with the screen's estimate, within its interval or 10 %, whichever is wider.\n\n```\n{table}```\n");
    // Why each judged candidate was named or not: the table says only yes or no, and a reader
    // who expected an effect must see which condition it failed (the same notes as
    // `diagnosis.parquet`'s `note`; a candidate the screen passed over says only that).
    let judged: Vec<&pendulum_discover::DiagnosisRow> = d
        .rows
        .iter()
        .filter(|row| {
            row.accepted || row.heldout_gain.is_finite() || row.heldout_eq_gain.is_finite()
        })
        .collect();
    if !judged.is_empty() {
        let _ = writeln!(
            r,
            "Why each candidate judged on the held-out runs was named or not:\n"
        );
        for row in judged {
            let _ = writeln!(
                r,
                "- `{}`: {}. {}.",
                row.effect,
                if row.accepted { "named" } else { "not named" },
                row.note.trim_end_matches('.')
            );
        }
        let _ = writeln!(r);
    }
    if !d.forcing_not_understood.is_empty() {
        let _ = writeln!(r, "**Forcing not understood.** The crank-rod model, with the crank phase tracked turn by turn, does not explain the accelerometer of these runs (residual over {} × the sensor's own noise, measured while the shaker was off); their forced segments were left out of the equation-error view and their crank fits out of the sensor and drive effects (`forcing_understood` in `runs.parquet`):\n", pendulum_process::align::FORCING_MISFIT_RATIO);
        for (id, res, noise) in &d.forcing_not_understood {
            let _ = writeln!(
                r,
                "- `{id}`: residual {res:.3} m/s² RMS, noise {noise:.3} m/s²"
            );
        }
        let _ = writeln!(r);
    }
    match &d.unexplained {
        Some(u) => {
            let _ = writeln!(r, "**Unexplained:** {u}.\n");
        }
        None => {
            // The variables as the analysis bins them.
            let v = pendulum_discover::campaign_variables();
            let variables = match v.split_last() {
                Some((last, rest)) if !rest.is_empty() => format!("{} or {last}", rest.join(", ")),
                _ => v.join(""),
            };
            let _ = writeln!(r, "No structure is left in the equation error against {variables} that rows the fit did not see confirm (a one-way F on the identify runs' rows with p < 1e-6, whose bin means take more than max(5 %, its noise) off the equation error of the validate runs' rows and of each identify run's from the others' means), and the generic description finds none the validate runs confirm.\n");
        }
    }
    if let Some(ext) = &d.extended {
        let _ = writeln!(r, "## Extended model `{}`\n", ext.spec.name);
        for (p, v) in ext.spec.params.iter().zip(&ext.params) {
            let _ = writeln!(r, "- {} = {:.5} {}", p.name(), v, p.unit());
        }
    }
    if !envs.is_empty() {
        let _ = writeln!(r, "\n## Free-decay segments\n\nEach run swings freely before its shaker starts. How the swing's amplitude decays says which losses dominate: a constant loss per cycle (linear decay) is dry friction, a loss proportional to the amplitude (exponential decay) is viscous, one growing with the amplitude squared (1/n-like) is quadratic drag (`envelopes.parquet`, `envelopes.png`).\n");
        let fits = envelope_fits(envs, ctx);
        let pooled = pooled_envelope(&fits);
        if !pooled.is_empty() {
            let _ = writeln!(
                r,
                "Pooled over the {} segments, the loss per cycle is best explained (lowest BIC among the catalogue's exact pendulum loss curves, non-negative, each interval excluding zero) by:\n",
                fits.len()
            );
            for t in &pooled {
                let _ = writeln!(
                    r,
                    "- `{}`: {:.4e} {} (95 % interval {:.4e} to {:.4e})",
                    t.name, t.estimate, t.unit, t.ci_low, t.ci_high
                );
            }
            let _ = writeln!(
                r,
                "\nThe envelope is a coarse view: a load-dependent dry friction loses per cycle much like a constant dry torque plus an amplitude-squared term, so these three are hard to tell apart from the envelope alone (in the twin's demo campaign, with bearing friction and no drag, it names a constant dry torque and quadratic drag). The equation-error screen above is the sharper test.\n\nRun by run (5–9 cycles each, so the shapes are rougher still):\n"
            );
        }
        let _ = writeln!(
            r,
            "| run | turning points | amplitude (rad) | shape |\n|---|---|---|---|"
        );
        for e in envs {
            match &e.env {
                Ok(env) => {
                    let first = env.rows.first().map_or(f64::NAN, |x| x.amplitude_rad);
                    let last = env.rows.last().map_or(f64::NAN, |x| x.amplitude_rad);
                    let _ = writeln!(
                        r,
                        "| {} | {} | {first:.3} → {last:.3} | {} |",
                        e.run,
                        env.rows.len(),
                        env.shape
                    );
                }
                Err(why) => {
                    let _ = writeln!(r, "| {} | - | - | not read: {why} |", e.run);
                }
            }
        }
    }
    let _ = writeln!(r, "\n## Held-out runs\n\n| run | E_θ base | E_θ final | steady measured | base | final |\n|---|---|---|---|---|---|");
    for (b, f) in d.validation_base.iter().zip(&d.validation_final) {
        let _ = writeln!(
            r,
            "| {} | {:.4} | {:.4} | {} | {} | {} |",
            b.id,
            b.e_theta,
            f.e_theta,
            b.measured,
            b.simulated.map_or("-".into(), |s| s.to_string()),
            f.simulated.map_or("-".into(), |s| s.to_string())
        );
    }
    let _ = writeln!(r, "\n## Figures\n");
    for p in plots {
        if let Some(name) = p.file_name() {
            let _ = writeln!(r, "![{0}]({0})\n", name.to_string_lossy());
        }
    }
    std::fs::write(path, r).map_err(|source| JobError::Io {
        path: path.to_path_buf(),
        source,
    })
}

/// Every run's free segment before its shaker starts (at least
/// [`crate::identify::FREE_SEGMENT_MIN_S`]), aligned, started and prepared as free decays by the
/// pipeline's own stages (not its fit), then as runs of the shaker model with the crank still
/// ([`pendulum_process::fit::PreparedRun::unforced`]): discover's trajectory refits see the
/// damping over the identify runs' widest swings, and a named effect's value refitted on every
/// run sees the validate runs' too. A segment the stages cannot read, or whose preparation
/// fails, is left out (the second value: a note per segment the stages refused).
pub fn free_segments(
    ctx: &Context,
    stages: &PipelineConfig,
    cfg: &DiscoverConfig,
) -> (Vec<pendulum_process::fit::PreparedRun>, Vec<String>) {
    let runs = crate::identify::free_segment_runs(ctx);
    let (kept, left_out) = crate::identify::prepared_free_segments(runs, stages);
    let mut out = Vec::new();
    for fctx in &kept {
        for run in &fctx.runs {
            // (A run the user named "warm-free" is "warm-free-free" here.)
            let parent = pendulum_process::run::parent_run_id(&run.id);
            let Some(omega_hz) = (parent != run.id)
                .then(|| ctx.alignments.get(parent))
                .flatten()
                .map(|a| a.omega_hz)
            else {
                continue;
            };
            let (Some(al), Some(ic), Some(st)) = (
                fctx.alignments.get(&run.id),
                fctx.initial.get(&run.id),
                fctx.steady.get(&run.id),
            ) else {
                continue;
            };
            let Ok(p) = pendulum_process::identify::prepare_run(
                run,
                al,
                ic,
                st,
                &fctx.steady_cfg,
                &cfg.validate.window,
            ) else {
                continue;
            };
            out.extend(p.unforced(omega_hz));
        }
    }
    (out, left_out)
}

#[cfg(test)]
mod pct_tests {
    use super::pct;

    #[test]
    fn a_gain_far_below_anything_physical_keeps_the_tables_width() {
        assert_eq!(pct(0.532), "53.2%");
        assert_eq!(pct(-9.0), "-900.0%");
        assert_eq!(pct(-3.7e10), "<-999%");
        assert_eq!(pct(f64::NAN), "-");
        assert!(pct(-9.99).len() <= 8);
    }
}
