//! `neurotex inspect`: a quick, read-only check of a dataset folder or of raw logs before
//! any analysis, with findings and the options that address them.

use std::path::PathBuf;

use anyhow::{Context, Result};
use clap::Args;
use neurotex::inspect::{inspect, InspectParams, Opened, Severity};
use neurotex::report::inspection::{text_lines, write_inspection};

use crate::csv_args::LogArgs;
use crate::open_args::OpenArgs;
use crate::output::{progress, tick};
use crate::stage_args::StageArgs;

/// Options of `neurotex inspect`.
#[derive(Args)]
pub struct InspectArgs {
    /// A dataset folder (with `manifest.csv`), or raw CSV logs: files, or folders whose
    /// .csv files are all read, with the options `import csv` would be given.
    #[arg(required = true)]
    pub inputs: Vec<PathBuf>,
    /// Also write inspect.md, inspect.json and figures/ (PNG and SVG) into this folder.
    #[arg(long)]
    pub out: Option<PathBuf>,
    /// Print one JSON object instead of text.
    #[arg(long)]
    pub json: bool,
    /// Skip the encoder's check (the firing rates at the gain, and the gain `--gain auto`
    /// would choose): only the design, layout and signals.
    #[arg(long = "no-encoder")]
    pub no_encoder: bool,
    /// Cross-validation folds the design is judged for.
    #[arg(long, default_value_t = neurotex::classify::CvParams::default().folds)]
    pub folds: usize,
    /// KNN's neighbours the design is judged for.
    #[arg(long, default_value_t = neurotex::classify::KnnParams::default().k)]
    pub k: usize,
    /// Exit with status 2 when there is a severe finding (for scripts).
    #[arg(long)]
    pub strict: bool,
    #[command(flatten)]
    pub logs: LogArgs,
    #[command(flatten)]
    pub stages: StageArgs,
    #[command(flatten)]
    pub open: OpenArgs,
}

/// Runs `neurotex inspect`; `Ok(false)` when `--strict` found a severe finding.
pub fn run(args: InspectArgs) -> Result<bool> {
    let params = InspectParams {
        pipeline: args.stages.pipeline()?,
        encoder: !args.no_encoder,
        folds: args.folds,
        k: args.k,
        gain_target: args.stages.gain_target(),
        traces: args.out.is_some(),
    };
    let _claim = match &args.out {
        Some(dir) => {
            Some(neurotex::io::claim_output_dir(dir).context("checking the output folder")?)
        }
        None => None,
    };
    let opened = Opened::open(
        &args.inputs,
        args.logs.params(),
        args.logs.any(),
        args.open.allow_outside_paths,
    )?;
    let n = opened.len();
    let bar = progress(n, "inspecting");
    let inspection = inspect(opened.source(), &params, &|| tick(&bar));
    bar.finish_and_clear();
    let inspection = inspection?;
    if let Some(dir) = &args.out {
        write_inspection(dir, &inspection, &args.inputs[0]).context("writing the inspection")?;
        eprintln!("wrote {}", dir.join("inspect.md").display());
    }
    if args.json {
        println!("{}", serde_json::to_string_pretty(&inspection)?);
    } else {
        for line in text_lines(&inspection) {
            println!("{line}");
        }
    }
    let severe = inspection.at_least(Severity::Severe).count();
    Ok(!(args.strict && severe > 0))
}
