//! `pendulum design`: for a fitted model (a row of `params.parquet`) on its rig, the generator
//! load and operating point (crank speed Ω, crank radius r) that maximise the expected mean power
//! into the load over a set of starts, with the fraction of starts that rotate and the standard
//! error; optionally a second model beside it. `design.parquet` (the search grid), `design.png`
//! (power and rotation against the load at the optimum), `design_map.png` (the best load's power
//! over Ω × r) and `design.md` ("this load, this speed, this many watts, this sure"). Sharded
//! like the other maps (`--shard`, `pendulum merge`).

use std::path::{Path, PathBuf};
use std::time::Instant;

use pendulum_maps::design::{self, Design, DesignConfig, DesignModel, Load};
use pendulum_maps::params_file::read_params;
use pendulum_model::spec::PHYSICAL_KEYS;
use pendulum_model::{ParamSpec, Physical};

use crate::bifurcate::{create_dir, progress_bar, IcArgs, Study};
use crate::inputs::Inputs;
use crate::merge::Ran;
use crate::JobError;

/// Most values one list option may give.
const MAX_LIST: usize = 10_000;

/// `pendulum design` options.
#[derive(Debug, Clone, clap::Args)]
pub struct DesignArgs {
    /// A params.parquet written by `pendulum identify`: the rig (m, l, L, r_b, g) and the fitted
    /// damping of --model.
    #[arg(long = "params", value_name = "FILE")]
    pub params_file: PathBuf,
    /// The model row of --params (default: the first).
    #[arg(long, value_name = "NAME")]
    pub model: Option<String>,
    /// A second model beside the first: another row of --params.
    #[arg(long = "compare-model", value_name = "NAME")]
    pub compare_model: Option<String>,
    /// A second model beside the first: the study's damping (α, β, M) on the first model's rig.
    #[arg(long = "compare-study", value_enum, conflicts_with = "compare_model")]
    pub compare_study: Option<Study>,
    /// A physical parameter `key=value` applied to every model after --params (e.g.
    /// m_kg=0.745, rod_L_m=0.6). Repeatable. Ω, r and the generator are the search's.
    #[arg(long = "param", value_name = "KEY=VALUE")]
    pub param: Vec<String>,
    /// Crank speeds Ω to search, Hz: a list or START:STOP:STEP (default: the rig's set points).
    #[arg(
        long = "omega-hz",
        value_name = "LIST",
        allow_hyphen_values = true,
        default_value = "0.87,1.18,1.54,1.92,2.36"
    )]
    pub omega_hz: String,
    /// Crank radii r to search, m: a list or START:STOP:STEP.
    #[arg(
        long = "crank-r-m",
        value_name = "LIST",
        allow_hyphen_values = true,
        default_value = "0.0725,0.1065,0.205"
    )]
    pub crank_r_m: String,
    /// Generator loads c_g = k_e²/R to search, N·m·s/rad (default 0.01 to 2.56, doubling: wide
    /// enough that a load too heavy to keep the pendulum rotating is in the search).
    #[arg(long = "c-g", value_name = "LIST", allow_hyphen_values = true)]
    pub c_g: Option<String>,
    /// Generator dead bands ω_d = V_d/k_e to search, rad/s (default 0,2); every pair with --c-g.
    #[arg(long = "omega-d", value_name = "LIST", allow_hyphen_values = true)]
    pub omega_d: Option<String>,
    /// The load given electrically instead: generator EMF constants k_e, V·s/rad; every
    /// combination with --v-d and --r-ohm is a load (c_g = k_e²/R, ω_d = V_d/k_e).
    #[arg(long = "k-e", value_name = "LIST", allow_hyphen_values = true, conflicts_with_all = ["c_g", "omega_d"], requires_all = ["v_d", "r_ohm"])]
    pub k_e: Option<String>,
    /// Rectifier diode drops V_d, V (with --k-e).
    #[arg(
        long = "v-d",
        value_name = "LIST",
        allow_hyphen_values = true,
        requires = "k_e"
    )]
    pub v_d: Option<String>,
    /// Load resistances R, Ω (with --k-e).
    #[arg(
        long = "r-ohm",
        value_name = "LIST",
        allow_hyphen_values = true,
        requires = "k_e"
    )]
    pub r_ohm: Option<String>,
    #[command(flatten)]
    pub ics: IcArgs,
    /// Transient, in forcing periods, before the steady state is read.
    #[arg(long, default_value_t = 200)]
    pub transient: u32,
    /// Recorded forcing periods: the class and the mean powers are read from them.
    #[arg(long, default_value_t = 32)]
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
    #[command(flatten)]
    pub shard: crate::merge::ShardArgs,
    /// Output folder (design.parquet, design.png, design_map.png, design.md; with --shard,
    /// shard=I/part.parquet and shard=I/manifest.json).
    #[arg(long, value_name = "DIR")]
    pub out: PathBuf,
}

/// What a design job produced.
#[derive(Debug, Clone)]
pub struct DesignSummary {
    pub designs: Vec<Design>,
    pub wall_s: f64,
    pub table: PathBuf,
    pub markdown: PathBuf,
    pub figures: Vec<PathBuf>,
}

impl std::fmt::Display for DesignSummary {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let Some(first) = self.designs.first() else {
            return writeln!(f, "no design");
        };
        let c = &first.config;
        writeln!(
            f,
            "design over {} × {} × {} loads = {} points, {} starts each, {} + {} periods: {} simulations in {:.1} s",
            c.omega_hz.len(),
            c.crank_r_m.len(),
            c.loads.len(),
            c.cells(),
            c.starts.len(),
            c.transient_periods,
            c.record_periods,
            c.tasks() * self.designs.len() as u64,
            self.wall_s
        )?;
        for d in &self.designs {
            match d.best() {
                Some(b) => writeln!(
                    f,
                    "  {}: {} at Ω = {} Hz, r = {} m: {} W ± {} W into the load (se over {} starts), {} of {} starts rotate",
                    d.model.label,
                    b.load.describe(),
                    b.omega_hz,
                    b.crank_r_m,
                    design::fmt_w(b.load_w()),
                    design::fmt_w(b.load_power_se_w()),
                    b.starts,
                    b.rotating,
                    b.starts
                )?,
                None => writeln!(f, "  {}: no finite power anywhere", d.model.label)?,
            }
        }
        write!(
            f,
            "wrote {}, {}",
            self.table.display(),
            self.markdown.display()
        )?;
        for p in &self.figures {
            write!(f, ", {}", p.display())?;
        }
        writeln!(f)
    }
}

/// A list option: `v1,v2,…` or `START:STOP:STEP` (stop included when on the grid).
pub fn parse_list(flag: &str, text: &str) -> Result<Vec<f64>, JobError> {
    let bad = |why: String| {
        JobError::Invalid(format!(
            "{flag} {text:?}: {why}; expected V1,V2,… or START:STOP:STEP"
        ))
    };
    let num = |s: &str| -> Result<f64, JobError> {
        let v: f64 = s
            .trim()
            .parse()
            .map_err(|_| bad(format!("cannot read {s:?} as a number")))?;
        if v.is_finite() {
            Ok(v)
        } else {
            Err(bad(format!("{s:?} is not a finite number")))
        }
    };
    let parts: Vec<&str> = text.split(':').collect();
    let values = match parts.as_slice() {
        [a, b, c] => {
            let (start, stop, step) = (num(a)?, num(b)?, num(c)?);
            if step <= 0.0 {
                return Err(bad(format!("step {step} must be > 0")));
            }
            if stop < start {
                return Err(bad(format!("stop {stop} is below start {start}")));
            }
            let n = ((stop - start) / step + 1e-9).floor() + 1.0;
            if n > MAX_LIST as f64 {
                return Err(bad(format!("{n} values; at most {MAX_LIST}")));
            }
            // Rounded to 1e-10 so that 0.1 + 2·0.05 reads 0.2.
            (0..n as usize)
                .map(|i| {
                    let v = start + i as f64 * step;
                    (v * 1e10).round() / 1e10
                })
                .collect()
        }
        [one] => one.split(',').map(num).collect::<Result<Vec<_>, _>>()?,
        _ => return Err(bad("too many ':'".into())),
    };
    if values.is_empty() || values.len() > MAX_LIST {
        return Err(bad(format!("{} values", values.len())));
    }
    Ok(values)
}

/// The loads of the search: c_g × ω_d, or k_e × V_d × R given electrically.
fn loads_of(a: &DesignArgs) -> Result<Vec<Load>, JobError> {
    if let (Some(k), Some(v), Some(r)) = (&a.k_e, &a.v_d, &a.r_ohm) {
        let (k, v, r) = (
            parse_list("--k-e", k)?,
            parse_list("--v-d", v)?,
            parse_list("--r-ohm", r)?,
        );
        let mut out = Vec::new();
        for &ke in &k {
            for &vd in &v {
                for &ro in &r {
                    out.push(Load::electrical(ke, vd, ro)?);
                }
            }
        }
        return Ok(out);
    }
    let c = parse_list(
        "--c-g",
        a.c_g
            .as_deref()
            .unwrap_or("0.01,0.02,0.04,0.08,0.16,0.32,0.64,1.28,2.56"),
    )?;
    let w = parse_list("--omega-d", a.omega_d.as_deref().unwrap_or("0,2"))?;
    Ok(c.iter()
        .flat_map(|&c| w.iter().map(move |&w| Load::new(c, w)))
        .collect())
}

/// A model from assignments: the study's rig under them, the generator removed (the search sets
/// it).
fn model_of(label: &str, assignments: &[String]) -> Result<DesignModel, JobError> {
    let (mut physical, _) = ParamSpec::parse(assignments)?.resolve(&Physical::default())?;
    physical.effects.set("generator_rectified", None);
    Ok(DesignModel {
        label: label.to_string(),
        physical,
    })
}

/// The models of a design job: --model of --params, and the compared one if any.
fn models_of(a: &DesignArgs) -> Result<Vec<DesignModel>, JobError> {
    let rows = read_params(&a.params_file)?;
    let name = match &a.model {
        Some(n) => n.clone(),
        None => rows.first().map(|r| r.model.clone()).ok_or_else(|| {
            JobError::Invalid(format!(
                "{}: no model rows: not a params table written by pendulum identify?",
                a.params_file.display()
            ))
        })?,
    };
    let row = pendulum_maps::params_file::find_model(&a.params_file, rows.clone(), &name)?;
    // The physical form: Ω and r are the search's, so the fit's dimensionless ω and R must not
    // override them.
    let mut first = row.assignments(false);
    first.extend(a.param.iter().cloned());
    let mut models = vec![model_of(&name, &first)?];
    if let Some(other) = &a.compare_model {
        let row = pendulum_maps::params_file::find_model(&a.params_file, rows, other)?;
        let mut asg = row.assignments(false);
        asg.extend(a.param.iter().cloned());
        let label = if *other == name {
            format!("{other} (compare)")
        } else {
            other.clone()
        };
        models.push(model_of(&label, &asg)?);
    } else if let Some(study) = a.compare_study {
        // The study's damping on the first model's rig: its rig keys, then α, β, M.
        let rig: Vec<String> = first
            .iter()
            .filter(|s| {
                s.split_once('=').is_some_and(|(k, _)| {
                    PHYSICAL_KEYS.contains(&k) && !matches!(k, "a" | "b" | "mu")
                })
            })
            .cloned()
            .chain(study.assignments().into_iter().filter(|s| {
                s.starts_with("alpha=") || s.starts_with("beta=") || s.starts_with("M=")
            }))
            .collect();
        let label = if study.name() == name {
            format!("{} (study)", study.name())
        } else {
            study.name().to_string()
        };
        models.push(model_of(&label, &rig)?);
    }
    Ok(models)
}

/// The search configuration of a design job.
fn config_of(a: &DesignArgs) -> Result<(DesignConfig, String), JobError> {
    if !(a.tol.is_finite() && a.tol > 0.0 && a.tol < 1e-2) {
        return Err(JobError::Invalid(format!(
            "--tol {}: expected a tolerance in (0, 0.01)",
            a.tol
        )));
    }
    let ics = a.ics.spec("4x4")?;
    let mut cfg = DesignConfig::new(
        parse_list("--omega-hz", &a.omega_hz)?,
        parse_list("--crank-r-m", &a.crank_r_m)?,
        loads_of(a)?,
        ics.starts(),
    );
    cfg.transient_periods = a.transient;
    cfg.record_periods = a.record;
    cfg.sim = pendulum_model::SimOptions::with_tol(a.tol);
    cfg.threads = a.threads;
    Ok((cfg, ics.describe()))
}

/// The outputs a one-machine run writes into `out`.
pub const OUTPUTS: [&str; 4] = [
    "design.parquet",
    "design.md",
    "design.png",
    "design_map.png",
];

/// Writes the table, the summary and the figures of whole designs into `out` (one-machine run
/// and merge alike).
pub(crate) fn write_outputs(
    designs: &[Design],
    columns: &[pendulum_report::Column],
    metadata: &[(String, String)],
    out: &Path,
    wall_s: f64,
) -> Result<DesignSummary, JobError> {
    let table = out.join(OUTPUTS[0]);
    let mut opts = pendulum_report::TableOptions::new();
    for (k, v) in metadata {
        opts = opts.meta(k, v.clone());
    }
    opts.write(&table, columns)?;
    let markdown = out.join(OUTPUTS[1]);
    crate::outputs::write_atomic(&markdown, design::summary_markdown(designs).as_bytes())?;
    let curves = out.join(OUTPUTS[2]);
    design::plot_curves(designs, &curves)?;
    let map = out.join(OUTPUTS[3]);
    design::plot_map(designs, &map)?;
    Ok(DesignSummary {
        designs: designs.to_vec(),
        wall_s,
        table,
        markdown,
        figures: vec![curves, map],
    })
}

/// The one-machine table's key-value metadata.
fn table_metadata(
    models: &[DesignModel],
    cfg: &DesignConfig,
    ic_description: &str,
    params_file: &Path,
) -> Vec<(String, String)> {
    let mut md = vec![("command".to_string(), "pendulum design".to_string())];
    md.extend(design::metadata(models, cfg));
    md.push(("initial_states".to_string(), ic_description.to_string()));
    md.push((
        "params_file".to_string(),
        params_file
            .file_name()
            .map(|n| n.to_string_lossy().into_owned())
            .unwrap_or_default(),
    ));
    md
}

/// Runs `pendulum design`: the whole search, or with `--shard` one shard of it.
pub fn run(a: &DesignArgs) -> Result<Ran<DesignSummary>, JobError> {
    let models = models_of(a)?;
    let (cfg, ic_description) = config_of(a)?;
    cfg.validate(&models)?;
    let shard = a.shard.resolve()?;
    let mut inputs = Inputs::new();
    inputs.add("--params", &a.params_file);
    let outputs: Vec<PathBuf> = match shard {
        Some(s) => [pendulum_maps::shard::PART, pendulum_maps::shard::MANIFEST]
            .iter()
            .map(|n| a.out.join(s.dir_name()).join(n))
            .collect(),
        None => OUTPUTS.iter().map(|n| a.out.join(n)).collect(),
    };
    for p in &outputs {
        inputs.check_output("the output", p)?;
    }
    let md = table_metadata(&models, &cfg, &ic_description, &a.params_file);
    if let Some(s) = shard {
        let job = crate::merge::DesignJob {
            config: cfg,
            models,
            ic_description,
        };
        return Ok(Ran::Shard(crate::merge::design_shard(
            &job, &md, s, &a.out, !a.quiet,
        )?));
    }
    create_dir(&a.out)?;
    let bar = progress_bar(cfg.tasks() * models.len() as u64, "design", !a.quiet);
    let t = Instant::now();
    let designs = design::run(&models, &cfg, &|n| bar.inc(n))?;
    bar.finish_and_clear();
    let wall_s = t.elapsed().as_secs_f64();
    let cols = design::columns(&designs, true);
    Ok(Ran::Full(write_outputs(
        &designs, &cols, &md, &a.out, wall_s,
    )?))
}
