//! `neurotex reproduce` from Python: every analysis of the paper (E0-E9) on the built-in
//! simulator or on a dataset folder, the report written as the CLI writes it, and the
//! results handed back.

use std::path::PathBuf;
use std::sync::Mutex;
use std::time::Instant;

use neurotex::experiments::{claims, HeadlinePrediction, DEFAULT_ENCODER_DRAWS, WITHIN_SPEED};
use neurotex::options::StageOptions;
use neurotex::progress::Progress;
use neurotex::recording::Dataset;
use neurotex::workflows::reproduce::ReproduceOptions;
use neurotex::workflows::{KnnOptions, OpenOptions};
use pyo3::prelude::*;
use pyo3::types::PyDict;

use crate::convert::{open, to_object};
use crate::errors::guarded;
use crate::params;

/// One headline out-of-fold prediction: `(speed_mm_s, method, file, label, predicted,
/// fold or None for a held-out test set, repeat)`, the CLI's `--predictions` row.
type PredictionRow = (f64, String, String, String, String, Option<usize>, usize);

/// What a run hands back: `results.json` and the claims as dicts and lists, the headline
/// predictions and the run's wall-clock seconds.
type Outcome = (Py<PyAny>, Py<PyAny>, Vec<PredictionRow>, f64);

/// A run's results as the detached run hands them over: `results.json`'s and the claims'
/// values, the headline predictions, the wall-clock seconds, and what the CLI says as a
/// `warning:` (to be raised as Python warnings once the run is back under the GIL).
type Finished = (
    serde_json::Value,
    serde_json::Value,
    Vec<PredictionRow>,
    f64,
    Vec<String>,
);

/// Runs every analysis as `neurotex reproduce` does with the same options, writes
/// `report.md`, `results.json` and `figures/` into `out` (whole or not at all) and returns
/// the results. The GIL is released for the whole run.
#[pyfunction]
#[pyo3(signature = (out, options, dataset=None, quick=false, seed=0, trials=None, seeds=None, k=5, standardize=true, group_by=None, encoder_draws=None, command=String::new(), folds=None, repeats=None, snn=false))]
#[allow(clippy::too_many_arguments)]
fn reproduce(
    py: Python<'_>,
    out: PathBuf,
    options: &Bound<'_, PyDict>,
    dataset: Option<PathBuf>,
    quick: bool,
    seed: u64,
    trials: Option<u32>,
    seeds: Option<u64>,
    k: usize,
    standardize: bool,
    group_by: Option<String>,
    encoder_draws: Option<usize>,
    command: String,
    folds: Option<usize>,
    repeats: Option<usize>,
    snn: bool,
) -> PyResult<Outcome> {
    let stages = params::stage_options(options)?;
    let reproduce = ReproduceOptions {
        dataset: None,
        seed,
        quick,
        trials,
        seeds,
        knn: KnnOptions {
            k,
            no_standardize: !standardize,
        },
        folds,
        repeats,
        group_by,
        encoder_draws: encoder_draws.map_or(DEFAULT_ENCODER_DRAWS as u64, |n| n as u64),
        snn,
        open: OpenOptions::default(),
    };
    let dataset = dataset.map(|dir| open(&dir)).transpose()?;
    let (results, claims, predictions, seconds, warnings) = crate::interrupt::watched(py, || {
        guarded(|| run(&out, dataset.as_ref(), &stages, &reproduce, command))
    })?;
    let warn = PyModule::import(py, "warnings")?;
    for text in warnings {
        warn.call_method1("warn", (text,))?;
    }
    Ok((
        to_object(py, &results)?,
        to_object(py, &claims)?,
        predictions,
        seconds,
    ))
}

/// Runs the library's `reproduce` workflow (the report written as the CLI writes it) and
/// hands back the results and claims as JSON values, the headline predictions and the
/// seconds taken.
fn run(
    out: &std::path::Path,
    dataset: Option<&Dataset>,
    stages: &StageOptions,
    reproduce: &ReproduceOptions,
    command: String,
) -> neurotex::Result<Finished> {
    let started = Instant::now();
    let warnings = Mutex::new(Vec::new());
    let say = |text: String| warnings.lock().expect("warnings").push(text);
    let on_progress = |p: Progress| {
        // A Ctrl-C during the call ends the run here ([`crate::interrupt`]).
        neurotex::progress::stop_point();
        match p {
            Progress::TooSmall(e) => {
                say(format!(
                    "{WITHIN_SPEED}, which cannot run: {e}; they are skipped"
                ));
            }
            Progress::Advice(text) => say(text.to_string()),
            _ => (),
        }
    };
    let results = reproduce.run(out, dataset, stages, command, &on_progress)?;
    let json = |what: &str, value: serde_json::Result<serde_json::Value>| {
        value.map_err(|e| neurotex::error::DataError::invalid(out.join(what), e.to_string()))
    };
    let results_json = json("results.json", serde_json::to_value(&results))?;
    let claims_json = json("claims", serde_json::to_value(claims(&results)))?;
    let predictions = results.predictions.iter().map(prediction_row).collect();
    Ok((
        results_json,
        claims_json,
        predictions,
        started.elapsed().as_secs_f64(),
        warnings.into_inner().expect("warnings"),
    ))
}

fn prediction_row(p: &HeadlinePrediction) -> PredictionRow {
    (
        p.speed.mm_s(),
        p.method.to_string(),
        p.file.clone(),
        p.label.clone(),
        p.predicted.clone(),
        p.fold,
        p.repeat,
    )
}

/// Registers `reproduce`.
pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(reproduce, m)?)
}
