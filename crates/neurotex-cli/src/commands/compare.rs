//! `neurotex compare`: every encoding x feature method x classifier on the same splits of a
//! dataset, ranked with 95 % intervals and a paired test against the paper's method
//! (SA encoding, 3D-GLCM, KNN); to find what suits a sensor best.

use std::path::PathBuf;

use anyhow::{Context, Result};
use clap::Args;
use neurotex::report::comparison::{text_lines, write_comparison};
use neurotex::workflows::compare::CompareOptions;

use crate::output::Shown;
use crate::stage_args::StageArgs;

/// Options of `neurotex compare`.
#[derive(Args)]
pub struct CompareArgs {
    #[command(flatten)]
    pub options: CompareOptions,
    /// Print one JSON object instead of text.
    #[arg(long)]
    pub json: bool,
    /// Also write compare.json, compare.md and the figures into this folder.
    #[arg(long)]
    pub out: Option<PathBuf>,
    #[command(flatten)]
    pub stages: StageArgs,
}

/// Runs `neurotex compare`.
pub fn run(args: CompareArgs) -> Result<()> {
    let o = &args.options;
    if let Some(dir) = &args.out {
        crate::output::check_folder(dir, "--out")?;
    }
    let dataset = o.open.open(&o.dataset)?;
    let _claim = match &args.out {
        Some(dir) => {
            Some(neurotex::io::claim_output_dir(dir).context("checking the output folder")?)
        }
        None => None,
    };
    let shown = Shown::new("starting");
    let mut comparison = o.run(&dataset, &args.stages.options, &shown.callback())?;
    let at = 1.min(comparison.provenance.len());
    (comparison.provenance).insert(at, format!("command: {}", crate::output::command_line()));
    shown.finish();
    if let Some(dir) = &args.out {
        write_comparison(dir, &comparison, &o.dataset).context("writing the comparison")?;
        eprintln!("wrote {}", dir.display());
    }
    if args.json {
        println!("{}", serde_json::to_string_pretty(&comparison)?);
    } else {
        for line in text_lines(&comparison) {
            println!("{line}");
        }
    }
    Ok(())
}
