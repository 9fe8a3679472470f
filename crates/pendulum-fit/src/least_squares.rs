//! What a least-squares solver needs from a problem: its box, its residual vector and (by
//! default numerically) the residuals' Jacobian. [`SumOfSquares`] turns any such problem into a
//! [`Problem`] (cost = Σ rᵢ²), so the same model can be handed to DE or Nelder–Mead as well as to
//! [`LevenbergMarquardt`](crate::LevenbergMarquardt) or [`GaussNewton`](crate::GaussNewton).

use serde::Serialize;

use crate::error::FitError;
use crate::problem::{Cost, Problem};

/// A bounded nonlinear least-squares problem: minimise Σ rᵢ(x)² over the box.
///
/// The Jacobian is stored by columns: `jac[j][i] = ∂rᵢ/∂xⱼ`, `dim()` columns of `r.len()`
/// entries each.
pub trait LeastSquaresProblem {
    /// Number of variables.
    fn dim(&self) -> usize;

    /// Per-variable box `(lo, hi)` with `lo ≤ hi`; either side may be infinite (an unbounded
    /// variable). `dim()` entries.
    fn bounds(&self) -> Vec<(f64, f64)>;

    /// The residual vector at `x` (always inside the bounds), the same length at every `x`;
    /// `None` where the model cannot be evaluated (a failed simulation, a log of a negative
    /// number). The solvers back off from such a point, or fail if it is the start.
    fn residuals(&self, x: &[f64]) -> Option<Vec<f64>>;

    /// The Jacobian at `x`, whose residuals `r` the caller has already computed. `None` when
    /// it cannot be evaluated. Default: [`finite_difference_jacobian`] with steps
    /// [`fd_step`](Self::fd_step).
    fn jacobian(&self, x: &[f64], r: &[f64]) -> Option<Vec<Vec<f64>>> {
        finite_difference_jacobian(self, x, r)
    }

    /// Finite-difference step of variable `j` at `x` for the default Jacobian. Default
    /// `ε^(1/3)·max(|xⱼ|, 1)` (≈ 6e-6 relative), the usual choice for central differences.
    fn fd_step(&self, x: &[f64], j: usize) -> f64 {
        f64::EPSILON.cbrt() * x[j].abs().max(1.0)
    }
}

/// Lets callers lend a problem to a solver and keep using it afterwards.
impl<P: LeastSquaresProblem + ?Sized> LeastSquaresProblem for &P {
    fn dim(&self) -> usize {
        (**self).dim()
    }
    fn bounds(&self) -> Vec<(f64, f64)> {
        (**self).bounds()
    }
    fn residuals(&self, x: &[f64]) -> Option<Vec<f64>> {
        (**self).residuals(x)
    }
    fn jacobian(&self, x: &[f64], r: &[f64]) -> Option<Vec<Vec<f64>>> {
        (**self).jacobian(x, r)
    }
    fn fd_step(&self, x: &[f64], j: usize) -> f64 {
        (**self).fd_step(x, j)
    }
}

/// Finite-difference Jacobian of `problem` at `x` (residuals `r` there): central differences
/// `(r(x + h eⱼ) − r(x − h eⱼ)) / 2h` with `h = problem.fd_step(x, j)`, one-sided (forward, or
/// backward at the upper bound, reusing `r`) where the central stencil would leave the box.
/// `None` if any evaluation fails or returns the wrong length.
pub fn finite_difference_jacobian<P: LeastSquaresProblem + ?Sized>(
    problem: &P,
    x: &[f64],
    r: &[f64],
) -> Option<Vec<Vec<f64>>> {
    let bounds = problem.bounds();
    let eval = |j: usize, h: f64| -> Option<Vec<f64>> {
        let mut xs = x.to_vec();
        xs[j] += h;
        problem.residuals(&xs).filter(|v| v.len() == r.len())
    };
    let mut cols = Vec::with_capacity(x.len());
    for (j, &(lo, hi)) in bounds.iter().enumerate().take(x.len()) {
        let h = problem.fd_step(x, j);
        let col: Vec<f64> = if x[j] + h <= hi {
            let rp = eval(j, h)?;
            if x[j] - h >= lo {
                let rm = eval(j, -h)?;
                rp.iter()
                    .zip(&rm)
                    .map(|(a, b)| (a - b) / (2.0 * h))
                    .collect()
            } else {
                rp.iter().zip(r).map(|(a, b)| (a - b) / h).collect()
            }
        } else {
            let rm = eval(j, -h)?;
            r.iter().zip(&rm).map(|(a, b)| (a - b) / h).collect()
        };
        cols.push(col);
    }
    Some(cols)
}

/// Σ rᵢ², summed in order.
pub(crate) fn sum_of_squares(r: &[f64]) -> f64 {
    r.iter().map(|v| v * v).sum()
}

/// JᵀJ of a column-stored Jacobian, `p×p` row-major.
pub(crate) fn jtj(jac: &[Vec<f64>]) -> Vec<f64> {
    let p = jac.len();
    let mut a = vec![0.0; p * p];
    for i in 0..p {
        for k in i..p {
            let v: f64 = jac[i].iter().zip(&jac[k]).map(|(u, w)| u * w).sum();
            a[i * p + k] = v;
            a[k * p + i] = v;
        }
    }
    a
}

/// −Jᵀr, the right-hand side of the normal equations (`jac` by columns), for both solvers.
pub(crate) fn neg_jt_r(jac: &[Vec<f64>], r: &[f64]) -> Vec<f64> {
    jac.iter()
        .map(|c| -c.iter().zip(r).map(|(u, w)| u * w).sum::<f64>())
        .collect()
}

/// Why a least-squares solver stopped.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
pub enum LsStop {
    /// The solver's convergence test held (see its config).
    Converged,
    /// Levenberg–Marquardt: no trial step lowered the sum of squares, however damped; the point
    /// is a local minimum to working precision (or the residuals fail all around it).
    NoImprovement,
    /// The iteration cap was reached.
    MaxIterations,
}

/// Outcome of a least-squares solve.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct LsResult {
    /// The solution (inside the bounds).
    pub x: Vec<f64>,
    /// Σ rᵢ² at `x`.
    pub rss: f64,
    /// The residuals at `x`.
    pub residuals: Vec<f64>,
    /// The Jacobian at `x`, by columns (`jacobian[j][i] = ∂rᵢ/∂xⱼ`).
    pub jacobian: Vec<Vec<f64>>,
    /// Iterations run (a last one that found no acceptable step included).
    pub iterations: usize,
    pub stop: LsStop,
}

impl LsResult {
    /// JᵀJ at the solution, `p×p` row-major; its inverse times σ² is the usual covariance.
    pub fn jtj(&self) -> Vec<f64> {
        jtj(&self.jacobian)
    }
}

/// A least-squares problem seen as a [`Problem`] with cost Σ rᵢ², for DE or Nelder–Mead.
///
/// The cost is always [`Cost::Exact`] (the residual vector is computed whole, so stopping the
/// sum early would save nothing). Residuals that fail, or a non-finite sum, cost `f64::MAX`, the
/// large finite penalty the [`Problem`] contract asks for. DE needs finite bounds: an infinite
/// side is passed through and rejected by the driver as [`FitError::BadBounds`](crate::FitError).
#[derive(Debug, Clone, Copy)]
pub struct SumOfSquares<P>(pub P);

impl<P: LeastSquaresProblem + Sync> Problem for SumOfSquares<P> {
    fn dim(&self) -> usize {
        self.0.dim()
    }
    fn bounds(&self) -> Vec<(f64, f64)> {
        self.0.bounds()
    }
    fn cost(&self, x: &[f64], _bound: f64) -> Cost {
        let v = self.0.residuals(x).map_or(f64::MAX, |r| sum_of_squares(&r));
        Cost::Exact(if v.is_finite() { v } else { f64::MAX })
    }
}

/// A problem's box and a start point projected into it.
pub(crate) type BoxAndStart = (Vec<(f64, f64)>, Vec<f64>);

/// Checks `problem` and `x0` and returns the box and `x0` projected into it.
pub(crate) fn prepare<P: LeastSquaresProblem + ?Sized>(
    problem: &P,
    x0: &[f64],
) -> Result<BoxAndStart, FitError> {
    let dim = problem.dim();
    let bounds = problem.bounds();
    if dim == 0 || bounds.len() != dim {
        return Err(FitError::BadDimension {
            dim,
            got: bounds.len(),
        });
    }
    for (index, &(lo, hi)) in bounds.iter().enumerate() {
        // Written so that NaN fails too.
        if !(lo <= hi) {
            return Err(FitError::BadBox { index, lo, hi });
        }
    }
    if x0.len() != dim {
        return Err(FitError::BadStart {
            x: x0.to_vec(),
            reason: "expected dim() entries",
        });
    }
    if x0.iter().any(|v| !v.is_finite()) {
        return Err(FitError::BadStart {
            x: x0.to_vec(),
            reason: "expected finite entries",
        });
    }
    let mut x = x0.to_vec();
    project(&mut x, &bounds);
    Ok((bounds, x))
}

/// Clamps `x` into the box.
pub(crate) fn project(x: &mut [f64], bounds: &[(f64, f64)]) {
    for (v, &(lo, hi)) in x.iter_mut().zip(bounds) {
        if *v < lo {
            *v = lo;
        }
        if *v > hi {
            *v = hi;
        }
    }
}

/// Residuals and Jacobian of `problem`, checked for shape: `m` is the number of residuals
/// (`None` until the first evaluation).
pub(crate) struct Evaluator<'p, P: ?Sized> {
    problem: &'p P,
    m: Option<usize>,
}

impl<'p, P: LeastSquaresProblem + ?Sized> Evaluator<'p, P> {
    pub(crate) fn new(problem: &'p P) -> Self {
        Self { problem, m: None }
    }

    /// `None` when the residuals fail or change length.
    pub(crate) fn residuals(&mut self, x: &[f64]) -> Option<Vec<f64>> {
        let r = self.problem.residuals(x)?;
        match self.m {
            Some(m) if m != r.len() => None,
            _ => {
                self.m = Some(r.len());
                Some(r)
            }
        }
    }

    /// The Jacobian, checked for shape; `Err` names the point.
    pub(crate) fn jacobian(&self, x: &[f64], r: &[f64]) -> Result<Vec<Vec<f64>>, FitError> {
        match self.problem.jacobian(x, r) {
            Some(j) if j.len() == x.len() && j.iter().all(|c| c.len() == r.len()) => Ok(j),
            _ => Err(FitError::JacobianFailed { x: x.to_vec() }),
        }
    }
}
