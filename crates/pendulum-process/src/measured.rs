//! The measured steady state of a run's tail, classified like a simulation (Poincaré section,
//! one point per crank turn) with tolerances above the encoder's resolution and noise.

use pendulum_model::{classify_history, ClassifyOptions, SteadyState};
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
