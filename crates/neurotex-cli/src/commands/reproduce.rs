//! `neurotex reproduce`: every analysis of the paper (E0-E8) into a report with figures.

use std::path::PathBuf;
use std::sync::Mutex;
use std::time::Instant;

use anyhow::{bail, Result};
use clap::Args;
use indicatif::ProgressBar;
use neurotex::experiments::{
    claims, prepare, run_all, Progress, ReproduceParams, Source, ValidReproduceParams,
};
use neurotex::recording::Dataset;
use neurotex::report::{write_report, ReportContext};

use crate::output::progress;
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
    /// Neighbours in KNN.
    #[arg(long, default_value_t = 5)]
    pub k: usize,
    #[command(flatten)]
    pub stages: StageArgs,
}

impl ReproduceArgs {
    /// The analyses' parameters these options name, checked.
    fn params(&self) -> Result<ValidReproduceParams> {
        let mut params = if self.quick {
            ReproduceParams::quick()
        } else {
            ReproduceParams::default()
        };
        params.pipeline = self.stages.pipeline()?;
        params.knn = self.stages.knn(self.k)?;
        params.seed = self.seed;
        params.cv.seed = self.seed;
        Ok(params.check()?)
    }

    /// The data to run on: the dataset folder, or the paper's design on the simulator.
    fn source<'a>(&self, dataset: Option<&'a Dataset>) -> Result<Source<'a>> {
        let trials_per = self.trials.unwrap_or(if self.quick { 10 } else { 20 });
        if trials_per == 0 {
            bail!("--trials must be at least 1");
        }
        Ok(match dataset {
            Some(ds) => Source::Dataset(ds),
            None => Source::paper_design(trials_per, self.seed),
        })
    }
}

/// Runs `neurotex reproduce`.
pub fn run(args: ReproduceArgs) -> Result<()> {
    let started = Instant::now();
    let params = args.params()?;
    let dataset = match &args.dataset {
        Some(dir) => Some(Dataset::open(dir)?),
        None => None,
    };
    let source = args.source(dataset.as_ref())?;
    let bar = Mutex::new(progress(0, "starting"));
    let on_progress = |p: Progress| show_progress(&bar.lock().expect("progress bar"), p);
    let prepared = prepare(&source, &params, &on_progress)?;
    let results = run_all(&prepared, &params, &on_progress)?;
    bar.lock().expect("progress bar").finish_and_clear();
    let ctx = ReportContext {
        dataset: source.describe(),
        parameters: params.describe(),
        total_seconds: started.elapsed().as_secs_f64(),
        command: command_line(),
        paper_comparable: dataset.is_none(),
    };
    write_report(&args.out, &results, &ctx)?;
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

/// Moves the progress bar on one event of the analyses.
fn show_progress(bar: &ProgressBar, event: Progress) {
    match event {
        Progress::Stage(name, n) => {
            bar.set_length(n as u64);
            bar.set_position(0);
            bar.set_message(name.to_string());
        }
        Progress::Tick => bar.inc(1),
    }
}

/// The command line that produced the report, as `neurotex ...` with quoted arguments.
fn command_line() -> String {
    let command = std::env::args()
        .map(|a| if a.contains(' ') { format!("'{a}'") } else { a })
        .collect::<Vec<_>>()
        .join(" ");
    command.replacen(&std::env::args().next().unwrap_or_default(), "neurotex", 1)
}
