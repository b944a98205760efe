//! Keyword options into the library's validated parameters, as the CLI's stage options
//! are: the one place where the Python layer parses options (the pipeline's, the
//! classifiers', the feature method).

use neurotex::calibrate::GainChoice;
use neurotex::classify::{
    ChosenClassifier, ClassifierChoice, ForestParams, KnnParams, LinearParams,
};
use neurotex::encode::{FiringType, IzhikevichParams};
use neurotex::pipeline::{Encoding, HaralickSet, Method, PipelineParams};
use neurotex::recording::Baseline;
use pyo3::prelude::*;
use pyo3::types::PyDict;

use crate::errors::{param, raise, Kind};

/// Reads `key` from `options`, or `None` when absent or `None`.
fn get<'py, T: FromPyObjectOwned<'py>>(
    options: &Bound<'py, PyDict>,
    key: &str,
) -> PyResult<Option<T>> {
    match options.get_item(key)? {
        Some(v) if !v.is_none() => v.extract::<T>().map(Some).map_err(|e| {
            let e: PyErr = e.into();
            invalid(key, e)
        }),
        _ => Ok(None),
    }
}

/// A `ParameterError` for option `key`.
fn invalid(key: &str, reason: impl std::fmt::Display) -> PyErr {
    raise(
        Kind::Parameter,
        format!("invalid parameter `{key}`: {reason}"),
    )
}

/// Parses a text option with the library's `FromStr`.
fn parsed<T>(options: &Bound<'_, PyDict>, key: &str) -> PyResult<Option<T>>
where
    T: std::str::FromStr<Err = neurotex::error::ParamError>,
{
    match get::<String>(options, key)? {
        Some(s) => s.parse().map(Some).map_err(param),
        None => Ok(None),
    }
}

/// Refuses keys of `options` that are not in `known`; `what` names the options' owner
/// in the message.
fn only_known(options: &Bound<'_, PyDict>, known: &[&str], what: &str) -> PyResult<()> {
    for key in options.keys() {
        let key: String = key.extract()?;
        if !known.contains(&key.as_str()) {
            return Err(raise(
                Kind::Parameter,
                format!("unknown option `{key}`{what} {}", known.join(", ")),
            ));
        }
    }
    Ok(())
}

/// The stage options: the pipeline's parameters and what is still to be calibrated on
/// the training recordings before they apply (the CLI's `StageArgs`).
#[derive(Debug, Clone)]
pub struct Stages {
    /// The pipeline parameters, checked; under `gain="auto"` the gain is a placeholder
    /// replaced by the calibrated one before anything is encoded.
    pub params: PipelineParams,
    /// A gain given as a number, or `auto` with its target rate.
    pub gain: GainChoice,
    /// Causal conditioning (`--causal`): resting values and a scale fixed on the training
    /// recordings.
    pub causal: bool,
}

impl Stages {
    /// The target rate of `gain="auto"`, or `None` for a gain given as a number.
    pub fn gain_target(&self) -> Option<f64> {
        match self.gain {
            GainChoice::Auto { target_hz } => Some(target_hz),
            GainChoice::Fixed(_) => None,
        }
    }
}

/// The gain option: a number, or `"auto"` / `"auto:HZ"` (the CLI's `--gain`).
fn gain(options: &Bound<'_, PyDict>) -> PyResult<GainChoice> {
    match options.get_item("gain")? {
        None => Ok(GainChoice::Fixed(IzhikevichParams::default().gain)),
        Some(v) if v.is_none() => Ok(GainChoice::Fixed(IzhikevichParams::default().gain)),
        Some(v) => match v.extract::<f64>() {
            Ok(g) => Ok(GainChoice::Fixed(g)),
            Err(_) => match v.extract::<String>() {
                Ok(text) => text.parse().map_err(|e: String| invalid("gain", e)),
                Err(_) => Err(invalid(
                    "gain",
                    format!(
                        "expected a number, `auto` or `auto:HZ`, got {}",
                        v.get_type().name()?
                    ),
                )),
            },
        },
    }
}

/// The stage options (the paper's defaults for the absent ones), checked: `gain` (a
/// number, `"auto"` or `"auto:HZ"`), `causal`, `preset`, `cutoff`, `baseline`, `whole`,
/// `levels`, `bin_ms`, `distances`, `symmetric`, `encoding`, `fa_gain`, `haralick`,
/// `bin_widths`, `window_mm`.
pub fn stages(options: &Bound<'_, PyDict>) -> PyResult<Stages> {
    let known = [
        "gain",
        "causal",
        "preset",
        "cutoff",
        "baseline",
        "whole",
        "levels",
        "bin_ms",
        "distances",
        "symmetric",
        "encoding",
        "fa_gain",
        "haralick",
        "bin_widths",
        "window_mm",
    ];
    only_known(options, &known, "; the options are")?;
    let preset: FiringType = parsed(options, "preset")?.unwrap_or_default();
    let mut p = PipelineParams {
        encoder: preset.params(),
        ..PipelineParams::default()
    };
    let gain = gain(options)?;
    if let GainChoice::Fixed(g) = gain {
        p.encoder = p.encoder.with_gain(g);
    }
    if let Some(c) = get::<f64>(options, "cutoff")? {
        p.preprocess.cutoff_hz = c;
    }
    p.preprocess.baseline = parsed::<Baseline>(options, "baseline")?;
    if let Some(w) = get::<bool>(options, "whole")? {
        p.preprocess.slide_only = !w;
    }
    if let Some(l) = get::<usize>(options, "levels")? {
        p.volume.levels = l;
    }
    if let Some(b) = get::<usize>(options, "bin_ms")? {
        p.volume.bin_ms = b;
    }
    if let Some(d) = get::<Vec<usize>>(options, "distances")? {
        p.glcm.distances = d;
    }
    if let Some(s) = get::<bool>(options, "symmetric")? {
        p.glcm.symmetric = s;
    }
    if let Some(e) = parsed::<Encoding>(options, "encoding")? {
        p.encoding = e;
    }
    if let Some(g) = get::<f64>(options, "fa_gain")? {
        p.fa.gain = g;
    }
    if let Some(h) = parsed::<HaralickSet>(options, "haralick")? {
        p.features.haralick = h;
    }
    if let Some(w) = get::<Vec<usize>>(options, "bin_widths")? {
        p.features.bin_widths_ms = w;
    }
    if let Some(w) = get::<f64>(options, "window_mm")? {
        p.features.window_mm = w;
    }
    p.check().map_err(param)?;
    Ok(Stages {
        params: p,
        gain,
        causal: get::<bool>(options, "causal")?.unwrap_or(false),
    })
}

/// The baseline of the recordings' dataset (its layout's, as the Python layer passes it
/// by name), used when the stage options give none; `None`: no baseline.
pub fn baseline(name: Option<&str>) -> PyResult<Baseline> {
    match name {
        Some(s) => s.parse().map_err(param),
        None => Ok(Baseline::default()),
    }
}

/// A feature method by its CLI name.
pub fn method(name: &str) -> PyResult<Method> {
    name.parse().map_err(param)
}

/// A classifier by name with its knobs, checked, in its validated form (to fit or
/// cross-validate).
pub fn chosen_classifier(kind: &str, options: &Bound<'_, PyDict>) -> PyResult<ChosenClassifier> {
    classifier(kind, options)?.check().map_err(param)
}

/// A classifier by name with its knobs: `k`, `standardize` (KNN); `trees`, `max_depth`,
/// `min_samples_leaf`, `max_features`, `bootstrap`, `seed` or `forest_seed` (forest); `c`,
/// `max_iter`, `tol` (linear). Checked (a model file stores this form).
pub fn classifier(kind: &str, options: &Bound<'_, PyDict>) -> PyResult<ClassifierChoice> {
    // The kind by the library's name, with its defaults.
    let defaults: ClassifierChoice = kind.parse().map_err(param)?;
    let known: &[&str] = match defaults {
        ClassifierChoice::Knn(_) => &["k", "standardize"],
        ClassifierChoice::Forest(_) => &[
            "trees",
            "max_depth",
            "min_samples_leaf",
            "max_features",
            "bootstrap",
            "seed",
            "forest_seed",
        ],
        ClassifierChoice::Linear(_) => &["c", "max_iter", "tol"],
    };
    only_known(
        options,
        known,
        &format!(" for classifier {kind}; its options are"),
    )?;
    let choice = match defaults {
        ClassifierChoice::Knn(d) => ClassifierChoice::Knn(KnnParams {
            k: get(options, "k")?.unwrap_or(d.k),
            standardize: get(options, "standardize")?.unwrap_or(d.standardize),
        }),
        ClassifierChoice::Forest(d) => ClassifierChoice::Forest(ForestParams {
            trees: get(options, "trees")?.unwrap_or(d.trees),
            max_depth: get(options, "max_depth")?.or(d.max_depth),
            min_samples_leaf: get(options, "min_samples_leaf")?.unwrap_or(d.min_samples_leaf),
            max_features: get(options, "max_features")?.or(d.max_features),
            bootstrap: get(options, "bootstrap")?.unwrap_or(d.bootstrap),
            seed: match get(options, "forest_seed")? {
                Some(seed) => seed,
                None => get(options, "seed")?.unwrap_or(d.seed),
            },
        }),
        ClassifierChoice::Linear(d) => ClassifierChoice::Linear(LinearParams {
            c: get(options, "c")?.unwrap_or(d.c),
            max_iter: get(options, "max_iter")?.unwrap_or(d.max_iter),
            tol: get(options, "tol")?.unwrap_or(d.tol),
        }),
    };
    choice.check().map_err(param)?;
    Ok(choice)
}
