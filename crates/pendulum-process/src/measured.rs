//! The measured steady state of a run's tail, classified like a simulation (Poincaré section,
//! one point per crank turn) with tolerances above the encoder's resolution and noise.

use pendulum_model::{classify_history, ClassifyOptions, SteadyClass, SteadyState};
use serde::{Deserialize, Serialize};

use crate::run::RunData;
use crate::ProcessError;

/// Measured-steady-state settings.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct SteadyConfig {
    /// The tail classified, s (the end of the capture).
    pub tail_s: f64,
    /// Angle tolerance for two Poincaré points to repeat, rad.
    pub theta_tol_rad: f64,
    /// A tail whose angle stays within this of its mean is at rest, rad.
    pub rest_tol_rad: f64,
}

impl Default for SteadyConfig {
    fn default() -> Self {
        Self {
            tail_s: 20.0,
            theta_tol_rad: 0.05,
            rest_tol_rad: 0.01,
        }
    }
}

impl SteadyConfig {
    /// Classifier options for a given crank period (θ̇'s stand-in is Δθ over a quarter period).
    pub fn classify_options(&self, period_s: f64) -> ClassifyOptions {
        ClassifyOptions {
            theta_tol: self.theta_tol_rad,
            theta_dot_tol: self.theta_tol_rad / (0.25 * period_s),
            max_period: 16,
            rest_tol: self.rest_tol_rad,
        }
    }
}

/// Class of the last `tail_s` of the run at crank speed `omega_hz`.
pub fn measured_steady_state(
    run: &RunData,
    omega_hz: f64,
    cfg: &SteadyConfig,
) -> Result<SteadyState, ProcessError> {
    let period = 1.0 / omega_hz;
    let t_end = *run.enc_t_s.last().ok_or_else(|| ProcessError::Run {
        run: run.id.clone(),
        reason: "no encoder samples".into(),
    })?;
    classify_history(
        &run.enc_t_s,
        &run.theta_rad,
        period,
        t_end - cfg.tail_s,
        &cfg.classify_options(period),
    )
    .map_err(|e| ProcessError::Run {
        run: run.id.clone(),
        reason: format!("steady state of the last {} s: {e}", cfg.tail_s),
    })
}

/// Class of a free decay's tail (no forcing period to take a Poincaré section with): `rest` when
/// θ stays within `rest_tol_rad` of its mean over the tail's second half (see
/// [`classify_free`]), else `oscillation` (the capture ended while it still swung). The tail is the last `tail_s` but at most a quarter of the record from
/// `t_from_s`: a decay is mostly transient, and `tail_s` is sized for forced runs.
pub fn free_steady_state(
    run: &RunData,
    t_from_s: f64,
    cfg: &SteadyConfig,
) -> Result<SteadyState, ProcessError> {
    let t_end = *run.enc_t_s.last().ok_or_else(|| ProcessError::Run {
        run: run.id.clone(),
        reason: "no encoder samples".into(),
    })?;
    let from = free_tail_start_s(t_end, t_from_s, cfg);
    let lo = run.enc_t_s.partition_point(|&x| x < from);
    Ok(classify_free(&run.theta_rad[lo..], cfg.rest_tol_rad))
}

/// `rest` when the angles of the tail's second half stay within `rest_tol` of their mean (the
/// decay came to rest inside the tail: its last swings before stopping are no steady
/// oscillation), else `oscillation`. Measured and simulated tails go through the same rule.
pub fn classify_free(theta: &[f64], rest_tol: f64) -> SteadyState {
    let settled = &theta[theta.len() / 2..];
    let n = settled.len().max(1) as f64;
    let mean = settled.iter().sum::<f64>() / n;
    let still = settled.iter().all(|v| (v - mean).abs() <= rest_tol);
    SteadyState {
        class: if still {
            SteadyClass::Rest
        } else {
            SteadyClass::Oscillation
        },
        period: u32::from(!still),
        mean_theta_dot: 0.0,
    }
}

/// Start of a free decay's classified tail, s (see [`free_steady_state`]).
pub fn free_tail_start_s(t_end_s: f64, t_from_s: f64, cfg: &SteadyConfig) -> f64 {
    (t_end_s - cfg.tail_s).max(t_end_s - 0.25 * (t_end_s - t_from_s))
}
