//! `pendulum synth CASE.toml OUT_DIR`: the digital twin writes a campaign with known truth.

use std::path::Path;

use pendulum_rig::names;
use pendulum_rig::twin::{synthesize, TwinCase, TwinFormat, TwinSummary};
use pendulum_rig::RigError;

use crate::inputs::Inputs;
use crate::JobError;

/// Writes the twin's campaign into `out_dir` as one unit: the completion marker goes first,
/// this program's stale temporary files of the campaign's files go (nothing else in the
/// folder), every file is written under a temporary name unique to this process and renamed
/// into place, and the marker naming them is written last ([`crate::outputs::mark_complete`]).
pub fn run(case_path: &Path, out_dir: &Path) -> Result<TwinSummary, JobError> {
    let case = TwinCase::load(case_path)?;
    check_ids(&case, case_path)?;
    let names = output_names(&case);
    check_outputs(&names, case_path, out_dir)?;
    std::fs::create_dir_all(out_dir).map_err(|source| JobError::Io {
        path: out_dir.to_path_buf(),
        source,
    })?;
    crate::outputs::remove_marker(out_dir)?;
    crate::outputs::remove_stale_temps_of(out_dir, &names)?;
    let summary = synthesize(&case, out_dir)?;
    let files: Vec<_> = names
        .iter()
        .filter(|n| *n != crate::outputs::COMPLETE_MARKER)
        .map(|n| out_dir.join(n))
        .collect();
    crate::outputs::mark_complete(out_dir, "pendulum synth", &files)?;
    Ok(summary)
}

/// The files the twin writes into its folder (the marker included).
fn output_names(case: &TwinCase) -> Vec<String> {
    let mut names: Vec<String> = [
        "campaign.toml",
        "truth.json",
        crate::outputs::COMPLETE_MARKER,
    ]
    .map(String::from)
    .into();
    for run in &case.runs {
        names.push(match run.format {
            TwinFormat::Serial => format!("{}.csv", run.id),
            TwinFormat::Sd => format!("{}.bin", run.id),
        });
    }
    names
}

/// None of the files the twin writes may be the case file itself (`pendulum synth
/// OUT/campaign.toml OUT`).
fn check_outputs(names: &[String], case_path: &Path, out_dir: &Path) -> Result<(), JobError> {
    let mut inputs = Inputs::new();
    inputs.add("the case file", case_path);
    for name in names {
        inputs.check_output("the output", &out_dir.join(name))?;
    }
    Ok(())
}

/// The twin names each run's capture `<id>.csv` / `<id>.bin` in `out_dir`: an id that is not a
/// safe file name would write outside it. Checked here, before anything is simulated or written,
/// with the same rule as a campaign's ids ([`names::check_run_id`]).
fn check_ids(case: &TwinCase, case_path: &Path) -> Result<(), JobError> {
    for (i, run) in case.runs.iter().enumerate() {
        names::check_run_id(&run.id).map_err(|problem| RigError::UnsafeName {
            path: case_path.to_path_buf(),
            run: format!("run #{}", i + 1),
            key: "id",
            value: run.id.clone(),
            problem,
        })?;
    }
    Ok(())
}
