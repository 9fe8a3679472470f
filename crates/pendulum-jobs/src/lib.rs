//! The jobs the `pendulum` binary offers, as library functions: each takes an options struct,
//! does the work and returns a summary the binary prints. No argument parsing here, no printing
//! of results (progress bars excepted).

pub mod bifurcate;
pub mod demo;
pub mod design;
pub mod discover;
pub mod identify;
pub mod ingest;
pub mod inputs;
pub mod merge;
pub mod outputs;
pub mod replay;
pub mod runs;
pub mod simulate;
pub mod synth;
pub mod zones;

use std::path::PathBuf;

/// This process's invocation (id carried by every table, start instant): the binary calls it
/// first thing so that the start is the process's.
pub use pendulum_report::invocation;

/// Errors of a job, with the layer that failed.
#[derive(Debug, thiserror::Error)]
pub enum JobError {
    #[error(transparent)]
    Model(#[from] pendulum_model::ModelError),
    #[error(transparent)]
    Report(#[from] pendulum_report::ReportError),
    #[error(transparent)]
    Rig(#[from] pendulum_rig::RigError),
    #[error(transparent)]
    Log(#[from] pendulum_log::LogError),
    #[error(transparent)]
    Process(#[from] pendulum_process::ProcessError),
    #[error(transparent)]
    Plot(#[from] pendulum_plot::PlotError),
    #[error("{path}: {source}")]
    Io {
        path: PathBuf,
        #[source]
        source: std::io::Error,
    },
    /// An output path names one of the command's input files (see [`inputs`]).
    #[error(
        "{}: {what_output} is the same file as {what_input} {}: refusing to overwrite an input; \
         choose another output path",
        .output.display(),
        .input.display()
    )]
    OutputIsInput {
        output: PathBuf,
        what_output: String,
        input: PathBuf,
        what_input: String,
    },
    /// A size the machine cannot hold, refused before any work: `given` names the options and
    /// their values, `what` counts what they ask for, `why` says what each unit costs and what
    /// the limit comes to.
    #[error("{given} asks for {what}, more than the limit of {limit}: {why}")]
    TooLarge {
        given: String,
        what: String,
        limit: String,
        why: String,
    },
    #[error("{0}")]
    Invalid(String),
}
