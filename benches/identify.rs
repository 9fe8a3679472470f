//! Study-scale identification: N = 7 identify runs (the built-in twin campaign), Np = 160, to
//! convergence (best − worst < 0.001) or 1730 generations, on all cores; then the same budget
//! with the plain algorithm (no early abandoning) in the same run, and a check that both made
//! the same selections (identical best parameters).
//!
//! `cargo bench --bench identify` (env PENDULUM_BENCH_GENERATIONS caps the generations for a
//! quicker look). Prints; asserts nothing about time.

use std::time::Instant;

use pendulum_process::identify::{identify, FitConfig};
use pendulum_process::pipeline::{Context, PipelineConfig, StageConfig};
use pendulum_process::Role;
use pendulum_rig::twin::{synthesize, TwinCase};

const CASE: &str = include_str!("../crates/pendulum-jobs/cases/study.toml");

fn main() {
    let generations: u64 = std::env::var("PENDULUM_BENCH_GENERATIONS")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(1730);
    let dir = tempfile::tempdir().expect("tempdir");
    let case = TwinCase::from_toml(CASE, std::path::Path::new("study.toml")).expect("case");
    synthesize(&case, dir.path()).expect("twin");
    let runs = pendulum_jobs::runs::load_runs(dir.path()).expect("load");
    let pipeline = PipelineConfig::from_toml(
        pendulum_jobs::identify::IDENTIFY_PIPELINE,
        std::path::Path::new("identify.toml"),
    )
    .expect("pipeline");
    let mut fit_cfg: FitConfig = pipeline
        .stages
        .iter()
        .find_map(|s| match s {
            StageConfig::Fit(c) => Some(c.clone()),
            _ => None,
        })
        .expect("fit stage");
    let mut ctx = Context::new(runs);
    let prep = PipelineConfig {
        name: "prep".into(),
        stages: pipeline
            .stages
            .iter()
            .filter(|s| !matches!(s, StageConfig::Fit(_) | StageConfig::Validate(_)))
            .cloned()
            .collect(),
    };
    prep.run(&mut ctx).expect("stages");
    let prepared = ctx
        .prepared(Role::Identify, &fit_cfg.window, "bench")
        .expect("prepare");
    fit_cfg.np = Some(160);
    fit_cfg.max_generations = generations;
    println!(
        "study-scale fit: {} identify runs, Np = 160, ≤ {generations} generations, {} threads",
        prepared.len(),
        rayon::current_num_threads()
    );
    println!(
        "variant        wall_s  generations  evaluations  abandoned  f_obj        b        mu"
    );
    let mut results = Vec::new();
    for early in [true, false] {
        let mut cfg = fit_cfg.clone();
        cfg.early_abandon = early;
        if !early {
            // Same budget as the shortcut run actually used.
            cfg.max_generations = results
                .first()
                .map_or(generations, |r: &pendulum_process::identify::FitOutcome| {
                    r.generations
                });
            cfg.tol = 0.0;
        }
        let t = Instant::now();
        let out = identify(&prepared, &cfg, None).expect("identify");
        let wall = t.elapsed().as_secs_f64();
        println!(
            "{:<13} {wall:>7.1} {:>12} {:>12} {:>10} {:>10.4} {:>8.4} {:>9.5}",
            if early { "early-abandon" } else { "plain" },
            out.generations,
            out.evaluations,
            out.abandoned,
            out.f_obj,
            out.param(pendulum_process::fit::FitParam::B),
            out.param(pendulum_process::fit::FitParam::Mu),
        );
        results.push(out);
    }
    let same = results[0].params == results[1].params && results[0].f_obj == results[1].f_obj;
    println!("identical selections (same best parameters and objective): {same}");
    // The study's t_sim as a knob: the steady-state penalty simulated 20 s past the window
    // instead of to the capture's end (a different objective, so different selections).
    let mut cfg = fit_cfg.clone();
    cfg.window.t_sim_s = Some(20.0);
    let prepared_tsim = ctx
        .prepared(Role::Identify, &cfg.window, "bench")
        .expect("prepare");
    let t = Instant::now();
    let out = identify(&prepared_tsim, &cfg, None).expect("identify");
    println!(
        "{:<13} {:>7.1} {:>12} {:>12} {:>10} {:>10.4} {:>8.4} {:>9.5}",
        "t_sim = 20 s",
        t.elapsed().as_secs_f64(),
        out.generations,
        out.evaluations,
        out.abandoned,
        out.f_obj,
        out.param(pendulum_process::fit::FitParam::B),
        out.param(pendulum_process::fit::FitParam::Mu),
    );
}
