//! The files a command reads, so that none of its outputs is written over one of them.
//!
//! `pendulum replay RUN --params P.parquet --out P.parquet` used to replace the params table
//! with an MCAP file and exit 0 (issue 13): outputs are written to a temporary file and renamed
//! over the target, so reading the input first does not protect it. Every command that takes
//! input files and output paths collects its inputs here and checks each output path before
//! writing it (and, where the names are known up front, before any long computation).

use std::path::{Path, PathBuf};

use pendulum_rig::Campaign;

use crate::JobError;

/// One input file: what it is for messages (`--params`, `run r01's capture`), the path as the
/// user gave it, and its identity on disk.
#[derive(Debug, Clone)]
struct Input {
    what: String,
    path: PathBuf,
    id: FileId,
}

/// A file's identity: its canonical path (symbolic links and `..` resolved) and, on Unix, its
/// device and inode, which also catch a hard link under another name.
#[derive(Debug, Clone, PartialEq, Eq)]
struct FileId {
    canonical: PathBuf,
    #[cfg(unix)]
    dev_ino: (u64, u64),
}

impl FileId {
    /// `None` when `path` does not exist (nothing there to overwrite) or cannot be resolved.
    fn of(path: &Path) -> Option<Self> {
        let canonical = path.canonicalize().ok()?;
        #[cfg(unix)]
        {
            use std::os::unix::fs::MetadataExt;
            let m = std::fs::metadata(&canonical).ok()?;
            Some(FileId {
                canonical,
                dev_ino: (m.dev(), m.ino()),
            })
        }
        #[cfg(not(unix))]
        Some(FileId { canonical })
    }

    fn same_file(&self, other: &FileId) -> bool {
        #[cfg(unix)]
        if self.dev_ino == other.dev_ino {
            return true;
        }
        self.canonical == other.canonical
    }
}

/// The input files of one command.
#[derive(Debug, Clone, Default)]
pub struct Inputs {
    files: Vec<Input>,
}

impl Inputs {
    pub fn new() -> Self {
        Self::default()
    }

    /// Adds an input file; a path that does not exist is skipped (the command reports it
    /// when it reads it).
    pub fn add(&mut self, what: impl Into<String>, path: &Path) {
        if let Some(id) = FileId::of(path) {
            self.files.push(Input {
                what: what.into(),
                path: path.to_path_buf(),
                id,
            });
        }
    }

    /// Every file a campaign folder or a folder of MCAP files contributes (what
    /// [`crate::runs::load_runs`] reads): campaign.toml and each run's capture, or each MCAP.
    pub fn add_run_source(&mut self, dir: &Path) -> Result<(), JobError> {
        match crate::runs::source(dir)? {
            crate::runs::Source::Campaign(c) => self.add_campaign(&c, dir),
            crate::runs::Source::Mcap(files) => {
                for f in files {
                    self.add("a run log", &f);
                }
            }
        }
        Ok(())
    }

    /// A campaign's files: its campaign.toml (`dir_or_toml` is what [`Campaign::load`] was
    /// given) and each run's capture.
    pub fn add_campaign(&mut self, c: &Campaign, dir_or_toml: &Path) {
        let toml = if dir_or_toml.is_dir() {
            c.toml_path()
        } else {
            dir_or_toml.to_path_buf()
        };
        self.add("the campaign file", &toml);
        for r in &c.runs {
            self.add(format!("run {}'s capture", r.id), &r.file);
        }
    }

    /// Fails when `output` is the same file as one of the inputs. `what` names the output for
    /// the message (`--out`, `the params table`).
    pub fn check_output(&self, what: &str, output: &Path) -> Result<(), JobError> {
        let Some(out_id) = FileId::of(output) else {
            return Ok(());
        };
        match self.files.iter().find(|i| i.id.same_file(&out_id)) {
            Some(input) => Err(JobError::OutputIsInput {
                output: output.to_path_buf(),
                what_output: what.to_string(),
                input: input.path.clone(),
                what_input: input.what.clone(),
            }),
            None => Ok(()),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn issue_13_an_output_that_is_an_input_is_refused() {
        let dir = tempfile::tempdir().unwrap();
        let params = dir.path().join("params.parquet");
        std::fs::write(&params, "table").unwrap();
        std::fs::create_dir(dir.path().join("sub")).unwrap();
        let mut inputs = Inputs::new();
        inputs.add("--params", &params);
        inputs.add("--missing", &dir.path().join("missing.parquet"));

        // The same file under another spelling is still the same file.
        let other_spelling = dir.path().join("sub/../params.parquet");
        let e = inputs
            .check_output("--out", &other_spelling)
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("--out") && e.contains("--params") && e.contains("same file"),
            "{e}"
        );
        #[cfg(unix)]
        {
            let link = dir.path().join("link.mcap");
            std::os::unix::fs::symlink(&params, &link).unwrap();
            assert!(inputs.check_output("--out", &link).is_err());
            let hard = dir.path().join("hard.mcap");
            std::fs::hard_link(&params, &hard).unwrap();
            assert!(inputs.check_output("--out", &hard).is_err());
        }
        // New files and other existing files are fine.
        assert!(inputs
            .check_output("--out", &dir.path().join("overlay.mcap"))
            .is_ok());
        assert!(inputs
            .check_output("--out", &dir.path().join("missing.parquet"))
            .is_ok());
        std::fs::write(dir.path().join("old.mcap"), "x").unwrap();
        assert!(inputs
            .check_output("--out", &dir.path().join("old.mcap"))
            .is_ok());
    }
}
