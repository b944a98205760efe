//! Options shared by every command that runs the pipeline. Every default is the library's
//! (`PipelineParams::default()` and its parts), so it is written once, there.

use anyhow::Result;
use clap::Args;
use neurotex::calibrate::GainChoice;
use neurotex::classify::KnnParams;
use neurotex::encode::{FaParams, FiringType, IzhikevichParams};
use neurotex::features::{GlcmParams, VolumeParams};
use neurotex::pipeline::{Encoding, FeatureParams, HaralickSet, PipelineParams};
use neurotex::recording::Baseline;
use neurotex::signal::PreprocessParams;

/// Stage parameters; defaults are the paper's values (or SPEC's choice where it gives none).
#[derive(Args, Debug, Clone)]
pub struct StageArgs {
    /// Gain G from normalised signal to Izhikevich input current (paper: 8). `auto` chooses
    /// it on the training recordings (labels unused) so that the median taxel with any
    /// signal fires at 20 Hz during the slide; `auto:HZ` sets another target rate.
    #[arg(long, default_value_t = GainChoice::default(), allow_negative_numbers = true)]
    pub gain: GainChoice,
    /// Izhikevich firing type: RS (slowly adapting, the paper's), IB, CH, FS, LTS, TC, RZ.
    #[arg(long, default_value_t = FiringType::default())]
    pub preset: FiringType,
    /// Low-pass cutoff in Hz (zero-phase 2nd-order Butterworth); 0 turns the filter off.
    #[arg(long, default_value_t = PreprocessParams::default().cutoff_hz, allow_negative_numbers = true)]
    pub cutoff: f64,
    /// Baseline removal: `none`, or `min` (each taxel's minimum). Default: the dataset's layout.toml.
    #[arg(long)]
    pub baseline: Option<Baseline>,
    /// Use the whole recording instead of only its sliding phase.
    #[arg(long)]
    pub whole: bool,
    /// Gray levels for GLCM quantisation.
    #[arg(long, default_value_t = VolumeParams::default().levels)]
    pub levels: usize,
    /// Rate-volume bin and Fano window in ms.
    #[arg(long = "bin-ms", default_value_t = VolumeParams::default().bin_ms)]
    pub bin_ms: usize,
    /// GLCM offset distances, comma-separated.
    #[arg(long, value_delimiter = ',', default_values_t = GlcmParams::default().distances)]
    pub distances: Vec<usize>,
    /// Count co-occurrences in both directions.
    #[arg(long)]
    pub symmetric: bool,
    /// Mechanoreceptor populations: `sa` (slowly adapting, driven by the signal; the
    /// paper's), `fa` (fast adapting, driven by its rectified rate of change) or `sa+fa`
    /// (both, each with its own features, names prefixed `sa_` and `fa_`).
    #[arg(long, default_value_t = Encoding::default())]
    pub encoding: Encoding,
    /// Gain of the FA neurons from rate of change (normalised units per ms) to current;
    /// the default 8000 gives FA neurons about the SA neurons' rate on a typical simulated slide.
    #[arg(long = "fa-gain", default_value_t = FaParams::default().gain)]
    pub fa_gain: f64,
    /// Haralick features of the GLCM methods: `paper` (contrast, correlation, ASM) or
    /// `full` (the 13 of Haralick 1973, as mahotas defines them).
    #[arg(long, default_value_t = HaralickSet::default())]
    pub haralick: HaralickSet,
    /// Rate-volume bin widths in ms of `--method glcm3d-multi`, comma-separated.
    #[arg(
        long = "bin-widths",
        value_delimiter = ',',
        default_values_t = FeatureParams::default().bin_widths_ms
    )]
    pub bin_widths: Vec<usize>,
    /// Fano window of `--method all-taxels-mm`, in mm of travel.
    #[arg(long = "window-mm", default_value_t = FeatureParams::default().window_mm)]
    pub window_mm: f64,
    /// Condition causally, as a live stream can (`neurotex stream`): a forward-only
    /// low-pass, and each taxel's resting value and one normalisation scale fixed on the
    /// training recordings (labels unused) instead of the zero-phase filter and each
    /// recording's own baseline and maximum, which need the whole recording.
    #[arg(long)]
    pub causal: bool,
    /// Do not z-score features with training-fold statistics before KNN.
    #[arg(long = "no-standardize")]
    pub no_standardize: bool,
}

impl StageArgs {
    /// The pipeline parameters these options name, checked.
    pub fn pipeline(&self) -> Result<PipelineParams> {
        let mut p = PipelineParams {
            encoder: self.preset.params().with_gain(match self.gain {
                GainChoice::Fixed(g) => g,
                // Replaced by the calibrated gain before anything is encoded.
                GainChoice::Auto { .. } => IzhikevichParams::default().gain,
            }),
            ..PipelineParams::default()
        };
        p.preprocess.cutoff_hz = self.cutoff;
        p.preprocess.slide_only = !self.whole;
        p.preprocess.baseline = self.baseline;
        p.volume.levels = self.levels;
        p.volume.bin_ms = self.bin_ms;
        p.glcm.distances = self.distances.clone();
        p.glcm.symmetric = self.symmetric;
        p.encoding = self.encoding;
        p.fa.gain = self.fa_gain;
        p.features = FeatureParams {
            haralick: self.haralick,
            bin_widths_ms: self.bin_widths.clone(),
            window_mm: self.window_mm,
        };
        p.check()?;
        Ok(p)
    }

    /// The target rate of `--gain auto`, or `None` for a fixed gain.
    pub fn gain_target(&self) -> Option<f64> {
        match self.gain {
            GainChoice::Auto { target_hz } => Some(target_hz),
            GainChoice::Fixed(_) => None,
        }
    }

    /// KNN parameters with `k` neighbours, checked.
    pub fn knn(&self, k: usize) -> Result<KnnParams> {
        let knn = KnnParams {
            k,
            standardize: !self.no_standardize,
        };
        knn.check()?;
        Ok(knn)
    }
}
