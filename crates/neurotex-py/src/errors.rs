//! The library's errors as Python exceptions of `neurotex.errors`, and panics caught before
//! they reach Python.

use std::panic::{catch_unwind, AssertUnwindSafe};

use neurotex::error::{DataError, ParamError};
use pyo3::prelude::*;

/// The exception classes of `neurotex.errors`, by name.
#[derive(Debug, Clone, Copy)]
pub enum Kind {
    /// A parameter broke its rule (also a `ValueError`).
    Parameter,
    /// Bad input data (also a `ValueError`).
    Data,
    /// A file or folder that does not exist (also a `FileNotFoundError`).
    NotFound,
    /// Another input/output failure (also an `OSError`).
    Io,
    /// A model file that cannot be used (also a `ValueError`).
    Model,
    /// Training or prediction data a classifier cannot use (also a `ValueError`).
    Classify,
    /// A bug: a panic inside neurotex, caught at the boundary.
    Internal,
}

impl Kind {
    fn class_name(self) -> &'static str {
        match self {
            Kind::Parameter => "ParameterError",
            Kind::Data => "DataError",
            Kind::NotFound => "NotFoundError",
            Kind::Io => "ReadWriteError",
            Kind::Model => "ModelError",
            Kind::Classify => "ClassifyError",
            Kind::Internal => "InternalError",
        }
    }
}

/// A Python exception of class `kind` with `message`.
pub fn raise(kind: Kind, message: impl Into<String>) -> PyErr {
    let message = message.into();
    Python::attach(|py| {
        let class = py
            .import("neurotex.errors")
            .and_then(|m| m.getattr(kind.class_name()));
        match class.and_then(|c| c.call1((message.clone(),))) {
            Ok(value) => PyErr::from_value(value),
            // Only when the package's Python half is missing (the module imported alone).
            Err(_) => pyo3::exceptions::PyRuntimeError::new_err(message),
        }
    })
}

/// The exception class a library error belongs to.
fn kind_of(error: &neurotex::Error) -> Kind {
    use neurotex::Error as E;
    match error {
        E::Param(_) | E::Options(_) => Kind::Parameter,
        E::Data(DataError::Io { reason, .. } | DataError::Write { reason, .. }) => io_kind(reason),
        E::Data(_) | E::Dataset(_) => Kind::Data,
        E::Classify(_) | E::Stats(_) => Kind::Classify,
        E::Model(_) => Kind::Model,
        E::InRecording { source, .. } | E::InAnalysis { source, .. } => kind_of(source),
        // The library's error enum may grow; a new stage's errors are bad input until
        // this layer learns better.
        #[allow(unreachable_patterns)]
        _ => Kind::Data,
    }
}

/// `NotFound` for a missing file, the general input/output class otherwise.
fn io_kind(error: &std::io::Error) -> Kind {
    match error.kind() {
        std::io::ErrorKind::NotFound => Kind::NotFound,
        _ => Kind::Io,
    }
}

/// A library error as the Python exception of its kind, with the library's message.
pub fn to_py(error: neurotex::Error) -> PyErr {
    if out_of_memory(&error) {
        return pyo3::exceptions::PyMemoryError::new_err(error.to_string());
    }
    let hint = error
        .classify()
        .and_then(|c| c.hint(&|name, value| format!("{name}={value}")));
    let text = match &error {
        // The workflows name options as the command line spells them.
        neurotex::Error::Options(_) => keywords(&error.to_string()),
        neurotex::Error::Param(p) => {
            let (name, rule, got) = (keyword(p.name), p.rule, &p.got);
            format!("invalid parameter `{name}`: {rule}, got {got}")
        }
        _ => error.to_string(),
    };
    match hint {
        Some(hint) => raise(kind_of(&error), format!("{text}\nhint: {hint}")),
        None => raise(kind_of(&error), text),
    }
}

/// A parameter's name as Python's keyword spells it: `bin_ms` for the command line's
/// `bin-ms`, and the spiking network's knobs without the CLI's `snn-` prefix (`hidden`
/// for `snn-hidden`), as `classifier_options` and `SpikingModel.train` take them.
fn keyword(name: &str) -> String {
    let knob = name.strip_prefix("snn-").filter(|rest| !rest.is_empty());
    knob.unwrap_or(name).replace('-', "_")
}

/// `text` with each command-line option (`--forest-seed`) spelled as Python's keyword
/// (`forest_seed`).
fn keywords(text: &str) -> String {
    let mut out = String::with_capacity(text.len());
    let mut rest = text;
    while let Some(at) = rest.find("--") {
        out.push_str(&rest[..at]);
        let name = &rest[at + 2..];
        let end = name
            .find(|c: char| !(c.is_ascii_alphanumeric() || c == '-'))
            .unwrap_or(name.len());
        out.push_str(&keyword(&name[..end]));
        rest = &name[end..];
    }
    out.push_str(rest);
    out
}

/// Memory the input asked for and the machine does not have: Python's `MemoryError`,
/// which a notebook survives.
fn out_of_memory(error: &neurotex::Error) -> bool {
    match error {
        neurotex::Error::Data(DataError::OutOfMemory { .. }) => true,
        neurotex::Error::InRecording { source, .. }
        | neurotex::Error::InAnalysis { source, .. } => out_of_memory(source),
        _ => false,
    }
}

/// `len` values in a new vector reserved fallibly ([`neurotex::error::try_with_capacity`]):
/// `MemoryError` when the machine cannot hold them.
pub fn try_vec<T>(len: usize, what: &str, values: impl Iterator<Item = T>) -> PyResult<Vec<T>> {
    let mut v = neurotex::error::try_with_capacity(len, what).map_err(to_py)?;
    v.extend(values);
    Ok(v)
}

/// A parameter error as a `neurotex.ParameterError`, the parameter named as Python spells
/// it (`bin_ms` for the command line's `--bin-ms`).
pub fn param(error: ParamError) -> PyErr {
    raise(
        Kind::Parameter,
        format!(
            "invalid parameter `{}`: {}, got {}",
            keyword(error.name),
            error.rule,
            error.got
        ),
    )
}

/// Runs `f`, turning a panic into a `neurotex.InternalError` (no panic crosses into
/// Python) and a library error into its exception.
pub fn guarded<T>(f: impl FnOnce() -> neurotex::Result<T>) -> PyResult<T> {
    match catch_unwind(AssertUnwindSafe(f)) {
        Ok(Ok(value)) => Ok(value),
        Ok(Err(error)) => Err(to_py(error)),
        Err(panic) => Err(from_panic(panic)),
    }
}

/// Runs `f`, which returns Python errors already, turning a panic into a
/// `neurotex.InternalError`.
pub fn guarded_py<T>(f: impl FnOnce() -> PyResult<T>) -> PyResult<T> {
    match catch_unwind(AssertUnwindSafe(f)) {
        Ok(result) => result,
        Err(panic) => Err(from_panic(panic)),
    }
}

/// A caught panic as an exception: `KeyboardInterrupt` for a run a Ctrl-C stopped
/// ([`crate::interrupt`]), else a `neurotex.InternalError`.
fn from_panic(panic: Box<dyn std::any::Any + Send>) -> PyErr {
    match panic.downcast::<neurotex::progress::Stopped>() {
        Ok(stopped) => crate::interrupt::stopped_error(&stopped),
        Err(panic) => raise(Kind::Internal, panic_message(panic)),
    }
}

/// The text of a caught panic.
fn panic_message(panic: Box<dyn std::any::Any + Send>) -> String {
    let text = panic
        .downcast_ref::<&str>()
        .map(|s| s.to_string())
        .or_else(|| panic.downcast_ref::<String>().cloned())
        .unwrap_or_else(|| "unknown panic".to_string());
    format!("internal error in neurotex (please report it): {text}")
}

#[cfg(test)]
mod tests {
    use super::keywords;

    #[test]
    fn options_are_spelled_as_keywords() {
        assert_eq!(
            keywords("--trees and --forest-seed apply only to --classifier forest"),
            "trees and forest_seed apply only to classifier forest"
        );
        assert_eq!(keywords("a - b -- c"), "a - b  c");
    }
}
