//! Generic optimisation layer of the damping-model identification, argmin-style: a [`Problem`]
//! only knows how to cost a point, [`DifferentialEvolution`] only knows how to advance a
//! population by one generation, and the [`Driver`] owns the loop (stopping, threads,
//! observers, timing). Keeping them apart lets the CLI, batch jobs and tests reuse the same solver
//! with different problems and reporting.
//!
//! The solver is DE/rand/1/bin with synchronous generations. All random draws are made
//! sequentially from a seeded ChaCha8 stream before the parallel evaluation, so a run is
//! bit-identical whatever the number of threads, and the optional early abandon of hopeless
//! trials ([`Cost::AtLeast`]) never changes the trajectory, only the work done.
//!
//! Least squares follow the same split: a [`LeastSquaresProblem`] only knows its residuals (and,
//! by default numerically, their Jacobian), [`LevenbergMarquardt`] and [`GaussNewton`] only know
//! how to minimise Σ r², and [`SumOfSquares`] hands the same problem to DE or Nelder–Mead.

pub mod de;
pub mod driver;
pub mod error;
pub mod gn;
pub mod least_squares;
pub mod lm;
pub mod polish;
pub mod problem;

pub use de::{DeConfig, DeState, DifferentialEvolution, StopRule};
pub use driver::{
    ConvergenceHistory, DeResult, Driver, FnObserver, GenerationStats, HistoryPoint, Observer,
    StopReason,
};
pub use error::FitError;
pub use gn::{GaussNewton, GnConfig};
pub use least_squares::{
    finite_difference_jacobian, LeastSquaresProblem, LsResult, LsStop, SumOfSquares,
};
pub use lm::{LevenbergMarquardt, LmConfig};
pub use polish::nelder_mead;
pub use problem::{Cost, Problem};
