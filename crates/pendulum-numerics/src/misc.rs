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

/// What [`golden_section`] ends with: the last bracket and its better interior point.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Golden {
    pub lo: f64,
    pub hi: f64,
    /// The better of the two last interior points, and its value.
    pub x: f64,
    pub f: f64,
}

/// Golden-section search for a minimum of `f` on [lo, hi] (unimodal there), `iters` shrinks of
/// the bracket by 0.618 each; one evaluation per shrink.
pub fn golden_section(mut f: impl FnMut(f64) -> f64, lo: f64, hi: f64, iters: usize) -> Golden {
    let (mut lo, mut hi) = (lo, hi);
    let g = 0.5 * (5f64.sqrt() - 1.0);
    let (mut a, mut b) = (hi - g * (hi - lo), lo + g * (hi - lo));
    let (mut fa, mut fb) = (f(a), f(b));
    for _ in 0..iters {
        if fa < fb {
            hi = b;
            b = a;
            fb = fa;
            a = hi - g * (hi - lo);
            fa = f(a);
        } else {
            lo = a;
            a = b;
            fa = fb;
            b = lo + g * (hi - lo);
            fb = f(b);
        }
    }
    let (x, fx) = if fa < fb { (a, fa) } else { (b, fb) };
    Golden { lo, hi, x, f: fx }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The minimum of a smooth function, to what its values can tell apart: a parabola of
    /// height 1 is flat to rounding within √ε ≈ 1.5e-8 of its minimum, so the bracket (0.618⁶⁰
    /// of the start wide) closes there, not on 0.3 itself.
    #[test]
    fn golden_section_finds_a_parabola_minimum() {
        let g = golden_section(|x| (x - 0.3).powi(2) + 1.0, 0.0, 1.0, 60);
        assert!((g.x - 0.3).abs() < 3e-8, "{g:?}");
        assert!(g.hi - g.lo < 1e-10 && g.lo <= g.x && g.x <= g.hi, "{g:?}");
        // Where the values do resolve the minimum (no constant beside the square), it is found
        // to the bracket's width.
        let h = golden_section(|x| (x - 0.3).powi(2), 0.0, 1.0, 60);
        assert!((h.x - 0.3).abs() < 1e-10, "{h:?}");
        assert!((g.f - 1.0).abs() < 1e-15);
        // A minimum at the bracket's end is approached from inside.
        let e = golden_section(|x| x, 2.0, 3.0, 40);
        assert!(e.x - 2.0 < 1e-8 && e.x >= 2.0);
    }
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
