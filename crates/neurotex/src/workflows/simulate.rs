//! `simulate`: the paper's rig, simulated into a dataset folder.

use std::path::Path;

use super::OnProgress;
use crate::error::ParamError;
use crate::progress::Progress;
use crate::sim::{check_design, design, write_dataset, RigParams, Texture, ALL_TEXTURES};
use crate::{Result, Speed};

/// Options of `simulate`.
#[derive(Debug, Clone)]
#[cfg_attr(feature = "cli", derive(clap::Args))]
pub struct SimulateOptions {
    /// Seed of every random draw: the same seed gives the same bits.
    #[cfg_attr(feature = "cli", arg(long, default_value_t = 0))]
    pub seed: u64,
    /// Trials per texture and speed (paper: 20).
    #[cfg_attr(feature = "cli", arg(long, default_value_t = 20))]
    pub trials: u32,
    /// Sliding speeds in mm/s (paper: 5, 10, 15).
    #[cfg_attr(
        feature = "cli",
        arg(long, value_delimiter = ',', default_value = "5,10,15")
    )]
    pub speeds: Vec<Speed>,
    /// Textures, by the paper's names: FT1, FT2, FT3, RT, TRug, SB, CP, STF (default all).
    #[cfg_attr(feature = "cli", arg(long, value_delimiter = ',', value_parser = texture))]
    pub textures: Option<Vec<Texture>>,
}

/// A texture by the paper's name, in any case.
///
/// # Errors
/// [`ParamError`] for `textures`: a name that is none of the paper's textures.
pub fn texture(name: &str) -> std::result::Result<Texture, ParamError> {
    Texture::from_name(name.trim()).ok_or_else(|| {
        ParamError::new(
            "textures",
            "a texture is one of the paper's: FT1, FT2, FT3, RT, TRug, SB, CP or STF",
            name,
        )
    })
}

impl SimulateOptions {
    /// Simulates the design into the dataset folder `out`; returns the recordings written.
    ///
    /// # Errors
    /// A design out of range, a folder that cannot be written, or one another run is writing.
    pub fn run(&self, out: &Path, on: OnProgress) -> Result<usize> {
        // Claimed before anything is simulated: a second run into the folder says so at once.
        let _claim = crate::io::claim_folder(out)?;
        let textures = self
            .textures
            .clone()
            .unwrap_or_else(|| ALL_TEXTURES.to_vec());
        let speeds: Vec<f64> = self.speeds.iter().map(|s| s.mm_s()).collect();
        let rig = RigParams::default();
        // checked before the trial list is built: --trials 4000000000 would allocate it
        check_design(&rig, &textures, &speeds, self.trials)?;
        let trials = design(&textures, &speeds, self.trials);
        on(Progress::Stage("simulating", trials.len()));
        write_dataset(out, &rig, &trials, self.seed, &|| on(Progress::Tick))?;
        Ok(trials.len())
    }
}
