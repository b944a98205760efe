//! `neurotex`: the command line over the neurotex library. It parses arguments, calls the
//! library, shows progress and writes files (always to a temporary name, then renamed, so a
//! failed run leaves no partial output).

mod commands;
mod output;
mod stage_args;

use std::process::ExitCode;

use clap::{Parser, Subcommand};

/// Neuromorphic tactile texture classification: taxel recordings → Izhikevich spikes →
/// single-taxel statistics or 2D/3D GLCM features → KNN.
#[derive(Parser)]
#[command(name = "neurotex", version, about, long_about = None)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Encode one recording into spikes (u8 raster `(T, rows, cols)` at 1 kHz, .npy).
    Encode(commands::EncodeArgs),
    /// Extract one feature row per recording of a dataset into a CSV file.
    Features(commands::FeaturesArgs),
    /// Classify a dataset's recordings with KNN and print accuracy and confusion matrix.
    Evaluate(commands::EvaluateArgs),
    /// Simulate the paper's rig (8 textures, 4x4 taxels, 1 N, 90 mm slides) into a dataset folder.
    Simulate(commands::SimulateArgs),
    /// Run every analysis of the paper (E0-E8) and write a report with figures; without
    /// --dataset, on the built-in simulated rig.
    Reproduce(commands::ReproduceArgs),
    /// Import CSV logs or stacked arrays into a dataset folder.
    #[command(subcommand)]
    Import(commands::ImportCommand),
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    let result = match cli.command {
        Command::Encode(args) => commands::encode(args),
        Command::Features(args) => commands::features(args),
        Command::Evaluate(args) => commands::evaluate(args),
        Command::Simulate(args) => commands::simulate(args),
        Command::Reproduce(args) => commands::reproduce(args),
        Command::Import(cmd) => commands::import(cmd),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(err) => {
            eprintln!("error: {err:#}");
            ExitCode::FAILURE
        }
    }
}
