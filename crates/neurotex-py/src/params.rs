//! Keyword options into the library's validated parameters, as the CLI's stage options
//! are: the one place where the Python layer parses options (the pipeline's, the
//! classifiers', the feature method).

use neurotex::classify::{ChosenClassifier, ClassifierChoice};
use neurotex::options::{
    classifier_with, knobs_of, snn_with, CheckedStages, KnobSpec, OptionKind, StageOptions,
    STAGE_OPTIONS,
};
use neurotex::pipeline::Method;
use neurotex::recording::Baseline;
use neurotex::snn::SnnParams;
use pyo3::prelude::*;
use pyo3::types::PyDict;

use crate::errors::{param, raise, Kind};

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
fn option_text(name: &str, kind: OptionKind, value: &Bound<'_, PyAny>) -> PyResult<String> {
    // Python's `True` is an `int` too: a switch given where a count or a number is
    // expected is refused, not read as 1.
    let is_bool = value.is_instance_of::<pyo3::types::PyBool>();
    let expected = |what: &str| -> PyResult<String> {
        let got = value
            .repr()
            .map(|r| r.to_string())
            .unwrap_or_else(|_| "?".into());
        Err(invalid(name, format!("expected {what}, got {got}")))
    };
    match kind {
        OptionKind::Flag | OptionKind::Bool => match value.extract::<bool>() {
            Ok(b) => Ok(b.to_string()),
            Err(_) => expected("True or False"),
        },
        OptionKind::Count if is_bool => expected("a whole number of at least 0"),
        OptionKind::Count => match value.extract::<usize>() {
            Ok(n) => Ok(n.to_string()),
            Err(_) => expected("a whole number of at least 0"),
        },
        OptionKind::Counts => match value.extract::<Vec<usize>>() {
            Ok(v) => {
                let v: Vec<String> = v.iter().map(usize::to_string).collect();
                Ok(v.join(","))
            }
            _ => expected("a list of whole numbers of at least 0"),
        },
        OptionKind::Number if is_bool => expected("a number"),
        OptionKind::Number => match value.extract::<f64>() {
            Ok(x) => Ok(x.to_string()),
            Err(_) => expected("a number"),
        },
        // A number (the gain) or a name; anything else as Python prints it, for the
        // option's own parser to say what it expects.
        OptionKind::Text => match value.extract::<f64>() {
            Ok(x) if !is_bool => Ok(x.to_string()),
            _ => match value.extract::<String>() {
                Ok(text) => Ok(text),
                Err(_) => Ok(value.str()?.to_string()),
            },
        },
    }
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
                let text = option_text(spec.name, spec.kind, &v)?;
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
        out.set_item(key, py_value(py, key, spec.kind, &text)?)?;
    }
    Ok(out)
}

/// A default as the Python value a keyword argument takes: `True`, `200`, `(1, 2)`, `8.0`,
/// `"RS"`.
fn py_value<'py>(
    py: Python<'py>,
    key: &str,
    kind: OptionKind,
    text: &str,
) -> PyResult<Bound<'py, PyAny>> {
    let bad = |e: String| raise(Kind::Internal, format!("default of `{key}`: {e}"));
    Ok(match kind {
        OptionKind::Flag | OptionKind::Bool => {
            (text == "true").into_pyobject(py)?.to_owned().into_any()
        }
        OptionKind::Count => text
            .parse::<usize>()
            .map_err(|e| bad(e.to_string()))?
            .into_pyobject(py)?
            .into_any(),
        OptionKind::Counts => {
            let v: Result<Vec<usize>, _> = text.split(',').map(str::parse).collect();
            pyo3::types::PyTuple::new(py, v.map_err(|e| bad(e.to_string()))?)?.into_any()
        }
        OptionKind::Number => text
            .parse::<f64>()
            .map_err(|e| bad(e.to_string()))?
            .into_pyobject(py)?
            .into_any(),
        OptionKind::Text => match text.parse::<f64>() {
            Ok(x) => x.into_pyobject(py)?.into_any(),
            Err(_) => text.into_pyobject(py)?.into_any(),
        },
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

/// A classifier by name with its knobs ([`neurotex::options::CLASSIFIER_OPTIONS`] by
/// their Python names; the forest's `seed` also as `forest_seed`), checked (a model file
/// stores this form).
pub fn classifier(kind: &str, options: &Bound<'_, PyDict>) -> PyResult<ClassifierChoice> {
    // The kind by the library's name, with its defaults.
    let defaults: ClassifierChoice = kind.parse().map_err(param)?;
    let given = knobs_given(defaults.name(), options)?;
    classifier_with(defaults, &given).map_err(crate::errors::to_py)
}

/// The knobs of the classifier `name` in `options`, each with its value as the library's
/// parser reads it (checked one by one, not yet together); a key the classifier does not
/// take is refused, naming the ones it does.
pub fn knobs_given(
    name: &str,
    options: &Bound<'_, PyDict>,
) -> PyResult<Vec<(&'static KnobSpec, String)>> {
    let mut known: Vec<&str> = knobs_of(name).map(|k| k.name).collect();
    if name == "forest" {
        known.push("forest_seed");
    }
    let what = match name {
        "snn" => " for the spiking network; its options are".to_string(),
        _ => format!(" for classifier {name}; its options are"),
    };
    only_known(options, &known, &what)?;
    let mut given = Vec::new();
    for spec in knobs_of(name) {
        let alias = (spec.name == "seed" && name == "forest").then_some("forest_seed");
        let value = match alias.map(|a| options.get_item(a)).transpose()?.flatten() {
            Some(v) if !v.is_none() => Some(v),
            _ => options.get_item(spec.name)?.filter(|v| !v.is_none()),
        };
        if let Some(value) = value {
            let text = option_text(spec.name, spec.kind, &value)?;
            spec.read(&text).map_err(|e| invalid(spec.name, e))?;
            given.push((spec, text));
        }
    }
    Ok(given)
}

/// The knobs `classifier_options` takes for the classifier `kind` (`knn`, `forest`,
/// `linear`, `snn`), by their Python names: what the tests hold against the CLI's flags.
#[pyfunction]
pub fn classifier_knobs(kind: &str) -> PyResult<Vec<&'static str>> {
    let kind: ClassifierChoice = kind.parse().map_err(param)?;
    Ok(knobs_of(kind.name()).map(|k| k.name).collect())
}

/// The knobs of the classifier `kind` with their defaults (`None` for a knob without
/// one, as the forest's `max_depth`): the one source of the Python estimators' and
/// `SpikingModel.train`'s keyword defaults.
#[pyfunction]
pub fn classifier_defaults<'py>(py: Python<'py>, kind: &str) -> PyResult<Bound<'py, PyDict>> {
    let kind: ClassifierChoice = kind.parse().map_err(param)?;
    let out = PyDict::new(py);
    for spec in knobs_of(kind.name()) {
        match spec.default_text() {
            Some(text) => out.set_item(spec.name, py_value(py, spec.name, spec.kind, &text)?)?,
            None => out.set_item(spec.name, py.None())?,
        }
    }
    Ok(out)
}

/// The spiking network's training knobs, checked.
pub fn snn(options: &Bound<'_, PyDict>) -> PyResult<SnnParams> {
    let given = knobs_given("snn", options)?;
    snn_with(SnnParams::default(), &given).map_err(crate::errors::to_py)
}
