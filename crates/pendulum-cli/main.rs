//! The `pendulum` binary: parses arguments, calls the library crates, prints results and errors
//! (with their chain), maps failures to exit codes. No logic lives here.

use std::io::Write as _;
use std::path::PathBuf;
use std::process::ExitCode;
use std::sync::atomic::{AtomicBool, Ordering};

use clap::{Parser, Subcommand};
use pendulum_jobs::{demo, discover, identify, ingest, simulate, synth};
use pendulum_model::SteadyClass;

#[derive(Parser)]
#[command(
    name = "pendulum",
    version,
    about = "Parametric-pendulum rig logs in, damping answers out"
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Integrate the dimensionless equation of motion (the study's Eq. 5, plus any effects) and
    /// write t, theta, theta_dot to Parquet with the steady state in its metadata.
    Simulate(SimulateArgs),
    /// Run the main job on built-in data.
    Demo(DemoArgs),
    /// Ingest a campaign's raw captures (serial-v1 CSV, sd-v2 binary) into one MCAP file per run.
    Ingest(IngestArgs),
    /// Simulate a campaign with the rig's digital twin: raw captures, campaign.toml, truth.json.
    Synth(SynthArgs),
    /// Bifurcation diagram over a parameter sweep: bifurcation.parquet and PNGs.
    Bifurcate(pendulum_jobs::bifurcate::BifurcateArgs),
    /// Rotation-zone maps over two swept parameters, two models compared: Parquet and PNGs.
    Zones(pendulum_jobs::zones::ZonesArgs),
    /// Harvester design: the generator load and operating point (crank speed, crank radius) that
    /// maximise the expected power into the load for a fitted model, a second model beside it.
    Design(pendulum_jobs::design::DesignArgs),
    /// Merge the shards of a map (`bifurcate`/`zones`/`design --shard I/N --out DIR`) into the table and
    /// figures the one-machine run writes; refuses missing shards and mixed configurations.
    Merge(pendulum_jobs::merge::MergeArgs),
    /// Replay a run with a fitted model: measured channels plus /sim/theta in one MCAP file.
    Replay(pendulum_jobs::replay::ReplayArgs),
    /// Identify damping by the study's method (align, initial conditions, DE fit, validation);
    /// writes params/initial_conditions/residuals/convergence/runs Parquet tables and plots.
    Identify(IdentifyArgs),
    /// Validate given damping parameters (from a params.parquet) on a campaign's validate runs.
    Validate(ValidateArgs),
    /// Show what the base model gets wrong, name the catalogue effect responsible (or say
    /// unexplained), extend the model and measure the gain on the validate runs.
    Discover(DiscoverArgs),
}

#[derive(clap::Args)]
struct IngestArgs {
    /// Campaign folder (holding campaign.toml and the captures).
    campaign_dir: PathBuf,
    /// Output folder for <run_id>.mcap files.
    #[arg(long)]
    out: PathBuf,
    /// No progress bar.
    #[arg(long)]
    quiet: bool,
}

#[derive(clap::Args)]
struct IdentifyArgs {
    /// A campaign folder (raw captures + campaign.toml) or a folder of .mcap run logs.
    input: PathBuf,
    /// Output folder for the tables and plots.
    #[arg(long)]
    out: PathBuf,
    /// Damping model: reference (a, b, μ) or linear (b only).
    #[arg(long)]
    model: Option<String>,
    /// Pipeline file (default: the built-in pipelines/identify.toml).
    #[arg(long)]
    pipeline: Option<PathBuf>,
    /// DE population size (default 10·(3 + 2N)).
    #[arg(long)]
    np: Option<usize>,
    /// Generation cap.
    #[arg(long)]
    generations: Option<u64>,
    /// Stop when best − worst < tol; `--tol 0 --generations G` runs exactly G generations.
    #[arg(long)]
    tol: Option<f64>,
    /// Read --tol relative to the best objective (scale-free) instead of absolute.
    #[arg(long)]
    relative_tol: bool,
    /// Random seed.
    #[arg(long)]
    seed: Option<u64>,
    /// Worker threads (default: all cores).
    #[arg(long)]
    threads: Option<usize>,
    /// Fit window after t = 0, s.
    #[arg(long)]
    window_s: Option<f64>,
    /// Evaluate every trial in full (the plain algorithm; same result, slower).
    #[arg(long)]
    no_early_abandon: bool,
    /// Also fit the free-motion segments before the shakers start as free decays
    /// (into OUT/free_segments/).
    #[arg(long)]
    free_segments: bool,
    /// Fit MCAP files of different campaigns together (refused otherwise).
    #[arg(long)]
    mix_campaigns: bool,
    /// No progress bar.
    #[arg(long)]
    quiet: bool,
}

#[derive(clap::Args)]
struct ValidateArgs {
    /// A campaign folder or a folder of .mcap run logs.
    input: PathBuf,
    /// params.parquet written by `pendulum identify`.
    #[arg(long)]
    params: PathBuf,
    /// Which model row of params.parquet (default: the first).
    #[arg(long)]
    model: Option<String>,
    /// Output folder.
    #[arg(long)]
    out: PathBuf,
    /// Pipeline file (default: the built-in pipelines/validate.toml).
    #[arg(long)]
    pipeline: Option<PathBuf>,
    /// Validate on MCAP files of different campaigns together (refused otherwise).
    #[arg(long)]
    mix_campaigns: bool,
}

#[derive(clap::Args)]
struct DiscoverArgs {
    /// A campaign folder or a folder of .mcap run logs (identify and validate runs).
    input: PathBuf,
    /// Output folder (tables, plots, report.md).
    #[arg(long)]
    out: PathBuf,
    /// The model in hand: reference (a, b, μ) or linear (b only).
    #[arg(long, value_enum, default_value_t = BaseArg::Reference)]
    base: BaseArg,
    /// Pipeline file (default: the built-in pipelines/discover.toml).
    #[arg(long)]
    pipeline: Option<PathBuf>,
    /// Generation cap of the base fit.
    #[arg(long)]
    generations: Option<u64>,
    /// Random seed.
    #[arg(long)]
    seed: Option<u64>,
    /// No progress bar.
    #[arg(long)]
    quiet: bool,
}

#[derive(Clone, Copy, clap::ValueEnum)]
enum BaseArg {
    Reference,
    Linear,
    /// Dry bearing friction alone (μ): the base in which viscous drag can be missing.
    Dry,
}

#[derive(clap::Args)]
struct SynthArgs {
    /// Twin case file (rig, truth, sensors, runs).
    case: PathBuf,
    /// Output campaign folder.
    out_dir: PathBuf,
}

#[derive(clap::Args)]
struct SimulateArgs {
    /// A parameter, `key=value`: dimensionless omega, R, lambda, alpha, beta, M; physical m_kg,
    /// l_m, crank_r_m, rod_L_m, r_b_m, omega_hz, g_m_s2, a, b, mu; effects such as
    /// coulomb_constant.T_c. Unset ones come from the study's rig. Repeatable.
    #[arg(long = "param", value_name = "KEY=VALUE")]
    params: Vec<String>,
    /// Initial angle from hanging, rad.
    #[arg(long, default_value_t = 0.5, allow_negative_numbers = true)]
    theta0: f64,
    /// Initial dimensionless angular velocity.
    #[arg(
        long = "theta-dot0",
        default_value_t = 0.0,
        allow_negative_numbers = true
    )]
    theta_dot0: f64,
    /// End time, dimensionless (t = ω0·τ).
    #[arg(long = "t-end", default_value_t = 300.0)]
    t_end: f64,
    /// Output spacing, dimensionless.
    #[arg(long = "dt-out", default_value_t = 0.05)]
    dt_out: f64,
    /// Integrator tolerance (relative and absolute).
    #[arg(long, default_value_t = 1e-8)]
    tol: f64,
    /// Output Parquet file.
    #[arg(long)]
    out: Option<PathBuf>,
}

#[derive(clap::Args)]
struct DemoArgs {
    /// Initial-condition grid size per axis (grid × grid starts per configuration).
    #[arg(long, default_value_t = 4)]
    grid: usize,
    /// Output folder for the demo's campaign, MCAP files, tables and plots.
    #[arg(long, default_value = "demo-out")]
    out: PathBuf,
    /// DE generation cap of the demo's identification.
    #[arg(long, default_value_t = 300)]
    generations: u64,
    /// Only the quick simulation table.
    #[arg(long)]
    quick: bool,
}

/// Set once stdout's reader has gone (`pendulum … | head`): the rest of the report is dropped.
static STDOUT_GONE: AtomicBool = AtomicBool::new(false);

/// Writes part of the report to stdout. A reader that went away (a broken pipe: `| head` has
/// what it wanted) is not the job's failure: the rest of the report is dropped quietly and the
/// exit code stays the job's own (0 when it succeeded; `print!` used to panic there, exit 101).
/// Any other write error (a full disk behind `> file`) is one, and is returned.
fn emit(args: std::fmt::Arguments<'_>) -> anyhow::Result<()> {
    if STDOUT_GONE.load(Ordering::Relaxed) {
        return Ok(());
    }
    let mut out = std::io::stdout().lock();
    match out.write_fmt(args).and_then(|()| out.flush()) {
        Ok(()) => Ok(()),
        Err(e) if e.kind() == std::io::ErrorKind::BrokenPipe => {
            STDOUT_GONE.store(true, Ordering::Relaxed);
            Ok(())
        }
        Err(e) => Err(anyhow::anyhow!("writing the report to stdout: {e}")),
    }
}

/// `print!` through [`emit`].
macro_rules! out {
    ($($arg:tt)*) => { emit(format_args!($($arg)*))? };
}

/// `println!` through [`emit`].
macro_rules! outln {
    () => { emit(format_args!("\n"))? };
    ($($arg:tt)*) => { emit(format_args!("{}\n", format_args!($($arg)*)))? };
}

fn main() -> ExitCode {
    // Fixes the invocation's id and start now: temporary files in OUT older than it are not ours.
    pendulum_jobs::invocation();
    let cli = Cli::parse();
    match run(cli) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            // Errors that name a file say `{path}: {source}` and keep the source in the chain:
            // a cause already said above is not printed again (it read "Not a directory" twice).
            // Written with `writeln!`, whose failure (stderr closed too) is ignored, not a panic.
            let mut err = std::io::stderr().lock();
            let mut said = e.to_string();
            let _ = writeln!(err, "error: {said}");
            for cause in e.chain().skip(1) {
                let cause = cause.to_string();
                if !said.contains(&cause) {
                    let _ = writeln!(err, "  caused by: {cause}");
                    said.push_str(&cause);
                }
            }
            ExitCode::FAILURE
        }
    }
}

fn run(cli: Cli) -> anyhow::Result<()> {
    match cli.command {
        Command::Simulate(a) => {
            let summary = simulate::run(&simulate::SimulateJob {
                params: a.params,
                theta0: a.theta0,
                theta_dot0: a.theta_dot0,
                t_end: a.t_end,
                dt_out: a.dt_out,
                tol: a.tol,
                out: a.out,
            })?;
            outln!("{summary}");
        }
        Command::Ingest(a) => {
            let summary = ingest::run(&a.campaign_dir, &a.out, !a.quiet)?;
            out!("{summary}");
            let failed = summary.failed();
            if failed > 0 {
                anyhow::bail!(
                    "{failed} of {} runs could not be ingested",
                    summary.rows.len()
                );
            }
        }
        Command::Synth(a) => {
            let s = synth::run(&a.case, &a.out_dir)?;
            outln!(
                "wrote {} runs to {} (campaign {}, truth {})",
                s.truth_data.runs.len(),
                s.dir.display(),
                s.campaign.display(),
                s.truth.display()
            );
            for r in &s.truth_data.runs {
                outln!(
                    "  {:<8} {:<6} Ω = {:.5} Hz  t0 = {:.4} s  θ0 = {:+.4} rad  θ̇0 = {:+.4} rad/s  steady {}",
                    r.id, format!("{:?}", r.format).to_lowercase(), r.omega_real_hz, r.t0_s, r.theta0_rad, r.theta_dot0_rad_s, r.steady
                );
            }
        }
        Command::Identify(a) => {
            let s = identify::run(&identify::IdentifyJob {
                input: a.input,
                out: a.out,
                pipeline: a.pipeline,
                overrides: identify::FitOverrides {
                    model: a.model,
                    np: a.np,
                    generations: a.generations,
                    tol: a.tol,
                    relative_tol: a.relative_tol,
                    seed: a.seed,
                    threads: a.threads,
                    window_s: a.window_s,
                    no_early_abandon: a.no_early_abandon,
                    mix_campaigns: a.mix_campaigns,
                },
                progress: !a.quiet,
                free_segments: a.free_segments,
            })?;
            out!("{s}");
        }
        Command::Discover(a) => {
            let s = discover::run(&discover::DiscoverJob {
                input: a.input,
                out: a.out,
                base: match a.base {
                    BaseArg::Reference => pendulum_discover::Base::Reference,
                    BaseArg::Linear => pendulum_discover::Base::Linear,
                    BaseArg::Dry => pendulum_discover::Base::Dry,
                },
                pipeline: a.pipeline,
                generations: a.generations,
                seed: a.seed,
                progress: !a.quiet,
            })?;
            out!("{s}");
        }
        Command::Validate(a) => {
            let s = identify::validate(&identify::ValidateJob {
                input: a.input,
                params: a.params,
                model: a.model,
                out: a.out,
                pipeline: a.pipeline,
                mix_campaigns: a.mix_campaigns,
            })?;
            out!("{s}");
        }
        Command::Bifurcate(a) => out!("{}", pendulum_jobs::bifurcate::run(&a)?),
        Command::Zones(a) => out!("{}", pendulum_jobs::zones::run(&a)?),
        Command::Design(a) => out!("{}", pendulum_jobs::design::run(&a)?),
        Command::Merge(a) => out!("{}", pendulum_jobs::merge::run(&a)?),
        Command::Replay(a) => out!("{}", pendulum_jobs::replay::run(&a)?),
        Command::Demo(a) => {
            outln!(
                "Study configurations (R = 0.7, λ = 0.126), {0}×{0} starts each, steady states:",
                a.grid
            );
            let rows = demo::run(a.grid)?;
            out!("{:<10} {:>6}", "model", "omega");
            for c in SteadyClass::ALL {
                out!(" {:>12}", c.as_str());
            }
            outln!();
            for r in rows {
                out!("{:<10} {:>6.3}", r.model, r.omega);
                for n in r.counts {
                    out!(" {n:>12}");
                }
                outln!();
            }
            if !a.quick {
                outln!("\nDigital twin campaign (truth: a = 0, b = 0.5 N·s/m, μ = 0.15) → raw captures → MCAP → identify:");
                let c = demo::campaign(&a.out, a.generations, true)?;
                out!("{}", c.ingest);
                out!("{}", c.identify);
                outln!(
                    "truth: a = {}, b = {}, μ = {}",
                    c.truth.params.a_kg_m,
                    c.truth.params.b_n_s_m,
                    c.truth.params.mu
                );
                outln!("\nA second twin campaign with an effect hidden in it (named at the end) → discover:");
                let d = demo::hidden_effect(&a.out, true)?;
                out!("{d}");
                outln!("(hidden: horizontal_base, δ = 0.04 rad)");
                outln!(
                    "\nWhere does it rotate? The study's dry-friction vs linear model over ω × R:"
                );
                let z = pendulum_jobs::zones::demo_comparison(&a.out.join("zones"), true)?;
                out!("{z}");
            }
        }
    }
    Ok(())
}
