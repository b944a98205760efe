//! The stages joined: a recording becomes spike trains, spike trains become a feature row.
//! Every stage is planned once (filter, GLCM offsets) and applied to many recordings,
//! in parallel across recordings.

use rayon::prelude::*;
use serde::{Deserialize, Serialize};

use crate::encode::{encode, IzhikevichParams, SpikeTrains};
use crate::error::{DataError, ParamError, Result};
use crate::features::glcm::GlcmKind;
use crate::features::{haralick, spike_stats, CountVolume, GlcmParams, GlcmPlan, VolumeParams};
use crate::recording::{Baseline, Dataset, Meta, Recording};
use crate::signal::{Conditioned, PreprocessParams, Preprocessor};
use crate::values::Grid;

/// The feature sets the paper compares.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Method {
    /// MSR, CV_ISI and Fano factor of each taxel (approach 1).
    Taxel,
    /// Contrast, correlation, ASM of the time-collapsed image's GLCM (the paper's control).
    Glcm2d,
    /// Contrast, correlation, ASM of the rate volume's mean 3D GLCM (approach 2).
    Glcm3d,
}

impl Method {
    /// The command-line name.
    pub fn name(self) -> &'static str {
        match self {
            Method::Taxel => "taxel",
            Method::Glcm2d => "glcm2d",
            Method::Glcm3d => "glcm3d",
        }
    }
}

impl std::str::FromStr for Method {
    type Err = ParamError;
    fn from_str(s: &str) -> Result<Self, ParamError> {
        match s {
            "taxel" => Ok(Method::Taxel),
            "glcm2d" => Ok(Method::Glcm2d),
            "glcm3d" => Ok(Method::Glcm3d),
            _ => Err(ParamError::new(
                "method",
                "method must be taxel, glcm2d or glcm3d",
                s,
            )),
        }
    }
}

/// All stage parameters, each with the paper's value (or SPEC's choice) as default.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
pub struct PipelineParams {
    /// Conditioning.
    pub preprocess: PreprocessParams,
    /// Neuron model and gain.
    pub encoder: IzhikevichParams,
    /// Rate volume bins (also the Fano window) and quantisation.
    pub volume: VolumeParams,
    /// Co-occurrence offsets.
    pub glcm: GlcmParams,
}

impl PipelineParams {
    /// Checks every stage's rules.
    ///
    /// # Errors
    /// The first rule broken.
    pub fn check(&self) -> Result<(), ParamError> {
        self.preprocess.check()?;
        self.encoder.check()?;
        self.volume.check()?;
        self.glcm.check()
    }
}

/// One recording's spikes with what the conditioning noticed.
#[derive(Debug, Clone, PartialEq)]
pub struct Encoded {
    /// The recording's manifest fields.
    pub meta: Meta,
    /// Spike trains over the selected phase.
    pub spikes: SpikeTrains,
    /// The input was resampled to 1 kHz.
    pub resampled: bool,
    /// The recording had no positive signal and was left at zero.
    pub flat: bool,
}

/// The planned pipeline.
#[derive(Debug, Clone)]
pub struct Pipeline {
    params: PipelineParams,
    preprocessor: Preprocessor,
}

impl Pipeline {
    /// Checks the parameters and plans the stages.
    ///
    /// # Errors
    /// A broken parameter rule.
    pub fn new(params: PipelineParams) -> Result<Self, ParamError> {
        params.check()?;
        let preprocessor = Preprocessor::new(&params.preprocess)?;
        Ok(Pipeline {
            params,
            preprocessor,
        })
    }

    /// The parameters.
    pub fn params(&self) -> &PipelineParams {
        &self.params
    }

    /// Conditions one recording (sliding phase, 1 kHz, baseline, low-pass, normalised),
    /// checking it lasts at least one bin.
    ///
    /// # Errors
    /// An empty sliding phase or a selected phase shorter than one bin.
    pub fn condition(&self, rec: &Recording, dataset_baseline: Baseline) -> Result<Conditioned> {
        let cond = self.preprocessor.apply(rec, dataset_baseline)?;
        let bin = self.params.volume.bin_ms;
        if cond.n_steps() < bin {
            return Err(DataError::invalid(
                &rec.meta.file,
                format!(
                    "the selected phase lasts {} ms, shorter than one {bin} ms bin",
                    cond.n_steps()
                ),
            )
            .into());
        }
        Ok(cond)
    }

    /// Encodes a conditioned recording with the pipeline's neurons, or with `gain` instead
    /// of the pipeline's gain.
    ///
    /// # Errors
    /// A gain that breaks the encoder's rules.
    pub fn encode_conditioned(
        &self,
        rec: &Recording,
        cond: &Conditioned,
        gain: Option<f64>,
    ) -> Result<SpikeTrains> {
        let l = &rec.layout;
        let params = match gain {
            Some(g) => self.params.encoder.with_gain(g),
            None => self.params.encoder,
        };
        Ok(encode(&cond.samples, l.rows, l.cols, &l.present, params)?)
    }

    /// Conditions and encodes one recording.
    ///
    /// # Errors
    /// An empty sliding phase or a selected phase shorter than one bin.
    pub fn encode(&self, rec: &Recording, dataset_baseline: Baseline) -> Result<Encoded> {
        let cond = self.condition(rec, dataset_baseline)?;
        let spikes = self.encode_conditioned(rec, &cond, None)?;
        Ok(Encoded {
            meta: rec.meta.clone(),
            spikes,
            resampled: cond.resampled,
            flat: cond.flat,
        })
    }

    /// Loads and encodes the dataset's recordings `indices` in parallel, calling
    /// `on_done` once per finished recording (for a progress bar). The output keeps the
    /// order of `indices`; a dataset's raw samples are never all in memory at once.
    ///
    /// # Errors
    /// The first failing recording's error.
    pub fn encode_dataset(
        &self,
        dataset: &Dataset,
        indices: &[usize],
        on_done: &(dyn Fn() + Sync),
    ) -> Result<Vec<Encoded>> {
        let baseline = dataset.layout.baseline.unwrap_or_default();
        indices
            .par_iter()
            .map(|&i| {
                let rec = dataset.load(i)?;
                let out = self.encode(&rec, baseline);
                on_done();
                out
            })
            .collect()
    }

    /// A feature extractor for trains of this grid.
    ///
    /// # Errors
    /// A broken parameter rule.
    pub fn extractor(&self, grid: &Grid) -> Result<FeatureExtractor, ParamError> {
        FeatureExtractor::new(&self.params, grid)
    }
}

/// Turns spike trains into feature rows, with the GLCM offsets planned once for a grid.
#[derive(Debug, Clone)]
pub struct FeatureExtractor {
    volume: VolumeParams,
    glcm: GlcmParams,
    grid: Grid,
    plan3d: GlcmPlan,
    plan2d: GlcmPlan,
}

impl FeatureExtractor {
    /// Plans the extractor for `grid`.
    ///
    /// # Errors
    /// A broken parameter rule.
    pub fn new(params: &PipelineParams, grid: &Grid) -> Result<Self, ParamError> {
        params.volume.check()?;
        let levels = params.volume.levels;
        let (rows, cols, present) = (grid.rows(), grid.cols(), grid.present());
        Ok(FeatureExtractor {
            volume: params.volume.clone(),
            glcm: params.glcm.clone(),
            grid: grid.clone(),
            plan3d: GlcmPlan::new(rows, cols, present, levels, &params.glcm, GlcmKind::ThreeD)?,
            plan2d: GlcmPlan::new(rows, cols, present, levels, &params.glcm, GlcmKind::TwoD)?,
        })
    }

    /// The grid the extractor was planned for.
    pub fn grid(&self) -> &Grid {
        &self.grid
    }

    /// Column names of `method`'s features for this grid.
    pub fn names(&self, method: Method) -> Vec<String> {
        match method {
            Method::Taxel => self
                .grid
                .taxels()
                .flat_map(|cell| {
                    let cell = self.grid.cell(cell);
                    ["msr", "cv_isi", "fano"].map(|f| format!("{cell}_{f}"))
                })
                .collect(),
            Method::Glcm2d | Method::Glcm3d => ["contrast", "correlation", "asm"]
                .map(String::from)
                .to_vec(),
        }
    }

    /// The feature row of one recording's spike trains.
    ///
    /// # Errors
    /// The trains are shorter than one bin.
    pub fn row(&self, spikes: &SpikeTrains, method: Method) -> Result<Vec<f64>> {
        let bin = self.volume.bin_ms;
        let too_short = || -> crate::Error {
            DataError::TooShort {
                n_ms: spikes.n_steps,
                bin_ms: bin,
            }
            .into()
        };
        if spikes.n_steps < bin {
            return Err(too_short());
        }
        match method {
            Method::Taxel => Ok(taxel_cells(&spikes.present)
                .flat_map(|cell| spike_stats(spikes.train(cell), spikes.n_steps, bin).to_array())
                .collect()),
            Method::Glcm2d | Method::Glcm3d => {
                let volume = if method == Method::Glcm3d {
                    CountVolume::from_spikes(spikes, bin)
                } else {
                    CountVolume::collapsed(spikes)
                }
                .ok_or_else(too_short)?;
                let same_grid = (spikes.rows, spikes.cols) == (self.grid.rows(), self.grid.cols())
                    && spikes.present == self.grid.present();
                let kind = if method == Method::Glcm3d {
                    GlcmKind::ThreeD
                } else {
                    GlcmKind::TwoD
                };
                let replanned;
                let plan = match (same_grid, kind) {
                    (true, GlcmKind::ThreeD) => &self.plan3d,
                    (true, GlcmKind::TwoD) => &self.plan2d,
                    (false, _) => {
                        replanned = GlcmPlan::new(
                            spikes.rows,
                            spikes.cols,
                            &spikes.present,
                            self.volume.levels,
                            &self.glcm,
                            kind,
                        )?;
                        &replanned
                    }
                };
                if !plan.counts_fit_wide(volume.bins) {
                    return Err(DataError::TooLarge {
                        what: "the time bins of this recording's rate volume",
                        got: volume.bins as u64,
                        limit: crate::features::glcm::MAX_SLICE_PAIRS,
                        hint: "use a shorter recording or a wider --bin-ms",
                    }
                    .into());
                }
                let mut q = Vec::new();
                volume.quantise(self.volume.levels, self.volume.range, &mut q);
                let l = self.volume.levels;
                // u64 counts: a long volume with many distances passes u32's 4.3 billion
                // pairs; below it the u32 kernels count and the result is widened.
                let mut counts = vec![0u64; l * l];
                plan.count_wide(&q, volume.bins, &mut counts);
                Ok(haralick(&counts, l).to_array().to_vec())
            }
        }
    }
}

/// Row-major indices of the cells holding a taxel.
pub fn taxel_cells(present: &[bool]) -> impl Iterator<Item = usize> + '_ {
    present
        .iter()
        .enumerate()
        .filter(|(_, &p)| p)
        .map(|(i, _)| i)
}
