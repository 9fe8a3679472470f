//! The `pendulum` binary: parses arguments, calls the library crates, prints results and errors
//! (with their chain), maps failures to exit codes. No logic lives here.

use std::path::PathBuf;
use std::process::ExitCode;

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
    /// Merge the shards of a map (`bifurcate`/`zones --shard I/N --out DIR`) into the table and
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

fn main() -> ExitCode {
    // Fixes the invocation's id and start now: temporary files in OUT older than it are not ours.
    pendulum_jobs::invocation();
    let cli = Cli::parse();
    match run(cli) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            // Errors that name a file say `{path}: {source}` and keep the source in the chain:
            // a cause already said above is not printed again (it read "Not a directory" twice).
            let mut said = e.to_string();
            eprintln!("error: {said}");
            for cause in e.chain().skip(1) {
                let cause = cause.to_string();
                if !said.contains(&cause) {
                    eprintln!("  caused by: {cause}");
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
            println!("{summary}");
        }
        Command::Ingest(a) => {
            let summary = ingest::run(&a.campaign_dir, &a.out, !a.quiet)?;
            print!("{summary}");
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
            println!(
                "wrote {} runs to {} (campaign {}, truth {})",
                s.truth_data.runs.len(),
                s.dir.display(),
                s.campaign.display(),
                s.truth.display()
            );
            for r in &s.truth_data.runs {
                println!(
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
                },
                progress: !a.quiet,
                free_segments: a.free_segments,
            })?;
            print!("{s}");
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
            print!("{s}");
        }
        Command::Validate(a) => {
            let s = identify::validate(&identify::ValidateJob {
                input: a.input,
                params: a.params,
                model: a.model,
                out: a.out,
                pipeline: a.pipeline,
            })?;
            print!("{s}");
        }
        Command::Bifurcate(a) => print!("{}", pendulum_jobs::bifurcate::run(&a)?),
        Command::Zones(a) => print!("{}", pendulum_jobs::zones::run(&a)?),
        Command::Merge(a) => print!("{}", pendulum_jobs::merge::run(&a)?),
        Command::Replay(a) => print!("{}", pendulum_jobs::replay::run(&a)?),
        Command::Demo(a) => {
            println!(
                "Study configurations (R = 0.7, λ = 0.126), {0}×{0} starts each, steady states:",
                a.grid
            );
            let rows = demo::run(a.grid)?;
            print!("{:<10} {:>6}", "model", "omega");
            for c in SteadyClass::ALL {
                print!(" {:>12}", c.as_str());
            }
            println!();
            for r in rows {
                print!("{:<10} {:>6.3}", r.model, r.omega);
                for n in r.counts {
                    print!(" {n:>12}");
                }
                println!();
            }
            if !a.quick {
                println!("\nDigital twin campaign (truth: a = 0, b = 0.5 N·s/m, μ = 0.15) → raw captures → MCAP → identify:");
                let c = demo::campaign(&a.out, a.generations, true)?;
                print!("{}", c.ingest);
                print!("{}", c.identify);
                println!(
                    "truth: a = {}, b = {}, μ = {}",
                    c.truth.params.a_kg_m, c.truth.params.b_n_s_m, c.truth.params.mu
                );
                println!("\nA second twin campaign with an effect hidden in it (named at the end) → discover:");
                let d = demo::hidden_effect(&a.out, true)?;
                print!("{d}");
                println!("(hidden: horizontal_base, δ = 0.04 rad)");
                println!(
                    "\nWhere does it rotate? The study's dry-friction vs linear model over ω × R:"
                );
                let z = pendulum_jobs::zones::demo_comparison(&a.out.join("zones"), true)?;
                print!("{z}");
            }
        }
    }
    Ok(())
}
