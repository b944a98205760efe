//! `reproduce`: every analysis of the paper (E0-E8), and E5c and E9 beyond it, into a
//! report with figures, on a dataset folder or the built-in simulated rig.

use std::path::{Path, PathBuf};

use super::{calibration_line, KnnOptions, OnProgress, OpenOptions};
use crate::error::OptionsError;
use crate::experiments::{ReproduceParams, Results};
use crate::options::StageOptions;
use crate::progress::Progress;
use crate::recording::Dataset;
use crate::report::reproduce::{reproduce, simulated_design, Data, Run};
use crate::Result;

/// Options of `reproduce`.
#[derive(Debug, Clone)]
#[cfg_attr(feature = "cli", derive(clap::Args))]
pub struct ReproduceOptions {
    /// A dataset folder to run on; without it the built-in simulator generates the paper's
    /// design (8 textures x 5, 10, 15 mm/s x 20 trials) in memory.
    #[cfg_attr(feature = "cli", arg(long))]
    pub dataset: Option<PathBuf>,
    /// Seed of the simulation, the CV shuffles and the perturbations.
    #[cfg_attr(feature = "cli", arg(long, default_value_t = 0))]
    pub seed: u64,
    /// A small run (10 trials per condition when simulating, fewer repeats, gains, fractions).
    #[cfg_attr(feature = "cli", arg(long))]
    pub quick: bool,
    /// Simulated trials per texture and speed (default 20, or 10 with --quick).
    #[cfg_attr(feature = "cli", arg(long))]
    pub trials: Option<u32>,
    /// Independent simulated datasets (simulation seeds seed, seed + 1, ...; default 5, or 1
    /// with --quick). The report shows the first in full and every headline accuracy as its
    /// mean over the datasets with a 95 % interval, and how often each claim held. Only
    /// without --dataset (a dataset folder is one draw).
    #[cfg_attr(feature = "cli", arg(long, conflicts_with = "dataset", value_parser = clap::value_parser!(u64).range(1..=crate::report::reproduce::MAX_SEEDS)))]
    pub seeds: Option<u64>,
    /// KNN's neighbours and z-scoring.
    #[cfg_attr(feature = "cli", command(flatten))]
    pub knn: KnnOptions,
    /// Cross-validation folds of every analysis (stratified, shuffled) [default: 5]. A small
    /// pilot needs fewer: each class needs at least this many recordings at each speed.
    #[cfg_attr(feature = "cli", arg(long))]
    pub folds: Option<usize>,
    /// Cross-validation repeats with different shuffles [default: 10, or 2 with --quick].
    #[cfg_attr(feature = "cli", arg(long))]
    pub repeats: Option<usize>,
    /// Every cross-validation of the analyses keeps each group of this manifest column in
    /// one fold (`trial` for repeats of one run, or a session or subject column); with fewer
    /// groups than folds at a speed, each group is held out in turn.
    #[cfg_attr(feature = "cli", arg(long = "group-by"))]
    pub group_by: Option<String>,
    /// Encodings of every recording behind E1's, E4's, E6's and E8's accuracies: as run, and N - 1 more
    /// with independent rounding-level perturbations of the input (each sample times
    /// 1 + u x 1e-12). Spiking neurons near threshold turn such changes into moved spikes;
    /// the accuracies are means over the encodings and their intervals resample encodings
    /// as well as recordings. 1 evaluates the input as run only.
    #[cfg_attr(feature = "cli", arg(long = "encoder-draws", value_name = "N", default_value_t = crate::experiments::DEFAULT_ENCODER_DRAWS as u64,
          value_parser = clap::value_parser!(u64).range(1..=crate::experiments::MAX_ENCODER_DRAWS as u64)))]
    pub encoder_draws: u64,
    /// E9 also runs the spiking network (`--classifier snn` on the SA+FA spikes, its
    /// default hyperparameters, no selection) beside the paper's method on the same folds,
    /// within each speed and with each speed held out, with intervals, chance and the paired
    /// test. It trains one network per fold, on the first dataset only: on two cores the
    /// paper-scale simulated default takes about 2.5 min instead of 40 s.
    #[cfg_attr(feature = "cli", arg(long))]
    pub snn: bool,
    /// How the dataset folder is opened.
    #[cfg_attr(feature = "cli", command(flatten))]
    pub open: OpenOptions,
}

impl ReproduceOptions {
    /// The analyses' parameters these options and the stage options name (the gain still
    /// to be calibrated with `--gain auto`).
    ///
    /// # Errors
    /// `--causal` (reproduce runs the causal pipeline itself), or a parameter out of range.
    pub fn params(&self, stages: &StageOptions) -> Result<ReproduceParams> {
        let mut params = if self.quick {
            ReproduceParams::quick()
        } else {
            ReproduceParams::default()
        };
        if stages.causal {
            return Err(OptionsError::Conflict("reproduce runs the causal pipeline itself (its causal E5 beside the paper's offline E5); --causal is for train, evaluate, features and compare".into()).into());
        }
        params.pipeline = stages.check()?.to_calibrate().clone();
        params.knn = self.knn.params()?;
        params.seed = self.seed;
        params.cv.seed = self.seed;
        params.cv.folds = self.folds.unwrap_or(params.cv.folds);
        params.cv.repeats = self.repeats.unwrap_or(params.cv.repeats);
        params.group_by = self.group_by.clone();
        params.encoder_draws = usize::try_from(self.encoder_draws).unwrap_or(usize::MAX);
        params.e9_snn = self.snn;
        Ok(params)
    }

    /// Runs every analysis on `dataset` (the simulated rig when `None`) and writes the
    /// report into `out`, naming `command` as what produced it.
    ///
    /// # Errors
    /// Options out of range, a report folder that cannot be written, recordings that
    /// cannot be read.
    pub fn run(
        &self,
        out: &Path,
        dataset: Option<&Dataset>,
        stages: &StageOptions,
        command: String,
        on: OnProgress,
    ) -> Result<Results> {
        let params = self.params(stages)?;
        if dataset.is_some() && (self.trials.is_some() || self.seeds.is_some()) {
            return Err(OptionsError::Conflict("--trials and --seeds apply to the built-in simulator; a dataset folder is one draw of its own size".into()).into());
        }
        let (trials, seeds) = match dataset {
            Some(_) => (0, Vec::new()),
            None => simulated_design(self.quick, self.trials, self.seeds, self.seed)?,
        };
        if let Some(note) = dataset.and_then(|ds| fewer_groups(ds, &params)) {
            on(Progress::Advice(&note));
        }
        let data = match dataset {
            Some(ds) => Data::Folder(ds),
            None => Data::Simulated {
                trials,
                seeds: &seeds,
            },
        };
        let run = Run {
            gain_target: stages.gain.target_hz(),
            command,
            on_progress: on,
            on_gain: &|c| on(Progress::Say(&calibration_line(c))),
        };
        reproduce(out, data, params, &run)
    }
}

/// What `--group-by` makes of `--folds` at the speed with the fewest groups, when fewer
/// than the folds (each group is then held out in turn there), said once.
fn fewer_groups(dataset: &Dataset, params: &ReproduceParams) -> Option<String> {
    let column = params.group_by.as_deref()?;
    let folds = params.cv.folds;
    let entries = &dataset.entries;
    let mut speeds: Vec<String> = entries
        .iter()
        .filter_map(|m| m.field("speed_mm_s"))
        .collect();
    speeds.sort();
    speeds.dedup();
    let (groups, speed) = speeds
        .iter()
        .map(|speed| {
            let rows: Vec<usize> = (0..entries.len())
                .filter(|&i| entries[i].field("speed_mm_s").as_ref() == Some(speed))
                .collect();
            (crate::analysis::group_count(entries, &rows, column), speed)
        })
        .min()?;
    (groups < folds).then(|| format!(
        "--folds {folds} with --group-by {column}: {groups} `{column}` group(s) at {speed} mm/s, so {groups} folds are used there (each group held out in turn)"
    ))
}
