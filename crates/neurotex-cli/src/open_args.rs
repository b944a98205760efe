//! How a command opens a dataset folder.

use std::path::Path;

use anyhow::Result;
use clap::Args;
use neurotex::recording::Dataset;

/// Options on opening a dataset, shared by every command that reads one.
#[derive(Args, Debug, Clone, Default)]
pub struct OpenArgs {
    /// Let manifest `file` entries point outside the dataset folder (`../x.npy`, absolute
    /// paths, symbolic links to elsewhere). Refused by default: a manifest should not make
    /// neurotex read any file on the machine.
    #[arg(long = "allow-outside-paths")]
    pub allow_outside_paths: bool,
}

impl OpenArgs {
    /// Opens the dataset folder `dir` under these options.
    pub fn open(&self, dir: &Path) -> Result<Dataset> {
        Ok(Dataset::open_with(dir, self.allow_outside_paths)?)
    }
}
