//! `neurotex evaluate`: KNN on a dataset's features, by cross-validation or by training on
//! some conditions (speeds, trials, sessions: any manifest column) and testing on others;
//! prints accuracy and confusion matrix, and for the single-taxel method which taxels
//! stay silent or saturate.

use std::io::Write;
use std::path::PathBuf;

use anyhow::{bail, Context, Result};
use clap::Args;
use neurotex::analysis::{
    evaluate, Columns, FeatureTable, OutOfFold, Outcome, Split, TaxelAccuracy,
};
use neurotex::classify::{CvParams, Metrics};
use neurotex::diagnostics::TaxelDiagnostics;
use neurotex::pipeline::{Method, Pipeline};
use neurotex::recording::{Dataset, Selection};
use neurotex::{Cell, Speed};

use super::{calibrated_pipeline, encode_all, encoded_features};
use crate::classifier_args::ClassifierArgs;
use crate::open_args::OpenArgs;
use crate::output::{check_output, write_file};
use crate::stage_args::StageArgs;
use neurotex::classify::ClassifierChoice;
use neurotex::compare::candidates::{
    candidates, CandidateSet, MethodChoice, STANDARD_TAU_MS, VAN_ROSSUM,
};

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
    /// Write each recording's out-of-fold prediction to this CSV file:
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
    let classifier = args.classifier.choice(args.stages.knn(args.k)?)?;
    let split = args.split()?;
    let columns = args.columns()?;
    if args.predictions.is_some() && columns == Columns::EachTaxel {
        bail!("--predictions needs one classifier, not one per taxel: add --taxel ROW,COL");
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
    let calibration = calibrated.gain;
    let causal = calibrated.causal;
    let pipeline = Pipeline::new(calibrated.params)?;
    let MethodChoice::Features(method) = args.method else {
        return evaluate_spike_timing(&args, &dataset, &indices, &pipeline, &split);
    };
    let features = encoded_features(&dataset, &pipeline, &indices, method)?;
    let (table, grid) = (&features.table, &features.grid);
    if let Some(cell) = args.taxel {
        grid.locate(cell)?;
    }
    let outcome = evaluate(table, columns, &split, &classifier.check()?)?;
    if let Some(path) = &args.predictions {
        let predictions = outcome
            .predictions
            .as_deref()
            .context("one classifier's predictions for --predictions")?;
        write_file(path, "out-of-fold predictions", |w| {
            write_out_of_fold(w, table, &outcome.labels, predictions)
        })?;
    }
    // Silent and saturated taxels matter where taxels are scored one by one.
    let taxels = (columns == Columns::EachTaxel).then_some(&features.taxels);
    if args.json {
        let mut value = serde_json::to_value(&outcome)?;
        value["method"] = method.name().into();
        // Balanced accuracy, per-class recall and precision and both chance levels from the
        // confusion matrix; the interval resamples recordings, keeping each one's
        // predictions over repeats (and taxels) together.
        value["metrics"] = serde_json::to_value(Metrics::from_confusion(&outcome.confusion))?;
        let interval = outcome.accuracy_interval(args.seed)?;
        value["accuracy_interval"] = serde_json::to_value(interval)?;
        if let Some(taxels) = taxels {
            value["taxels"] = taxels_json(taxels, &outcome)?;
        }
        if let Some(c) = &causal {
            value["causal_conditioning"] = serde_json::to_value(c)?;
        }
        if let Some(c) = &calibration {
            value["gain_calibration"] = serde_json::to_value(c)?;
        }
        println!("{}", serde_json::to_string(&value)?);
    } else {
        print_outcome(&outcome, method.name(), &split, grid.cols(), args.seed)?;
        if let Some(taxels) = taxels {
            print_taxels(taxels, &outcome);
        }
    }
    Ok(())
}

/// `evaluate --method van-rossum`: KNN over the van Rossum distances between the
/// recordings' spike trains (of the encoding's populations), the matrix computed once.
fn evaluate_spike_timing(
    args: &EvaluateArgs,
    dataset: &Dataset,
    indices: &[usize],
    pipeline: &Pipeline,
    split: &Split,
) -> Result<()> {
    let ClassifierChoice::Knn(knn) = args.classifier.choice(args.stages.knn(args.k)?)? else {
        bail!("--method van-rossum classifies with KNN only (--classifier knn)");
    };
    if args.taxel.is_some() || args.predictions.is_some() {
        bail!("--taxel and --predictions do not apply to --method van-rossum");
    }
    let (encoded, grid) = encode_all(dataset, pipeline, indices)?;
    let set = CandidateSet {
        encodings: vec![pipeline.params().encoding],
        methods: vec![MethodChoice::VanRossum],
        classifiers: vec![ClassifierChoice::Knn(knn)],
        tau_ms: args.tau_ms,
    };
    let candidate = candidates(&encoded, &grid, pipeline.params(), &set, 0.0)?.remove(0);
    let outcome = (candidate.evaluate)(&candidate.table, Columns::All, split)?;
    if args.json {
        let mut value = serde_json::to_value(&outcome)?;
        value["method"] = VAN_ROSSUM.into();
        value["tau_ms"] = args.tau_ms.into();
        value["metrics"] = serde_json::to_value(Metrics::from_confusion(&outcome.confusion))?;
        let interval = outcome.accuracy_interval(args.seed)?;
        value["accuracy_interval"] = serde_json::to_value(interval)?;
        println!("{}", serde_json::to_string(&value)?);
    } else {
        print_outcome(&outcome, VAN_ROSSUM, split, grid.cols(), args.seed)?;
    }
    Ok(())
}

/// The taxel diagnostics for `evaluate --json`: every taxel's silent and saturated shares,
/// the silent and saturated ones by name, and the mean accuracy over responsive taxels
/// (`null` when none responds) beside the mean over all.
fn taxels_json(taxels: &TaxelDiagnostics, outcome: &Outcome) -> Result<serde_json::Value> {
    let per = outcome.per_taxel.as_deref().unwrap_or_default();
    let mut value = serde_json::to_value(taxels)?;
    value["silent"] = serde_json::to_value(taxels.silent())?;
    value["saturated"] = serde_json::to_value(taxels.saturated())?;
    value["mean_all"] = outcome.accuracy.into();
    value["mean_responsive"] = serde_json::to_value(taxels.responsive_mean(per))?;
    Ok(value)
}

/// Prints the silent and saturated taxels and the mean over the responsive ones.
fn print_taxels(taxels: &TaxelDiagnostics, outcome: &Outcome) {
    let names = |list: Vec<&str>| match list.is_empty() {
        true => "none".to_string(),
        false => list.join(", "),
    };
    println!(
        "taxels silent (no spike) in most recordings: {}; at the encoder's ceiling ({:.0} Hz) in most recordings: {}",
        names(taxels.silent()),
        taxels.ceiling_hz,
        names(taxels.saturated())
    );
    let per = outcome.per_taxel.as_deref().unwrap_or_default();
    let all = 100.0 * outcome.accuracy;
    match taxels.responsive_mean(per) {
        Some(mean) => println!(
            "accuracy {:.1}% (mean over responsive taxels) beside {all:.1}% (mean over all taxels)",
            100.0 * mean
        ),
        None => println!("no taxel responds in most recordings; mean over all taxels {all:.1}%"),
    }
}

/// Prints the outcome as text: what was run, the accuracy (per taxel when every taxel was
/// evaluated) and the confusion matrix.
fn print_outcome(
    outcome: &Outcome,
    method: &str,
    split: &Split,
    cols: usize,
    seed: u64,
) -> Result<()> {
    let how = match split {
        Split::CrossValidation {
            cv,
            group_by: Some(column),
            speeds,
        } => format!(
            "{}, up to {}-fold CV keeping each `{column}` group in one fold, seed {}, {} repeat(s)",
            recordings_at(speeds.as_deref()),
            cv.folds,
            cv.seed,
            cv.repeats
        ),
        Split::CrossValidation { cv, speeds, .. } => format!(
            "{}, {}-fold stratified CV, seed {}, {} repeat(s)",
            recordings_at(speeds.as_deref()),
            cv.folds,
            cv.seed,
            cv.repeats
        ),
        Split::Where { train, test } => {
            format!("train on {}, test on {}", selected(train), selected(test))
        }
        Split::Rows { train, test } => {
            format!(
                "train on {} recordings, test on {}",
                train.len(),
                test.len()
            )
        }
    };
    println!("method {method}: {} samples, {how}", outcome.n);
    print_accuracy(outcome, cols);
    // No accuracy without its uncertainty and the level a guess reaches.
    let interval = outcome.accuracy_interval(seed)?;
    let metrics = Metrics::from_confusion(&outcome.confusion);
    println!(
        "95 % interval [{:.1}%, {:.1}%] (bootstrap over recordings); chance {:.1}% (one over {} classes), {:.1}% always answering the most frequent class",
        100.0 * interval.lower,
        100.0 * interval.upper,
        100.0 * metrics.chance_uniform,
        metrics.classes_present,
        100.0 * metrics.chance_majority
    );
    print_confusion(outcome);
    Ok(())
}

/// The recordings cross-validation runs over, as text.
fn recordings_at(speeds: Option<&[Speed]>) -> String {
    match speeds {
        None => "all recordings".into(),
        Some(speeds) => format!("recordings at {}", selected(&Selection::speeds(speeds))),
    }
}

/// A selection as text: `[5, 10] mm/s` for speeds, `session in [s1, s2]` otherwise.
fn selected(selection: &Selection) -> String {
    let values = selection.values.join(", ");
    match selection.column.as_str() {
        "speed_mm_s" => format!("[{values}] mm/s"),
        column => format!("{column} in [{values}]"),
    }
}

/// Prints the accuracy: per taxel with the mean and best when every taxel was evaluated,
/// with its spread over repeats when there is one.
fn print_accuracy(outcome: &Outcome, cols: usize) {
    if let (Some(per), Some(best)) = (&outcome.per_taxel, &outcome.best) {
        print_taxel_grid(per, cols);
        println!(
            "accuracy {:.1}% (mean over taxels); best taxel r{}c{} {:.1}% (chosen after the fact)",
            100.0 * outcome.accuracy,
            best.row,
            best.col,
            100.0 * best.accuracy
        );
    } else if outcome.accuracy_std > 0.0 {
        println!(
            "accuracy {:.1}% ± {:.1}%",
            100.0 * outcome.accuracy,
            100.0 * outcome.accuracy_std
        );
    } else {
        println!("accuracy {:.1}%", 100.0 * outcome.accuracy);
    }
}

/// Prints each taxel's accuracy in its place on the grid; `-` for cells without a taxel.
fn print_taxel_grid(per: &[TaxelAccuracy], cols: usize) {
    println!("accuracy per taxel (%):");
    let rows = per.iter().map(|t| t.row).max().unwrap_or(0) + 1;
    for r in 0..rows {
        let line: Vec<String> = (0..cols)
            .map(|c| {
                per.iter()
                    .find(|t| t.row == r && t.col == c)
                    .map_or("    -".to_string(), |t| {
                        format!("{:5.1}", 100.0 * t.accuracy)
                    })
            })
            .collect();
        println!("  {}", line.join(" "));
    }
}

/// Prints the confusion matrix, rows the true labels.
fn print_confusion(outcome: &Outcome) {
    let summed = if outcome.per_taxel.is_some() {
        ", summed over taxels"
    } else {
        ""
    };
    println!("confusion (rows = true, columns = predicted{summed}):");
    let width = outcome
        .labels
        .iter()
        .map(|l| l.len())
        .max()
        .unwrap_or(1)
        .max(5);
    print!("{:width$}", "");
    for l in &outcome.labels {
        print!(" {l:>width$}");
    }
    println!();
    for (l, row) in outcome.labels.iter().zip(outcome.confusion.rows()) {
        print!("{l:width$}");
        for v in row {
            print!(" {v:>width$}");
        }
        println!();
    }
}

/// Writes `file,label,predicted,fold,repeat`, one row per prediction.
fn write_out_of_fold(
    w: &mut dyn Write,
    table: &FeatureTable,
    labels: &[String],
    predictions: &[OutOfFold],
) -> std::io::Result<()> {
    let mut out = csv::Writer::from_writer(w);
    out.write_record(["file", "label", "predicted", "fold", "repeat"])?;
    for p in predictions {
        let meta = &table.metas[p.row];
        let fold = p.fold.map_or("test".to_string(), |f| f.to_string());
        out.write_record([
            meta.file.as_str(),
            meta.label.as_str(),
            labels[p.predicted].as_str(),
            fold.as_str(),
            p.repeat.to_string().as_str(),
        ])?;
    }
    out.flush()
}
