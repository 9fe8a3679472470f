//! Gauss–Newton: full undamped steps δ = −(JᵀJ)⁻¹Jᵀr, projected onto the box, stopped when
//! every variable's step is below its tolerance. No line search and no damping: meant for
//! well-started fits (a coarse search, the previous block's answer) where it converges in a few
//! steps; use [`LevenbergMarquardt`](crate::LevenbergMarquardt) when the start may be far.

use pendulum_numerics::solve_spd;
use serde::{Deserialize, Serialize};

use crate::error::FitError;
use crate::least_squares::{
    jtj, neg_jt_r, prepare, project, sum_of_squares, Evaluator, LeastSquaresProblem, LsResult,
    LsStop,
};

/// Settings of [`GaussNewton`]. Deserialises from partial tables (missing fields take the
/// defaults); unknown keys are rejected.
///
/// Convergence: after a step δ to the new point x, every variable has
/// `|δⱼ| < abs_tol[j] + rel_tol[j]·|xⱼ|`. An empty tolerance vector means 0 for every variable
/// (absolute) or 1e-10 (relative); an infinite entry leaves that variable out of the test.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct GnConfig {
    /// Iteration (step) cap. Default 50.
    pub max_iterations: usize,
    /// Steps taken before convergence is tested, ≥ 1. Default 1.
    pub min_iterations: usize,
    /// Absolute step tolerance per variable (empty: 0 for all), each ≥ 0.
    pub abs_tol: Vec<f64>,
    /// Relative step tolerance per variable (empty: 1e-10 for all), each ≥ 0.
    pub rel_tol: Vec<f64>,
}

impl Default for GnConfig {
    fn default() -> Self {
        Self {
            max_iterations: 50,
            min_iterations: 1,
            abs_tol: Vec::new(),
            rel_tol: Vec::new(),
        }
    }
}

impl GnConfig {
    /// Sets [`max_iterations`](Self::max_iterations).
    pub fn with_max_iterations(mut self, n: usize) -> Self {
        self.max_iterations = n;
        self
    }

    /// Sets [`min_iterations`](Self::min_iterations).
    pub fn with_min_iterations(mut self, n: usize) -> Self {
        self.min_iterations = n;
        self
    }

    /// Sets both step tolerances, one entry per variable.
    pub fn with_step_tolerance(mut self, abs_tol: Vec<f64>, rel_tol: Vec<f64>) -> Self {
        self.abs_tol = abs_tol;
        self.rel_tol = rel_tol;
        self
    }

    /// Checks the ranges that do not depend on the problem.
    pub fn validate(&self) -> Result<(), FitError> {
        let bad = |field, value: String, expected| {
            Err(FitError::BadConfig {
                field,
                value,
                expected,
            })
        };
        if self.min_iterations == 0 {
            return bad("min_iterations", "0".into(), "min_iterations ≥ 1");
        }
        // Written so that NaN fails too.
        if let Some(v) = self.abs_tol.iter().find(|v| !(**v >= 0.0)) {
            return bad("abs_tol", v.to_string(), "every entry ≥ 0");
        }
        if let Some(v) = self.rel_tol.iter().find(|v| !(**v >= 0.0)) {
            return bad("rel_tol", v.to_string(), "every entry ≥ 0");
        }
        Ok(())
    }

    fn check_dim(&self, dim: usize) -> Result<(), FitError> {
        for (field, v) in [("abs_tol", &self.abs_tol), ("rel_tol", &self.rel_tol)] {
            if !v.is_empty() && v.len() != dim {
                return Err(FitError::BadConfig {
                    field,
                    value: format!("{} entries", v.len()),
                    expected: "none or one per variable",
                });
            }
        }
        Ok(())
    }

    fn small(&self, delta: &[f64], x: &[f64]) -> bool {
        delta.iter().zip(x).enumerate().all(|(j, (d, v))| {
            let abs = self.abs_tol.get(j).copied().unwrap_or(0.0);
            let rel = self.rel_tol.get(j).copied().unwrap_or(1e-10);
            d.abs() < abs + rel * v.abs()
        })
    }
}

/// Projected Gauss–Newton (see the module docs).
#[derive(Debug, Clone, PartialEq)]
pub struct GaussNewton {
    config: GnConfig,
}

impl GaussNewton {
    /// A solver with checked settings.
    pub fn new(config: GnConfig) -> Result<Self, FitError> {
        config.validate()?;
        Ok(Self { config })
    }

    pub fn config(&self) -> &GnConfig {
        &self.config
    }

    /// Minimises Σ r² from `x0` (projected into the box first). The result's residuals and
    /// Jacobian are those at its `x`, after the last step.
    ///
    /// Errors: a malformed problem, start or tolerance vector; residuals or a Jacobian that
    /// fail at any iterate (Gauss–Newton has no step to back off to); a singular JᵀJ.
    pub fn solve<P: LeastSquaresProblem + ?Sized>(
        &self,
        problem: &P,
        x0: &[f64],
    ) -> Result<LsResult, FitError> {
        let cfg = &self.config;
        let (bounds, mut x) = prepare(problem, x0)?;
        cfg.check_dim(x.len())?;
        let p = x.len();
        let mut eval = Evaluator::new(problem);
        let mut r = eval
            .residuals(&x)
            .ok_or_else(|| FitError::ResidualsFailed { x: x.clone() })?;
        let mut jac = eval.jacobian(&x, &r)?;
        let mut iterations = 0;
        let mut stop = LsStop::MaxIterations;
        while iterations < cfg.max_iterations {
            iterations += 1;
            let a = jtj(&jac);
            let g = neg_jt_r(&jac, &r);
            let delta = solve_spd(&a, &g, p).map_err(|_| FitError::Singular {
                x: x.clone(),
                iteration: iterations,
            })?;
            for (v, d) in x.iter_mut().zip(&delta) {
                *v += d;
            }
            project(&mut x, &bounds);
            r = eval
                .residuals(&x)
                .ok_or_else(|| FitError::ResidualsFailed { x: x.clone() })?;
            jac = eval.jacobian(&x, &r)?;
            if iterations >= cfg.min_iterations && cfg.small(&delta, &x) {
                stop = LsStop::Converged;
                break;
            }
        }
        Ok(LsResult {
            rss: sum_of_squares(&r),
            x,
            residuals: r,
            jacobian: jac,
            iterations,
            stop,
        })
    }
}
