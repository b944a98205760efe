//! `neurotex evaluate`: KNN on a dataset's features, by cross-validation or by training on
//! some conditions (speeds, trials, sessions: any manifest column) and testing on others;
//! prints accuracy and confusion matrix, and for the single-taxel method which taxels
//! stay silent or saturate.

use std::path::PathBuf;

use anyhow::{bail, Result};
use clap::Args;
use neurotex::analysis::{Columns, Split};
use neurotex::classify::CvParams;
use neurotex::evaluation::{Evaluation, Spikes};
use neurotex::pipeline::{Method, Pipeline};
use neurotex::recording::{Dataset, Selection};
use neurotex::{Cell, Speed};

use super::{calibrated_pipeline, encode_all};
use crate::classifier_args::ClassifierArgs;
use crate::open_args::OpenArgs;
use crate::output::{check_output, is_stdout, write_file};
use crate::stage_args::StageArgs;
use neurotex::classify::ClassifierChoice;
use neurotex::compare::candidates::{MethodChoice, STANDARD_TAU_MS};

/// Options of `neurotex evaluate`.
#[derive(Args)]
pub struct EvaluateArgs {
    /// The dataset folder.
    #[arg(long)]
    pub dataset: PathBuf,
    /// Feature set: `taxel` (each taxel alone, the mean reported), `glcm2d`, `glcm3d`,
    /// `all-taxels` (every taxel's statistics in one vector), `all-taxels-mm` (the same per
    /// mm of travel), `glcm3d-multi` (3D-GLCM at each of `--bin-widths`) or `van-rossum`
    /// (KNN over van Rossum distances between the recordings' spike trains).
    #[arg(long)]
    pub method: MethodChoice,
    /// With `--method van-rossum`: the kernel's time constant in ms (default: the rate
    /// volume's 200 ms bin).
    #[arg(long = "tau-ms", default_value_t = STANDARD_TAU_MS)]
    pub tau_ms: f64,
    /// With `--method taxel`: the taxel to use, as `ROW,COL`. Without it every taxel is
    /// evaluated and the mean over taxels is reported, with the best beside it.
    #[arg(long)]
    pub taxel: Option<Cell>,
    /// Neighbours in KNN.
    #[arg(long, default_value_t = neurotex::classify::KnnParams::default().k)]
    pub k: usize,
    /// Cross-validation folds (stratified, shuffled).
    #[arg(long, default_value_t = neurotex::classify::CvParams::default().folds)]
    pub folds: usize,
    /// Seed of the fold shuffle (repeat r uses seed + r).
    #[arg(long, default_value_t = 0)]
    pub seed: u64,
    /// Cross-validation repeats with different shuffles.
    #[arg(long, default_value_t = neurotex::classify::CvParams::default().repeats)]
    pub repeats: usize,
    /// Only recordings at these speeds (mm/s, comma-separated); default all.
    #[arg(
        long,
        value_delimiter = ',',
        allow_hyphen_values = true,
        conflicts_with = "train_speeds"
    )]
    pub speeds: Option<Vec<Speed>>,
    /// Train on these speeds instead of cross-validating (needs --test-speeds); the same
    /// as --train-where speed_mm_s=SPEEDS.
    #[arg(
        long = "train-speeds",
        value_delimiter = ',',
        allow_hyphen_values = true,
        requires = "test_speeds",
        conflicts_with = "train_where"
    )]
    pub train_speeds: Option<Vec<Speed>>,
    /// Test on these speeds (needs --train-speeds).
    #[arg(
        long = "test-speeds",
        value_delimiter = ',',
        allow_hyphen_values = true,
        requires = "train_speeds",
        conflicts_with = "test_where"
    )]
    pub test_speeds: Option<Vec<Speed>>,
    /// Train on the recordings whose manifest column COL holds one of the values, instead
    /// of cross-validating (needs --test-where): COL=V1,V2. Any column but `label`;
    /// `speed_mm_s`, `force_n` and `trial` compare as numbers, other columns as text.
    #[arg(
        long = "train-where",
        value_name = "COL=V1,V2",
        allow_hyphen_values = true,
        requires = "test_where",
        conflicts_with_all = ["speeds", "group_by"]
    )]
    pub train_where: Option<Selection>,
    /// Test on the recordings whose column COL holds one of the values (needs
    /// --train-where; no recording may be in both sets).
    #[arg(
        long = "test-where",
        value_name = "COL=V1,V2",
        allow_hyphen_values = true,
        requires = "train_where"
    )]
    pub test_where: Option<Selection>,
    /// Cross-validation folds never split a group of this manifest column (`trial`,
    /// `force_n`, or any further column such as a session or subject); with fewer groups
    /// than folds, each group is held out in turn.
    #[arg(long = "group-by", conflicts_with = "train_speeds")]
    pub group_by: Option<String>,
    /// Print one JSON object instead of text.
    #[arg(long)]
    pub json: bool,
    /// Write each recording's out-of-fold prediction to this CSV file (`-`: standard
    /// output, the evaluation then said on standard error):
    /// `file,label,predicted,fold,repeat`, one row per recording and CV repeat (folds and
    /// repeats count from 0; `fold` is `test` with a train/test split). Needs one
    /// classifier: a GLCM method, or --method taxel with --taxel.
    #[arg(long)]
    pub predictions: Option<PathBuf>,
    #[command(flatten)]
    pub stages: StageArgs,
    #[command(flatten)]
    pub classifier: ClassifierArgs,
    #[command(flatten)]
    pub open: OpenArgs,
}

impl EvaluateArgs {
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
    fn calibration_indices(&self, dataset: &Dataset, all: &[usize]) -> Result<Vec<usize>> {
        match self.selections() {
            Some((train, _)) => Ok(train.rows(&dataset.entries)?),
            None => {
                if self.stages.gain_target().is_some() {
                    eprintln!("note: under cross-validation --gain auto calibrates on every recording evaluated (labels unused), test folds included; a train/test split calibrates on the training set only");
                }
                Ok(all.to_vec())
            }
        }
    }

    /// The feature columns to classify with.
    fn columns(&self) -> Result<Columns> {
        Ok(match (self.method, self.taxel) {
            (MethodChoice::Features(Method::Taxel), Some(cell)) => Columns::Taxel(cell),
            (MethodChoice::Features(Method::Taxel), None) => Columns::EachTaxel,
            (_, Some(_)) => bail!("--taxel applies only to --method taxel"),
            (_, None) => Columns::All,
        })
    }
}

/// Runs `neurotex evaluate`.
pub fn run(args: EvaluateArgs) -> Result<()> {
    let to_stdout = args.predictions.as_deref().is_some_and(is_stdout);
    if args.json && to_stdout {
        bail!("--predictions - and --json would both write standard output; write the predictions to a file with --json");
    }
    let classifier = args.classifier.choice(args.stages.knn(args.k)?)?;
    let split = args.split()?;
    let columns = args.columns()?;
    if args.predictions.is_some() && columns == Columns::EachTaxel {
        bail!("--predictions needs one classifier, not one per taxel: add --taxel ROW,COL");
    }
    let spike_timing = args.method == MethodChoice::VanRossum;
    let knn = match (spike_timing, classifier) {
        (false, _) => None,
        (true, ClassifierChoice::Knn(knn)) => Some(knn),
        (true, _) => bail!("--method van-rossum classifies with KNN only (--classifier knn)"),
    };
    if spike_timing && (args.taxel.is_some() || args.predictions.is_some()) {
        bail!("--taxel and --predictions do not apply to --method van-rossum");
    }
    let dataset = args.open.open(&args.dataset)?;
    if let Some(path) = &args.predictions {
        check_output(path, &dataset.files())?;
    }
    let indices = args.indices(&dataset)?;
    let calibrated = calibrated_pipeline(
        &args.stages,
        &dataset,
        &args.calibration_indices(&dataset, &indices)?,
    )?;
    let pipeline = Pipeline::new(calibrated.params)?;
    let (encoded, grid) = encode_all(&dataset, &pipeline, &indices)?;
    let spikes = Spikes {
        encoded: &encoded,
        grid: &grid,
        pipeline: &pipeline,
    };
    let evaluation = match (args.method, knn) {
        (MethodChoice::Features(method), _) => Evaluation::of_features(
            spikes,
            method,
            columns,
            &split,
            &classifier.check()?,
            args.seed,
        )?,
        (_, Some(knn)) => Evaluation::of_spike_timing(spikes, knn, args.tau_ms, &split, args.seed)?,
        (_, None) => unreachable!("spike timing has its KNN"),
    };
    if let Some(path) = &args.predictions {
        write_file(path, "out-of-fold predictions", |w| {
            evaluation.write_out_of_fold(w)
        })?;
    }
    if args.json {
        let mut value = evaluation.json()?;
        if let Some(c) = &calibrated.causal {
            value["causal_conditioning"] = serde_json::to_value(c)?;
        }
        if let Some(c) = &calibrated.gain {
            value["gain_calibration"] = serde_json::to_value(c)?;
        }
        println!("{}", serde_json::to_string(&value)?);
    } else if to_stdout {
        eprint!("{}", evaluation.text());
    } else {
        print!("{}", evaluation.text());
    }
    Ok(())
}
