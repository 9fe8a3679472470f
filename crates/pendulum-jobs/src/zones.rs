//! `pendulum zones`: rotation-zone maps over two swept parameters (e.g. ω × R): per cell, the
//! fraction of initial states that end in rotation and the mean rotation speed, for one model
//! or two models compared (the cells where exactly one of them rotates are marked).
//! [`demo_comparison`] is the small study-model comparison the demo ends with.

use std::path::{Path, PathBuf};
use std::time::Instant;

use pendulum_maps::zones::{self, Comparison, ZoneConfig, ZoneMap};
use pendulum_maps::{IcSpec, Sweep};

use crate::bifurcate::{
    create_dir, fmt_ranges, progress_bar, resolve_assignments, runs_of, IcArgs, ModelArgs,
    ResolvedModel, RunArgs, Study,
};
use crate::inputs::Inputs;
use crate::merge::Ran;
use crate::JobError;

/// `pendulum zones` options.
#[derive(Debug, Clone, clap::Args)]
pub struct ZonesArgs {
    #[command(flatten)]
    pub model: ModelArgs,
    /// Compare with one of the study's models.
    #[arg(long = "compare-study", value_enum, conflicts_with = "compare_model")]
    pub compare_study: Option<Study>,
    /// Compare with another model of the same --params file.
    #[arg(long = "compare-model", value_name = "NAME", requires = "params_file")]
    pub compare_model: Option<String>,
    /// A parameter of the compared model, `key=value`: applied on top of --compare-study /
    /// --compare-model, or else on top of the first model's parameters. Repeatable.
    #[arg(long = "compare-param", value_name = "KEY=VALUE")]
    pub compare_param: Vec<String>,
    /// The map's x axis: NAME=START:STOP:STEP (or a list), NAME one of omega, R, lambda, alpha,
    /// beta, M.
    #[arg(long, value_name = "NAME=START:STOP:STEP")]
    pub x: String,
    /// The map's y axis, as --x.
    #[arg(long, value_name = "NAME=START:STOP:STEP")]
    pub y: String,
    #[command(flatten)]
    pub ics: IcArgs,
    #[command(flatten)]
    pub run: RunArgs,
    #[command(flatten)]
    pub shard: crate::merge::ShardArgs,
    /// Output folder (zones.parquet, zones_<model>.png, zones_compare.png; with --shard,
    /// shard=I/part.parquet and shard=I/manifest.json).
    #[arg(long, value_name = "DIR")]
    pub out: PathBuf,
}

/// What a zones job produced.
#[derive(Debug, Clone)]
pub struct ZonesSummary {
    pub maps: Vec<ZoneMap>,
    pub comparison: Option<Comparison>,
    pub ic_description: String,
    pub wall_s: f64,
    pub table: PathBuf,
    pub figures: Vec<PathBuf>,
}

fn pct(v: f64) -> String {
    format!("{:.0} %", 100.0 * v)
}

impl std::fmt::Display for ZonesSummary {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let Some(first) = self.maps.first() else {
            return writeln!(f, "no maps");
        };
        let c = &first.config;
        let cells = c.x.len() * c.y.len();
        writeln!(
            f,
            "rotation zones over {} × {} = {cells} cells",
            c.x.describe(),
            c.y.describe(),
        )?;
        writeln!(
            f,
            "  per cell {} starts ({}), {} + {} periods; {} simulations in {:.1} s",
            c.starts.len(),
            self.ic_description,
            c.transient_periods,
            c.record_periods,
            c.tasks() * self.maps.len() as u64,
            self.wall_s
        )?;
        let w = self.maps.iter().map(|m| m.label.len()).max().unwrap_or(0);
        for m in &self.maps {
            let best = m
                .cells
                .iter()
                .max_by(|a, b| a.rotation_fraction().total_cmp(&b.rotation_fraction()));
            write!(
                f,
                "  {:<w$}  rotation in {:>3} of {cells} cells",
                m.label,
                m.rotating_cells()
            )?;
            if let Some(b) = best.filter(|b| b.rotates()) {
                write!(
                    f,
                    " (most: {} of starts at {} = {}, {} = {})",
                    pct(b.rotation_fraction()),
                    c.x.param.name(),
                    b.x,
                    c.y.param.name(),
                    b.y
                )?;
            }
            // The harvester's answer when the model has a generator: its best cell, in W.
            let most_power = m
                .cells
                .iter()
                .filter(|x| x.mean_power_w.load.is_finite())
                .max_by(|a, b| a.mean_power_w.load.total_cmp(&b.mean_power_w.load));
            if let Some(p) = most_power.filter(|p| p.mean_power_w.load > 0.0) {
                write!(
                    f,
                    "; most power into the load: {:.4} W (mean over the starts) at {} = {}, {} = {}",
                    p.mean_power_w.load,
                    c.x.param.name(),
                    p.x,
                    c.y.param.name(),
                    p.y
                )?;
            }
            writeln!(f)?;
        }
        if let (Some(cmp), [a, b]) = (&self.comparison, self.maps.as_slice()) {
            for (who, other, cells_only) in [(a, b, &cmp.only_a), (b, a, &cmp.only_b)] {
                write!(
                    f,
                    "  {} rotates where {} does not: {} cells",
                    who.label,
                    other.label,
                    cells_only.len()
                )?;
                // Per y value, the x ranges.
                let mut parts = Vec::new();
                for iy in 0..c.y.len() {
                    let r = runs_of(&c.x.values, |ix| cells_only.contains(&(ix, iy)));
                    if !r.is_empty() {
                        parts.push(format!(
                            "{} = {}: {} {}",
                            c.y.param.name(),
                            c.y.values[iy],
                            c.x.param.name(),
                            fmt_ranges(&r)
                        ));
                    }
                }
                if parts.is_empty() {
                    writeln!(f)?;
                } else {
                    writeln!(f, " ({})", parts.join("; "))?;
                }
            }
        }
        write!(f, "wrote {}", self.table.display())?;
        for p in &self.figures {
            write!(f, ", {}", p.display())?;
        }
        writeln!(f)
    }
}

/// A file-name-safe version of a label.
fn slug(s: &str) -> String {
    s.chars()
        .map(|c| {
            if c.is_ascii_alphanumeric() || c == '-' || c == '_' {
                c
            } else {
                '_'
            }
        })
        .collect()
}

/// The table's metadata beyond the grid's: the command, each model's assignments, the starts.
fn table_extra(
    models: &[ResolvedModel],
    ic_description: &str,
    extra: &[(String, String)],
) -> Vec<(String, String)> {
    let mut meta = vec![("command".to_string(), "pendulum zones".to_string())];
    for m in models {
        meta.push((format!("assignments.{}", m.label), m.assignments.join(" ")));
    }
    meta.push(("initial_states".to_string(), ic_description.to_string()));
    meta.extend(extra.iter().cloned());
    meta
}

/// Each model's heat maps (`zones_<model>.png`) and, for two models, `zones_compare.png`
/// (one-machine run and merge alike).
pub(crate) fn write_figures(
    maps: &[ZoneMap],
    out: &Path,
) -> Result<(Vec<PathBuf>, Option<Comparison>), JobError> {
    let mut figures = Vec::new();
    for m in maps {
        let p = out.join(format!("zones_{}.png", slug(&m.label)));
        m.plot(&p)?;
        figures.push(p);
        let p = out.join(format!("zones_power_{}.png", slug(&m.label)));
        m.plot_power(&p)?;
        figures.push(p);
    }
    let comparison = match maps {
        [a, b] => {
            let p = out.join("zones_compare.png");
            let cmp = zones::plot_comparison(a, b, &p)?;
            figures.push(p);
            let p = out.join("zones_power_compare.png");
            zones::plot_power_comparison(a, b, &p)?;
            figures.push(p);
            Some(cmp)
        }
        _ => None,
    };
    Ok((figures, comparison))
}

/// Runs the maps of `models` on `cfg` and writes the table and figures into `out`.
pub fn run_models(
    models: &[ResolvedModel],
    cfg: &ZoneConfig,
    ic_description: &str,
    out: &Path,
    show_progress: bool,
    extra: &[(String, String)],
) -> Result<ZonesSummary, JobError> {
    create_dir(out)?;
    let list: Vec<(String, pendulum_model::Dimensionless)> =
        models.iter().map(|m| (m.label.clone(), m.params)).collect();
    let bar = progress_bar(cfg.tasks() * list.len() as u64, "zones", show_progress);
    let t = Instant::now();
    let maps = zones::run(&list, cfg, &|n| bar.inc(n))?;
    bar.finish_and_clear();
    let wall_s = t.elapsed().as_secs_f64();
    let table = out.join("zones.parquet");
    let meta = table_extra(models, ic_description, extra);
    zones::write_parquet(&maps, &table, &meta)?;
    let (figures, comparison) = write_figures(&maps, out)?;
    Ok(ZonesSummary {
        maps,
        comparison,
        ic_description: ic_description.to_string(),
        wall_s,
        table,
        figures,
    })
}

/// The models of a zones job: the first from [`ModelArgs`], the compared one (if any).
fn models_of(a: &ZonesArgs) -> Result<Vec<ResolvedModel>, JobError> {
    let first = a.model.resolve()?;
    let mut models = vec![first.clone()];
    let compare =
        a.compare_study.is_some() || a.compare_model.is_some() || !a.compare_param.is_empty();
    if compare {
        let (mut label, mut assignments) = if let Some(s) = a.compare_study {
            (s.name().to_string(), s.assignments())
        } else if let (Some(path), Some(name)) = (&a.model.params_file, &a.compare_model) {
            (
                name.clone(),
                pendulum_maps::params_file::load_model(path, name)?.assignments(true),
            )
        } else {
            ("compare".to_string(), first.assignments.clone())
        };
        assignments.extend(a.compare_param.iter().cloned());
        if label == first.label {
            label = format!("{label} (compare)");
        }
        models.push(resolve_assignments(&label, assignments)?);
    }
    Ok(models)
}

/// Runs `pendulum zones`: the whole map, or with `--shard` one shard of it.
pub fn run(a: &ZonesArgs) -> Result<Ran<ZonesSummary>, JobError> {
    let models = models_of(a)?;
    let ics = a.ics.spec("4x4")?;
    let mut cfg = ZoneConfig::new(Sweep::parse(&a.x)?, Sweep::parse(&a.y)?, ics.starts());
    cfg.transient_periods = a.run.transient;
    cfg.record_periods = a.run.record;
    cfg.sim = a.run.sim()?;
    cfg.threads = a.run.threads;
    // Watts on the first model's rig (a fitted model's own m, l, g), for both models alike.
    cfg.power_scale_w = models[0].physical.power_scale_w();
    let shard = a.shard.resolve()?;
    // Before the maps: none of the outputs may replace the --params file.
    let mut inputs = Inputs::new();
    if let Some(p) = &a.model.params_file {
        inputs.add("--params", p);
    }
    let mut outputs: Vec<PathBuf> = match shard {
        Some(s) => [pendulum_maps::shard::PART, pendulum_maps::shard::MANIFEST]
            .iter()
            .map(|n| a.out.join(s.dir_name()).join(n))
            .collect(),
        None => vec![
            a.out.join("zones.parquet"),
            a.out.join("zones_compare.png"),
            a.out.join("zones_power_compare.png"),
        ],
    };
    if shard.is_none() {
        outputs.extend(models.iter().flat_map(|m| {
            [
                a.out.join(format!("zones_{}.png", slug(&m.label))),
                a.out.join(format!("zones_power_{}.png", slug(&m.label))),
            ]
        }));
    }
    for p in &outputs {
        inputs.check_output("the output", p)?;
    }
    let Some(s) = shard else {
        return Ok(Ran::Full(run_models(
            &models,
            &cfg,
            &ics.describe(),
            &a.out,
            !a.run.quiet,
            &[],
        )?));
    };
    // The table's metadata as the one-machine run writes it (it depends on the grid and the
    // models, not on the cells).
    let empty: Vec<ZoneMap> = models
        .iter()
        .map(|m| ZoneMap {
            label: m.label.clone(),
            base: m.params,
            config: cfg.clone(),
            cells: Vec::new(),
        })
        .collect();
    let md = zones::metadata(&empty, &table_extra(&models, &ics.describe(), &[]))?;
    let job = crate::merge::ZonesJob {
        config: cfg,
        models: models
            .iter()
            .map(|m| crate::merge::ZonesModel {
                label: m.label.clone(),
                assignments: m.assignments.clone(),
                params: m.params,
            })
            .collect(),
        ic_description: ics.describe(),
    };
    Ok(Ran::Shard(crate::merge::zones_shard(
        &job,
        &md,
        s,
        &a.out,
        !a.run.quiet,
    )?))
}

/// The demo's closing comparison: the study's dry-friction (reference) and linear models on a
/// coarse ω × R grid (ω 1.2–3.2, R 0.4–1.0, steps 0.1; 4×4 starts; 150 + 32 periods).
/// Writes zones.parquet and the PNGs into `out_dir`; the summary prints as a short report.
pub fn demo_comparison(out_dir: &Path, show_progress: bool) -> Result<ZonesSummary, JobError> {
    let models = [Study::Reference, Study::Linear]
        .into_iter()
        .map(|s| resolve_assignments(s.name(), s.assignments()))
        .collect::<Result<Vec<_>, _>>()?;
    let ics = IcSpec::Grid {
        n_theta: 4,
        n_theta_dot: 4,
        theta_dot_max: 3.0,
    };
    let mut cfg = ZoneConfig::new(
        Sweep::range(pendulum_maps::SweepParam::Omega, 1.2, 3.2, 0.1)?,
        Sweep::range(pendulum_maps::SweepParam::R, 0.4, 1.0, 0.1)?,
        ics.starts(),
    );
    cfg.transient_periods = 150;
    cfg.record_periods = 32;
    run_models(
        &models,
        &cfg,
        &ics.describe(),
        out_dir,
        show_progress,
        &[("job".to_string(), "demo".to_string())],
    )
}
