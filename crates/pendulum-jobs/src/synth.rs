//! `pendulum synth CASE.toml OUT_DIR`: the digital twin writes a campaign with known truth.

use std::path::Path;

use pendulum_rig::twin::{synthesize, TwinCase, TwinSummary};

use crate::JobError;

pub fn run(case: &Path, out_dir: &Path) -> Result<TwinSummary, JobError> {
    let case = TwinCase::load(case)?;
    Ok(synthesize(&case, out_dir)?)
}
