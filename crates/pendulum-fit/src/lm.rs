//! Levenberg–Marquardt for bounded least squares: Marquardt's diagonal damping, steps projected
//! onto the box, and an active set that holds a variable on its bound while the step would push
//! it out.
//!
//! One iteration builds A = JᵀJ and g = Jᵀr at the current point and tries damped steps
//! δ = −(A + λ·diag A)⁻¹ g: a variable sitting on a bound whose δ points outward is frozen (its row
//! and column removed) and the step re-solved, until the frozen set stops growing; the trial
//! point x + δ is clamped into the box. A trial that lowers Σ r² is accepted and λ shrinks; a
//! trial that does not, or whose residuals fail, grows λ and is retried, at most
//! [`LmConfig::max_tries`] times per iteration.

use pendulum_numerics::solve_spd;
use serde::{Deserialize, Serialize};

use crate::error::FitError;
use crate::least_squares::{
    jtj, neg_jt_r, prepare, project, sum_of_squares, Evaluator, LeastSquaresProblem, LsResult,
    LsStop,
};

/// Settings of [`LevenbergMarquardt`]. Deserialises from partial tables (missing fields take the
/// defaults); unknown keys are rejected.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct LmConfig {
    /// Iteration cap (0 returns the projected start). Default 100.
    pub max_iterations: usize,
    /// Initial damping λ, > 0. Default 1e-3.
    pub lambda_init: f64,
    /// λ is multiplied by this after a rejected trial (no decrease, or failed residuals), > 1.
    /// Default 8.
    pub lambda_up: f64,
    /// λ is multiplied by this when the damped normal matrix cannot be factorised, > 1.
    /// Default 10.
    pub lambda_up_singular: f64,
    /// λ is divided by this after an accepted step, ≥ 1. Default 5.
    pub lambda_down: f64,
    /// Floor of λ after an accepted step, ≥ 0. Default 1e-9.
    pub lambda_min: f64,
    /// Trial steps per iteration before giving up ([`LsStop::NoImprovement`]), ≥ 1. Default 14.
    pub max_tries: usize,
    /// An accepted step whose relative decrease of Σ r², (old − new)/old, is below this counts as
    /// small, ≥ 0. Default 1e-9.
    pub rel_decrease: f64,
    /// Converged after this many small steps in a row, ≥ 1. Default 2.
    pub patience: usize,
}

impl Default for LmConfig {
    fn default() -> Self {
        Self {
            max_iterations: 100,
            lambda_init: 1e-3,
            lambda_up: 8.0,
            lambda_up_singular: 10.0,
            lambda_down: 5.0,
            lambda_min: 1e-9,
            max_tries: 14,
            rel_decrease: 1e-9,
            patience: 2,
        }
    }
}

impl LmConfig {
    /// Sets [`max_iterations`](Self::max_iterations).
    pub fn with_max_iterations(mut self, n: usize) -> Self {
        self.max_iterations = n;
        self
    }

    /// Checks the ranges.
    pub fn validate(&self) -> Result<(), FitError> {
        let bad = |field, value: f64, expected| {
            Err(FitError::BadConfig {
                field,
                value: value.to_string(),
                expected,
            })
        };
        // Written so that NaN fails too.
        if !(self.lambda_init > 0.0 && self.lambda_init.is_finite()) {
            return bad("lambda_init", self.lambda_init, "finite lambda_init > 0");
        }
        if !(self.lambda_up > 1.0) {
            return bad("lambda_up", self.lambda_up, "lambda_up > 1");
        }
        if !(self.lambda_up_singular > 1.0) {
            return bad(
                "lambda_up_singular",
                self.lambda_up_singular,
                "lambda_up_singular > 1",
            );
        }
        if !(self.lambda_down >= 1.0) {
            return bad("lambda_down", self.lambda_down, "lambda_down ≥ 1");
        }
        if !(self.lambda_min >= 0.0) {
            return bad("lambda_min", self.lambda_min, "lambda_min ≥ 0");
        }
        if self.max_tries == 0 {
            return bad("max_tries", 0.0, "max_tries ≥ 1");
        }
        if !(self.rel_decrease >= 0.0) {
            return bad("rel_decrease", self.rel_decrease, "rel_decrease ≥ 0");
        }
        if self.patience == 0 {
            return bad("patience", 0.0, "patience ≥ 1");
        }
        Ok(())
    }
}

/// Bounded Levenberg–Marquardt (see the module docs).
#[derive(Debug, Clone, PartialEq)]
pub struct LevenbergMarquardt {
    config: LmConfig,
}

impl LevenbergMarquardt {
    /// A solver with checked settings.
    pub fn new(config: LmConfig) -> Result<Self, FitError> {
        config.validate()?;
        Ok(Self { config })
    }

    pub fn config(&self) -> &LmConfig {
        &self.config
    }

    /// Minimises Σ r² from `x0` (projected into the box first).
    ///
    /// Errors: a malformed problem or start, residuals that fail at the start, or a Jacobian
    /// that fails at an accepted point. Residuals that fail at a trial point only grow λ.
    pub fn solve<P: LeastSquaresProblem + ?Sized>(
        &self,
        problem: &P,
        x0: &[f64],
    ) -> Result<LsResult, FitError> {
        let cfg = &self.config;
        let (bounds, mut x) = prepare(problem, x0)?;
        let p = x.len();
        let mut eval = Evaluator::new(problem);
        let mut r = eval
            .residuals(&x)
            .ok_or_else(|| FitError::ResidualsFailed { x: x.clone() })?;
        let mut rss = sum_of_squares(&r);
        let mut jac = eval.jacobian(&x, &r)?;
        let mut lambda = cfg.lambda_init;
        let mut iterations = 0;
        let mut small_steps = 0;
        let mut stop = LsStop::MaxIterations;
        for _ in 0..cfg.max_iterations {
            iterations += 1;
            let a = jtj(&jac);
            // −Jᵀr: the right-hand side of the normal equations.
            let g = neg_jt_r(&jac, &r);
            let mut accepted = None;
            for _ in 0..cfg.max_tries {
                let Some(delta) = damped_step(&a, &g, lambda, &x, &bounds) else {
                    lambda *= cfg.lambda_up_singular;
                    continue;
                };
                let mut xn: Vec<f64> = x.iter().zip(&delta).map(|(a, d)| a + d).collect();
                project(&mut xn, &bounds);
                let Some(rn) = eval.residuals(&xn) else {
                    lambda *= cfg.lambda_up;
                    continue;
                };
                let rssn = sum_of_squares(&rn);
                if rssn.is_finite() && rssn < rss {
                    accepted = Some((xn, rn, rssn));
                    lambda = (lambda / cfg.lambda_down).max(cfg.lambda_min);
                    break;
                }
                lambda *= cfg.lambda_up;
            }
            let Some((xn, rn, rssn)) = accepted else {
                stop = LsStop::NoImprovement;
                break;
            };
            let rel = (rss - rssn) / rss.max(1e-300);
            x = xn;
            r = rn;
            rss = rssn;
            jac = eval.jacobian(&x, &r)?;
            if rel < cfg.rel_decrease {
                small_steps += 1;
                if small_steps >= cfg.patience {
                    stop = LsStop::Converged;
                    break;
                }
            } else {
                small_steps = 0;
            }
        }
        debug_assert_eq!(jac.len(), p);
        Ok(LsResult {
            x,
            rss,
            residuals: r,
            jacobian: jac,
            iterations,
            stop,
        })
    }
}

/// The damped step for `λ` with the active set: solves (A + λ diag A) δ = g, freezing each
/// variable on a bound that δ pushes out and re-solving until no new variable freezes (at most
/// `p + 1` solves). `None` if the first solve fails; a later failure keeps the previous step.
fn damped_step(
    a: &[f64],
    g: &[f64],
    lambda: f64,
    x: &[f64],
    bounds: &[(f64, f64)],
) -> Option<Vec<f64>> {
    let p = g.len();
    let mut frozen = vec![false; p];
    let mut delta = None;
    for _ in 0..=p {
        let mut aa = a.to_vec();
        let mut gg = g.to_vec();
        for i in 0..p {
            // The tiny floor keeps an all-zero column (a variable the residuals ignore) solvable.
            aa[i * p + i] = a[i * p + i] * (1.0 + lambda) + 1e-300;
            if frozen[i] {
                for k in 0..p {
                    aa[i * p + k] = 0.0;
                    aa[k * p + i] = 0.0;
                }
                aa[i * p + i] = 1.0;
                gg[i] = 0.0;
            }
        }
        let Ok(dl) = solve_spd(&aa, &gg, p) else {
            break;
        };
        let mut changed = false;
        for i in 0..p {
            let (lo, hi) = bounds[i];
            if !frozen[i] && ((x[i] <= lo && dl[i] < 0.0) || (x[i] >= hi && dl[i] > 0.0)) {
                frozen[i] = true;
                changed = true;
            }
        }
        delta = Some(dl);
        if !changed {
            break;
        }
    }
    delta
}
