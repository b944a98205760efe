//! `features`: one feature row per recording of a dataset.

use std::path::PathBuf;

use super::{calibrated_pipeline, feature_table, OnProgress, OpenOptions};
use crate::analysis::FeatureTable;
use crate::options::StageOptions;
use crate::pipeline::{Method, Pipeline};
use crate::recording::Dataset;
use crate::Result;

/// Options of `features`.
#[derive(Debug, Clone)]
#[cfg_attr(feature = "cli", derive(clap::Args))]
pub struct FeaturesOptions {
    /// The dataset folder (with `manifest.csv`, optional `layout.toml`).
    #[cfg_attr(feature = "cli", arg(long))]
    pub dataset: PathBuf,
    /// Feature set: `taxel` or `all-taxels` (MSR, CV_ISI, Fano of every taxel),
    /// `all-taxels-mm` (spikes per mm, CV_ISI, Fano over fixed travel), `glcm2d`, `glcm3d`
    /// or `glcm3d-multi` (Haralick features, at each of `--bin-widths` for the last),
    /// `spectrum` (each taxel's spike counts along the slide, their Fourier magnitudes in
    /// logarithmic bands of spatial frequency: `--spectrum-bins`, `--spectrum-bands`,
    /// `--travel-mm`), or `rates` (every taxel's mean spike rate in spikes/s: the counts
    /// without their timing).
    #[cfg_attr(feature = "cli", arg(long))]
    pub method: Method,
    /// How the dataset folder is opened.
    #[cfg_attr(feature = "cli", command(flatten))]
    pub open: OpenOptions,
}

impl FeaturesOptions {
    /// Every recording's features with the stage options `stages`; `--gain auto`
    /// calibrates on all of them (features are computed for every recording).
    ///
    /// # Errors
    /// A parameter out of range, or recordings that cannot be read or encoded.
    pub fn run(
        &self,
        dataset: &Dataset,
        stages: &StageOptions,
        on: OnProgress,
    ) -> Result<FeatureTable> {
        let all: Vec<usize> = (0..dataset.entries.len()).collect();
        let params = calibrated_pipeline(stages, dataset, &all, on)?.params;
        let pipeline = Pipeline::new(params)?;
        Ok(feature_table(dataset, &pipeline, &all, self.method, on)?.0)
    }
}
