//! The run loop around [`DifferentialEvolution`]: stopping, thread pool, observers, timing.
//!
//! Stopping is checked after initialisation and after every generation: first convergence
//! (the configured [`StopRule`](crate::StopRule)), then the generation cap. A run of `G`
//! generations therefore costs `np · (G + 1)` evaluations, the `+ 1` being the initial
//! population; with `tol = 0` it never converges and runs exactly `max_generations`.

use std::time::Instant;

use serde::Serialize;

use crate::de::{DeConfig, DeState, DifferentialEvolution};
use crate::error::FitError;
use crate::problem::Problem;

/// Snapshot of the population after a generation (generation 0 = the initial population).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct GenerationStats {
    pub generation: u64,
    pub best: f64,
    pub worst: f64,
    pub mean: f64,
    /// The best member (first one on ties).
    pub best_x: Vec<f64>,
    /// Cumulative cost evaluations, abandoned ones included.
    pub evaluations: u64,
    /// Cumulative evaluations that stopped early.
    pub abandoned: u64,
}

impl GenerationStats {
    /// Statistics of the current population.
    pub fn of(state: &DeState) -> Self {
        let (best, worst, mean) = state.cost_summary();
        Self {
            generation: state.generation(),
            best,
            worst,
            mean,
            best_x: state.population()[state.best_index()].clone(),
            evaluations: state.evaluations(),
            abandoned: state.abandoned(),
        }
    }
}

/// Called on the driver's thread after initialisation and after every generation.
/// `Send` so a driver (and its observers) can be moved to a worker thread.
pub trait Observer: Send {
    fn on_generation(&mut self, g: &GenerationStats);
}

/// Lets a caller lend an observer (`Box::new(&mut history)`) and read it after the run.
impl<O: Observer + ?Sized> Observer for &mut O {
    fn on_generation(&mut self, g: &GenerationStats) {
        (**self).on_generation(g);
    }
}

/// One point of a convergence curve.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct HistoryPoint {
    pub generation: u64,
    pub best: f64,
    pub worst: f64,
    pub mean: f64,
}

/// Observer collecting the convergence curve (generation, best, worst, mean).
#[derive(Debug, Clone, Default)]
pub struct ConvergenceHistory {
    pub points: Vec<HistoryPoint>,
}

impl Observer for ConvergenceHistory {
    fn on_generation(&mut self, g: &GenerationStats) {
        self.points.push(HistoryPoint {
            generation: g.generation,
            best: g.best,
            worst: g.worst,
            mean: g.mean,
        });
    }
}

/// Observer forwarding every generation to a closure (e.g. a progress bar's update).
pub struct FnObserver<F>(pub F);

impl<F: FnMut(&GenerationStats) + Send> FnObserver<F> {
    pub fn new(f: F) -> Self {
        Self(f)
    }
}

impl<F: FnMut(&GenerationStats) + Send> Observer for FnObserver<F> {
    fn on_generation(&mut self, g: &GenerationStats) {
        (self.0)(g);
    }
}

/// Why a run ended.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
pub enum StopReason {
    /// The stop rule held (checked before the cap, so it wins a tie).
    Converged,
    /// `max_generations` generations were run.
    GenerationCap,
}

/// Outcome of a DE run.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct DeResult {
    pub best_x: Vec<f64>,
    pub best_cost: f64,
    /// Generations run after the initial population.
    pub generations: u64,
    /// `np · (generations + 1)`, abandoned evaluations included.
    pub evaluations: u64,
    /// Evaluations that stopped early.
    pub abandoned: u64,
    pub stop_reason: StopReason,
    /// One entry per generation, the initial population first (`generations + 1` entries).
    pub history: Vec<GenerationStats>,
    /// Final population and its exact costs, e.g. to seed a follow-up run via `init`.
    pub population: Vec<Vec<f64>>,
    pub costs: Vec<f64>,
    /// Wall-clock seconds of the run, thread-pool construction included.
    pub wall_s: f64,
}

/// Runs DE on a problem. `'a` bounds borrowed observers.
pub struct Driver<'a, P> {
    problem: P,
    config: DeConfig,
    observers: Vec<Box<dyn Observer + 'a>>,
    threads: Option<usize>,
}

impl<'a, P: Problem> Driver<'a, P> {
    /// A driver on `problem` (pass `&problem` to keep it); the config is validated by `run`.
    pub fn new(problem: P, config: DeConfig) -> Self {
        Self {
            problem,
            config,
            observers: Vec::new(),
            threads: None,
        }
    }

    /// Adds an observer; observers are called in the order added.
    pub fn observer(mut self, observer: Box<dyn Observer + 'a>) -> Self {
        self.observers.push(observer);
        self
    }

    /// `Some(n)`: evaluate on a private pool of `n ≥ 1` threads (so concurrent fits don't
    /// contend for the global pool); `None`: the current rayon pool. Results do not depend on it.
    pub fn threads(mut self, threads: Option<usize>) -> Self {
        self.threads = threads;
        self
    }

    /// Runs to convergence or the generation cap.
    pub fn run(mut self) -> Result<DeResult, FitError> {
        let start = Instant::now();
        let solver = DifferentialEvolution::new(self.config.clone())?;
        let pool = match self.threads {
            None => None,
            Some(0) => {
                return Err(FitError::BadConfig {
                    field: "threads",
                    value: "0".into(),
                    expected: "at least 1 thread",
                })
            }
            Some(n) => Some(
                rayon::ThreadPoolBuilder::new()
                    .num_threads(n)
                    .build()
                    .map_err(|e| FitError::ThreadPool(e.to_string()))?,
            ),
        };
        let problem = &self.problem;
        // Only the evaluation runs inside the pool; observers stay on this thread.
        let in_pool = |op: &mut (dyn FnMut() -> Result<(), FitError> + Send)| match &pool {
            Some(pool) => pool.install(op),
            None => op(),
        };

        let mut state = None;
        in_pool(&mut || {
            state = Some(solver.init(problem)?);
            Ok(())
        })?;
        let mut state = state.expect("init succeeded");
        let mut history = Vec::new();
        let stop_reason = loop {
            let stats = GenerationStats::of(&state);
            for o in &mut self.observers {
                o.on_generation(&stats);
            }
            history.push(stats);
            if solver.converged(&state) {
                break StopReason::Converged;
            }
            if state.generation() >= self.config.max_generations {
                break StopReason::GenerationCap;
            }
            in_pool(&mut || solver.step(problem, &mut state))?;
        };

        let best = state.best_index();
        Ok(DeResult {
            best_x: state.population()[best].clone(),
            best_cost: state.costs()[best],
            generations: state.generation(),
            evaluations: state.evaluations(),
            abandoned: state.abandoned(),
            stop_reason,
            history,
            population: state.population().to_vec(),
            costs: state.costs().to_vec(),
            wall_s: start.elapsed().as_secs_f64(),
        })
    }
}
