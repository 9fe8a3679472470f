//! Levenberg–Marquardt and Gauss–Newton against independent answers: the linear least-squares
//! solution of `pendulum-numerics`, known parameters of exact data, Rosenbrock's minimum, the
//! optimum of a problem restricted to a face of its box.

use std::sync::atomic::{AtomicUsize, Ordering};

use pendulum_fit::{
    finite_difference_jacobian, nelder_mead, FitError, GaussNewton, GnConfig, LeastSquaresProblem,
    LevenbergMarquardt, LmConfig, LsStop, Problem, SumOfSquares,
};

/// r = X b − y, with an analytic Jacobian (X's columns) unless `numeric`.
struct Linear {
    rows: Vec<[f64; 3]>,
    y: Vec<f64>,
    bounds: Vec<(f64, f64)>,
    numeric: bool,
}

impl Linear {
    fn new(bounds: Vec<(f64, f64)>, numeric: bool) -> Self {
        // A fixed, well-conditioned design with an inexact fit (non-zero residuals).
        let rows: Vec<[f64; 3]> = (0..12)
            .map(|i| {
                let t = i as f64 / 11.0;
                [1.0, t, (3.0 * t).sin()]
            })
            .collect();
        let y = (0..12)
            .map(|i| {
                let t = i as f64 / 11.0;
                0.5 - 2.0 * t + 0.3 * (3.0 * t).sin() + 0.05 * ((7 * i) % 5) as f64
            })
            .collect();
        Self {
            rows,
            y,
            bounds,
            numeric,
        }
    }
}

impl LeastSquaresProblem for Linear {
    fn dim(&self) -> usize {
        3
    }
    fn bounds(&self) -> Vec<(f64, f64)> {
        self.bounds.clone()
    }
    fn residuals(&self, x: &[f64]) -> Option<Vec<f64>> {
        Some(
            self.rows
                .iter()
                .zip(&self.y)
                .map(|(row, y)| row.iter().zip(x).map(|(a, b)| a * b).sum::<f64>() - y)
                .collect(),
        )
    }
    fn jacobian(&self, x: &[f64], r: &[f64]) -> Option<Vec<Vec<f64>>> {
        if self.numeric {
            return finite_difference_jacobian(self, x, r);
        }
        Some(
            (0..3)
                .map(|j| self.rows.iter().map(|row| row[j]).collect())
                .collect(),
        )
    }
}

fn unbounded(n: usize) -> Vec<(f64, f64)> {
    vec![(f64::NEG_INFINITY, f64::INFINITY); n]
}

#[test]
fn gauss_newton_solves_a_linear_problem_in_one_step_to_the_ols_answer() {
    let problem = Linear::new(unbounded(3), false);
    let ols = pendulum_numerics::ols(&problem.rows, &problem.y).unwrap();
    let one = GaussNewton::new(GnConfig::default().with_max_iterations(1)).unwrap();
    let out = one.solve(&problem, &[10.0, -5.0, 3.0]).unwrap();
    assert_eq!(out.iterations, 1);
    for (a, b) in out.x.iter().zip(&ols.coef) {
        assert!((a - b).abs() < 1e-12 * (1.0 + b.abs()), "{a} vs {b}");
    }
    assert!((out.rss - ols.rss).abs() < 1e-12 * ols.rss);
    // The second step is zero, so the default solver stops there, converged.
    let full = GaussNewton::new(GnConfig::default()).unwrap();
    let out = full.solve(&problem, &[10.0, -5.0, 3.0]).unwrap();
    assert_eq!(out.stop, LsStop::Converged);
    assert!(out.iterations <= 2, "{} iterations", out.iterations);
    // JᵀJ at the solution is XᵀX, whose inverse is the OLS unscaled covariance.
    let inv = pendulum_numerics::inverse_spd(&out.jtj(), 3).unwrap();
    for (a, b) in inv.iter().zip(&ols.cov_unscaled) {
        assert!((a - b).abs() < 1e-9 * (1.0 + b.abs()));
    }
}

#[test]
fn default_jacobian_matches_the_analytic_one_on_a_linear_problem() {
    let exact = Linear::new(unbounded(3), false);
    let numeric = Linear::new(unbounded(3), true);
    let x = [0.3, -1.0, 2.0];
    let r = exact.residuals(&x).unwrap();
    let a = exact.jacobian(&x, &r).unwrap();
    let b = numeric.jacobian(&x, &r).unwrap();
    for (ca, cb) in a.iter().zip(&b) {
        for (u, v) in ca.iter().zip(cb) {
            assert!((u - v).abs() < 1e-8, "{u} vs {v}");
        }
    }
}

/// rᵢ = a·exp(−k tᵢ) + c − yᵢ; Jacobian by the default finite differences.
struct ExpDecay {
    t: Vec<f64>,
    y: Vec<f64>,
}

impl ExpDecay {
    fn exact(a: f64, k: f64, c: f64) -> Self {
        let t: Vec<f64> = (0..40).map(|i| 0.1 * i as f64).collect();
        let y = t.iter().map(|t| a * (-k * t).exp() + c).collect();
        Self { t, y }
    }
}

impl LeastSquaresProblem for ExpDecay {
    fn dim(&self) -> usize {
        3
    }
    fn bounds(&self) -> Vec<(f64, f64)> {
        vec![
            (0.0, 100.0),
            (0.0, 50.0),
            (f64::NEG_INFINITY, f64::INFINITY),
        ]
    }
    fn residuals(&self, x: &[f64]) -> Option<Vec<f64>> {
        Some(
            self.t
                .iter()
                .zip(&self.y)
                .map(|(t, y)| x[0] * (-x[1] * t).exp() + x[2] - y)
                .collect(),
        )
    }
}

#[test]
fn levenberg_marquardt_recovers_exponential_decay_parameters_from_exact_data() {
    let problem = ExpDecay::exact(2.0, 0.7, 0.3);
    let lm = LevenbergMarquardt::new(LmConfig::default()).unwrap();
    let out = lm.solve(&problem, &[1.0, 0.2, 0.0]).unwrap();
    for (v, want) in out.x.iter().zip([2.0, 0.7, 0.3]) {
        assert!((v - want).abs() < 1e-7, "{:?}", out.x);
    }
    assert!(out.rss < 1e-18, "rss {}", out.rss);
    assert_ne!(out.stop, LsStop::MaxIterations);
    // Gauss–Newton from a close start reaches the same answer.
    let gn = GaussNewton::new(GnConfig::default()).unwrap();
    let out = gn.solve(&problem, &[1.9, 0.65, 0.35]).unwrap();
    assert_eq!(out.stop, LsStop::Converged);
    for (v, want) in out.x.iter().zip([2.0, 0.7, 0.3]) {
        assert!((v - want).abs() < 1e-7, "{:?}", out.x);
    }
}

/// Rosenbrock as residuals: r = (10 (x₂ − x₁²), 1 − x₁); minimum 0 at (1, 1).
struct Rosenbrock;

impl LeastSquaresProblem for Rosenbrock {
    fn dim(&self) -> usize {
        2
    }
    fn bounds(&self) -> Vec<(f64, f64)> {
        unbounded(2)
    }
    fn residuals(&self, x: &[f64]) -> Option<Vec<f64>> {
        Some(vec![10.0 * (x[1] - x[0] * x[0]), 1.0 - x[0]])
    }
}

#[test]
fn levenberg_marquardt_takes_rosenbrock_from_the_classic_start_to_one_one() {
    let lm = LevenbergMarquardt::new(LmConfig::default()).unwrap();
    let out = lm.solve(&Rosenbrock, &[-1.2, 1.0]).unwrap();
    assert!(
        (out.x[0] - 1.0).abs() < 1e-6 && (out.x[1] - 1.0).abs() < 1e-6,
        "{:?}",
        out.x
    );
    assert!(out.rss < 1e-12);
    assert!(out.iterations < 100);
}

#[test]
fn an_active_bound_is_returned_exactly_with_the_optimum_of_the_restricted_problem() {
    // Unconstrained, the linear problem wants a negative coefficient of t; bound it at 0.
    let free = Linear::new(unbounded(3), false);
    let ols = pendulum_numerics::ols(&free.rows, &free.y).unwrap();
    assert!(
        ols.coef[1] < -1.0,
        "the test needs an active bound: {:?}",
        ols.coef
    );
    let mut bounds = unbounded(3);
    bounds[1] = (0.0, f64::INFINITY);
    let problem = Linear::new(bounds, false);
    // Independent answer: the least squares on the other two columns, coefficient of t = 0.
    let reduced: Vec<[f64; 2]> = free.rows.iter().map(|r| [r[0], r[2]]).collect();
    let want = pendulum_numerics::ols(&reduced, &free.y).unwrap();

    let lm = LevenbergMarquardt::new(LmConfig::default()).unwrap();
    let out = lm.solve(&problem, &[0.0, 1.0, 0.0]).unwrap();
    assert_eq!(out.x[1], 0.0, "{:?}", out.x);
    assert!(
        (out.x[0] - want.coef[0]).abs() < 1e-7,
        "{:?} vs {:?}",
        out.x,
        want.coef
    );
    assert!(
        (out.x[2] - want.coef[1]).abs() < 1e-7,
        "{:?} vs {:?}",
        out.x,
        want.coef
    );
    assert!((out.rss - want.rss).abs() < 1e-9 * (1.0 + want.rss));
}

/// r = √x − 1: fails for x < 0, where an undamped step from x = 9 lands (x = −3).
struct SqrtFails {
    failures: AtomicUsize,
}

impl LeastSquaresProblem for SqrtFails {
    fn dim(&self) -> usize {
        1
    }
    fn bounds(&self) -> Vec<(f64, f64)> {
        unbounded(1)
    }
    fn residuals(&self, x: &[f64]) -> Option<Vec<f64>> {
        if x[0] < 0.0 {
            self.failures.fetch_add(1, Ordering::Relaxed);
            return None;
        }
        Some(vec![x[0].sqrt() - 1.0])
    }
    fn jacobian(&self, x: &[f64], _r: &[f64]) -> Option<Vec<Vec<f64>>> {
        Some(vec![vec![0.5 / x[0].sqrt()]])
    }
}

#[test]
fn levenberg_marquardt_backs_off_from_points_where_the_residuals_fail() {
    let problem = SqrtFails {
        failures: AtomicUsize::new(0),
    };
    let lm = LevenbergMarquardt::new(LmConfig::default()).unwrap();
    let out = lm.solve(&problem, &[9.0]).unwrap();
    assert!(
        problem.failures.load(Ordering::Relaxed) > 0,
        "no step failed"
    );
    assert!((out.x[0] - 1.0).abs() < 1e-6, "{:?}", out.x);
    // Gauss–Newton has nothing to back off to: the failure is an error naming the point.
    let gn = GaussNewton::new(GnConfig::default()).unwrap();
    match gn.solve(&problem, &[9.0]) {
        Err(FitError::ResidualsFailed { x }) => assert!(x[0] < 0.0),
        other => panic!("{other:?}"),
    }
    // And a start where the residuals fail is an error for both.
    assert!(matches!(
        lm.solve(&problem, &[-1.0]),
        Err(FitError::ResidualsFailed { .. })
    ));
}

#[test]
fn gauss_newton_reports_a_singular_normal_matrix() {
    // The second variable does not enter the residuals.
    struct Flat;
    impl LeastSquaresProblem for Flat {
        fn dim(&self) -> usize {
            2
        }
        fn bounds(&self) -> Vec<(f64, f64)> {
            unbounded(2)
        }
        fn residuals(&self, x: &[f64]) -> Option<Vec<f64>> {
            Some(vec![x[0] - 1.0, x[0] + 1.0])
        }
    }
    let gn = GaussNewton::new(GnConfig::default()).unwrap();
    assert!(matches!(
        gn.solve(&Flat, &[0.0, 0.0]),
        Err(FitError::Singular { iteration: 1, .. })
    ));
    // Levenberg–Marquardt's damping floor makes the same problem solvable.
    let lm = LevenbergMarquardt::new(LmConfig::default()).unwrap();
    let out = lm.solve(&Flat, &[0.5, 0.0]).unwrap();
    assert!(out.x[0].abs() < 1e-9, "{:?}", out.x);
}

#[test]
fn settings_and_starts_out_of_range_are_rejected() {
    let bad = LmConfig {
        lambda_up: 1.0,
        ..LmConfig::default()
    };
    assert!(matches!(
        LevenbergMarquardt::new(bad),
        Err(FitError::BadConfig {
            field: "lambda_up",
            ..
        })
    ));
    assert!(matches!(
        GaussNewton::new(GnConfig::default().with_min_iterations(0)),
        Err(FitError::BadConfig { .. })
    ));
    let gn = GaussNewton::new(GnConfig::default().with_step_tolerance(vec![0.0], vec![])).unwrap();
    assert!(matches!(
        gn.solve(&Rosenbrock, &[0.0, 0.0]),
        Err(FitError::BadConfig {
            field: "abs_tol",
            ..
        })
    ));
    let lm = LevenbergMarquardt::new(LmConfig::default()).unwrap();
    assert!(matches!(
        lm.solve(&Rosenbrock, &[0.0]),
        Err(FitError::BadStart { .. })
    ));
}

#[test]
fn a_least_squares_problem_is_a_problem_costing_its_sum_of_squares() {
    let p = SumOfSquares(Rosenbrock);
    assert_eq!(p.dim(), 2);
    assert_eq!(p.cost(&[0.0, 0.0], f64::INFINITY).value(), 1.0);
    assert!(p.cost(&[0.0, 0.0], 0.0).is_exact());
    let failing = SumOfSquares(SqrtFails {
        failures: AtomicUsize::new(0),
    });
    assert_eq!(failing.cost(&[-1.0], f64::INFINITY).value(), f64::MAX);
    // Nelder–Mead on the adapter finds the same minimum as LM on the problem.
    let bounded = SumOfSquares(ExpDecay::exact(2.0, 0.7, 0.3));
    let (x, f, _) = nelder_mead(&bounded, &[1.0, 0.2, 0.0], &[0.5, 0.1, 0.1], 4000, 1e-20);
    assert!(f < 1e-10, "{f}");
    assert!((x[1] - 0.7).abs() < 1e-3, "{x:?}");
}
