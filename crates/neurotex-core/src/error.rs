//! The crate-level error type: one variant per stage, each wrapping that stage's error.

use std::path::PathBuf;

pub use crate::model_format::{MODEL_FORMAT, MODEL_VERSION, SNN_MODEL_FORMAT};
pub use crate::values::ParamError;
use crate::values::{Grid, Speed};
pub use crate::words::{json_error, number_words, parser_words, toml_error};

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
    /// An error in one analysis or condition of a larger run, naming it (`at 5 mm/s, the
    /// cross-validation within a speed`).
    #[error("{what}: {source}")]
    InAnalysis {
        /// The analysis and condition, and what the design supports when that helps.
        what: String,
        /// What went wrong.
        source: Box<Error>,
    },
    /// A statistic could not be computed from what it was given.
    #[error(transparent)]
    Stats(#[from] StatsError),
    /// A dataset cannot serve what was asked of it (speeds, one grid).
    #[error(transparent)]
    Dataset(#[from] DatasetError),
    /// A model file cannot be used, or recordings do not fit a model.
    #[error(transparent)]
    Model(#[from] ModelError),
    /// Options that do not go together, or one given where it does not apply.
    #[error(transparent)]
    Options(#[from] OptionsError),
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

impl Error {
    /// This error within the analysis or condition `what`.
    pub fn in_analysis(self, what: impl Into<String>) -> Error {
        Error::InAnalysis {
            what: what.into(),
            source: Box::new(self),
        }
    }

    /// Whether this error says the data is too small for the folds or neighbours asked
    /// for ([`ClassifyError::is_design`]), through the recording or analysis it is named in.
    pub fn is_design(&self) -> bool {
        self.classify().is_some_and(ClassifyError::is_design)
    }

    /// The classification error at the heart of this one, through the recording or
    /// analysis it is named in: what a front end's hint is drawn from.
    pub fn classify(&self) -> Option<&ClassifyError> {
        match self {
            Error::Classify(c) => Some(c),
            Error::InRecording { source, .. } | Error::InAnalysis { source, .. } => {
                source.classify()
            }
            _ => None,
        }
    }
}

/// A shorthand for results with [`Error`].
pub type Result<T, E = Error> = std::result::Result<T, E>;

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
    /// A size beyond one of neurotex's limits on input (docs/your-data.md), in data that
    /// has no file of its own (the recording is named by [`Error::in_recording`]).
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

/// What is wrong with one event of an event recording, before the file and the line are
/// named (a reader reports it in a [`DataError::Invalid`], a live stream as a bad frame).
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum EventError {
    /// A polarity that is neither the ON value nor the OFF value.
    #[error("polarity {value} is neither ON ({on}) nor OFF ({off}); `import events --polarity-values ON,OFF` (or layout.toml's `[events] values = [on, off]`) names them")]
    Polarity {
        /// The polarity read.
        value: i64,
        /// The ON value.
        on: i64,
        /// The OFF value.
        off: i64,
    },
    /// A taxel index the layout does not have.
    #[error("taxel {taxel} is outside the layout's {taxels} taxels (0 to {})", .taxels.saturating_sub(1))]
    TaxelOutside {
        /// The index read.
        taxel: i64,
        /// The layout's taxels.
        taxels: usize,
    },
    /// An `(x, y)` outside the grid.
    #[error("x = {x}, y = {y} is outside the {rows}x{cols} grid (x is the column, 0 to {}; y the row, 0 to {})", .cols - 1, .rows - 1)]
    OutsideGrid {
        /// The column read.
        x: i64,
        /// The row read.
        y: i64,
        /// The grid's rows.
        rows: usize,
        /// The grid's columns.
        cols: usize,
    },
    /// A cell the layout's mask leaves out.
    #[error("the event is at row {row}, column {col}, a cell layout.toml's mask leaves out")]
    Masked {
        /// Its row.
        row: usize,
        /// Its column.
        col: usize,
    },
    /// A time before the recording's start.
    #[error("time {time} is before the recording's start: stamps from a clock need `--origin first` (`origin = \"first\"` in layout.toml's [events])")]
    BeforeStart {
        /// The time stamp, as written.
        time: String,
    },
    /// A time that is not a finite number.
    #[error("time {time} is not a finite number")]
    NotFinite {
        /// The time stamp, as written.
        time: String,
    },
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
    /// Folds that keep groups whole put every recording of a class in one fold, so the
    /// models tested on it never trained on the class.
    #[error("the folds keep each group whole and so put every recording of class `{label}` in one fold: the model tested on that fold never trained on it, and would score it wrong whatever the features. The grouping column separates this class from the others (it is the label itself, or the class was recorded in one group alone): group by a column whose groups each hold recordings of several classes (a trial or session of every texture)")]
    GroupsHoldAClass {
        /// The class.
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
    /// A class too small for the spiking classifier's validation split.
    #[error("class `{class}` has {count} training recording(s): the spiking classifier sets at least one aside for early stopping and trains on the rest, so each class needs at least 2")]
    ValidationTooSmall {
        /// The class (its label where known, else its index).
        class: String,
        /// Its training recordings.
        count: usize,
    },
}

impl ClassifyError {
    /// Whether the data is too small for the folds or neighbours asked for: a design a
    /// larger run skips with this reason instead of stopping (fewer folds or neighbours
    /// would run it).
    pub fn is_design(&self) -> bool {
        matches!(
            self,
            ClassifyError::KTooLarge { .. }
                | ClassifyError::ClassTooSmall { .. }
                | ClassifyError::ValidationTooSmall { .. }
        )
    }

    /// The error with a class given by its index named by `names` (the spiking
    /// classifier's validation split sees class indices only), and, inside
    /// cross-validation, said to be a training fold.
    pub fn with_class_names(self, names: &[String]) -> Self {
        match self {
            ClassifyError::ValidationTooSmall { class, count } => {
                ClassifyError::ValidationTooSmall {
                    class: class
                        .parse::<usize>()
                        .ok()
                        .and_then(|c| names.get(c).cloned())
                        .unwrap_or(class),
                    count,
                }
            }
            other => other,
        }
    }

    /// What to change when the data is too small for the folds or neighbours asked for,
    /// the options spelled by `option(name, value)` (`--folds 2` on the command line,
    /// `folds=2` in Python); `None` for the other errors.
    pub fn hint(&self, option: &dyn Fn(&str, &str) -> String) -> Option<String> {
        let pilot = format!("{} {}", option("folds", "2"), option("k", "1"));
        match self {
            ClassifyError::ClassTooSmall { .. } => Some(format!(
                "{} sets the cross-validation folds: each class needs at least that many recordings (in reproduce, at each speed); a small pilot runs with {pilot}",
                option("folds", "N")
            )),
            ClassifyError::ValidationTooSmall { .. } => Some(format!(
                "the spiking network sets 20 % of each class's training recordings aside for early stopping: each class needs at least 2 in every training set (inside cross-validation, a training fold); fewer folds ({}) or more recordings help",
                option("folds", "2")
            )),
            ClassifyError::KTooLarge { .. } => Some(format!(
                "{} sets the neighbours of KNN: each training fold must hold at least that many recordings (in reproduce, at each speed); a small pilot runs with {pilot}",
                option("k", "N")
            )),
            _ => None,
        }
    }
}

/// A dataset that cannot serve what was asked of it.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum DatasetError {
    /// No recording at a speed that was asked for.
    #[error("no recordings at {speed} mm/s in {} (its speeds: {})", .root.display(), speeds_or_none(.available))]
    NoRecordingsAt {
        /// The speed asked for.
        speed: Speed,
        /// The dataset folder.
        root: PathBuf,
        /// The speeds the dataset has, ascending.
        available: Vec<Speed>,
    },
    /// Two recordings on different taxel grids (size or mask).
    #[error("{file}: its taxel grid differs from that of {first}; a dataset needs one layout")]
    MixedGrids {
        /// The first recording whose grid differs.
        file: String,
        /// The recording whose grid the others must share.
        first: String,
    },
    /// No recording was selected.
    #[error("no recordings selected")]
    Empty,
    /// A selection names a column in which no recording has a value.
    #[error("no recording has a value in manifest column `{column}` (columns with values: {})", .columns.join(", "))]
    NoColumn {
        /// The column asked for.
        column: String,
        /// The columns in which some recording has a value.
        columns: Vec<String>,
    },
    /// A selection asks for a value that no recording has.
    #[error("no recording has {column} = {value} (values present: {})", .present.join(", "))]
    NoRecordingsWhere {
        /// The column.
        column: String,
        /// The value asked for.
        value: String,
        /// The column's distinct values, in order (numerically for numeric columns).
        present: Vec<String>,
    },
    /// A recording selected both for training and for testing.
    #[error("{file} is selected both for training ({train}) and for testing ({test}); the two sets must not share a recording")]
    InBothSets {
        /// The first recording in both sets.
        file: String,
        /// The training selection, as typed.
        train: String,
        /// The test selection, as typed.
        test: String,
    },
}

fn speeds_or_none(speeds: &[Speed]) -> String {
    if speeds.is_empty() {
        return "none, the manifest gives no speed_mm_s".into();
    }
    let texts: Vec<String> = speeds.iter().map(Speed::to_string).collect();
    texts.join(", ")
}

/// A statistic asked of data it cannot be computed from.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum StatsError {
    /// No observations at all.
    #[error("no {what}: an interval needs at least one")]
    Empty {
        /// What was missing (recordings, repeats).
        what: &'static str,
    },
    /// More correct predictions than predictions.
    #[error("{correct} correct out of {n}: the correct count cannot exceed the total")]
    CountAboveTotal {
        /// Correct predictions given.
        correct: usize,
        /// Predictions given.
        n: usize,
    },
    /// Two methods' per-recording results of different lengths, so they cannot be paired.
    #[error(
        "paired results need one entry per recording for both methods, got {first} and {second}"
    )]
    LengthMismatch {
        /// Entries for the first method.
        first: usize,
        /// Entries for the second method.
        second: usize,
    },
    /// A t interval over repeats from fewer than two repeats (no spread to estimate).
    #[error("a t interval over repeats needs at least 2 repeats, got {got}")]
    TooFewRepeats {
        /// Repeats given.
        got: usize,
    },
    /// A value that should be an accuracy or a share of correct predictions is not in [0, 1].
    #[error("entry {index} is {value}, not an accuracy in [0, 1]")]
    NotAnAccuracy {
        /// Its position in the input.
        index: usize,
        /// The value.
        value: f64,
    },
    /// A probability outside the open interval (0, 1).
    #[error("a quantile needs a probability strictly between 0 and 1, got {got}")]
    Probability {
        /// The value given.
        got: f64,
    },
    /// Student's t with zero degrees of freedom.
    #[error("Student's t needs at least 1 degree of freedom, got 0")]
    ZeroDegreesOfFreedom,
}

/// A model file that cannot be used, or recordings a model cannot take.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum ModelError {
    /// The file is JSON but not a neurotex model.
    #[error("{}: not a neurotex model file (its `format` is {found}, expected \"{MODEL_FORMAT}\" for a feature model or \"{SNN_MODEL_FORMAT}\" for a spiking one)", .path.display())]
    NotAModel {
        /// The file.
        path: PathBuf,
        /// What its `format` field holds, as JSON, or that it has none.
        found: String,
    },
    /// A model file of a format version this neurotex does not read.
    #[error("{}: model file version {found} is not supported; neurotex {} reads version {MODEL_VERSION}", .path.display(), env!("CARGO_PKG_VERSION"))]
    UnsupportedVersion {
        /// The file.
        path: PathBuf,
        /// Its `version` field, as JSON, or that it has none.
        found: String,
    },
    /// The file is truncated or not JSON.
    #[error("{}: damaged or truncated model file (not valid JSON): {reason}", .path.display())]
    Damaged {
        /// The file.
        path: PathBuf,
        /// What is wrong.
        reason: String,
    },
    /// The file is whole JSON of the model format, but its content breaks a rule that
    /// neurotex's own files keep: a field edited, or a file written by other software.
    #[error("{}: model file with content neurotex never writes (edited, or written by other software): {reason}", .path.display())]
    Invalid {
        /// The file.
        path: PathBuf,
        /// The rule broken.
        reason: String,
    },
    /// A NIR graph neurotex cannot run: not HDF5, damaged, or of another shape.
    #[error("{}: cannot run this NIR graph: {reason}", .path.display())]
    Nir {
        /// The file.
        path: PathBuf,
        /// What is wrong, naming the node or the rule.
        reason: String,
    },
    /// A spiking model where a feature model is needed.
    #[error("{}: a spiking model (a `{SNN_MODEL_FORMAT}` file or a NIR graph), where a feature model is needed: `predict`, `stream` and `export` take it (in Python: SpikingModel.load)", .path.display())]
    SpikingModel {
        /// The file.
        path: PathBuf,
    },
    /// A feature model where a spiking model is needed.
    #[error("{}: a feature model (`{MODEL_FORMAT}`), not a spiking model: train one with --classifier snn (in Python: SpikingModel.train); only a spiking network has a NIR graph and input tensors", .path.display())]
    NotSpiking {
        /// The file.
        path: PathBuf,
    },
    /// A model's parts disagree with each other (only a damaged file can make them).
    #[error("{0}")]
    Inconsistent(String),
    /// A spiking network that breaks a rule of its own (a shape, the time step, a time
    /// constant, a weight) or of the chip it is meant for.
    #[error("{reason}")]
    Network {
        /// The network's field or the chip's limit at fault: `w_in`, `tau_mem_ms`,
        /// `dt_ms`, `inputs`.
        parameter: &'static str,
        /// The rule broken, as a sentence naming the parameter.
        reason: String,
    },
    /// A recording on another taxel grid than the model's.
    #[error("{file}: its taxel grid ({}) differs from the model's ({}); a model applies only to recordings of the grid it was trained on", grid_text(.found, .expected), grid_text(.expected, .found))]
    OtherGrid {
        /// The recording.
        file: String,
        /// The model's grid.
        expected: Grid,
        /// The recording's grid.
        found: Grid,
    },
}

impl ModelError {
    /// A network's broken rule: `parameter` at fault, `reason` the sentence naming it.
    pub fn network(parameter: &'static str, reason: impl Into<String>) -> Self {
        ModelError::Network {
            parameter,
            reason: reason.into(),
        }
    }
}

/// `4x4, 16 taxels`, saying when the mask is all that differs from `other`.
fn grid_text(grid: &Grid, other: &Grid) -> String {
    let same_shape = (grid.rows(), grid.cols(), grid.n_taxels())
        == (other.rows(), other.cols(), other.n_taxels());
    let mask = if same_shape { ", another mask" } else { "" };
    format!("{grid}, {} taxels{mask}", grid.n_taxels())
}

/// Options that do not go together, or one given where it does not apply; the options are
/// named as the command line spells them.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum OptionsError {
    /// An option that applies only with another choice.
    #[error("{option} applies only to {applies_to}")]
    NotApplicable {
        /// The option given.
        option: &'static str,
        /// The choice it applies to.
        applies_to: &'static str,
    },
    /// Options, or an option and the input, that cannot go together; the message says why
    /// and what to do instead.
    #[error("{0}")]
    Conflict(String),
    /// A value an option does not take.
    #[error("invalid value for {option}: {reason}")]
    Invalid {
        /// The option given.
        option: &'static str,
        /// What was expected, and what came.
        reason: String,
    },
}
