//! `neurotex simulate`: the paper's rig, simulated into a dataset folder.

use std::path::PathBuf;

use anyhow::Result;
use clap::Args;
use neurotex::sim::{check_design, design, write_dataset, RigParams, Texture, ALL_TEXTURES};
use neurotex::Speed;

use crate::output::{progress, tick};

/// Options of `neurotex simulate`.
#[derive(Args)]
pub struct SimulateArgs {
    /// The dataset folder to create (must not exist, or be empty).
    #[arg(long)]
    pub out: PathBuf,
    /// Seed of every random draw: the same seed gives the same bits.
    #[arg(long, default_value_t = 0)]
    pub seed: u64,
    /// Trials per texture and speed (paper: 20).
    #[arg(long, default_value_t = 20)]
    pub trials: u32,
    /// Sliding speeds in mm/s (paper: 5, 10, 15).
    #[arg(long, value_delimiter = ',', default_value = "5,10,15")]
    pub speeds: Vec<Speed>,
    /// Textures, by the paper's names: FT1, FT2, FT3, RT, TRug, SB, CP, STF (default all).
    #[arg(long, value_delimiter = ',', value_parser = texture)]
    pub textures: Option<Vec<Texture>>,
}

/// A texture by the paper's name, in any case.
pub fn texture(name: &str) -> Result<Texture, String> {
    Texture::from_name(name.trim()).ok_or_else(|| {
        format!("unknown texture `{name}`: expected FT1, FT2, FT3, RT, TRug, SB, CP or STF")
    })
}

/// Runs `neurotex simulate`.
pub fn run(args: SimulateArgs) -> Result<()> {
    let textures = args.textures.unwrap_or_else(|| ALL_TEXTURES.to_vec());
    let speeds: Vec<f64> = args.speeds.iter().map(|s| s.mm_s()).collect();
    let rig = RigParams::default();
    // checked before the trial list is built: --trials 4000000000 would allocate it
    check_design(&rig, &textures, &speeds, args.trials)?;
    let trials = design(&textures, &speeds, args.trials);
    let bar = progress(trials.len(), "simulating");
    let result = write_dataset(&args.out, &rig, &trials, args.seed, &|| tick(&bar));
    bar.finish_and_clear();
    result?;
    eprintln!("{} recordings -> {}", trials.len(), args.out.display());
    Ok(())
}
