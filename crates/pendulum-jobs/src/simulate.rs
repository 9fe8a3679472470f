//! `pendulum simulate`: integrate the dimensionless equation from one initial state, classify the
//! steady state, write the trajectory to Parquet.

use std::path::PathBuf;

use pendulum_model::steady::steady_state_of;
use pendulum_model::{
    mean_powers, simulate, ClassifyOptions, MeanPowers, Model, ParamSpec, Physical, SimOptions,
    SteadyState,
};
use pendulum_report::{Column, TableOptions, TableSummary};

use crate::JobError;

/// What to simulate.
#[derive(Debug, Clone)]
pub struct SimulateJob {
    /// `key=value` parameter assignments (see [`ParamSpec`]).
    pub params: Vec<String>,
    /// Initial angle, rad.
    pub theta0: f64,
    /// Initial dimensionless angular velocity dθ/dt.
    pub theta_dot0: f64,
    /// End time (dimensionless).
    pub t_end: f64,
    /// Output spacing (dimensionless).
    pub dt_out: f64,
    /// Integrator tolerance (relative and absolute).
    pub tol: f64,
    /// Output Parquet file; `None` = classify only.
    pub out: Option<PathBuf>,
}

/// What a simulation produced.
#[derive(Debug, Clone)]
pub struct SimulateSummary {
    pub model: Model,
    pub physical: Physical,
    pub steady: SteadyState,
    pub rows: usize,
    pub steps: u64,
    pub events: u64,
    /// Mean powers in W over the recorded whole forcing periods (the ones the class is read
    /// from), with that window in dimensionless time; `None` when the run is shorter than two
    /// periods.
    pub power: Option<PowerWindow>,
    pub table: Option<TableSummary>,
}

/// Mean powers over a window of whole forcing periods.
#[derive(Debug, Clone, Copy)]
pub struct PowerWindow {
    /// Window start and end, dimensionless time.
    pub t_from: f64,
    pub t_to: f64,
    /// Whole forcing periods in it.
    pub periods: u32,
    /// Mean powers, W.
    pub watts: MeanPowers,
}

impl std::fmt::Display for SimulateSummary {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let d = &self.model.params;
        write!(
            f,
            "omega={:.4} R={:.4} lambda={:.4} alpha={:.4} beta={:.4} M={:.5}: {} (mean dθ/dt {:+.4}); {} steps, {} θ'=0 events",
            d.omega, d.r, d.lambda, d.alpha, d.beta, d.m_coulomb, self.steady, self.steady.mean_theta_dot, self.steps, self.events
        )?;
        if let Some(p) = &self.power {
            let w = &p.watts;
            // One line (scripts read it): the balance as an equation, in mW.
            write!(
                f,
                "; mean power over the last {} periods, mW: base {:.4} = viscous {:.4} + quadratic {:.4} + dry {:.4} + generator {:.4} (load {:.4}, diodes {:.4}) + stored {:+.2e}",
                p.periods,
                1e3 * w.base,
                1e3 * w.viscous,
                1e3 * w.quadratic,
                1e3 * w.dry,
                1e3 * w.generator,
                1e3 * w.load,
                1e3 * w.diodes,
                1e3 * w.stored
            )?;
        }
        if let Some(t) = &self.table {
            write!(f, "; wrote {} ({} rows)", t.path.display(), t.rows)?;
        }
        Ok(())
    }
}

/// The most output samples `simulate` writes. The trajectory holds t, θ, θ̇ (3 × 8 = 24 bytes a
/// sample) in vectors that grow by doubling (up to 2× while growing), and the table is written
/// from a copy of them plus Arrow's own buffers: about 4 × 24 ≈ 100 bytes a sample at the peak,
/// so 20,000,000 samples ≈ 2 GB, a tenth of this 24 GB machine and within a laptop's. The
/// default run (t = 300, dt_out = 0.05) writes 6,001.
pub const MAX_SAMPLES: f64 = 20_000_000.0;

/// Refuses a `t_end`/`dt_out` pair whose output would not fit in memory, before integrating:
/// `--dt-out 1e-9` used to abort on a 4 GB allocation (exit 134), `--t-end 1e9` to grow until the
/// integrator's step cap. Invalid values (non-positive, NaN) are left to the simulator's check.
fn check_size(job: &SimulateJob) -> Result<(), JobError> {
    if !(job.dt_out > 0.0) || !(job.t_end > 0.0) {
        return Ok(());
    }
    let samples = (job.t_end / job.dt_out).floor() + 1.0;
    if samples <= MAX_SAMPLES {
        return Ok(());
    }
    Err(JobError::TooLarge {
        given: format!("--t-end {} with --dt-out {}", job.t_end, job.dt_out),
        what: format!("{samples:.3e} output samples"),
        limit: format!("{MAX_SAMPLES:.0}"),
        why: "each sample is t, θ, θ̇ (24 bytes), held about 4 times over while the table is \
              written: 2 GB at the limit; raise --dt-out or lower --t-end"
            .into(),
    })
}

/// Poincaré points recorded for the class: the last `RECORD` forcing periods (or half the run).
const RECORD: u32 = 50;

pub fn run(job: &SimulateJob) -> Result<SimulateSummary, JobError> {
    check_size(job)?;
    let spec = ParamSpec::parse(&job.params)?;
    let (physical, params) = spec.resolve(&Physical::default())?;
    let model = Model::new(params);
    let opts = SimOptions::with_tol(job.tol);
    let tr = simulate(
        &model,
        &opts,
        [job.theta0, job.theta_dot0],
        0.0,
        job.t_end,
        job.dt_out,
    )?;
    // Same integration (the step sequence does not depend on output times) sampled once per period.
    let period = params.forcing_period();
    let period = if period.is_finite() {
        period
    } else {
        2.0 * std::f64::consts::PI
    };
    let n = (job.t_end / period).floor() as u32;
    let record = RECORD.min(n / 2);
    let (steady, _, _) = steady_state_of(
        &model,
        &opts,
        [job.theta0, job.theta_dot0],
        0.0,
        n - record,
        record,
        &ClassifyOptions::default(),
    )?;
    // Powers over the same whole periods the class is read from (after the transient).
    let power = if record >= 1 {
        let (t_from, t_to) = (f64::from(n - record) * period, f64::from(n) * period);
        let dimensionless = mean_powers(
            &model,
            &opts,
            0.0,
            [job.theta0, job.theta_dot0],
            t_from,
            t_to,
        )?;
        Some(PowerWindow {
            t_from,
            t_to,
            periods: record,
            watts: dimensionless.si(physical.power_scale_w()),
        })
    } else {
        None
    };
    let table = match &job.out {
        None => None,
        Some(path) => {
            // The table is one file, renamed into place whole (never half written) and
            // carrying the invocation id; an interrupted earlier run's temporary files of it
            // go, nothing else in that folder.
            crate::outputs::remove_stale_temps_of_file(path)?;
            let cols = vec![
                Column::f64("t", "1 (t = ω0·τ)", tr.t.clone()).describe("dimensionless time"),
                Column::f64("theta", "rad", tr.theta.clone())
                    .describe("angle from hanging, unwrapped"),
                Column::f64("theta_dot", "1 (dθ/dt)", tr.theta_dot.clone())
                    .describe("dimensionless angular velocity"),
            ];
            let mut meta = TableOptions::new()
                .meta("steady_state", steady.class.as_str())
                .meta("period", steady.period.to_string())
                .meta("mean_theta_dot", format!("{}", steady.mean_theta_dot))
                .meta("params", serde_json::to_string(&params).unwrap_or_default())
                .meta(
                    "physical",
                    serde_json::to_string(&physical).unwrap_or_default(),
                )
                .meta("theta0", job.theta0.to_string())
                .meta("theta_dot0", job.theta_dot0.to_string())
                .meta("tol", job.tol.to_string())
                .meta("command", "pendulum simulate");
            // Scalars of the run, so metadata: the unit is in each key's name (`_w`: W, `_t`:
            // dimensionless time), as the columns carry theirs in field metadata.
            if let Some(p) = &power {
                meta = meta
                    .meta("mean_power_from_t", p.t_from.to_string())
                    .meta("mean_power_to_t", p.t_to.to_string())
                    .meta("mean_power_periods", p.periods.to_string());
                for (name, v) in p.watts.named() {
                    meta = meta.meta(&format!("mean_power_{name}_w"), v.to_string());
                }
            }
            Some(meta.write(path, &cols)?)
        }
    };
    Ok(SimulateSummary {
        rows: tr.t.len(),
        steps: tr.stats.steps,
        events: tr.stats.events,
        power,
        model,
        physical,
        steady,
        table,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The study's rotation with a generator given electrically: the run reports the mean
    /// powers over its recorded whole periods (base = the losses + the stored energy's rate,
    /// that rate ≈ 0, the generator's load + diodes its whole power), prints them on its one
    /// line and writes them, in W, to the table's metadata.
    #[test]
    fn simulate_reports_and_writes_the_power_balance() {
        let dir = tempfile::tempdir().unwrap();
        let out = dir.path().join("sim.parquet");
        let job = SimulateJob {
            params: [
                "omega=1.585",
                "R=0.7",
                "lambda=0.126",
                "alpha=0",
                "beta=0.109",
                "M=0.007",
                "generator_rectified.k_e=0.1",
                "generator_rectified.V_d=0.3",
                "generator_rectified.R=2",
            ]
            .map(String::from)
            .to_vec(),
            theta0: 0.0,
            theta_dot0: 2.5,
            t_end: 300.0,
            dt_out: 0.05,
            tol: 1e-9,
            out: Some(out.clone()),
        };
        let s = run(&job).unwrap();
        // Rotating, one turn per forcing period on average (the classifier's verdict on so
        // short a run does not matter here).
        assert!((s.steady.mean_theta_dot - 1.585).abs() < 1e-3, "{s}");
        let p = s.power.expect("a power window");
        let w = p.watts;
        assert!(
            w.base > 0.0 && w.generator > 0.0 && w.dry > 0.0 && w.viscous > 0.0,
            "{w:?}"
        );
        assert!(
            (w.base - w.dissipated() - w.stored).abs() < 1e-6 * w.base,
            "base {} vs dissipated {} + stored {}",
            w.base,
            w.dissipated(),
            w.stored
        );
        assert!(w.stored.abs() < 1e-4 * w.base, "{w:?}");
        assert!((w.load + w.diodes - w.generator).abs() < 1e-9 * w.generator);
        assert!(w.load > 0.0 && w.load < w.generator);
        let line = s.to_string();
        assert!(!line.contains('\n') && line.contains("generator"), "{line}");

        use parquet::file::reader::{FileReader, SerializedFileReader};
        let r = SerializedFileReader::new(std::fs::File::open(&out).unwrap()).unwrap();
        let kv: std::collections::HashMap<String, String> = r
            .metadata()
            .file_metadata()
            .key_value_metadata()
            .unwrap()
            .iter()
            .map(|k| (k.key.clone(), k.value.clone().unwrap_or_default()))
            .collect();
        let get = |k: &str| -> f64 { kv[k].parse().unwrap() };
        assert_eq!(get("mean_power_generator_w"), w.generator);
        assert_eq!(get("mean_power_load_w"), w.load);
        assert_eq!(get("mean_power_base_w"), w.base);
        assert_eq!(get("mean_power_to_t"), p.t_to);
    }
}
