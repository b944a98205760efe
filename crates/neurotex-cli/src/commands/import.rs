//! `neurotex import`: recordings from other layouts into the dataset format.

use std::path::PathBuf;

use anyhow::Result;
use clap::{Args, Subcommand};
use neurotex::workflows::import::{ImportCsvOptions, ImportEventsOptions, ImportStackedOptions};

use crate::output::{check_folder, Shown};

/// `neurotex import`: bring recordings from other layouts into the dataset format.
#[derive(Subcommand)]
pub enum ImportCommand {
    /// Per-trial CSV logs (a header row or none, a time column, one column per channel),
    /// with metadata taken from the file names.
    Csv(ImportCsvArgs),
    /// A stacked array `(N, ...)` with one label (and optionally one speed) per sample.
    Stacked(ImportStackedArgs),
    /// Address-event logs of an event sensor (one file per trial: a time, x and y or a
    /// taxel index, and optionally a polarity per event; CSV with a header row or tonic's
    /// structured `.npy`), with metadata from the file names. Events out of time order are
    /// sorted (and counted); every other rule is checked as a dataset's reader checks it.
    /// The dataset's recordings skip the encoder: ON events are the SA population's spikes,
    /// OFF events the FA population's.
    Events(ImportEventsArgs),
}

/// Options of `neurotex import events`.
#[derive(Args)]
pub struct ImportEventsArgs {
    #[command(flatten)]
    pub options: ImportEventsOptions,
    /// The dataset folder to create (must not exist, or be empty).
    #[arg(long)]
    pub out: PathBuf,
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

/// Runs `neurotex import csv`, `stacked` or `events`.
pub fn run(command: ImportCommand) -> Result<()> {
    match command {
        ImportCommand::Csv(args) => {
            check_folder(&args.out, "--out")?;
            let shown = Shown::new("importing");
            let summary = args.options.run(&args.out, &shown.callback());
            shown.finish();
            summary?;
        }
        ImportCommand::Events(args) => {
            check_folder(&args.out, "--out")?;
            let shown = Shown::new("importing");
            let imported = args.options.run(&args.out, &shown.callback());
            shown.finish();
            imported?;
        }
        ImportCommand::Stacked(args) => {
            check_folder(&args.out, "--out")?;
            let n = args.options.run(&args.out)?;
            eprintln!("{n} recordings -> {}", args.out.display());
        }
    }
    Ok(())
}
