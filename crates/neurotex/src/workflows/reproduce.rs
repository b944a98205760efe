//! `reproduce`: every analysis of the paper (E0-E8), and E5c and E9 beyond it, into a
//! report with figures, on a dataset folder or the built-in simulated rig. [`reproduce`] is
//! the workflow as one function (the gain calibrated first under `--gain auto`, the report
//! written); the binary and the Python package both call it, so a report reads the same
//! whichever wrote it.

use std::path::{Path, PathBuf};
use std::time::Instant;

use super::{calibration_line, KnnOptions, OnProgress, OpenOptions};
use crate::calibrate::GainCalibration;
use crate::error::{OptionsError, ParamError};
use crate::experiments::{
    prepare, run_all, run_seeds, ReproduceParams, Results, Source, ValidReproduceParams,
};
use crate::options::StageOptions;
use crate::pipeline::Pipeline;
use crate::progress::Progress;
use crate::recording::Dataset;
use crate::report::{
    check_report_dir, folder_source, simulated_source, write_report, ReportContext,
};
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
    #[cfg_attr(feature = "cli", arg(long, conflicts_with = "dataset", value_parser = clap::value_parser!(u64).range(1..=MAX_SEEDS)))]
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
    /// default hyperparameters, no selection) beside the paper's method and beside its
    /// inputs' spike rates with logistic regression (`--method rates --classifier linear`)
    /// on the same folds, within each speed and with each speed held out, with intervals,
    /// chance and the paired test against the paper's method. It trains one network per
    /// fold, on the first dataset only: on two cores the paper-scale simulated default
    /// takes about 3 min instead of 40 s.
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

/// Most simulated datasets one run makes (each takes seconds; more is a typo).
pub const MAX_SEEDS: u64 = 1000;

/// The built-in simulator's design for a run: `trials` per texture and speed (default 20,
/// or 10 for a quick run) and one simulation seed per dataset, `seed`, `seed + 1`, ...
/// (`seeds` of them; default 5, or 1 for a quick run).
///
/// # Errors
/// Trials outside 1 to [`crate::sim::MAX_TRIALS`], seeds outside 1 to [`MAX_SEEDS`], or
/// seeds that overflow a 64-bit seed.
pub fn simulated_design(
    quick: bool,
    trials: Option<u32>,
    seeds: Option<u64>,
    seed: u64,
) -> std::result::Result<(u32, Vec<u64>), ParamError> {
    // The rules name the limits as literals; these keep them the limits.
    const _: () = assert!(crate::sim::MAX_TRIALS == 10_000 && MAX_SEEDS == 1000);
    let trials = trials.unwrap_or(if quick { 10 } else { 20 });
    if !(1..=crate::sim::MAX_TRIALS).contains(&trials) {
        let rule = "trials must be between 1 and 10000";
        return Err(ParamError::new("trials", rule, trials));
    }
    let n = seeds.unwrap_or(if quick { 1 } else { 5 });
    if !(1..=MAX_SEEDS).contains(&n) {
        return Err(ParamError::new(
            "seeds",
            "seeds must be between 1 and 1000",
            n,
        ));
    }
    let seeds = (0..n)
        .map(|i| seed.checked_add(i))
        .collect::<Option<Vec<u64>>>()
        .ok_or_else(|| ParamError::new("seeds", "seed plus seeds overflows a 64-bit seed", seed))?;
    Ok((trials, seeds))
}

/// Where the analyses' recordings come from.
#[derive(Debug, Clone, Copy)]
pub enum Data<'a> {
    /// A dataset folder, analysed as it is.
    Folder(&'a Dataset),
    /// The built-in simulator's design with `trials` per texture and speed, one dataset
    /// per seed (the first reported in full).
    Simulated {
        /// Trials per texture and speed.
        trials: u32,
        /// One simulation seed per dataset.
        seeds: &'a [u64],
    },
}

/// How a run goes beyond its parameters.
pub struct Run<'a> {
    /// `--gain auto`'s target median rate, Hz: the gain is calibrated on the dataset (or the
    /// first simulated one), labels unused, before anything else.
    pub gain_target: Option<f64>,
    /// The command that produced the report, as the report prints it.
    pub command: String,
    /// Progress of the analyses.
    pub on_progress: &'a (dyn Fn(Progress) + Sync),
    /// Told which gain `--gain auto` chose, once chosen.
    pub on_gain: &'a dyn Fn(&GainCalibration),
}

/// Runs every analysis on `data` with `params` and writes the report into `out` (claimed
/// before any work and replaced as a whole); returns the results.
///
/// # Errors
/// The report folder cannot be claimed; a parameter breaks a rule; a recording cannot be
/// read; an analysis or the report fails.
pub fn reproduce(
    out: &Path,
    data: Data<'_>,
    params: ReproduceParams,
    run: &Run<'_>,
) -> Result<Results> {
    let started = Instant::now();
    let _claim = check_report_dir(out)?;
    let (results, described) = analyse(data, params, run)?;
    let source = match data {
        Data::Folder(ds) => folder_source(&ds.root),
        Data::Simulated { seeds, .. } => simulated_source(seeds),
    };
    let ctx = ReportContext {
        dataset: described,
        source,
        parameters: parameters_described(&results),
        total_seconds: started.elapsed().as_secs_f64(),
        command: run.command.clone(),
        paper_comparable: matches!(data, Data::Simulated { .. }),
    };
    write_report(out, &results, &ctx)?;
    Ok(results)
}

/// Every analysis on the dataset folder, or on the simulated datasets; returns the results
/// and the report's paragraph on the data.
fn analyse(data: Data<'_>, params: ReproduceParams, run: &Run<'_>) -> Result<(Results, String)> {
    Ok(match data {
        Data::Folder(ds) => {
            let source = Source::Dataset(ds);
            let events = ds.is_events();
            let params = match events {
                true => for_events(params, run)?,
                false => params,
            };
            let (params, calibration) = calibrated(params, run, &source)?;
            let prepared = prepare(&source, &params, run.on_progress)?;
            let mut results = run_all(&prepared, &params, run.on_progress)?;
            if events {
                for (id, why) in EVENTS_SKIP {
                    results.skipped.insert(id.into(), why.into());
                }
            }
            results.gain_calibration = calibration;
            (results, source.describe())
        }
        Data::Simulated { trials, seeds } => {
            let simulate = |seed| Source::paper_design(trials, seed);
            let first = simulate(*seeds.first().ok_or(crate::error::DatasetError::Empty)?);
            let (params, calibration) = calibrated(params, run, &first)?;
            let mut results = run_seeds(&simulate, seeds, &params, run.on_progress)?;
            results.gain_calibration = calibration;
            (results, describe_seeds(&first, seeds))
        }
    })
}

/// The analyses an address-event dataset cannot have, and why: its spikes come from the
/// sensor, not from neurotex's encoder.
const EVENTS_SKIP: [(&str, &str); 3] = [
    ("e7", "the recordings are address events, which skip the encoder: there is no gain to sweep"),
    ("e5c", "the recordings are address events, which skip the encoder: there is no signal to condition causally"),
    ("encoder sensitivity", "the recordings are address events, which skip the encoder: there is no input to perturb"),
];

/// The parameters of a run on address events: no gain sweep, causal conditioning or
/// perturbed encodings (see [`EVENTS_SKIP`]).
///
/// # Errors
/// `--gain auto`, which calibrates the encoder.
fn for_events(params: ReproduceParams, run: &Run<'_>) -> Result<ReproduceParams> {
    if run.gain_target.is_some() {
        let why = "--gain auto calibrates the encoder, and address events skip it";
        return Err(crate::error::OptionsError::Conflict(why.into()).into());
    }
    Ok(ReproduceParams {
        e7: false,
        e5_causal: false,
        encoder_draws: 1,
        ..params
    })
}

/// The checked parameters, with the gain calibrated on `first` (the dataset, or the first
/// simulated one) under `--gain auto`.
fn calibrated(
    mut params: ReproduceParams,
    run: &Run<'_>,
    first: &Source,
) -> Result<(ValidReproduceParams, Option<GainCalibration>)> {
    let calibration = match run.gain_target {
        Some(target) => {
            let pipeline = Pipeline::new(params.pipeline.clone())?;
            let c = first.calibrate_gain(&pipeline, target)?;
            (run.on_gain)(&c);
            params.pipeline.encoder.gain = c.gain;
            Some(c)
        }
        None => None,
    };
    Ok((params.check()?, calibration))
}

/// The report's parameter lines: the run's parameters as its provenance lists them (with
/// the dataset's `layout.toml` baseline where the pipeline sets none, and how many
/// recordings have slide times) and, under `--gain auto`, the gain chosen.
fn parameters_described(results: &Results) -> Vec<String> {
    // A run's results always hold their provenance (only results read from files written
    // before it existed lack one).
    let mut lines = (results.provenance.as_ref())
        .map(|p| p.parameters.clone())
        .unwrap_or_default();
    if let Some(c) = &results.gain_calibration {
        let shared = if results.across_seeds.is_some() {
            "; calibrated on the first simulated dataset and used for all"
        } else {
            ""
        };
        lines.push(format!(
            "gain: --gain auto chose G = {} so that the median taxel with signal fires at {} Hz (median {:.1} Hz over {} taxel x recording pairs of {} recordings; labels unused{shared})",
            c.gain, c.target_hz, c.median_hz, c.pairs, c.recordings
        ));
    }
    lines
}

/// The report's data paragraph for a run over simulated datasets: the first dataset's
/// description and, with several, which further seeds were run.
fn describe_seeds(first: &Source, seeds: &[u64]) -> String {
    let mut text = first.describe();
    if let [_, rest @ ..] = seeds {
        if !rest.is_empty() {
            let list: Vec<String> = rest.iter().map(u64::to_string).collect();
            text.push_str(&format!(
                " {} further independent datasets of the same design (seeds {}) were simulated and analysed the same way; the sections below show the first, and \"Across simulated datasets\" gives every headline accuracy over all {}.",
                rest.len(),
                list.join(", "),
                seeds.len()
            ));
        }
    }
    text
}
