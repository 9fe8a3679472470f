//! Small helpers that were written more than once: median, angle wrapping, trapezoid rule.

/// Median of `v`, sorting it in place (NaN sorts last, by `total_cmp`); NaN when empty.
pub fn median(v: &mut [f64]) -> f64 {
    if v.is_empty() {
        return f64::NAN;
    }
    v.sort_by(f64::total_cmp);
    let n = v.len();
    if n % 2 == 1 {
        v[n / 2]
    } else {
        0.5 * (v[n / 2 - 1] + v[n / 2])
    }
}

/// An angle wrapped to [−π, π).
pub fn wrap_pi(x: f64) -> f64 {
    let two_pi = 2.0 * std::f64::consts::PI;
    (x + std::f64::consts::PI).rem_euclid(two_pi) - std::f64::consts::PI
}

/// ∫ y dt by the trapezoid rule over samples `y` spaced `dt` apart (0 for fewer than two).
pub fn trapezoid(y: &[f64], dt: f64) -> f64 {
    y.windows(2).map(|w| 0.5 * dt * (w[0] + w[1])).sum()
}

/// Weight of sample `i` of `0..=n` in the trapezoid rule with spacing `dt` (half at both ends),
/// for sums accumulated while the samples stream past.
pub fn trapezoid_weight(i: usize, n: usize, dt: f64) -> f64 {
    if i == 0 || i == n {
        0.5 * dt
    } else {
        dt
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f64::consts::PI;

    #[test]
    fn median_odd_even_empty() {
        assert_eq!(median(&mut [3.0, 1.0, 2.0]), 2.0);
        assert_eq!(median(&mut [4.0, 1.0, 3.0, 2.0]), 2.5);
        assert!(median(&mut []).is_nan());
    }

    #[test]
    fn wrap_range() {
        assert_eq!(wrap_pi(0.0), 0.0);
        assert!((wrap_pi(3.0 * PI / 2.0) + PI / 2.0).abs() < 1e-15);
        assert!((wrap_pi(-7.0 * PI) + PI).abs() < 1e-14);
        assert!((-PI..PI).contains(&wrap_pi(PI)));
    }

    /// Exact for a straight line; the streamed weights give the same sum.
    #[test]
    fn trapezoid_line() {
        let dt = 0.25;
        let y: Vec<f64> = (0..=8).map(|i| 1.0 + 2.0 * i as f64 * dt).collect();
        assert!((trapezoid(&y, dt) - 6.0).abs() < 1e-14);
        let s: f64 = y
            .iter()
            .enumerate()
            .map(|(i, v)| trapezoid_weight(i, 8, dt) * v)
            .sum();
        assert!((s - 6.0).abs() < 1e-14);
        assert_eq!(trapezoid(&[1.0], dt), 0.0);
    }
}
