//! Differential Evolution DE/rand/1/bin: configuration, solver state and one generation.
//!
//! Generations are synchronous: every trial of generation `g` is built from the population at
//! the start of `g`, so the trials can be costed in parallel. All random numbers of a generation
//! (indices, crossover draws, bound repairs) are drawn sequentially from one ChaCha8 stream
//! *before* the parallel evaluation, which makes a run bit-identical for any thread count.

use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;
use rayon::prelude::*;
use serde::{Deserialize, Serialize};

use crate::error::FitError;
use crate::problem::{Cost, Problem};

/// When the population counts as converged.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum StopRule {
    /// `worst − best < tol`: the study's rule.
    #[default]
    Absolute,
    /// `worst − best < tol · max(|best|, f64::MIN_POSITIVE)`: scale-free, for costs far from 0.
    Relative,
}

/// Settings of DE/rand/1/bin. Deserialises from partial tables (missing fields take the
/// defaults); unknown keys are rejected so a typo cannot silently fall back to a default.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct DeConfig {
    /// Population size Np (≥ 4: a target needs three other distinct members). Default 40.
    pub np: usize,
    /// Differential weight F, in (0, 2]. Default 0.8.
    pub f: f64,
    /// Crossover probability CR, in [0, 1]. Default 0.9.
    pub cr: f64,
    /// Seed of the ChaCha8 stream; same seed, same run. Default 0.
    pub seed: u64,
    /// Generation cap (the initial population is generation 0). Default 1000.
    pub max_generations: u64,
    /// Convergence tolerance of `stop_rule`, ≥ 0; 0 never converges. Default 0.001.
    pub tol: f64,
    /// Convergence test. Default [`StopRule::Absolute`].
    pub stop_rule: StopRule,
    /// Pass the target's cost as `bound` so hopeless trials can stop early. Never changes the
    /// result, only the work. Default true.
    pub early_abandon: bool,
    /// Optional seeded members (e.g. a previous fit); the rest of the population is uniform in
    /// the bounds. At most `np` members, each inside the bounds.
    pub init: Option<Vec<Vec<f64>>>,
}

impl Default for DeConfig {
    fn default() -> Self {
        Self {
            np: 40,
            f: 0.8,
            cr: 0.9,
            seed: 0,
            max_generations: 1000,
            tol: 1e-3,
            stop_rule: StopRule::Absolute,
            early_abandon: true,
            init: None,
        }
    }
}

impl DeConfig {
    /// Checks the ranges that do not depend on the problem.
    pub fn validate(&self) -> Result<(), FitError> {
        let bad = |field, value: String, expected| {
            Err(FitError::BadConfig {
                field,
                value,
                expected,
            })
        };
        if self.np < 4 {
            return bad("np", self.np.to_string(), "np ≥ 4");
        }
        // Written so that NaN fails too.
        if !(self.f > 0.0 && self.f <= 2.0) {
            return bad("f", self.f.to_string(), "0 < f ≤ 2");
        }
        if !(0.0..=1.0).contains(&self.cr) {
            return bad("cr", self.cr.to_string(), "0 ≤ cr ≤ 1");
        }
        if self.tol.is_nan() || self.tol < 0.0 {
            return bad("tol", self.tol.to_string(), "tol ≥ 0");
        }
        if let Some(init) = &self.init {
            if init.len() > self.np {
                return bad(
                    "init",
                    format!("{} members", init.len()),
                    "at most np members",
                );
            }
        }
        Ok(())
    }
}

/// The population and everything needed to continue a run.
///
/// Members always carry exact costs: an abandoned trial never enters the population.
#[derive(Debug, Clone)]
pub struct DeState {
    bounds: Vec<(f64, f64)>,
    population: Vec<Vec<f64>>,
    costs: Vec<f64>,
    generation: u64,
    evaluations: u64,
    abandoned: u64,
    rng: ChaCha8Rng,
}

impl DeState {
    /// Members, `np` points of `dim` variables.
    pub fn population(&self) -> &[Vec<f64>] {
        &self.population
    }
    /// Exact costs of the members, same order.
    pub fn costs(&self) -> &[f64] {
        &self.costs
    }
    /// Completed generations (0 right after initialisation).
    pub fn generation(&self) -> u64 {
        self.generation
    }
    /// Cost evaluations so far, abandoned ones included.
    pub fn evaluations(&self) -> u64 {
        self.evaluations
    }
    /// Evaluations that returned [`Cost::AtLeast`].
    pub fn abandoned(&self) -> u64 {
        self.abandoned
    }
    /// Index of the best member (the first one on ties, so it is deterministic).
    pub fn best_index(&self) -> usize {
        let mut best = 0;
        for (i, &c) in self.costs.iter().enumerate() {
            if c < self.costs[best] {
                best = i;
            }
        }
        best
    }
    /// `(best, worst, mean)` of the member costs.
    pub fn cost_summary(&self) -> (f64, f64, f64) {
        let n = self.costs.len() as f64;
        let best = self.costs.iter().copied().fold(f64::INFINITY, f64::min);
        let worst = self.costs.iter().copied().fold(f64::NEG_INFINITY, f64::max);
        // Dividing each term keeps the mean finite even with f64::MAX penalties.
        let mean = self.costs.iter().map(|c| c / n).sum();
        (best, worst, mean)
    }
}

/// The DE/rand/1/bin solver: a validated configuration, stateless between calls.
#[derive(Debug, Clone)]
pub struct DifferentialEvolution {
    config: DeConfig,
}

impl DifferentialEvolution {
    /// Validates `config`.
    pub fn new(config: DeConfig) -> Result<Self, FitError> {
        config.validate()?;
        Ok(Self { config })
    }

    /// The configuration.
    pub fn config(&self) -> &DeConfig {
        &self.config
    }

    /// Checks the problem's box, draws the initial population (seeded members first, the rest
    /// uniform in the bounds) and costs it exactly, in parallel: `np` evaluations.
    pub fn init<P: Problem + ?Sized>(&self, problem: &P) -> Result<DeState, FitError> {
        let bounds = checked_bounds(problem)?;
        let dim = bounds.len();
        let np = self.config.np;
        let mut rng = ChaCha8Rng::seed_from_u64(self.config.seed);
        let mut population = Vec::with_capacity(np);
        for (member, x) in self.config.init.iter().flatten().enumerate() {
            if x.len() != dim {
                return Err(FitError::BadInit {
                    member,
                    reason: format!("has {} variables, the problem has {dim}", x.len()),
                });
            }
            for (j, (&v, &(lo, hi))) in x.iter().zip(&bounds).enumerate() {
                if !(lo..=hi).contains(&v) {
                    return Err(FitError::BadInit {
                        member,
                        reason: format!("variable {j} = {v} is outside [{lo}, {hi}]"),
                    });
                }
            }
            population.push(x.clone());
        }
        while population.len() < np {
            let x = bounds
                .iter()
                .map(|&(lo, hi)| uniform_between(&mut rng, lo, hi))
                .collect();
            population.push(x);
        }
        let evaluated: Vec<Cost> = population
            .par_iter()
            .map(|x| problem.cost(x, f64::INFINITY))
            .collect();
        let mut costs = Vec::with_capacity(np);
        for (x, c) in population.iter().zip(evaluated) {
            match c {
                Cost::Exact(v) if v.is_finite() => costs.push(v),
                Cost::Exact(v) => return Err(non_finite(x, v)),
                Cost::AtLeast(v) => return Err(abandon_below(x, v, f64::INFINITY)),
            }
        }
        Ok(DeState {
            bounds,
            population,
            costs,
            generation: 0,
            evaluations: np as u64,
            abandoned: 0,
            rng,
        })
    }

    /// One generation: `np` trials, costed in parallel on the current rayon pool, then
    /// selection (a trial replaces its target if `f_trial ≤ f_target`).
    ///
    /// On error the population is left unchanged (the random stream has advanced).
    pub fn step<P: Problem + ?Sized>(
        &self,
        problem: &P,
        state: &mut DeState,
    ) -> Result<(), FitError> {
        let trials = self.trials(state);
        let bounds: Vec<f64> = if self.config.early_abandon {
            state.costs.clone()
        } else {
            vec![f64::INFINITY; trials.len()]
        };
        let evaluated: Vec<Cost> = trials
            .par_iter()
            .zip(bounds.par_iter())
            .map(|(x, &bound)| problem.cost(x, bound))
            .collect();
        // Validate everything before touching the population.
        for ((x, c), &bound) in trials.iter().zip(&evaluated).zip(&bounds) {
            match *c {
                Cost::Exact(v) if !v.is_finite() => return Err(non_finite(x, v)),
                Cost::AtLeast(v) if v.is_nan() || v <= bound => {
                    return Err(abandon_below(x, v, bound))
                }
                _ => {}
            }
        }
        for (i, (x, c)) in trials.into_iter().zip(evaluated).enumerate() {
            match c {
                Cost::Exact(v) => {
                    if v <= state.costs[i] {
                        state.population[i] = x;
                        state.costs[i] = v;
                    }
                }
                // Proven worse than the target: the plain algorithm would reject it too.
                Cost::AtLeast(_) => state.abandoned += 1,
            }
        }
        state.evaluations += state.population.len() as u64;
        state.generation += 1;
        Ok(())
    }

    /// Whether `state` meets the configured stop rule (never when `tol` is 0).
    pub fn converged(&self, state: &DeState) -> bool {
        let (best, worst, _) = state.cost_summary();
        let spread = worst - best;
        match self.config.stop_rule {
            StopRule::Absolute => spread < self.config.tol,
            StopRule::Relative => spread < self.config.tol * best.abs().max(f64::MIN_POSITIVE),
        }
    }

    /// Builds the generation's trial vectors, drawing all randomness sequentially.
    ///
    /// Out-of-bounds mutant components are resampled uniformly between the target's component
    /// and the violated bound (a "bounce-back" repair): unlike clamping it does not pile members
    /// on the faces of the box, and unlike a full uniform redraw it keeps the target's progress.
    fn trials(&self, state: &mut DeState) -> Vec<Vec<f64>> {
        let np = state.population.len();
        let dim = state.bounds.len();
        let (f, cr) = (self.config.f, self.config.cr);
        let rng = &mut state.rng;
        let pop = &state.population;
        let mut trials = Vec::with_capacity(np);
        for (i, target) in pop.iter().enumerate() {
            let r1 = pick_distinct(rng, np, &[i]);
            let r2 = pick_distinct(rng, np, &[i, r1]);
            let r3 = pick_distinct(rng, np, &[i, r1, r2]);
            let j_rand = rng.random_range(0..dim);
            let mut trial = target.clone();
            for j in 0..dim {
                // Always draw, so the stream does not depend on j_rand.
                let u: f64 = rng.random();
                if j != j_rand && u >= cr {
                    continue;
                }
                let (lo, hi) = state.bounds[j];
                let v = pop[r1][j] + f * (pop[r2][j] - pop[r3][j]);
                trial[j] = if v < lo {
                    uniform_between(rng, lo, target[j])
                } else if v > hi {
                    uniform_between(rng, target[j], hi)
                } else {
                    v
                };
            }
            trials.push(trial);
        }
        trials
    }
}

/// Uniform in `[a, b)` (or `a` when `a == b`), clamped against rounding.
fn uniform_between(rng: &mut ChaCha8Rng, a: f64, b: f64) -> f64 {
    let u: f64 = rng.random();
    (a + u * (b - a)).clamp(a.min(b), a.max(b))
}

/// A uniform index in `0..n` not in `exclude` (rejection sampling: `exclude` is tiny).
fn pick_distinct(rng: &mut ChaCha8Rng, n: usize, exclude: &[usize]) -> usize {
    loop {
        let r = rng.random_range(0..n);
        if !exclude.contains(&r) {
            return r;
        }
    }
}

/// The problem's bounds, checked: `dim()` entries, finite, `lo < hi`, finite width.
pub(crate) fn checked_bounds<P: Problem + ?Sized>(
    problem: &P,
) -> Result<Vec<(f64, f64)>, FitError> {
    let dim = problem.dim();
    let bounds = problem.bounds();
    if dim == 0 || bounds.len() != dim {
        return Err(FitError::BadDimension {
            dim,
            got: bounds.len(),
        });
    }
    for (index, &(lo, hi)) in bounds.iter().enumerate() {
        if !(lo < hi && (hi - lo).is_finite()) {
            return Err(FitError::BadBounds { index, lo, hi });
        }
    }
    Ok(bounds)
}

fn non_finite(x: &[f64], value: f64) -> FitError {
    FitError::NonFiniteCost {
        x: x.to_vec(),
        value,
    }
}

fn abandon_below(x: &[f64], value: f64, bound: f64) -> FitError {
    FitError::AbandonBelowBound {
        x: x.to_vec(),
        value,
        bound,
    }
}
