//! Keyword options into the library's validated parameters, as the CLI's stage options
//! are: the one place where the Python layer parses options (the pipeline's, the
//! classifiers', the feature method).

use neurotex::classify::{
    ChosenClassifier, ClassifierChoice, ForestParams, KnnParams, LinearParams,
};
use neurotex::options::{CheckedStages, OptionKind, OptionSpec, StageOptions, STAGE_OPTIONS};
use neurotex::pipeline::Method;
use neurotex::recording::Baseline;
use neurotex::snn::{Reset, SnnParams, Target};
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

/// The stage options checked (the library's [`CheckedStages`]): the pipeline's
/// parameters and what is still to be calibrated on the training recordings.
pub type Stages = CheckedStages;

/// A Python value as the text the library's option parser reads: `True` as `true`, a
/// sequence of counts as `1,2`, a number or a name as it is written.
fn option_text(spec: &OptionSpec, value: &Bound<'_, PyAny>) -> PyResult<String> {
    let text = match spec.kind {
        OptionKind::Flag => value.extract::<bool>().map(|b| b.to_string()),
        OptionKind::Count => value.extract::<usize>().map(|n| n.to_string()),
        OptionKind::Counts => value.extract::<Vec<usize>>().map(|v| {
            let v: Vec<String> = v.iter().map(usize::to_string).collect();
            v.join(",")
        }),
        OptionKind::Number => value.extract::<f64>().map(|x| x.to_string()),
        // A number (the gain) or a name; anything else as Python prints it, for the
        // option's own parser to say what it expects.
        OptionKind::Text => match value.extract::<f64>() {
            Ok(x) => Ok(x.to_string()),
            Err(_) => match value.extract::<String>() {
                Ok(text) => Ok(text),
                Err(_) => Ok(value.str()?.to_string()),
            },
        },
    };
    text.map_err(|e| {
        // A negative whole number is a value out of range, not a type to convert.
        let negative = match spec.kind {
            OptionKind::Count => value.extract::<i64>().ok().map(|i| i.to_string()),
            OptionKind::Counts => value.extract::<Vec<i64>>().ok().map(|v| format!("{v:?}")),
            _ => None,
        };
        match negative {
            Some(got) => invalid(
                spec.name,
                format!("expected whole numbers of at least 0, got {got}"),
            ),
            None => invalid(spec.name, e),
        }
    })
}

/// The stage options of [`STAGE_OPTIONS`] by their names (the paper's defaults for the
/// absent ones and those given as `None`), checked once.
pub fn stages(options: &Bound<'_, PyDict>) -> PyResult<Stages> {
    stage_options(options)?.check().map_err(param)
}

/// The stage options given as keywords, read but not yet checked.
pub fn stage_options(options: &Bound<'_, PyDict>) -> PyResult<StageOptions> {
    let known: Vec<&str> = STAGE_OPTIONS.iter().map(|o| o.name).collect();
    only_known(options, &known, "; the options are")?;
    let mut chosen = StageOptions::default();
    for spec in STAGE_OPTIONS {
        match options.get_item(spec.name)? {
            Some(v) if !v.is_none() => {
                let text = option_text(spec, &v)?;
                (spec.set)(&mut chosen, &text).map_err(|e| invalid(spec.name, e))?;
            }
            _ => {}
        }
    }
    Ok(chosen)
}

/// Every stage option's default as the Python value a keyword argument takes (`None` for
/// an option without one): the one source of the package's keyword defaults.
#[pyfunction]
pub fn stage_defaults<'py>(py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
    let out = PyDict::new(py);
    let defaults = StageOptions::default();
    for spec in STAGE_OPTIONS {
        let key = spec.name;
        let Some(text) = (spec.get)(&defaults) else {
            out.set_item(key, py.None())?;
            continue;
        };
        let bad = |e: String| raise(Kind::Internal, format!("default of `{key}`: {e}"));
        match spec.kind {
            OptionKind::Flag => out.set_item(key, text == "true")?,
            OptionKind::Count => {
                out.set_item(key, text.parse::<usize>().map_err(|e| bad(e.to_string()))?)?
            }
            OptionKind::Counts => {
                let v: Result<Vec<usize>, _> = text.split(',').map(str::parse).collect();
                out.set_item(
                    key,
                    pyo3::types::PyTuple::new(py, v.map_err(|e| bad(e.to_string()))?)?,
                )?
            }
            OptionKind::Number => {
                out.set_item(key, text.parse::<f64>().map_err(|e| bad(e.to_string()))?)?
            }
            OptionKind::Text => match text.parse::<f64>() {
                Ok(x) => out.set_item(key, x)?,
                Err(_) => out.set_item(key, text)?,
            },
        }
    }
    Ok(out)
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
    let known = knobs(&defaults);
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
        ClassifierChoice::Snn(d) => ClassifierChoice::Snn(snn_params(options, d)?),
    };
    choice.check().map_err(param)?;
    Ok(choice)
}

/// A classifier's knobs by their Python names.
fn knobs(kind: &ClassifierChoice) -> &'static [&'static str] {
    match kind {
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
        ClassifierChoice::Snn(_) => SNN_OPTIONS,
    }
}

/// The knobs `classifier_options` takes for the classifier `kind` (`knn`, `forest`,
/// `linear`, `snn`), by their Python names: what the tests hold against the CLI's flags.
#[pyfunction]
pub fn classifier_knobs(kind: &str) -> PyResult<Vec<&'static str>> {
    let kind: ClassifierChoice = kind.parse().map_err(param)?;
    Ok(knobs(&kind).to_vec())
}

/// The spiking network's training knobs (`hidden`, `dt_ms`, `epochs`, `readout`, `seed`,
/// `recurrent`, `reset`, `target`) over `d`, unchecked; without `reset`, the target's
/// (subtract for Xylo).
fn snn_params(options: &Bound<'_, PyDict>, d: SnnParams) -> PyResult<SnnParams> {
    let target = match get::<String>(options, "target")? {
        Some(t) => t.parse().map_err(param)?,
        None => d.target,
    };
    Ok(SnnParams {
        hidden: get(options, "hidden")?.unwrap_or(d.hidden),
        dt_ms: get(options, "dt_ms")?.unwrap_or(d.dt_ms),
        epochs: get(options, "epochs")?.unwrap_or(d.epochs),
        readout: match get::<String>(options, "readout")? {
            Some(r) => r.parse().map_err(param)?,
            None => d.readout,
        },
        seed: get(options, "seed")?.unwrap_or(d.seed),
        recurrent: get(options, "recurrent")?.unwrap_or(d.recurrent),
        reset: match (get::<String>(options, "reset")?, target) {
            (Some(r), _) => r.parse().map_err(param)?,
            // The chip's neurons subtract; its profile asks for no other option.
            (None, Target::Xylo) => Reset::Subtract,
            (None, Target::Float) => d.reset,
        },
        target,
        tau_syn_ms: get(options, "tau_syn_ms")?.unwrap_or(d.tau_syn_ms),
        tau_mem_ms: get(options, "tau_mem_ms")?.unwrap_or(d.tau_mem_ms),
        tau_out_ms: get(options, "tau_out_ms")?.unwrap_or(d.tau_out_ms),
        ..d
    })
}

/// The spiking network's knobs Python takes, with their defaults: the one source of
/// `SpikingModel.train`'s and `SpikingClassifier`'s keyword defaults.
#[pyfunction]
pub fn snn_defaults(py: Python<'_>) -> PyResult<Bound<'_, PyDict>> {
    let d = SnnParams::default();
    let out = PyDict::new(py);
    out.set_item("hidden", d.hidden)?;
    out.set_item("dt_ms", d.dt_ms)?;
    out.set_item("epochs", d.epochs)?;
    out.set_item("readout", d.readout.name())?;
    out.set_item("seed", d.seed)?;
    out.set_item("recurrent", d.recurrent)?;
    out.set_item("reset", d.reset.name())?;
    out.set_item("target", d.target.name())?;
    out.set_item("tau_syn_ms", d.tau_syn_ms)?;
    out.set_item("tau_mem_ms", d.tau_mem_ms)?;
    out.set_item("tau_out_ms", d.tau_out_ms)?;
    Ok(out)
}

/// The spiking network's options, by their Python names.
const SNN_OPTIONS: &[&str] = &[
    "hidden",
    "dt_ms",
    "epochs",
    "readout",
    "seed",
    "recurrent",
    "reset",
    "target",
    "tau_syn_ms",
    "tau_mem_ms",
    "tau_out_ms",
];

/// The spiking network's training knobs, checked.
pub fn snn(options: &Bound<'_, PyDict>) -> PyResult<SnnParams> {
    only_known(
        options,
        SNN_OPTIONS,
        " for the spiking network; its options are",
    )?;
    snn_params(options, SnnParams::default())?
        .check()
        .map_err(param)
}
