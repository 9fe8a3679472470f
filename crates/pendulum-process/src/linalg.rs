//! Tiny dense linear algebra for the few-parameter least-squares problems here (≤ 8 unknowns):
//! not worth a dependency.

/// Solves A x = b (A n×n, row-major) by Gaussian elimination with partial pivoting.
/// Returns `None` when A is singular to working precision.
pub fn solve(a: &[f64], b: &[f64], n: usize) -> Option<Vec<f64>> {
    let mut m = a.to_vec();
    let mut x = b.to_vec();
    for col in 0..n {
        let piv =
            (col..n).max_by(|&i, &j| m[i * n + col].abs().total_cmp(&m[j * n + col].abs()))?;
        let scale = (0..n)
            .map(|j| m[col * n + j].abs())
            .fold(0.0, f64::max)
            .max(1e-300);
        if m[piv * n + col].abs() <= 1e-14 * scale {
            return None;
        }
        if piv != col {
            for j in 0..n {
                m.swap(piv * n + j, col * n + j);
            }
            x.swap(piv, col);
        }
        for i in col + 1..n {
            let f = m[i * n + col] / m[col * n + col];
            if f != 0.0 {
                for j in col..n {
                    m[i * n + j] -= f * m[col * n + j];
                }
                x[i] -= f * x[col];
            }
        }
    }
    for i in (0..n).rev() {
        let mut s = x[i];
        for j in i + 1..n {
            s -= m[i * n + j] * x[j];
        }
        x[i] = s / m[i * n + i];
    }
    Some(x)
}

/// Inverse of an n×n matrix (column by column), `None` if singular.
pub fn inverse(a: &[f64], n: usize) -> Option<Vec<f64>> {
    let mut inv = vec![0.0; n * n];
    for c in 0..n {
        let mut e = vec![0.0; n];
        e[c] = 1.0;
        let col = solve(a, &e, n)?;
        for r in 0..n {
            inv[r * n + c] = col[r];
        }
    }
    Some(inv)
}

/// Linear least squares: rows of the design matrix `x` (each of length p) against `y`.
/// Returns (coefficients, covariance scaled by the residual variance, residual rms).
pub fn lstsq(x: &[Vec<f64>], y: &[f64]) -> Option<(Vec<f64>, Vec<f64>, f64)> {
    let p = x.first()?.len();
    let n = x.len();
    let mut ata = vec![0.0; p * p];
    let mut atb = vec![0.0; p];
    for (row, &yi) in x.iter().zip(y) {
        for i in 0..p {
            atb[i] += row[i] * yi;
            for j in 0..p {
                ata[i * p + j] += row[i] * row[j];
            }
        }
    }
    let beta = solve(&ata, &atb, p)?;
    let mut ss = 0.0;
    for (row, &yi) in x.iter().zip(y) {
        let fit: f64 = row.iter().zip(&beta).map(|(a, b)| a * b).sum();
        ss += (yi - fit) * (yi - fit);
    }
    let dof = n.saturating_sub(p).max(1) as f64;
    let s2 = ss / dof;
    let mut cov = inverse(&ata, p)?;
    for v in &mut cov {
        *v *= s2;
    }
    Some((beta, cov, (ss / n.max(1) as f64).sqrt()))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn solves_and_fits() {
        let a = [4.0, 1.0, 2.0, 1.0, 3.0, 0.0, 2.0, 0.0, 5.0];
        let x = solve(&a, &[7.0, 4.0, 7.0], 3).unwrap();
        for (got, want) in x.iter().zip([1.0, 1.0, 1.0]) {
            assert!((got - want).abs() < 1e-12);
        }
        assert!(solve(&[1.0, 2.0, 2.0, 4.0], &[1.0, 2.0], 2).is_none());
        let rows: Vec<Vec<f64>> = (0..20).map(|i| vec![1.0, i as f64]).collect();
        let y: Vec<f64> = (0..20).map(|i| 3.0 + 0.5 * i as f64).collect();
        let (b, _, rms) = lstsq(&rows, &y).unwrap();
        assert!((b[0] - 3.0).abs() < 1e-12 && (b[1] - 0.5).abs() < 1e-12 && rms < 1e-12);
    }
}
