//! `pendulum synth CASE.toml OUT_DIR`: the digital twin writes a campaign with known truth.

use std::path::Path;

use pendulum_rig::names;
use pendulum_rig::twin::{synthesize, TwinCase, TwinFormat, TwinSummary};
use pendulum_rig::RigError;

use crate::inputs::Inputs;
use crate::JobError;

pub fn run(case_path: &Path, out_dir: &Path) -> Result<TwinSummary, JobError> {
    let case = TwinCase::load(case_path)?;
    check_ids(&case, case_path)?;
    check_outputs(&case, case_path, out_dir)?;
    Ok(synthesize(&case, out_dir)?)
}

/// The files the twin writes into `out_dir` (and its temporaries for the last two): none may be
/// the case file itself (`pendulum synth OUT/campaign.toml OUT`).
fn check_outputs(case: &TwinCase, case_path: &Path, out_dir: &Path) -> Result<(), JobError> {
    let mut inputs = Inputs::new();
    inputs.add("the case file", case_path);
    let mut names: Vec<String> = ["campaign.toml", "campaign.tmp", "truth.json", "truth.tmp"]
        .map(String::from)
        .into();
    for run in &case.runs {
        names.push(match run.format {
            TwinFormat::Serial => format!("{}.csv", run.id),
            TwinFormat::Sd => format!("{}.bin", run.id),
        });
    }
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
