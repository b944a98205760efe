//! `neurotex simulate`: the paper's rig, simulated into a dataset folder.

use std::path::PathBuf;

use anyhow::Result;
use clap::Args;
use neurotex::workflows::simulate::SimulateOptions;

use crate::output::{check_folder, Shown};

/// Options of `neurotex simulate`.
#[derive(Args)]
pub struct SimulateArgs {
    /// The dataset folder to create (must not exist, or be empty).
    #[arg(long)]
    pub out: PathBuf,
    #[command(flatten)]
    pub options: SimulateOptions,
}

/// Runs `neurotex simulate`.
pub fn run(args: SimulateArgs) -> Result<()> {
    check_folder(&args.out, "--out")?;
    let shown = Shown::new("simulating");
    let n = args.options.run(&args.out, &shown.callback());
    shown.finish();
    eprintln!("{} recordings -> {}", n?, args.out.display());
    Ok(())
}
