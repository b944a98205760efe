//! `neurotex`: the command line over the neurotex library. It parses arguments, calls the
//! library, shows progress and writes files (always to a temporary name, then renamed, so a
//! failed run leaves no partial output).

mod commands;
mod interrupt;
mod output;
mod stage_args;

use std::process::ExitCode;

use clap::{Parser, Subcommand};
use commands::{
    compare, datasets, encode, evaluate, export, features, import, inspect, predict, reproduce,
    simulate, stream, train,
};

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
    /// Check a dataset or raw logs before analysing them: the design and what it supports,
    /// the signals (rate, gaps, offsets, dead, clipped, copied channels, a clock read as a
    /// channel), the layout and the encoder at the gain; each finding with the option that
    /// addresses it.
    Inspect(inspect::InspectArgs),
    /// Encode one recording into spikes (u8 raster `(T, rows, cols)` at 1 kHz, .npy).
    Encode(encode::EncodeArgs),
    /// Extract one feature row per recording of a dataset into a CSV file.
    Features(features::FeaturesArgs),
    /// Classify a dataset's recordings (KNN, random forest or logistic regression) and print
    /// accuracy and confusion matrix.
    Evaluate(evaluate::EvaluateArgs),
    /// Compare encodings, feature methods and classifiers on the same splits of a dataset:
    /// a ranking with 95 % intervals and a paired test against the paper's method.
    Compare(compare::CompareArgs),
    /// Train a classifier on a dataset and save it as a model file (pipeline, features, grid,
    /// classifier, training data's fingerprint) for `neurotex predict`.
    Train(train::TrainArgs),
    /// Predict the texture of new recordings (a dataset or files) with a saved model,
    /// applying the model's own pipeline; writes one CSV row per recording.
    Predict(predict::PredictArgs),
    /// Simulate the paper's rig (8 textures, 4x4 taxels, 1 N, 90 mm slides) into a dataset folder.
    Simulate(simulate::SimulateArgs),
    /// Run every analysis of the paper (E0-E8), and E5c and E9 beyond it, and write a
    /// report with figures; without --dataset, on the built-in simulated rig.
    Reproduce(reproduce::ReproduceArgs),
    /// Classify a live taxel stream (standard input, a file, TCP, UDP or the Lab Streaming
    /// Layer) frame by frame with a model trained with --causal, or an event sensor's events
    /// (--format events or events-bin) with any model: one JSON line per 200 ms bin, one per
    /// episode's end (docs/live-rigs.md).
    ///
    /// Bad frames are said on standard error with their line or frame number, counted
    /// (`bad_frames` in the end line) and skipped; the stream goes on. They are: a CSV line
    /// longer than 64 bytes a taxel (at least 1 MiB; it is read to its end in bounded
    /// memory) or not UTF-8, a wrong field count, a value that is not a finite number, a
    /// stamp beyond 2^33 s (272 years) from zero, where f64 stamps stop resolving 1 us, and
    /// a stamp that does not follow the previous frame's: not after it, or more than
    /// --max-gap-s after it. When the next frame follows such a stamp instead of the previous
    /// one, the clock has jumped (a pause, a restarted sensor): the episode ends
    /// ("ended_by":"gap") and a new one starts at that next frame. So one wrong stamp (a bit
    /// flip far ahead) costs its own frame, and a jump that stays costs one frame.
    Stream(neurotex::workflows::stream::StreamOptions),
    /// The public datasets neurotex has recipes for: list, check, fetch (downloaded or from
    /// a local copy; checksums verified, imported once), their folder in the cache.
    #[command(subcommand)]
    Datasets(neurotex::workflows::datasets::DatasetsCommand),
    /// The public datasets' leaderboard: under each protocol of each recipe, a fixed
    /// candidate set compared with nested selection, the published results beside it.
    Benchmark(neurotex::workflows::benchmark::BenchmarkOptions),
    /// Import CSV logs or stacked arrays into a dataset folder.
    #[command(subcommand)]
    Import(import::ImportCommand),
    /// Export a spiking model's network as a NIR graph (for snnTorch, Norse, Rockpool and
    /// neuromorphic hardware), or the spike tensors its input receives.
    #[command(subcommand)]
    Export(export::ExportCommand),
}

/// Ends on an argument the parser refused, a number's error in words rather than the
/// standard library's ("invalid digit found in string" for `--folds -1`).
fn parse_failed(e: clap::Error) -> ! {
    use clap::error::ErrorKind;
    if !matches!(
        e.kind(),
        ErrorKind::ValueValidation | ErrorKind::InvalidValue
    ) {
        e.exit()
    }
    let text = e.render().to_string();
    eprint!("{}", neurotex::error::number_words(&text));
    std::process::exit(e.exit_code())
}

fn main() -> ExitCode {
    let cli = Cli::try_parse().unwrap_or_else(|e| parse_failed(e));
    interrupt::install();
    if let Ok(value) = std::env::var("NEUROTEX_SIMD") {
        if !matches!(value.as_str(), "native" | "avx2" | "portable") {
            eprintln!("warning: NEUROTEX_SIMD={value} is not native, avx2 or portable; the processor's widest instructions are used");
        }
    }
    let result = match cli.command {
        Command::Inspect(args) => match inspect::run(args) {
            Ok(false) => return ExitCode::from(2),
            other => other.map(|_| ()),
        },
        Command::Encode(args) => encode::run(args),
        Command::Features(args) => features::run(args),
        Command::Evaluate(args) => evaluate::run(args),
        Command::Compare(args) => compare::run(args),
        Command::Train(args) => train::run(args),
        Command::Predict(args) => predict::run(args),
        Command::Simulate(args) => simulate::run(args),
        Command::Reproduce(args) => reproduce::run(args),
        Command::Stream(args) => stream::run(args),
        Command::Import(command) => import::run(command),
        Command::Datasets(command) => datasets::run(command),
        Command::Benchmark(options) => datasets::benchmark(options),
        Command::Export(command) => export::run(command),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(err) => {
            eprintln!("error: {}", message(&err));
            if let Some(hint) = hint(&err) {
                eprintln!("hint: {hint}");
            }
            ExitCode::FAILURE
        }
    }
}

/// The error and its causes, each said once: a library error that names its recording or
/// analysis already ends with its cause's text.
fn message(err: &anyhow::Error) -> String {
    let mut text = String::new();
    for cause in err.chain() {
        let said = cause.to_string();
        if text.ends_with(&said) {
            continue;
        }
        if !text.is_empty() {
            text.push_str(": ");
        }
        text.push_str(&said);
    }
    text
}

/// What to change when a dataset is too small for the folds or neighbours asked for.
fn hint(err: &anyhow::Error) -> Option<String> {
    err.chain().find_map(|e| {
        if let Some(c) = e.downcast_ref::<neurotex::error::ClassifyError>() {
            return c.hint(&option);
        }
        design_hint(e.downcast_ref::<neurotex::Error>()?)
    })
}

/// What to change when `err` says the data is too small for the folds or neighbours.
fn design_hint(err: &neurotex::Error) -> Option<String> {
    err.classify()?.hint(&option)
}

/// An option as the command line spells it (`--folds 2`).
fn option(name: &str, value: &str) -> String {
    format!("--{name} {value}")
}
