//! The subcommands, one module each: every one parses its options into the library's typed
//! values and parameters, runs the library, and writes or prints the result.

pub mod compare;
pub mod encode;
pub mod evaluate;
pub mod features;
pub mod import;
pub mod inspect;
pub mod predict;
pub mod reproduce;
pub mod simulate;
pub mod stream;
pub mod train;

use anyhow::Result;
use neurotex::analysis::FeatureTable;
use neurotex::calibrate::{calibrate_pipeline, CalibratedParams, GainCalibration};
use neurotex::pipeline::{shared_grid, Encoded, Method, Pipeline};
use neurotex::recording::Dataset;
use neurotex::{Grid, Speed};

use crate::output::{progress, tick};
use crate::stage_args::StageArgs;

/// Encodes the dataset's recordings at `speeds` (all when `None`) with a progress bar and
/// extracts `method`'s features; also returns the grid the recordings share.
fn feature_table(
    dataset: &Dataset,
    pipeline: &Pipeline,
    speeds: Option<&[Speed]>,
    method: Method,
) -> Result<(FeatureTable, Grid)> {
    let indices = match speeds {
        Some(speeds) => dataset.indices_at(speeds)?,
        None => (0..dataset.entries.len()).collect(),
    };
    let (encoded, grid) = encode_all(dataset, pipeline, &indices)?;
    let extractor = pipeline.extractor(&grid)?;
    Ok((FeatureTable::build(&encoded, &extractor, method)?, grid))
}

/// Encodes the dataset's recordings `indices` with a progress bar, saying what the
/// conditioning noticed; also returns the grid the recordings share.
fn encode_all(
    dataset: &Dataset,
    pipeline: &Pipeline,
    indices: &[usize],
) -> Result<(Vec<Encoded>, Grid)> {
    let bar = progress(indices.len(), "encoding");
    let encoded = pipeline.encode_dataset(dataset, indices, &|| tick(&bar));
    bar.finish_and_clear();
    let encoded = encoded?;
    report_conditions(&encoded);
    let grid = shared_grid(&encoded)?;
    Ok((encoded, grid))
}

/// The pipeline the options name, after saying the dataset's severe findings on its signals
/// and layout ([`neurotex::inspect::severe_findings`]); with `--causal`, its resting values and scale fixed on
/// `dataset`'s recordings `indices` (the training recordings: never a test one); with
/// `--gain auto`, its gain calibrated on them too ([`calibrate_pipeline`]). Each choice is
/// said on standard error.
fn calibrated_pipeline(
    stages: &StageArgs,
    dataset: &Dataset,
    indices: &[usize],
) -> Result<CalibratedParams> {
    for finding in neurotex::inspect::severe_findings(dataset, &stages.pipeline()?)? {
        eprintln!("warning: {} (neurotex inspect says more)", finding.line());
    }
    let baseline = dataset.layout.baseline.unwrap_or_default();
    let load = |i: usize| dataset.load(i);
    let (causal, gain) = (stages.options.causal, stages.options.gain);
    let calibrated =
        calibrate_pipeline(stages.pipeline()?, causal, gain, &load, indices, baseline)?;
    if let Some(c) = &calibrated.causal {
        eprintln!(
            "--causal: forward-only filter; resting values and scale {:.6} fixed on {} training recording(s) (median selected phase {} ms)",
            c.conditioning.scale, c.recordings, c.median_duration_ms
        );
    }
    if let Some(c) = &calibrated.gain {
        say_calibration(c);
    }
    Ok(calibrated)
}

/// Says on standard error which gain `--gain auto` chose.
fn say_calibration(c: &GainCalibration) {
    let reached = if c.clamped {
        " (target out of reach: the end of the searched range)"
    } else {
        ""
    };
    eprintln!(
        "--gain auto: G = {} gives a median of {:.1} Hz (target {} Hz) over {} taxel x recording pairs with signal in {} training recording(s){reached}",
        c.gain, c.median_hz, c.target_hz, c.pairs, c.recordings
    );
}

/// Says on standard error what conditioning did that the user should know.
fn report_conditions(encoded: &[Encoded]) {
    let resampled = encoded.iter().filter(|e| e.resampled).count();
    if resampled > 0 {
        eprintln!("note: {resampled} recording(s) resampled to the encoder's 1 kHz by linear interpolation");
    }
    for e in encoded.iter().filter(|e| e.flat) {
        eprintln!(
            "warning: {}: no positive signal in the selected phase; left at zero (no spikes)",
            e.meta.file
        );
    }
}
