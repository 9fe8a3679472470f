//! Pipelines: a TOML file names stages by `type`; each stage's config validates and builds a
//! runtime object implementing [`Stage`], which reads and extends a shared [`Context`].
//!
//! ```toml
//! name = "identify"
//! [[stage]]
//! type = "align"
//! [[stage]]
//! type = "initial_conditions"
//! [[stage]]
//! type = "steady_state"
//! [[stage]]
//! type = "fit"
//! model = "reference"
//! ```

use std::collections::BTreeMap;
use std::path::Path;

use pendulum_model::SteadyState;
use serde::{Deserialize, Serialize};

use crate::align::{align, AlignConfig, Alignment};
use crate::ic::{estimate_state, hanging_position, IcConfig, InitialState};
use crate::identify::{
    identify, prepare_run, validate, FitConfig, FitOutcome, ProgressFn, RunFit, ValidateConfig,
};
use crate::measured::{free_steady_state, measured_steady_state, SteadyConfig};
use crate::run::{Role, RunData};
use crate::ProcessError;

/// What the stages know about the runs so far.
#[derive(Default)]
pub struct Context {
    pub runs: Vec<RunData>,
    pub alignments: BTreeMap<String, Alignment>,
    pub initial: BTreeMap<String, InitialState>,
    /// Hanging position seen by the encoder in the free decay (encoder-zero check), rad.
    pub hanging: BTreeMap<String, Option<f64>>,
    pub steady: BTreeMap<String, SteadyState>,
    pub steady_cfg: SteadyConfig,
    pub fits: Vec<FitOutcome>,
    /// Validation results, per fitted model name.
    pub validations: Vec<(String, Vec<RunFit>)>,
    /// A model given from outside (e.g. `--params`), validated by `validate` when no fit ran.
    pub given: Option<FitOutcome>,
    pub progress: Option<ProgressFn>,
    /// Human-readable notes (warnings) the stages leave.
    pub notes: Vec<String>,
    /// The fit windows the fit and validate stages sampled their runs with (for outputs that
    /// show the residual the fit minimised).
    pub fit_window: Option<crate::identify::Window>,
    pub validate_window: Option<crate::identify::Window>,
    /// Each run's angle resolution, rad, where its capture states it (`counts_per_rev`): it
    /// bounds the free-decay envelope the fit is checked against.
    pub resolutions: BTreeMap<String, f64>,
    /// Issue 16 item 4: the per-run fits of free decays that do not share ω0
    /// ([`crate::identify::per_run_fits`]), per fitted model name: run id → the run's own fit.
    /// Empty for a model whose runs share ω0 (and for shaker campaigns).
    pub per_run: BTreeMap<String, BTreeMap<String, FitOutcome>>,
}

impl Context {
    pub fn new(runs: Vec<RunData>) -> Self {
        Self {
            runs,
            ..Self::default()
        }
    }

    fn require<'a, T>(
        &self,
        map: &'a BTreeMap<String, T>,
        id: &str,
        what: &str,
        stage: &str,
    ) -> Result<&'a T, ProcessError> {
        map.get(id).ok_or_else(|| ProcessError::Run {
            run: id.to_string(),
            reason: format!("stage {stage} needs {what}: put that stage before it in the pipeline"),
        })
    }

    /// Prepared runs of a role for fitting.
    pub fn prepared(
        &self,
        role: Role,
        window: &crate::identify::Window,
        stage: &str,
    ) -> Result<Vec<crate::fit::PreparedRun>, ProcessError> {
        let mut out = Vec::new();
        for run in self.runs.iter().filter(|r| r.role == role) {
            let al = self.require(&self.alignments, &run.id, "the alignment", stage)?;
            let ic = self.require(&self.initial, &run.id, "initial conditions", stage)?;
            let st = self.require(&self.steady, &run.id, "the measured steady state", stage)?;
            out.push(prepare_run(run, al, ic, st, &self.steady_cfg, window)?);
        }
        Ok(out)
    }
}

/// A pipeline stage's runtime.
pub trait Stage: Send + Sync {
    fn name(&self) -> &'static str;
    fn run(&self, ctx: &mut Context) -> Result<(), ProcessError>;
}

/// The stage configs a pipeline file may name.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(tag = "type", rename_all = "snake_case", deny_unknown_fields)]
pub enum StageConfig {
    Align(AlignConfig),
    InitialConditions(IcConfig),
    SteadyState(SteadyConfig),
    Fit(FitConfig),
    Validate(ValidateConfig),
}

impl StageConfig {
    /// Validates and builds the runtime.
    pub fn build(&self) -> Result<Box<dyn Stage>, ProcessError> {
        Ok(match self {
            StageConfig::Align(c) => {
                c.validate()?;
                Box::new(AlignStage(c.clone()))
            }
            StageConfig::InitialConditions(c) => {
                c.validate()?;
                Box::new(IcStage(c.clone()))
            }
            StageConfig::SteadyState(c) => {
                if !(c.tail_s > 0.0 && c.theta_tol_rad > 0.0 && c.rest_tol_rad > 0.0) {
                    return Err(ProcessError::BadConfig {
                        stage: "steady_state".into(),
                        field: "tail_s/theta_tol_rad/rest_tol_rad".into(),
                        message: "must all be > 0".into(),
                    });
                }
                Box::new(SteadyStage(c.clone()))
            }
            StageConfig::Fit(c) => {
                c.validate()?;
                Box::new(FitStage(c.clone()))
            }
            StageConfig::Validate(c) => Box::new(ValidateStage(c.clone())),
        })
    }
}

/// A pipeline file.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PipelineConfig {
    pub name: String,
    #[serde(rename = "stage")]
    pub stages: Vec<StageConfig>,
}

impl PipelineConfig {
    /// Parses pipeline TOML; errors carry the line and column.
    pub fn from_toml(text: &str, source: &Path) -> Result<Self, ProcessError> {
        toml::from_str(text).map_err(|e| {
            let (line, col) = e.span().map_or((0, 0), |s| {
                let before = &text[..s.start.min(text.len())];
                (
                    before.matches('\n').count() + 1,
                    before.len() - before.rfind('\n').map_or(0, |i| i + 1) + 1,
                )
            });
            ProcessError::Pipeline {
                path: source.to_path_buf(),
                line,
                column: col,
                message: e.message().to_string(),
            }
        })
    }

    pub fn load(path: &Path) -> Result<Self, ProcessError> {
        let text = std::fs::read_to_string(path).map_err(|e| ProcessError::Pipeline {
            path: path.to_path_buf(),
            line: 0,
            column: 0,
            message: e.to_string(),
        })?;
        Self::from_toml(&text, path)
    }

    /// The fit stage's config, if any (for overrides from the command line).
    pub fn fit_mut(&mut self) -> Option<&mut FitConfig> {
        self.stages.iter_mut().find_map(|s| match s {
            StageConfig::Fit(c) => Some(c),
            _ => None,
        })
    }

    /// Builds every stage (validating its config) and runs them in order.
    pub fn run(&self, ctx: &mut Context) -> Result<(), ProcessError> {
        let stages = self
            .stages
            .iter()
            .map(StageConfig::build)
            .collect::<Result<Vec<_>, _>>()?;
        for s in stages {
            s.run(ctx)?;
        }
        Ok(())
    }
}

struct AlignStage(AlignConfig);

impl Stage for AlignStage {
    fn name(&self) -> &'static str {
        "align"
    }
    fn run(&self, ctx: &mut Context) -> Result<(), ProcessError> {
        use rayon::prelude::*;
        let results: Vec<_> = ctx
            .runs
            .par_iter()
            .map(|r| (r.id.clone(), align(r, &self.0)))
            .collect();
        // A run that cannot be aligned (its accelerometer never leaves its quiet level, fewer
        // than five crank turns at speed, a free decay without swings) is left out of the
        // analysis with a note, as the initial-state stage leaves out a run whose state cannot
        // be estimated: one bad capture need not take a campaign's other runs with it. (Every
        // run left out is still an error: there is nothing to analyse.)
        let n = results.len();
        let mut left_out = Vec::new();
        for (id, res) in results {
            match res {
                Ok(al) => {
                    ctx.alignments.insert(id, al);
                }
                Err(ProcessError::Align { reason, .. }) if n > 1 => left_out.push((id, reason)),
                Err(e) => return Err(e),
            }
        }
        if left_out.len() == n {
            let (run, reason) = left_out.swap_remove(0);
            return Err(ProcessError::Align { run, reason });
        }
        for (id, why) in left_out {
            ctx.runs.retain(|r| r.id != id);
            ctx.notes.push(format!(
                "run {id} is left out of the analysis: it cannot be aligned ({why})"
            ));
        }
        Ok(())
    }
}

struct IcStage(IcConfig);

impl Stage for IcStage {
    fn name(&self) -> &'static str {
        "initial_conditions"
    }
    fn run(&self, ctx: &mut Context) -> Result<(), ProcessError> {
        // A run whose state at t0 cannot be estimated (a burst of lost samples there leaves the
        // window nearly empty) is left out of the analysis with a note, not the campaign's
        // failure: a drawn twin campaign stopped on "only 1 encoder samples within ±0.06 s".
        // (Every run left out is still an error: there is nothing to analyse.)
        let mut left_out = Vec::new();
        for run in &ctx.runs {
            let al = ctx.require(&ctx.alignments, &run.id, "the alignment", self.name())?;
            let ic = match estimate_state(run, al.t0_s, &self.0) {
                Ok(ic) => ic,
                Err(e @ ProcessError::Run { .. }) if ctx.runs.len() > 1 => {
                    left_out.push((run.id.clone(), e));
                    continue;
                }
                Err(e) => return Err(e),
            };
            let hang = hanging_position(run, al.free_segment_s.0, al.free_segment_s.1);
            if let Some(h) = hang {
                // A zero more than ~6 counts off the hanging position is worth saying.
                if h.abs() > 0.01 {
                    ctx.notes.push(format!(
                        "run {}: the free decay swings about θ = {h:+.4} rad, not 0: the encoder zero is off the hanging position (effect encoder_offset?)",
                        run.id
                    ));
                }
            }
            ctx.initial.insert(run.id.clone(), ic);
            ctx.hanging.insert(run.id.clone(), hang);
        }
        if left_out.len() == ctx.runs.len() {
            let (_, first) = left_out.swap_remove(0);
            return Err(first);
        }
        for (id, why) in left_out {
            ctx.runs.retain(|r| r.id != id);
            ctx.notes.push(format!(
                "run {id} is left out of the analysis: its initial state cannot be estimated ({why})"
            ));
        }
        Ok(())
    }
}

struct SteadyStage(SteadyConfig);

impl Stage for SteadyStage {
    fn name(&self) -> &'static str {
        "steady_state"
    }
    fn run(&self, ctx: &mut Context) -> Result<(), ProcessError> {
        ctx.steady_cfg = self.0.clone();
        for run in &ctx.runs {
            let al = ctx.require(&ctx.alignments, &run.id, "the alignment", self.name())?;
            // A free decay has no forcing period: its tail is at rest or still swinging.
            let s = if al.is_free() {
                free_steady_state(run, al.t0_s, &self.0)?
            } else {
                measured_steady_state(run, al.omega_hz, &self.0)?
            };
            ctx.steady.insert(run.id.clone(), s);
        }
        Ok(())
    }
}

struct FitStage(FitConfig);

impl Stage for FitStage {
    fn name(&self) -> &'static str {
        "fit"
    }
    fn run(&self, ctx: &mut Context) -> Result<(), ProcessError> {
        let runs = ctx.prepared(Role::Identify, &self.0.window, self.name())?;
        ctx.fit_window = Some(self.0.window);
        let out = identify(&runs, &self.0, ctx.progress.clone())?;
        // Free decays: the fit and the envelope reach one verdict (issue 16 item 1).
        let (out, law) = crate::identify::decay_law(&runs, ctx, &self.0, out);
        ctx.notes.extend(law);
        ctx.notes
            .extend(crate::identify::shared_omega0_notes(&runs, &out));
        // Free decays that do not share ω0 also get their own fits, reported per run.
        let alone = crate::identify::per_run_fits(&runs, ctx, &self.0, &out)?;
        ctx.notes
            .extend(crate::identify::per_run_notes(&runs, &out, &alone));
        if !alone.is_empty() {
            ctx.per_run.insert(
                out.spec.name.clone(),
                crate::identify::per_run_by_id(&runs, &alone),
            );
        }
        ctx.notes
            .extend(crate::identify::params_at_bounds(&runs, &out));
        ctx.fits.push(out);
        Ok(())
    }
}

struct ValidateStage(ValidateConfig);

impl Stage for ValidateStage {
    fn name(&self) -> &'static str {
        "validate"
    }
    fn run(&self, ctx: &mut Context) -> Result<(), ProcessError> {
        let runs = ctx.prepared(Role::Validate, &self.0.window, self.name())?;
        ctx.validate_window = Some(self.0.window);
        let models: Vec<FitOutcome> = if ctx.fits.is_empty() {
            ctx.given.clone().into_iter().collect()
        } else {
            ctx.fits.clone()
        };
        if models.is_empty() {
            return Err(ProcessError::BadConfig {
                stage: "validate".into(),
                field: "model".into(),
                message: "no fitted model to validate: add a fit stage or give --params".into(),
            });
        }
        for m in models {
            let res = validate(&runs, &m.spec, &m.params, &self.0)?;
            ctx.validations.push((m.spec.name.clone(), res));
        }
        Ok(())
    }
}
