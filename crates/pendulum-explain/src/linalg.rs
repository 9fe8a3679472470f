//! Dense linear algebra for the few-unknown least-squares problems here (≤ 8 unknowns).

/// Inverse of the symmetric positive (semi)definite `a` (n×n, row-major), computed on the
/// Jacobi-scaled matrix (unit diagonal) by Gauss–Jordan elimination with partial pivoting.
/// `None` when singular to working precision.
pub fn inverse_spd(a: &[f64], n: usize) -> Option<Vec<f64>> {
    let d: Vec<f64> = (0..n)
        .map(|i| {
            let v = a[i * n + i];
            if v > 0.0 && v.is_finite() {
                1.0 / v.sqrt()
            } else {
                0.0
            }
        })
        .collect();
    if d.contains(&0.0) {
        return None;
    }
    let mut m: Vec<f64> = (0..n * n).map(|k| a[k] * d[k / n] * d[k % n]).collect();
    let mut inv = vec![0.0; n * n];
    for i in 0..n {
        inv[i * n + i] = 1.0;
    }
    for col in 0..n {
        let piv =
            (col..n).max_by(|&i, &j| m[i * n + col].abs().total_cmp(&m[j * n + col].abs()))?;
        if m[piv * n + col].abs() < 1e-13 {
            return None;
        }
        if piv != col {
            for j in 0..n {
                m.swap(piv * n + j, col * n + j);
                inv.swap(piv * n + j, col * n + j);
            }
        }
        let p = m[col * n + col];
        for j in 0..n {
            m[col * n + j] /= p;
            inv[col * n + j] /= p;
        }
        for i in 0..n {
            if i != col {
                let f = m[i * n + col];
                if f != 0.0 {
                    for j in 0..n {
                        m[i * n + j] -= f * m[col * n + j];
                        inv[i * n + j] -= f * inv[col * n + j];
                    }
                }
            }
        }
    }
    Some((0..n * n).map(|k| inv[k] * d[k / n] * d[k % n]).collect())
}

/// Solves the symmetric system `a x = b` through [`inverse_spd`].
pub fn solve_spd(a: &[f64], b: &[f64], n: usize) -> Option<Vec<f64>> {
    let inv = inverse_spd(a, n)?;
    Some(
        (0..n)
            .map(|i| (0..n).map(|j| inv[i * n + j] * b[j]).sum())
            .collect(),
    )
}

/// Ordinary least squares `y ≈ X β` (`rows` of X). Returns (β, covariance σ²(XᵀX)⁻¹, RSS);
/// `None` when there are not more rows than unknowns or XᵀX is singular.
pub fn ols(rows: &[Vec<f64>], y: &[f64]) -> Option<(Vec<f64>, Vec<f64>, f64)> {
    let k = rows.first()?.len();
    let n = rows.len();
    if n <= k || k == 0 {
        return None;
    }
    let mut xtx = vec![0.0; k * k];
    let mut xty = vec![0.0; k];
    for (r, &yi) in rows.iter().zip(y) {
        for i in 0..k {
            xty[i] += r[i] * yi;
            for j in 0..k {
                xtx[i * k + j] += r[i] * r[j];
            }
        }
    }
    let inv = inverse_spd(&xtx, k)?;
    let beta: Vec<f64> = (0..k)
        .map(|i| (0..k).map(|j| inv[i * k + j] * xty[j]).sum())
        .collect();
    let rss: f64 = rows
        .iter()
        .zip(y)
        .map(|(r, &yi)| {
            let f: f64 = r.iter().zip(&beta).map(|(a, b)| a * b).sum();
            (yi - f) * (yi - f)
        })
        .sum();
    let s2 = rss / (n - k) as f64;
    let cov = inv.iter().map(|v| v * s2).collect();
    Some((beta, cov, rss))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn inverse_and_ols() {
        let a = [4.0, 1.0, 1.0, 3.0];
        let inv = inverse_spd(&a, 2).unwrap();
        let id = [
            a[0] * inv[0] + a[1] * inv[2],
            a[0] * inv[1] + a[1] * inv[3],
            a[2] * inv[0] + a[3] * inv[2],
            a[2] * inv[1] + a[3] * inv[3],
        ];
        for (x, y) in id.iter().zip([1.0, 0.0, 0.0, 1.0]) {
            assert!((x - y).abs() < 1e-12);
        }
        let rows: Vec<Vec<f64>> = (0..10).map(|i| vec![1.0, i as f64]).collect();
        let y: Vec<f64> = (0..10).map(|i| 2.0 + 0.5 * i as f64).collect();
        let (b, _, rss) = ols(&rows, &y).unwrap();
        assert!((b[0] - 2.0).abs() < 1e-12 && (b[1] - 0.5).abs() < 1e-12 && rss < 1e-20);
        assert!(solve_spd(&[1.0, 1.0, 1.0, 1.0], &[1.0, 1.0], 2).is_none());
    }
}
