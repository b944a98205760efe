//! Keyword options into the library's validated parameters, as the CLI's stage options are.

use neurotex::classify::{ClassifierChoice, ForestParams, KnnParams, LinearParams};
use neurotex::encode::FiringType;
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
            raise(Kind::Parameter, format!("invalid parameter `{key}`: {e}"))
        }),
        _ => Ok(None),
    }
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

/// The pipeline parameters the options name (the paper's defaults for the absent ones),
/// checked: `gain`, `preset`, `cutoff`, `baseline`, `whole`, `levels`, `bin_ms`,
/// `distances`, `symmetric`, `encoding`, `fa_gain`, `haralick`, `bin_widths`, `window_mm`.
pub fn pipeline(options: &Bound<'_, PyDict>) -> PyResult<PipelineParams> {
    let known = [
        "gain",
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
    for key in options.keys() {
        let key: String = key.extract()?;
        if !known.contains(&key.as_str()) {
            return Err(raise(
                Kind::Parameter,
                format!(
                    "unknown option `{key}`; the options are {}",
                    known.join(", ")
                ),
            ));
        }
    }
    let preset: FiringType = parsed(options, "preset")?.unwrap_or_default();
    let mut p = PipelineParams {
        encoder: preset.params(),
        ..PipelineParams::default()
    };
    if let Some(g) = get::<f64>(options, "gain")? {
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
    Ok(p)
}

/// A feature method by its CLI name.
pub fn method(name: &str) -> PyResult<Method> {
    name.parse().map_err(param)
}

/// A classifier by name with its knobs: `k`, `standardize` (KNN); `trees`, `max_depth`,
/// `min_samples_leaf`, `max_features`, `bootstrap`, `seed` or `forest_seed` (forest); `c`, `max_iter`, `tol`
/// (linear). Checked.
pub fn classifier(kind: &str, options: &Bound<'_, PyDict>) -> PyResult<ClassifierChoice> {
    let known: &[&str] = match kind {
        "knn" => &["k", "standardize"],
        "forest" => &[
            "trees",
            "max_depth",
            "min_samples_leaf",
            "max_features",
            "bootstrap",
            "seed",
            "forest_seed",
        ],
        "linear" => &["c", "max_iter", "tol"],
        _ => &[],
    };
    for key in options.keys() {
        let key: String = key.extract()?;
        if !known.contains(&key.as_str()) {
            return Err(raise(
                Kind::Parameter,
                format!(
                    "unknown option `{key}` for classifier {kind}; its options are {}",
                    known.join(", ")
                ),
            ));
        }
    }
    let choice = match kind {
        "knn" => {
            let d = KnnParams::default();
            ClassifierChoice::Knn(KnnParams {
                k: get(options, "k")?.unwrap_or(d.k),
                standardize: get(options, "standardize")?.unwrap_or(d.standardize),
            })
        }
        "forest" => {
            let d = ForestParams::default();
            ClassifierChoice::Forest(ForestParams {
                trees: get(options, "trees")?.unwrap_or(d.trees),
                max_depth: get(options, "max_depth")?.or(d.max_depth),
                min_samples_leaf: get(options, "min_samples_leaf")?.unwrap_or(d.min_samples_leaf),
                max_features: get(options, "max_features")?.or(d.max_features),
                bootstrap: get(options, "bootstrap")?.unwrap_or(d.bootstrap),
                seed: match get(options, "forest_seed")? {
                    Some(seed) => seed,
                    None => get(options, "seed")?.unwrap_or(d.seed),
                },
            })
        }
        "linear" => {
            let d = LinearParams::default();
            ClassifierChoice::Linear(LinearParams {
                c: get(options, "c")?.unwrap_or(d.c),
                max_iter: get(options, "max_iter")?.unwrap_or(d.max_iter),
                tol: get(options, "tol")?.unwrap_or(d.tol),
            })
        }
        other => return Err(param(other.parse::<ClassifierChoice>().unwrap_err())),
    };
    choice.check().map_err(param)?;
    Ok(choice)
}
