//! `evaluate`: a classifier on a dataset's features, by cross-validation or by training on
//! some conditions (speeds, trials, sessions: any manifest column) and testing on others.

pub mod draws;
pub mod evaluation;

use std::path::PathBuf;

use super::{
    calibrated_pipeline, encode_all, ClassifierOptions, KnnOptions, OnProgress, OpenOptions,
};
use crate::analysis::{evaluator, Columns, Split};
use crate::calibrate::CalibratedParams;
use crate::classify::{ClassifierChoice, CvParams};
use crate::error::OptionsError;
use crate::options::StageOptions;
use crate::pipeline::{Method, Pipeline};
use crate::progress::Progress;
use crate::recording::{Dataset, Selection};
use crate::samples::MethodChoice;
use crate::{Cell, Result, Speed};
use evaluation::{EncoderDraws, Evaluation, Spikes};

/// The method evaluated when neither `--method` nor a classifier that implies one is
/// given: the paper's 3D-GLCM.
pub const DEFAULT_METHOD: MethodChoice = MethodChoice::Features(Method::Glcm3d);

/// Options of `neurotex evaluate`.
#[derive(Debug, Clone)]
#[cfg_attr(feature = "cli", derive(clap::Args))]
pub struct EvaluateOptions {
    /// The dataset folder.
    #[cfg_attr(feature = "cli", arg(long))]
    pub dataset: PathBuf,
    /// Feature set: `taxel` (each taxel alone, the mean reported), `glcm2d`, `glcm3d`,
    /// `all-taxels` (every taxel's statistics in one vector), `all-taxels-mm` (the same per
    /// mm of travel), `glcm3d-multi` (3D-GLCM at each of `--bin-widths`), `spectrum` (each
    /// taxel's spike counts along the slide in bands of spatial frequency), `rates` (every
    /// taxel's mean spike rate in spikes/s, the counts without their timing), `van-rossum`
    /// (KNN over van Rossum distances between the recordings' spike trains) or `spikes`
    /// (the spike trains themselves, classified by the spiking network, `--classifier snn`,
    /// which `--method spikes` chooses when no other classifier is given). [default:
    /// glcm3d, the paper's method; spikes with `--classifier snn`]
    #[cfg_attr(feature = "cli", arg(long))]
    pub method: Option<MethodChoice>,
    /// With `--method van-rossum`: the kernel's time constant in ms (default: the rate
    /// volume's 200 ms bin).
    #[cfg_attr(feature = "cli", arg(long = "tau-ms", default_value_t = crate::samples::STANDARD_TAU_MS))]
    pub tau_ms: f64,
    /// With `--method taxel`: the taxel to use, as `ROW,COL`. Without it every taxel is
    /// evaluated and the mean over taxels is reported, with the best beside it.
    #[cfg_attr(feature = "cli", arg(long))]
    pub taxel: Option<Cell>,
    /// KNN's neighbours and z-scoring.
    #[cfg_attr(feature = "cli", command(flatten))]
    pub knn: KnnOptions,
    /// Cross-validation folds (stratified, shuffled).
    #[cfg_attr(feature = "cli", arg(long, default_value_t = crate::classify::CvParams::default().folds))]
    pub folds: usize,
    /// Seed of the fold shuffle (repeat r uses seed + r).
    #[cfg_attr(feature = "cli", arg(long, default_value_t = 0))]
    pub seed: u64,
    /// Cross-validation repeats with different shuffles.
    #[cfg_attr(feature = "cli", arg(long, default_value_t = crate::classify::CvParams::default().repeats))]
    pub repeats: usize,
    /// Encodings of every recording: the input as run, then N - 1 more with each of its
    /// conditioned samples times 1 + u x 1e-12 (u uniform in [-1, 1), a stream per seed,
    /// encoding and recording), the classifier evaluated on each under the same split. The
    /// accuracy is then also given as the mean over the encodings, with an interval that
    /// resamples encodings as well as recordings: spiking neurons turn rounding-level input
    /// changes into moved spikes, which can move an accuracy by several points, and the
    /// interval over recordings alone does not hold that. Costs N times the encoding and
    /// the evaluation; 1 (the default) evaluates the input as run only.
    #[cfg_attr(feature = "cli", arg(long = "encoder-draws", default_value_t = 1))]
    pub encoder_draws: usize,
    /// Only recordings at these speeds (mm/s, comma-separated); default all.
    #[cfg_attr(
        feature = "cli",
        arg(
            long,
            value_delimiter = ',',
            allow_hyphen_values = true,
            conflicts_with = "train_speeds"
        )
    )]
    pub speeds: Option<Vec<Speed>>,
    /// Train on these speeds instead of cross-validating (needs --test-speeds); the same
    /// as --train-where speed_mm_s=SPEEDS.
    #[cfg_attr(
        feature = "cli",
        arg(
            long = "train-speeds",
            value_delimiter = ',',
            allow_hyphen_values = true,
            requires = "test_speeds",
            conflicts_with = "train_where"
        )
    )]
    pub train_speeds: Option<Vec<Speed>>,
    /// Test on these speeds (needs --train-speeds).
    #[cfg_attr(
        feature = "cli",
        arg(
            long = "test-speeds",
            value_delimiter = ',',
            allow_hyphen_values = true,
            requires = "train_speeds",
            conflicts_with = "test_where"
        )
    )]
    pub test_speeds: Option<Vec<Speed>>,
    /// Train on the recordings whose manifest column COL holds one of the values, instead
    /// of cross-validating (needs --test-where): COL=V1,V2. Any column but `label`;
    /// `speed_mm_s`, `force_n` and `trial` compare as numbers, other columns as text.
    #[cfg_attr(feature = "cli", arg(
        long = "train-where",
        value_name = "COL=V1,V2",
        allow_hyphen_values = true,
        requires = "test_where",
        conflicts_with_all = ["speeds", "group_by"]
    ))]
    pub train_where: Option<Selection>,
    /// Test on the recordings whose column COL holds one of the values (needs
    /// --train-where; no recording may be in both sets).
    #[cfg_attr(
        feature = "cli",
        arg(
            long = "test-where",
            value_name = "COL=V1,V2",
            allow_hyphen_values = true,
            requires = "train_where"
        )
    )]
    pub test_where: Option<Selection>,
    /// Cross-validation folds never split a group of this manifest column (`trial`,
    /// `force_n`, or any further column such as a session or subject); with fewer groups
    /// than folds, each group is held out in turn.
    #[cfg_attr(
        feature = "cli",
        arg(long = "group-by", conflicts_with = "train_speeds")
    )]
    pub group_by: Option<String>,
    /// The classifier and its knobs.
    #[cfg_attr(feature = "cli", command(flatten))]
    pub classifier: ClassifierOptions,
    /// How the dataset folder is opened.
    #[cfg_attr(feature = "cli", command(flatten))]
    pub open: OpenOptions,
}

impl EvaluateOptions {
    /// Cross-validation, or training and testing on the selected recordings.
    fn split(&self) -> Result<Split> {
        let cv = CvParams {
            folds: self.folds,
            seed: self.seed,
            repeats: self.repeats,
        }
        .check()?;
        Ok(match self.selections() {
            Some((train, test)) => Split::Where { train, test },
            None => Split::CrossValidation {
                speeds: self.speeds.clone(),
                cv,
                group_by: self.group_by.clone(),
            },
        })
    }

    /// The training and test selections of a train/test split, `--train-speeds` and
    /// `--test-speeds` as selections on `speed_mm_s`.
    fn selections(&self) -> Option<(Selection, Selection)> {
        match (&self.train_where, &self.test_where) {
            (Some(train), Some(test)) => Some((train.clone(), test.clone())),
            _ => match (&self.train_speeds, &self.test_speeds) {
                (Some(train), Some(test)) => {
                    Some((Selection::speeds(train), Selection::speeds(test)))
                }
                _ => None,
            },
        }
    }

    /// The dataset's recordings the evaluation uses, in manifest order.
    fn indices(&self, dataset: &Dataset) -> Result<Vec<usize>> {
        let entries = &dataset.entries;
        if let (Some(train), Some(test)) = (&self.train_speeds, &self.test_speeds) {
            // A speed the dataset lacks is named as --speeds names it, with the speeds it has.
            dataset.indices_at(&[&train[..], test].concat())?;
        }
        Ok(match (self.selections(), &self.speeds) {
            (Some((train, test)), _) => {
                let mut rows = train.rows(entries)?;
                rows.extend(test.rows(entries)?);
                rows.sort_unstable();
                rows.dedup();
                rows
            }
            (None, Some(speeds)) => dataset.indices_at(speeds)?,
            (None, None) => (0..entries.len()).collect(),
        })
    }

    /// The recordings `--gain auto` calibrates on: the training set of a train/test split;
    /// under cross-validation every recording evaluated (each is in some training fold, and
    /// labels are not read; calibrating again inside every fold is not done), said on
    /// standard error.
    fn calibration_indices(
        &self,
        dataset: &Dataset,
        all: &[usize],
        stages: &StageOptions,
        on: OnProgress,
    ) -> Result<Vec<usize>> {
        let split = self.selections();
        super::calibration_rows(split.as_ref().map(|s| &s.0), dataset, all, stages, on)
    }

    /// What `--group-by` makes of `--folds` when the recordings `indices` hold fewer
    /// groups than folds (each group is then held out in turn): said once, with the folds
    /// given and used.
    fn fewer_groups(&self, dataset: &Dataset, indices: &[usize]) -> Vec<String> {
        let (Some(column), None) = (&self.group_by, self.selections()) else {
            return Vec::new();
        };
        let groups = crate::analysis::group_count(&dataset.entries, indices, column);
        if groups >= self.folds || groups < 2 {
            return Vec::new();
        }
        vec![format!(
            "--folds {} with --group-by {column}: {groups} `{column}` groups, so {groups} folds are used (each group held out in turn)",
            self.folds
        )]
    }

    /// The classifier's fits on the recordings `indices`: one per fold and repeat, with as
    /// many folds as groups when `--group-by` finds fewer; one for a train/test split.
    fn fits(&self, dataset: &Dataset, indices: &[usize]) -> usize {
        if self.selections().is_some() {
            return 1;
        }
        let folds = match &self.group_by {
            Some(column) => {
                let groups = crate::analysis::group_count(&dataset.entries, indices, column);
                self.folds.min(groups)
            }
            None => self.folds,
        };
        self.repeats * folds
    }

    /// The feature columns to classify with.
    ///
    /// # Errors
    /// `--taxel` with another method than `taxel`.
    pub fn columns(&self) -> Result<Columns> {
        Ok(match (self.method(), self.taxel) {
            (MethodChoice::Features(Method::Taxel), Some(cell)) => Columns::Taxel(cell),
            (MethodChoice::Features(Method::Taxel), None) => Columns::EachTaxel,
            (_, Some(_)) => return Err(super::taxel_not_applicable()),
            (_, None) => Columns::All,
        })
    }

    /// The method evaluated: `--method`, or what `--classifier` reads.
    pub fn method(&self) -> MethodChoice {
        self.classifier.kinds(self.method, DEFAULT_METHOD).0
    }

    /// Checks that the options name one classifier, whose out-of-fold predictions can be
    /// written: any method but `taxel` without `--taxel`.
    ///
    /// # Errors
    /// One classifier per taxel.
    pub fn one_classifier(&self) -> Result<()> {
        if self.columns()? == Columns::EachTaxel {
            return Err(OptionsError::Conflict(
                "--predictions needs one classifier, not one per taxel: add --taxel ROW,COL".into(),
            )
            .into());
        }
        Ok(())
    }

    /// With the spiking network: its note on short windows, and a stage of one step per
    /// epoch of each fit (minutes on long slides).
    fn say_training(
        &self,
        classifier: ClassifierChoice,
        dataset: &Dataset,
        indices: &[usize],
        on: OnProgress,
    ) {
        if let ClassifierChoice::Snn(snn) = classifier {
            if let Some(note) = snn.short_window() {
                on(Progress::Say(&note));
            }
            on(Progress::Stage(
                "training the spiking network (epochs of every fit)",
                self.fits(dataset, indices) * snn.epochs,
            ));
        }
    }

    /// Runs the evaluation on `dataset` with the stage options `stages`.
    ///
    /// # Errors
    /// Options that do not go together, a parameter out of range, recordings that cannot
    /// be read, or a design too small for the split.
    pub fn run(
        &self,
        dataset: &Dataset,
        stages: &StageOptions,
        on: OnProgress,
    ) -> Result<Evaluated> {
        let (method, classifier) =
            self.classifier
                .with_method(self.method, DEFAULT_METHOD, self.knn.params()?)?;
        let split = self.split()?;
        let columns = self.columns()?;
        draws::check(self.encoder_draws, dataset)?;
        let indices = self.indices(dataset)?;
        let mut notes = self.fewer_groups(dataset, &indices);
        notes.iter().for_each(|note| on(Progress::Advice(note)));
        let calibration = self.calibration_indices(dataset, &indices, stages, on)?;
        let calibrated = calibrated_pipeline(stages, dataset, &calibration, on)?;
        let pipeline = Pipeline::new(calibrated.params.clone())?;
        let (encoded, grid) = encode_all(dataset, &pipeline, &indices, on)?;
        let spikes = Spikes {
            encoded: &encoded,
            grid: &grid,
            pipeline: &pipeline,
        };
        // One path for every method, as `compare` takes: the method's samples, the
        // classifier over them under the split, the result summarised.
        let samples = spikes.samples(method, columns, &classifier, self.tau_ms)?;
        let all: Vec<usize> = (0..samples.metas().len()).collect();
        self.say_training(classifier, dataset, &indices, on);
        let outcome = evaluator(classifier, samples)?(&all, &split, on)?;
        let chosen = (method, columns);
        let evaluation = Evaluation::of(spikes, chosen, outcome, &split, self.tau_ms, self.seed)?;
        let evaluation = Evaluation {
            classifier: Some(classifier.to_string()),
            ..evaluation
        };
        let run = draws::Run {
            dataset,
            pipeline: &pipeline,
            grid: &grid,
            indices: &indices,
            chosen,
            classifier,
            split: &split,
            tau_ms: self.tau_ms,
        };
        let evaluation = draws::with_draws(&run, evaluation, self.encoder_draws, self.seed, on)?;
        if let Some(note) = evaluation.chance_note() {
            on(Progress::Advice(&note));
            notes.push(note);
        }
        let split_apart = !matches!(split, Split::CrossValidation { .. });
        // The evaluation's recordings: how many have their slide's times in the manifest.
        let slides = crate::experiments::slide_times(&evaluation.metas);
        let provenance = provenance(dataset, (slides, split_apart), method, &calibrated)?;
        let mut applied = calibrated.params.clone();
        let pre = &mut applied.preprocess;
        pre.baseline = pre.baseline.or(dataset.layout.baseline);
        // The sliding phase is kept only where the manifest gives its times.
        pre.slide_only &= slides[0] > 0;
        Ok(Evaluated {
            evaluation,
            calibrated,
            notes,
            provenance,
            applied,
        })
    }
}

/// An evaluation and the calibrations its pipeline went through.
#[derive(Debug)]
pub struct Evaluated {
    /// The evaluation.
    pub evaluation: Evaluation,
    /// The pipeline as run, with what `--causal` and `--gain auto` fixed.
    pub calibrated: CalibratedParams,
    /// Options the design could not honour as given (fewer folds than asked), and an
    /// accuracy not shown above chance ([`Evaluation::chance_note`]), each as said on
    /// standard error.
    pub notes: Vec<String>,
    /// Where the evaluation comes from: neurotex's build, the dataset's fingerprint and
    /// folder, and every stage's setting as run, one line each as results list them.
    pub provenance: Vec<String>,
    /// The stages' parameters as they applied to these recordings: the pipeline as run,
    /// its baseline the dataset's `layout.toml` one where the pipeline set none, and the
    /// whole recording kept (`slide_only` false) when the manifest gives no slide times.
    /// Every stage is listed, those the method does not use (FA under `sa`, the spectrum's
    /// bins under a GLCM method) as they stand.
    pub applied: crate::pipeline::PipelineParams,
}

/// The provenance of evaluating `method` on recordings of `dataset`, `slides[0]` of
/// `slides[1]` with their slide's times in the manifest, with the stages as `calibrated`
/// ran them; `split` whether a train/test split (not cross-validation) chose what was
/// calibrated on.
///
/// # Errors
/// The manifest or a listed file can no longer be read for the fingerprint.
fn provenance(
    dataset: &Dataset,
    (slides, split): ([usize; 2], bool),
    method: MethodChoice,
    calibrated: &CalibratedParams,
) -> Result<Vec<String>> {
    // No time of creation: the same evaluation gives the same output.
    let mut lines = vec![crate::experiments::build(), super::data_line(dataset)?];
    let methods = match method {
        MethodChoice::Features(m) => vec![m],
        _ => Vec::new(),
    };
    lines.extend((calibrated.params).describe(dataset.layout.baseline, slides, &methods));
    if let Some(c) = &calibrated.gain {
        lines.push(super::calibration_provenance(c, split));
    }
    Ok(lines)
}

impl Evaluated {
    /// The evaluation as one JSON object, with the calibrations under
    /// `causal_conditioning` and `gain_calibration`, [`Evaluated::applied`] under
    /// `pipeline` and the [`Evaluated::provenance`] lines under `provenance`.
    ///
    /// # Errors
    /// A value JSON cannot hold.
    pub fn json(&self) -> serde_json::Result<serde_json::Value> {
        let mut value = self.evaluation.json()?;
        if let Some(c) = &self.calibrated.causal {
            value["causal_conditioning"] = serde_json::to_value(c)?;
        }
        if let Some(c) = &self.calibrated.gain {
            value["gain_calibration"] = serde_json::to_value(c)?;
        }
        // Always there, empty when nothing was said, so that a script can read it.
        value["notes"] = serde_json::to_value(&self.notes)?;
        // What ran, as numbers a script can read and as the lines results list.
        value["pipeline"] = serde_json::to_value(&self.applied)?;
        value["provenance"] = serde_json::to_value(&self.provenance)?;
        Ok(value)
    }
}
