//! The commands' workflows, one module each, shared by the command line and the Python
//! package. Each module defines its command's options once (their help, defaults and
//! rules; with the `cli` feature the command line's flags are derived from them), checks
//! them, and runs the library on them. A workflow never prints: what it has to say (a
//! note, a warning, what a calibration chose) and its progress go to the caller's
//! [`Progress`] callback, which the command line shows on standard error and Python turns
//! into warnings.

pub mod compare;
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
use crate::calibrate::{calibrate_pipeline, CalibratedParams, GainCalibration};
use crate::classify::{ClassifierChoice, ForestParams, KnnParams, LinearParams};
use crate::error::OptionsError;
use crate::options::StageOptions;
use crate::pipeline::{shared_grid, Encoded, Method, Pipeline};
use crate::progress::Progress;
use crate::recording::{one_grid, Dataset, Meta};
use crate::samples::MethodChoice;
use crate::snn::{Reset, SnnParams, Target};
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

/// Options choosing the classifier (KNN's own are [`KnnOptions`]).
#[derive(Debug, Clone, Default)]
#[cfg_attr(feature = "cli", derive(clap::Args))]
pub struct ClassifierOptions {
    /// Classifier: `knn` (the paper's), `forest` (random forest of CART trees, √d features
    /// tried per split), `linear` (multinomial logistic regression, L2 penalty) or `snn` (a
    /// spiking network that reads the spike trains themselves, not features: it implies
    /// `--method spikes`, and `--method spikes` implies it). The regression always z-scores
    /// features with training statistics and the forest needs no scaling: --no-standardize
    /// applies to KNN only. [default: knn]
    #[cfg_attr(feature = "cli", arg(long))]
    pub classifier: Option<ClassifierChoice>,
    /// With `--classifier forest`: trees in the forest [default: 200].
    #[cfg_attr(feature = "cli", arg(long))]
    pub trees: Option<usize>,
    /// With `--classifier forest`: seed of the trees' random streams [default: 0].
    #[cfg_attr(feature = "cli", arg(long = "forest-seed"))]
    pub forest_seed: Option<u64>,
    /// With `--classifier forest`: deepest level of a tree, the root at 0 [default: grown
    /// until leaves are pure or too small to split].
    #[cfg_attr(feature = "cli", arg(long = "max-depth"))]
    pub max_depth: Option<usize>,
    /// With `--classifier forest`: fewest training recordings in a leaf [default: 1].
    #[cfg_attr(feature = "cli", arg(long = "min-samples-leaf"))]
    pub min_samples_leaf: Option<usize>,
    /// With `--classifier forest`: features tried at each split [default: ⌊√d⌋].
    #[cfg_attr(feature = "cli", arg(long = "max-features"))]
    pub max_features: Option<usize>,
    /// With `--classifier forest`: grow each tree on a bootstrap sample (`true`) or on the
    /// whole training set (`false`) [default: true].
    #[cfg_attr(feature = "cli", arg(long))]
    pub bootstrap: Option<bool>,
    /// With `--classifier linear`: inverse penalty strength, scikit-learn's C [default: 1].
    #[cfg_attr(feature = "cli", arg(long = "c"))]
    pub c: Option<f64>,
    /// With `--classifier linear`: most L-BFGS iterations [default: 1000].
    #[cfg_attr(feature = "cli", arg(long = "max-iter"))]
    pub max_iter: Option<usize>,
    /// With `--classifier linear`: stop when no gradient component exceeds this [default:
    /// 1e-8].
    #[cfg_attr(feature = "cli", arg(long))]
    pub tol: Option<f64>,
    /// The spiking network's options (`--classifier snn`).
    #[cfg_attr(feature = "cli", command(flatten))]
    pub snn: SnnOptions,
}

/// Options of the spiking classifier (`--classifier snn`, `docs/spiking-classifier.md`).
#[derive(Debug, Clone, Default)]
#[cfg_attr(feature = "cli", derive(clap::Args))]
pub struct SnnOptions {
    /// With `--classifier snn`: hidden LIF neurons [default: 128].
    #[cfg_attr(feature = "cli", arg(long = "snn-hidden", id = "snn-hidden"))]
    pub hidden: Option<usize>,
    /// With `--classifier snn`: the network's time step in ms; the encoder's 1 ms spikes
    /// are counted in bins this wide [default: 10].
    #[cfg_attr(feature = "cli", arg(long = "snn-dt-ms", id = "snn-dt-ms"))]
    pub dt_ms: Option<u32>,
    /// With `--classifier snn`: most training epochs; early stopping on a validation split
    /// of the training recordings may end sooner [default: 60].
    #[cfg_attr(feature = "cli", arg(long = "snn-epochs", id = "snn-epochs"))]
    pub epochs: Option<usize>,
    /// With `--classifier snn`: class scores are the readout's `mean` over time or its
    /// `max` [default: mean].
    #[cfg_attr(feature = "cli", arg(long = "snn-readout", id = "snn-readout"))]
    pub readout: Option<neurotex_learn::snn::Readout>,
    /// With `--classifier snn`: seed of the initial weights, validation split and batch
    /// order [default: 0].
    #[cfg_attr(feature = "cli", arg(long = "snn-seed", id = "snn-seed"))]
    pub seed: Option<u64>,
    /// With `--classifier snn`: recurrent connections within the hidden layer (each step's
    /// spikes drive the next step's currents); default feed-forward.
    #[cfg_attr(feature = "cli", arg(long = "snn-recurrent", id = "snn-recurrent"))]
    pub recurrent: bool,
    /// With `--classifier snn`: how a hidden neuron resets on a spike: `zero` (the
    /// default; one spike per step at most) or `subtract` (n = floor(v) spikes, v - n
    /// kept: the neuron of sinabs, Rockpool and Xylo, needed to export to them).
    #[cfg_attr(feature = "cli", arg(long = "snn-reset", id = "snn-reset"))]
    pub reset: Option<neurotex_learn::snn::Reset>,
    /// With `--classifier snn`: the hidden neurons' synaptic time constant, ms [default:
    /// 20].
    #[cfg_attr(feature = "cli", arg(long = "snn-tau-syn-ms", id = "snn-tau-syn-ms"))]
    pub tau_syn_ms: Option<f64>,
    /// With `--classifier snn`: the hidden neurons' membrane time constant, ms [default:
    /// 40].
    #[cfg_attr(feature = "cli", arg(long = "snn-tau-mem-ms", id = "snn-tau-mem-ms"))]
    pub tau_mem_ms: Option<f64>,
    /// With `--classifier snn`: the readout's time constant, ms [default: 40].
    #[cfg_attr(feature = "cli", arg(long = "snn-tau-out-ms", id = "snn-tau-out-ms"))]
    pub tau_out_ms: Option<f64>,
    /// With `--classifier snn`: where the network runs: `float` (the default) or `xylo`
    /// (SynSense's Xylo Audio 2: trained within the chip's limits, its time constants
    /// moved to the chip's bitshift decays, subtractive reset, and predicting in the
    /// chip's integers as its simulator does; `export xylo` writes its configuration).
    #[cfg_attr(feature = "cli", arg(long = "snn-target", id = "snn-target"))]
    pub target: Option<neurotex_learn::snn::Target>,
}

impl SnnOptions {
    /// The first option given, as the command line spells it.
    pub fn given(&self) -> Option<&'static str> {
        let given = [
            ("--snn-hidden", self.hidden.is_some()),
            ("--snn-dt-ms", self.dt_ms.is_some()),
            ("--snn-epochs", self.epochs.is_some()),
            ("--snn-readout", self.readout.is_some()),
            ("--snn-seed", self.seed.is_some()),
            ("--snn-recurrent", self.recurrent),
            ("--snn-reset", self.reset.is_some()),
            ("--snn-target", self.target.is_some()),
            ("--snn-tau-syn-ms", self.tau_syn_ms.is_some()),
            ("--snn-tau-mem-ms", self.tau_mem_ms.is_some()),
            ("--snn-tau-out-ms", self.tau_out_ms.is_some()),
        ];
        given.into_iter().find(|g| g.1).map(|g| g.0)
    }

    /// Whether any option was given.
    pub fn any(&self) -> bool {
        self.hidden.is_some()
            || self.dt_ms.is_some()
            || self.epochs.is_some()
            || self.readout.is_some()
            || self.seed.is_some()
            || self.recurrent
            || self.reset.is_some()
            || self.target.is_some()
            || self.tau_syn_ms.is_some()
            || self.tau_mem_ms.is_some()
            || self.tau_out_ms.is_some()
    }

    /// `defaults` with the options given applied, checked.
    ///
    /// # Errors
    /// A parameter out of its range.
    pub fn params(&self, defaults: SnnParams) -> Result<SnnParams> {
        Ok(SnnParams {
            hidden: self.hidden.unwrap_or(defaults.hidden),
            dt_ms: self.dt_ms.unwrap_or(defaults.dt_ms),
            epochs: self.epochs.unwrap_or(defaults.epochs),
            readout: self.readout.unwrap_or(defaults.readout),
            seed: self.seed.unwrap_or(defaults.seed),
            recurrent: self.recurrent || defaults.recurrent,
            reset: self.reset.unwrap_or(match self.target {
                // The chip's neurons subtract; its profile asks for no other option.
                Some(Target::Xylo) => Reset::Subtract,
                _ => defaults.reset,
            }),
            target: self.target.unwrap_or(defaults.target),
            tau_syn_ms: self.tau_syn_ms.unwrap_or(defaults.tau_syn_ms),
            tau_mem_ms: self.tau_mem_ms.unwrap_or(defaults.tau_mem_ms),
            tau_out_ms: self.tau_out_ms.unwrap_or(defaults.tau_out_ms),
            ..defaults
        }
        .check()?)
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
    /// As [`ClassifierOptions::choice`], and a method the classifier does not read.
    pub fn with_method(
        &self,
        method: Option<MethodChoice>,
        default: MethodChoice,
        knn: KnnParams,
    ) -> Result<(MethodChoice, ClassifierChoice)> {
        let (method, kind) = self.kinds(method, default);
        let classifier = self.choice_of(kind, knn)?;
        method.check_pairing(&classifier)?;
        Ok((method, classifier))
    }

    /// The method and the classifier's kind (its default parameters) the options name.
    pub fn kinds(
        &self,
        method: Option<MethodChoice>,
        default: MethodChoice,
    ) -> (MethodChoice, ClassifierChoice) {
        let spikes = ClassifierChoice::Snn(SnnParams::default());
        let kind = match (self.classifier, method) {
            (Some(kind), _) => kind,
            (None, Some(MethodChoice::Spikes)) => spikes,
            (None, _) => ClassifierChoice::default(),
        };
        let method = method.unwrap_or_else(|| MethodChoice::for_classifier(&kind, default));
        (method, kind)
    }

    /// The classifier of kind `kind` with its options applied, checked.
    fn choice_of(&self, kind: ClassifierChoice, knn: KnnParams) -> Result<ClassifierChoice> {
        let choice = match kind {
            ClassifierChoice::Knn(_) => ClassifierChoice::Knn(knn),
            ClassifierChoice::Forest(defaults) => ClassifierChoice::Forest(ForestParams {
                trees: self.trees.unwrap_or(defaults.trees),
                seed: self.forest_seed.unwrap_or(defaults.seed),
                max_depth: self.max_depth.or(defaults.max_depth),
                min_samples_leaf: self.min_samples_leaf.unwrap_or(defaults.min_samples_leaf),
                max_features: self.max_features.or(defaults.max_features),
                bootstrap: self.bootstrap.unwrap_or(defaults.bootstrap),
            }),
            ClassifierChoice::Linear(defaults) => ClassifierChoice::Linear(LinearParams {
                c: self.c.unwrap_or(defaults.c),
                max_iter: self.max_iter.unwrap_or(defaults.max_iter),
                tol: self.tol.unwrap_or(defaults.tol),
            }),
            ClassifierChoice::Snn(defaults) => ClassifierChoice::Snn(self.snn.params(defaults)?),
        };
        self.only_its_own(&choice)?;
        if !matches!(choice, ClassifierChoice::Snn(_)) {
            choice.check()?;
        }
        Ok(choice)
    }
}

impl ClassifierOptions {
    /// Refuses an option of another classifier than `choice`.
    ///
    /// # Errors
    /// The first option given that `choice` does not take.
    fn only_its_own(&self, choice: &ClassifierChoice) -> Result<()> {
        if let Some(option) = self.snn.given() {
            if !matches!(choice, ClassifierChoice::Snn(_)) {
                let applies_to = "--classifier snn";
                return Err(OptionsError::NotApplicable { option, applies_to }.into());
            }
        }
        let forest = matches!(choice, ClassifierChoice::Forest(_));
        if !forest && (self.trees.is_some() || self.forest_seed.is_some()) {
            return Err(OptionsError::Conflict(
                "--trees and --forest-seed apply only to --classifier forest".into(),
            )
            .into());
        }
        let forest_knobs = [
            ("--max-depth", self.max_depth.is_some()),
            ("--min-samples-leaf", self.min_samples_leaf.is_some()),
            ("--max-features", self.max_features.is_some()),
            ("--bootstrap", self.bootstrap.is_some()),
        ];
        let linear_knobs = [
            ("--c", self.c.is_some()),
            ("--max-iter", self.max_iter.is_some()),
            ("--tol", self.tol.is_some()),
        ];
        let linear = matches!(choice, ClassifierChoice::Linear(_));
        for (knobs, own, applies_to) in [
            (&forest_knobs[..], forest, "--classifier forest"),
            (&linear_knobs[..], linear, "--classifier linear"),
        ] {
            if let Some((option, _)) = knobs.iter().find(|k| k.1 && !own) {
                return Err(OptionsError::NotApplicable { option, applies_to }.into());
            }
        }
        Ok(())
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
    let params = stages.check()?.params;
    if dataset.is_events() && (stages.causal || stages.gain.target_hz().is_some()) {
        return Err(OptionsError::Conflict(format!(
            "{} holds address events, which skip the encoder: --gain auto and --causal condition and encode a sampled signal",
            dataset.root.display()
        ))
        .into());
    }
    for line in crate::inspect::severe_findings(dataset, &params)?.lines() {
        on(Progress::Advice(&line));
    }
    let baseline = dataset.layout.baseline.unwrap_or_default();
    let load = |i: usize| dataset.load(i);
    let calibrated =
        calibrate_pipeline(params, stages.causal, stages.gain, &load, indices, baseline)?;
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
                on(Progress::Say("note: under cross-validation --gain auto and --causal calibrate on every recording evaluated (labels unused), test folds included; a train/test split calibrates on the training set only"));
            }
            Ok(all.to_vec())
        }
    }
}

/// What `--gain auto` chose, as said to the user.
pub fn calibration_line(c: &GainCalibration) -> String {
    let reached = if c.clamped {
        " (target out of reach: the end of the searched range)"
    } else {
        ""
    };
    format!(
        "--gain auto: G = {} gives a median of {:.1} Hz (target {} Hz) over {} taxel x recording pairs with signal in {} training recording(s){reached}",
        c.gain, c.median_hz, c.target_hz, c.pairs, c.recordings
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
}

/// [`say_conditions`] from the count of resampled recordings and the flat ones' files.
fn say_noticed<'a>(resampled: usize, flat: impl Iterator<Item = &'a str>, on: OnProgress) {
    if resampled > 0 {
        on(Progress::Say(&format!("note: {resampled} recording(s) resampled to the encoder's 1 kHz by linear interpolation")));
    }
    for file in flat {
        on(Progress::Advice(&format!(
            "{file}: no positive signal in the selected phase; left at zero (no spikes)"
        )));
    }
}
