//! Behaviour of the DE driver and the Nelder–Mead polish on small analytic problems.

use std::sync::Mutex;

use pendulum_fit::{
    nelder_mead, ConvergenceHistory, Cost, DeConfig, DeResult, Driver, FitError, FnObserver,
    GenerationStats, Problem, StopReason, StopRule,
};

struct Sphere {
    dim: usize,
}

impl Problem for Sphere {
    fn dim(&self) -> usize {
        self.dim
    }
    fn bounds(&self) -> Vec<(f64, f64)> {
        vec![(-5.0, 5.0); self.dim]
    }
    fn cost(&self, x: &[f64], _bound: f64) -> Cost {
        Cost::Exact(x.iter().map(|v| v * v).sum())
    }
}

struct Rosenbrock {
    dim: usize,
}

impl Problem for Rosenbrock {
    fn dim(&self) -> usize {
        self.dim
    }
    fn bounds(&self) -> Vec<(f64, f64)> {
        vec![(-2.0, 2.0); self.dim]
    }
    fn cost(&self, x: &[f64], _bound: f64) -> Cost {
        Cost::Exact(
            x.windows(2)
                .map(|w| 100.0 * (w[1] - w[0] * w[0]).powi(2) + (1.0 - w[0]).powi(2))
                .sum(),
        )
    }
}

/// A least-squares fit: a sum of many non-negative residual terms, abandoned as soon as the
/// partial sum exceeds the bound (what the pendulum fits do with their time series).
struct Residuals {
    data: Vec<(f64, f64)>,
}

impl Residuals {
    fn new() -> Self {
        let truth = [0.3, -1.2, 0.7, 2.0];
        let data = (0..200)
            .map(|k| {
                let t = k as f64 * 0.05;
                let noise = 0.01 * ((k * 7919 % 101) as f64 / 101.0 - 0.5);
                (t, Self::model(&truth, t) + noise)
            })
            .collect();
        Self { data }
    }
    fn model(x: &[f64], t: f64) -> f64 {
        x[0] + x[1] * (-x[2] * t).exp() * (x[3] * t).cos()
    }
}

impl Problem for Residuals {
    fn dim(&self) -> usize {
        4
    }
    fn bounds(&self) -> Vec<(f64, f64)> {
        vec![(-2.0, 2.0), (-3.0, 3.0), (0.0, 2.0), (0.5, 4.0)]
    }
    fn cost(&self, x: &[f64], bound: f64) -> Cost {
        let mut sum = 0.0;
        for &(t, y) in &self.data {
            sum += (Self::model(x, t) - y).powi(2);
            if sum > bound {
                return Cost::AtLeast(sum);
            }
        }
        Cost::Exact(sum)
    }
}

/// Records every evaluated point; optimum outside the box so mutants often leave it.
struct Recording {
    seen: Mutex<Vec<Vec<f64>>>,
}

impl Problem for Recording {
    fn dim(&self) -> usize {
        3
    }
    fn bounds(&self) -> Vec<(f64, f64)> {
        vec![(-1.0, 1.0), (0.0, 0.5), (10.0, 20.0)]
    }
    fn cost(&self, x: &[f64], _bound: f64) -> Cost {
        self.seen.lock().unwrap().push(x.to_vec());
        Cost::Exact((x[0] + 3.0).powi(2) + (x[1] - 2.0).powi(2) + (x[2] - 15.0).powi(2))
    }
}

fn config(np: usize, seed: u64, generations: u64, tol: f64) -> DeConfig {
    DeConfig {
        np,
        seed,
        max_generations: generations,
        tol,
        ..DeConfig::default()
    }
}

fn assert_close(x: &[f64], target: f64, eps: f64) {
    for &v in x {
        assert!(
            (v - target).abs() < eps,
            "{x:?} not within {eps} of {target}"
        );
    }
}

fn bits(x: &[f64]) -> Vec<u64> {
    x.iter().map(|v| v.to_bits()).collect()
}

fn pop_bits(r: &DeResult) -> Vec<Vec<u64>> {
    r.population.iter().map(|x| bits(x)).collect()
}

/// History without the abandon counter (the only thing early abandon may change).
fn trajectory(r: &DeResult) -> Vec<(u64, u64, u64, u64, Vec<u64>, u64)> {
    r.history
        .iter()
        .map(|g| {
            (
                g.generation,
                g.best.to_bits(),
                g.worst.to_bits(),
                g.mean.to_bits(),
                bits(&g.best_x),
                g.evaluations,
            )
        })
        .collect()
}

#[test]
fn sphere_converges() {
    for dim in [2, 5] {
        let r = Driver::new(Sphere { dim }, config(10 * dim, 1, 2000, 1e-14))
            .run()
            .unwrap();
        assert_eq!(r.stop_reason, StopReason::Converged, "dim {dim}");
        assert_close(&r.best_x, 0.0, 1e-6);
        assert!(r.best_cost < 1e-12);
    }
}

#[test]
fn rosenbrock_converges() {
    for dim in [2, 5] {
        let r = Driver::new(Rosenbrock { dim }, config(15 * dim, 3, 5000, 1e-12))
            .run()
            .unwrap();
        assert_eq!(r.stop_reason, StopReason::Converged, "dim {dim}");
        assert_close(&r.best_x, 1.0, 1e-4);
    }
}

#[test]
fn relative_rule_converges() {
    let cfg = DeConfig {
        stop_rule: StopRule::Relative,
        ..config(20, 5, 2000, 1e-9)
    };
    // Shift the sphere so the optimum cost is 1: the relative rule sees a 1e-9 spread.
    struct Shifted;
    impl Problem for Shifted {
        fn dim(&self) -> usize {
            2
        }
        fn bounds(&self) -> Vec<(f64, f64)> {
            vec![(-5.0, 5.0); 2]
        }
        fn cost(&self, x: &[f64], _: f64) -> Cost {
            Cost::Exact(1.0 + x[0] * x[0] + x[1] * x[1])
        }
    }
    let r = Driver::new(Shifted, cfg).run().unwrap();
    assert_eq!(r.stop_reason, StopReason::Converged);
    let last = r.history.last().unwrap();
    assert!(last.worst - last.best < 1e-9 * last.best.abs());
    assert_close(&r.best_x, 0.0, 1e-3);
}

#[test]
fn same_seed_same_result_for_any_thread_count() {
    let p = Rosenbrock { dim: 3 };
    let run = |threads, seed| {
        Driver::new(&p, config(20, seed, 150, 0.0))
            .threads(threads)
            .run()
            .unwrap()
    };
    let a = run(Some(1), 7);
    let b = run(Some(2), 7);
    let c = run(None, 7);
    for other in [&b, &c] {
        assert_eq!(pop_bits(&a), pop_bits(other));
        assert_eq!(trajectory(&a), trajectory(other));
        assert_eq!(bits(&a.best_x), bits(&other.best_x));
    }
    let d = run(Some(2), 8);
    assert_ne!(pop_bits(&a), pop_bits(&d), "the seed must matter");
}

#[test]
fn early_abandon_matches_plain_algorithm() {
    let p = Residuals::new();
    let run = |early_abandon| {
        let cfg = DeConfig {
            early_abandon,
            ..config(30, 11, 300, 1e-10)
        };
        Driver::new(&p, cfg).threads(Some(2)).run().unwrap()
    };
    let plain = run(false);
    let fast = run(true);
    assert_eq!(plain.abandoned, 0);
    assert!(
        fast.abandoned > fast.evaluations / 4,
        "abandoned {} of {}",
        fast.abandoned,
        fast.evaluations
    );
    assert_eq!(plain.generations, fast.generations);
    assert_eq!(plain.evaluations, fast.evaluations);
    assert_eq!(plain.stop_reason, fast.stop_reason);
    assert_eq!(bits(&plain.best_x), bits(&fast.best_x));
    assert_eq!(pop_bits(&plain), pop_bits(&fast));
    assert_eq!(bits(&plain.costs), bits(&fast.costs));
    assert_eq!(trajectory(&plain), trajectory(&fast));
    // And the fit found the generating parameters.
    assert!((fast.best_x[2] - 0.7).abs() < 0.05 && (fast.best_x[3] - 2.0).abs() < 0.05);
}

#[test]
fn tol_zero_runs_exactly_g_generations() {
    for g in [0, 1, 37] {
        let np = 8;
        let mut history = ConvergenceHistory::default();
        let mut calls = 0u64;
        let r = Driver::new(Sphere { dim: 2 }, config(np, 2, g, 0.0))
            .observer(Box::new(&mut history))
            .observer(Box::new(FnObserver::new(|s: &GenerationStats| {
                assert_eq!(s.generation, calls);
                calls += 1;
            })))
            .run()
            .unwrap();
        assert_eq!(r.stop_reason, StopReason::GenerationCap);
        assert_eq!(r.generations, g);
        assert_eq!(r.evaluations, np as u64 * (g + 1));
        assert_eq!(r.history.len() as u64, g + 1);
        assert_eq!(calls, g + 1);
        assert_eq!(history.points.len() as u64, g + 1);
        assert!(history.points.windows(2).all(|w| w[1].best <= w[0].best));
        assert_eq!(history.points.last().unwrap().best, r.best_cost);
    }
}

#[test]
fn every_evaluated_point_is_inside_the_bounds() {
    let p = Recording {
        seen: Mutex::new(Vec::new()),
    };
    let r = Driver::new(&p, config(12, 4, 200, 0.0)).run().unwrap();
    let seen = p.seen.into_inner().unwrap();
    assert_eq!(seen.len() as u64, r.evaluations);
    let bounds = p_bounds();
    for x in &seen {
        for (v, (lo, hi)) in x.iter().zip(&bounds) {
            assert!(lo <= v && v <= hi, "{x:?} outside {bounds:?}");
        }
    }
    // The optimum sits on the corner (-1, 0.5, 15).
    assert!((r.best_x[0] + 1.0).abs() < 1e-6 && (r.best_x[1] - 0.5).abs() < 1e-6);

    fn p_bounds() -> Vec<(f64, f64)> {
        vec![(-1.0, 1.0), (0.0, 0.5), (10.0, 20.0)]
    }
}

#[test]
fn seeded_members_enter_the_population() {
    let cfg = DeConfig {
        init: Some(vec![vec![0.0, 0.0], vec![1.0, -1.0]]),
        ..config(6, 0, 0, 0.0)
    };
    let r = Driver::new(Sphere { dim: 2 }, cfg).run().unwrap();
    assert_eq!(r.population[0], vec![0.0, 0.0]);
    assert_eq!(r.population[1], vec![1.0, -1.0]);
    assert_eq!(r.best_cost, 0.0);

    let bad = DeConfig {
        init: Some(vec![vec![0.0, 9.0]]),
        ..config(6, 0, 0, 0.0)
    };
    let err = Driver::new(Sphere { dim: 2 }, bad).run().unwrap_err();
    assert!(matches!(err, FitError::BadInit { member: 0, .. }), "{err}");
}

#[test]
fn config_validation_names_the_field() {
    let field_of = |cfg: DeConfig| match cfg.validate() {
        Err(FitError::BadConfig { field, .. }) => field,
        other => panic!("expected BadConfig, got {other:?}"),
    };
    let d = DeConfig::default();
    assert!(d.validate().is_ok());
    assert_eq!(field_of(DeConfig { np: 3, ..d.clone() }), "np");
    assert_eq!(
        field_of(DeConfig {
            f: 0.0,
            ..d.clone()
        }),
        "f"
    );
    assert_eq!(
        field_of(DeConfig {
            f: 2.5,
            ..d.clone()
        }),
        "f"
    );
    assert_eq!(
        field_of(DeConfig {
            f: f64::NAN,
            ..d.clone()
        }),
        "f"
    );
    assert_eq!(
        field_of(DeConfig {
            cr: -0.1,
            ..d.clone()
        }),
        "cr"
    );
    assert_eq!(
        field_of(DeConfig {
            cr: 1.5,
            ..d.clone()
        }),
        "cr"
    );
    assert_eq!(
        field_of(DeConfig {
            tol: -1.0,
            ..d.clone()
        }),
        "tol"
    );
    let too_many = DeConfig {
        np: 4,
        init: Some(vec![vec![0.0]; 5]),
        ..d.clone()
    };
    assert_eq!(field_of(too_many), "init");
    let msg = DeConfig { np: 3, ..d.clone() }
        .validate()
        .unwrap_err()
        .to_string();
    assert!(msg.contains("np") && msg.contains("np ≥ 4"), "{msg}");

    // The driver validates too, and rejects a zero-thread pool.
    let err = Driver::new(
        Sphere { dim: 2 },
        DeConfig {
            cr: 2.0,
            ..d.clone()
        },
    )
    .run()
    .unwrap_err();
    assert!(matches!(err, FitError::BadConfig { field: "cr", .. }));
    let err = Driver::new(Sphere { dim: 2 }, d)
        .threads(Some(0))
        .run()
        .unwrap_err();
    assert!(matches!(
        err,
        FitError::BadConfig {
            field: "threads",
            ..
        }
    ));
}

#[test]
fn config_deserialises_with_defaults_and_rejects_unknown_keys() {
    let cfg: DeConfig =
        serde_json::from_str(r#"{"np": 12, "stop_rule": "relative", "seed": 5}"#).unwrap();
    assert_eq!(cfg.np, 12);
    assert_eq!(cfg.seed, 5);
    assert_eq!(cfg.stop_rule, StopRule::Relative);
    assert_eq!(cfg.f, 0.8);
    assert_eq!(cfg.cr, 0.9);
    assert_eq!(cfg.tol, 1e-3);
    assert!(cfg.early_abandon);
    let err = serde_json::from_str::<DeConfig>(r#"{"npop": 12}"#).unwrap_err();
    assert!(err.to_string().contains("npop"), "{err}");
}

#[test]
fn bad_problems_are_reported() {
    struct Bad(Vec<(f64, f64)>, f64);
    impl Problem for Bad {
        fn dim(&self) -> usize {
            2
        }
        fn bounds(&self) -> Vec<(f64, f64)> {
            self.0.clone()
        }
        fn cost(&self, x: &[f64], bound: f64) -> Cost {
            if self.1.is_nan() {
                Cost::Exact(f64::NAN)
            } else if x[0] > 0.0 {
                Cost::AtLeast(bound) // not > bound: contract violation
            } else {
                Cost::Exact(self.1)
            }
        }
    }
    let cfg = config(5, 0, 10, 0.0);
    let run = |p: Bad| Driver::new(p, cfg.clone()).run().unwrap_err();
    assert!(matches!(
        run(Bad(vec![(0.0, 1.0), (2.0, 2.0)], 1.0)),
        FitError::BadBounds { index: 1, .. }
    ));
    assert!(matches!(
        run(Bad(vec![(f64::NEG_INFINITY, 1.0), (0.0, 1.0)], 1.0)),
        FitError::BadBounds { index: 0, .. }
    ));
    assert!(matches!(
        run(Bad(vec![(0.0, 1.0)], 1.0)),
        FitError::BadDimension { dim: 2, got: 1 }
    ));
    assert!(matches!(
        run(Bad(vec![(-1.0, 1.0); 2], f64::NAN)),
        FitError::NonFiniteCost { .. }
    ));
    assert!(matches!(
        run(Bad(vec![(-1.0, 1.0); 2], 1.0)),
        FitError::AbandonBelowBound { .. }
    ));
}

#[test]
fn nelder_mead_polishes_and_respects_bounds() {
    let (x, f, evals) = nelder_mead(
        &Rosenbrock { dim: 2 },
        &[0.8, 0.6],
        &[0.1, 0.1],
        2000,
        1e-20,
    );
    assert_close(&x, 1.0, 1e-5);
    assert!(f < 1e-10 && evals <= 2000, "f {f} evals {evals}");

    // Optimum outside the box: the polish ends on the bound, never outside.
    let p = Recording {
        seen: Mutex::new(Vec::new()),
    };
    let (x, _, evals) = nelder_mead(&p, &[0.0, 0.25, 12.0], &[0.5, 0.1, 1.0], 500, 1e-14);
    let seen = p.seen.into_inner().unwrap();
    assert_eq!(seen.len(), evals);
    assert!(evals <= 500);
    for x in &seen {
        assert!((-1.0..=1.0).contains(&x[0]) && (0.0..=0.5).contains(&x[1]));
        assert!((10.0..=20.0).contains(&x[2]));
    }
    assert!((x[0] + 1.0).abs() < 1e-6 && (x[1] - 0.5).abs() < 1e-6);
    assert!((x[2] - 15.0).abs() < 1e-4);

    // The budget is a hard cap.
    let (_, _, evals) = nelder_mead(&Sphere { dim: 5 }, &[1.0; 5], &[0.5; 5], 3, 0.0);
    assert_eq!(evals, 3);
}
