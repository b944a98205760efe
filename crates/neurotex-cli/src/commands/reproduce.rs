//! `neurotex reproduce`: every analysis of the paper (E0-E8) into a report with figures.

use std::path::PathBuf;
use std::sync::Mutex;
use std::time::Instant;

use anyhow::{bail, Context, Result};
use clap::Args;
use neurotex::experiments::{claims, ReproduceParams};
use neurotex::progress::Progress;
use neurotex::recording::Dataset;
use neurotex::report::reproduce::{
    reproduce, simulated_design, write_headline_predictions, Data, Run, MAX_SEEDS,
};

use super::say_calibration;
use crate::open_args::OpenArgs;
use crate::output::{check_output, progress, show_progress, write_file};
use crate::stage_args::StageArgs;

/// Options of `neurotex reproduce`.
#[derive(Args)]
pub struct ReproduceArgs {
    /// A dataset folder to run on; without it the built-in simulator generates the paper's
    /// design (8 textures x 5, 10, 15 mm/s x 20 trials) in memory.
    #[arg(long)]
    pub dataset: Option<PathBuf>,
    /// Folder for report.md, results.json and figures/.
    #[arg(long, default_value = "report")]
    pub out: PathBuf,
    /// Seed of the simulation, the CV shuffles and the perturbations.
    #[arg(long, default_value_t = 0)]
    pub seed: u64,
    /// A small run (10 trials per condition when simulating, fewer repeats, gains, fractions).
    #[arg(long)]
    pub quick: bool,
    /// Simulated trials per texture and speed (default 20, or 10 with --quick).
    #[arg(long)]
    pub trials: Option<u32>,
    /// Independent simulated datasets (simulation seeds seed, seed + 1, ...; default 5, or 1
    /// with --quick). The report shows the first in full and every headline accuracy as its
    /// mean over the datasets with a 95 % interval, and how often each claim held. Only
    /// without --dataset (a dataset folder is one draw).
    #[arg(long, conflicts_with = "dataset", value_parser = clap::value_parser!(u64).range(1..=MAX_SEEDS))]
    pub seeds: Option<u64>,
    /// Neighbours in KNN.
    #[arg(long, default_value_t = neurotex::classify::KnnParams::default().k)]
    pub k: usize,
    /// Cross-validation folds of every analysis (stratified, shuffled) [default: 5]. A small
    /// pilot needs fewer: each class needs at least this many recordings at each speed.
    #[arg(long)]
    pub folds: Option<usize>,
    /// Cross-validation repeats with different shuffles [default: 10, or 2 with --quick].
    #[arg(long)]
    pub repeats: Option<usize>,
    /// Every cross-validation of the analyses keeps each group of this manifest column in
    /// one fold (`trial` for repeats of one run, or a session or subject column); with fewer
    /// groups than folds at a speed, each group is held out in turn.
    #[arg(long = "group-by")]
    pub group_by: Option<String>,
    /// Encodings of every recording behind E1's, E4's, E6's and E8's accuracies: as run, and N - 1 more
    /// with independent rounding-level perturbations of the input (each sample times
    /// 1 + u x 1e-12). Spiking neurons near threshold turn such changes into moved spikes;
    /// the accuracies are means over the encodings and their intervals resample encodings
    /// as well as recordings. 1 evaluates the input as run only.
    #[arg(long = "encoder-draws", value_name = "N", default_value_t = neurotex::experiments::DEFAULT_ENCODER_DRAWS as u64,
          value_parser = clap::value_parser!(u64).range(1..=neurotex::experiments::MAX_ENCODER_DRAWS as u64))]
    pub encoder_draws: u64,
    /// Write the headline 3D-GLCM evaluations' out-of-fold predictions to this CSV file:
    /// `speed_mm_s,method,file,label,predicted,fold,repeat`, one row per recording and CV
    /// repeat at each speed (of the first dataset with --seeds).
    #[arg(long)]
    pub predictions: Option<PathBuf>,
    #[command(flatten)]
    pub stages: StageArgs,
    #[command(flatten)]
    pub open: OpenArgs,
}

impl ReproduceArgs {
    /// The analyses' parameters these options name (the gain still to be calibrated with
    /// `--gain auto`).
    fn params(&self) -> Result<ReproduceParams> {
        let mut params = if self.quick {
            ReproduceParams::quick()
        } else {
            ReproduceParams::default()
        };
        if self.stages.options.causal {
            bail!("reproduce runs the causal pipeline itself (its causal E5 beside the paper's offline E5); --causal is for train, evaluate, features and compare");
        }
        params.pipeline = self.stages.pipeline()?;
        params.knn = self.stages.knn(self.k)?;
        params.seed = self.seed;
        params.cv.seed = self.seed;
        params.cv.folds = self.folds.unwrap_or(params.cv.folds);
        params.cv.repeats = self.repeats.unwrap_or(params.cv.repeats);
        params.group_by = self.group_by.clone();
        params.encoder_draws = usize::try_from(self.encoder_draws)?;
        Ok(params)
    }
}

/// Runs `neurotex reproduce`.
pub fn run(args: ReproduceArgs) -> Result<()> {
    let started = Instant::now();
    let dataset = match &args.dataset {
        Some(dir) => Some(args.open.open(dir)?),
        None => None,
    };
    let _claim =
        neurotex::report::check_report_dir(&args.out).context("checking the report folder")?;
    if let Some(path) = &args.predictions {
        let inputs = dataset.as_ref().map(Dataset::files).unwrap_or_default();
        check_output(path, &inputs)?;
    }
    let (trials, seeds) = match dataset {
        Some(_) => (0, Vec::new()),
        None => simulated_design(args.quick, args.trials, args.seeds, args.seed)?,
    };
    let data = match &dataset {
        Some(ds) => Data::Folder(ds),
        None => Data::Simulated {
            trials,
            seeds: &seeds,
        },
    };
    let bar = Mutex::new(progress(0, "starting"));
    let on_progress = |p: Progress| show_progress(&bar.lock().expect("progress bar"), p);
    let run = Run {
        gain_target: args.stages.gain_target(),
        command: command_line(),
        on_progress: &on_progress,
        on_gain: &say_calibration,
    };
    let results = reproduce(&args.out, data, args.params()?, &run)?;
    bar.lock().expect("progress bar").finish_and_clear();
    if let Some(path) = &args.predictions {
        write_file(path, "out-of-fold predictions", |w| {
            write_headline_predictions(w, &results.predictions)
        })?;
    }
    for claim in claims(&results) {
        eprintln!("{:<40} {}", claim.verdict.describe(), claim.statement);
    }
    eprintln!(
        "report in {}/report.md ({:.1} s)",
        args.out.display(),
        started.elapsed().as_secs_f64()
    );
    Ok(())
}

/// The command line that produced the report, as `neurotex ...` with quoted arguments.
fn command_line() -> String {
    let command = std::env::args()
        .map(|a| if a.contains(' ') { format!("'{a}'") } else { a })
        .collect::<Vec<_>>()
        .join(" ");
    command.replacen(&std::env::args().next().unwrap_or_default(), "neurotex", 1)
}
