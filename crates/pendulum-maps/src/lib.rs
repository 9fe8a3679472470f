//! Parameter sweeps of the pendulum model: bifurcation diagrams and rotation-zone maps.
//!
//! * [`bifurcation`]: one parameter swept (usually ω), from a set of initial states at every
//!   value ([`Mode::Grid`]) or by continuation ([`Mode::Continuation`]: each value starts from
//!   the attractor the previous one reached, swept up and down). The Poincaré points (one per
//!   forcing period after the transient) and their class, as a Parquet table and a PNG in the
//!   manner of the study's Figs. 8–9.
//! * [`zones`]: two parameters swept on a grid (e.g. ω × R); per cell, the fraction of initial
//!   states that end in rotation and the mean rotation speed; heat maps, and two models compared
//!   cell by cell with the cells where one rotates and the other does not marked.
//! * [`ics`]: the initial states (a θ0 × θ̇0 grid, seeded random draws, or a list).
//! * [`sweep`]: `omega=0.5:3.5:0.01`-style sweep specifications.
//! * [`shard`]: a map split into shards (`--shard I/N`, or from a Slurm array or a Kubernetes
//!   Indexed Job), each writing `OUT/shard=I/part.parquet` and a manifest, and the checks and
//!   row order of `pendulum merge`.
//! * [`params_file`]: the model rows of `params.parquet` (written by `pendulum identify`) as
//!   parameter assignments.
//!
//! Every (value, initial state) is an independent simulation: the work runs in parallel with
//! rayon, on the global pool or on a pool of a given size. Results come back in a fixed order
//! and each simulation is deterministic, so the same inputs give bit-identical outputs whatever
//! the number of threads.

pub mod bifurcation;
pub mod design;
pub mod ics;
pub mod params_file;
pub mod power;
pub mod shard;
pub mod style;
pub mod sweep;
pub mod zones;

use std::path::PathBuf;

pub use bifurcation::{Bifurcation, BifurcationConfig, Direction, Mode, Outcome};
pub use ics::IcSpec;
pub use params_file::{read_params, ParamsRow};
pub use shard::{Manifest, Shard, ShardSet, ShardSpec};
pub use sweep::{Sweep, SweepParam};
pub use zones::{ZoneCell, ZoneConfig, ZoneMap};

/// Errors of the sweeps; each names what was wrong and what was expected.
#[derive(Debug, thiserror::Error)]
pub enum MapsError {
    #[error(transparent)]
    Model(#[from] pendulum_model::ModelError),
    #[error(transparent)]
    Report(#[from] pendulum_report::ReportError),
    #[error(transparent)]
    Plot(#[from] pendulum_plot::PlotError),
    #[error("{path}: reading Parquet: {source}")]
    Parquet {
        path: PathBuf,
        #[source]
        source: parquet::errors::ParquetError,
    },
    #[error("{path}: {source}")]
    Io {
        path: PathBuf,
        #[source]
        source: std::io::Error,
    },
    #[error("{0}")]
    Invalid(String),
}

/// Runs `f` on a rayon pool of `threads` threads (`None` = the global pool).
pub(crate) fn with_pool<R: Send>(
    threads: Option<usize>,
    f: impl FnOnce() -> R + Send,
) -> Result<R, MapsError> {
    match threads {
        None => Ok(f()),
        Some(0) => Err(MapsError::Invalid("threads must be at least 1".to_string())),
        Some(n) => {
            let pool = rayon::ThreadPoolBuilder::new()
                .num_threads(n)
                .build()
                .map_err(|e| MapsError::Invalid(format!("cannot start {n} threads: {e}")))?;
            Ok(pool.install(f))
        }
    }
}

// θ wrapped to [−π, π): the workspace's one implementation, for the modules' `crate::wrap_pi`.
use pendulum_numerics::wrap_pi;

/// Index of a class in [`pendulum_model::SteadyClass::ALL`].
pub fn class_index(c: pendulum_model::SteadyClass) -> usize {
    pendulum_model::SteadyClass::ALL
        .iter()
        .position(|x| *x == c)
        .unwrap_or(4)
}
