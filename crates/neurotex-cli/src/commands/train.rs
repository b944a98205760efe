//! `neurotex train`: a classifier (KNN, random forest or logistic regression) trained on a
//! dataset's features, saved as a model file that `neurotex predict` applies to new
//! recordings.

use std::path::PathBuf;

use anyhow::Result;
use clap::Args;
use neurotex::workflows::train::TrainOptions;

use crate::output::{check_output, save_to, Shown};
use crate::stage_args::StageArgs;

/// Options of `neurotex train`.
#[derive(Args)]
pub struct TrainArgs {
    #[command(flatten)]
    pub options: TrainOptions,
    /// The model file to write (JSON: pipeline, features, grid, classifier, training rows,
    /// the dataset's fingerprint).
    #[arg(long)]
    pub out: PathBuf,
    #[command(flatten)]
    pub stages: StageArgs,
}

/// Runs `neurotex train`.
pub fn run(args: TrainArgs) -> Result<()> {
    let o = &args.options;
    let dataset = o.open.open(&o.dataset)?;
    check_output(&args.out, &dataset.files())?;
    let shown = Shown::new("starting");
    if o.spiking() {
        let trained = o.run_spiking(&dataset, &args.stages.options, &shown.callback());
        shown.finish();
        let trained = trained?;
        let model = &trained.model;
        save_to(&args.out, "the model", |p| model.save(p))?;
        eprintln!(
            "{} -> {}",
            trained.summary(),
            crate::output::shown(&args.out)
        );
        if let Some(note) = trained.at_the_cap() {
            eprintln!("note: {note}");
        }
        return Ok(());
    }
    let trained = o.run(&dataset, &args.stages.options, &shown.callback())?;
    shown.finish();
    let model = &trained.model;
    save_to(&args.out, "the model", |p| model.save(p))?;
    eprintln!(
        "{} -> {}",
        trained.summary(),
        crate::output::shown(&args.out)
    );
    Ok(())
}
