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
}
