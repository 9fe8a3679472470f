//! Pipeline stages: alignment, initial conditions, the measured steady state, the study's damping
//! fit and its validation.

pub mod align;
pub mod fit;
#[cfg(test)]
mod free_tests;
pub mod ic;
pub mod identify;
pub mod measured;
pub mod pipeline;
pub mod run;

pub use align::{align, AlignConfig, Alignment, AlignmentKind};
pub use run::{RigParams, Role, RunData};

/// Errors of the processing stages; each names the run or stage and what was expected.
#[derive(Debug, thiserror::Error)]
pub enum ProcessError {
    #[error("run {run}: cannot align: {reason}")]
    Align { run: String, reason: String },
    #[error("stage {stage}: {field}: {message}")]
    BadConfig {
        stage: String,
        field: String,
        message: String,
    },
    #[error("run {run}: {reason}")]
    Run { run: String, reason: String },
    #[error("{path}:{line}:{column}: pipeline: {message}")]
    Pipeline {
        path: std::path::PathBuf,
        line: usize,
        column: usize,
        message: String,
    },
    #[error(transparent)]
    Model(#[from] pendulum_model::ModelError),
    #[error(transparent)]
    Fit(#[from] pendulum_fit::FitError),
}
