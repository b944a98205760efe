//! `reproduce` as one library function: every analysis on a dataset folder or on simulated
//! datasets, the gain calibrated first under `--gain auto`, and the report written. The
//! binary and the Python package both call it, so a report reads the same whichever
//! wrote it.

use std::path::Path;
use std::time::Instant;

use crate::calibrate::GainCalibration;
use crate::error::{ParamError, Result};
use crate::experiments::{
    prepare, run_all, run_seeds, HeadlinePrediction, Progress, ReproduceParams, Results, Source,
    ValidReproduceParams,
};
use crate::pipeline::Pipeline;
use crate::recording::Dataset;

use super::{check_report_dir, folder_source, simulated_source, write_report, ReportContext};

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
    let (results, described, params) = analyse(data, params, run)?;
    let source = match data {
        Data::Folder(ds) => folder_source(&ds.root),
        Data::Simulated { seeds, .. } => simulated_source(seeds),
    };
    let ctx = ReportContext {
        dataset: described,
        source,
        parameters: parameters_described(&params, &results),
        total_seconds: started.elapsed().as_secs_f64(),
        command: run.command.clone(),
        paper_comparable: matches!(data, Data::Simulated { .. }),
    };
    write_report(out, &results, &ctx)?;
    Ok(results)
}

/// Every analysis on the dataset folder, or on the simulated datasets; returns the results,
/// the report's paragraph on the data and the parameters run with.
fn analyse(
    data: Data<'_>,
    params: ReproduceParams,
    run: &Run<'_>,
) -> Result<(Results, String, ValidReproduceParams)> {
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
            (results, source.describe(), params)
        }
        Data::Simulated { trials, seeds } => {
            let simulate = |seed| Source::paper_design(trials, seed);
            let first = simulate(*seeds.first().ok_or(crate::error::DatasetError::Empty)?);
            let (params, calibration) = calibrated(params, run, &first)?;
            let mut results = run_seeds(&simulate, seeds, &params, run.on_progress)?;
            results.gain_calibration = calibration;
            (results, describe_seeds(&first, seeds), params)
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

/// The report's parameter lines: the run's parameters and, under `--gain auto`, the gain
/// chosen.
fn parameters_described(params: &ValidReproduceParams, results: &Results) -> Vec<String> {
    let mut lines = params.describe();
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

/// Writes the headline predictions as CSV, `speed_mm_s,method,file,label,predicted,fold,
/// repeat`, one row per prediction (`fold` is `test` for a train/test split).
///
/// # Errors
/// Writing fails.
pub fn write_headline_predictions(
    w: &mut dyn std::io::Write,
    predictions: &[HeadlinePrediction],
) -> std::io::Result<()> {
    let mut out = csv::Writer::from_writer(w);
    let header = [
        "speed_mm_s",
        "method",
        "file",
        "label",
        "predicted",
        "fold",
        "repeat",
    ];
    out.write_record(header)?;
    for p in predictions {
        let fold = p.fold.map_or("test".to_string(), |f| f.to_string());
        out.write_record([
            p.speed.to_string().as_str(),
            p.method,
            &p.file,
            &p.label,
            &p.predicted,
            &fold,
            &p.repeat.to_string(),
        ])?;
    }
    out.flush()
}
