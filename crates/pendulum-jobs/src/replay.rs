//! `pendulum replay RUN.mcap --params params.parquet --model NAME --out overlay.mcap`: the run's
//! measured channels plus the model's simulation of the run on `/sim/theta` ([`SimulatedMsg`]:
//! simulated θ, θ̇ and the residual measured − simulated), on the run's own time axis, so that a
//! viewer (Foxglove, the `mcap` readers) plays measurement and simulation together.
//!
//! The run is aligned ([`pendulum_process::align`]: real crank speed, t0 at the first
//! acceleration peak at speed); the initial state is the encoder's local polynomial estimate at
//! t0 ([`pendulum_process::ic::estimate_state`]); the model is the params row's damping (a, b, μ
//! and any fitted effect, in SI) on the run's own rig and aligned crank speed. The simulation is
//! sampled at the encoder's sample times from t0 on (or fewer, with `--rate-hz`): simulated time
//! τ (s after t0) maps back to the run's `t_s = t0_s + τ`, so a simulated sample and the encoder
//! sample it pairs with share `t_s` and log time.

use std::collections::BTreeMap;
use std::ops::ControlFlow;
use std::path::PathBuf;

use pendulum_log::{read_run, RunLogOptions, SimulatedMsg};
use pendulum_maps::params_file::load_model;
use pendulum_model::{integrate, Model, ParamSpec, Physical, Sensors, SimOptions};
use pendulum_process::ic::{estimate_state, IcConfig};
use pendulum_process::{align, AlignConfig};

use crate::inputs::Inputs;
use crate::runs::run_data_from_log;
use crate::JobError;

/// Metadata record the replay adds (model, alignment, initial state).
pub const METADATA_REPLAY: &str = "replay";

/// `pendulum replay` options.
#[derive(Debug, Clone, clap::Args)]
pub struct ReplayArgs {
    /// The run file (MCAP written by `pendulum ingest`).
    pub run: PathBuf,
    /// params.parquet written by `pendulum identify`.
    #[arg(long = "params", value_name = "FILE")]
    pub params_file: PathBuf,
    /// Model name (a row of --params), e.g. reference.
    #[arg(long, value_name = "NAME")]
    pub model: String,
    /// Output MCAP file (measured channels + /sim/theta).
    #[arg(long, value_name = "FILE")]
    pub out: PathBuf,
    /// Integrator tolerance (relative and absolute).
    #[arg(long, default_value_t = 1e-9)]
    pub tol: f64,
    /// Simulated samples per second (default: one per encoder sample from t0 on).
    #[arg(long = "rate-hz")]
    pub rate_hz: Option<f64>,
}

/// What a replay wrote.
#[derive(Debug, Clone)]
pub struct ReplaySummary {
    pub run_id: String,
    pub model: String,
    pub physical: Physical,
    pub t0_s: f64,
    pub omega_hz: f64,
    pub theta0_rad: f64,
    pub theta_dot0_rad_s: f64,
    /// Simulated samples and their t_s span.
    pub samples: usize,
    pub t_span_s: (f64, f64),
    /// RMS of measured − simulated θ over the first 10 s after t0 and over the whole run, rad.
    pub residual_rms_10s: f64,
    pub residual_rms: f64,
    pub out: PathBuf,
    pub messages: BTreeMap<String, u64>,
}

impl std::fmt::Display for ReplaySummary {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let p = &self.physical;
        writeln!(
            f,
            "replay of run {} with model {} (a = {} kg/m, b = {} N·s/m, μ = {}): t0 = {:.4} s, Ω = {:.5} Hz, θ0 = {:+.4} rad, θ̇0 = {:+.4} rad/s",
            self.run_id, self.model, p.a_kg_m, p.b_n_s_m, p.mu, self.t0_s, self.omega_hz, self.theta0_rad, self.theta_dot0_rad_s
        )?;
        writeln!(
            f,
            "  simulated {} samples, t_s {:.3}–{:.3} s; residual (measured − simulated θ) RMS {:.4} rad over the first 10 s, {:.4} rad over the run",
            self.samples, self.t_span_s.0, self.t_span_s.1, self.residual_rms_10s, self.residual_rms
        )?;
        let counts: Vec<String> = self
            .messages
            .iter()
            .map(|(k, v)| format!("{k} {v}"))
            .collect();
        writeln!(f, "wrote {} ({})", self.out.display(), counts.join(", "))
    }
}

/// Runs `pendulum replay`.
pub fn run(a: &ReplayArgs) -> Result<ReplaySummary, JobError> {
    if !(a.tol.is_finite() && a.tol > 0.0 && a.tol < 1e-2) {
        return Err(JobError::Invalid(format!(
            "--tol {}: expected a tolerance in (0, 0.01)",
            a.tol
        )));
    }
    if let Some(r) = a.rate_hz {
        if !(r.is_finite() && r > 0.0) {
            return Err(JobError::Invalid(format!(
                "--rate-hz {r}: expected a rate > 0"
            )));
        }
    }
    // Checked before anything is read or simulated: the output replaces its target by rename,
    // so `--out` equal to `--params` (or to RUN) would silently destroy that input.
    let mut inputs = Inputs::new();
    inputs.add("RUN", &a.run);
    inputs.add("--params", &a.params_file);
    inputs.check_output("--out", &a.out)?;
    // One file, renamed into place whole; an interrupted earlier replay's temporary files of
    // it go, nothing else in that folder.
    crate::outputs::remove_stale_temps_of_file(&a.out)?;
    let log = read_run(&a.run)?;
    let rd = run_data_from_log(&log)?;
    if rd.enc_t_s.is_empty() {
        return Err(JobError::Invalid(format!(
            "{}: the run has no encoder samples",
            a.run.display()
        )));
    }
    let al = align(&rd, &AlignConfig::default())?;

    // The model: the row's damping and effects (SI) on this run's rig and crank speed.
    let row = load_model(&a.params_file, &a.model)?;
    for key in ["a", "b", "mu"] {
        if row.get(key).is_none() {
            return Err(JobError::Invalid(format!(
                "{}: model {} has no value in column {key:?} (the physical damping a, b, mu is needed to replay a run on its own rig)",
                a.params_file.display(),
                a.model
            )));
        }
    }
    let (mut physical, _) =
        ParamSpec::parse(&row.assignments(false))?.resolve(&Physical::default())?;
    physical.m_kg = rd.rig.m_kg;
    physical.l_m = rd.rig.l_m;
    physical.crank_r_m = rd.rig.crank_r_m;
    physical.rod_l_m = rd.rig.rod_l_m;
    physical.r_b_m = rd.rig.r_b_m;
    physical.g_m_s2 = rd.rig.g_m_s2;
    physical.omega_hz = al.omega_hz;
    physical.validate()?;
    let params = physical.to_dimensionless();
    params.validate()?;
    // The shared sensor transform, as the fit and discover simulate: an accel_delay shifts the
    // forcing (`Model::new` alone dropped it), the encoder offset moves the angle.
    let model = Model::measured(&physical);
    let sensors = Sensors::of(&physical);
    let w0 = physical.omega0_rad_s();

    // Initial state at t0, in the model's frame.
    let ic = estimate_state(&rd, al.t0_s, &IcConfig::default())?;
    let y0 = [sensors.theta_true(ic.theta_rad), ic.theta_dot_rad_s / w0];

    // Sample times: the encoder's from t0 on, decimated to --rate-hz if given.
    let enc = &log.encoder;
    let first = enc.partition_point(|e| e.t_s < al.t0_s);
    let step = match a.rate_hz {
        Some(r) if enc.len() > first + 1 => {
            let span = enc[enc.len() - 1].t_s - enc[first].t_s;
            let rate = (enc.len() - first - 1) as f64 / span.max(1e-9);
            ((rate / r).round() as usize).max(1)
        }
        _ => 1,
    };
    let idx: Vec<usize> = (first..enc.len()).step_by(step).collect();
    if idx.len() < 2 {
        return Err(JobError::Invalid(format!(
            "{}: fewer than 2 encoder samples after t0 = {:.3} s",
            a.run.display(),
            al.t0_s
        )));
    }
    let times: Vec<f64> = idx.iter().map(|&i| w0 * (enc[i].t_s - al.t0_s)).collect();
    let mut sim: Vec<[f64; 2]> = Vec::with_capacity(times.len());
    integrate(
        &model,
        &SimOptions::with_tol(a.tol),
        0.0,
        y0,
        *times.last().unwrap_or(&0.0),
        times.iter().copied(),
        |s| {
            sim.push([s.theta, s.theta_dot]);
            ControlFlow::Continue(())
        },
    )?;

    // The overlay file: the run's records, then /sim/theta.
    let start_ns = match (enc.first(), log.encoder_log_time_ns.first()) {
        (Some(e), Some(&lt)) if lt != e.t_us.saturating_mul(1000) => {
            let since_first_ns = (e.t_s * 1e6).round() as i128 * 1000;
            u64::try_from(i128::from(lt) - since_first_ns).ok()
        }
        _ => None,
    };
    let mut w = RunLogOptions::new()
        .library(concat!("pendulum replay/", env!("CARGO_PKG_VERSION")))
        .start_ns(start_ns)
        .create(&a.out)?;
    for (name, map) in &log.metadata {
        if name != METADATA_REPLAY {
            w.write_metadata(name, map.clone())?;
        }
    }
    let mut meta = BTreeMap::new();
    // The invocation id, as every table carries it.
    meta.insert(
        "invocation_id".to_string(),
        pendulum_report::invocation().id.clone(),
    );
    meta.insert("model".to_string(), a.model.clone());
    meta.insert(
        "params_file".to_string(),
        a.params_file.display().to_string(),
    );
    meta.insert("source".to_string(), a.run.display().to_string());
    meta.insert("t0_s".to_string(), al.t0_s.to_string());
    meta.insert("omega_hz".to_string(), al.omega_hz.to_string());
    meta.insert("theta0_rad".to_string(), ic.theta_rad.to_string());
    meta.insert(
        "theta_dot0_rad_s".to_string(),
        ic.theta_dot_rad_s.to_string(),
    );
    meta.insert("tol".to_string(), a.tol.to_string());
    meta.insert(
        "params".to_string(),
        serde_json::to_string(&params).unwrap_or_default(),
    );
    meta.insert(
        "physical".to_string(),
        serde_json::to_string(&physical).unwrap_or_default(),
    );
    w.write_metadata(METADATA_REPLAY, meta)?;
    for e in enc {
        w.write_encoder(e)?;
    }
    for acc in &log.accel {
        w.write_accel(acc)?;
    }
    let (mut ss10, mut n10, mut ss, mut n) = (0.0, 0usize, 0.0, 0usize);
    for (&i, s) in idx.iter().zip(&sim) {
        let e = &enc[i];
        let theta = sensors.theta_measured(s[0]);
        let residual = e.theta_rad - theta;
        w.write_simulated(&SimulatedMsg {
            t_s: e.t_s,
            theta_rad: theta,
            theta_dot_rad_s: s[1] * w0,
            residual_rad: residual,
        })?;
        ss += residual * residual;
        n += 1;
        if e.t_s - al.t0_s <= 10.0 {
            ss10 += residual * residual;
            n10 += 1;
        }
    }
    if let Some(stats) = &log.stats {
        w.write_stats(stats)?;
    }
    let written = w.finish()?;
    let rms = |s: f64, n: usize| {
        if n > 0 {
            (s / n as f64).sqrt()
        } else {
            f64::NAN
        }
    };
    Ok(ReplaySummary {
        run_id: rd.id.clone(),
        model: a.model.clone(),
        physical,
        t0_s: al.t0_s,
        omega_hz: al.omega_hz,
        theta0_rad: ic.theta_rad,
        theta_dot0_rad_s: ic.theta_dot_rad_s,
        samples: sim.len(),
        t_span_s: (enc[idx[0]].t_s, enc[idx[sim.len().max(1) - 1]].t_s),
        residual_rms_10s: rms(ss10, n10),
        residual_rms: rms(ss, n),
        out: written.path,
        messages: written.messages,
    })
}
