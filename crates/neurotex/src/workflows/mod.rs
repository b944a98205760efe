//! The commands' workflows, one module each, shared by the command line and the Python
//! package. Each module defines its command's options once (their help, defaults and
//! rules; with the `cli` feature the command line's flags are derived from them), checks
//! them, and runs the library on them. A workflow never prints: what it has to say (a
//! note, a warning, what a calibration chose) and its progress go to the caller's
//! [`Progress`] callback, which the command line shows on standard error and Python turns
//! into warnings.

pub mod benchmark;
pub mod compare;
pub mod datasets;
pub mod encode;
pub mod evaluate;
pub mod export;
pub mod features;
pub mod import;
pub mod inspect;
pub mod predict;
pub mod reading;
pub mod reproduce;
pub mod simulate;
pub mod stream;
pub mod train;

use rayon::prelude::*;

use crate::analysis::FeatureTable;
use crate::calibrate::{CalibratedParams, GainCalibration};
use crate::classify::{ClassifierChoice, KnnParams};
use crate::error::OptionsError;
use crate::options::{classifier_with, snn_with, KnobSpec, StageOptions};
use crate::pipeline::{shared_grid, Encoded, Method, Pipeline};
use crate::progress::Progress;
use crate::recording::{one_grid, Dataset, Meta};
use crate::samples::MethodChoice;
use crate::snn::SnnParams;
use crate::{Grid, Result};

pub use reading::{CsvOptions, LogOptions, OpenOptions, ReadOptions};

/// Where a workflow reports its progress and what it has to say.
pub type OnProgress<'a> = &'a (dyn Fn(Progress) + Sync);

/// KNN's options: the neighbours and the z-scoring of features.
#[derive(Debug, Clone)]
#[cfg_attr(feature = "cli", derive(clap::Args))]
pub struct KnnOptions {
    /// Neighbours in KNN; at most the number of recordings in a training set.
    #[cfg_attr(feature = "cli", arg(short = 'k', long = "k", default_value_t = KnnParams::default().k))]
    pub k: usize,
    /// Do not z-score features with training-fold statistics before KNN.
    #[cfg_attr(feature = "cli", arg(long = "no-standardize"))]
    pub no_standardize: bool,
}

impl Default for KnnOptions {
    fn default() -> Self {
        Self {
            k: KnnParams::default().k,
            no_standardize: !KnnParams::default().standardize,
        }
    }
}

impl KnnOptions {
    /// KNN's parameters, checked.
    ///
    /// # Errors
    /// `k` is zero.
    pub fn params(&self) -> Result<KnnParams> {
        let knn = KnnParams {
            k: self.k,
            standardize: !self.no_standardize,
        };
        knn.check()?;
        Ok(knn)
    }
}

/// Options choosing the classifier and its knobs, each defined once in
/// [`CLASSIFIER_OPTIONS`](crate::options::CLASSIFIER_OPTIONS) (KNN's own are [`KnnOptions`], shared with the commands that run
/// the paper's KNN alone).
#[derive(Debug, Clone, Default)]
pub struct ClassifierOptions {
    /// The classifier; `None`: the one the method implies, else KNN.
    pub classifier: Option<ClassifierChoice>,
    /// The knobs given, each with its value as typed.
    pub knobs: Vec<(&'static KnobSpec, String)>,
}

/// The spiking network's knobs alone (`compare`'s network candidate).
#[derive(Debug, Clone, Default)]
pub struct SnnOptions {
    /// The knobs given, each with its value as typed.
    pub knobs: Vec<(&'static KnobSpec, String)>,
}

impl SnnOptions {
    /// `defaults` with the knobs given applied, checked.
    ///
    /// # Errors
    /// A value a knob does not take, or a parameter out of its range.
    pub fn params(&self, defaults: SnnParams) -> Result<SnnParams> {
        snn_with(defaults, &self.knobs)
    }

    /// `network` in words, with the options given as the command line spells them (the
    /// training settings the words leave out, such as epochs and time constants, among
    /// them), so that a ranking says how to train its network again.
    pub fn described(&self, network: &ClassifierChoice) -> String {
        let given: Vec<String> = (self.knobs.iter())
            .map(|(spec, text)| match (spec.kind, text.as_str()) {
                (crate::options::OptionKind::Flag, "true") => spec.flag.to_string(),
                _ => format!("{} {text}", spec.flag),
            })
            .collect();
        match given.is_empty() {
            true => network.to_string(),
            false => format!("{network}, given {}", given.join(" ")),
        }
    }
}

impl ClassifierOptions {
    /// The chosen classifier with its options applied, checked; `knn` is used as it is for
    /// `--classifier knn`.
    ///
    /// # Errors
    /// An option of another classifier, or a parameter out of its range.
    pub fn choice(&self, knn: KnnParams) -> Result<ClassifierChoice> {
        self.choice_of(self.classifier.unwrap_or_default(), knn)
    }

    /// The method and the classifier that reads it: `--classifier snn` reads the spike
    /// trains and `--method spikes` is read by the spiking network, so either implies the
    /// other; without either, `method` given or `default`, and KNN. A pairing that does not
    /// run is refused here, naming the pairings that do.
    ///
    /// # Errors
    /// As [`ClassifierOptions::choice`], a method the classifier does not read, and KNN's
    /// `k` or z-scoring changed for another classifier.
    pub fn with_method(
        &self,
        method: Option<MethodChoice>,
        default: MethodChoice,
        knn: KnnParams,
    ) -> Result<(MethodChoice, ClassifierChoice)> {
        let (method, kind) = self.kinds(method, default);
        let classifier = self.choice_of(kind, knn)?;
        method.check_pairing(&classifier)?;
        let defaults = KnnParams::default();
        if !matches!(classifier, ClassifierChoice::Knn(_)) {
            // A `k` or z-scoring other than the default would otherwise go unused.
            let option = match (knn.k != defaults.k, knn.standardize != defaults.standardize) {
                (true, _) => Some("-k"),
                (_, true) => Some("--no-standardize"),
                _ => None,
            };
            if let Some(option) = option {
                let applies_to = "--classifier knn";
                return Err(OptionsError::NotApplicable { option, applies_to }.into());
            }
        }
        Ok((method, classifier))
    }

    /// The method and the classifier's kind (its default parameters) the options name.
    pub fn kinds(
        &self,
        method: Option<MethodChoice>,
        default: MethodChoice,
    ) -> (MethodChoice, ClassifierChoice) {
        let spikes = ClassifierChoice::Snn(SnnParams::default());
        let kind = match (&self.classifier, method) {
            (Some(kind), _) => *kind,
            (None, Some(MethodChoice::Spikes)) => spikes,
            (None, _) => ClassifierChoice::default(),
        };
        let method = method.unwrap_or_else(|| MethodChoice::for_classifier(&kind, default));
        (method, kind)
    }

    /// The classifier of kind `kind` with its knobs applied, checked; KNN as `knn` says.
    fn choice_of(&self, kind: ClassifierChoice, knn: KnnParams) -> Result<ClassifierChoice> {
        let kind = match kind {
            ClassifierChoice::Knn(_) => ClassifierChoice::Knn(knn),
            other => other,
        };
        classifier_with(kind, &self.knobs)
    }
}

#[cfg(feature = "cli")]
mod knob_flags {
    //! The classifiers' knobs as flags, built from [`CLASSIFIER_OPTIONS`].

    use clap::{Arg, ArgAction, ArgMatches, Args, Command, FromArgMatches};

    use super::{ClassifierOptions, KnobSpec, SnnOptions};
    use crate::classify::ClassifierChoice;
    use crate::options::{OptionKind, CLASSIFIER_OPTIONS};

    /// The knobs of every classifier but KNN (whose `-k` and `--no-standardize` are
    /// [`super::KnnOptions`]'), or of the network alone.
    fn offered(snn_only: bool) -> impl Iterator<Item = &'static KnobSpec> {
        CLASSIFIER_OPTIONS
            .iter()
            .filter(move |k| k.classifier != "knn" && (!snn_only || k.classifier == "snn"))
    }

    /// The flag of one knob, its value checked as it is parsed; `compare` names its
    /// classifiers in `--classifiers`.
    fn flag(spec: &'static KnobSpec, in_list: bool) -> Arg {
        let long = &spec.flag[2..];
        let mut help = spec.help_with_default();
        if in_list {
            let one = format!("With `--classifier {}`", spec.classifier);
            let many = format!("With `{}` in `--classifiers`", spec.classifier);
            help = help.replacen(&one, &many, 1);
        }
        let arg = Arg::new(long).long(long).help(help);
        if spec.kind == OptionKind::Flag {
            return arg.action(ArgAction::SetTrue);
        }
        arg.value_name(long.replace('-', "_").to_uppercase())
            .action(ArgAction::Set)
            .allow_negative_numbers(true)
            .value_parser(move |text: &str| spec.read(text).map(|()| text.to_string()))
    }

    /// The knobs given on the command line, each with its text.
    fn given(matches: &ArgMatches, snn_only: bool) -> Vec<(&'static KnobSpec, String)> {
        offered(snn_only)
            .filter_map(|spec| {
                let id = &spec.flag[2..];
                let text = match spec.kind {
                    OptionKind::Flag => matches.get_flag(id).then(|| "true".to_string()),
                    _ => matches.get_one::<String>(id).cloned(),
                };
                text.map(|t| (spec, t))
            })
            .collect()
    }

    /// `--classifier`'s help.
    const CLASSIFIER_HELP: &str = "Classifier: `knn` (the paper's), `forest` (random forest \
        of CART trees, √d features tried per split), `linear` (multinomial logistic \
        regression, L2 penalty) or `snn` (a spiking network that reads the spike trains \
        themselves, not features: it implies `--method spikes`, and `--method spikes` \
        implies it). The regression always z-scores features with training statistics and \
        the forest needs no scaling: --no-standardize applies to KNN only. [default: knn]";

    impl Args for ClassifierOptions {
        fn augment_args(cmd: Command) -> Command {
            let classifier = Arg::new("classifier")
                .long("classifier")
                .value_name("CLASSIFIER")
                .help(CLASSIFIER_HELP)
                .value_parser(|text: &str| text.parse::<ClassifierChoice>());
            offered(false).fold(cmd.arg(classifier), |cmd, spec| cmd.arg(flag(spec, false)))
        }

        fn augment_args_for_update(cmd: Command) -> Command {
            Self::augment_args(cmd)
        }
    }

    impl FromArgMatches for ClassifierOptions {
        fn from_arg_matches(matches: &ArgMatches) -> Result<Self, clap::Error> {
            let mut options = Self::default();
            options.update_from_arg_matches(matches)?;
            Ok(options)
        }

        fn update_from_arg_matches(&mut self, matches: &ArgMatches) -> Result<(), clap::Error> {
            if let Some(choice) = matches.get_one::<ClassifierChoice>("classifier") {
                self.classifier = Some(*choice);
            }
            self.knobs = given(matches, false);
            Ok(())
        }
    }

    impl Args for SnnOptions {
        fn augment_args(cmd: Command) -> Command {
            offered(true).fold(cmd, |cmd, spec| cmd.arg(flag(spec, true)))
        }

        fn augment_args_for_update(cmd: Command) -> Command {
            Self::augment_args(cmd)
        }
    }

    impl FromArgMatches for SnnOptions {
        fn from_arg_matches(matches: &ArgMatches) -> Result<Self, clap::Error> {
            let mut options = Self::default();
            options.update_from_arg_matches(matches)?;
            Ok(options)
        }

        fn update_from_arg_matches(&mut self, matches: &ArgMatches) -> Result<(), clap::Error> {
            self.knobs = given(matches, true);
            Ok(())
        }
    }
}

/// `--taxel` given with another method than `taxel`.
fn taxel_not_applicable() -> crate::Error {
    OptionsError::NotApplicable {
        option: "--taxel",
        applies_to: "--method taxel",
    }
    .into()
}

/// The recordings of `dataset` at `speeds` (all when `None`), in manifest order.
///
/// # Errors
/// A speed the dataset has no recording at.
pub fn indices_at(dataset: &Dataset, speeds: Option<&[crate::Speed]>) -> Result<Vec<usize>> {
    Ok(match speeds {
        Some(speeds) => dataset.indices_at(speeds)?,
        None => (0..dataset.entries.len()).collect(),
    })
}

/// Encodes the dataset's recordings `indices` and extracts `method`'s features; also
/// returns the grid the recordings share.
///
/// # Errors
/// A recording that cannot be read or encoded, or recordings on different grids.
pub fn feature_table(
    dataset: &Dataset,
    pipeline: &Pipeline,
    indices: &[usize],
    method: Method,
    on: OnProgress,
) -> Result<(FeatureTable, Grid)> {
    // Each recording's spikes are dropped once its row is made: a dataset's spikes are
    // never all in memory at once (the first recording, encoded twice, gives the grid).
    on(Progress::Stage("encoding", indices.len()));
    let one = |i: usize| -> Result<Encoded> {
        let mut e = pipeline.encode_dataset(dataset, &[i], &|| ())?;
        Ok(e.pop().expect("one recording encoded"))
    };
    let first = match indices.first() {
        Some(&i) => one(i)?,
        None => return Err(crate::error::DatasetError::Empty.into()),
    };
    let grid = shared_grid(std::slice::from_ref(&first))?;
    let extractor = pipeline.extractor(&grid)?;
    type Row = (Meta, bool, bool, Vec<f64>);
    let rows: Vec<Row> = indices
        .par_iter()
        .map(|&i| {
            let e = one(i)?;
            let grids = [
                (first.meta.file.as_str(), grid.clone()),
                (e.meta.file.as_str(), e.spikes.grid()),
            ];
            one_grid(grids)?;
            let row = extractor
                .row(&e, method)
                .map_err(|err| err.in_recording(&e.meta.file))?;
            on(Progress::Tick);
            Ok((e.meta, e.resampled, e.flat, row))
        })
        .collect::<Result<_>>()?;
    let resampled = rows.iter().filter(|r| r.1).count();
    let flat = rows.iter().filter(|r| r.2).map(|r| r.0.file.as_str());
    say_noticed(resampled, flat, on);
    let (metas, rows): (Vec<Meta>, Vec<Vec<f64>>) =
        rows.into_iter().map(|(m, _, _, row)| (m, row)).unzip();
    Ok((
        FeatureTable::from_rows(&extractor, method, metas, &rows),
        grid,
    ))
}

/// Encodes the dataset's recordings `indices` (a stage `encoding` of one step each),
/// saying what the conditioning noticed; also returns the grid the recordings share.
///
/// # Errors
/// A recording that cannot be read or encoded, or recordings on different grids.
pub fn encode_all(
    dataset: &Dataset,
    pipeline: &Pipeline,
    indices: &[usize],
    on: OnProgress,
) -> Result<(Vec<Encoded>, Grid)> {
    on(Progress::Stage("encoding", indices.len()));
    let encoded = pipeline.encode_dataset(dataset, indices, &|| on(Progress::Tick))?;
    say_conditions(&encoded, on);
    let grid = shared_grid(&encoded)?;
    Ok((encoded, grid))
}

/// The pipeline the stage options name, after saying the dataset's severe findings on its
/// signals and layout ([`crate::inspect::severe_findings`]); with `--causal`, its resting
/// values and scale fixed on `dataset`'s recordings `indices` (the training recordings:
/// never a test one); with `--gain auto`, its gain calibrated on them too
/// ([`calibrate_pipeline`]). Each choice is said.
///
/// # Errors
/// A stage option out of range, or a recording that cannot be read.
pub fn calibrated_pipeline(
    stages: &StageOptions,
    dataset: &Dataset,
    indices: &[usize],
    on: OnProgress,
) -> Result<CalibratedParams> {
    let checked = stages.check()?;
    if dataset.is_events() && (stages.causal || stages.gain.target_hz().is_some()) {
        return Err(OptionsError::Conflict(format!(
            "{} holds address events, which skip the encoder: --gain auto and --causal condition and encode a sampled signal",
            dataset.root.display()
        ))
        .into());
    }
    for line in crate::inspect::severe_findings(dataset, checked.to_calibrate())?.lines() {
        on(Progress::Advice(&line));
    }
    let baseline = dataset.layout.baseline.unwrap_or_default();
    let load = |i: usize| dataset.load(i);
    let calibrated = checked.calibrate(&load, indices, baseline)?;
    if let Some(c) = &calibrated.causal {
        on(Progress::Say(&format!(
            "--causal: forward-only filter; resting values and scale {:.6} fixed on {} training recording(s) (median selected phase {} ms)",
            c.conditioning.scale, c.recordings, c.median_duration_ms
        )));
        if c.rest_spread >= 1.0 && calibrated.params.preprocess.drift_window_ms.is_none() {
            on(Progress::Advice(&format!(
                "the training recordings' resting values differ by {:.1} times the causal scale (median taxel, 10th to 90th percentile): one fixed resting value leaves recordings resting above it at the ceiling and those below it silent, whatever the gain; --drift-window-s tracks each taxel's resting value instead",
                c.rest_spread
            )));
        }
    }
    if let Some(c) = &calibrated.gain {
        on(Progress::Say(&calibration_line(c)));
    }
    Ok(calibrated)
}

/// The recordings `--gain auto` and `--causal` calibrate on: those of `all` that `train`
/// selects under a train/test split; otherwise every recording evaluated (each is in some
/// training fold, and labels are not read; calibrating again inside every fold is not
/// done), which is said when a calibration happens.
///
/// # Errors
/// A selection naming a column the manifest lacks.
pub fn calibration_rows(
    train: Option<&crate::recording::Selection>,
    dataset: &Dataset,
    all: &[usize],
    stages: &StageOptions,
    on: OnProgress,
) -> Result<Vec<usize>> {
    match train {
        Some(train) => {
            let rows = train.rows(&dataset.entries)?;
            Ok(all.iter().copied().filter(|i| rows.contains(i)).collect())
        }
        None => {
            if stages.gain.target_hz().is_some() || stages.causal {
                on(Progress::Say(&format!("note: under cross-validation --gain auto and --causal calibrate on the recordings evaluated (labels unused; the gain on at most {} of them, spread evenly), test folds included; a train/test split calibrates on the training set only", crate::calibrate::MAX_CALIBRATION_RECORDINGS)));
            }
            Ok(all.to_vec())
        }
    }
}

/// A result's data line: `data: FINGERPRINT (FOLDER)`, the folder made absolute so that a
/// result names the same folder whatever directory the command ran in.
///
/// # Errors
/// The manifest or a listed file can no longer be read for the fingerprint.
pub fn data_line(dataset: &Dataset) -> Result<String> {
    let folder = std::fs::canonicalize(&dataset.root).unwrap_or_else(|_| dataset.root.clone());
    Ok(format!(
        "data: {} ({})",
        dataset.fingerprint()?,
        folder.display()
    ))
}

/// [`calibration_line`] in a result's provenance: under cross-validation (`split` false)
/// it says that the recordings calibrated on are drawn from all those evaluated, test
/// folds included.
pub fn calibration_provenance(c: &GainCalibration, split: bool) -> String {
    let on = match split {
        true => "",
        false => "; under cross-validation they are drawn from all the recordings evaluated, test folds included (labels unused)",
    };
    format!("{}{on}", calibration_line(c))
}

/// What `--gain auto` chose, as said to the user.
pub fn calibration_line(c: &GainCalibration) -> String {
    let reached = if c.clamped {
        " (target out of reach: the end of the searched range)"
    } else {
        ""
    };
    format!(
        "--gain auto: G = {} gives a median of {:.1} Hz (target {} Hz) over {} taxel x recording pairs with signal in the {} it calibrated on{reached}",
        c.gain, c.median_hz, c.target_hz, c.pairs, crate::words::counted(c.recordings, "recording")
    )
}

/// Says what conditioning did that the user should know: recordings resampled to 1 kHz,
/// recordings without positive signal.
pub fn say_conditions(encoded: &[Encoded], on: OnProgress) {
    let resampled = encoded.iter().filter(|e| e.resampled).count();
    let flat = encoded
        .iter()
        .filter(|e| e.flat)
        .map(|e| e.meta.file.as_str());
    say_noticed(resampled, flat, on);
    for warning in encoded.iter().filter_map(Encoded::constant_warning) {
        on(Progress::Advice(&warning));
    }
}

/// [`say_conditions`] from the count of resampled recordings and the flat ones' files.
fn say_noticed<'a>(resampled: usize, flat: impl Iterator<Item = &'a str>, on: OnProgress) {
    if resampled > 0 {
        let resampled = crate::words::counted(resampled, "recording");
        on(Progress::Say(&format!(
            "note: {resampled} resampled to the encoder's 1 kHz by linear interpolation"
        )));
    }
    for file in flat {
        on(Progress::Advice(&format!(
            "{file}: no positive signal in the selected phase; left at zero (no spikes)"
        )));
    }
}
