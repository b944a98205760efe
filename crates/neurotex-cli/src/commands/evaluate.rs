//! `neurotex evaluate`: KNN on a dataset's features, by cross-validation or by training on
//! some conditions (speeds, trials, sessions: any manifest column) and testing on others;
//! prints accuracy and confusion matrix, and for the single-taxel method which taxels
//! stay silent or saturate.

use std::path::PathBuf;

use anyhow::{bail, Result};
use clap::Args;
use neurotex::workflows::evaluate::EvaluateOptions;

use crate::output::{check_output, is_stdout, Shown};
use crate::stage_args::StageArgs;

/// Options of `neurotex evaluate`.
#[derive(Args)]
pub struct EvaluateArgs {
    #[command(flatten)]
    pub options: EvaluateOptions,
    /// Print one JSON object instead of text.
    #[arg(long)]
    pub json: bool,
    /// Write each recording's out-of-fold prediction to this CSV file (`-`: standard
    /// output, the evaluation then said on standard error):
    /// `file,label,predicted,fold,repeat`, one row per recording and CV repeat (folds and
    /// repeats count from 0; `fold` is `test` with a train/test split). Needs one
    /// classifier: any method but --method taxel without --taxel.
    #[arg(long)]
    pub predictions: Option<PathBuf>,
    #[command(flatten)]
    pub stages: StageArgs,
}

/// Runs `neurotex evaluate`.
pub fn run(args: EvaluateArgs) -> Result<()> {
    let o = &args.options;
    let to_stdout = args.predictions.as_deref().is_some_and(is_stdout);
    if args.json && to_stdout {
        bail!("--predictions - and --json would both write standard output; write the predictions to a file with --json");
    }
    if args.predictions.is_some() {
        o.one_classifier()?;
    }
    let dataset = o.open.open(&o.dataset)?;
    if let Some(path) = &args.predictions {
        check_output(path, &dataset.files())?;
    }
    let shown = Shown::new("starting");
    let evaluated = o.run(&dataset, &args.stages.options, &shown.callback())?;
    shown.finish();
    let evaluation = &evaluated.evaluation;
    if let Some(path) = &args.predictions {
        crate::output::write_file(path, "out-of-fold predictions", |w| {
            evaluation.write_out_of_fold(w)
        })?;
    }
    if args.json {
        println!("{}", serde_json::to_string(&evaluated.json()?)?);
    } else if to_stdout {
        eprint!("{}", evaluation.text());
    } else {
        print!("{}", evaluation.text());
    }
    Ok(())
}
