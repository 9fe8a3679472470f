//! `pendulum demo`: the main job on built-in data. For now: the study's two damping models at a
//! few forcing frequencies, each from a grid of initial states, with the steady states they reach.

use pendulum_model::steady::steady_state_of;
use pendulum_model::{ClassifyOptions, Dimensionless, Model, SimOptions, SteadyClass};
use rayon::prelude::*;

use crate::JobError;

/// One configuration's outcome.
#[derive(Debug, Clone)]
pub struct DemoRow {
    pub model: &'static str,
    pub omega: f64,
    /// Number of starts per class, in `SteadyClass::ALL` order.
    pub counts: [usize; 5],
    pub starts: usize,
}

/// The study's dry-friction model (Fig. 8: β = 0.109, M = 0.007) and the classic linear model
/// (Fig. 9: β = 0.066, M = 0) at R = 0.7, λ = 0.126.
pub fn study_models(omega: f64) -> [(&'static str, Dimensionless); 2] {
    let mut d = Dimensionless::conservative();
    d.omega = omega;
    d.r = 0.7;
    d.lambda = 0.126;
    let mut reference = d;
    reference.beta = 0.109;
    reference.m_coulomb = 0.007;
    let mut linear = d;
    linear.beta = 0.066;
    [("reference", reference), ("linear", linear)]
}

pub fn run(grid: usize) -> Result<Vec<DemoRow>, JobError> {
    let omegas = [1.57, 1.585, 2.0, 2.8];
    let mut jobs = Vec::new();
    for &w in &omegas {
        for (name, d) in study_models(w) {
            jobs.push((name, w, d));
        }
    }
    jobs.par_iter()
        .map(|&(name, omega, d)| {
            let model = Model::new(d);
            let mut counts = [0usize; 5];
            for i in 0..grid {
                for j in 0..grid {
                    let th0 =
                        -std::f64::consts::PI + 2.0 * std::f64::consts::PI * i as f64 / grid as f64;
                    let w0 = -3.0 + 6.0 * j as f64 / grid as f64;
                    let (s, _, _) = steady_state_of(
                        &model,
                        &SimOptions::with_tol(1e-8),
                        [th0, w0],
                        0.0,
                        200,
                        32,
                        &ClassifyOptions::default(),
                    )?;
                    let k = SteadyClass::ALL
                        .iter()
                        .position(|c| *c == s.class)
                        .unwrap_or(4);
                    counts[k] += 1;
                }
            }
            Ok(DemoRow {
                model: name,
                omega,
                counts,
                starts: grid * grid,
            })
        })
        .collect()
}

/// The twin campaign the demo analyses (seven identify and three validate runs, both formats).
pub const STUDY_CASE: &str = include_str!("../cases/study.toml");

/// What the campaign part of the demo produced.
#[derive(Debug, Clone)]
pub struct DemoCampaign {
    pub campaign_dir: std::path::PathBuf,
    pub ingest: crate::ingest::IngestSummary,
    pub identify: crate::outputs::OutputSummary,
    pub truth: pendulum_rig::twin::TwinTruthFile,
}

/// Synthesises the built-in twin campaign into `out/campaign`, ingests it to `out/mcap`, and
/// identifies the reference model from the MCAP files into `out/identify`.
pub fn campaign(
    out: &std::path::Path,
    generations: u64,
    progress: bool,
) -> Result<DemoCampaign, JobError> {
    use pendulum_rig::twin::{synthesize, TwinCase};
    let campaign_dir = out.join("campaign");
    let case = TwinCase::from_toml(STUDY_CASE, std::path::Path::new("<built-in study.toml>"))?;
    let truth = synthesize(&case, &campaign_dir)?.truth_data;
    let mcap_dir = out.join("mcap");
    let ingest = crate::ingest::run(&campaign_dir, &mcap_dir, progress)?;
    let identify = crate::identify::run(&crate::identify::IdentifyJob {
        input: mcap_dir,
        out: out.join("identify"),
        pipeline: None,
        overrides: crate::identify::FitOverrides {
            generations: Some(generations),
            ..Default::default()
        },
        progress,
        free_segments: false,
    })?;
    Ok(DemoCampaign {
        campaign_dir,
        ingest,
        identify,
        truth,
    })
}

/// A discovery campaign for the twin: five identify and three validate runs whose design is
/// drawn per run from `seed` as rig.md allows ([`pendulum_rig::twin::draw_design`]: bob, length,
/// crank, speed, format, hand start, durations), with damping a, b, μ and `effects` (lines of
/// the case's `[truth.effects]` table) hidden in the captures.
pub fn discovery_campaign(name: &str, seed: u64, a: f64, b: f64, mu: f64, effects: &str) -> String {
    let roles = [
        "identify", "identify", "identify", "identify", "identify", "validate", "validate",
        "validate",
    ];
    let rod_l_m = 0.575;
    format!(
        "name = \"{name}\"\nseed = {seed}\n[rig]\nm_kg = 1.46\nl_m = 0.265\ncrank_r_m = 0.0725\nrod_L_m = {rod_l_m}\nr_b_m = 0.01225\n[truth]\na_kg_m = {a}\nb_n_s_m = {b}\nmu = {mu}\n[truth.effects]\n{effects}\n{}",
        pendulum_rig::twin::draw_design(seed, &roles, rod_l_m)
    )
}

/// The demo's discovery campaign: a guide tilted 0.04 rad from vertical (`horizontal_base`)
/// hidden in the captures.
pub fn discovery_case() -> String {
    discovery_campaign(
        "demo-hidden-effect",
        2027,
        0.0,
        0.5,
        0.15,
        "horizontal_base_delta_rad = 0.04",
    )
}

/// Writes the discovery campaign into `out/hidden` and runs `discover` on it (reference base).
pub fn hidden_effect(
    out: &std::path::Path,
    progress: bool,
) -> Result<crate::discover::DiscoverSummary, JobError> {
    use pendulum_rig::twin::{synthesize, TwinCase};
    let dir = out.join("hidden");
    let case = TwinCase::from_toml(
        &discovery_case(),
        std::path::Path::new("<built-in discovery case>"),
    )?;
    synthesize(&case, &dir)?;
    crate::discover::run(&crate::discover::DiscoverJob {
        input: dir,
        out: out.join("discover"),
        base: pendulum_discover::Base::Reference,
        pipeline: None,
        generations: Some(300),
        seed: None,
        progress,
    })
}
