//! Maps split over machines: the `--shard` option every map command shares (`bifurcate`,
//! `zones`, `design`), what a shard run writes and prints, and
//! `pendulum merge DIR`, which checks the shards and writes the table and figures exactly as the
//! one-machine run would (see `pendulum_maps::shard`).

use std::path::{Path, PathBuf};

use pendulum_maps::bifurcation::{self, BifurcationConfig};
use pendulum_maps::shard::{self, Shard, ShardPart, ShardSpec, ShardWritten};
use pendulum_maps::zones::{self, ZoneConfig};
use pendulum_model::Dimensionless;
use pendulum_report::{Column, TableOptions};
use serde::{Deserialize, Serialize};

use crate::bifurcate::BifurcateSummary;
use crate::design::DesignSummary;
use crate::zones::ZonesSummary;
use crate::JobError;

/// The shard option of the map commands.
#[derive(Debug, Clone, Default, clap::Args)]
pub struct ShardArgs {
    /// Compute one shard of the map: I/N (shard I of N, 0 ≤ I < N; cells c with c mod N = I),
    /// or `auto` / `auto/N` to read it from a Slurm job array (SLURM_ARRAY_TASK_ID − MIN, COUNT)
    /// or a Kubernetes Indexed Job (JOB_COMPLETION_INDEX; N from auto/N or
    /// PENDULUM_SHARD_COUNT). Writes OUT/shard=I/part.parquet and manifest.json; `pendulum
    /// merge OUT` then writes the table and figures.
    #[arg(long, value_name = "I/N|auto|auto/N")]
    pub shard: Option<String>,
}

impl ShardArgs {
    /// The shard, `None` for a one-machine run; `auto` reads this process's environment.
    pub fn resolve(&self) -> Result<Option<Shard>, JobError> {
        let Some(text) = &self.shard else {
            return Ok(None);
        };
        let spec = ShardSpec::parse(text)?;
        Ok(Some(spec.resolve(&|k| std::env::var(k).ok())?))
    }
}

/// A one-machine run's summary, or a shard's.
#[derive(Debug, Clone)]
pub enum Ran<T> {
    Full(T),
    Shard(ShardSummary),
}

impl<T: std::fmt::Display> std::fmt::Display for Ran<T> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Ran::Full(s) => s.fmt(f),
            Ran::Shard(s) => s.fmt(f),
        }
    }
}

/// What a shard run did.
#[derive(Debug, Clone)]
pub struct ShardSummary {
    pub command: String,
    pub shard: Shard,
    pub cells: usize,
    pub cells_total: usize,
    pub simulations: u64,
    pub wall_s: f64,
    pub out: PathBuf,
    pub written: ShardWritten,
}

impl std::fmt::Display for ShardSummary {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        writeln!(
            f,
            "{} shard {}: {} of {} cells, {} simulations in {:.1} s (config {})",
            self.command,
            self.shard,
            self.cells,
            self.cells_total,
            self.simulations,
            self.wall_s,
            &self.written.config_hash[..self.written.config_hash.len().min(19)]
        )?;
        writeln!(
            f,
            "wrote {} ({} rows), {}",
            self.written.part.display(),
            self.written.rows,
            self.written.manifest.display()
        )?;
        writeln!(
            f,
            "when all {} shards are done: pendulum merge {}",
            self.shard.count,
            self.out.display()
        )
    }
}

/// What a bifurcate shard records for the merge.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct BifurcateJob {
    pub config: BifurcationConfig,
    pub label: String,
    pub ic_description: String,
}

/// A model of a zones run, as the merge needs it.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct ZonesModel {
    pub label: String,
    pub assignments: Vec<String>,
    pub params: Dimensionless,
}

/// What a zones shard records for the merge.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct ZonesJob {
    pub config: ZoneConfig,
    pub models: Vec<ZonesModel>,
    pub ic_description: String,
}

/// What a design shard records for the merge.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct DesignJob {
    pub config: pendulum_maps::design::DesignConfig,
    pub models: Vec<pendulum_maps::design::DesignModel>,
    pub ic_description: String,
}

fn to_json<T: Serialize>(v: &T) -> Result<serde_json::Value, JobError> {
    serde_json::to_value(v)
        .map_err(|e| JobError::Invalid(format!("cannot encode the shard's configuration: {e}")))
}

/// Checks that `shard` has cells to compute.
fn check_count(command: &str, shard: Shard, total: usize, cell: &str) -> Result<(), JobError> {
    if shard.count > total {
        return Err(JobError::Invalid(format!(
            "{command} --shard {shard}: the map has only {total} cells ({cell}); use at most {total} shards"
        )));
    }
    Ok(())
}

/// What a map command's shard is: its name, what one cell is, how many cells the whole map has,
/// the simulations each cell runs, and the job as recorded in the manifest (threads left out:
/// they change no result).
struct ShardRun<'a> {
    command: &'static str,
    cell: &'a str,
    total: usize,
    sims_per_cell: u64,
    job: serde_json::Value,
}

/// Runs shard `shard` of a map command and writes it into `out/shard=i/`: the one driver of the
/// three map commands' shards; `run` computes the given cells' rows of the one-machine table.
fn run_shard(
    r: ShardRun<'_>,
    table_metadata: &[(String, String)],
    shard: Shard,
    out: &Path,
    show_progress: bool,
    run: impl FnOnce(&[usize], &(dyn Fn(u64) + Sync)) -> Result<Vec<Column>, JobError>,
) -> Result<ShardSummary, JobError> {
    check_count(r.command, shard, r.total, r.cell)?;
    let cells = shard.cells(r.total);
    crate::bifurcate::create_dir(&out.join(shard.dir_name()))?;
    let sims = cells.len() as u64 * r.sims_per_cell;
    let bar = crate::bifurcate::progress_bar(sims, &format!("{} shard", r.command), show_progress);
    let t = std::time::Instant::now();
    let columns = run(&cells, &|n| bar.inc(n))?;
    bar.finish_and_clear();
    let wall_s = t.elapsed().as_secs_f64();
    let written = shard::write_shard(
        out,
        &ShardPart {
            command: r.command,
            shard,
            cell: r.cell,
            cells_total: r.total,
            cells: &cells,
            columns: &columns,
            table_metadata,
            job: r.job,
            wall_s,
        },
    )?;
    Ok(ShardSummary {
        command: r.command.into(),
        shard,
        cells: cells.len(),
        cells_total: r.total,
        simulations: sims,
        wall_s,
        out: out.to_path_buf(),
        written,
    })
}

/// Runs shard `shard` of a bifurcation sweep and writes it into `out/shard=i/`.
pub(crate) fn bifurcate_shard(
    job: &BifurcateJob,
    table_metadata: &[(String, String)],
    shard: Shard,
    out: &Path,
    show_progress: bool,
) -> Result<ShardSummary, JobError> {
    let cfg = &job.config;
    let mut recorded = job.clone();
    recorded.config.threads = None;
    let run = ShardRun {
        command: "bifurcate",
        cell: cfg.cell_description(),
        total: cfg.cells(),
        sims_per_cell: match cfg.mode {
            bifurcation::Mode::Grid => 1,
            bifurcation::Mode::Continuation => cfg.sweep.len() as u64,
        },
        job: to_json(&recorded)?,
    };
    run_shard(
        run,
        table_metadata,
        shard,
        out,
        show_progress,
        |cells, inc| Ok(bifurcation::run_cells(cfg, cells, inc)?.columns()),
    )
}

/// Runs shard `shard` of a zones map and writes it into `out/shard=i/`.
pub(crate) fn zones_shard(
    job: &ZonesJob,
    table_metadata: &[(String, String)],
    shard: Shard,
    out: &Path,
    show_progress: bool,
) -> Result<ShardSummary, JobError> {
    let cfg = &job.config;
    let list: Vec<(String, Dimensionless)> = job
        .models
        .iter()
        .map(|m| (m.label.clone(), m.params))
        .collect();
    let mut recorded = job.clone();
    recorded.config.threads = None;
    let run = ShardRun {
        command: "zones",
        cell: "one (x, y) cell with all its starts and models; cell = iy·nx + ix",
        total: cfg.cells(),
        sims_per_cell: (cfg.starts.len() * list.len()) as u64,
        job: to_json(&recorded)?,
    };
    run_shard(
        run,
        table_metadata,
        shard,
        out,
        show_progress,
        |cells, inc| Ok(zones::columns(&zones::run_cells(&list, cfg, cells, inc)?)?),
    )
}

/// Runs shard `shard` of a design search and writes it into `out/shard=i/`.
pub(crate) fn design_shard(
    job: &DesignJob,
    table_metadata: &[(String, String)],
    shard: Shard,
    out: &Path,
    show_progress: bool,
) -> Result<ShardSummary, JobError> {
    use pendulum_maps::design;
    let cfg = &job.config;
    let mut recorded = job.clone();
    recorded.config.threads = None;
    let run = ShardRun {
        command: "design",
        cell: cfg.cell_description(),
        total: cfg.cells(),
        sims_per_cell: (cfg.starts.len() * job.models.len()) as u64,
        job: to_json(&recorded)?,
    };
    run_shard(
        run,
        table_metadata,
        shard,
        out,
        show_progress,
        |cells, inc| {
            // `best` needs the whole grid: false here, set by the merge.
            Ok(design::columns(
                &design::run_cells(&job.models, cfg, cells, inc)?,
                false,
            ))
        },
    )
}

/// `pendulum merge` options.
#[derive(Debug, Clone, clap::Args)]
pub struct MergeArgs {
    /// The folder the shards wrote into (holding shard=0 … shard=N-1).
    pub dir: PathBuf,
    /// Where to write the merged table and figures (default: DIR).
    #[arg(long, value_name = "DIR")]
    pub out: Option<PathBuf>,
}

/// What the merge wrote: the one-machine summary of the map.
#[derive(Debug, Clone)]
pub enum Merged {
    Bifurcate(Box<BifurcateSummary>),
    Zones(Box<ZonesSummary>),
    Design(Box<DesignSummary>),
}

/// What `pendulum merge` did.
#[derive(Debug, Clone)]
pub struct MergeSummary {
    pub dir: PathBuf,
    pub shards: usize,
    pub cells: usize,
    pub config_hash: String,
    /// Summed over the shards, and the longest.
    pub wall_sum_s: f64,
    pub wall_max_s: f64,
    pub merged: Merged,
}

impl std::fmt::Display for MergeSummary {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        writeln!(
            f,
            "merged {} shards of {} ({} cells, config {}): shard wall times sum to {:.1} s, longest {:.1} s",
            self.shards,
            self.dir.display(),
            self.cells,
            &self.config_hash[..self.config_hash.len().min(19)],
            self.wall_sum_s,
            self.wall_max_s
        )?;
        match &self.merged {
            Merged::Bifurcate(s) => s.fmt(f),
            Merged::Zones(s) => s.fmt(f),
            Merged::Design(s) => s.fmt(f),
        }
    }
}

/// Writes `columns` with the one-machine table's metadata (as `TableOptions::new()` plus the
/// pairs, in order: what the one-machine run writes).
fn write_table(
    path: &Path,
    columns: &[Column],
    metadata: &[(String, String)],
) -> Result<usize, JobError> {
    let mut opts = TableOptions::new();
    for (k, v) in metadata {
        opts = opts.meta(k, v.clone());
    }
    Ok(opts.write(path, columns)?.rows)
}

/// Runs `pendulum merge`: reads and checks the shards (refusing missing, duplicated or
/// incomplete shards and mixed configurations, naming them), then writes the table and figures
/// the one-machine run writes, into `--out` (default DIR).
pub fn run(a: &MergeArgs) -> Result<MergeSummary, JobError> {
    let set = shard::read_shards(&a.dir)?;
    let out = a.out.clone().unwrap_or_else(|| a.dir.clone());
    crate::bifurcate::create_dir(&out)?;
    let first = set.first().clone();
    let decode = |what: &str, e: serde_json::Error| {
        JobError::Invalid(format!(
            "{}: the shards' {what} configuration cannot be read: {e}",
            a.dir.display()
        ))
    };
    let wall_sum_s = set.manifests.iter().map(|m| m.wall_s).sum::<f64>();
    let wall_max_s = set.manifests.iter().map(|m| m.wall_s).fold(0.0, f64::max);
    let merged = match first.command.as_str() {
        "bifurcate" => {
            let job: BifurcateJob =
                serde_json::from_value(first.job.clone()).map_err(|e| decode("bifurcate", e))?;
            let (result, columns) = bifurcation::merge_shards(&job.config, &set)?;
            let table = out.join("bifurcation.parquet");
            let rows = write_table(&table, &columns, &first.table_metadata)?;
            let figures = crate::bifurcate::write_figures(&result, &job.label, &out)?;
            Merged::Bifurcate(Box::new(BifurcateSummary {
                label: job.label,
                result,
                ic_description: job.ic_description,
                wall_s: wall_sum_s,
                table,
                rows,
                figures,
            }))
        }
        "zones" => {
            let job: ZonesJob =
                serde_json::from_value(first.job.clone()).map_err(|e| decode("zones", e))?;
            let list: Vec<(String, Dimensionless)> = job
                .models
                .iter()
                .map(|m| (m.label.clone(), m.params))
                .collect();
            let (maps, columns) = zones::merge_shards(&list, &job.config, &set)?;
            let table = out.join("zones.parquet");
            write_table(&table, &columns, &first.table_metadata)?;
            let (figures, comparison) = crate::zones::write_figures(&maps, &out)?;
            Merged::Zones(Box::new(ZonesSummary {
                maps,
                comparison,
                ic_description: job.ic_description,
                wall_s: wall_sum_s,
                table,
                figures,
            }))
        }
        "design" => {
            let job: DesignJob =
                serde_json::from_value(first.job.clone()).map_err(|e| decode("design", e))?;
            let (designs, columns) =
                pendulum_maps::design::merge_shards(&job.models, &job.config, &set)?;
            let s = crate::design::write_outputs(
                &designs,
                &columns,
                &first.table_metadata,
                &out,
                wall_sum_s,
            )?;
            Merged::Design(Box::new(s))
        }
        other => {
            return Err(JobError::Invalid(format!(
            "{}: shards of command {other:?}, which this pendulum cannot merge (bifurcate, zones, design)",
            a.dir.display()
        )))
        }
    };
    Ok(MergeSummary {
        dir: a.dir.clone(),
        shards: set.manifests.len(),
        cells: first.cells_total,
        config_hash: first.config_hash.clone(),
        wall_sum_s,
        wall_max_s,
        merged,
    })
}
