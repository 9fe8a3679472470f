//! Bounded Nelder–Mead: a cheap local polish of a DE optimum. DE stops on a population spread,
//! so its best member is only as good as `tol`; a few hundred simplex steps sharpen it.
//! Callers should report the polished point apart from the DE result, since it is a different
//! algorithm with its own evaluation count.

use crate::problem::Problem;

/// Reflection, expansion, contraction and shrink coefficients (the standard ones).
const ALPHA: f64 = 1.0;
const GAMMA: f64 = 2.0;
const RHO: f64 = 0.5;
const SIGMA: f64 = 0.5;

/// Minimises `problem` from `x0` with Nelder–Mead, every point clamped into the bounds.
///
/// The initial simplex is `x0` plus `x0 ± step[j]·e_j` (the minus side when the plus side is
/// clamped back onto `x0`). Stops when the simplex's cost spread `f_worst − f_best ≤ ftol`
/// (absolute, like the DE stop rule) or after `max_evals` evaluations (at least one: `x0`).
/// Costs are always exact (`bound = ∞`); a NaN cost counts as `+∞`. Clamping can flatten the
/// simplex onto a face of the box, so an optimum on a bound is reached but not left again.
///
/// Returns `(x, f, evals)`: the best point, its cost, the evaluations used.
///
/// # Panics
/// If `x0`, `step` or `problem.bounds()` do not have `problem.dim()` entries.
pub fn nelder_mead<P: Problem + ?Sized>(
    problem: &P,
    x0: &[f64],
    step: &[f64],
    max_evals: usize,
    ftol: f64,
) -> (Vec<f64>, f64, usize) {
    let n = problem.dim();
    let bounds = problem.bounds();
    assert_eq!(x0.len(), n, "x0 has the wrong dimension");
    assert_eq!(step.len(), n, "step has the wrong dimension");
    assert_eq!(bounds.len(), n, "bounds have the wrong dimension");
    let max_evals = max_evals.max(1);
    let clamp = |mut x: Vec<f64>| {
        for (v, &(lo, hi)) in x.iter_mut().zip(&bounds) {
            *v = v.max(lo).min(hi);
        }
        x
    };
    let mut evals = 0usize;
    // `None` once the budget is spent.
    let eval = |evals: &mut usize, x: &[f64]| -> Option<f64> {
        if *evals >= max_evals {
            return None;
        }
        *evals += 1;
        let v = problem.cost(x, f64::INFINITY).value();
        Some(if v.is_nan() { f64::INFINITY } else { v })
    };

    let start = clamp(x0.to_vec());
    let f0 = eval(&mut evals, &start).expect("max_evals ≥ 1");
    let mut simplex = vec![(start.clone(), f0)];
    for j in 0..n {
        let mut v = start.clone();
        v[j] += step[j];
        let mut v = clamp(v);
        if v[j] == start[j] {
            v[j] -= step[j];
            v = clamp(v);
        }
        match eval(&mut evals, &v) {
            Some(f) => simplex.push((v, f)),
            None => return best_of(simplex, evals),
        }
    }

    let combine = |a: &[f64], b: &[f64], t: f64| -> Vec<f64> {
        // a + t (a − b)
        clamp(a.iter().zip(b).map(|(&a, &b)| a + t * (a - b)).collect())
    };
    loop {
        simplex.sort_by(|a, b| a.1.total_cmp(&b.1));
        let (f_best, f_worst) = (simplex[0].1, simplex[n].1);
        if f_worst - f_best <= ftol || evals >= max_evals {
            break;
        }
        let mut centroid = vec![0.0; n];
        for (x, _) in &simplex[..n] {
            for (c, &v) in centroid.iter_mut().zip(x) {
                *c += v / n as f64;
            }
        }
        let worst = simplex[n].0.clone();
        let second = simplex[n - 1].1;

        let xr = combine(&centroid, &worst, ALPHA);
        let Some(fr) = eval(&mut evals, &xr) else {
            break;
        };
        if fr < f_best {
            let xe = combine(&centroid, &xr, -GAMMA);
            let Some(fe) = eval(&mut evals, &xe) else {
                simplex[n] = (xr, fr);
                break;
            };
            simplex[n] = if fe < fr { (xe, fe) } else { (xr, fr) };
            continue;
        }
        if fr < second {
            simplex[n] = (xr, fr);
            continue;
        }
        // Contraction: outside if the reflection beat the worst point, inside otherwise.
        let outside = fr < f_worst;
        let xc = if outside {
            combine(&centroid, &xr, -RHO)
        } else {
            combine(&centroid, &worst, -RHO)
        };
        let Some(fc) = eval(&mut evals, &xc) else {
            break;
        };
        if (outside && fc <= fr) || (!outside && fc < f_worst) {
            simplex[n] = (xc, fc);
            continue;
        }
        // Shrink towards the best vertex (stays in the box: the box is convex).
        let best = simplex[0].0.clone();
        for vertex in simplex.iter_mut().skip(1) {
            let x = combine(&best, &vertex.0, -SIGMA);
            let Some(f) = eval(&mut evals, &x) else {
                return best_of(simplex, evals);
            };
            *vertex = (x, f);
        }
    }
    best_of(simplex, evals)
}

fn best_of(simplex: Vec<(Vec<f64>, f64)>, evals: usize) -> (Vec<f64>, f64, usize) {
    let (x, f) = simplex
        .into_iter()
        .min_by(|a, b| a.1.total_cmp(&b.1))
        .expect("simplex has a vertex");
    (x, f, evals)
}
