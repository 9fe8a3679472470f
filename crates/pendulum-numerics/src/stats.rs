//! Quantiles and tails of the Student-t, F and normal distributions (from `statrs`: exact to
//! ~1e-12 where the replaced code used a table stepping to 2.2 for 11–20 degrees of freedom, a
//! Numerical Recipes erfc good to 1.2e-7 and a Wilson–Hilferty normal approximation of the F
//! tail), and the Bayesian information criterion.
//!
//! Invalid arguments (a probability outside (0, 1), degrees of freedom not > 0, NaN) give NaN:
//! callers test results with `!(x > …)`, which rejects NaN along with the rest.

use statrs::distribution::{ContinuousCDF, FisherSnedecor, Normal, StudentsT};

/// The `p`-quantile of Student's t with `df` degrees of freedom (`t_quantile(0.975, df)` is
/// the two-sided 95 % factor).
pub fn t_quantile(p: f64, df: f64) -> f64 {
    if !(p > 0.0 && p < 1.0 && df > 0.0) {
        return f64::NAN;
    }
    if df > LARGE_DF {
        // statrs 0.19's inverse loses accuracy above ~1e4 degrees of freedom (1e-4 off at
        // 1e6, wrong at 1e7, and it does not return at 1e8): there the Cornish–Fisher expansion
        // about the normal quantile (Abramowitz & Stegun 26.7.5) is exact to ~1/df⁵.
        let z = normal_quantile(p);
        let z2 = z * z;
        let g1 = z * (z2 + 1.0) / 4.0;
        let g2 = z * ((5.0 * z2 + 16.0) * z2 + 3.0) / 96.0;
        let g3 = z * (((3.0 * z2 + 19.0) * z2 + 17.0) * z2 - 15.0) / 384.0;
        let g4 = z * ((((79.0 * z2 + 776.0) * z2 + 1482.0) * z2 - 1920.0) * z2 - 945.0) / 92160.0;
        return z + (g1 + (g2 + (g3 + g4 / df) / df) / df) / df;
    }
    StudentsT::new(0.0, 1.0, df).map_or(f64::NAN, |d| d.inverse_cdf(p))
}

/// Above this many degrees of freedom [`t_quantile`] uses the expansion about the normal.
const LARGE_DF: f64 = 1000.0;

/// Upper tail P(F > f) of the F distribution with (`d1`, `d2`) degrees of freedom: the p-value
/// of a nested-model F test.
pub fn f_sf(f: f64, d1: f64, d2: f64) -> f64 {
    if f.is_nan() {
        return f64::NAN;
    }
    if f <= 0.0 {
        return 1.0;
    }
    FisherSnedecor::new(d1, d2).map_or(f64::NAN, |d| d.sf(f))
}

/// Upper tail P(Z > x) of the standard normal (`2 · normal_sf(|z|)` is a two-sided p-value).
pub fn normal_sf(x: f64) -> f64 {
    if x.is_nan() {
        return f64::NAN;
    }
    standard_normal().sf(x)
}

/// The `p`-quantile of the standard normal.
pub fn normal_quantile(p: f64) -> f64 {
    if !(p > 0.0 && p < 1.0) {
        return f64::NAN;
    }
    standard_normal().inverse_cdf(p)
}

fn standard_normal() -> Normal {
    Normal::standard()
}

/// Bayesian information criterion of a Gaussian least-squares fit: n ln(RSS/n) + k ln n, with
/// RSS/n floored at 1e-300 so that an exact fit scores finitely.
pub fn bic(rss: f64, n: usize, k: usize) -> f64 {
    let n = n as f64;
    n * (rss / n).max(1e-300).ln() + k as f64 * n.ln()
}

/// The Wilcoxon signed-rank statistic of paired differences `d` as a standard normal score:
/// (W⁺ − n(n+1)/4) / σ, W⁺ the sum of the ranks of |d| over the positive differences, zeros
/// left out, tied |d| given their mean rank and σ corrected for the ties (Lehmann,
/// *Nonparametrics*, 1975, §3.2). Positive where the differences lean positive. Its null
/// distribution (differences symmetric about 0) holds whatever their tails, and the normal score
/// approximates it closely beyond a dozen or so units; that is why it is asked where a few heavy
/// units carry most of a sum: there the spread of the differences (the paired t) cannot tell any
/// fall from chance, since the sum's sign hangs on those few. NaN without a non-zero difference.
pub fn signed_rank_z(d: &[f64]) -> f64 {
    let mut a: Vec<(f64, bool)> = d
        .iter()
        .filter(|v| **v != 0.0 && v.is_finite())
        .map(|v| (v.abs(), *v > 0.0))
        .collect();
    let n = a.len();
    if n == 0 {
        return f64::NAN;
    }
    a.sort_by(|x, y| x.0.total_cmp(&y.0));
    let (mut w_plus, mut ties) = (0.0, 0.0);
    let mut i = 0;
    while i < n {
        let mut j = i;
        while j + 1 < n && a[j + 1].0 == a[i].0 {
            j += 1;
        }
        // Ranks i+1 ..= j+1 share their mean.
        let rank = (i + j + 2) as f64 / 2.0;
        let t = (j - i + 1) as f64;
        ties += t * t * t - t;
        w_plus += rank * a[i..=j].iter().filter(|x| x.1).count() as f64;
        i = j + 1;
    }
    let nf = n as f64;
    let mean = nf * (nf + 1.0) / 4.0;
    let var = nf * (nf + 1.0) * (2.0 * nf + 1.0) / 24.0 - ties / 48.0;
    if var <= 0.0 {
        return f64::NAN;
    }
    (w_plus - mean) / var.sqrt()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn close(a: f64, b: f64, tol: f64) -> bool {
        (a - b).abs() <= tol * b.abs().max(1e-300)
    }

    /// Reference values from the regularised incomplete beta function at 30 digits (mpmath).
    #[test]
    fn known_values() {
        assert!(close(t_quantile(0.975, 10.0), 2.228138851986, 1e-11));
        assert!(close(t_quantile(0.975, 1.0), 12.70620473617, 1e-10));
        assert!(close(t_quantile(0.975, 15.0), 2.131449545559, 1e-11));
        assert!(close(t_quantile(0.975, 1e9), 1.959963986912, 1e-11));
        // Either side of the switch to the expansion, and far beyond it.
        assert!(close(t_quantile(0.975, 1000.0), 1.962339080826, 1e-11));
        assert!(close(t_quantile(0.975, 1001.0), 1.962336705281, 1e-11));
        assert!(close(t_quantile(0.975, 1e6), 1.959966356814, 1e-11));
        assert!(close(t_quantile(0.995, 2000.0), 2.578289787558, 1e-11));
        assert!(close(t_quantile(0.025, 10.0), -2.228138851986, 1e-11));
        // Large denominator degrees of freedom (weak-form fits have thousands of rows).
        assert!(close(f_sf(2.6, 3.0, 1e3), 0.05092953115027, 1e-9));
        assert!(close(f_sf(2.6, 3.0, 1e4), 0.05039091230378, 1e-9));
        assert!(close(f_sf(3.0, 2.0, 1e5), 0.04979154922642, 1e-9));
        assert!(close(f_sf(3.84, 1.0, 1e6), 0.05004379860997, 1e-9));
        assert!(close(f_sf(4.0, 5.0, 3e5), 0.001250036582720, 1e-9));
        assert!(close(normal_quantile(0.975), 1.959963984540, 1e-11));
        assert!(close(normal_sf(1.959963984540), 0.025, 1e-10));
        assert!(close(normal_sf(6.0), 9.865876450377e-10, 1e-9));
        // qf(0.95, 3, 20) = 3.098391212; P(F(2, 10) > 4.102821) = 0.05.
        assert!(close(f_sf(3.098391212, 3.0, 20.0), 0.05, 1e-8));
        assert!(close(f_sf(4.102821015, 2.0, 10.0), 0.05, 1e-8));
        assert_eq!(f_sf(0.0, 2.0, 10.0), 1.0);
        assert!(t_quantile(1.0, 10.0).is_nan() && t_quantile(0.5, 0.0).is_nan());
        assert!(normal_sf(f64::NAN).is_nan());
    }

    #[test]
    fn bic_values() {
        let b = bic(2.0, 10, 3);
        assert!(close(b, 10.0 * 0.2f64.ln() + 3.0 * 10f64.ln(), 1e-15));
        assert!(bic(0.0, 10, 1).is_finite());
    }

    /// Worked by hand: five positive differences give W⁺ = 15 against a mean of 7.5 and a
    /// variance of 5·6·11/24 = 13.75; a tie of two shares rank 1.5 and takes (8 − 2)/48 off.
    #[test]
    fn signed_rank_by_hand() {
        assert!(close(
            signed_rank_z(&[1.0, 2.0, 3.0, 4.0, 5.0]),
            7.5 / 13.75f64.sqrt(),
            1e-14
        ));
        assert!(close(
            signed_rank_z(&[-1.0, -2.0, -3.0, -4.0, -5.0]),
            -7.5 / 13.75f64.sqrt(),
            1e-14
        ));
        // |d| = 1, 1, 3 with the ranks 1.5, 1.5, 3; positive: the second 1 and the 3.
        let z = signed_rank_z(&[-1.0, 1.0, 3.0, 0.0]);
        let var = 3.0 * 4.0 * 7.0 / 24.0 - 6.0 / 48.0;
        assert!(close(z, (4.5 - 3.0) / f64::sqrt(var), 1e-14));
        // One huge positive difference among many small negative ones leans negative: ranks,
        // not sizes, and the sum's sign does not decide.
        let mut d = vec![-0.01; 20];
        d.push(1e6);
        assert!(signed_rank_z(&d) < -2.0);
        assert!(signed_rank_z(&[0.0, 0.0]).is_nan());
    }
}
