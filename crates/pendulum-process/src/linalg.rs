//! The former home of this crate's least squares, now thin forwards to `pendulum_numerics`
//! kept only because pendulum-discover (screen.rs, sparse.rs, weak.rs) still calls them by this
//! path. New code calls `pendulum_numerics` directly; delete this module once discover does.

/// Solves the symmetric positive-definite system `a x = b` (n×n, row-major):
/// [`pendulum_numerics::solve_spd`]. `None` when singular.
pub fn solve(a: &[f64], b: &[f64], n: usize) -> Option<Vec<f64>> {
    pendulum_numerics::solve_spd(a, b, n).ok()
}

/// Inverse of a symmetric positive-definite n×n matrix: [`pendulum_numerics::inverse_spd`].
pub fn inverse(a: &[f64], n: usize) -> Option<Vec<f64>> {
    pendulum_numerics::inverse_spd(a, n).ok()
}

/// Linear least squares ([`pendulum_numerics::ols`]) in the old return convention:
/// (coefficients, covariance σ²(XᵀX)⁻¹ with σ² = RSS / max(n − p, 1), RMS residual).
pub fn lstsq(x: &[Vec<f64>], y: &[f64]) -> Option<(Vec<f64>, Vec<f64>, f64)> {
    let f = pendulum_numerics::ols(x, y).ok()?;
    let rms = f.rms();
    Some((f.coef, f.cov, rms))
}
