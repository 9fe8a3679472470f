//! One linear least-squares routine (weighted, with ordinary least squares as unit weights) and
//! the symmetric positive-definite solve and inverse it is built on.
//!
//! Why the normal equations rather than QR of the design: every problem here has few unknowns
//! (≤ 16) and many rows, the callers already form JᵀJ in their Gauss–Newton loops, and the
//! answers of the routines this replaces (all normal-equation solvers) must not move beyond
//! rounding. The normal matrix is Jacobi-scaled to unit diagonal before its Cholesky
//! factorisation, so columns that differ by orders of magnitude (sgn θ̇ beside θ³ of a rotating
//! run) do not look singular.

use nalgebra::{Cholesky, DMatrix, DVector};

use crate::NumericsError;

/// A pivot of the unit-diagonal normal matrix below this is taken as singular (about 1e14 for
/// the condition number of the scaled matrix; the replaced solvers used 1e-14 and 1e-13).
const SINGULAR_PIVOT: f64 = 1e-14;

/// The result of a (weighted) linear least-squares fit `y ≈ X β`.
#[derive(Debug, Clone, PartialEq)]
pub struct LsFit {
    /// β, one per column.
    pub coef: Vec<f64>,
    /// Covariance of β, σ²(XᵀWX)⁻¹ with σ² = `rss / max(dof, 1)`, row-major p×p.
    pub cov: Vec<f64>,
    /// (XᵀWX)⁻¹ itself, row-major p×p: the covariance when the weights are inverse variances
    /// (a χ² fit) rather than relative.
    pub cov_unscaled: Vec<f64>,
    /// Weighted residual sum of squares Σ wᵢ (yᵢ − xᵢβ)².
    pub rss: f64,
    /// Rows with a positive weight.
    pub n: usize,
    /// Residual degrees of freedom, `n − p`.
    pub dof: usize,
}

impl LsFit {
    /// Number of unknowns.
    pub fn p(&self) -> usize {
        self.coef.len()
    }

    /// Standard error of coefficient `i` (from [`LsFit::cov`]).
    pub fn se(&self, i: usize) -> f64 {
        self.cov[i * self.p() + i].max(0.0).sqrt()
    }

    /// Root-mean-square residual, √(RSS / n).
    pub fn rms(&self) -> f64 {
        (self.rss / self.n.max(1) as f64).sqrt()
    }
}

/// Ordinary least squares: [`wls`] with unit weights.
pub fn ols<R: AsRef<[f64]>>(rows: &[R], y: &[f64]) -> Result<LsFit, NumericsError> {
    fit(rows, y, None)
}

/// Weighted least squares of `y` on the design `rows` (one slice of p values per row) with
/// weights `w` (≥ 0; a zero weight drops the row). Needs at least p rows of positive weight.
pub fn wls<R: AsRef<[f64]>>(rows: &[R], y: &[f64], w: &[f64]) -> Result<LsFit, NumericsError> {
    fit(rows, y, Some(w))
}

fn fit<R: AsRef<[f64]>>(rows: &[R], y: &[f64], w: Option<&[f64]>) -> Result<LsFit, NumericsError> {
    let p = rows.first().map_or(0, |r| r.as_ref().len());
    let shape = |what, got, expected| NumericsError::Shape {
        what,
        got,
        expected,
    };
    if y.len() != rows.len() {
        return Err(shape("target", y.len(), rows.len()));
    }
    if let Some(w) = w {
        if w.len() != rows.len() {
            return Err(shape("weights", w.len(), rows.len()));
        }
        if let Some((index, &value)) = w
            .iter()
            .enumerate()
            .find(|(_, v)| !(**v >= 0.0 && v.is_finite()))
        {
            return Err(NumericsError::BadWeight { index, value });
        }
    }
    if let Some(r) = rows.iter().find(|r| r.as_ref().len() != p) {
        return Err(shape("design row", r.as_ref().len(), p));
    }
    let weight = |i: usize| w.map_or(1.0, |w| w[i]);
    let n = (0..rows.len()).filter(|&i| weight(i) > 0.0).count();
    if p == 0 || n < p {
        return Err(NumericsError::TooFewRows {
            rows: n,
            unknowns: p,
        });
    }
    let mut xtx = vec![0.0; p * p];
    let mut xty = vec![0.0; p];
    for (i, (row, &yi)) in rows.iter().zip(y).enumerate() {
        let row = row.as_ref();
        let wi = weight(i);
        for a in 0..p {
            xty[a] += wi * row[a] * yi;
            for b in 0..p {
                xtx[a * p + b] += wi * row[a] * row[b];
            }
        }
    }
    let (coef, inv) = spd(&xtx, Some(&xty), p)?;
    let coef = coef.unwrap_or_default();
    let rss: f64 = rows
        .iter()
        .zip(y)
        .enumerate()
        .map(|(i, (row, &yi))| {
            let f: f64 = row.as_ref().iter().zip(&coef).map(|(a, b)| a * b).sum();
            weight(i) * (yi - f) * (yi - f)
        })
        .sum();
    let dof = n - p;
    let s2 = rss / dof.max(1) as f64;
    Ok(LsFit {
        coef,
        cov: inv.iter().map(|v| v * s2).collect(),
        cov_unscaled: inv,
        rss,
        n,
        dof,
    })
}

/// Solves `a x = b` for a symmetric positive-definite `a` (n×n, row-major; the lower triangle
/// is read). `Singular` when `a` is not positive definite to working precision.
pub fn solve_spd(a: &[f64], b: &[f64], n: usize) -> Result<Vec<f64>, NumericsError> {
    if b.len() != n {
        return Err(NumericsError::Shape {
            what: "right-hand side",
            got: b.len(),
            expected: n,
        });
    }
    Ok(spd(a, Some(b), n)?.0.unwrap_or_default())
}

/// Inverse of a symmetric positive-definite `a` (n×n, row-major; the lower triangle is read).
pub fn inverse_spd(a: &[f64], n: usize) -> Result<Vec<f64>, NumericsError> {
    Ok(spd(a, None, n)?.1)
}

/// Cholesky of the Jacobi-scaled `a`: the solution of `a x = b` (when `b` is given) and a⁻¹.
#[allow(clippy::type_complexity)]
fn spd(
    a: &[f64],
    b: Option<&[f64]>,
    n: usize,
) -> Result<(Option<Vec<f64>>, Vec<f64>), NumericsError> {
    if a.len() != n * n {
        return Err(NumericsError::Shape {
            what: "matrix",
            got: a.len(),
            expected: n * n,
        });
    }
    let singular = NumericsError::Singular { n };
    if n == 0 {
        return Err(singular);
    }
    let mut d = Vec::with_capacity(n);
    for i in 0..n {
        let v = a[i * n + i];
        if !(v > 0.0 && v.is_finite()) {
            return Err(singular);
        }
        d.push(1.0 / v.sqrt());
    }
    let scaled = DMatrix::from_fn(n, n, |i, j| a[i * n + j] * d[i] * d[j]);
    let chol = Cholesky::new(scaled).ok_or(singular.clone())?;
    let l = chol.l_dirty();
    if (0..n).any(|i| !(l[(i, i)] * l[(i, i)] >= SINGULAR_PIVOT)) {
        return Err(singular);
    }
    let x = b.map(|b| {
        let x = chol.solve(&DVector::from_fn(n, |i, _| b[i] * d[i]));
        (0..n).map(|i| x[i] * d[i]).collect()
    });
    let inv = chol.inverse();
    let inv = (0..n * n)
        .map(|k| inv[(k / n, k % n)] * d[k / n] * d[k % n])
        .collect();
    Ok((x, inv))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn close(a: f64, b: f64, tol: f64) -> bool {
        (a - b).abs() <= tol * (1.0 + b.abs())
    }

    /// An exactly representable line is recovered exactly, with zero RSS.
    #[test]
    fn exact_problem() {
        let rows: Vec<[f64; 2]> = (0..20).map(|i| [1.0, i as f64]).collect();
        let y: Vec<f64> = (0..20).map(|i| 3.0 + 0.5 * i as f64).collect();
        let f = ols(&rows, &y).unwrap();
        assert!(close(f.coef[0], 3.0, 1e-12) && close(f.coef[1], 0.5, 1e-12));
        assert!(f.rss < 1e-20 && f.n == 20 && f.dof == 18);
    }

    /// Straight line through (x, y) with known residuals: slope, intercept, RSS and the
    /// closed-form covariance σ²/Sxx, σ²(1/n + x̄²/Sxx), −x̄σ²/Sxx.
    #[test]
    fn covariance_closed_form() {
        let x = [0.0, 1.0, 2.0, 3.0, 4.0, 5.0];
        let e = [0.1, -0.2, 0.05, 0.15, -0.3, 0.2];
        let y: Vec<f64> = x.iter().zip(&e).map(|(x, e)| 1.0 + 2.0 * x + e).collect();
        let rows: Vec<Vec<f64>> = x.iter().map(|&x| vec![1.0, x]).collect();
        let f = ols(&rows, &y).unwrap();
        let n = x.len() as f64;
        let xm = x.iter().sum::<f64>() / n;
        let ym = y.iter().sum::<f64>() / n;
        let sxx: f64 = x.iter().map(|x| (x - xm).powi(2)).sum();
        let sxy: f64 = x.iter().zip(&y).map(|(x, y)| (x - xm) * (y - ym)).sum();
        let slope = sxy / sxx;
        let icpt = ym - slope * xm;
        let rss: f64 = x
            .iter()
            .zip(&y)
            .map(|(x, y)| (y - icpt - slope * x).powi(2))
            .sum();
        let s2 = rss / (n - 2.0);
        assert!(close(f.coef[0], icpt, 1e-12) && close(f.coef[1], slope, 1e-12));
        assert!(close(f.rss, rss, 1e-10) && f.dof == 4);
        assert!(close(f.cov[3], s2 / sxx, 1e-10));
        assert!(close(f.cov[0], s2 * (1.0 / n + xm * xm / sxx), 1e-10));
        assert!(close(f.cov[1], -xm * s2 / sxx, 1e-10) && f.cov[1] == f.cov[2]);
        assert!(close(f.se(1), (s2 / sxx).sqrt(), 1e-10));
        assert!(close(f.rms(), (rss / n).sqrt(), 1e-10));
    }

    /// Weights: an integer weight is the same as repeating the row; a zero weight drops it.
    #[test]
    fn weights_repeat_and_drop_rows() {
        let rows = [[1.0, 0.0], [1.0, 1.0], [1.0, 2.0], [1.0, 3.0]];
        let y = [0.1, 0.9, 2.2, 2.8];
        let w = wls(&rows, &y, &[2.0, 1.0, 0.0, 1.0]).unwrap();
        let rep = ols(
            &[rows[0], rows[0], rows[1], rows[3]],
            &[y[0], y[0], y[1], y[3]],
        )
        .unwrap();
        for (a, b) in w.coef.iter().zip(&rep.coef) {
            assert!(close(*a, *b, 1e-12));
        }
        assert!(close(w.rss, rep.rss, 1e-12));
        assert_eq!((w.n, w.dof), (3, 1));
        assert!(matches!(
            wls(&rows, &y, &[1.0, -1.0, 1.0, 1.0]),
            Err(NumericsError::BadWeight { index: 1, .. })
        ));
    }

    /// Columns 10⁷ apart in scale are no obstacle; a repeated column is singular.
    #[test]
    fn scaling_and_singularity() {
        let rows: Vec<[f64; 2]> = (0..10).map(|i| [1e-4, 1e3 * (i as f64).powi(3)]).collect();
        let y: Vec<f64> = rows.iter().map(|r| 2e4 * r[0] - 3e-3 * r[1]).collect();
        let f = ols(&rows, &y).unwrap();
        assert!(close(f.coef[0], 2e4, 1e-10) && close(f.coef[1], -3e-3, 1e-10));
        let dup: Vec<[f64; 2]> = (0..10).map(|i| [i as f64, i as f64]).collect();
        assert_eq!(ols(&dup, &y), Err(NumericsError::Singular { n: 2 }));
        assert!(matches!(
            ols(&rows[..1], &y[..1]),
            Err(NumericsError::TooFewRows { .. })
        ));
    }

    #[test]
    fn spd_solve_and_inverse() {
        let a = [4.0, 1.0, 2.0, 1.0, 3.0, 0.0, 2.0, 0.0, 5.0];
        let x = solve_spd(&a, &[7.0, 4.0, 7.0], 3).unwrap();
        for v in x {
            assert!(close(v, 1.0, 1e-14));
        }
        let inv = inverse_spd(&a, 3).unwrap();
        for i in 0..3 {
            for j in 0..3 {
                let s: f64 = (0..3).map(|k| a[i * 3 + k] * inv[k * 3 + j]).sum();
                assert!((s - f64::from(u8::from(i == j))).abs() < 1e-14);
            }
        }
        assert!(solve_spd(&[1.0, 2.0, 2.0, 4.0], &[1.0, 2.0], 2).is_err());
        assert!(solve_spd(&[1.0, 1.0, 1.0, 1.0], &[1.0, 1.0], 2).is_err());
    }
}
