//! `neurotex import`: recordings from other layouts into the dataset format.

use std::path::PathBuf;

use anyhow::Result;
use clap::{Args, Subcommand};
use neurotex::workflows::import::{ImportCsvOptions, ImportStackedOptions};

use crate::output::Shown;

/// `neurotex import`: bring recordings from other layouts into the dataset format.
#[derive(Subcommand)]
pub enum ImportCommand {
    /// Per-trial CSV logs (a header row or none, a time column, one column per channel),
    /// with metadata taken from the file names.
    Csv(ImportCsvArgs),
    /// A stacked array `(N, ...)` with one label (and optionally one speed) per sample.
    Stacked(ImportStackedArgs),
}

/// Options of `neurotex import csv`.
#[derive(Args)]
pub struct ImportCsvArgs {
    #[command(flatten)]
    pub options: ImportCsvOptions,
    /// The dataset folder to create (must not exist, or be empty).
    #[arg(long)]
    pub out: PathBuf,
}

/// Options of `neurotex import stacked`.
#[derive(Args)]
pub struct ImportStackedArgs {
    #[command(flatten)]
    pub options: ImportStackedOptions,
    /// The dataset folder to create.
    #[arg(long)]
    pub out: PathBuf,
}

/// Runs `neurotex import csv` or `neurotex import stacked`.
pub fn run(command: ImportCommand) -> Result<()> {
    match command {
        ImportCommand::Csv(args) => {
            let shown = Shown::new("importing");
            let summary = args.options.run(&args.out, &shown.callback());
            shown.finish();
            summary?;
        }
        ImportCommand::Stacked(args) => {
            let n = args.options.run(&args.out)?;
            eprintln!("{n} recordings -> {}", args.out.display());
        }
    }
    Ok(())
}
