//! The crate-level error type: one variant per stage, each wrapping that stage's error.

use std::path::PathBuf;

pub use crate::model::ModelError;
pub use crate::recording::DatasetError;

/// Everything that can go wrong in neurotex, by stage.
#[derive(Debug, thiserror::Error)]
pub enum Error {
    /// Reading or validating recordings, manifests and layouts.
    #[error(transparent)]
    Data(#[from] DataError),
    /// A parameter broke one of its rules.
    #[error(transparent)]
    Param(#[from] ParamError),
    /// Classification or cross-validation could not run on the given data.
    #[error(transparent)]
    Classify(#[from] ClassifyError),
    /// An error while working on one recording's data after it was read, naming the
    /// recording (the inner error has no file of its own).
    #[error("{file}: {source}")]
    InRecording {
        /// The recording's file, as the manifest names it.
        file: String,
        /// What went wrong.
        source: Box<Error>,
    },
    /// A statistic could not be computed from what it was given.
    #[error(transparent)]
    Stats(#[from] crate::classify::stats::StatsError),
    /// A dataset cannot serve what was asked of it (speeds, one grid).
    #[error(transparent)]
    Dataset(#[from] DatasetError),
    /// A model file cannot be used, or recordings do not fit a model.
    #[error(transparent)]
    Model(#[from] ModelError),
}

impl Error {
    /// This error with the recording `file` named (see [`Error::InRecording`]); errors that
    /// already name a file are returned as they are.
    pub fn in_recording(self, file: &str) -> Error {
        match self {
            Error::Data(
                DataError::Io { .. } | DataError::Write { .. } | DataError::Invalid { .. },
            )
            | Error::InRecording { .. } => self,
            other => Error::InRecording {
                file: file.to_string(),
                source: Box::new(other),
            },
        }
    }
}

/// A shorthand for results with [`Error`].
pub type Result<T, E = Error> = std::result::Result<T, E>;

/// A parameter outside its allowed range; the message names the rule.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("invalid parameter `{name}`: {rule}, got {got}")]
pub struct ParamError {
    /// The parameter's name as the command line spells it.
    pub name: &'static str,
    /// The rule it must satisfy.
    pub rule: &'static str,
    /// The value that came.
    pub got: String,
}

impl ParamError {
    /// Builds the error for parameter `name` that broke `rule` with value `got`.
    pub fn new(name: &'static str, rule: &'static str, got: impl ToString) -> Self {
        Self {
            name,
            rule,
            got: got.to_string(),
        }
    }
}

/// Bad or unreadable input data: each variant names the file and what was expected.
#[derive(Debug, thiserror::Error)]
pub enum DataError {
    /// A file could not be opened or read.
    #[error("cannot read {path}: {reason}")]
    Io {
        /// The file.
        path: PathBuf,
        /// The operating system's reason (in the message, so not also a `source()`, which
        /// would print it twice in an error chain).
        reason: std::io::Error,
    },
    /// A file or folder could not be created or written.
    #[error("cannot write {path}: {reason}")]
    Write {
        /// The output, as the user named it (never the hidden temporary).
        path: PathBuf,
        /// The operating system's reason (in the message, not a `source()`).
        reason: std::io::Error,
    },
    /// Spike trains (or a part of them) shorter than one rate-volume bin.
    #[error("{n_ms} ms of spikes is shorter than one {bin_ms} ms bin")]
    TooShort {
        /// Milliseconds of spikes.
        n_ms: usize,
        /// The bin, ms.
        bin_ms: usize,
    },
    /// A size beyond one of neurotex's limits (SPEC 8), in data that has no file of its
    /// own (the recording is named by [`Error::in_recording`]).
    #[error("{what} is {got}, beyond the limit of {limit}: {hint}")]
    TooLarge {
        /// What is too large.
        what: &'static str,
        /// Its size.
        got: u64,
        /// The limit.
        limit: u64,
        /// What to do about it.
        hint: &'static str,
    },
    /// Memory for a buffer whose size the input decides could not be reserved: reported
    /// (as `MemoryError` in Python) instead of aborting the process.
    #[error("{what}: {bytes} bytes do not fit in memory")]
    OutOfMemory {
        /// What the buffer would hold.
        what: String,
        /// Its size in bytes.
        bytes: u64,
    },
    /// A file was read but its content is not what was expected.
    #[error("{path}: {message}")]
    Invalid {
        /// The file.
        path: PathBuf,
        /// What is wrong and what was expected, with line and field where they apply.
        message: String,
    },
}

/// An empty vector with room for `len` values, reserved fallibly: where the input decides
/// a buffer's size, a request the machine cannot meet is a [`DataError::OutOfMemory`]
/// naming `what`, not an abort.
///
/// # Errors
/// The memory cannot be reserved.
pub fn try_with_capacity<T>(len: usize, what: &str) -> Result<Vec<T>> {
    let mut v = Vec::new();
    v.try_reserve_exact(len)
        .map_err(|_| DataError::OutOfMemory {
            what: what.to_string(),
            bytes: (len as u64).saturating_mul(std::mem::size_of::<T>() as u64),
        })?;
    Ok(v)
}

impl DataError {
    /// An [`DataError::Invalid`] for `path` with `message`.
    pub fn invalid(path: impl Into<PathBuf>, message: impl Into<String>) -> Self {
        DataError::Invalid {
            path: path.into(),
            message: message.into(),
        }
    }

    /// A [`DataError::Write`] for output `path`.
    pub fn write(path: impl Into<PathBuf>, source: std::io::Error) -> Self {
        DataError::Write {
            path: path.into(),
            reason: source,
        }
    }

    /// An [`DataError::Io`] for `path`.
    pub fn io(path: impl Into<PathBuf>, source: std::io::Error) -> Self {
        DataError::Io {
            path: path.into(),
            reason: source,
        }
    }
}

/// Classification problems that come from the data given, not from a bug.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum ClassifyError {
    /// Fewer training samples than neighbours.
    #[error("k = {k} neighbours needs at least {k} training samples, got {n_train}")]
    KTooLarge {
        /// Neighbours asked for.
        k: usize,
        /// Training samples available.
        n_train: usize,
    },
    /// A class has fewer samples than folds, so stratified folds cannot hold it.
    #[error("class `{label}` has {count} samples, fewer than the {folds} folds; use fewer folds or drop the class")]
    ClassTooSmall {
        /// The class.
        label: String,
        /// Its sample count.
        count: usize,
        /// Folds asked for.
        folds: usize,
    },
    /// Every sample has one class: any classifier scores 100 %, which says nothing.
    #[error(
        "every recording to {what} is of class `{label}`: telling classes apart needs at least two"
    )]
    OneClass {
        /// The one class.
        label: String,
        /// What was to be done (`cross-validate`, `train`).
        what: &'static str,
    },
    /// The test set holds a label the training set never saw.
    #[error("test label `{label}` does not occur in the training set")]
    UnknownTestLabel {
        /// The label.
        label: String,
    },
    /// Nothing to classify.
    #[error("no samples to {what}")]
    Empty {
        /// What was to be done.
        what: &'static str,
    },
    /// Two evaluations to be compared recording by recording cover different recordings.
    #[error("{first} and {second} were not evaluated on the same recordings")]
    Unpaired {
        /// The first evaluation.
        first: String,
        /// The second evaluation.
        second: String,
    },
    /// Feature rows of different lengths, or a non-finite feature.
    #[error("{0}")]
    BadFeatures(String),
}
