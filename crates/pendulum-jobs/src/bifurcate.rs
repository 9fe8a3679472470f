//! `pendulum bifurcate`: a bifurcation diagram of one model over a parameter sweep (usually ω),
//! from a grid of initial states or by continuation; `bifurcation.parquet` (the Poincaré points
//! and their class) and PNGs in the manner of the study's Figs. 8–9.
//!
//! Also home of what the sweep commands share: the model options ([`ModelArgs`]: `--param`,
//! `--params FILE --model NAME`, `--study`), the initial-state options ([`IcArgs`]) and the
//! simulation options ([`RunArgs`]).

use std::path::{Path, PathBuf};
use std::time::Instant;

use indicatif::{ProgressBar, ProgressStyle};
use pendulum_maps::bifurcation::{self, Bifurcation, BifurcationConfig, Mode};
use pendulum_maps::params_file::load_model;
use pendulum_maps::{IcSpec, MapsError, Sweep};
use pendulum_model::{ClassifyOptions, Dimensionless, ParamSpec, Physical, SimOptions};

use crate::inputs::Inputs;
use crate::merge::Ran;
use crate::JobError;

impl From<MapsError> for JobError {
    fn from(e: MapsError) -> Self {
        match e {
            MapsError::Model(e) => JobError::Model(e),
            MapsError::Report(e) => JobError::Report(e),
            MapsError::Plot(e) => JobError::Plot(e),
            MapsError::Io { path, source } => JobError::Io { path, source },
            other => JobError::Invalid(other.to_string()),
        }
    }
}

/// The study's two damping models, by name.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum Study {
    /// Dry friction (Fig. 8): R = 0.7, λ = 0.126, α = 0, β = 0.109, M = 0.007.
    Reference,
    /// Linear damping (Fig. 9): R = 0.7, λ = 0.126, α = 0, β = 0.066, M = 0.
    Linear,
}

impl Study {
    pub fn name(self) -> &'static str {
        match self {
            Study::Reference => "reference",
            Study::Linear => "linear",
        }
    }

    /// The model as `key=value` assignments (ω is left to the rig default or the sweep).
    pub fn assignments(self) -> Vec<String> {
        let [reference, linear] = crate::demo::study_models(1.0);
        let d = match self {
            Study::Reference => reference.1,
            Study::Linear => linear.1,
        };
        vec![
            format!("R={}", d.r),
            format!("lambda={}", d.lambda),
            format!("alpha={}", d.alpha),
            format!("beta={}", d.beta),
            format!("M={}", d.m_coulomb),
        ]
    }
}

/// Which model to simulate.
#[derive(Debug, Clone, Default, clap::Args)]
pub struct ModelArgs {
    /// A parameter, `key=value`, as in `pendulum simulate`: dimensionless omega, R, lambda,
    /// alpha, beta, M; physical m_kg, l_m, crank_r_m, rod_L_m, r_b_m, omega_hz, g_m_s2, a, b, mu;
    /// effects such as coulomb_constant.T_c. Applied after --study / --params. Repeatable.
    #[arg(long = "param", value_name = "KEY=VALUE")]
    pub param: Vec<String>,
    /// A params.parquet written by `pendulum identify`; the row of --model is used.
    #[arg(long = "params", value_name = "FILE", requires = "model")]
    pub params_file: Option<PathBuf>,
    /// Model name (a row of --params), e.g. reference or linear.
    #[arg(long, value_name = "NAME", requires = "params_file")]
    pub model: Option<String>,
    /// Start from one of the study's models (reference: dry friction, Fig. 8; linear: Fig. 9).
    #[arg(long, value_enum, conflicts_with = "params_file")]
    pub study: Option<Study>,
}

/// A model resolved from [`ModelArgs`].
#[derive(Debug, Clone)]
pub struct ResolvedModel {
    /// reference / linear / the --model name / `custom`.
    pub label: String,
    /// Every assignment, in the order applied.
    pub assignments: Vec<String>,
    pub physical: Physical,
    pub params: Dimensionless,
}

/// Resolves a list of assignments like `--param` does.
pub fn resolve_assignments(
    label: &str,
    assignments: Vec<String>,
) -> Result<ResolvedModel, JobError> {
    let (physical, params) = ParamSpec::parse(&assignments)?.resolve(&Physical::default())?;
    Ok(ResolvedModel {
        label: label.to_string(),
        assignments,
        physical,
        params,
    })
}

impl ModelArgs {
    /// The assignments in order (study or params row first, then --param) and the label.
    pub fn assignments(&self) -> Result<(String, Vec<String>), JobError> {
        let mut a = Vec::new();
        let mut label = "custom".to_string();
        if let Some(s) = self.study {
            a.extend(s.assignments());
            label = s.name().to_string();
        }
        if let (Some(path), Some(name)) = (&self.params_file, &self.model) {
            a.extend(load_model(path, name)?.assignments(true));
            label = name.clone();
        }
        a.extend(self.param.iter().cloned());
        Ok((label, a))
    }

    pub fn resolve(&self) -> Result<ResolvedModel, JobError> {
        let (label, a) = self.assignments()?;
        resolve_assignments(&label, a)
    }
}

/// Initial states.
#[derive(Debug, Clone, clap::Args)]
pub struct IcArgs {
    /// Grid of initial states, θ0 points × θ̇0 points: θ0 ∈ [−π, π), θ̇0 ∈ [−w, w]
    /// (w = --theta-dot-max). Default 8x8 when no other choice is given.
    #[arg(long = "ic-grid", value_name = "NxM", conflicts_with_all = ["ic_random", "ic"])]
    pub ic_grid: Option<String>,
    /// N random initial states, uniform over the grid's box, drawn from --seed.
    #[arg(long = "ic-random", value_name = "N", conflicts_with = "ic")]
    pub ic_random: Option<usize>,
    /// Seed of --ic-random.
    #[arg(long, default_value_t = 0)]
    pub seed: u64,
    /// One initial state `THETA,THETA_DOT` (rad, dimensionless). Repeatable.
    #[arg(
        long = "ic",
        value_name = "THETA,THETA_DOT",
        allow_hyphen_values = true
    )]
    pub ic: Vec<String>,
    /// Half-width of the θ̇0 range of --ic-grid / --ic-random (dimensionless).
    #[arg(long = "theta-dot-max", default_value_t = 3.0)]
    pub theta_dot_max: f64,
}

impl Default for IcArgs {
    fn default() -> Self {
        Self {
            ic_grid: None,
            ic_random: None,
            seed: 0,
            ic: Vec::new(),
            theta_dot_max: 3.0,
        }
    }
}

impl IcArgs {
    pub fn spec(&self, default_grid: &str) -> Result<IcSpec, JobError> {
        let spec = if !self.ic.is_empty() {
            IcSpec::List(
                self.ic
                    .iter()
                    .map(|s| IcSpec::parse_pair(s))
                    .collect::<Result<_, _>>()?,
            )
        } else if let Some(n) = self.ic_random {
            IcSpec::Random {
                n,
                seed: self.seed,
                theta_dot_max: self.theta_dot_max,
            }
        } else {
            IcSpec::parse_grid(
                self.ic_grid.as_deref().unwrap_or(default_grid),
                self.theta_dot_max,
            )?
        };
        spec.validate()?;
        Ok(spec)
    }
}

/// Simulation lengths and execution.
#[derive(Debug, Clone, clap::Args)]
pub struct RunArgs {
    /// Transient, in forcing periods, simulated before the Poincaré points are recorded.
    #[arg(long, default_value_t = 300)]
    pub transient: u32,
    /// Recorded forcing periods (one Poincaré point each; 32 or more to find period 16).
    #[arg(long, default_value_t = 50)]
    pub record: u32,
    /// Integrator tolerance (relative and absolute).
    #[arg(long, default_value_t = 1e-8)]
    pub tol: f64,
    /// Worker threads (default: all cores).
    #[arg(long)]
    pub threads: Option<usize>,
    /// No progress bar.
    #[arg(long)]
    pub quiet: bool,
}

impl Default for RunArgs {
    fn default() -> Self {
        Self {
            transient: 300,
            record: 50,
            tol: 1e-8,
            threads: None,
            quiet: false,
        }
    }
}

impl RunArgs {
    pub fn sim(&self) -> Result<SimOptions, JobError> {
        if !(self.tol.is_finite() && self.tol > 0.0 && self.tol < 1e-2) {
            return Err(JobError::Invalid(format!(
                "--tol {}: expected a tolerance in (0, 0.01)",
                self.tol
            )));
        }
        Ok(SimOptions::with_tol(self.tol))
    }
}

/// A progress bar over `total` simulations (hidden when `show` is false or stderr is not a
/// terminal).
pub(crate) fn progress_bar(total: u64, what: &str, show: bool) -> ProgressBar {
    if !show {
        return ProgressBar::hidden();
    }
    let b = ProgressBar::new(total);
    b.set_style(
        ProgressStyle::with_template(&format!(
            "{what} {{bar:30}} {{pos}}/{{len}} simulations, {{elapsed}} elapsed, ~{{eta}} left"
        ))
        .unwrap_or_else(|_| ProgressStyle::default_bar()),
    );
    b
}

/// Creates OUT, checks it is writable and sweeps this program's stale temporary files from it
/// ([`crate::outputs::prepare_out_dir`]).
pub(crate) fn create_dir(dir: &Path) -> Result<(), JobError> {
    crate::outputs::prepare_out_dir(dir).map(drop)
}

/// `pendulum bifurcate` options.
#[derive(Debug, Clone, clap::Args)]
pub struct BifurcateArgs {
    #[command(flatten)]
    pub model: ModelArgs,
    /// The sweep: NAME=START:STOP:STEP (stop included), NAME=V1,V2,… or NAME=V; NAME one of
    /// omega, R, lambda, alpha, beta, M.
    #[arg(long, value_name = "NAME=START:STOP:STEP")]
    pub sweep: String,
    #[command(flatten)]
    pub ics: IcArgs,
    /// Continuation: each initial state starts a chain swept up and one swept down, every value
    /// starting from the attractor the previous value reached.
    #[arg(long)]
    pub continuation: bool,
    #[command(flatten)]
    pub run: RunArgs,
    #[command(flatten)]
    pub shard: crate::merge::ShardArgs,
    /// Output folder (bifurcation.parquet, bifurcation.png, bifurcation_classes.png; with
    /// --shard, shard=I/part.parquet and shard=I/manifest.json).
    #[arg(long, value_name = "DIR")]
    pub out: PathBuf,
}

/// What `pendulum bifurcate` did.
#[derive(Debug, Clone)]
pub struct BifurcateSummary {
    pub label: String,
    pub result: Bifurcation,
    pub ic_description: String,
    pub wall_s: f64,
    pub table: PathBuf,
    pub rows: usize,
    pub figures: Vec<PathBuf>,
}

/// Maximal runs of consecutive sweep values where `pred` holds, as (first, last) values.
pub(crate) fn runs_of(values: &[f64], pred: impl Fn(usize) -> bool) -> Vec<(f64, f64)> {
    let mut out = Vec::new();
    let mut start: Option<usize> = None;
    for i in 0..=values.len() {
        let on = i < values.len() && pred(i);
        match (on, start) {
            (true, None) => start = Some(i),
            (false, Some(s)) => {
                out.push((values[s], values[i - 1]));
                start = None;
            }
            _ => {}
        }
    }
    out
}

pub(crate) fn fmt_ranges(r: &[(f64, f64)]) -> String {
    r.iter()
        .map(|&(a, b)| {
            if a == b {
                format!("{a}")
            } else {
                format!("{a}–{b}")
            }
        })
        .collect::<Vec<_>>()
        .join(", ")
}

impl std::fmt::Display for BifurcateSummary {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let c = &self.result.config;
        let p = c.sweep.param.name();
        writeln!(
            f,
            "bifurcate {} model, {}: {}; {}{}, {} + {} periods: {} simulations in {:.1} s",
            self.label,
            pendulum_maps::style::describe_params(&c.base, Some(p)),
            c.sweep.describe(),
            self.ic_description,
            if c.mode == Mode::Continuation {
                " (continuation up and down)"
            } else {
                ""
            },
            c.transient_periods,
            c.record_periods,
            c.tasks(),
            self.wall_s
        )?;
        let summary = self.result.summary(None);
        let values: Vec<f64> = summary.iter().map(|s| s.value).collect();
        let rot = runs_of(&values, |i| summary[i].rotation_fraction() > 0.0);
        if rot.is_empty() {
            writeln!(f, "  no rotation anywhere in the sweep")?;
        } else {
            let best = summary
                .iter()
                .max_by(|a, b| a.rotation_fraction().total_cmp(&b.rotation_fraction()))
                .map(|s| (s.value, s.rotation_fraction()))
                .unwrap_or((f64::NAN, 0.0));
            writeln!(
                f,
                "  rotation at {} of {} values: {p} in {} (most: {:.0} % of starts at {p} = {})",
                summary
                    .iter()
                    .filter(|s| s.rotation_fraction() > 0.0)
                    .count(),
                summary.len(),
                fmt_ranges(&rot),
                100.0 * best.1,
                best.0
            )?;
        }
        let mut totals = [0usize; 5];
        for s in &summary {
            for (t, n) in totals.iter_mut().zip(s.counts) {
                *t += n;
            }
        }
        let parts: Vec<String> = pendulum_model::SteadyClass::ALL
            .iter()
            .zip(totals)
            .map(|(c, n)| format!("{} {n}", c.as_str()))
            .collect();
        writeln!(f, "  simulations ending in: {}", parts.join(", "))?;
        write!(f, "wrote {} ({} rows)", self.table.display(), self.rows)?;
        for p in &self.figures {
            write!(f, ", {}", p.display())?;
        }
        writeln!(f)
    }
}

/// Runs `pendulum bifurcate`: the whole sweep, or with `--shard` one shard of it.
pub fn run(a: &BifurcateArgs) -> Result<Ran<BifurcateSummary>, JobError> {
    let model = a.model.resolve()?;
    let sweep = Sweep::parse(&a.sweep)?;
    let ics = a.ics.spec("8x8")?;
    let mut cfg = BifurcationConfig::new(model.params, sweep, ics.starts());
    cfg.mode = if a.continuation {
        Mode::Continuation
    } else {
        Mode::Grid
    };
    cfg.transient_periods = a.run.transient;
    cfg.record_periods = a.run.record;
    cfg.sim = a.run.sim()?;
    cfg.classify = ClassifyOptions::default();
    cfg.threads = a.run.threads;
    cfg.power_scale_w = model.physical.power_scale_w();
    cfg.validate()?;
    let shard = a.shard.resolve()?;
    // Before the sweep: none of the outputs may replace the --params file.
    let mut inputs = Inputs::new();
    if let Some(p) = &a.model.params_file {
        inputs.add("--params", p);
    }
    let names: Vec<PathBuf> = match shard {
        Some(s) => [pendulum_maps::shard::PART, pendulum_maps::shard::MANIFEST]
            .iter()
            .map(|n| a.out.join(s.dir_name()).join(n))
            .collect(),
        None => [
            "bifurcation.parquet",
            "bifurcation.png",
            "bifurcation_classes.png",
        ]
        .iter()
        .map(|n| a.out.join(n))
        .collect(),
    };
    for p in &names {
        inputs.check_output("the output", p)?;
    }
    let extra = vec![
        ("command".to_string(), "pendulum bifurcate".to_string()),
        ("model".to_string(), model.label.clone()),
        ("assignments".to_string(), model.assignments.join(" ")),
        ("initial_states".to_string(), ics.describe()),
    ];
    if let Some(s) = shard {
        let job = crate::merge::BifurcateJob {
            config: cfg.clone(),
            label: model.label.clone(),
            ic_description: ics.describe(),
        };
        let empty = Bifurcation {
            config: cfg,
            outcomes: Vec::new(),
        };
        let mut md = empty.metadata();
        md.extend(extra);
        return Ok(Ran::Shard(crate::merge::bifurcate_shard(
            &job,
            &md,
            s,
            &a.out,
            !a.run.quiet,
        )?));
    }
    create_dir(&a.out)?;
    let bar = progress_bar(cfg.tasks(), "bifurcate", !a.run.quiet);
    let t = Instant::now();
    let result = bifurcation::run(&cfg, &|n| bar.inc(n))?;
    bar.finish_and_clear();
    let wall_s = t.elapsed().as_secs_f64();
    let table = a.out.join("bifurcation.parquet");
    let written = result.write_parquet(&table, &extra)?;
    let figures = write_figures(&result, &model.label, &a.out)?;
    Ok(Ran::Full(BifurcateSummary {
        label: model.label,
        result,
        ic_description: ics.describe(),
        wall_s,
        table,
        rows: written.rows,
        figures,
    }))
}

/// The diagram and the class fractions, `bifurcation.png` and `bifurcation_classes.png` in
/// `out` (one-machine run and merge alike).
pub(crate) fn write_figures(
    result: &Bifurcation,
    label: &str,
    out: &Path,
) -> Result<Vec<PathBuf>, JobError> {
    let title = result.default_title(label);
    let png = out.join("bifurcation.png");
    result.plot(&png, &title)?;
    let classes = out.join("bifurcation_classes.png");
    result.plot_fractions(&classes, &format!("Steady states along the sweep, {title}"))?;
    Ok(vec![png, classes])
}
