//! `neurotex inspect`: a quick, read-only check of a dataset folder or of raw logs before
//! any analysis, with findings and the options that address them.

use std::path::PathBuf;

use anyhow::{Context, Result};
use clap::Args;
use neurotex::inspect::Severity;
use neurotex::report::inspection::{text_lines, write_inspection};
use neurotex::workflows::inspect::InspectOptions;

use crate::output::Shown;
use crate::stage_args::StageArgs;

/// Options of `neurotex inspect`.
#[derive(Args)]
pub struct InspectArgs {
    #[command(flatten)]
    pub options: InspectOptions,
    /// Also write inspect.md, inspect.json and figures/ (PNG and SVG) into this folder.
    #[arg(long)]
    pub out: Option<PathBuf>,
    /// Print one JSON object instead of text.
    #[arg(long)]
    pub json: bool,
    /// Exit with status 2 when there is a severe finding (for scripts).
    #[arg(long)]
    pub strict: bool,
    #[command(flatten)]
    pub stages: StageArgs,
}

/// Runs `neurotex inspect`; `Ok(false)` when `--strict` found a severe finding.
pub fn run(args: InspectArgs) -> Result<bool> {
    let o = &args.options;
    let _claim = match &args.out {
        Some(dir) => {
            crate::output::check_folder(dir, "--out")?;
            Some(neurotex::io::claim_output_dir(dir).context("checking the output folder")?)
        }
        None => None,
    };
    let shown = Shown::new("inspecting");
    let inspection = o.run(&args.stages.options, args.out.is_some(), &shown.callback());
    shown.finish();
    let inspection = inspection?;
    if let Some(dir) = &args.out {
        write_inspection(dir, &inspection, &o.inputs[0]).context("writing the inspection")?;
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
