//! `neurotex reproduce`: every analysis of the paper (E0-E8) into a report with figures.

use std::path::PathBuf;
use std::time::Instant;

use anyhow::{Context, Result};
use clap::Args;
use neurotex::experiments::claims;
use neurotex::recording::Dataset;
use neurotex::report::reproduce::write_headline_predictions;
use neurotex::workflows::reproduce::ReproduceOptions;

use crate::output::{check_output, write_file, Shown};
use crate::stage_args::StageArgs;

/// Options of `neurotex reproduce`.
#[derive(Args)]
pub struct ReproduceArgs {
    #[command(flatten)]
    pub options: ReproduceOptions,
    /// Folder for report.md, results.json and figures/.
    #[arg(long, default_value = "report")]
    pub out: PathBuf,
    /// Write the headline 3D-GLCM evaluations' out-of-fold predictions to this CSV file:
    /// `speed_mm_s,method,file,label,predicted,fold,repeat`, one row per recording and CV
    /// repeat at each speed (of the first dataset with --seeds).
    #[arg(long)]
    pub predictions: Option<PathBuf>,
    #[command(flatten)]
    pub stages: StageArgs,
}

/// Runs `neurotex reproduce`.
pub fn run(args: ReproduceArgs) -> Result<()> {
    let started = Instant::now();
    let o = &args.options;
    let dataset = match &o.dataset {
        Some(dir) => Some(o.open.open(dir)?),
        None => None,
    };
    crate::output::check_folder(&args.out, "--out")?;
    let _claim =
        neurotex::report::check_report_dir(&args.out).context("checking the report folder")?;
    if let Some(path) = &args.predictions {
        let inputs = dataset.as_ref().map(Dataset::files).unwrap_or_default();
        check_output(path, &inputs)?;
    }
    let shown = Shown::new("starting");
    let stages = &args.stages.options;
    let results = o.run(
        &args.out,
        dataset.as_ref(),
        stages,
        crate::output::command_line(),
        &shown.callback(),
    )?;
    shown.finish();
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
